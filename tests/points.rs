//! Calculation points (`radiosity::points`, `solve --points`) against exact answers: the CIE
//! 171:2006 analytic cases 5.3, 5.6 and 5.7 (the published values, recomputed by Lambert's
//! contour formula), the shadow-edge accuracy of the adaptive visibility, points on a
//! surface with light behind it, and the command line end to end.

use radiosity::formfactor::{clip_to_halfspace, point_polygon, point_polygon_unclipped};
use radiosity::geom::DVec3;
use radiosity::hierarchy::{self, BuildConfig};
use radiosity::pipeline::{self, Config, Solved};
use radiosity::points::{self, CalcPoint, PointGather, PointIrradiance, PointsConfig, SHADOW_EDGE_REL_ERROR};
use radiosity::refine::BfHand;
use radiosity::scene::{Material, Scene, SceneBuilder};
use radiosity::visibility::{RayCaster, Rng};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

#[path = "support/cie171.rs"]
mod cie171;

/// The CIE values in `cie171.md` are printed with 3 decimals: a gather exact up to rounding is
/// within half of the last digit.
const REFERENCE_ROUNDING: f64 = 5e-4;
/// CIE 5.3 bar from the reference file: 0.5% at every point.
const CIE_53_REL_TOL: f64 = 5e-3;
/// The project's aim for the obstruction case 5.7 (its bar is 2%).
const CIE_57_REL_TOL: f64 = 1e-2;
/// Fully shadowed points (5.7 J, K) and light from behind a surface: no more than this (W/m² for
/// emitters of 100 W/m²).
const DARK_BOUND: f64 = 1e-12;
/// Gathers that involve no partial visibility are exact up to rounding.
const EXACT_REL_TOL: f64 = 1e-9;

/// A test scene in the CIE cases' frame (x, y horizontal, z up, metres).
struct Room {
    b: SceneBuilder,
    black: u32,
}

impl Room {
    fn new(name: &str) -> Room {
        let mut b = SceneBuilder::new(Path::new(name), name);
        let black = b.material(Material::diffuse("black", [0.0; 3])).expect("valid material");
        Room { b, black }
    }

    /// A black-bodied emitter material of exitance `e` (W/m² per channel).
    fn emitter(&mut self, name: &str, e: f64) -> u32 {
        let mut m = Material::diffuse(name, [0.0; 3]);
        m.emission = [e; 3];
        self.b.material(m).expect("valid material")
    }

    /// The quad `corners` (in cyclic order), wound so that its front faces `facing`.
    fn quad(&mut self, corners: [[f64; 3]; 4], facing: [f64; 3], material: u32) {
        let mut v = corners.map(DVec3::from);
        let newell: DVec3 = (0..4).map(|i| v[i].cross(v[(i + 1) % 4])).sum();
        if newell.dot(DVec3::from(facing)) < 0.0 {
            v.reverse();
        }
        let g = self.b.group("g");
        self.b.face(&v, material, g, 0).expect("valid quad");
    }

    /// The axis-aligned rectangle `[x0, x1] × [y0, y1]` at height `z`.
    fn xy(&mut self, (x0, x1): (f64, f64), (y0, y1): (f64, f64), z: f64, facing_z: f64, material: u32) {
        self.quad([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], [0.0, 0.0, facing_z], material);
    }

    /// The rectangle `[x0, x1] × [z0, z1]` in the plane `y`.
    fn xz(&mut self, (x0, x1): (f64, f64), (z0, z1): (f64, f64), y: f64, facing_y: f64, material: u32) {
        self.quad([[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]], [0.0, facing_y, 0.0], material);
    }

    /// The rectangle `[y0, y1] × [z0, z1]` in the plane `x`.
    fn yz(&mut self, (y0, y1): (f64, f64), (z0, z1): (f64, f64), x: f64, facing_x: f64, material: u32) {
        self.quad([[x, y0, z0], [x, y1, z0], [x, y1, z1], [x, y0, z1]], [facing_x, 0.0, 0.0], material);
    }

    fn finish(self) -> Scene {
        self.b.finish()
    }
}

