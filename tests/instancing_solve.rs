//! The instanced solver and prototype properties (issue 5, "Tests"): a scene without instances
//! solves exactly as the plain solver does, a box of 8 instanced cubes stays within a stated error
//! of the full solve, prototype properties match known values, and the cache follows the geometry.

use radiosity_core::instancing::properties::{self, CacheOutcome, PhaseMethod, PropertyCache, PropertyConfig, content_hashes};
use radiosity_core::instancing::solver::relative_error;
use radiosity_core::instancing::{self, InstancedConfig, PolygonMeans, solve_full, solve_instanced};
use std::path::Path;

/// Same scene, same solver: the instanced path must reproduce the plain one to rounding.
const SAME_ANSWER_TOL: f64 = 1e-12;
/// Stated bound for the 8-cube box: area-weighted mean error per polygon, relative to the largest
/// radiosity of the full solve.
const EIGHT_CUBES_MEAN_TOL: f64 = 0.02;
/// Stated bound for the 8-cube box: largest error of any polygon, relative to the same.
const EIGHT_CUBES_MAX_TOL: f64 = 0.10;
/// Relative change of a value stored as JSON text and read back.
const JSON_TOL: f64 = 1e-14;
/// Energy: escape albedo of a prototype against its exact value (issue: within 2%).
const ALBEDO_TOL: f64 = 0.02;

fn parse(text: &str) -> instancing::InstancedScene {
    instancing::parse(text, Path::new("test.toml"), Path::new(".")).unwrap()
}

const ROOM: &str = r#"
[[material]]
name = "wall"
reflectance = 0.5
[[material]]
name = "cube"
reflectance = [0.7, 0.5, 0.3]
[[material]]
name = "light"
reflectance = 0.0
emission = 10.0

[[box]]
min = [0, 0, 0]
max = [4, 4, 4]
material = "wall"
inward = true

[[polygon]]
material = "light"
vertices = [[1.5, 1.5, 3.99], [1.5, 2.5, 3.99], [2.5, 2.5, 3.99], [2.5, 1.5, 3.99]]
"#;

fn config() -> InstancedConfig {
    InstancedConfig {
        properties: PropertyConfig { n_directions: 16, rays_per_direction: 400, ..PropertyConfig::default() },
        ..InstancedConfig::default()
    }
}

#[test]
fn scene_without_instances_gives_the_plain_answer() {
    let scene = parse(&format!("{ROOM}\n[[box]]\nmin = [1, 1, 0]\nmax = [2, 2, 1]\nmaterial = \"cube\"\n"));
    let c = config();
    let (full, _) = solve_full(&scene, &c).unwrap();
    let mut inst = PolygonMeans::default();
    let stats = solve_instanced(&scene, &c, &mut inst).unwrap();
    assert_eq!(stats.local_solves, 1);
    assert_eq!(inst.radiosity.len(), full.radiosity.len());
    let (worst, _) = relative_error(&full, &inst);
    assert!(worst <= SAME_ANSWER_TOL, "instanced vs plain without instances: {worst:e}");
}

fn eight_cubes() -> String {
    let mut s = String::from(ROOM);
    s.push_str("\n[[prototype]]\nname = \"cube\"\n[[prototype.box]]\nmin = [0, 0, 0]\nmax = [0.4, 0.4, 0.4]\nmaterial = \"cube\"\n");
    for k in 0..8 {
        let (x, y, z) = (0.8 + 2.0 * (k & 1) as f64, 0.8 + 2.0 * ((k >> 1) & 1) as f64, 0.6 + 1.6 * ((k >> 2) & 1) as f64);
        s.push_str(&format!("\n[[instance]]\nof = \"cube\"\ntranslate = [{x}, {y}, {z}]\nrotate = [0, 0, {}]\n", 10 * k));
    }
    s
}

