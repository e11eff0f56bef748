//! The sun and the sky light instanced scenes (issue 18, item 1): the instanced solver against
//! the flattened plain solve of the same scene under the same daylight, an unoccluded polygon's
//! exact irradiance at every level, and `radiosity solve` of a scene file with `[sun]` and `[sky]`
//! through the streaming output.

use radiosity_core::daylight::{self, DistantSource, Site, SkyModel};
use radiosity_core::geom::DVec3;
use radiosity_core::instancing::properties::PropertyConfig;
use radiosity_core::instancing::solver::relative_error;
use radiosity_core::instancing::{
    self, ForestParams, InstancedConfig, InstancedScene, Leaf, PolygonInfo, PolygonMeans, RadiositySink, generate_forest, solve_full,
    solve_instanced,
};
use std::path::Path;
use std::process::Command;

/// Largest error of a polygon's mean radiosity, instanced against flattened, as a fraction of the
/// flattened solve's largest (the sunlit ground's): a small generated tree (1,289 polygons) under
/// a sun and a 46-cell sky, measured 0.145 (0.142 now, see below). The direct light agrees (each kind of polygon's
/// sunlit power through the nested BVHs within 0.2% of brute force through the flattened scene,
/// `diagnose_direct_sun`); the rest is the instanced model's interreflection: the light the ground
/// reflects up reaches an opened instance as parallel beams binned by the links' directions, which
/// gives tilted leaves less than a hemisphere of ground would (the leaves' light 4% low under sun
/// and sky, 5% high with a black ground; under the generated lamps the same tree's leaves are
/// 21–24% high, hidden there by the lamps' far larger radiosity), and single leaves differ by
/// their few points against the plain solve's elements split along the sun's shadows. Measured
/// 0.142 since the ground gets its points by area (`TOP_POINT_AREA_REL`).
const TREE_MAX_TOL: f64 = 0.20;
/// Area-weighted mean error of the same, measured 0.0046 (0.0166 when the lone tree's ground had
/// 16 points; 4 such trees, before that: 0.046, max 0.279).
const TREE_MEAN_TOL: f64 = 0.01;
/// How far an instanced solve's power balance may be from closing. Measured on the small tree:
/// 0.48% to 0.57% short, above the 0.5% the plain solve meets (`tests/daylight.rs`): the
/// instanced model (proxies, beams) does not conserve energy exactly (README, "Plants under the
/// sun and sky"). Before a lone tree's ground got its direct light from more than 16 points
/// (`TOP_POINT_AREA_REL`) the balance read 2.3% over (with 16 escape rays on the ground); the
/// estimate's own noise is about 0.15% here (4,096 escape rays on the ground, which sends most of
/// the light out).
const INSTANCED_BALANCE_TOL: f64 = 0.01;
/// The incident power's grid estimate against `E·A` on a lone polygon: edge cells only.
const INCIDENT_TOL: f64 = 0.005;
/// An unoccluded polygon's irradiance is a sum of `E·cos` terms, computed exactly: rounding only.
const EXACT_TOL: f64 = 1e-9;

fn daylight_sources(sky_cells: u32) -> Vec<DistantSource> {
    let site = Site::default();
    let mut sources = vec![daylight::sun(DVec3::new(0.3, 0.2, -0.93), [400.0, 380.0, 300.0], &site).unwrap().unwrap()];
    sources.extend(daylight::sky(SkyModel::Uniform, [100.0, 90.0, 80.0], sky_cells, &site).unwrap());
    sources
}

fn config(sources: Vec<DistantSource>) -> InstancedConfig {
    InstancedConfig {
        properties: PropertyConfig { n_directions: 16, rays_per_direction: 400, ..PropertyConfig::default() },
        daylight: sources,
        ..InstancedConfig::default()
    }
}

/// A small generated tree on its ground, the lamps taken away: daylight only.
fn small_tree() -> InstancedScene {
    let mut scene = generate_forest(&ForestParams { trees: 1, min_age: 3, max_age: 4, spacing: 3.0, ..ForestParams::default() });
    let root = scene.root as usize;
    scene.prototypes[root].polygons.truncate(1);
    scene
}

