//! Accuracy against exact and independently computed answers (`radiosity::validation`): Ward's
//! 1990 room at the default settings, CIE 171:2006 test case 5.8, a closed room lit by a tiny, very
//! bright source near a corner, furnaces (six quads at ρ = 0.995, slivers), the power balance of
//! closed rooms lit by tiny bright sources at their centre, near a corner and among furniture, and
//! the error estimate against the true error.

use radiosity::pipeline::{self, Config, Solved};
use radiosity::refine::{BfHand, BfParams};
use radiosity::scene::Scene;
use radiosity::validation::{self, LampPlace, scenes};

/// Tolerance of Ward's surface-class means at the default settings (the bar).
const WARD_CLASS_TOL: f64 = 0.01;
/// Tolerance of the CIE 5.8 walls' mean (the bar).
const CIE58_MEAN_TOL: f64 = 0.005;
/// Tolerance of the power balance of a closed scene (the bar).
const BALANCE_TOL: f64 = 0.005;
/// Tolerance of Ward's calculation points at the default settings (the bar).
const WARD_POINT_TOL: f64 = 0.01;
/// The reference points' own uncertainty (constant elements with exact form factors on three
/// meshes, Richardson-extrapolated: within 0.2%, as shipped with them).
const WARD_POINT_REFERENCE_TOL: f64 = 0.002;
/// Share of the points whose true error is within their estimated error (plus the reference's
/// own): the bar; measured 480 of 480 with and without importance rounds.
const POINT_ESTIMATE_COVER: f64 = 0.95;
/// The worst point's estimate, at most this times its true error (measured 2.2 with the
/// importance rounds of the default settings).
const POINT_ESTIMATE_MAX_RATIO: f64 = 3.0;
/// The default target error of `radiosity solve`.
const DEFAULT_TARGET: f64 = 0.01;

fn solve_eps(scene: &Scene, eps: f64) -> Solved {
    pipeline::run(scene, &BfHand { params: BfParams { eps } }, &Config::default(), &|_| {})
}

fn solve_default(scene: &Scene) -> Solved {
    let config = Config { target_error: Some(DEFAULT_TARGET), ..Config::default() };
    pipeline::run(scene, &BfHand::default(), &config, &|_| {})
}

fn means(solved: &Solved) -> Vec<[f64; 3]> {
    radiosity::output::polygon_results(&solved.hierarchy, &solved.solution).into_iter().map(|r| r.b).collect()
}

fn balance(solved: &Solved) -> f64 {
    let (emitted, absorbed, _) = radiosity::output::power_balance(&solved.hierarchy, &solved.lights, &solved.solution);
    absorbed / emitted
}

fn case(name: &str) -> validation::Case {
    validation::cases().into_iter().find(|c| c.name == name).expect("a validation case")
}

/// Ward's room, as `radiosity solve` solves it by default (target error 1%): the floor, ceiling and
/// walls means within 1% of the published reference (`reference/globillum1990_room.md`), and the
/// estimate not below the true error.
#[test]
fn ward_room_class_means_within_one_percent_at_the_default_settings() {
    let c = case("ward-room");
    let solved = solve_default(&c.scene);
    let results = radiosity::output::polygon_results(&solved.hierarchy, &solved.solution);
    for (class, reference) in [("floor", 0.033361), ("ceiling", 0.022187), ("wall", 0.027126)] {
        let (mut sum, mut area) = (0.0, 0.0);
        for (p, r) in c.scene.polygons.iter().zip(&results) {
            if c.scene.materials[p.material as usize].name == class {
                sum += r.area * r.b[0];
                area += r.area;
            }
        }
        let err = sum / area / reference - 1.0;
        assert!(
            err.abs() <= WARD_CLASS_TOL,
            "{class}: {:+.3}% ({} levels, {} links)",
            100.0 * err,
            solved.levels.len(),
            solved.links.len()
        );
    }
    let truth = validation::true_error(&c.reference, &means(&solved));
    let estimate = solved.error_estimate.expect("estimated");
    assert!(estimate <= DEFAULT_TARGET, "the target was reached: {estimate}");
    assert!(estimate >= truth, "estimate {estimate:.3e} below the true error {truth:.3e}");
    assert!((balance(&solved) - 1.0).abs() <= 1e-6, "closed room: balance {}", balance(&solved));
}

