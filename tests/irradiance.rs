//! Irradiance on black receivers: CIE 171:2006 test case 5.7 ("diffuse reflections with an
//! internal obstruction"), where the sensors and every surface but the lit wall are black. The
//! irradiance criterion (the default, `--criterion irradiance`) refines a black sensor's penumbra like a white wall's; the
//! radiosity criterion, which weighs a shadow's shape by the receiver's reflectance, leaves it.

use std::path::Path;
use std::process::Command;

#[path = "support/cie171.rs"]
mod cie171;
#[path = "support/obj.rs"]
mod obj;

/// CIE 171:2006 case 5.7, as corrected (NVIDIA Iray validation report, Table 14; the printed
/// Table 19 is wrong): `E/(E_v·ρ)` in % at points A–F on the black wall y = 0 (x = 2, z = 2.75 …
/// 0.25) and G–K on the black floor (x = 2, y = 0.25 … 2.25). With the lit wall emitting
/// 100 W/m², a point's irradiance in W/m² is this value. (Our own contour integration over the
/// visible part of the wall reproduces them to 0.003; averaged over the 2 cm sensors the values
/// differ from the points' by under 0.0003, but J's, 0.024, which straddles the shadow line.)
const CIE_57: [(&str, f64); 11] = [
    ("A", 16.071),
    ("B", 16.330),
    ("C", 15.399),
    ("D", 13.322),
    ("E", 10.317),
    ("F", 7.079),
    ("G", 3.382),
    ("H", 3.629),
    ("I", 3.013),
    ("J", 0.0),
    ("K", 0.0),
];

/// The bar for a sensor's irradiance against the exact point value.
const SENSOR_TOL: f64 = 0.02;

/// Case 5.3's bar for a sensor against its own exact irradiance, relative to the largest
/// non-emitting mean irradiance: a tenth of the default target error, since an unobstructed
/// source's direct light needs exact form factors and no refinement (measured: 1.1e-4, see
/// `black_sensors_meet_cie_171_case_5_3_at_the_default_settings`).
const SENSOR_SOLVER_TOL: f64 = 1e-3;

/// Largest irradiance of a sensor in full shadow: half a percent of the brightest sensor's (J's
/// 2 cm square reaches 1 cm past the shadow line, where it sees a sliver of the wall: 0.024 W/m²
/// averaged over it).
const SHADOWED_MAX: f64 = 0.005 * 16.071;

/// The case's scene: the lit wall S2 (4 × 3 m at y = 4, facing −y) emitting 100 W/m², the black
/// wall at y = 0, the black floor strip y ∈ [0, 2.5], the black box x ∈ [0, 4], y ∈ [2.5, 2.7],
/// z ∈ [0, 1], and a 2 cm black sensor 1 mm in front of each point.
fn scene(dir: &Path) {
    let mut obj = obj::Obj::new("cie57.mtl");
    obj.quad([[0., 4., 0.], [4., 4., 0.], [4., 4., 3.], [0., 4., 3.]], [0., -1., 0.], "s2");
    obj.quad([[0., 0., 0.], [4., 0., 0.], [4., 0., 3.], [0., 0., 3.]], [0., 1., 0.], "black");
    obj.quad([[0., 0., 0.], [4., 0., 0.], [4., 2.5, 0.], [0., 2.5, 0.]], [0., 0., 1.], "black");
    obj.quad([[0., 2.5, 1.], [4., 2.5, 1.], [4., 2.7, 1.], [0., 2.7, 1.]], [0., 0., 1.], "black");
    obj.quad([[0., 2.5, 0.], [4., 2.5, 0.], [4., 2.5, 1.], [0., 2.5, 1.]], [0., -1., 0.], "black");
    obj.quad([[0., 2.7, 0.], [4., 2.7, 0.], [4., 2.7, 1.], [0., 2.7, 1.]], [0., 1., 0.], "black");
    let h = 0.01;
    for z in [2.75, 2.25, 1.75, 1.25, 0.75, 0.25] {
        obj.quad([[2. - h, 0.001, z - h], [2. + h, 0.001, z - h], [2. + h, 0.001, z + h], [2. - h, 0.001, z + h]], [0., 1., 0.], "sensor");
    }
    for y in [0.25, 0.75, 1.25, 1.75, 2.25] {
        obj.quad([[2. - h, y - h, 0.001], [2. + h, y - h, 0.001], [2. + h, y + h, 0.001], [2. - h, y + h, 0.001]], [0., 0., 1.], "sensor");
    }
    std::fs::write(dir.join("cie57.obj"), obj.text).unwrap();
    std::fs::write(dir.join("cie57.mtl"), "newmtl s2\nKd 0 0 0\nKe 100 100 100\nnewmtl black\nKd 0 0 0\nnewmtl sensor\nKd 0 0 0\n")
        .unwrap();
}

