use super::*;
use crate::geom::DVec3;

fn spec() -> GridSpec {
    GridSpec {
        name: "work".into(),
        origin: [0.5, 0.5, 0.8],
        u: [3.0, 0.0, 0.0],
        v: [0.0, 3.0, 0.0],
        spacing: 0.25,
        normal: Some([0.0, 0.0, 1.0]),
    }
}

/// Positions are sums of a few exactly representable steps.
const POS_TOL: f64 = 1e-12;

#[test]
fn points_sit_at_cell_centres_half_a_spacing_in() {
    let g = spec().grid().unwrap();
    assert_eq!((g.n_u, g.n_v, g.points.len()), (12, 12, 144));
    let first = &g.points[0];
    assert_eq!(first.name, "work_0_0");
    assert!((first.position - DVec3::new(0.625, 0.625, 0.8)).length() < POS_TOL);
    assert_eq!(first.normal, DVec3::Z);
    // Row by row along u: index j·n_u + i.
    let p = &g.points[12 * 3 + 5];
    assert_eq!(p.name, "work_5_3");
    assert!((p.position - DVec3::new(0.5 + 5.5 * 0.25, 0.5 + 3.5 * 0.25, 0.8)).length() < POS_TOL);
    let last = g.points.last().unwrap();
    assert!((last.position - DVec3::new(3.375, 3.375, 0.8)).length() < POS_TOL);
    // A side that is not a multiple of the spacing: ⌈1 / 0.3⌉ = 4 cells of 0.25, ⌈0.2 / 0.3⌉ = 1.
    let g = GridSpec { u: [1.0, 0.0, 0.0], v: [0.0, 0.2, 0.0], spacing: 0.3, normal: None, ..spec() }.grid().unwrap();
    assert_eq!((g.n_u, g.n_v), (4, 1));
    let xs: Vec<f64> = g.points.iter().map(|p| p.position.x).collect();
    assert_eq!(xs, vec![0.625, 0.875, 1.125, 1.375]);
    assert!((g.points[0].position.y - 0.6).abs() < POS_TOL);
    // The normal defaults to u × v, and is normalised when given.
    assert_eq!(g.normal, DVec3::Z);
    let g = GridSpec { normal: Some([0.0, 0.0, -5.0]), ..spec() }.grid().unwrap();
    assert_eq!(g.points[7].normal, -DVec3::Z);
    // A slanted parallelogram.
    let g = GridSpec { origin: [0.0; 3], u: [1.0, 0.0, 1.0], v: [0.0, 1.0, 0.0], spacing: 0.5, normal: None, ..spec() }.grid().unwrap();
    assert_eq!((g.n_u, g.n_v), (3, 2));
    assert!((g.normal - DVec3::new(-1.0, 0.0, 1.0).normalize()).length() < POS_TOL);
}

#[test]
fn invalid_specs_say_why() {
    let cases: [(GridSpec, &str); 7] = [
        (GridSpec { spacing: 0.0, ..spec() }, "grid `work`: `spacing` must be positive, found 0"),
        (GridSpec { spacing: f64::NAN, ..spec() }, "grid `work`: `spacing` must be positive, found NaN"),
        (GridSpec { origin: [0.0, f64::INFINITY, 0.0], ..spec() }, "grid `work`: `origin` = [0.0, inf, 0.0] is not finite"),
        (GridSpec { v: [6.0, 0.0, 0.0], ..spec() }, "grid `work`: `u` and `v` must be non-zero and not parallel"),
        (GridSpec { normal: Some([0.0; 3]), ..spec() }, "grid `work`: `normal` must not be zero"),
        (GridSpec { spacing: 1e-3, ..spec() }, "grid `work`: 3000 × 3000 points is more than 1000000: use a larger `spacing`"),
        (GridSpec { name: "a b".into(), ..spec() }, "grid `a b`: name must be letters, digits, `-` or `_`"),
    ];
    for (s, want) in cases {
        assert_eq!(s.validate().unwrap_err().to_string(), want);
    }
}