/// Solves `scene` with the default BF oracle, the analysis on or off.
fn solve(scene: &Scene, analyse: bool) -> Solved {
    let config = Config { analyse, ..Config::default() };
    pipeline::run(scene, &BfHand::default(), &config, &|_| {})
}

fn point(name: &str, x: [f64; 3], n: [f64; 3]) -> CalcPoint {
    CalcPoint::new(name, DVec3::from(x), DVec3::from(n)).expect("valid point")
}

/// The CIE measurement points: on the wall y = 0 at x = 2 (normal +y, heights `wall_z`) and on a
/// horizontal surface at height `floor_z` (normal `floor_nz`) at x = 2 (`floor_y`), with their
/// exact values.
fn cie_points(wall: &[(&str, f64, f64)], floor: &[(&str, f64, f64)], floor_z: f64, floor_nz: f64) -> (Vec<CalcPoint>, Vec<f64>) {
    let mut pts = Vec::new();
    let mut exact = Vec::new();
    for &(name, z, v) in wall {
        pts.push(point(name, [2.0, 0.0, z], [0.0, 1.0, 0.0]));
        exact.push(v);
    }
    for &(name, y, v) in floor {
        pts.push(point(name, [2.0, y, floor_z], [0.0, 0.0, floor_nz]));
        exact.push(v);
    }
    (pts, exact)
}

/// Gathers at `pts` and returns the values (grey scenes: every channel and the photopic value
/// agree) with the seconds the gather took and the rays it cast.
fn gather(solved: &Solved, pts: &[CalcPoint]) -> (Vec<f64>, f64, u64) {
    let t = Instant::now();
    let r = points::gather(solved, pts, &PointsConfig::default());
    let seconds = t.elapsed().as_secs_f64();
    for (p, r) in pts.iter().zip(&r) {
        assert!(r.h.iter().all(|&h| (h - r.h[0]).abs() <= EXACT_REL_TOL * r.h[0]), "{}: grey scene, channels differ: {:?}", p.name, r.h);
        assert!((r.photopic() - r.h[0]).abs() <= EXACT_REL_TOL * r.h[0], "{}: photopic of grey {:?}", p.name, r.photopic());
    }
    (r.iter().map(|r| r.h[0]).collect(), seconds, r.iter().map(|r| r.rays).sum())
}

/// CIE 171:2006 case 5.3 (area source): a 4×4×3 m black room, a 1×1 m Lambertian source of
/// luminance 1000 cd/m² (exitance π·1000) centred in the ceiling facing down; `E = π L F`.
fn cie_5_3() -> (Scene, Vec<CalcPoint>, Vec<f64>) {
    let mut r = Room::new("cie-5.3");
    let (k, src) = (r.black, r.emitter("source", std::f64::consts::PI * 1000.0));
    r.xy((0.0, 4.0), (0.0, 4.0), 0.0, 1.0, k);
    r.xz((0.0, 4.0), (0.0, 3.0), 0.0, 1.0, k);
    r.xz((0.0, 4.0), (0.0, 3.0), 4.0, -1.0, k);
    r.yz((0.0, 4.0), (0.0, 3.0), 0.0, 1.0, k);
    r.yz((0.0, 4.0), (0.0, 3.0), 4.0, -1.0, k);
    // The ceiling around the source, then the source in its hole.
    r.xy((0.0, 4.0), (0.0, 1.5), 3.0, -1.0, k);
    r.xy((0.0, 4.0), (2.5, 4.0), 3.0, -1.0, k);
    r.xy((0.0, 1.5), (1.5, 2.5), 3.0, -1.0, k);
    r.xy((2.5, 4.0), (1.5, 2.5), 3.0, -1.0, k);
    r.xy((1.5, 2.5), (1.5, 2.5), 3.0, -1.0, src);
    let (pts, exact) = cie_points(&cie171::CASE_53_WALL, &cie171::CASE_53_FLOOR, 0.0, 1.0);
    (r.finish(), pts, exact)
}