/// The shipped reference of Ward's room reproduces the published surface means
/// (`reference/globillum1990_room.md`, h = 0.25: floor 0.033361, ceiling 0.022187, walls 0.027126)
/// within the reference's stated 0.05%, and so does the dense solver that made it, on a coarse mesh
/// (h = 1 m, 270 patches) within 1%.
#[test]
fn ward_reference_matches_the_published_means() {
    let scene = scenes::ward_room();
    let shipped = validation::reference_means(validation::WARD_ROOM_CSV, "ward-room");
    let dense = validation::dense::DenseSystem::new(&scene, 1.0);
    let (rho, e) = validation::dense::materials(&scene);
    let coarse = dense.polygon_means(&rho, &e);
    for (class, published) in [("floor", 0.033361), ("ceiling", 0.022187), ("wall", 0.027126)] {
        let (mut s_ref, mut s_dense, mut area) = (0.0, 0.0, 0.0);
        for (i, p) in scene.polygons.iter().enumerate() {
            if scene.materials[p.material as usize].name == class {
                let a = p.poly.area();
                s_ref += a * shipped[i];
                s_dense += a * coarse[i][0];
                area += a;
            }
        }
        let (r, d) = (s_ref / area / published - 1.0, s_dense / area / published - 1.0);
        assert!(r.abs() <= 5e-4, "{class}: shipped reference {:+.4}%", 100.0 * r);
        assert!(d.abs() <= 1e-2, "{class}: dense h = 1 {:+.3}%", 100.0 * d);
    }
    assert!(dense.row_sums().iter().all(|s| (s - 1.0).abs() < 1e-8), "a closed room's form factors sum to 1");
}

/// The error of Ward's room falls as eps falls (true errors, not estimates).
#[test]
fn ward_room_error_falls_with_eps() {
    let c = case("ward-room");
    let errors: Vec<f64> =
        [0.04, 0.0025, 0.000625].iter().map(|&eps| validation::true_error(&c.reference, &means(&solve_eps(&c.scene, eps)))).collect();
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "errors {errors:?}");
}

/// CIE 171:2006 test case 5.8 (a closed 4 m cube, a 10,000 lm source at its centre): the walls'
/// mean indirect illuminance is `ρΦ / (S_T (1 − ρ))`, so their mean radiosity is known exactly
/// (`validation::scenes::cie58_wall_mean`); within 0.5% at ρ from 0.3 to 0.95, power balanced.
#[test]
fn cie58_walls_mean_within_half_a_percent() {
    for rho in [0.3, 0.7, 0.95] {
        let scene = scenes::cie58_cube(rho);
        let solved = solve_default(&scene);
        let results = radiosity::output::polygon_results(&solved.hierarchy, &solved.solution);
        let (mut sum, mut area) = (0.0, 0.0);
        for (p, r) in scene.polygons.iter().zip(&results) {
            if scene.materials[p.material as usize].name == "wall" {
                sum += r.area * r.b[0];
                area += r.area;
            }
        }
        let mean = sum / area;
        let exact = scenes::cie58_wall_mean(rho);
        // The indirect illuminance of CIE's table, from the mean radiosity: E_ind = B/ρ − Φ/S_T.
        let indirect = mean / rho - scenes::CIE58_FLUX / (6.0 * scenes::CIE58_SIDE * scenes::CIE58_SIDE);
        let table = scenes::cie58_indirect_illuminance(rho);
        assert!((mean / exact - 1.0).abs() <= CIE58_MEAN_TOL, "rho {rho}: walls' mean {mean} vs {exact}");
        assert!((indirect / table - 1.0).abs() <= 2.0 * CIE58_MEAN_TOL / (1.0 - rho).max(0.1), "rho {rho}: E_ind {indirect} vs {table}");
        assert!((balance(&solved) - 1.0).abs() <= BALANCE_TOL, "rho {rho}: balance {}", balance(&solved));
    }
}

/// A closed room lit by one tiny, very bright source (5 cm, 1 kW) near a corner, at ρ 0.3, 0.7,
/// 0.95, against the dense reference: the default solve within 1% of the largest mean, the estimate
/// not below the true error, the power balanced.
#[test]
fn tiny_bright_source_near_a_corner() {
    for name in ["corner-room-rho0.3", "corner-room-rho0.7", "corner-room-rho0.95"] {
        let c = case(name);
        let solved = solve_default(&c.scene);
        let truth = validation::true_error(&c.reference, &means(&solved));
        let estimate = solved.error_estimate.expect("estimated");
        assert!(truth <= DEFAULT_TARGET, "{name}: true error {truth:.3e}");
        assert!(estimate >= truth, "{name}: estimate {estimate:.3e} below the true error {truth:.3e}");
        assert!((balance(&solved) - 1.0).abs() <= BALANCE_TOL, "{name}: balance {}", balance(&solved));
    }
}