#[test]
fn a_small_tree_under_sun_and_sky_matches_the_flattened_solve() {
    let scene = small_tree();
    let c = config(daylight_sources(46));
    let t = std::time::Instant::now();
    let (full, full_links) = solve_full(&scene, &c).unwrap();
    let t_full = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    let mut inst = PolygonMeans::default();
    let stats = solve_instanced(&scene, &c, &mut inst).unwrap();
    let t_inst = t.elapsed().as_secs_f64();
    assert_eq!(inst.radiosity.len(), full.radiosity.len());
    let (worst, mean) = relative_error(&full, &inst);
    eprintln!(
        "{} polygons: full {full_links} links {t_full:.2}s, instanced {} local solves {} links {t_inst:.2}s: max {:.4}%, mean {:.4}%",
        full.radiosity.len(),
        stats.local_solves,
        stats.links,
        100.0 * worst,
        100.0 * mean
    );
    assert!(stats.local_solves > 1, "the trees must be solved as instances");
    assert!(worst <= TREE_MAX_TOL, "max error {worst}");
    assert!(mean <= TREE_MEAN_TOL, "mean error {mean}");
    // Daylight reached the leaves below the top: no polygon of the tree is black.
    let lit = inst.radiosity.iter().filter(|b| b.iter().any(|&x| x > 0.0)).count();
    assert!(lit * 10 >= inst.radiosity.len() * 9, "{lit} of {} polygons lit", inst.radiosity.len());
}

/// The power balance of an instanced solve, measured beside it
/// (`radiosity::instancing::balance`): on the small tree under sun and sky, absorbed plus escaped
/// against incident (measured 0.9943, 0.9952, 0.9949 in the three channels); the incident power
/// of a lone ground polygon against `E·A`.
#[test]
fn instanced_balance_closes_on_a_small_tree() {
    use instancing::balance::DaylightBalance;
    let scene = small_tree();
    let sources = daylight_sources(46);
    let c = config(sources.clone());
    let mut sink = DaylightBalance::new(PolygonMeans::default(), &scene, &sources);
    solve_instanced(&scene, &c, &mut sink).unwrap();
    let (_, balance) = sink.finish();
    let b = balance.expect("daylight gives a balance");
    for ch in 0..3 {
        let r = b.ratio(ch).unwrap();
        eprintln!("channel {ch}: incident {:.1} absorbed {:.1} escaped {:.1}: {r:.4}", b.incident[ch], b.absorbed[ch], b.escaped[ch]);
    }
    for ch in 0..3 {
        let r = b.ratio(ch).unwrap();
        assert!((r - 1.0).abs() <= INSTANCED_BALANCE_TOL, "channel {ch}: balance {r}");
        assert!(b.escaped[ch] > 0.0 && b.absorbed[ch] > 0.0);
    }

    // A lone horizontal 10 × 10 ground: every ray of every source's grid that crosses it hits.
    let mut ground = small_tree();
    let root = ground.root as usize;
    ground.prototypes[root].instances.clear();
    let mut sink = DaylightBalance::new(PolygonMeans::default(), &ground, &sources);
    solve_instanced(&ground, &c, &mut sink).unwrap();
    let b = sink.finish().1.unwrap();
    let area = ground.prototypes[root].polygons[0].poly.area();
    for ch in 0..3 {
        let want: f64 = sources.iter().map(|s| s.on(DVec3::Z)[ch]).sum::<f64>() * area;
        assert!((b.incident[ch] / want - 1.0).abs() <= INCIDENT_TOL, "channel {ch}: {} vs {want}", b.incident[ch]);
    }
}

/// Keeps each polygon's mean irradiance.
#[derive(Default)]
struct Irradiance(Vec<[f64; 3]>);

impl RadiositySink for Irradiance {
    fn polygon(&mut self, info: &PolygonInfo, leaves: &[Leaf]) -> Result<(), instancing::InstancingError> {
        let i = info.flat_index as usize;
        if self.0.len() <= i {
            self.0.resize(i + 1, [0.0; 3]);
        }
        self.0[i] = instancing::solver::leaf_means(leaves).2;
        Ok(())
    }
}

const OPEN_SKY: &str = r#"
[[material]]
name = "black"
reflectance = 0.0
[[material]]
name = "grey"
reflectance = 0.5

[[polygon]]
material = "black"
vertices = [[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0]]