/// Checks `got` against `exact` point by point within the references' rounding and `rel_tol`;
/// returns the largest relative error.
fn check(case: &str, pts: &[CalcPoint], got: &[f64], exact: &[f64], rel_tol: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for ((p, &g), &e) in pts.iter().zip(got).zip(exact) {
        let err = (g - e).abs();
        assert!(err <= REFERENCE_ROUNDING + rel_tol * e, "{case} point {}: {g:.6} against exact {e:.3}", p.name);
        worst = worst.max(err / e);
    }
    worst
}

#[test]
fn cie_5_3_area_source_is_exact_at_every_point() {
    let (scene, pts, exact) = cie_5_3();
    // The room is a convex enclosure: the solve and the points cast no ray ...
    let solved = solve(&scene, true);
    let (got, seconds, rays) = gather(&solved, &pts);
    assert_eq!(rays, 0, "no ray inside a convex enclosure");
    let worst = check("5.3", &pts, &got, &exact, EXACT_REL_TOL);
    assert!(worst <= CIE_53_REL_TOL);
    // Unrounded: Lambert's formula over the whole source, which the gather sums leaf by leaf.
    let source = [[1.5, 1.5], [1.5, 2.5], [2.5, 2.5], [2.5, 1.5]].map(|[x, y]| DVec3::new(x, y, 3.0));
    let mut worst_unrounded: f64 = 0.0;
    for (p, &g) in pts.iter().zip(&got) {
        let e = std::f64::consts::PI * 1000.0 * point_polygon(p.position, p.normal, &source, -DVec3::Z);
        worst_unrounded = worst_unrounded.max((g - e).abs() / e);
    }
    assert!(worst_unrounded <= EXACT_REL_TOL, "{worst_unrounded}");
    eprintln!(
        "CIE 5.3: max relative error {worst:.2e} against the 3-decimal references, {worst_unrounded:.1e} against Lambert's formula \
         over the whole source; gather {:.3} ms, {} points",
        1e3 * seconds,
        pts.len()
    );
    // ... and with the analysis off the points cast rays, each from a point on the floor or a wall
    // that must not block its own rays.
    let solved = solve(&scene, false);
    let (got, seconds, rays) = gather(&solved, &pts);
    assert!(rays > 0);
    let worst = check("5.3 with rays", &pts, &got, &exact, EXACT_REL_TOL);
    eprintln!("CIE 5.3 with rays: max relative error {worst:.2e}, gather {:.3} ms, {rays} rays", 1e3 * seconds);
}

/// A point outside a convex enclosure is not inside what the analysis vouched for: below the 5.3
/// room's floor, facing up at the source, it gets nothing through the floor.
#[test]
fn point_outside_a_convex_enclosure_casts_rays() {
    let (scene, _, _) = cie_5_3();
    let solved = solve(&scene, true);
    assert!(solved.traits.as_ref().is_some_and(|t| !t.needs_visibility), "the room is a convex enclosure");
    let below = point("below", [2.0, 2.0, -0.5], [0.0, 0.0, 1.0]);
    let r = points::gather(&solved, &[below], &PointsConfig::default())[0];
    assert!(r.rays > 0 && r.h[0] <= DARK_BOUND, "{r:?}");
}