/// Local levels (the default) refine, from the third level on, only the polygons over half the
/// target and those that light them: fewer links than refining every polygon at every level, with
/// the estimate still not below the true error and the target still met (Ward's room: 2,779
/// links for 3,331; the corner room of ρ 0.3: 2,875 for 4,627, 2026-12-06). A local level
/// examines again only the links whose thresholds it tightened, and keeps the others as they were.
#[test]
fn local_levels_take_fewer_links_and_stay_honest() {
    for name in ["ward-room", "corner-room-rho0.3", "corner-room-rho0.7", "corner-room-rho0.95"] {
        let c = case(name);
        let mut links = Vec::new();
        for local_levels in [true, false] {
            let config = Config { target_error: Some(DEFAULT_TARGET), local_levels, ..Config::default() };
            let solved = pipeline::run(&c.scene, &BfHand::default(), &config, &|_| {});
            let truth = validation::true_error(&c.reference, &means(&solved));
            let estimate = solved.error_estimate.expect("estimated");
            assert!(truth <= DEFAULT_TARGET, "{name} local {local_levels}: true error {truth:.3e}");
            assert!(estimate >= truth, "{name} local {local_levels}: estimate {estimate:.3e} below the true error {truth:.3e}");
            links.push(solved.links.len());
            if local_levels {
                let mut local = 0;
                for w in solved.levels.windows(2).filter(|w| w[1].polygons_refined.is_some()) {
                    let (before, level) = (&w[0], &w[1]);
                    assert!(level.links_kept_unexamined < before.links, "{name}: {level:?}");
                    local += usize::from(level.links_kept_unexamined > 0);
                }
                assert!(local > 0, "{name}: no local level kept a link unexamined");
            }
        }
        assert!(links[0] < links[1], "{name}: local levels {} links, global {}", links[0], links[1]);
    }
}

/// Closed rooms lit by a tiny, very bright lamp (3 cm, 1 kW) at the room's centre, near a corner and
/// among furniture (a table and four chairs, which occlude): absorbed = emitted within 0.5% at every
/// eps, the coarsest included, for ρ from 0.3 to 0.95.
#[test]
fn tiny_bright_lamps_in_closed_rooms_balance_at_every_eps() {
    for place in [LampPlace::Centre, LampPlace::Corner, LampPlace::AmongFurniture] {
        for rho in [0.3, 0.95] {
            let scene = scenes::furnished_room(place, rho);
            for eps in [0.5, 0.04] {
                let solved = solve_eps(&scene, eps);
                assert!(solved.closed, "{place:?}: the room is closed (escape {})", solved.escape_fraction);
                let b = balance(&solved);
                assert!((b - 1.0).abs() <= BALANCE_TOL, "{place:?} rho {rho} eps {eps}: balance {b}");
            }
        }
    }
}

/// A closed six-quad furnace at ρ = 0.995 (exact answer `B = E/(1 − ρ)` everywhere): exact to 0.1%
/// with at most 10,000 links (30: uniform sources are never subdivided).
#[test]
fn stiff_furnace_exact_with_few_links() {
    let c = case("furnace-cube-rho0.995");
    let solved = solve_default(&c.scene);
    let err = validation::true_error(&c.reference, &means(&solved));
    assert!(err <= 1e-3, "error {err}");
    assert!(solved.links.len() <= 10_000, "{} links", solved.links.len());
}

/// A furnace of 150 sliver triangles (aspect ratio up to 12): exact.
#[test]
fn sliver_furnace_is_exact() {
    let scene = scenes::sliver_furnace(0.9, 25);
    let solved = solve_eps(&scene, 0.01);
    let exact = 1.0 / (1.0 - 0.9);
    let worst = means(&solved).iter().map(|m| (m[0] / exact - 1.0).abs()).fold(0.0, f64::max);
    assert!(worst <= 1e-4, "worst polygon off by {worst}");
}

/// The error estimate is not below the true error on the validation scenes, at several eps; at 0.64
/// most polygons are left whole (Ward's room: 13 leaves for 10 polygons, true error 7.6%), which
/// the coarser meshes do not show (the estimate said 0.001% before it counted them).
#[test]
fn estimate_is_not_below_the_true_error() {
    for c in validation::cases() {
        for eps in [0.64, 0.04, 0.01, 0.0025] {
            let solved = solve_eps(&c.scene, eps);
            let truth = validation::true_error(&c.reference, &means(&solved));
            let estimate = solved.error_estimate.expect("estimated");
            assert!(estimate >= truth, "{} eps {eps}: estimate {estimate:.3e} below the true error {truth:.3e}", c.name);
        }
    }
}