# Tilted toward the sun, high above the rest.
[[polygon]]
material = "grey"
vertices = [[2, 2, 6], [3, 2, 6.5], [3, 3, 6.5], [2, 3, 6]]

[[prototype]]
name = "cube"
[[prototype.box]]
min = [0, 0, 0]
max = [1, 1, 1]
material = "grey"

[[instance]]
of = "cube"
translate = [6, 6, 1]
"#;

/// A polygon in full sun and open sky gets exactly `Σ E·max(0, −n·toward)`: at the top level
/// (the tilted quad) and inside an opened instance (the cube's top face, traced through the
/// nested BVHs).
#[test]
fn unoccluded_polygons_get_e_cos_exactly() {
    let scene = instancing::parse(OPEN_SKY, Path::new("open.toml"), Path::new(".")).unwrap();
    let sources = daylight_sources(46);
    let mut sink = Irradiance::default();
    let stats = solve_instanced(&scene, &config(sources.clone()), &mut sink).unwrap();
    assert_eq!(stats.local_solves, 2, "the cube is an instance");
    let expected = |n: DVec3| -> [f64; 3] {
        let mut e = [0.0; 3];
        for s in &sources {
            let on = s.on(n);
            for c in 0..3 {
                e[c] += on[c];
            }
        }
        e
    };
    let flat = instancing::flatten(&scene, &instancing::FlattenOptions { two_sided_pairs: true }).unwrap();
    let mut checked = 0;
    for (i, p) in flat.polygons.iter().enumerate() {
        let n = p.poly.normal();
        let c = p.poly.centroid();
        // The tilted quad (z ≥ 6), the cube's top face (z = 2, facing up).
        let tilted = c.z > 5.0;
        let cube_top = (c.z - 2.0).abs() < 1e-9 && n.z > 0.99;
        if !(tilted || cube_top) {
            continue;
        }
        let want = expected(n);
        for ch in 0..3 {
            assert!((sink.0[i][ch] - want[ch]).abs() <= EXACT_TOL * want[ch], "polygon {i}: {:?} vs {want:?}", sink.0[i]);
        }
        checked += 1;
    }
    assert_eq!(checked, 2);
}

/// Runs `radiosity solve scene` into `dir/out` (no image, quiet), which it returns; the solve
/// must succeed.
fn solve_cli(scene: &Path, dir: &Path) -> std::path::PathBuf {
    let out = dir.join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--no-image", "--quiet"])
        .output()
        .expect("the binary runs");
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    out
}

