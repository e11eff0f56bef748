//! Sun and sky through the whole command: scene files with `[sun]`, `[sky]` and `bands`, the power
//! balance of open scenes, and the outputs per band.

use std::path::Path;
use std::process::{Command, Output};

/// The power balance `(absorbed + escaped) / incident` of an open scene, measured independently of
/// the links (the escape is ray cast), must close within this.
const BALANCE_TOL: f64 = 0.005;
/// Two packs with the same values agree to the linear solve's convergence (its iterations stop on
/// the largest residual over a pack's three channels, so packs whose third channels differ stop
/// at slightly different iterates).
const PACK_TOL: f64 = 1e-9;
/// Two packs with the same values, refined each on its own light: a pack's links are decided on
/// the brightest of its three channels, so packs with different third channels get different
/// meshes, and their powers agree within the balance tolerance of the band's incident light
/// (measured 0.09% of it on the incident light, whose direct part is integrated over each mesh's
/// elements, and 0.27% on the escaped light).
const CROSS_PACK_TOL: f64 = BALANCE_TOL;
/// Exact cases (an unobstructed plane) agree to rounding.
const EXACT_TOL: f64 = 1e-9;
/// A luminaire's light on a room's surfaces, integrated by the leaves' quadrature (an isotropic
/// lamp in a black room: measured 1e-7 of the closed form).
const LAMP_ONTO_TOL: f64 = 1e-4;
/// The 145-cell sky's light through a roof opening at a calculation point, against the continuous
/// sky (each cell the point sees in part sampled ray by ray; measured 0.05-1.6% at three floor
/// points, up to 1.8% over a 10 x 10 floor grid; 60% off before, the cells seen or hidden whole).
const SKY_THROUGH_OPENING_REL_TOL: f64 = 0.03;
/// A luminaire's illuminance at a calculation point, against the inverse-square law.
const LAMP_POINT_TOL: f64 = 1e-6;

fn run_cli(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).current_dir(dir).output().expect("the binary runs")
}