#[test]
fn eight_instanced_cubes_match_the_full_solve() {
    let scene = parse(&eight_cubes());
    let c = config();
    let (full, _) = solve_full(&scene, &c).unwrap();
    let mut inst = PolygonMeans::default();
    let stats = solve_instanced(&scene, &c, &mut inst).unwrap();
    assert_eq!(stats.local_solves, 9, "the room, then each cube opened once");
    assert_eq!(stats.polygons_out as usize, full.radiosity.len());
    let (worst, mean) = relative_error(&full, &inst);
    eprintln!("8 cubes: max error {:.3}%, mean error {:.3}% of max radiosity", 100.0 * worst, 100.0 * mean);
    assert!(mean <= EIGHT_CUBES_MEAN_TOL, "mean error {mean}");
    assert!(worst <= EIGHT_CUBES_MAX_TOL, "max error {worst}");
}

fn cube_scene(size: f64) -> instancing::InstancedScene {
    parse(&format!(
        "[[material]]\nname = \"c\"\nreflectance = 0.5\n[[prototype]]\nname = \"cube\"\n[[prototype.box]]\nmin = [0, 0, 0]\nmax = [{size}, 1, 1]\nmaterial = \"c\"\n[[instance]]\nof = \"cube\"\n"
    ))
}

#[test]
fn convex_prototype_reflects_its_reflectance() {
    // A convex object re-emits exactly ρ of what it intercepts, and transmits nothing.
    let scene = cube_scene(1.0);
    let id = scene.find("cube").unwrap();
    for method in [PhaseMethod::RandomWalk, PhaseMethod::Radiosity { eps: 0.01 }] {
        let config = PropertyConfig { n_directions: 8, rays_per_direction: 1600, method, ..PropertyConfig::default() };
        let p = properties::compute(&scene, id, &config).unwrap();
        for (k, tau) in p.transmittance.iter().enumerate() {
            assert!(*tau < 0.01, "{method:?}: τ = {tau} in direction {k}");
            assert!((p.effective_area[k] - p.box_area[k]).abs() <= 0.01 * p.box_area[k]);
        }
        let albedo = p.mean_albedo();
        assert!((albedo[0] - 0.5).abs() <= ALBEDO_TOL, "{method:?}: albedo {albedo:?}, expected 0.5");
    }
}

#[test]
fn leaf_reflects_and_transmits() {
    // One two-sided leaf: every intercepted ray is reflected (ρ) or transmitted (t) once, then escapes.
    let scene = parse(
        "[[material]]\nname = \"leaf\"\nreflectance = 0.3\ntransmittance = 0.2\n[[prototype]]\nname = \"leaf\"\n[[prototype.polygon]]\nmaterial = \"leaf\"\nvertices = [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]\n[[instance]]\nof = \"leaf\"\n",
    );
    let config = PropertyConfig { n_directions: 8, rays_per_direction: 1600, ..PropertyConfig::default() };
    let p = properties::compute(&scene, scene.find("leaf").unwrap(), &config).unwrap();
    let albedo = p.mean_albedo();
    assert!((albedo[1] - 0.5).abs() <= ALBEDO_TOL, "albedo {albedo:?}, expected ρ + t = 0.5");
    assert!(p.mean_transmittance() < 0.01, "a flat leaf covers its own flat box: {:?}", p.transmittance);
}