#[test]
fn grid_argument_round_trips_and_errors_name_the_argument() {
    let s = GridSpec::parse_arg("name=work,origin=0.5;0.5;0.8,u=3;0;0,v=0;3;0,spacing=0.25,normal=0;0;1").unwrap();
    assert_eq!(s, spec());
    let s = GridSpec::parse_arg(" name = w2 , origin=0 0 0, u=1;0;0, v=0;1;0, spacing=0.5").unwrap();
    assert_eq!((s.name.as_str(), s.normal), ("w2", None));
    let cases = [
        ("name=w,origin=0;0;0,u=1;0;0,v=0;1;0", "--grid `name=w,origin=0;0;0,u=1;0;0,v=0;1;0`: missing `spacing`"),
        (
            "name=w,origin=0;0,u=1;0;0,v=0;1;0,spacing=1",
            "--grid `name=w,origin=0;0,u=1;0;0,v=0;1;0,spacing=1`: `origin` needs three numbers separated by `;`, found `0;0`",
        ),
        ("name=w,colour=red", "--grid `name=w,colour=red`: unknown key `colour` (expected name, origin, u, v, spacing, normal)"),
        ("name=w,name=x", "--grid `name=w,name=x`: `name` given twice"),
        ("work", "--grid `work`: expected `key=value`, found `work`"),
        ("name=w,origin=0;0;0,u=1;0;0,v=2;0;0,spacing=1", "grid `w`: `u` and `v` must be non-zero and not parallel"),
    ];
    for (arg, want) in cases {
        assert_eq!(GridSpec::parse_arg(arg).unwrap_err().to_string(), want);
    }
}

#[test]
fn grid_specs_read_from_toml_deny_unknown_fields() {
    let s: GridSpec = toml::from_str(
        "name = \"work\"\norigin = [0.5, 0.5, 0.8]\nu = [3.0, 0.0, 0.0]\nv = [0.0, 3.0, 0.0]\nspacing = 0.25\nnormal = [0.0, 0.0, 1.0]\n",
    )
    .unwrap();
    assert_eq!(s, spec());
    let e = toml::from_str::<GridSpec>("name = \"w\"\norigin = [0, 0, 0]\nu = [1, 0, 0]\nv = [0, 1, 0]\nspacing = 1\nheight = 2\n")
        .unwrap_err();
    assert!(e.message().contains("unknown field `height`"), "{e}");
}

#[test]
fn summary_of_known_values() {
    let s = GridSummary::of(&[100.0, 200.0, 300.0, 400.0]).unwrap();
    assert_eq!(
        s,
        GridSummary {
            points: 4,
            e_avg: 250.0,
            e_min: 100.0,
            e_max: 400.0,
            u0: 0.4,
            min_over_max: 0.25,
            e_err_max: None,
            daylight_factor: None
        }
    );
    assert_eq!(s.with_errors(&[1.0, 3.0, 2.0, 0.5]).e_err_max, Some(3.0));
    assert_eq!(s.with_errors(&[1.0, f64::NAN]).e_err_max, None);
    let dark = GridSummary::of(&[0.0, 0.0]).unwrap();
    assert_eq!((dark.u0, dark.min_over_max), (0.0, 0.0));
    assert_eq!(GridSummary::of(&[]), None);
    assert_eq!(GridSummary::of(&[1.0, f64::NAN]), None);
    assert_eq!(photopic_column(Units::Photometric), "e_lx");
    assert_eq!(photopic_column(Units::Radiometric), "h_photopic");
}

/// Daylight factors by hand: 20 points of 10, 20, ..., 200 lx under an outside 10,000 lx are
/// 0.1, 0.2, ..., 2.0%; half of them reach 1.1% (the 10th largest), 95% reach 0.2% (the 19th).
#[test]
fn daylight_factor_figures_by_hand() {
    let values: Vec<f64> = (1..=20).rev().map(|k| 10.0 * f64::from(k)).collect();
    let errors = vec![1.0; 20];
    let s = GridSummary::of(&values).unwrap().with_daylight_factor(&values, &errors, 10_000.0);
    let df = s.daylight_factor.expect("figures");
    let near = |a: f64, b: f64| (a - b).abs() < 1e-12;
    assert!(near(df.median, 1.1) && near(df.over_95, 0.2) && near(df.min, 0.1) && near(df.max, 2.0), "{df:?}");
    assert!(near(df.mean, 1.05) && near(df.outside, 10_000.0) && df.err_max.is_some_and(|e| near(e, 0.01)), "{df:?}");
    // Three points: half is two of them, 95% all three.
    let s = GridSummary::of(&[3.0, 1.0, 2.0]).unwrap().with_daylight_factor(&[3.0, 1.0, 2.0], &[f64::NAN; 3], 100.0);
    let df = s.daylight_factor.unwrap();
    assert!(near(df.median, 2.0) && near(df.over_95, 1.0) && df.err_max.is_none(), "{df:?}");
    assert_eq!(GridSummary::of(&[1.0]).unwrap().with_daylight_factor(&[1.0], &[0.0], 0.0).daylight_factor, None);
}

#[test]
fn en12464_spacing_formula() {
    // p = 0.2 · 5^log10(d): 0.2 m at d = 1 m, 1 m at d = 10 m, 5 m at d = 100 m (capped at 10 m).
    for (d, p) in [(1.0, 0.2), (10.0, 1.0), (100.0, 5.0), (1e4, 10.0)] {
        assert!((en12464_spacing(d) - p).abs() < 1e-12, "d {d}: {}", en12464_spacing(d));
    }
}