/// A memory budget far below what refinement wants stops it with a warning instead of growing.
#[test]
fn memory_budget_stops_refinement_with_a_warning() {
    let c = case("ward-room");
    let config = Config { max_memory_bytes: 200_000, ..Config::default() };
    let solved = pipeline::run(&c.scene, &BfHand { params: BfParams { eps: 1e-4 } }, &config, &|_| {});
    assert!(solved.memory_limited, "the budget was reached");
    assert!(solved.warnings.iter().any(|w| w.contains("memory budget")), "{:?}", solved.warnings);
    let bytes = solved.hierarchy.len() * radiosity::refine::BYTES_PER_ELEMENT + solved.links.len() * radiosity::refine::BYTES_PER_LINK;
    assert!(bytes <= 4 * config.max_memory_bytes, "refinement stopped near the budget: {bytes} bytes");
}

/// Calculation points at Ward's reference points (`surface, x, y, B`): on the floor facing up, on
/// the ceiling (3 m) facing down.
fn ward_calc_points(reference: &[(String, f64, f64, f64)]) -> Vec<radiosity::points::CalcPoint> {
    use radiosity::geom::DVec3;
    reference
        .iter()
        .map(|(surface, x, y, _)| {
            let (z, n) = if surface == "floor" { (0.0, DVec3::Z) } else { (3.0, -DVec3::Z) };
            radiosity::points::CalcPoint::new(format!("{surface} {x} {y}"), DVec3::new(*x, *y, z), n).expect("finite point")
        })
        .collect()
}

/// Ward's room's 480 calculation points (`reference_points.csv`, radiosity `ρ H` on the floor and
/// ceiling), solved as `radiosity solve --points` solves them at the default settings: once the
/// polygon means meet the target, importance rounds refine where the points' estimated errors come
/// from (`pipeline::run_with_points`), until each point's, relative to its own value, is within
/// the target. Every point within [`WARD_POINT_TOL`] of the reference; each point's estimated
/// error (`h_err`) covers its true error, and the worst point's is at most
/// [`POINT_ESTIMATE_MAX_RATIO`] times it. Measured 2026-12-05: worst 0.31% (ceiling corner),
/// estimated 0.69% there, 480 of 480 covered, 3 rounds, 14 s; without the rounds the worst point
/// was 2.6% off (room corners: a point 0.25 m from two walls sees their leaves at the corner most).
#[test]
fn ward_room_points_within_one_percent_at_the_default_settings() {
    let c = case("ward-room");
    let reference = validation::ward_room_points();
    assert_eq!(reference.len(), 480);
    let points = ward_calc_points(&reference);
    let config = Config { target_error: Some(DEFAULT_TARGET), ..Config::default() };
    let solved = pipeline::run_with_points(&c.scene, &BfHand::default(), &config, &[&points], &|_| {});
    let report = solved.importance.expect("the points asked for importance rounds");
    assert!(report.met && report.rounds > 0, "{report:?}");
    let got = &solved.point_results[0];
    let (mut worst, mut worst_estimate, mut covered): (f64, f64, usize) = (0.0, 0.0, 0);
    for ((surface, x, y, b_ref), h) in reference.iter().zip(got) {
        let rho = if surface == "floor" { 0.3 } else { 0.7 };
        let err = rho * h.h[0] / b_ref - 1.0;
        assert!(err.abs() <= WARD_POINT_TOL, "{surface} ({x}, {y}): {:+.2}%", 100.0 * err);
        // The point's own estimated error, relative to its value as `err` is.
        let estimate = rho * h.h_err[0] / b_ref;
        assert!(estimate <= DEFAULT_TARGET + WARD_POINT_REFERENCE_TOL, "{surface} ({x}, {y}): estimate {estimate}");
        covered += usize::from(estimate + WARD_POINT_REFERENCE_TOL >= err.abs());
        if err.abs() > worst {
            (worst, worst_estimate) = (err.abs(), estimate);
        }
    }
    eprintln!(
        "Ward's 480 points: worst {:.2}%, estimated {:.2}% there; {covered} points within their estimate; {report:?}",
        100.0 * worst,
        100.0 * worst_estimate
    );
    assert!(covered as f64 >= POINT_ESTIMATE_COVER * 480.0, "{covered} of 480 points within their estimated error");
    assert!(
        worst_estimate >= worst - WARD_POINT_REFERENCE_TOL && worst_estimate <= POINT_ESTIMATE_MAX_RATIO * worst,
        "the worst point's estimate {worst_estimate} against its error {worst}"
    );
}