#[test]
fn changing_a_prototype_invalidates_its_cache_entry() {
    let dir = tempfile::tempdir().unwrap();
    let cache = PropertyCache::new(dir.path());
    let config = PropertyConfig { n_directions: 4, rays_per_direction: 64, ..PropertyConfig::default() };
    let scene = cube_scene(1.0);
    let id = scene.find("cube").unwrap();
    let (first, o1) = cache.get_or_compute(&scene, &content_hashes(&scene), id, &config).unwrap();
    let (again, o2) = cache.get_or_compute(&scene, &content_hashes(&scene), id, &config).unwrap();
    assert_eq!((o1, o2), (CacheOutcome::Computed, CacheOutcome::Hit));
    assert_eq!(first.key, again.key);
    for (a, b) in first.albedo.iter().zip(&again.albedo) {
        assert!((a[0] - b[0]).abs() <= JSON_TOL * a[0].abs(), "a hit returns what was stored: {a:?} vs {b:?}");
    }
    let longer = cube_scene(2.0);
    let (changed, o3) = cache.get_or_compute(&longer, &content_hashes(&longer), id, &config).unwrap();
    assert_eq!(o3, CacheOutcome::Computed, "new geometry must not read the old entry");
    assert_ne!(changed.key, first.key);
    assert!(changed.box_area.iter().zip(&first.box_area).any(|(a, b)| a > b), "the longer box projects more");
    // A different configuration is a different entry too.
    let finer = PropertyConfig { rays_per_direction: 100, ..config };
    assert_eq!(cache.get_or_compute(&scene, &content_hashes(&scene), id, &finer).unwrap().1, CacheOutcome::Computed);
}

#[test]
fn streamed_outputs_hold_every_polygon_and_leaf() {
    let dir = tempfile::tempdir().unwrap();
    let scene = parse(&eight_cubes());
    let mut sink = instancing::StreamedOutput::create(dir.path(), &scene).unwrap();
    let stats = solve_instanced(&scene, &config(), &mut sink).unwrap();
    let render = radiosity_core::output::RenderConfig { width: 64, height: 48, samples: 2 };
    let summary = sink.finish(Some(&render)).unwrap();
    assert_eq!(summary.leaves, stats.leaves_out);
    // PLY: the header's counts match the streamed leaves and the body's size.
    let bytes = std::fs::read(dir.path().join("solution.ply")).unwrap();
    let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let count = |key: &str| -> u64 { header.lines().find_map(|l| l.strip_prefix(key)).unwrap().trim().parse().unwrap() };
    let (n_vertices, n_faces) = (count("element vertex "), count("element face "));
    assert_eq!(n_faces, stats.leaves_out);
    // 27 bytes a vertex; a face is its count byte and 4-byte indices.
    assert_eq!((bytes.len() - end) as u64, 27 * n_vertices + n_faces + 4 * n_vertices);
    // patches.csv: a row per flattened polygon, every index once.
    let csv = std::fs::read_to_string(dir.path().join("patches.csv")).unwrap();
    let mut rows: Vec<u64> = csv.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    assert_eq!(rows.len() as u64, stats.polygons_out);
    rows.sort_unstable();
    rows.dedup();
    assert_eq!(rows.len() as u64, stats.polygons_out);
    // The image shows something lit, and the spool is gone.
    let img = image::open(dir.path().join("image.png")).unwrap().to_rgb8();
    assert_eq!((img.width(), img.height()), (64, 48));
    assert!(img.pixels().any(|p| p.0.iter().any(|&c| c > 0)), "image is black");
    assert!(!dir.path().join("solution.spool").exists());
    // solution.glb: the PLY's vertices as triangle fans (issue 17), and no temporary file left.
    let glb = std::fs::read(dir.path().join("solution.glb")).unwrap();
    let gltf = gltf::Gltf::from_slice(&glb).unwrap();
    let blob = gltf.blob.clone().unwrap();
    let prim = gltf.meshes().next().unwrap().primitives().next().unwrap();
    let reader = prim.reader(|_| Some(&blob));
    assert_eq!(reader.read_positions().unwrap().count() as u64, n_vertices);
    assert_eq!(reader.read_colors(0).unwrap().into_rgb_f32().count() as u64, n_vertices);
    assert_eq!(reader.read_indices().unwrap().into_u32().count() as u64, 3 * (n_vertices - 2 * n_faces));
    let hidden: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "temporary files left: {hidden:?}");
}

/// Reused vs freshly refined levels (fractions of the largest radiosity): the two differ where a
/// beam's direction falls to another table direction in the reused level's frame, and where a fresh
/// level refined for another instance's class top subdivides differently (measured: max 0.39%,
/// mean 8e-6).
const REUSE_MAX_TOL: f64 = 0.01;
const REUSE_MEAN_TOL: f64 = 1e-4;

