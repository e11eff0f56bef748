//! Calculation grids (`radiosity::points::grid`, `solve --grid`, `--work-plane`) against exact
//! answers: the CIE 171:2006 area-source case 5.3 (`shared/reference/cie171.md`: E = π L F, the
//! values recomputed there by Lambert's contour formula) on a floor strip through the printed
//! points and on a floor grid checked point by point against `formfactor::point_polygon`, the CSV
//! rows and the isolux plot, and the command line end to end.

use radiosity::formfactor::point_polygon;
use radiosity::geom::DVec3;
use radiosity::output::{contour_levels, grid_svg, write_grid_csv};
use radiosity::photometry::Units;
use radiosity::pipeline::{self, Config, Solved};
use radiosity::points::{self, GridSpec, GridSummary, PointsConfig};
use radiosity::refine::BfHand;
use radiosity::scene::{Material, Scene, SceneBuilder};
use std::f64::consts::PI;
use std::path::Path;
use std::process::Command;

/// The values in `cie171.md` are printed with 3 decimals.
const REFERENCE_ROUNDING: f64 = 5e-4;
/// A gather that involves no partial visibility is exact up to rounding (see tests/points.rs).
const EXACT_REL_TOL: f64 = 1e-9;

/// CIE 171:2006 5.3: a 4×4×3 m black room, z up, a 1×1 m Lambertian source of luminance 1000
/// cd/m² (exitance π·1000) centred in the ceiling facing down.
fn cie_5_3() -> Scene {
    let mut b = SceneBuilder::new(Path::new("cie-5.3"), "cie-5.3");
    let black = b.material(Material::diffuse("black", [0.0; 3])).unwrap();
    let mut m = Material::diffuse("source", [0.0; 3]);
    m.emission = [PI * 1000.0; 3];
    let src = b.material(m).unwrap();
    let g = b.group("g");
    let mut quad = |c: [[f64; 3]; 4], facing: [f64; 3], material: u32| {
        let mut v = c.map(DVec3::from);
        let newell: DVec3 = (0..4).map(|i| v[i].cross(v[(i + 1) % 4])).sum();
        if newell.dot(DVec3::from(facing)) < 0.0 {
            v.reverse();
        }
        b.face(&v, material, g, 0).unwrap();
    };
    let xy = |x0: f64, x1: f64, y0: f64, y1: f64, z: f64| [[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]];
    quad(xy(0.0, 4.0, 0.0, 4.0, 0.0), [0.0, 0.0, 1.0], black);
    quad([[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 0.0, 3.0], [0.0, 0.0, 3.0]], [0.0, 1.0, 0.0], black);
    quad([[0.0, 4.0, 0.0], [4.0, 4.0, 0.0], [4.0, 4.0, 3.0], [0.0, 4.0, 3.0]], [0.0, -1.0, 0.0], black);
    quad([[0.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 4.0, 3.0], [0.0, 0.0, 3.0]], [1.0, 0.0, 0.0], black);
    quad([[4.0, 0.0, 0.0], [4.0, 4.0, 0.0], [4.0, 4.0, 3.0], [4.0, 0.0, 3.0]], [-1.0, 0.0, 0.0], black);
    for (x0, x1, y0, y1) in [(0.0, 4.0, 0.0, 1.5), (0.0, 4.0, 2.5, 4.0), (0.0, 1.5, 1.5, 2.5), (2.5, 4.0, 1.5, 2.5)] {
        quad(xy(x0, x1, y0, y1, 3.0), [0.0, 0.0, -1.0], black);
    }
    quad(xy(1.5, 2.5, 1.5, 2.5, 3.0), [0.0, 0.0, -1.0], src);
    b.finish()
}

fn solve(scene: &Scene) -> Solved {
    pipeline::run(scene, &BfHand::default(), &Config::default(), &|_| {})
}