fn solve(dir: &Path, scene: &str) -> serde_json::Value {
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    let out = run_cli(dir, &["solve", "scene.toml", "--quiet", "--no-image", "--out", "out"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_str(&std::fs::read_to_string(dir.join("out/stats.json")).unwrap()).unwrap()
}

fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(str::to_owned).collect();
    (header, lines.map(|l| l.split(',').map(str::to_owned).collect()).collect())
}

fn column(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

const GROUND: &str = r#"
[[material]]
name = "ground"
reflectance = 0.3
[[polygon]]
material = "ground"
vertices = [[-5,-5,0],[5,-5,0],[5,5,0],[-5,5,0]]
"#;

#[test]
fn an_open_plane_gets_exactly_the_sun_and_sky_and_reflects_its_share_away() {
    // Sun 60 degrees from the zenith (cos 0.5): E = 800 * 0.5 + 100 = 500 W/m2 on 100 m2.
    let dir = tempfile::tempdir().unwrap();
    let s = solve(
        dir.path(),
        &format!(
            "{GROUND}\n[sun]\ndirection = [{}, 0.0, -0.5]\ndirect_normal = 800\n[sky]\nmodel = \"cie-overcast\"\ndiffuse_horizontal = 100\ndirections = 46\n",
            0.75f64.sqrt()
        ),
    );
    let incident = s["power_incident"].as_f64().unwrap();
    assert!((incident - 50_000.0).abs() < EXACT_TOL * 50_000.0, "incident {incident}");
    let absorbed = s["power_absorbed"].as_f64().unwrap();
    assert!((absorbed - 0.7 * 50_000.0).abs() < EXACT_TOL * 50_000.0, "absorbed {absorbed}");
    // Everything reflected leaves (nothing above the plane).
    let escaped = s["power_escaped"].as_f64().unwrap();
    assert!((escaped - 0.3 * 50_000.0).abs() < EXACT_TOL * 50_000.0, "escaped {escaped}");
    assert!((s["power_balance"].as_f64().unwrap() - 1.0).abs() < EXACT_TOL);
    let sun = &s["sun"];
    assert!((sun["zenith_deg"].as_f64().unwrap() - 60.0).abs() < 1e-9, "{sun}");
    let (header, rows) = csv(&dir.path().join("out/patches.csv"));
    let h = rows[0][column(&header, "h_g")].parse::<f64>().unwrap();
    assert!((h - 500.0).abs() < EXACT_TOL * 500.0, "irradiance {h}");
}

/// A leaf layer over a grey ground with a wall: shadows, interreflection, transmission, two bands.
const SHADED: &str = r#"
bands = ["PAR", "NIR"]
[[material]]
name = "ground"
reflectance = [0.1, 0.3]
[[material]]
name = "wall"
reflectance = [0.5, 0.6]
[[material]]
name = "leaf"
reflectance = [0.10, 0.45]
transmittance = [0.05, 0.40]
two_sided = true
[[polygon]]
material = "ground"
vertices = [[-5,-5,0],[5,-5,0],[5,5,0],[-5,5,0]]
[[box]]
material = "wall"
min = [2, -3, 0]
max = [2.5, 3, 3]
[[polygon]]
material = "leaf"
vertices = [[-1,-1,1],[1,-1,1.2],[1,1,1.2],[-1,1,1]]
[[polygon]]
material = "leaf"
vertices = [[0,-1,1.6],[1.5,-1,1.9],[1.5,1,1.9],[0,1,1.6]]
[sun]
latitude = 43.6
longitude = 3.9
time = "2026-06-21T12:00:00+02:00"
direct_normal = [400.0, 380.0]
[sky]
model = "cie-overcast"
diffuse_horizontal = [100.0, 90.0]
"#;

#[test]
fn shaded_two_band_scene_balances_and_reports_every_band() {
    let dir = tempfile::tempdir().unwrap();
    let s = solve(dir.path(), SHADED);
    assert_eq!(s["bands"], serde_json::json!(["PAR", "NIR"]));
    let by_band = &s["power_by_band"];
    let mut total_absorbed = 0.0;
    for band in ["PAR", "NIR"] {
        let p = &by_band[band];
        let (inc, abs, esc) = (p["incident"].as_f64().unwrap(), p["absorbed"].as_f64().unwrap(), p["escaped"].as_f64().unwrap());
        assert!(inc > 0.0 && abs > 0.0 && esc > 0.0, "{band}: {p}");
        let balance = (abs + esc) / inc;
        assert!((balance - 1.0).abs() < BALANCE_TOL, "{band}: balance {balance}");
        total_absorbed += abs;
    }
    // Bands are parts of the spectrum: the scalars are sums over bands.
    assert!((s["power_absorbed"].as_f64().unwrap() - total_absorbed).abs() < 1e-9 * total_absorbed);
    // NIR: leaves reflect and transmit much more, so a larger share escapes than in PAR.
    let share = |b: &str| by_band[b]["escaped"].as_f64().unwrap() / by_band[b]["incident"].as_f64().unwrap();
    assert!(share("NIR") > 1.5 * share("PAR"), "escaped shares {} {}", share("PAR"), share("NIR"));
    // patches.csv and groups.csv follow the bands; their absorbed powers add up to stats.json's.
    let (header, rows) = csv(&dir.path().join("out/patches.csv"));
    for name in ["b_PAR", "b_NIR", "h_PAR", "h_NIR", "absorbed_PAR", "absorbed_NIR"] {
        column(&header, name);
    }
    assert!(!header.iter().any(|h| h == "b_r"));
    let par: f64 = rows.iter().map(|r| r[column(&header, "absorbed_PAR")].parse::<f64>().unwrap()).sum();
    let par_stats = by_band["PAR"]["absorbed"].as_f64().unwrap();
    assert!((par - par_stats).abs() < 1e-9 * par_stats, "{par} vs {par_stats}");
    let (gh, grows) = csv(&dir.path().join("out/groups.csv"));
    assert_eq!(gh, ["group", "area", "absorbed_PAR", "absorbed_NIR"]);
    let g: f64 = grows.iter().map(|r| r[2].parse::<f64>().unwrap()).sum();
    assert!((g - par_stats).abs() < 1e-9 * par_stats);
    // A leaf is two rows (its sides); each side absorbs (1 - rho - t) of what reaches it, so the
    // lower leaf's underside absorbs less than its top.
    let leaf_rows: Vec<&Vec<String>> = rows.iter().filter(|r| r[2] == "leaf").collect();
    assert_eq!(leaf_rows.len(), 4);
    let a = |r: &Vec<String>| r[column(&header, "absorbed_PAR")].parse::<f64>().unwrap();
    assert!(a(leaf_rows[0]) > a(leaf_rows[1]), "top {} bottom {}", a(leaf_rows[0]), a(leaf_rows[1]));
}

#[test]
fn four_bands_are_two_solves_that_agree_with_one() {
    // Bands c, d repeat a, b: c (pack 0's third channel) must give a's answer exactly, d (pack 1's
    // first) b's within the solve's error.
    let dir = tempfile::tempdir().unwrap();
    let four = SHADED
        .replace("bands = [\"PAR\", \"NIR\"]", "bands = [\"a\", \"b\", \"c\", \"d\"]")
        .replace("[0.1, 0.3]", "[0.1, 0.3, 0.1, 0.3]")
        .replace("[0.5, 0.6]", "[0.5, 0.6, 0.5, 0.6]")
        .replace("[0.10, 0.45]", "[0.10, 0.45, 0.10, 0.45]")
        .replace("[0.05, 0.40]", "[0.05, 0.40, 0.05, 0.40]")
        .replace("[400.0, 380.0]", "[400.0, 380.0, 400.0, 380.0]")
        .replace("[100.0, 90.0]", "[100.0, 90.0, 100.0, 90.0]");
    let s = solve(dir.path(), &four);
    let p = &s["power_by_band"];
    for (x, y, same_pack) in [("a", "c", true), ("b", "d", false)] {
        let incident = p[x]["incident"].as_f64().unwrap();
        for key in ["incident", "absorbed", "escaped"] {
            let (u, v) = (p[x][key].as_f64().unwrap(), p[y][key].as_f64().unwrap());
            let bound = if same_pack { PACK_TOL * u.abs() } else { CROSS_PACK_TOL * incident };
            assert!((u - v).abs() <= bound, "{x}/{y} {key}: {u} vs {v}");
        }
    }
    let (header, rows) = csv(&dir.path().join("out/patches.csv"));
    for r in &rows {
        let (u, v): (f64, f64) = (r[column(&header, "absorbed_a")].parse().unwrap(), r[column(&header, "absorbed_c")].parse().unwrap());
        assert!((u - v).abs() <= PACK_TOL * u.abs().max(1e-300), "{u} vs {v}");
    }
}

#[test]
fn bad_daylight_input_is_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &str); 14] = [
        (
            "bands = [\"PAR\", \"NIR\"]\n[[material]]\nname = \"m\"\nreflectance = [0.1, 0.2, 0.3]\n",
            "3 values given, the scene has 2 bands",
        ),
        ("bands = [\"PAR\", \"PAR\"]\n", "duplicate band `PAR`"),
        ("bands = [\"PAR\"]\n[[material]]\nname = \"m\"\nreflectance = 0.6\ntransmittance = 0.5\n", "sum below 1"),
        ("[sun]\ndirect_normal = 100\n", "give either `direction`, or `latitude`, `longitude` and `time`"),
        ("[sun]\nlatitude = 43.6\nlongitude = 3.9\ntime = \"tomorrow\"\ndirect_normal = 100\n", "not RFC 3339"),
        ("[sky]\ndiffuse_horizontal = 100\ndirections = 0\n", "sky directions 0"),
        ("[sky]\nmodel = \"cie-general\"\ntype = 12\ndiffuse_horizontal = 100\n", "needs the sun's position"),
        (
            "[sun]\ndirection = [0, 0.5, -0.8]\ndirect_normal = 0\n[sky]\nmodel = \"cie-general\"\ndiffuse_horizontal = 100\n",
            "needs `type` (1 to 15)",
        ),
        (
            "[sun]\ndirection = [0, 0.5, -0.8]\ndirect_normal = 0\n[sky]\nmodel = \"cie-general\"\ntype = 16\ndiffuse_horizontal = 100\n",
            "type 16: give 1 to 15",
        ),
        ("[sky]\nmodel = \"uniform\"\ntype = 3\ndiffuse_horizontal = 100\n", "`type` applies to model = \"cie-general\" only"),
        ("[sky]\nmodel = \"perez\"\nclearness = 3\nbrightness = 0.2\ndiffuse_horizontal = 100\n", "needs the sun's position"),
        (
            "[sun]\ndirection = [0, 0.5, -0.8]\ndirect_normal = 0\n[sky]\nmodel = \"perez\"\nclearness = 3\ndiffuse_horizontal = 100\n",
            "needs `clearness` and `brightness`",
        ),
        (
            "[sun]\ndirection = [0, 0.5, -0.8]\ndirect_normal = 0\n[sky]\nmodel = \"perez\"\nclearness = 0.5\nbrightness = 0.2\ndiffuse_horizontal = 100\n",
            "clearness 0.5 outside the model's range",
        ),
        ("[sky]\nmodel = \"uniform\"\nbrightness = 0.2\ndiffuse_horizontal = 100\n", "apply to model = \"perez\" only"),
    ];
    for (i, (text, expected)) in cases.iter().enumerate() {
        let name = format!("bad{i}.toml");
        std::fs::write(dir.path().join(&name), format!("{text}{GROUND}")).unwrap();
        let out = run_cli(dir.path(), &["solve", &name, "--quiet", "--out", "out"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name} was accepted");
        assert!(err.contains(&name) && err.contains(expected), "{name}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(!err.contains("panicked"));
    }
}

/// An open ground under `sky` (a `[sun]` with no beam and a `[sky]` of 100 W/m² diffuse
/// horizontal) receives the diffuse horizontal irradiance exactly.
fn open_ground_gets_the_diffuse_horizontal_exactly(sky: &str) {
    let dir = tempfile::tempdir().unwrap();
    let s = solve(dir.path(), &format!("{GROUND}{sky}"));
    assert!((s["power_incident"].as_f64().unwrap() - 10_000.0).abs() < EXACT_TOL * 10_000.0, "{}", s["power_incident"]);
    let (header, rows) = csv(&dir.path().join("out/patches.csv"));
    let h = rows[0][column(&header, "h_g")].parse::<f64>().unwrap();
    assert!((h - 100.0).abs() < EXACT_TOL * 100.0, "irradiance {h}");
}

/// A CIE general sky from the scene file (type 12, the standard clear sky, its sun given by
/// `[sun]` with no beam).
#[test]
fn a_cie_general_sky_lights_an_open_ground_exactly() {
    open_ground_gets_the_diffuse_horizontal_exactly(
        "[sun]\ndirection = [0.0, 0.6, -0.8]\ndirect_normal = 0\n[sky]\nmodel = \"cie-general\"\ntype = 12\ndiffuse_horizontal = 100\n",
    );
}

/// A Perez sky from the scene file (clearness 3.2, brightness 0.25, its sun given by `[sun]` with
/// no beam).
#[test]
fn a_perez_sky_lights_an_open_ground_exactly() {
    open_ground_gets_the_diffuse_horizontal_exactly(
        "[sun]\ndirection = [0.0, 0.6, -0.8]\ndirect_normal = 0\n[sky]\nmodel = \"perez\"\nclearness = 3.2\nbrightness = 0.25\ndiffuse_horizontal = 100\n",
    );
}

/// A small tilted square held a metre over a black ground under the sun alone: the ground's mean
/// irradiance is the sun's on it less the shadow, whose area is the square's times
/// `|n_square · t| / |n_ground · t|` (a parallel projection, `t` the sun's direction of travel).
/// The shadow is 0.05% of the ground, smaller than any element the ground would be cut into for
/// its own sake: the sun's light on each element is its exact lit share, not a quadrature that
/// could miss it.
#[test]
fn a_small_shadow_on_a_large_ground_is_exact_at_the_default_settings() {
    let (a, tilt) = (0.2f64, 40f64.to_radians());
    let centre = [0.3, -0.2, 1.0];
    let (dy, dz) = (0.5 * a * tilt.cos(), 0.5 * a * tilt.sin());
    let v = |sx: f64, sy: f64| [centre[0] + sx * 0.5 * a, centre[1] + sy * dy, centre[2] + sy * dz];
    let corners = [v(-1.0, -1.0), v(1.0, -1.0), v(1.0, 1.0), v(-1.0, 1.0)];
    let fmt = |p: [f64; 3]| format!("[{}, {}, {}]", p[0], p[1], p[2]);
    let toward = [0.0, 0.5, -(0.75f64.sqrt())];
    let scene = format!(
        "[[material]]\nname = \"black\"\nreflectance = 0.0\n\
         [[polygon]]\nmaterial = \"black\"\nvertices = [[-5,-5,0],[5,-5,0],[5,5,0],[-5,5,0]]\n\
         [[polygon]]\nmaterial = \"black\"\nvertices = [{}]\n\
         [sun]\ndirection = [{}, {}, {}]\ndirect_normal = 800\n",
        corners.map(fmt).join(", "),
        toward[0],
        toward[1],
        toward[2]
    );
    let dir = tempfile::tempdir().unwrap();
    solve(dir.path(), &scene);
    let (header, rows) = csv(&dir.path().join("out/patches.csv"));
    let ground = rows[0][column(&header, "h_g")].parse::<f64>().unwrap();
    let n_square = [0.0, -tilt.sin(), tilt.cos()];
    let along = |n: [f64; 3]| (n[0] * toward[0] + n[1] * toward[1] + n[2] * toward[2]).abs();
    let shadow = a * a * along(n_square) / along([0.0, 0.0, 1.0]);
    let expected = 800.0 * along([0.0, 0.0, 1.0]) * (1.0 - shadow / 100.0);
    assert!(
        (ground - expected).abs() < EXACT_TOL * expected,
        "ground {ground} expected {expected} (unshadowed {})",
        800.0 * along([0.0, 0.0, 1.0])
    );
}

/// A 4 × 4 × 3 m room whose ceiling has a 1 × 1 m opening in its middle (x, y 1.5..2.5), all of
/// reflectance `rho`, lit by a uniform sky of 1000 lx through the opening and an isotropic
/// 10,000 lm lamp at (1, 1, 2.5) (the shipped IES file): daylight and a luminaire in one scene.
fn skylit_room_with_a_lamp(rho: f64, lamp: bool, sky: bool) -> String {
    room_under_a_roof_opening(rho, lamp, sky, true)
}

/// [`skylit_room_with_a_lamp`], or with the whole ceiling open when `ceiling` is false.
fn room_under_a_roof_opening(rho: f64, lamp: bool, sky: bool, ceiling: bool) -> String {
    let mut s = format!("units = \"photometric\"\n[[material]]\nname = \"room\"\nreflectance = {rho}\n");
    let pieces = if ceiling { 9 } else { 5 };
    for v in [
        "[[0,0,0],[4,0,0],[4,4,0],[0,4,0]]",
        "[[0,0,0],[0,0,3],[4,0,3],[4,0,0]]",
        "[[0,4,0],[4,4,0],[4,4,3],[0,4,3]]",
        "[[0,0,0],[0,4,0],[0,4,3],[0,0,3]]",
        "[[4,0,0],[4,0,3],[4,4,3],[4,4,0]]",
        "[[0,0,3],[0,1.5,3],[4,1.5,3],[4,0,3]]",
        "[[0,2.5,3],[0,4,3],[4,4,3],[4,2.5,3]]",
        "[[0,1.5,3],[0,2.5,3],[1.5,2.5,3],[1.5,1.5,3]]",
        "[[2.5,1.5,3],[2.5,2.5,3],[4,2.5,3],[4,1.5,3]]",
    ]
    .into_iter()
    .take(pieces)
    {
        s += &format!("[[polygon]]\nmaterial = \"room\"\nvertices = {v}\n");
    }
    if lamp {
        s += "[[luminaire]]\nies = \"isotropic_10000lm.ies\"\nname = \"lamp\"\nposition = [1.0, 1.0, 2.5]\n";
    }
    if sky {
        s += "[sky]\nmodel = \"uniform\"\ndiffuse_horizontal = 1000\n";
    }
    s
}

/// Lambert's form factor from a point facing +z to the parallel rectangle [x0, x1] × [y0, y1] at
/// height `h` above it (corner rectangles added with signs).
fn point_to_rectangle(p: [f64; 2], x: [f64; 2], y: [f64; 2], h: f64) -> f64 {
    let corner = |a: f64, b: f64| {
        let (a, b) = (a / h, b / h);
        let (ra, rb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
        (a / ra * (b / ra).atan() + b / rb * (a / rb).atan()) / std::f64::consts::TAU
    };
    let mut f = 0.0;
    for (xi, sx) in [(x[1], 1.0), (x[0], -1.0)] {
        for (yi, sy) in [(y[1], 1.0), (y[0], -1.0)] {
            let (dx, dy) = (xi - p[0], yi - p[1]);
            f += sx * sy * dx.signum() * dy.signum() * corner(dx.abs(), dy.abs());
        }
    }
    f
}

/// Irradiance and its estimated error at the points of `points.csv` in `out`.
fn points_read(out: &Path) -> Vec<(f64, f64)> {
    let (header, rows) = csv(&out.join("points.csv"));
    let (h, err) = (column(&header, "h_photopic"), column(&header, "h_err"));
    rows.iter().map(|r| (r[h].parse().unwrap(), r[err].parse().unwrap())).collect()
}

/// Issue 40 step 4: daylight and luminaires in one scene and one solve, each source's share
/// reported. In the black room every number has a closed form: the lamp's light on the surfaces
/// is its flux less what leaves through the opening, `Φ (1 − Ω/4π)` with Ω the opening's solid
/// angle from the lamp; that remainder is the escaped light; a floor point gets `I cos θ / d²`
/// from the lamp plus the sky's `E_h F(point → opening)`. The points are read in one solve with
/// both sources and in two with one each: the same numbers (superposition), the lamp's part
/// exact, the sky's within its estimated error. In the grey room the light interreflects and
/// the balance still closes.
#[test]
fn daylight_and_a_luminaire_light_one_room_in_one_solve() {
    let dir = tempfile::tempdir().unwrap();
    let ies = Path::new(env!("CARGO_MANIFEST_DIR")).join("radiosity-core/data/luminaires/isotropic_10000lm.ies");
    std::fs::copy(ies, dir.path().join("isotropic_10000lm.ies")).unwrap();
    let floor: [[f64; 2]; 3] = [[2.0, 2.0], [1.0, 1.0], [3.5, 2.0]];
    let points: String = floor.iter().enumerate().map(|(i, [x, y])| format!("p{i},{x},{y},0,0,0,1\n")).collect();
    std::fs::write(dir.path().join("pts.csv"), format!("name,x,y,z,nx,ny,nz\n{points}")).unwrap();
    let run = |name: &str, text: &str| {
        std::fs::write(dir.path().join(format!("{name}.toml")), text).unwrap();
        let out = run_cli(dir.path(), &["solve", &format!("{name}.toml"), "--points", "pts.csv", "--quiet", "--no-image", "--out", name]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let stats: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join(name).join("stats.json")).unwrap()).unwrap();
        (stats, points_read(&dir.path().join(name)))
    };
    let (both, at_both) = run("both", &skylit_room_with_a_lamp(0.0, true, true));
    let (_, at_lamp) = run("lamp", &skylit_room_with_a_lamp(0.0, true, false));
    let (sky_only, at_sky) = run("sky", &skylit_room_with_a_lamp(0.0, false, true));

    // The lamp: what reaches the surfaces and what escapes through the opening, exactly.
    let flux = 10_000.0;
    // The opening seen from the lamp 0.5 m below it: x and y 0.5..1.5 m off its foot.
    let corner = |x: f64, y: f64| (x * y / (0.5 * (x * x + y * y + 0.25f64).sqrt())).atan();
    let solid_angle = corner(1.5, 1.5) - corner(0.5, 1.5) - corner(1.5, 0.5) + corner(0.5, 0.5);
    let onto_exact = flux * (1.0 - solid_angle / (4.0 * std::f64::consts::PI));
    let sources = both["sources"].as_array().expect("sources in stats.json");
    let source = |name: &str| sources.iter().find(|s| s["name"] == name).unwrap_or_else(|| panic!("no source {name}: {sources:?}"));
    let onto = |s: &serde_json::Value| s["onto_surfaces"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).sum::<f64>() / 3.0;
    let (lamp, sky) = (source("lamp"), source("sky"));
    assert_eq!((lamp["kind"].as_str(), sky["kind"].as_str(), sources.len()), (Some("luminaire"), Some("sky"), 2));
    assert!((onto(lamp) / onto_exact - 1.0).abs() < LAMP_ONTO_TOL, "lamp onto the surfaces {} against {onto_exact}", onto(lamp));
    // The sky's part is what the sky brings alone, and it is all the incident light.
    let incident = both["power_incident"].as_f64().unwrap();
    assert!((onto(sky) / incident - 1.0).abs() < EXACT_TOL, "sky {} against incident {incident}", onto(sky));
    let shares = lamp["share"].as_f64().unwrap() + sky["share"].as_f64().unwrap();
    assert!(
        (shares - 1.0).abs() < EXACT_TOL && (lamp["share"].as_f64().unwrap() - onto(lamp) / (onto(lamp) + onto(sky))).abs() < EXACT_TOL
    );
    // Black: nothing is reflected, so what escapes is the lamp's light through the opening.
    let escaped = both["power_escaped"].as_f64().unwrap();
    assert!((escaped - (flux - onto_exact)).abs() < LAMP_ONTO_TOL * flux, "escaped {escaped} against {}", flux - onto_exact);
    assert!((both["power_emitted"].as_f64().unwrap() - flux).abs() < 1e-6 * flux);
    assert!((both["power_balance"].as_f64().unwrap() - 1.0).abs() < BALANCE_TOL, "{}", both["power_balance"]);
    assert!(sky_only.get("sources").is_none(), "one kind of source: no shares");

    // The points: one solve with both is the sum of one with each; the lamp's part is exact, the
    // sky's within its estimate.
    let intensity = flux / (4.0 * std::f64::consts::PI);
    for (((p, b), l), s) in floor.iter().zip(&at_both).zip(&at_lamp).zip(&at_sky) {
        assert!((b.0 - (l.0 + s.0)).abs() < 1e-9 * b.0, "{p:?}: both {} against {} + {}", b.0, l.0, s.0);
        let d2 = (p[0] - 1.0).powi(2) + (p[1] - 1.0).powi(2) + 2.5 * 2.5;
        let lamp_exact = intensity * 2.5 / d2.powf(1.5);
        assert!((l.0 / lamp_exact - 1.0).abs() < LAMP_POINT_TOL, "{p:?}: lamp {} against {lamp_exact}", l.0);
        let sky_exact = 1000.0 * point_to_rectangle(*p, [1.5, 2.5], [1.5, 2.5], 3.0);
        eprintln!("{p:?}: lamp {:.4} (exact {lamp_exact:.4}), sky {:.4} ± {:.4} (exact {sky_exact:.4})", l.0, s.0, s.1);
        let sky_error = (s.0 - sky_exact).abs();
        assert!(
            sky_error <= s.1 && sky_error <= SKY_THROUGH_OPENING_REL_TOL * sky_exact,
            "{p:?}: sky {} ± {} against {sky_exact}",
            s.0,
            s.1
        );
    }

    // Grey: interreflected, and still balanced.
    let (grey, _) = run("grey", &skylit_room_with_a_lamp(0.5, true, true));
    assert!((grey["power_balance"].as_f64().unwrap() - 1.0).abs() < BALANCE_TOL, "{}", grey["power_balance"]);
    assert_eq!(grey["sources"].as_array().map(Vec::len), Some(2));
}

/// A point of CIE 171 5.9: name, position, normal, the table's value under the 1 × 1 m opening
/// and under the whole open ceiling (%; NaN where left out).
type Cie59Point = (&'static str, [f64; 3], [f64; 3], f64, f64);

/// CIE 171:2006 case 5.9, sky type 5 (uniform luminance), the sky component in % of the outside
/// horizontal illuminance: points A-F on the wall y = 0 (x = 2, z = 2.75 ... 0.25, facing +y) and
/// G-N on the floor (x = 2, y = 0.25 ... 3.75) of a black 4 × 4 × 3 m room, under a 1 × 1 m roof
/// opening in the middle of the ceiling, and with the whole ceiling open (the report's table, as
/// transcribed in the project's reference notes; 4 × 4 point A is left out: the table is 3.6%
/// high there, a known erratum, 45.12% exactly).
///
/// Each: the point's name, position and normal, and its value under each opening (%).
const CIE_59_TYPE_5: [Cie59Point; 14] = [
    ("A", [2.0, 0.0, 2.75], [0.0, 1.0, 0.0], 1.04, f64::NAN),
    ("B", [2.0, 0.0, 2.25], [0.0, 1.0, 0.0], 2.39, 36.05),
    ("C", [2.0, 0.0, 1.75], [0.0, 1.0, 0.0], 2.59, 28.05),
    ("D", [2.0, 0.0, 1.25], [0.0, 1.0, 0.0], 2.20, 21.67),
    ("E", [2.0, 0.0, 0.75], [0.0, 1.0, 0.0], 1.70, 16.73),
    ("F", [2.0, 0.0, 0.25], [0.0, 1.0, 0.0], 1.27, 12.98),
    ("G", [2.0, 0.25, 0.0], [0.0, 0.0, 1.0], 1.95, 26.80),
    ("H", [2.0, 0.75, 0.0], [0.0, 0.0, 1.0], 2.52, 30.95),
    ("I", [2.0, 1.25, 0.0], [0.0, 0.0, 1.0], 3.04, 33.99),
    ("J", [2.0, 1.75, 0.0], [0.0, 0.0, 1.0], 3.37, 35.58),
    ("K", [2.0, 2.25, 0.0], [0.0, 0.0, 1.0], 3.37, 35.58),
    ("L", [2.0, 2.75, 0.0], [0.0, 0.0, 1.0], 3.04, 33.99),
    ("M", [2.0, 3.25, 0.0], [0.0, 0.0, 1.0], 2.52, 30.95),
    ("N", [2.0, 3.75, 0.0], [0.0, 0.0, 1.0], 1.95, 26.80),
];
/// The daylight factor at CIE 171 5.9's points against the report's two-decimal table: 2% (the
/// issue's bar; the report's own tolerance is looser), plus half the table's last digit.
const CIE_59_REL_TOL: f64 = 0.02;

/// Issue 40 step 3: the daylight factor, `100 · E ÷ E_outside,horizontal`, at calculation points
/// and on a grid, in a scene lit by a sky alone. CIE 171 5.9 for sky type 5 (both openings, at the
/// report's points, through `points.csv`'s `df_pct`); the grid's figures in `stats.json` are those
/// of its `df_pct` column (mean, the factor reached by half and by 95% of the points, min, max),
/// and `--false-colour daylight-factor` draws it; a scene with a sun has no daylight factor and
/// the false colour asks for one.
#[test]
fn daylight_factor_at_cie_171_5_9_points_and_on_a_grid() {
    let dir = tempfile::tempdir().unwrap();
    let points: String =
        CIE_59_TYPE_5.iter().map(|(name, [x, y, z], [nx, ny, nz], _, _)| format!("{name},{x},{y},{z},{nx},{ny},{nz}\n")).collect();
    std::fs::write(dir.path().join("pts.csv"), format!("name,x,y,z,nx,ny,nz\n{points}")).unwrap();
    let grid = "[[grid]]\nname = \"floor\"\norigin = [0, 0, 0]\nu = [4, 0, 0]\nv = [0, 4, 0]\nspacing = 0.5\n";
    let small = skylit_room_with_a_lamp(0.0, false, true);
    let whole = room_under_a_roof_opening(0.0, false, true, false);
    for (case, text) in [("1x1", format!("{small}{grid}")), ("4x4", whole)] {
        let name = format!("df{case}");
        std::fs::write(dir.path().join(format!("{name}.toml")), &text).unwrap();
        let args =
            ["solve", &format!("{name}.toml"), "--points", "pts.csv", "--quiet", "--false-colour", "daylight-factor", "--out", &name];
        let out = run_cli(dir.path(), &args);
        assert!(out.status.success(), "{case}: {}", String::from_utf8_lossy(&out.stderr));
        let (header, rows) = csv(&dir.path().join(&name).join("points.csv"));
        let (df, df_err) = (column(&header, "df_pct"), column(&header, "df_err_pct"));
        for ((label, _, _, small_table, whole_table), row) in CIE_59_TYPE_5.iter().zip(&rows) {
            let table = if case == "1x1" { *small_table } else { *whole_table };
            if table.is_nan() {
                continue;
            }
            let (got, err): (f64, f64) = (row[df].parse().unwrap(), row[df_err].parse().unwrap());
            eprintln!("CIE 5.9 {case} {label}: DF {got:.3}% ± {err:.3} against {table}");
            assert!((got - table).abs() <= CIE_59_REL_TOL * table + 0.005, "{case} {label}: {got}% against the report's {table}%");
        }
        assert!(dir.path().join(&name).join("falsecolor.png").exists());
    }
    // The grid's figures are its column's.
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("df1x1/stats.json")).unwrap()).unwrap();
    let figures = &stats["grids"]["floor"]["daylight_factor"];
    let (header, rows) = csv(&dir.path().join("df1x1/grid_floor.csv"));
    let mut df: Vec<f64> = rows.iter().map(|r| r[column(&header, "df_pct")].parse().unwrap()).collect();
    df.sort_by(|a, b| b.total_cmp(a));
    let n = df.len();
    assert_eq!(n, 64);
    let want = [
        ("mean", df.iter().sum::<f64>() / n as f64),
        ("median", df[n / 2 - 1]),
        ("over_95", df[(0.95 * n as f64).ceil() as usize - 1]),
        ("min", df[n - 1]),
        ("max", df[0]),
    ];
    for (key, value) in want {
        let got = figures[key].as_f64().unwrap_or_else(|| panic!("no {key} in {figures}"));
        assert!((got - value).abs() <= 1e-9 * value.abs().max(1.0), "{key}: {got} against {value} from the column");
    }
    assert!((figures["outside"].as_f64().unwrap() - 1000.0).abs() < 1e-6, "{figures}");
    assert!(dir.path().join("df1x1/grid_floor_df.svg").exists());
    // With a sun there is no daylight factor: no column, no figures, and the false colour says why.
    let sunny = format!("{small}{grid}[sun]\ndirection = [0.3, 0.2, -0.9]\ndirect_normal = 5000\n");
    std::fs::write(dir.path().join("sunny.toml"), &sunny).unwrap();
    let out = run_cli(dir.path(), &["solve", "sunny.toml", "--quiet", "--no-image", "--out", "sunny"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (header, _) = csv(&dir.path().join("sunny/grid_floor.csv"));
    assert!(!header.iter().any(|h| h.starts_with("df_")), "{header:?}");
    let out = run_cli(dir.path(), &["solve", "sunny.toml", "--quiet", "--false-colour", "daylight-factor", "--out", "sunny2"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("not lit by a sky alone") && err.trim().lines().count() == 1, "{err}");
}

/// The worked example of the docs (`examples/daylight/sidelit_room.toml`, a side-lit room under
/// the CIE overcast sky) solves from the command the docs give: its work plane's daylight
/// factors are written, the balance of the open room closes, and the factors fall from the window
/// to the back wall.
#[test]
fn the_side_lit_room_example_gives_its_daylight_factors() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/daylight/sidelit_room.toml");
    let out = run_cli(dir.path(), &["solve", scene.to_str().unwrap(), "--quiet", "--false-colour", "daylight-factor", "--out", "out"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/stats.json")).unwrap()).unwrap();
    assert!((stats["power_balance"].as_f64().unwrap() - 1.0).abs() < BALANCE_TOL, "{}", stats["power_balance"]);
    let df = &stats["grids"]["work"]["daylight_factor"];
    assert!((df["outside"].as_f64().unwrap() - 10_000.0).abs() < 1e-6, "{df}");
    let (header, rows) = csv(&dir.path().join("out/grid_work.csv"));
    let (x, d) = (column(&header, "x"), column(&header, "df_pct"));
    let mean_at = |lo: f64, hi: f64| {
        let v: Vec<f64> = rows.iter().filter(|r| (lo..hi).contains(&r[x].parse::<f64>().unwrap())).map(|r| r[d].parse().unwrap()).collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let (front, back) = (mean_at(0.0, 1.5), mean_at(4.5, 6.0));
    assert!(front > 2.0 * back && back > 0.5, "daylight factor by the window {front}%, at the back {back}%");
    assert!(dir.path().join("out/falsecolor.png").exists() && dir.path().join("out/grid_work_df.svg").exists());
}