#[test]
fn reused_levels_give_the_answer_of_fresh_ones() {
    // An L of two boxes (faces that see each other, so a level has links of its own), placed eight
    // times, turned about z and about x, at two scales.
    let mut s = String::from(ROOM);
    s.push_str("\n[[prototype]]\nname = \"ell\"\n[[prototype.box]]\nmin = [0, 0, 0]\nmax = [0.4, 0.1, 0.1]\nmaterial = \"cube\"\n");
    s.push_str("[[prototype.box]]\nmin = [0, 0.1, 0]\nmax = [0.1, 0.4, 0.1]\nmaterial = \"cube\"\n");
    for k in 0..8 {
        let (x, y, z) = (0.8 + 2.0 * (k & 1) as f64, 0.8 + 2.0 * ((k >> 1) & 1) as f64, 0.6 + 1.6 * ((k >> 2) & 1) as f64);
        let scale = if k % 3 == 0 { 1.5 } else { 1.0 };
        s.push_str(&format!(
            "\n[[instance]]\nof = \"ell\"\ntranslate = [{x}, {y}, {z}]\nrotate = [{}, 0, {}]\nscale = {scale}\n",
            5 * k,
            37 * k
        ));
    }
    let scene = parse(&s);
    let cached = config();
    let mut fresh = config();
    fresh.level_cache_bytes = 0;
    let (mut a, mut b) = (PolygonMeans::default(), PolygonMeans::default());
    let sa = solve_instanced(&scene, &cached, &mut a).unwrap();
    let sb = solve_instanced(&scene, &fresh, &mut b).unwrap();
    assert_eq!(sb.levels_reused, 0);
    assert!(sa.levels_reused >= 4, "levels reused: {}", sa.levels_reused);
    let (worst, mean) = relative_error(&b, &a);
    eprintln!("reused vs fresh: {} of 8 reused, max {worst:e}, mean {mean:e} of max radiosity", sa.levels_reused);
    assert!(worst <= REUSE_MAX_TOL, "reused vs fresh levels: max difference {worst:e}");
    assert!(mean <= REUSE_MEAN_TOL, "reused vs fresh levels: mean difference {mean:e}");
}

/// Policy `none` vs the full solve: the same problem up to rounding in how the instance transforms
/// are composed, which can flip a refinement decision (measured 3.4e-4 of the largest radiosity).
const POLICY_NONE_TOL: f64 = 1e-3;

#[test]
fn instance_level_policy_none_opens_everything_and_gives_the_full_answer() {
    use radiosity_core::instancing::InstanceLevels;
    let scene = parse(&eight_cubes());
    let c = InstancedConfig { instance_levels: InstanceLevels::None, ..config() };
    let (full, _) = solve_full(&scene, &c).unwrap();
    let mut inst = PolygonMeans::default();
    let stats = solve_instanced(&scene, &c, &mut inst).unwrap();
    assert_eq!(stats.local_solves, 1, "one flattened problem");
    let (worst, _) = relative_error(&full, &inst);
    assert!(worst <= POLICY_NONE_TOL, "policy none vs full: {worst:e}");
    // Depth 1 is not a multiple of 2: every-2 opens the cubes too; every-1 is all.
    let mut two = PolygonMeans::default();
    let s2 = solve_instanced(&scene, &InstancedConfig { instance_levels: InstanceLevels::Every(2), ..config() }, &mut two).unwrap();
    assert_eq!(s2.local_solves, 1);
    let s1 =
        solve_instanced(&scene, &InstancedConfig { instance_levels: InstanceLevels::Every(1), ..config() }, &mut PolygonMeans::default())
            .unwrap();
    assert_eq!(s1.local_solves, 9);
    assert_eq!("every-3".parse::<InstanceLevels>(), Ok(InstanceLevels::Every(3)));
    assert!("every-0".parse::<InstanceLevels>().is_err() && "some".parse::<InstanceLevels>().is_err());
}