#[test]
fn floor_strip_through_the_cie_points_has_the_figures_computed_by_hand() {
    let solved = solve(&cie_5_3());
    // One point wide (x = 2), 8 long: the CIE floor points G..N at y = 0.25, 0.75, ..., 3.75.
    let spec =
        GridSpec { name: "cie".into(), origin: [1.75, 0.0, 0.0], u: [0.5, 0.0, 0.0], v: [0.0, 4.0, 0.0], spacing: 0.5, normal: None };
    let grid = spec.grid().unwrap();
    assert_eq!((grid.n_u, grid.n_v), (1, 8));
    let results = points::gather(&solved, &grid.points, &PointsConfig::default());
    let values: Vec<f64> = results.iter().map(points::PointIrradiance::photopic).collect();
    let exact = [61.424, 79.255, 95.667, 105.778, 105.778, 95.667, 79.255, 61.424];
    for ((v, e), r) in values.iter().zip(exact).zip(&results) {
        assert!((v - e).abs() <= REFERENCE_ROUNDING + EXACT_REL_TOL * e, "{v} vs {e}");
        // Its estimated error: finite, within 1% of the value, and covering the true error.
        let err = r.photopic_err();
        assert!(err.is_finite() && err <= 0.01 * e, "{v}: estimated error {err}");
        assert!((v - e).abs() <= err + REFERENCE_ROUNDING, "{v} vs {e}, estimated error {err}");
    }
    // By hand: the mean of the four distinct values, 342.124 / 4; U0 = 61.424 / 85.531.
    let s = GridSummary::of(&values).unwrap();
    assert_eq!(s.points, 8);
    assert!((s.e_avg - 85.531).abs() <= REFERENCE_ROUNDING, "{}", s.e_avg);
    assert!((s.e_min - 61.424).abs() <= REFERENCE_ROUNDING, "{}", s.e_min);
    assert!((s.e_max - 105.778).abs() <= REFERENCE_ROUNDING, "{}", s.e_max);
    assert!((s.u0 - 61.424 / 85.531).abs() <= 1e-5, "{}", s.u0);
    assert!((s.min_over_max - 61.424 / 105.778).abs() <= 1e-5, "{}", s.min_over_max);
    // The CSV: header, then one row per point in grid order, positions and normal exact.
    let mut csv = Vec::new();
    write_grid_csv(&mut csv, &grid, &results, Units::Photometric, None).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 9);
    assert_eq!(rows[0], "name,x,y,z,nx,ny,nz,h_r,h_g,h_b,h_photopic,e_lx,units,h_err,e_err");
    assert!(rows[1].starts_with("cie_0_0,2,0.25,0,0,0,1,"), "{}", rows[1]);
    assert!(rows[4].starts_with("cie_0_3,2,1.75,0,0,0,1,"), "{}", rows[4]);
    let fields: Vec<f64> = rows[4].split(',').skip(7).take(5).map(|f| f.parse().unwrap()).collect();
    assert_eq!(fields.len(), 5);
    assert!(rows[4].split(',').nth(12) == Some("lm/m2"), "{}", rows[4]);
    assert!(fields.iter().all(|f| (f - 105.778).abs() <= REFERENCE_ROUNDING), "{}", rows[4]);
    let mut csv = Vec::new();
    write_grid_csv(&mut csv, &grid, &results, Units::Radiometric, None).unwrap();
    assert!(String::from_utf8(csv).unwrap().starts_with("name,x,y,z,nx,ny,nz,h_r,h_g,h_b,h_photopic,units,h_err\n"));
}

#[test]
fn floor_grid_matches_lamberts_formula_and_its_plot_has_labelled_contours() {
    let solved = solve(&cie_5_3());
    let spec =
        GridSpec { name: "floor".into(), origin: [0.5, 0.5, 0.0], u: [3.0, 0.0, 0.0], v: [0.0, 3.0, 0.0], spacing: 0.5, normal: None };
    let grid = spec.grid().unwrap();
    assert_eq!(grid.points.len(), 36);
    let results = points::gather(&solved, &grid.points, &PointsConfig::default());
    let values: Vec<f64> = results.iter().map(points::PointIrradiance::photopic).collect();
    let source = [[1.5, 1.5], [1.5, 2.5], [2.5, 2.5], [2.5, 1.5]].map(|[x, y]| DVec3::new(x, y, 3.0));
    let exact: Vec<f64> = grid.points.iter().map(|p| PI * 1000.0 * point_polygon(p.position, p.normal, &source, -DVec3::Z)).collect();
    for ((p, v), e) in grid.points.iter().zip(&values).zip(&exact) {
        assert!((v - e).abs() <= EXACT_REL_TOL * e, "{}: {v} vs {e}", p.name);
    }
    let want = GridSummary::of(&exact).unwrap();
    let got = GridSummary::of(&values).unwrap();
    for (g, w) in [(got.e_avg, want.e_avg), (got.e_min, want.e_min), (got.e_max, want.e_max), (got.u0, want.u0)] {
        assert!((g - w).abs() <= EXACT_REL_TOL * w, "{g} vs {w}");
    }
    // The corners are the darkest points and the four central points the brightest.
    assert_eq!(got.e_min, values[0]);
    assert!((got.e_max - values[2 * 6 + 2]).abs() <= EXACT_REL_TOL * got.e_max);
    // The plot: a contour line with its label at every level, the points, the figures.
    let levels = contour_levels(got.e_min, got.e_max);
    assert!(levels.len() >= 3, "{levels:?}");
    let svg = grid_svg(&grid, &values, &got, Units::Photometric).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..100]);
    for l in &levels {
        assert!(svg.contains(&format!(">\n{l}\n</text>")) || svg.contains(&format!(">{l}</text>")), "no label {l}");
    }
    assert!(svg.matches("stroke=\"#005AB4\"").count() >= levels.len(), "contour lines");
    assert_eq!(svg.matches("<circle").count(), 36);
    assert!(svg.contains("U0 = Emin/Eavg"), "figures in the caption");
}