#[test]
fn work_plane_over_the_floor_less_the_border() {
    use crate::scene::{Material, SceneBuilder};
    // A 6 × 4 room, z up, floor at z = 0.1, with a table top (facing up, higher) that is not floor.
    let mut b = SceneBuilder::new(std::path::Path::new("room"), "room");
    let m = b.material(Material::diffuse("grey", [0.5; 3])).unwrap();
    let g = b.group("g");
    let quad = |x0: f64, x1: f64, y0: f64, y1: f64, z: f64| {
        [x0, x1, x1, x0].iter().zip([y0, y0, y1, y1]).map(|(&x, y)| DVec3::new(x, y, z)).collect::<Vec<_>>()
    };
    b.face(&quad(0.0, 3.0, 0.0, 4.0, 0.1), m, g, 1).unwrap();
    b.face(&quad(3.0, 6.0, 0.0, 4.0, 0.1), m, g, 2).unwrap();
    b.face(&quad(1.0, 2.0, 1.0, 2.0, 0.9), m, g, 3).unwrap();
    let mut ceiling = quad(0.0, 6.0, 0.0, 4.0, 3.0);
    ceiling.reverse();
    b.face(&ceiling, m, g, 4).unwrap();
    let scene = b.finish();
    let s = work_plane(&scene, 0.8, UpAxis::Z, EN12464_BORDER_M, None).unwrap();
    assert_eq!(s.name, "work");
    assert_eq!(s.origin, [0.5, 0.5, 0.9]);
    assert_eq!((s.u, s.v, s.normal), ([5.0, 0.0, 0.0], [0.0, 3.0, 0.0], Some([0.0, 0.0, 1.0])));
    assert!((s.spacing - en12464_spacing(5.0)).abs() < 1e-15);
    // With y up nothing faces up; a border that leaves nothing.
    assert_eq!(
        work_plane(&scene, 0.8, UpAxis::Y, 0.5, None).unwrap_err().to_string(),
        "--work-plane: no floor: no polygon faces up (+y); choose the up axis with --up"
    );
    assert_eq!(
        work_plane(&scene, 0.8, UpAxis::Z, 2.0, Some(0.5)).unwrap_err().to_string(),
        "--work-plane: the floor is 6 × 4 (at z = 0.1): no room inside a border zone of 2"
    );
}

const SCENE_WITH_GRIDS: &str = r#"
[[material]]
name = "wall"
reflectance = 0.5

[[box]]
min = [0, 0, 0]
max = [4, 4, 3]
material = "wall"
inward = true

[[grid]]
name = "work"
origin = [0.5, 0.5, 0.8]
u = [3.0, 0.0, 0.0]
v = [0.0, 3.0, 0.0]
spacing = 0.25
normal = [0.0, 0.0, 1.0]

[[grid]]
name = "wall"
origin = [0.0, 0.0, 0.0]
u = [0.0, 4.0, 0.0]
v = [0.0, 0.0, 3.0]
spacing = 0.5
"#;

fn parse_scene(text: &str) -> Result<crate::instancing::InstancedScene, String> {
    crate::instancing::parse(text, std::path::Path::new("scene.toml"), std::path::Path::new(".")).map_err(|e| e.to_string())
}

#[test]
fn scene_files_carry_their_grids() {
    let s = parse_scene(SCENE_WITH_GRIDS).unwrap();
    assert_eq!(s.grids.len(), 2);
    assert_eq!(s.grids[0], spec());
    assert_eq!(s.grids[1].grid().unwrap().normal, DVec3::X);
    // Written and read back.
    let dir = std::env::temp_dir().join(format!("radiosity-grid-roundtrip-{}", std::process::id()));
    let path = crate::instancing::write_scene(&s, &dir, "s").unwrap();
    let back = crate::instancing::load(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(back.grids, s.grids);
    // Errors name the line of the grid.
    let bad = SCENE_WITH_GRIDS.replace("spacing = 0.5", "spacing = -1");
    assert_eq!(parse_scene(&bad).unwrap_err(), "scene.toml:20: grid `wall`: `spacing` must be positive, found -1");
    let dup = SCENE_WITH_GRIDS.replace("name = \"wall\"\norigin", "name = \"work\"\norigin");
    assert_eq!(parse_scene(&dup).unwrap_err(), "scene.toml:20: duplicate grid `work`");
    let unknown = SCENE_WITH_GRIDS.replace("spacing = 0.5", "spacing = 0.5\nheight = 1");
    assert!(parse_scene(&unknown).unwrap_err().starts_with("scene.toml:"), "{}", parse_scene(&unknown).unwrap_err());
}