#[test]
fn cie_5_6_light_reflected_by_a_diffuse_floor() {
    // Scenario 2: S2 = the 4×4 m floor as a uniform Lambertian emitter of exitance 100, so the
    // points read F(dP → S2) in %; a black measurement wall at y = 0 (4 m wide, z 0.5..3) and a
    // black 4×4 m ceiling at 3 m.
    let mut r = Room::new("cie-5.6");
    let (k, s2) = (r.black, r.emitter("S2", 100.0));
    r.xy((0.0, 4.0), (0.0, 4.0), 0.0, 1.0, s2);
    r.xz((0.0, 4.0), (0.5, 3.0), 0.0, 1.0, k);
    r.xy((0.0, 4.0), (0.0, 4.0), 3.0, -1.0, k);
    let scene = r.finish();
    let wall = [("B", 0.75, 35.901), ("C", 1.25, 27.992), ("D", 1.75, 21.639), ("E", 2.25, 16.716), ("F", 2.75, 12.967)];
    let ceiling = [
        ("G", 0.25, 26.795),
        ("H", 0.75, 30.939),
        ("I", 1.25, 33.976),
        ("J", 1.75, 35.567),
        ("K", 2.25, 35.567),
        ("L", 2.75, 33.976),
        ("M", 3.25, 30.939),
        ("N", 3.75, 26.795),
    ];
    let (pts, exact) = cie_points(&wall, &ceiling, 3.0, -1.0);
    // Unrounded: Lambert's formula over the whole of S2.
    let s2 = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]].map(|[x, y]| DVec3::new(x, y, 0.0));
    for analyse in [true, false] {
        let solved = solve(&scene, analyse);
        let (got, seconds, rays) = gather(&solved, &pts);
        let worst = check("5.6", &pts, &got, &exact, EXACT_REL_TOL);
        let worst_unrounded = pts
            .iter()
            .zip(&got)
            .map(|(p, &g)| (g / (100.0 * point_polygon(p.position, p.normal, &s2, DVec3::Z)) - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(worst_unrounded <= EXACT_REL_TOL, "{worst_unrounded}");
        eprintln!(
            "CIE 5.6 (analysis {analyse}): max relative error {worst:.2e}, {worst_unrounded:.1e} against Lambert's formula over S2; \
             gather {:.3} ms, {rays} rays",
            1e3 * seconds
        );
    }
}

#[test]
fn cie_5_7_obstruction_shadows_within_one_percent() {
    // S2 = the wall y = 4 (x 0..4, z 0..3) facing −y as a uniform emitter of exitance 100 (points
    // read %); black measurement wall y = 0, black floor strip y 0..2.5, black box obstruction
    // x 0..4, y 2.5..2.7, z 0..1. G, H, I see S2 above a shadow line; J, K not at all.
    let mut r = Room::new("cie-5.7");
    let (k, s2) = (r.black, r.emitter("S2", 100.0));
    r.xz((0.0, 4.0), (0.0, 3.0), 4.0, -1.0, s2);
    r.xz((0.0, 4.0), (0.0, 3.0), 0.0, 1.0, k);
    r.xy((0.0, 4.0), (0.0, 2.5), 0.0, 1.0, k);
    r.xz((0.0, 4.0), (0.0, 1.0), 2.5, -1.0, k);
    r.xz((0.0, 4.0), (0.0, 1.0), 2.7, 1.0, k);
    r.xy((0.0, 4.0), (2.5, 2.7), 1.0, 1.0, k);
    r.yz((2.5, 2.7), (0.0, 1.0), 0.0, -1.0, k);
    r.yz((2.5, 2.7), (0.0, 1.0), 4.0, 1.0, k);
    let scene = r.finish();
    let wall =
        [("A", 2.75, 16.071), ("B", 2.25, 16.330), ("C", 1.75, 15.399), ("D", 1.25, 13.322), ("E", 0.75, 10.317), ("F", 0.25, 7.079)];
    let floor = [("G", 0.25, 3.382), ("H", 0.75, 3.629), ("I", 1.25, 3.013), ("J", 1.75, 0.0), ("K", 2.25, 0.0)];
    let (pts, exact) = cie_points(&wall, &floor, 0.0, 1.0);
    let solved = solve(&scene, true);
    assert!(solved.traits.as_ref().is_some_and(|t| t.needs_visibility));
    let (got, seconds, rays) = gather(&solved, &pts);
    // K sees none of S2. J lies exactly on the line through the box's top edge and S2's top edge:
    // the finest pieces of S2's top leaves straddle that line and count by their share of clear
    // samples, within the gather's shadow-edge budget of each such leaf's unoccluded form factor
    // (measured 5.4e-4 W/m², the reference's 0.000 being below 5e-4).
    let top_leaves = solved.hierarchy.leaves().filter_map(|e| solved.hierarchy.get(e).poly()).filter(|q| {
        let vs = q.vertices();
        vs.iter().all(|v| (v.y - 4.0).abs() < 1e-9) && vs.iter().any(|v| (v.z - 3.0).abs() < 1e-9)
    });
    let j = pts.iter().position(|p| p.name == "J").expect("J");
    let grazing: f64 =
        top_leaves.map(|q| SHADOW_EDGE_REL_ERROR * 100.0 * point_polygon(pts[j].position, pts[j].normal, q.vertices(), -DVec3::Y)).sum();
    assert!(got[j] <= grazing, "J is in the box's shadow: {} above the shadow-edge budget {grazing}", got[j]);
    let k = pts.iter().position(|p| p.name == "K").expect("K");
    assert!(got[k] <= DARK_BOUND, "K is in the box's shadow: {}", got[k]);
    let lit = exact.iter().position(|&e| e == 0.0).expect("J");
    let worst = check("5.7", &pts[..lit], &got[..lit], &exact[..lit], CIE_57_REL_TOL);
    eprintln!(
        "CIE 5.7: max relative error {worst:.2e} over A-I, J/K {:.1e} {:.1e}, gather {:.3} ms, {rays} rays, {} leaves",
        got[lit],
        got[lit + 1],
        1e3 * seconds,
        solved.hierarchy.leaves().count()
    );
    // Each lit point's estimated error covers its error (up to the reference's rounding).
    let with_errors = points::gather(&solved, &pts, &PointsConfig::default());
    for ((p, &e), r) in pts.iter().zip(&exact).zip(&with_errors).take(lit) {
        eprintln!("  {}: error {:.4} estimated {:.4}", p.name, r.h[0] - e, r.h_err[0]);
        assert!(
            (r.h[0] - e).abs() <= r.h_err[0] + REFERENCE_ROUNDING,
            "{}: {} against {e}, estimated error {}",
            p.name,
            r.h[0],
            r.h_err[0]
        );
    }
}

/// Lambert's closed form for a point on the normal through a corner of a parallel `a × b`
/// rectangle at distance `c` (`formfactors.md`, section (a)).
fn corner_form_factor(a: f64, b: f64, c: f64) -> f64 {
    let (a, b) = (a / c, b / c);
    let (sa, sb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
    (a / sa * (b / sa).atan() + b / sb * (a / sb).atan()) / (2.0 * std::f64::consts::PI)
}

/// Regression (the point's own surface): a point on a floor under which a light lies gets nothing
/// from it, whatever its normal, on the floor or just above it; a point on the floor's underside
/// facing down gets exactly the light's share.
#[test]
fn no_light_through_the_surface_under_the_point() {
    let mut r = Room::new("light-under-floor");
    let grey = r.b.material(Material::diffuse("grey", [0.5; 3])).expect("valid material");
    let lamp = r.emitter("lamp", 100.0);
    r.xy((-2.0, 2.0), (-2.0, 2.0), 0.0, 1.0, grey);
    r.xy((-0.5, 0.5), (-0.5, 0.5), -1.0, 1.0, lamp);
    let scene = r.finish();
    let solved = solve(&scene, true);
    let dark = [
        point("on, up", [0.3, -0.2, 0.0], [0.0, 0.0, 1.0]),
        point("on, tilted", [0.3, -0.2, 0.0], [1.0, 0.0, 1.0]),
        point("on, in the floor's plane", [0.3, -0.2, 0.0], [-1.0, 0.0, 0.0]),
        point("1 mm above, tilted", [0.1, 0.0, 1e-3], [-1.0, 0.0, 0.5]),
        point("on its corner, tilted", [2.0, 2.0, 0.0], [-1.0, -1.0, 0.2]),
    ];
    for (p, r) in dark.iter().zip(points::gather(&solved, &dark, &PointsConfig::default())) {
        assert!(r.h.iter().all(|&h| h <= DARK_BOUND), "{}: {r:?}", p.name);
    }
    // Under the floor, facing down at the lamp's centre: 100 · 4 corner rectangles 0.5 × 0.5.
    let under = [point("on the underside", [0.0, 0.0, 0.0], [0.0, 0.0, -1.0]), point("1 mm below", [0.0, 0.0, -1e-3], [0.0, 0.0, -1.0])];
    let exact = [100.0 * 4.0 * corner_form_factor(0.5, 0.5, 1.0), 100.0 * 4.0 * corner_form_factor(0.5, 0.5, 1.0 - 1e-3)];
    for ((p, r), e) in under.iter().zip(points::gather(&solved, &under, &PointsConfig::default())).zip(exact) {
        assert!((r.h[0] - e).abs() <= EXACT_REL_TOL * e, "{}: {} against exact {e}", p.name, r.h[0]);
    }
}

/// The adaptive visibility's stated accuracy: one leaf (an unsubdivided 2×2 m emitter, 1 m above
/// a half-plane occluder, 2 m above the point) crossed by a straight shadow edge at random angles
/// and offsets; the exact visible part is the emitter clipped by the edge's plane through the point.
#[test]
fn shadow_edge_on_one_leaf_within_the_stated_error() {
    let mut rng = Rng::for_link(7, 1, 2);
    let mut worst: f64 = 0.0;
    for _ in 0..24 {
        let phi = 2.0 * std::f64::consts::PI * rng.next_f64();
        let m = DVec3::new(phi.cos(), phi.sin(), 0.0);
        let t = DVec3::new(-m.y, m.x, 0.0);
        // The occluder covers m · p ≥ c at z = 1; its shadow on the emitter, m · y ≥ 2c.
        let c = 0.45 * (2.0 * rng.next_f64() - 1.0);
        let q0 = c * m + DVec3::Z;
        let mut r = Room::new("shadow-edge");
        let lamp = r.emitter("lamp", 1.0);
        let k = r.black;
        r.xy((-1.0, 1.0), (-1.0, 1.0), 2.0, -1.0, lamp);
        let corners = [q0 - 10.0 * t, q0 + 10.0 * t, q0 + 10.0 * t + 10.0 * m, q0 - 10.0 * t + 10.0 * m];
        r.quad(corners.map(|v| v.to_array()), [0.0, 0.0, -1.0], k);
        let scene = r.finish();
        // The emitter is one leaf: the hierarchy as built, before any refinement.
        let h = hierarchy::build(&scene, &BuildConfig::default());
        let b: Vec<[f64; 3]> = (0..h.len()).map(|i| if i < h.n_polygons as usize { h.emission[i] } else { [0.0; 3] }).collect();
        let caster = RayCaster::new(&scene);
        let g = PointGather::new(&h, &b, Some(&caster), &PointsConfig::default());
        let x = DVec3::ZERO;
        let got: PointIrradiance = g.irradiance(&point("x", [0.0; 3], [0.0, 0.0, 1.0]));
        let emitter = [DVec3::new(-1.0, -1.0, 2.0), DVec3::new(-1.0, 1.0, 2.0), DVec3::new(1.0, 1.0, 2.0), DVec3::new(1.0, -1.0, 2.0)];
        let mut visible = [DVec3::ZERO; 8];
        let n = clip_to_halfspace(&emitter, 2.0 * c * m + 2.0 * DVec3::Z, -m, &mut visible);
        let exact = if n < 3 { 0.0 } else { point_polygon_unclipped(x, DVec3::Z, &visible[..n]) };
        let unoccluded = 4.0 * corner_form_factor(1.0, 1.0, 2.0);
        let err = (got.h[0] - exact).abs() / unoccluded;
        assert!(err <= SHADOW_EDGE_REL_ERROR, "edge at {phi:.3} rad, offset {c:.3}: {} against exact {exact} ({err:.2e})", got.h[0]);
        worst = worst.max(err);
    }
    eprintln!("shadow edge across one leaf: max error {worst:.2e} of the unoccluded form factor (bound {SHADOW_EDGE_REL_ERROR})");
}

fn run_cli(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).current_dir(dir).output().expect("the binary runs")
}

#[test]
fn cli_writes_points_csv_in_input_order() {
    let dir = tempfile::tempdir().unwrap();
    // The embedded Cornell box (millimetres, y up; the lamp at y = 548.8 over x 213..343,
    // z 227..332).
    let text = "# name first, header optional\nname,x,y,z,nx,ny,nz\n\
                floor under the lamp,278,0,280,0,2,0\n\
                \"back of the ceiling, up\",278,548.8,100,0,1,0\n\
                mid-air,278,300,280,0,1,0\n";
    std::fs::write(dir.path().join("p.csv"), text).unwrap();
    let out = run_cli(dir.path(), &["solve", "--points", "p.csv", "--no-image", "--quiet", "--out", "o"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.path().join("o/points.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("name,x,y,z,nx,ny,nz,h_r,h_g,h_b,h_photopic,units,h_err"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 3, "{csv}");
    assert!(rows[0].starts_with("floor under the lamp,278,0,280,0,1,0,"), "normal written normalised: {}", rows[0]);
    assert!(rows[1].starts_with("\"back of the ceiling, up\","), "{}", rows[1]);
    let values = |row: &str| -> Vec<f64> { row.rsplit(',').skip(2).take(4).map(|v| v.parse().unwrap()).collect::<Vec<_>>() };
    let error = |row: &str| -> f64 { row.rsplit(',').next().unwrap().parse().unwrap() };
    for row in [rows[0], rows[2]] {
        let v = values(row); // photopic, b, g, r
        assert!(v.iter().all(|&h| h > 0.0), "a point facing the lit room gets light: {row}");
        let photopic = 0.2126 * v[3] + 0.7152 * v[2] + 0.0722 * v[1];
        assert!((v[0] - photopic).abs() <= 1e-12 * photopic, "Rec. 709 weights: {row}");
        assert!(error(row) > 0.0 && error(row) < v[0], "an estimated error, below the value: {row}");
    }
    assert!(values(rows[1]).iter().all(|&h| h == 0.0), "above the ceiling nothing is lit: {}", rows[1]);
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("o/stats.json")).unwrap()).unwrap();
    assert_eq!(stats["points"], 3);
    assert!(stats["time_s"]["points"].as_f64().is_some_and(|t| t >= 0.0), "{stats}");
    assert!(stats["point_rays"].as_u64().is_some_and(|r| r > 0), "{stats}");
}

#[test]
fn cli_bad_points_file_is_one_line_naming_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("p.csv"), "x,y,z,nx,ny,nz\n1,2,3,0,1,0\n1,two,3,0,1,0\n").unwrap();
    let out = run_cli(dir.path(), &["solve", "--points", "p.csv", "--no-image", "--out", "o"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.trim_end(), "error: p.csv:3: `y` is not a number: `two`");
    assert!(!dir.path().join("o").exists(), "nothing solved or written");
    // A zero normal, and --points where it is not supported.
    std::fs::write(dir.path().join("z.csv"), "0,0,0,0,0,0\n").unwrap();
    let out = run_cli(dir.path(), &["solve", "--points", "z.csv", "--out", "o"]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&out.stderr).trim_end(), "error: z.csv:1: zero normal: `nx,ny,nz` must not all be 0");
    let out = run_cli(dir.path(), &["solve", "--points", "p.csv", "--instances", "auto", "--out", "o"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--points applies to plain scenes"));
}

/// Share of points whose sky error must cover their true error against the continuous sky
/// (measured 118 of 120 at the worst of the three heights below).
const SKY_COVERED_SHARE: f64 = 0.95;
/// The points' mean sky error estimate, as a share of the sky's diffuse horizontal irradiance,
/// must stay below this: the estimate is first order where the errors left are much smaller
/// (measured 0.09-0.11%, 7 to 25 times the errors, which are 0.19% at worst).
const SKY_ESTIMATE_MEAN_MAX_REL: f64 = 0.003;
/// A point's worst error against the continuous sky (measured 0.19%, the square 0.3 m up; 14.8%
/// when each cell was seen or hidden whole).
const SKY_POINT_REL_TOL: f64 = 0.005;

/// The sky's discretisation at calculation points: a black 1 m square over a black ground under
/// the uniform 145-cell sky. The continuous sky's answer is `E_dh (1 − F)`, `F` the point's form
/// factor to the square (a uniform sky of radiance `L` gives `E_dh = π L`, and the square hides
/// `π L F` of it). A cell the point sees in part is sampled ray by ray (`SKY_PATCH_PIECES`, its
/// edge pieces again), so every point is within 0.5% of it (seen whole or not at all, the cells
/// were up to 15% off 0.3 m under the square, 5.5% 1 m and 2.4% 3 m under it). Each point's
/// `sky_err` (in `h_err`) covers its true error for at least 95% of the points and is 0.3% of the
/// sky's light at most on average; a point above the square has none.
#[test]
fn the_sky_discretisation_error_is_in_each_points_estimate() {
    for height in [0.3, 1.0, 3.0] {
        let mut b = SceneBuilder::new(Path::new("sky"), "sky");
        let m = b.material(Material::diffuse("black", [0.0; 3])).unwrap();
        let g = b.group("g");
        let corners = |h: f64, z: f64| [DVec3::new(-h, -h, z), DVec3::new(h, -h, z), DVec3::new(h, h, z), DVec3::new(-h, h, z)];
        b.face(&corners(10.0, 0.0), m, g, 0).unwrap();
        let mut square = corners(0.5, height);
        square.reverse();
        b.face(&square, m, g, 0).unwrap();
        let mut scene = b.finish();
        scene.distant =
            radiosity::daylight::sky(radiosity::daylight::SkyModel::Uniform, [100.0; 3], 145, &radiosity::daylight::Site::default())
                .unwrap();
        let config = Config { target_error: Some(0.01), ..Config::default() };
        let solved = pipeline::run(&scene, &BfHand::default(), &config, &|_| {});
        let mut pts = Vec::new();
        for i in 0..40 {
            for (dx, dy) in [(1.0, 0.0), (0.7, 0.7), (1.0, 0.3)] {
                let t = f64::from(i) * 0.05;
                pts.push(CalcPoint { name: format!("{i}"), position: DVec3::new(t * dx, t * dy, 0.0), normal: DVec3::Z });
            }
        }
        // Above the square, facing up: nothing hides any of the sky (on the ground, even far
        // out, the square hides a little of it near the horizon).
        pts.push(CalcPoint { name: "open".into(), position: DVec3::new(0.0, 0.0, height + 0.5), normal: DVec3::Z });
        let got = points::gather(&solved, &pts, &PointsConfig::default());
        let (open, got) = got.split_last().unwrap();
        let (mut covered, mut errors, mut estimates, mut worst) = (0, 0.0, 0.0, 0.0f64);
        for (p, r) in pts.iter().zip(got) {
            let exact = 100.0 * (1.0 - point_polygon(p.position, p.normal, &square, -DVec3::Z));
            let error = (r.h[1] - exact).abs();
            assert!(r.h_err[1] >= r.sky_err[1], "{}: the sky's error is part of h_err", p.name);
            covered += usize::from(error <= r.h_err[1]);
            errors += error;
            estimates += r.h_err[1];
            worst = worst.max(error / exact);
        }
        eprintln!(
            "square {height} m up: {covered}/{} covered, estimates {:.2} times the errors, worst error {:.3}%, mean estimate {:.3}%",
            got.len(),
            estimates / errors,
            100.0 * worst,
            estimates / got.len() as f64
        );
        assert!(worst <= SKY_POINT_REL_TOL, "{height} m: a point {:.3}% off the continuous sky", 100.0 * worst);
        assert!(covered as f64 >= SKY_COVERED_SHARE * got.len() as f64, "{height} m: {covered} of {} covered", got.len());
        let mean_estimate = estimates / got.len() as f64;
        assert!(mean_estimate <= SKY_ESTIMATE_MEAN_MAX_REL * 100.0, "{height} m: mean estimate {mean_estimate} (errors {errors})");
        assert_eq!(open.sky_err, [0.0; 3], "nothing hides the sky from the open point");
    }
}