/// Without importance (`pipeline::run`, points gathered after the solve), each point's estimated
/// error still covers its true error: measured 480 of 480, the worst point 2.6% off (a room
/// corner) for an estimate of 4.8% there.
#[test]
fn ward_room_point_estimates_cover_their_errors_without_importance() {
    use radiosity::points::{PointsConfig, gather};
    let c = case("ward-room");
    let solved = solve_default(&c.scene);
    assert!(solved.importance.is_none() && solved.point_results.is_empty());
    let reference = validation::ward_room_points();
    let points = ward_calc_points(&reference);
    let got = gather(&solved, &points, &PointsConfig::default());
    let mut covered = 0;
    for ((surface, _, _, b_ref), h) in reference.iter().zip(&got) {
        let rho = if surface == "floor" { 0.3 } else { 0.7 };
        let err = (rho * h.h[0] / b_ref - 1.0).abs();
        covered += usize::from(rho * h.h_err[0] / b_ref + WARD_POINT_REFERENCE_TOL >= err);
    }
    assert!(covered as f64 >= POINT_ESTIMATE_COVER * 480.0, "{covered} of 480 points within their estimated error");
}

/// The target steers the work: Ward's room at a target of 0.1 stops at a coarser level than at
/// 0.01 (637 and 3,331 links, 2026-12-04; both stopped at 3,331 before the estimate capped its
/// factor on a polygon's change), and meets its own target against the reference, with an
/// estimate not below the true error.
#[test]
fn a_coarse_target_stops_at_a_coarse_level_and_meets_itself() {
    let c = case("ward-room");
    let run =
        |target: f64| pipeline::run(&c.scene, &BfHand::default(), &Config { target_error: Some(target), ..Config::default() }, &|_| {});
    let (coarse, fine) = (run(0.1), run(0.01));
    assert!(2 * coarse.links.len() < fine.links.len(), "{} links at 0.1, {} at 0.01", coarse.links.len(), fine.links.len());
    assert!(coarse.target_missed.is_none(), "{:?}", coarse.target_missed);
    let estimate = coarse.error_estimate.expect("estimated");
    let truth = validation::true_error(&c.reference, &means(&coarse));
    assert!(estimate <= 0.1 && truth <= estimate, "estimate {estimate:.3e}, true error {truth:.3e}");
}

/// Ward's room with the two full-height partitions of its "obstructed" variant (x 3–3.1, y 3–6 and
/// x 7–7.1, y 0–3), which cover pieces of the floor and ceiling: the closure makes up for the
/// covered parts with factors far from 1, which are geometry and not an error of the links, so the
/// estimate does not count them and the default target is met (counting the covers kept it
/// refining to 8.8M links and 175 s). Measured 2026-12-06: five levels, 3.75M links, estimate
/// 0.78%, 86 s; the fourth level (891k links) moved a polygon mean by 1.6% of the largest, which
/// the estimate's floor on the last level's change (`solve::LEVEL_CHANGE_SAFETY`) does not let
/// pass for 1% (it stopped there at 0.38% before the floor).
#[test]
fn partitions_standing_on_the_floor_do_not_stall_the_estimate() {
    use radiosity::geom::DVec3;
    use radiosity::scene::{Material, SceneBuilder, shapes::box_faces};
    let mut b = SceneBuilder::new(std::path::Path::new("obstructed"), "obstructed");
    let grey = |b: &mut SceneBuilder, name: &str, rho: f64| b.material(Material::diffuse(name, [rho; 3])).unwrap();
    let (floor, ceiling, wall) = (grey(&mut b, "floor", 0.3), grey(&mut b, "ceiling", 0.7), grey(&mut b, "wall", 0.5));
    let source = b.material(Material { emission: [31.416; 3], ..Material::diffuse("source", [0.0; 3]) }).unwrap();
    let g = b.group("room");
    let quad = |x0: f64, x1: f64, y0: f64, y1: f64, z: f64, up: bool| {
        let v = [DVec3::new(x0, y0, z), DVec3::new(x1, y0, z), DVec3::new(x1, y1, z), DVec3::new(x0, y1, z)];
        if up { v } else { [v[0], v[3], v[2], v[1]] }
    };
    b.face(&quad(0.0, 10.0, 0.0, 6.0, 0.0, true), floor, g, 0).unwrap();
    for (x0, x1, y0, y1) in [(0.0, 10.0, 0.0, 2.75), (0.0, 10.0, 3.25, 6.0), (0.0, 4.75, 2.75, 3.25), (5.25, 10.0, 2.75, 3.25)] {
        b.face(&quad(x0, x1, y0, y1, 3.0, false), ceiling, g, 0).unwrap();
    }
    b.face(&quad(4.75, 5.25, 2.75, 3.25, 3.0, false), source, g, 0).unwrap();
    for (name, q) in box_faces(DVec3::ZERO, DVec3::new(10.0, 6.0, 3.0), true) {
        if !name.starts_with('z') {
            b.face(&q, wall, g, 0).unwrap();
        }
    }
    for (lo, hi) in [(DVec3::new(3.0, 3.0, 0.0), DVec3::new(3.1, 6.0, 3.0)), (DVec3::new(7.0, 0.0, 0.0), DVec3::new(7.1, 3.0, 3.0))] {
        for (name, q) in box_faces(lo, hi, false) {
            if !name.starts_with('z') {
                b.face(&q, wall, g, 0).unwrap();
            }
        }
    }
    let solved = solve_default(&b.finish());
    let estimate = solved.error_estimate.expect("estimated");
    eprintln!("obstructed room: {} links, estimate {:.2}%", solved.links.len(), 100.0 * estimate);
    assert!(solved.target_missed.is_none() && estimate <= DEFAULT_TARGET, "estimate {estimate}: {:?}", solved.target_missed);
    assert!(solved.links.len() <= 5_000_000, "{} links", solved.links.len());
}