/// A solve's sensors' irradiance (red channel) in `patches.csv` order, A to K, the largest mean
/// irradiance of a non-emitting polygon, and `stats.json`.
struct Run {
    sensors: Vec<f64>,
    top: f64,
    stats: serde_json::Value,
}

fn solve(dir: &Path, args: &[&str]) -> Run {
    solve_file(dir, "cie57.obj", args)
}

/// [`solve`] of scene file `file` (its emitter's material `s2` or `source`).
fn solve_file(dir: &Path, file: &str, args: &[&str]) -> Run {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", file, "--quiet", "--no-image", "--out", "out"])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the binary runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("out/patches.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (m, h) = (header.iter().position(|&c| c == "material").unwrap(), header.iter().position(|&c| c == "h_r").unwrap());
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let sensors = rows.iter().filter(|r| r[m] == "sensor").map(|r| r[h].parse().unwrap()).collect();
    let top = rows.iter().filter(|r| r[m] != "s2" && r[m] != "source").map(|r| r[h].parse::<f64>().unwrap()).fold(0.0, f64::max);
    let stats = serde_json::from_str(&std::fs::read_to_string(dir.join("out/stats.json")).unwrap()).unwrap();
    Run { sensors, top, stats }
}

/// Checks every sensor of a run against [`CIE_57`].
fn check(got: &[f64], run: &str) {
    assert_eq!(got.len(), CIE_57.len());
    for (&(name, want), &h) in CIE_57.iter().zip(got) {
        if want == 0.0 {
            assert!((0.0..=SHADOWED_MAX).contains(&h), "{run}, {name}: {h} W/m² in full shadow");
        } else {
            assert!((h - want).abs() <= SENSOR_TOL * want, "{run}, {name}: {h} W/m² against {want}");
        }
    }
}

/// Under the irradiance criterion (the default) every black sensor of case 5.7 gets its irradiance
/// within 2% of the exact value (and the shadowed ones stay dark), at the default settings and, for
/// three seeds, at `--eps 0.01`. Measured: default 1.6k links, worst 0.68–0.86% (seeds 1–3); eps 0.01,
/// seeds 1–4, 17–23k links, worst 0.41–0.79%. Under the radiosity criterion the eps 0.01 run keeps 300 links
/// and is off by up to 13% (D): nothing weighs a black receiver's shadow. Before the kept
/// visibility was sampled afresh (`LinkCtx::fresh_visibility`), the irradiance criterion's eps
/// 0.01 runs were off by 3.5–4.7% (I): links along the penumbra were kept with the 16 segments
/// that had happened to agree.
#[test]
fn black_sensors_in_a_penumbra_meet_cie_171_case_5_7_under_the_irradiance_criterion() {
    let dir = tempfile::tempdir().unwrap();
    scene(dir.path());
    check(&solve(dir.path(), &[]).sensors, "default settings");
    for seed in ["1", "2", "3"] {
        check(&solve(dir.path(), &["--eps", "0.01", "--seed", seed]).sensors, &format!("eps 0.01, seed {seed}"));
    }
}