/// `radiosity solve` of an instanced scene file with `[sun]` and `[sky]` solves it instanced
/// (not flattened) and writes the streamed outputs.
#[test]
fn cli_solves_an_instanced_scene_under_daylight() {
    let dir = std::env::temp_dir().join(format!("radiosity-instanced-daylight-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.toml");
    let text = format!(
        "{OPEN_SKY}\n[sun]\ndirection = [0.3, 0.2, -0.93]\ndirect_normal = 400.0\n[sky]\nmodel = \"cie-overcast\"\ndiffuse_horizontal = 100.0\ndirections = 46\n"
    );
    std::fs::write(&scene, text).unwrap();
    let out = solve_cli(&scene, &dir);
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["local_solves"], 2, "solved instanced: {stats}");
    let patches = std::fs::read_to_string(out.join("patches.csv")).unwrap();
    assert!(patches.lines().count() > 8, "{patches}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scene with named bands solved instanced: `patches.csv` and `groups.csv` name the bands, an
/// unoccluded polygon absorbs exactly `A·(1 − ρ − t)·Σ E·cos` in each band, `groups.csv` sums
/// the rows of each prototype, and `stats.json` holds the bands and their absorbed power.
#[test]
fn cli_instanced_bands_report_absorbed_power() {
    let dir = std::env::temp_dir().join(format!("radiosity-instanced-bands-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene_path = dir.join("scene.toml");
    let geometry =
        OPEN_SKY.replace("reflectance = 0.5", "reflectance = [0.2, 0.6]").replace("reflectance = 0.0", "reflectance = [0.0, 0.0]");
    let text = format!(
        "bands = [\"PAR\", \"NIR\"]\n{geometry}\n[sun]\ndirection = [0.3, 0.2, -0.93]\ndirect_normal = [400.0, 380.0]\n[sky]\nmodel = \"cie-overcast\"\ndiffuse_horizontal = [100.0, 90.0]\ndirections = 46\n"
    );
    std::fs::write(&scene_path, &text).unwrap();
    let out = solve_cli(&scene_path, &dir);
    let patches = std::fs::read_to_string(out.join("patches.csv")).unwrap();
    let mut lines = patches.lines();
    assert_eq!(lines.next(), Some("index,group,material,area,b_PAR,b_NIR,h_PAR,h_NIR,units,absorbed_PAR,absorbed_NIR"));
    let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(str::to_owned).collect()).collect();
    let num = |r: &[String], k: usize| r[k].parse::<f64>().unwrap();

    // The exact irradiance of the cube's top face (z = 2, facing up, in the open).
    let site = Site::default();
    let mut sources = vec![daylight::sun(DVec3::new(0.3, 0.2, -0.93), [400.0, 380.0, 0.0], &site).unwrap().unwrap()];
    sources.extend(daylight::sky(SkyModel::CieOvercast, [100.0, 90.0, 0.0], 46, &site).unwrap());
    let e: [f64; 2] = std::array::from_fn(|c| sources.iter().map(|s| s.on(DVec3::Z)[c]).sum());
    let scene = instancing::load(&scene_path).unwrap();
    let flat = instancing::flatten(&scene, &instancing::FlattenOptions { two_sided_pairs: true }).unwrap();
    let top = flat
        .polygons
        .iter()
        .position(|p| (p.poly.centroid().z - 2.0).abs() < 1e-9 && p.poly.normal().z > 0.99)
        .expect("the cube's top face");
    let row = rows.iter().find(|r| r[0] == top.to_string()).expect("its row");
    for (c, rho) in [0.2, 0.6].into_iter().enumerate() {
        let want = num(row, 3) * (1.0 - rho) * e[c];
        assert!((num(row, 9 + c) - want).abs() <= EXACT_TOL * want, "band {c}: {} vs {want}", num(row, 9 + c));
    }

    // groups.csv: one row per prototype holding polygons, the sums of its rows.
    let groups = std::fs::read_to_string(out.join("groups.csv")).unwrap();
    let mut glines = groups.lines();
    assert_eq!(glines.next(), Some("group,area,absorbed_PAR,absorbed_NIR"));
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["bands"], serde_json::json!(["PAR", "NIR"]));
    let mut total = [0.0; 2];
    for g in glines {
        let g: Vec<String> = g.split(',').map(str::to_owned).collect();
        let mine: Vec<&Vec<String>> = rows.iter().filter(|r| r[1] == g[0]).collect();
        assert!(!mine.is_empty(), "group {} has rows", g[0]);
        for (k, col) in [(1, 3), (2, 9), (3, 10)] {
            let sum: f64 = mine.iter().map(|r| num(r, col)).sum();
            assert!((num(&g, k) - sum).abs() <= 1e-9 * sum.abs().max(1e-300), "group {} column {k}: {} vs {sum}", g[0], g[k]);
        }
        total[0] += num(&g, 2);
        total[1] += num(&g, 3);
    }
    for (c, band) in ["PAR", "NIR"].into_iter().enumerate() {
        let reported = stats["absorbed_by_band"][band].as_f64().unwrap();
        assert!((reported - total[c]).abs() <= 1e-9 * total[c], "{band}: {reported} vs {}", total[c]);
    }
    // The black ground absorbs what reaches it: more than the cube and quad together.
    assert!(total[0] > 100.0 * 50.0, "PAR absorbed {}", total[0]);
    // The balance: the incident power is the 10 × 10 ground's E·A, give or take what the cube and
    // the quad catch beyond their shadows (0.13% measured); absorbed and escaped add up to it.
    for (c, band) in ["PAR", "NIR"].into_iter().enumerate() {
        let p = &stats["power_by_band"][band];
        let incident = p["incident"].as_f64().unwrap();
        assert!((incident / (100.0 * e[c]) - 1.0).abs() < 0.005, "{band}: incident {incident} vs {}", 100.0 * e[c]);
        let balance = (p["absorbed"].as_f64().unwrap() + p["escaped"].as_f64().unwrap()) / incident;
        assert!((balance - 1.0).abs() < INSTANCED_BALANCE_TOL, "{band}: balance {balance}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The plant scientist's two commands: `generate tree --daylight` and `solve` give absorbed PAR
/// and NIR per leaf side and per prototype, with the balance closed; a bad `--ground-tile` is one
/// line.
#[test]
fn generated_tree_under_daylight_reports_absorbed_par_and_nir() {
    let dir = std::env::temp_dir().join(format!("radiosity-generated-daylight-{}", std::process::id()));
    let bin = env!("CARGO_BIN_EXE_radiosity");
    let run = |args: &[&str]| Command::new(bin).args(args).output().expect("the binary runs");
    let tree = dir.join("tree");
    let g = run(&["generate", "tree", "--age", "3", "--daylight", "-o", tree.to_str().unwrap()]);
    assert!(g.status.success(), "{}", String::from_utf8_lossy(&g.stderr));
    let out = dir.join("out");
    let s = run(&["solve", tree.join("tree.toml").to_str().unwrap(), "-o", out.to_str().unwrap(), "--no-image", "--quiet"]);
    assert!(s.status.success(), "{}", String::from_utf8_lossy(&s.stderr));
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["bands"], serde_json::json!(["PAR", "NIR"]));
    assert!(stats["local_solves"].as_u64().unwrap() > 1, "solved instanced");
    for band in ["PAR", "NIR"] {
        let p = &stats["power_by_band"][band];
        let balance = (p["absorbed"].as_f64().unwrap() + p["escaped"].as_f64().unwrap()) / p["incident"].as_f64().unwrap();
        assert!((balance - 1.0).abs() < INSTANCED_BALANCE_TOL, "{band}: balance {balance}");
    }
    let patches = std::fs::read_to_string(out.join("patches.csv")).unwrap();
    let header: Vec<&str> = patches.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let (mat, par, nir) = (col("material"), col("absorbed_PAR"), col("absorbed_NIR"));
    let leaves: Vec<Vec<&str>> = patches.lines().skip(1).map(|l| l.split(',').collect::<Vec<_>>()).filter(|r| r[mat] == "leaf").collect();
    assert!(leaves.len() > 100 && leaves.len().is_multiple_of(2), "{} leaf sides", leaves.len());
    // Leaves absorb most of the PAR and scatter most of the NIR that reaches them.
    let sum = |k: usize| leaves.iter().map(|r| r[k].parse::<f64>().unwrap()).sum::<f64>();
    assert!(sum(par) > 2.0 * sum(nir), "leaves absorbed PAR {} NIR {}", sum(par), sum(nir));
    let groups = std::fs::read_to_string(out.join("groups.csv")).unwrap();
    assert!(groups.starts_with("group,area,absorbed_PAR,absorbed_NIR\n") && groups.lines().count() > 3, "{groups}");
    // The ground came in tiles of at most 0.5 m.
    let grounds = patches.lines().skip(1).filter(|l| l.split(',').nth(mat) == Some("ground")).count();
    assert!(grounds >= 16, "{grounds} ground tiles");
    let bad = run(&["generate", "tree", "--age", "3", "--daylight", "--ground-tile", "0", "-o", tree.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success() && err.trim().lines().count() == 1 && err.contains("--ground-tile"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A generated lamp-lit tree turned into a daylight scene by hand, as a user would: two bands
/// with optics per band, a sun and a sky, the ground left in one piece, and the lamps kept with no
/// emission (black, one-sided, their backs to the sky). The light landing on the lamps' backs
/// (from the sun and sky, and from the tree and ground below) is blocked there: it is counted as
/// lost at backs, the balance closes within [`HAND_WRITTEN_BALANCE_TOL`] with it in each band, and
/// a warning names the share and the one-sided materials. Before (2026-12-06) the balance read
/// 0.549 / 0.548 and the lost light was in no figure.
#[test]
fn a_hand_written_daylight_tree_balances_and_names_the_light_lost_at_backs() {
    let dir = std::env::temp_dir().join(format!("radiosity-hand-daylight-{}", std::process::id()));
    let bin = env!("CARGO_BIN_EXE_radiosity");
    let run = |args: &[&str]| Command::new(bin).args(args).output().expect("the binary runs");
    let tree = dir.join("tree");
    let g = run(&["generate", "tree", "--age", "3", "-o", tree.to_str().unwrap()]);
    assert!(g.status.success(), "{}", String::from_utf8_lossy(&g.stderr));
    let path = tree.join("tree.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut edited = String::new();
    let mut material = "";
    for line in text.lines() {
        if let Some(name) = line.strip_prefix("name = ") {
            material = if name.contains("bark") {
                "bark"
            } else if name.contains("leaf") {
                "leaf"
            } else if name.contains("ground") {
                "ground"
            } else if name.contains("light") {
                "light"
            } else {
                ""
            };
        }
        let replaced = match (material, line.split(" = ").next()) {
            ("bark", Some("reflectance")) => "reflectance = [0.15, 0.35]",
            ("leaf", Some("reflectance")) => "reflectance = [0.10, 0.45]",
            ("leaf", Some("transmittance")) => "transmittance = [0.05, 0.40]",
            ("ground", Some("reflectance")) => "reflectance = [0.10, 0.25]",
            ("light", Some("reflectance")) => "reflectance = [0.0, 0.0]",
            ("light", Some("emission")) => "emission = [0.0, 0.0]",
            _ => line,
        };
        edited.push_str(replaced);
        edited.push('\n');
        if line.starts_with("root = ") {
            edited.push_str("bands = [\"PAR\", \"NIR\"]\n");
        }
    }
    edited.push_str(
        "\n[sun]\nlatitude = 43.61\nlongitude = 3.88\ntime = \"2026-06-21T12:00:00+02:00\"\ndirect_normal = [400.0, 380.0]\n\n\
         [sky]\nmodel = \"cie-overcast\"\ndiffuse_horizontal = [100.0, 90.0]\ndirections = 145\n",
    );
    assert_eq!(edited.matches("[0.0, 0.0]").count(), 2, "the lamps made black and dark:\n{edited}");
    std::fs::write(&path, edited).unwrap();
    let out = dir.join("out");
    let s = run(&["solve", path.to_str().unwrap(), "-o", out.to_str().unwrap(), "--no-image", "--quiet"]);
    assert!(s.status.success(), "{}", String::from_utf8_lossy(&s.stderr));
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap();
    assert!(stats["local_solves"].as_u64().unwrap() > 1, "solved instanced");
    for band in ["PAR", "NIR"] {
        let p = &stats["power_by_band"][band];
        let (incident, absorbed, escaped, lost) = (
            p["incident"].as_f64().unwrap(),
            p["absorbed"].as_f64().unwrap(),
            p["escaped"].as_f64().unwrap(),
            p["lost_at_backs"].as_f64().unwrap(),
        );
        // The lamps' backs take a good share of the sky (three 2 m squares over the tree).
        assert!(lost > 0.1 * incident, "{band}: lost at backs {lost} of {incident}");
        let balance = (absorbed + escaped + lost) / incident;
        assert!((balance - 1.0).abs() <= HAND_WRITTEN_BALANCE_TOL, "{band}: balance {balance}");
    }
    let warnings = stats["solve_warnings"].as_array().expect("a warning");
    assert!(
        warnings.iter().any(|w| w.as_str().is_some_and(|w| w.contains("back of one-sided faces") && w.contains("`light`"))),
        "{warnings:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// How closely a user's hand-written daylight scene balances in each band (issue: 0.5%).
const HAND_WRITTEN_BALANCE_TOL: f64 = 5e-3;

/// Where the instanced solve departs from the flattened one, by material and side (run by hand).
#[test]
#[ignore = "diagnostic"]
fn diagnose_by_material() {
    let trees: u32 = std::env::var("TREES").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let mut scene = generate_forest(&ForestParams { trees, min_age: 3, max_age: 4, spacing: 3.0, ..ForestParams::default() });
    let root = scene.root as usize;
    let lamps = std::env::var("LAMPS").is_ok();
    if !lamps {
        scene.prototypes[root].polygons.truncate(1);
    }
    if std::env::var("BLACKGROUND").is_ok() {
        let g = scene.find_material("ground").unwrap() as usize;
        scene.materials[g].reflectance = [0.0; 3];
    }
    let cells: u32 = std::env::var("CELLS").ok().and_then(|s| s.parse().ok()).unwrap_or(46);
    let mut sources = daylight_sources(cells);
    if std::env::var("NOSKY").is_ok() {
        sources.truncate(1);
    }
    if std::env::var("NOSUN").is_ok() {
        sources.remove(0);
    }
    let c = config(if lamps { Vec::new() } else { sources });
    let (full, _) = solve_full(&scene, &c).unwrap();
    let mut inst = PolygonMeans::default();
    let _ = solve_instanced(&scene, &c, &mut inst).unwrap();
    let flat = instancing::flatten(&scene, &instancing::FlattenOptions { two_sided_pairs: true }).unwrap();
    let (worst, mean) = relative_error(&full, &inst);
    eprintln!("{} polygons: max {:.3}% mean {:.3}%", flat.polygons.len(), 100.0 * worst, 100.0 * mean);
    let mut sums: std::collections::BTreeMap<String, (f64, f64, f64, usize)> = Default::default();
    let mut prev_leaf = false;
    for (i, p) in flat.polygons.iter().enumerate() {
        let m = &flat.materials[p.material as usize];
        let side = if m.two_sided { if prev_leaf { "back" } else { "front" } } else { "" };
        prev_leaf = m.two_sided && !prev_leaf;
        let a = p.poly.area();
        let e = sums.entry(format!("{} {side}", m.name)).or_default();
        e.0 += a * full.radiosity[i][1];
        e.1 += a * inst.radiosity[i][1];
        e.2 += a * (full.radiosity[i][1] - inst.radiosity[i][1]).abs();
        e.3 += 1;
    }
    for (k, (f, s, d, n)) in &sums {
        eprintln!("{k}: {n} polygons, full {f:.4e} instanced {s:.4e} (ratio {:.4}), mean |diff| / mean {:.4}", s / f, d / f);
    }
}

/// The sun's direct light on each kind of polygon: the plain solve's (its elements' quadrature),
/// brute force through the flattened scene's caster and through the nested BVHs (run by hand).
#[test]
#[ignore = "diagnostic"]
fn diagnose_direct_sun() {
    use radiosity_core::visibility::{RayCaster, Rng};
    let mut scene = generate_forest(&ForestParams { trees: 1, min_age: 3, max_age: 4, spacing: 3.0, ..ForestParams::default() });
    let root = scene.root as usize;
    scene.prototypes[root].polygons.truncate(1);
    let sources = daylight_sources(46)[..1].to_vec();
    let c = config(sources.clone());
    let mut flat = instancing::flatten(&scene, &instancing::FlattenOptions { two_sided_pairs: true }).unwrap();
    flat.distant = sources.clone();
    let b_ref = instancing::solver::daylight_brightest(&flat.materials, &sources);
    let solved = radiosity_core::pipeline::run(
        &flat,
        &radiosity_core::refine::ClassicBf { eps: c.bf.eps, b_ref },
        &radiosity_core::pipeline::Config { levels: 1, estimate_error: false, detect_closure: false, ..c.pipeline },
        &|_| {},
    );
    let caster = RayCaster::new(&flat);
    let nested = instancing::InstanceCaster::new(&scene);
    let diag = flat.bounds().diagonal();
    let light = daylight::DistantLight::new(&sources, Some(&caster), diag);
    let mut sums: std::collections::BTreeMap<String, [f64; 4]> = Default::default();
    for (i, p) in flat.polygons.iter().enumerate() {
        let m = &flat.materials[p.material as usize];
        let n = p.poly.normal();
        let mut rng = Rng::for_link(9, i as u32, 0);
        let (mut plain, mut nest) = (0.0, 0.0);
        const N: usize = 256;
        for _ in 0..N {
            let x = p.poly.sample(rng.next_f64(), rng.next_f64());
            plain += light.at(x, n, i as u32)[1];
            let e = sources[0].on(n)[1];
            if e > 0.0 {
                let a = x + n * 1e-5 * diag;
                if nested.segment_clear(a, a - sources[0].toward * 1.01 * diag) {
                    nest += e;
                }
            }
        }
        let a = p.poly.area();
        let s = sums.entry(m.name.clone()).or_default();
        s[0] += a * solved.hierarchy.direct[i][1];
        s[1] += a * plain / N as f64;
        s[2] += a * nest / N as f64;
        s[3] += a;
    }
    for (k, s) in &sums {
        eprintln!("{k}: plain solve {:.4e}, brute force flat {:.4e}, nested {:.4e} (area {:.3e})", s[0], s[1], s[2], s[3]);
    }
}