/// Importance goes where the points are: Ward's room with only the reference points of one
/// corner (x, y ≤ 1.25 m, floor and ceiling) multiplies the leaves near that corner's edge (within
/// 2.5 m) at least twice as much as those far from it (beyond 6 m), and those points are each
/// within [`WARD_POINT_TOL`] of the reference, within their estimates. Measured 2026-12-05: 98 ->
/// 1,132 leaves near, 494 -> 2,269 far (the corner's links are tightened up to the polygons they
/// start from, and the oracle splits their far sources too), 3 rounds, 4.3 s, the 18 points within
/// 0.27%.
#[test]
fn importance_refines_near_the_points_only() {
    let c = case("ward-room");
    let corner: Vec<(String, f64, f64, f64)> =
        validation::ward_room_points().into_iter().filter(|(_, x, y, _)| *x <= 1.25 && *y <= 1.25).collect();
    assert_eq!(corner.len(), 18);
    let points = ward_calc_points(&corner);
    let config = Config { target_error: Some(DEFAULT_TARGET), ..Config::default() };
    let with = pipeline::run_with_points(&c.scene, &BfHand::default(), &config, &[&points], &|_| {});
    let without = solve_default(&c.scene);
    let report = with.importance.expect("importance rounds");
    assert!(report.met && report.rounds > 0 && report.leaves_split > 0, "{report:?}");
    for ((surface, x, y, b_ref), h) in corner.iter().zip(&with.point_results[0]) {
        let rho = if surface == "floor" { 0.3 } else { 0.7 };
        let err = (rho * h.h[0] / b_ref - 1.0).abs();
        let estimate = rho * h.h_err[0] / b_ref;
        assert!(err <= WARD_POINT_TOL, "{surface} ({x}, {y}): {:.2}%", 100.0 * err);
        assert!(err <= estimate + WARD_POINT_REFERENCE_TOL, "{surface} ({x}, {y}): {err} for an estimate of {estimate}");
    }
    // Leaves of every surface near the corner's vertical edge and far from it.
    let count = |s: &Solved, near: bool| {
        let h = &s.hierarchy;
        h.leaves()
            .map(|l| h.get(l).center)
            .filter(|c| {
                let d = (c.x * c.x + c.y * c.y).sqrt();
                if near { d < 2.5 } else { d > 6.0 }
            })
            .count() as f64
    };
    let (near, far) = ((count(&without, true), count(&with, true)), (count(&without, false), count(&with, false)));
    eprintln!("corner leaves {} -> {}, far {} -> {}; {report:?}", near.0, near.1, far.0, far.1);
    assert!(near.1 / near.0 >= 2.0 * (far.1 / far.0), "the corner's leaves {} -> {}, the far ones' {} -> {}", near.0, near.1, far.0, far.1);
}