/// Under the irradiance criterion (the default) the error estimate covers the polygons' mean
/// irradiance and bounds the sensors' true worst error (relative to the largest non-emitting mean
/// irradiance, as the estimate is), at the default settings for three seeds. Measured: estimate 0.74–0.92%, true
/// 0.10–0.14%, 1.6k links; under the radiosity criterion every receiver is black and the estimate
/// is its floor, 0.001%.
#[test]
fn the_estimate_bounds_the_black_sensors_error_under_the_irradiance_criterion() {
    let dir = tempfile::tempdir().unwrap();
    scene(dir.path());
    for seed in ["1", "2", "3"] {
        let run = solve(dir.path(), &["--seed", seed]);
        let covers = &run.stats["error_estimate_covers"];
        assert!(covers.as_array().unwrap().iter().any(|c| c == "irradiance"), "{covers}");
        let estimate = run.stats["error_estimate"].as_f64().unwrap();
        let worst = CIE_57.iter().zip(&run.sensors).map(|(&(_, want), &h)| (h - want).abs()).fold(0.0, f64::max) / run.top;
        assert!(estimate >= worst, "seed {seed}: estimate {estimate} below the true worst error {worst}");
    }
}

/// Case 5.3's room with a 2 cm black sensor 1 mm in front of each point (wall points first).
fn scene_53(dir: &Path) {
    let mut obj = obj::Obj::new("cie53.mtl");
    let k = "black";
    obj.quad([[0., 0., 0.], [4., 0., 0.], [4., 4., 0.], [0., 4., 0.]], [0., 0., 1.], k);
    obj.quad([[0., 0., 0.], [4., 0., 0.], [4., 0., 3.], [0., 0., 3.]], [0., 1., 0.], k);
    obj.quad([[0., 4., 0.], [4., 4., 0.], [4., 4., 3.], [0., 4., 3.]], [0., -1., 0.], k);
    obj.quad([[0., 0., 0.], [0., 4., 0.], [0., 4., 3.], [0., 0., 3.]], [1., 0., 0.], k);
    obj.quad([[4., 0., 0.], [4., 4., 0.], [4., 4., 3.], [4., 0., 3.]], [-1., 0., 0.], k);
    // The ceiling around the source, then the source in its hole.
    for (x, y) in [((0., 4.), (0., 1.5)), ((0., 4.), (2.5, 4.)), ((0., 1.5), (1.5, 2.5)), ((2.5, 4.), (1.5, 2.5))] {
        obj.quad([[x.0, y.0, 3.], [x.1, y.0, 3.], [x.1, y.1, 3.], [x.0, y.1, 3.]], [0., 0., -1.], k);
    }
    obj.quad([[1.5, 1.5, 3.], [2.5, 1.5, 3.], [2.5, 2.5, 3.], [1.5, 2.5, 3.]], [0., 0., -1.], "source");
    let h = 0.01;
    for (_, z, _) in cie171::CASE_53_WALL {
        obj.quad([[2. - h, 0.001, z - h], [2. + h, 0.001, z - h], [2. + h, 0.001, z + h], [2. - h, 0.001, z + h]], [0., 1., 0.], "sensor");
    }
    for (_, y, _) in cie171::CASE_53_FLOOR {
        obj.quad([[2. - h, y - h, 0.001], [2. + h, y - h, 0.001], [2. + h, y + h, 0.001], [2. - h, y + h, 0.001]], [0., 0., 1.], "sensor");
    }
    std::fs::write(dir.join("cie53.obj"), obj.text).unwrap();
    let exitance = std::f64::consts::PI * 1000.0;
    std::fs::write(
        dir.join("cie53.mtl"),
        format!("newmtl source\nKd 0 0 0\nKe {exitance} {exitance} {exitance}\nnewmtl black\nKd 0 0 0\nnewmtl sensor\nKd 0 0 0\n"),
    )
    .unwrap();
}

/// The form factor from a point at `p` with normal `n` to a convex polygon (Lambert's contour
/// formula: `1/2π Σ γ_i (u_i × u_{i+1})/|u_i × u_{i+1}| · n`, `u_i` the unit vectors to the
/// vertices, `γ_i` the angle between consecutive ones), the polygon wholly in front of the point.
fn point_form_factor(p: [f64; 3], n: [f64; 3], polygon: &[[f64; 3]]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let unit = |a: [f64; 3]| {
        let l = dot(a, a).sqrt();
        [a[0] / l, a[1] / l, a[2] / l]
    };
    let mut sum = 0.0;
    for i in 0..polygon.len() {
        let (u, v) = (unit(sub(polygon[i], p)), unit(sub(polygon[(i + 1) % polygon.len()], p)));
        let c = cross(u, v);
        sum += dot(u, v).clamp(-1.0, 1.0).acos() * dot(unit(c), n);
    }
    (sum / (2.0 * std::f64::consts::PI)).abs()
}