#[test]
fn instances_too_close_to_each_other_are_opened_when_asked() {
    // Two cubes of 0.4 m, 0.1 m apart along x: their boxes share 75% of their volume.
    let mut s = String::from(ROOM);
    s.push_str("\n[[prototype]]\nname = \"cube\"\n[[prototype.box]]\nmin = [0, 0, 0]\nmax = [0.4, 0.4, 0.4]\nmaterial = \"cube\"\n");
    for x in [1.0, 1.1] {
        s.push_str(&format!("\n[[instance]]\nof = \"cube\"\ntranslate = [{x}, 1.5, 1.0]\n"));
    }
    let scene = parse(&s);
    let apart = solve_instanced(&scene, &config(), &mut PolygonMeans::default()).unwrap();
    assert_eq!(apart.local_solves, 3, "by default both stay closed");
    let close = InstancedConfig { open_overlap: 0.5, ..config() };
    let opened = solve_instanced(&scene, &close, &mut PolygonMeans::default()).unwrap();
    assert_eq!(opened.local_solves, 1, "both opened in place");
    let loose = InstancedConfig { open_overlap: 0.8, ..config() };
    assert_eq!(solve_instanced(&scene, &loose, &mut PolygonMeans::default()).unwrap().local_solves, 3, "75% is under 0.8");
}

/// Stated bound for the shadowed slab: its radiosity against the full solve's, relative to the
/// largest radiosity of the full solve.
const CROSSED_BOX_TOL: f64 = 0.005;

/// A plate of the room passes through a closed instance's box, above the instance's slab: the slab
/// is in its shadow. The instance's own level does not hold the plate, so the beams from outside
/// must be tested against it (inherited occluders). Measured: full 0.26%, instanced 0.20% of the
/// largest radiosity; lit as if the plate were not there, the instanced slab top came out at 2.2%.
#[test]
fn a_box_crossed_by_the_level_above_is_shadowed_by_it() {
    let mut s = String::from(ROOM);
    s.push_str(concat!(
        "\n[[prototype]]\nname = \"slab\"\n",
        "[[prototype.box]]\nmin = [0, 0, 0]\nmax = [1, 1, 0.05]\nmaterial = \"cube\"\n",
        "[[prototype.box]]\nmin = [0.45, 0.45, 0.05]\nmax = [0.55, 0.55, 1]\nmaterial = \"cube\"\n",
        "\n[[instance]]\nof = \"slab\"\ntranslate = [1.5, 1.5, 0.5]\n",
        "\n[[box]]\nmin = [1.2, 1.2, 1.1]\nmax = [2.8, 2.8, 1.12]\nmaterial = \"wall\"\n",
    ));
    let scene = parse(&s);
    let c = config();
    let (full, _) = solve_full(&scene, &c).unwrap();
    let mut inst = PolygonMeans::default();
    let stats = solve_instanced(&scene, &c, &mut inst).unwrap();
    assert_eq!(stats.local_solves, 2, "the room, then the slab opened once");
    let max = full.radiosity.iter().flat_map(|b| b.iter().copied()).fold(0.0, f64::max);
    // The slab's top face, found among the flattened polygons by its height (z = 0.55).
    let flat = instancing::flatten(&scene, &instancing::FlattenOptions { two_sided_pairs: true }).unwrap();
    let top = (0..flat.polygons.len())
        .find(|&i| {
            let p = &flat.polygons[i].poly;
            p.normal().z > 0.99 && (p.centroid().z - 0.55).abs() < 1e-9 && p.area() > 0.5
        })
        .expect("the slab's top face");
    let (f, g) = (full.radiosity[top], inst.radiosity[top]);
    eprintln!("slab top: full {:.4}, instanced {:.4} of max", f[1] / max, g[1] / max);
    for ch in 0..3 {
        assert!((f[ch] - g[ch]).abs() <= CROSSED_BOX_TOL * max, "channel {ch}: full {} vs instanced {} (max {max})", f[ch], g[ch]);
    }
}