fn run_cli(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).current_dir(dir).output().expect("the binary runs")
}

#[test]
fn cli_grid_on_the_cornell_box_writes_csv_svg_and_stats() {
    let dir = tempfile::tempdir().unwrap();
    // The embedded Cornell box: millimetres, y up, floor y = 0 over x 0..556, z 0..559.
    let grid = "name=x,origin=100;1;420,u=300;0;0,v=0;0;120,spacing=100,normal=0;1;0";
    let out = run_cli(
        dir.path(),
        &[
            "solve",
            "--grid",
            grid,
            "--work-plane",
            "10",
            "--up",
            "y",
            "--work-plane-border",
            "100",
            "--work-plane-spacing",
            "120",
            "--no-image",
            "--eps",
            "0.05",
            "--out",
            "o",
        ],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.lines().any(|l| l.starts_with("grid x: 6 points, h_photopic avg ")), "{stdout}");
    assert!(stdout.lines().any(|l| l.starts_with("grid work: 9 points, h_photopic avg ")), "{stdout}");
    let csv = std::fs::read_to_string(dir.path().join("o/grid_x.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows[0], "name,x,y,z,nx,ny,nz,h_r,h_g,h_b,h_photopic,units,h_err");
    assert_eq!(rows.len(), 7);
    assert!(rows[1].starts_with("x_0_0,150,1,450,0,1,0,"), "{}", rows[1]);
    assert!(rows[6].starts_with("x_2_1,350,1,510,0,1,0,"), "{}", rows[6]);
    let svg = std::fs::read_to_string(dir.path().join("o/grid_x.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("grid x"));
    assert!(dir.path().join("o/grid_work.svg").is_file());
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("o/stats.json")).unwrap()).unwrap();
    let x = &stats["grids"]["x"];
    let column = |r: &str, k: usize| -> f64 { r.split(',').nth(k).unwrap().parse().unwrap() };
    let photopic: Vec<f64> = rows[1..].iter().map(|r| column(r, 10)).collect();
    let errors: Vec<f64> = rows[1..].iter().map(|r| column(r, 12)).collect();
    let want = GridSummary::of(&photopic).unwrap().with_errors(&errors);
    assert_eq!(x["e_err_max"].as_f64().unwrap(), want.e_err_max.unwrap(), "the worst point's estimated error");
    assert_eq!(x["points"], 6);
    // stats.json and the CSV agree (`{:e}` prints the shortest text that reads back exactly).
    assert_eq!(x["e_min"].as_f64().unwrap(), want.e_min);
    assert_eq!(x["e_max"].as_f64().unwrap(), want.e_max);
    assert!((x["e_avg"].as_f64().unwrap() - want.e_avg).abs() <= EXACT_REL_TOL * want.e_avg);
    assert!((x["u0"].as_f64().unwrap() - want.u0).abs() <= EXACT_REL_TOL);
    assert!(want.e_min > 0.0, "the floor under the lamp is lit");
    // The work plane: 10 above the floor (y = 0), over z 100..459.2 and x 100..452.8 (3 × 3 cells
    // of at most 120).
    let work = std::fs::read_to_string(dir.path().join("o/grid_work.csv")).unwrap();
    assert!(work.lines().nth(1).unwrap().starts_with("work_0_0,"), "{work}");
    assert_eq!(stats["grids"]["work"]["points"], 9);
    assert!(stats["time_s"]["grids"].as_f64().is_some());
}

#[test]
fn cli_grid_errors_are_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_cli(dir.path(), &["solve", "--grid", "name=x,origin=0;0;0,u=1;0;0,v=2;0;0,spacing=1", "--out", "o"]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&out.stderr).trim_end(), "error: grid `x`: `u` and `v` must be non-zero and not parallel");
    let out = run_cli(dir.path(), &["solve", "--work-plane", "0.8", "--out", "o"]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim_end(),
        "error: --work-plane: no floor: no polygon faces up (+z); choose the up axis with --up"
    );
    assert!(!dir.path().join("o").exists(), "nothing solved or written");
    let out = run_cli(dir.path(), &["solve", "--work-plane", "0.8", "--instances", "auto", "--out", "o"]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim_end(),
        "error: --grid and --work-plane apply to plain scenes, not to --instances auto"
    );
}
