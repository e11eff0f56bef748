//! Stiff and extreme scenes: every case finishes without NaN or infinity, with energy balance and the
//! known answer where there is one.

use radiosity::geom::DVec3;
use radiosity::output::{polygon_results, power_balance};
use radiosity::pipeline::{self, Config, Solved};
use radiosity::refine::{BfHand, BfParams};
use radiosity::scene::shapes::{box_faces, furnace_box};
use radiosity::scene::{Material, Scene, SceneBuilder, cornell_box};
use std::path::Path;

/// Energy balance bound in closed scenes.
const BALANCE_REL_TOL: f64 = 1e-2;
/// Scale and translation invariance bound (per-polygon mean radiosity).
const INVARIANCE_REL_TOL: f64 = 1e-2;

fn solve(scene: &Scene, eps: f64, min_area_rel: f64) -> Solved {
    let mut config = Config::default();
    config.build.min_area_rel = min_area_rel;
    pipeline::run(scene, &BfHand { params: BfParams { eps } }, &config, &|_| {})
}

fn assert_finite(s: &Solved) {
    for leaf in s.hierarchy.leaves() {
        let (b, h) = (s.solution.radiosity[leaf as usize], s.solution.irradiance[leaf as usize]);
        assert!(b.iter().chain(&h).all(|v| v.is_finite() && *v >= 0.0), "leaf {leaf}: B {b:?} H {h:?}");
    }
}

fn assert_balanced(s: &Solved) {
    let (emitted, absorbed, _) = power_balance(&s.hierarchy, &s.lights, &s.solution);
    assert!((absorbed / emitted - 1.0).abs() < BALANCE_REL_TOL, "emitted {emitted:e}, absorbed {absorbed:e}");
}

fn stiff(rho: f64, tol: f64) {
    let scene = furnace_box(DVec3::new(1.0, 0.7, 1.2), rho, 1.0);
    let s = solve(&scene, 0.1, 1e-3);
    assert_finite(&s);
    let exact = 1.0 / (1.0 - rho);
    let worst = s.hierarchy.leaves().map(|l| (s.solution.radiosity[l as usize][0] / exact - 1.0).abs()).fold(0.0, f64::max);
    println!("stiff rho = {rho}: {} iterations, worst leaf error {worst:.2e}", s.iterations);
    assert!(worst < tol, "rho = {rho}: worst leaf off by {worst:e}");
    assert!(s.iterations < 400, "{} iterations: must not grow like 1/(1-rho)", s.iterations);
    assert_balanced(&s);
}

#[test]
fn stiff_rho_0_99() {
    stiff(0.99, 5e-3);
}

#[test]
fn stiff_rho_0_999() {
    stiff(0.999, 2e-2);
}

#[test]
fn stiff_rho_0_9999() {
    stiff(0.9999, 5e-2);
}

fn per_polygon(scene: &Scene) -> Vec<[f64; 3]> {
    let s = solve(scene, 0.02, 1e-4);
    assert_finite(&s);
    polygon_results(&s.hierarchy, &s.solution).iter().map(|r| r.b).collect()
}

fn assert_same(a: &[[f64; 3]], b: &[[f64; 3]], what: &str) {
    let max = a.iter().flatten().fold(0.0f64, |m, v| m.max(*v));
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        for c in 0..3 {
            assert!((x[c] - y[c]).abs() <= INVARIANCE_REL_TOL * max, "{what}: polygon {i} channel {c}: {} vs {}", x[c], y[c]);
        }
    }
}

#[test]
fn cornell_box_is_invariant_under_scale_and_translation() {
    let unit = cornell_box();
    let reference = per_polygon(&unit);
    for (what, f) in [
        ("scaled by 1e-6", Box::new(|v: DVec3| v * 1e-6) as Box<dyn Fn(DVec3) -> DVec3>),
        ("scaled by 1e6", Box::new(|v: DVec3| v * 1e6)),
        ("translated by 1e6", Box::new(|v: DVec3| v + DVec3::new(1e6, -1e6, 1e6))),
    ] {
        let mut scene = unit.clone();
        scene.transform(f);
        assert_same(&reference, &per_polygon(&scene), what);
    }
}