/// Every black sensor of case 5.3 within 2% of the report's point value at the default settings
/// (the irradiance criterion) and under `--criterion radiosity`, and within [`SENSOR_SOLVER_TOL`]
/// of its own exact irradiance (Lambert's formula over 3 × 3 points of it, 1 mm nearer the source
/// than the report's point: J's exact value is 0.067% above the point's). Measured (both
/// criteria): 806 links, every sensor 1.1e-4 below its exact value. The room is closed, and the
/// closure that makes every source deliver its light whole scaled the source's links by
/// 1/(1 + 1.1e-4) (form factors summing a little over 1 elsewhere); at the default settings the
/// estimate counts what the closure moved (`solve::closure_error`) and covers the sensors: 0.029%
/// for a true 0.011% (under the radiosity criterion, which bounds B = 0 on black sensors, 0.001%).
#[test]
fn black_sensors_meet_cie_171_case_5_3_at_the_default_settings() {
    let dir = tempfile::tempdir().unwrap();
    scene_53(dir.path());
    let source = [[1.5, 1.5, 3.], [2.5, 1.5, 3.], [2.5, 2.5, 3.], [1.5, 2.5, 3.]];
    let exitance = std::f64::consts::PI * 1000.0;
    let h = 0.01;
    let mean = |centre: [f64; 3], n: [f64; 3], along: [[f64; 3]; 2]| {
        let mut e = 0.0;
        for i in -1..=1 {
            for j in -1..=1 {
                let (a, b) = (f64::from(i) * h * 2.0 / 3.0, f64::from(j) * h * 2.0 / 3.0);
                let p: [f64; 3] = std::array::from_fn(|k| centre[k] + a * along[0][k] + b * along[1][k]);
                e += exitance * point_form_factor(p, n, &source);
            }
        }
        e / 9.0
    };
    let sensors_exact: Vec<f64> = cie171::CASE_53_WALL
        .iter()
        .map(|&(_, z, _)| mean([2., 0.001, z], [0., 1., 0.], [[1., 0., 0.], [0., 0., 1.]]))
        .chain(cie171::CASE_53_FLOOR.iter().map(|&(_, y, _)| mean([2., y, 0.001], [0., 0., 1.], [[1., 0., 0.], [0., 1., 0.]])))
        .collect();
    let report: Vec<(&str, f64)> = cie171::CASE_53_WALL.iter().chain(&cie171::CASE_53_FLOOR).map(|&(n, _, v)| (n, v)).collect();
    for args in [&[][..], &["--criterion", "radiosity"][..]] {
        let run = solve_file(dir.path(), "cie53.obj", args);
        assert_eq!(run.sensors.len(), report.len());
        let mut worst: f64 = 0.0;
        for ((&(name, want), &h), &exact) in report.iter().zip(&run.sensors).zip(&sensors_exact) {
            assert!((h - want).abs() <= SENSOR_TOL * want, "{args:?}, {name}: {h} W/m² against {want}");
            worst = worst.max((h - exact).abs());
        }
        let estimate = run.stats["error_estimate"].as_f64().unwrap();
        eprintln!(
            "{args:?}: {} links, worst sensor {:.4}% of the largest mean, estimate {:.4}%",
            run.stats["links"],
            100.0 * worst / run.top,
            100.0 * estimate
        );
        assert!(worst / run.top <= SENSOR_SOLVER_TOL, "{args:?}: a sensor is {worst} W/m² off its exact irradiance");
        if args.is_empty() {
            assert!(estimate >= worst / run.top, "the estimate {estimate} is below the sensors' error {}", worst / run.top);
        }
    }
}