fn builder(name: &str) -> SceneBuilder {
    SceneBuilder::new(Path::new(name), name)
}

fn material(b: &mut SceneBuilder, name: &str, rho: f64, e: f64) -> u32 {
    let mut m = Material::diffuse(name, [rho; 3]);
    m.emission = [e; 3];
    b.material(m).expect("valid material")
}

/// A closed box whose faces are split: faces 0..k emit with the given strengths.
fn closed_box_with(emissions: &[f64]) -> Scene {
    let mut b = builder("dynamic-range");
    let wall = material(&mut b, "wall", 0.6, 0.0);
    let mats: Vec<u32> = emissions.iter().enumerate().map(|(i, &e)| material(&mut b, &format!("lamp{i}"), 0.6, e)).collect();
    for (k, (name, q)) in box_faces(DVec3::ZERO, DVec3::new(1.0, 1.0, 1.0), true).into_iter().enumerate() {
        let g = b.group(name);
        b.face(&q, mats.get(k).copied().unwrap_or(wall), g, 0).expect("valid face");
    }
    b.finish()
}

#[test]
fn emitters_from_1e_minus_6_to_1e6_in_one_scene() {
    let s = solve(&closed_box_with(&[1e6, 1e-6, 1.0]), 0.05, 1e-3);
    assert_finite(&s);
    assert_balanced(&s);
    let h = &s.hierarchy;
    for leaf in h.leaves() {
        let p = h.get(leaf).polygon().unwrap() as usize;
        assert!(s.solution.radiosity[leaf as usize][0] >= h.emission[p][0], "leaf {leaf} below its emission");
    }
}

/// A closed box plus extra geometry inside; the lamp is the ceiling.
fn room_with(extra: impl FnOnce(&mut SceneBuilder, u32)) -> Scene {
    let mut b = builder("room");
    let wall = material(&mut b, "wall", 0.5, 0.0);
    let lamp = material(&mut b, "lamp", 0.5, 5.0);
    for (name, q) in box_faces(DVec3::ZERO, DVec3::new(2.0, 2.0, 2.0), true) {
        let g = b.group(name);
        let ceiling = q.iter().all(|v| v.z == 2.0);
        b.face(&q, if ceiling { lamp } else { wall }, g, 0).expect("valid face");
    }
    let obj = material(&mut b, "object", 0.7, 0.0);
    extra(&mut b, obj);
    b.finish()
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

#[test]
fn sliver_triangles_shared_edges_vertex_contact_and_intersections() {
    let scene = room_with(|b, m| {
        let g = b.group("extreme");
        // A sliver triangle, aspect ratio 1e6, both sides.
        b.face(&[v(0.5, 1.0, 0.5), v(1.5, 1.0, 0.5), v(1.0, 1.0, 0.5 + 1e-6)], m, g, 0).unwrap();
        b.face(&[v(0.5, 1.0, 0.5), v(1.0, 1.0, 0.5 + 1e-6), v(1.5, 1.0, 0.5)], m, g, 0).unwrap();
        // Two quads sharing an edge at an angle (a folded card), and one touching it at a vertex.
        b.face(&[v(0.2, 0.2, 0.0), v(0.8, 0.2, 0.0), v(0.8, 0.2, 0.6), v(0.2, 0.2, 0.6)], m, g, 0).unwrap();
        b.face(&[v(0.2, 0.2, 0.6), v(0.8, 0.2, 0.6), v(0.8, 0.6, 1.0), v(0.2, 0.6, 1.0)], m, g, 0).unwrap();
        b.face(&[v(0.8, 0.6, 1.0), v(1.2, 0.6, 1.0), v(1.2, 1.0, 1.3)], m, g, 0).unwrap();
        // Two quads crossing each other, and a coplanar overlapping pair.
        b.face(&[v(1.2, 1.2, 0.3), v(1.8, 1.8, 0.3), v(1.8, 1.8, 0.9), v(1.2, 1.2, 0.9)], m, g, 0).unwrap();
        b.face(&[v(1.2, 1.8, 0.3), v(1.8, 1.2, 0.3), v(1.8, 1.2, 0.9), v(1.2, 1.8, 0.9)], m, g, 0).unwrap();
        b.face(&[v(0.3, 1.5, 1.5), v(0.9, 1.5, 1.5), v(0.9, 1.9, 1.5), v(0.3, 1.9, 1.5)], m, g, 0).unwrap();
        b.face(&[v(0.5, 1.6, 1.5), v(1.1, 1.6, 1.5), v(1.1, 1.95, 1.5), v(0.5, 1.95, 1.5)], m, g, 0).unwrap();
    });
    let s = solve(&scene, 0.05, 1e-4);
    assert_finite(&s);
    assert!(scene.warnings.degenerate_faces == 0, "the sliver is thin, not degenerate: {:?}", scene.warnings);
}

#[test]
fn tiny_emitter() {
    // 1e-8 of the scene's area, hanging below the ceiling, facing down.
    let scene = {
        let mut b = builder("tiny");
        let wall = material(&mut b, "wall", 0.5, 0.0);
        let lamp = material(&mut b, "lamp", 0.0, 1e8);
        for (name, q) in box_faces(DVec3::ZERO, DVec3::new(2.0, 2.0, 2.0), true) {
            let g = b.group(name);
            b.face(&q, wall, g, 0).unwrap();
        }
        let side = (24.0f64 * 1e-8).sqrt();
        let g = b.group("lamp");
        let (c, z) = (1.0, 1.9);
        b.face(&[v(c, c, z), v(c, c + side, z), v(c + side, c + side, z), v(c + side, c, z)], lamp, g, 0).unwrap();
        b.finish()
    };
    let s = solve(&scene, 0.05, 1e-4);
    assert_finite(&s);
    let floor_h = polygon_results(&s.hierarchy, &s.solution)
        [box_faces(DVec3::ZERO, DVec3::ONE, true).iter().position(|(_, q)| q.iter().all(|p| p.z == 0.0)).unwrap()]
    .h[0];
    assert!(floor_h > 0.0, "the floor is lit: H = {floor_h}");
}

#[test]
fn ten_thousand_emitters() {
    // The ceiling of a closed box as a 100 × 100 grid of emitting tiles.
    let mut b = builder("many-emitters");
    let wall = material(&mut b, "wall", 0.5, 0.0);
    let lamp = material(&mut b, "lamp", 0.5, 2.0);
    for (name, q) in box_faces(DVec3::ZERO, DVec3::new(1.0, 1.0, 1.0), true) {
        if q.iter().all(|v| v.z == 1.0) {
            continue;
        }
        let g = b.group(name);
        b.face(&q, wall, g, 0).unwrap();
    }
    let g = b.group("tiles");
    let n = 100;
    for i in 0..n {
        for j in 0..n {
            let (x0, x1, y0, y1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64, j as f64 / n as f64, (j + 1) as f64 / n as f64);
            b.face(&[v(x0, y0, 1.0), v(x0, y1, 1.0), v(x1, y1, 1.0), v(x1, y0, 1.0)], lamp, g, 0).unwrap();
        }
    }
    let scene = b.finish();
    assert_eq!(scene.polygons.len(), 5 + n * n);
    let s = solve(&scene, 0.02, 1e-5);
    assert_finite(&s);
    assert_balanced(&s);
}

#[test]
fn same_seed_gives_bit_identical_results_on_1_and_2_threads() {
    let scene = cornell_box();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
        pool.install(|| {
            let s = solve(&scene, 0.02, 1e-4);
            (s.links.len(), s.solution.radiosity.clone())
        })
    };
    let (l1, b1) = run(1);
    let (l2, b2) = run(2);
    assert_eq!(l1, l2);
    assert!(
        b1.iter().flatten().zip(b2.iter().flatten()).all(|(x, y)| x.to_bits() == y.to_bits()),
        "radiosity differs between 1 and 2 threads"
    );
}
