//! A block standing on a floor under an area light: the floor beside the block reads the light
//! that reaches it, element by element, against an independent quadrature (no lit strip along the
//! block's base where a coarse element's visibility was sampled as clear).
//!
//! The block and the lamp are black and the floor's light goes nowhere it could come back from,
//! so every floor point's irradiance is the lamp's direct light: `H(p) = L ∫ cos θ cos θ' / r² V dA`
//! over the lamp, `V` from a segment–box test written here (the solver's rays never enter it).

use radiosity::hierarchy::Hierarchy;
use radiosity::pipeline::{self, Config};
use radiosity::refine::{BfHand, Criterion};

#[path = "support/obj.rs"]
mod obj;

/// The block: x, z ∈ [−A, A], y ∈ [0, HEIGHT] (metres).
const A: f64 = 0.2;
const HEIGHT: f64 = 0.4;
/// The lamp: x ∈ [−0.4, 0.4], z ∈ [0.3, 0.7] at y = 1, facing down, emitting 100 W/m² (radiance
/// 100/π), behind the block so that the floor in front of it lies in its shadow.
const LAMP: ([f64; 2], [f64; 2], f64) = ([-0.4, 0.4], [0.3, 0.7], 1.0);
const EMISSION: f64 = 100.0;
/// Floor elements read: centres outside the block's footprint, at most this far from it.
const BAND: f64 = 0.06;
/// The bar: a floor element's irradiance against the exact mean over it, relative to the largest
/// of those exact means (1.8 W/m²): the default target error is 1% of a polygon mean, and an
/// element's mean carries its visibility sample's noise as well.
const ELEMENT_TOL: f64 = 0.03;

fn scene_obj() -> String {
    let mut obj = obj::Obj::new("blk.mtl");
    obj.quad([[-1., 0., -1.], [1., 0., -1.], [1., 0., 1.], [-1., 0., 1.]], [0., 1., 0.], "floor");
    let (a, h) = (A, HEIGHT);
    obj.quad([[-a, h, -a], [a, h, -a], [a, h, a], [-a, h, a]], [0., 1., 0.], "black");
    obj.quad([[-a, 0., -a], [a, 0., -a], [a, h, -a], [-a, h, -a]], [0., 0., -1.], "black");
    obj.quad([[-a, 0., a], [a, 0., a], [a, h, a], [-a, h, a]], [0., 0., 1.], "black");
    obj.quad([[-a, 0., -a], [-a, 0., a], [-a, h, a], [-a, h, -a]], [-1., 0., 0.], "black");
    obj.quad([[a, 0., -a], [a, 0., a], [a, h, a], [a, h, -a]], [1., 0., 0.], "black");
    let ([x0, x1], [z0, z1], y) = LAMP;
    obj.quad([[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]], [0., -1., 0.], "lamp");
    obj.text
}

const MTL: &str = "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl black\nKd 0 0 0\nnewmtl lamp\nKd 0 0 0\nKe 100 100 100\n";

/// Whether the segment `p → q` (ends excluded) passes through the block.
fn blocked(p: [f64; 3], q: [f64; 3]) -> bool {
    let (lo, hi) = ([-A, 0.0, -A], [A, HEIGHT, A]);
    let (mut t0, mut t1): (f64, f64) = (1e-9, 1.0 - 1e-9);
    for k in 0..3 {
        let d = q[k] - p[k];
        if d.abs() < 1e-15 {
            if p[k] < lo[k] || p[k] > hi[k] {
                return false;
            }
        } else {
            let (a, b) = ((lo[k] - p[k]) / d, (hi[k] - p[k]) / d);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

/// The lamp's irradiance at floor point `(x, z)`: midpoint rule on a 64 × 32 grid of the lamp.
fn point_irradiance(x: f64, z: f64) -> f64 {
    let ([x0, x1], [z0, z1], y) = LAMP;
    let (nx, nz) = (64, 32);
    let (dx, dz) = ((x1 - x0) / f64::from(nx), (z1 - z0) / f64::from(nz));
    let mut sum = 0.0;
    for i in 0..nx {
        for j in 0..nz {
            let q = [x0 + dx * (f64::from(i) + 0.5), y, z0 + dz * (f64::from(j) + 0.5)];
            if blocked([x, 0.0, z], q) {
                continue;
            }
            let r2 = (q[0] - x).powi(2) + y * y + (q[2] - z).powi(2);
            sum += y * y / (r2 * r2);
        }
    }
    EMISSION / std::f64::consts::PI * sum * dx * dz
}

/// The exact mean irradiance over a floor element (an axis-aligned rectangle, as the floor's
/// quadtree cuts it): the element cut along the block's sides into pieces wholly under it (dark) or
/// wholly beside it, 8 × 8 points on each piece beside it (a grid across the block's edge would
/// count a row of points on the wrong side: 4% on a 3 cm element).
fn element_irradiance(h: &Hierarchy, e: u32) -> f64 {
    let poly = h.get(e).poly().expect("a surface");
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in poly.vertices() {
        lo = [lo[0].min(v.x), lo[1].min(v.z)];
        hi = [hi[0].max(v.x), hi[1].max(v.z)];
    }
    let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
    assert!((area - h.get(e).area).abs() <= 1e-9 * area, "floor elements are axis-aligned rectangles");
    let cuts = |a: f64, b: f64| {
        let mut c = vec![a];
        c.extend([-A, A].into_iter().filter(|&x| x > a && x < b));
        c.push(b);
        c
    };
    let (xs, zs) = (cuts(lo[0], hi[0]), cuts(lo[1], hi[1]));
    let n = 8;
    let mut sum = 0.0;
    for x in xs.windows(2) {
        for z in zs.windows(2) {
            if to_footprint(0.5 * (x[0] + x[1]), 0.5 * (z[0] + z[1])) == 0.0 {
                continue;
            }
            let piece = (x[1] - x[0]) * (z[1] - z[0]);
            let mut s = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let px = x[0] + (x[1] - x[0]) * (f64::from(i) + 0.5) / f64::from(n);
                    let pz = z[0] + (z[1] - z[0]) * (f64::from(j) + 0.5) / f64::from(n);
                    s += point_irradiance(px, pz);
                }
            }
            sum += piece * s / f64::from(n * n);
        }
    }
    sum / area
}

/// Distance from floor point `(x, z)` to the block's footprint (0 inside).
fn to_footprint(x: f64, z: f64) -> f64 {
    let (dx, dz) = ((x.abs() - A).max(0.0), (z.abs() - A).max(0.0));
    dx.hypot(dz)
}

struct Worst {
    error: f64,
    at: [f64; 2],
    size: f64,
    got: f64,
    exact: f64,
    elements: usize,
    largest: f64,
}

fn worst_floor_error(criterion: Criterion) -> Worst {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("blk.obj"), scene_obj()).unwrap();
    std::fs::write(dir.path().join("blk.mtl"), MTL).unwrap();
    let scene = radiosity::scene::load(&dir.path().join("blk.obj"), &Default::default()).expect("the scene loads");
    // Global levels: the bar is on elements, which the target (on polygon means) does not bound;
    // local levels leave the floor as it is once its mean meets the target, and its worst element
    // beside the block was then 3.67% off (2026-12-06).
    let config = Config { target_error: Some(0.01), criterion, local_levels: false, ..Config::default() };
    let solved = pipeline::run(&scene, &BfHand::default(), &config, &|_| {});
    let h = &solved.hierarchy;
    let floor: Vec<u32> = h
        .leaves()
        .filter(|&e| h.get(e).polygon() == Some(0))
        .filter(|&e| {
            let c = h.get(e).center;
            let d = to_footprint(c.x, c.z);
            d > 0.0 && d <= BAND
        })
        .collect();
    let exact: Vec<f64> = floor.iter().map(|&e| element_irradiance(h, e)).collect();
    let largest = exact.iter().copied().fold(0.0, f64::max);
    let mut worst = Worst { error: 0.0, at: [0.0; 2], size: 0.0, got: 0.0, exact: 0.0, elements: floor.len(), largest };
    for (&e, &x) in floor.iter().zip(&exact) {
        let got = solved.solution.irradiance[e as usize][0];
        let error = (got - x).abs() / largest;
        if error > worst.error {
            let c = h.get(e).center;
            worst = Worst { error, at: [c.x, c.z], size: h.get(e).area.sqrt(), got, exact: x, ..worst };
        }
    }
    worst
}

#[test]
fn the_floor_beside_a_block_reads_its_direct_light_element_by_element() {
    let w = worst_floor_error(Criterion::Irradiance);
    eprintln!(
        "{} floor elements within {BAND} m of the block; worst {:.2}% of {:.3} W/m² at ({:.3}, {:.3}), {:.3} m wide: {:.4} against {:.4}",
        w.elements,
        100.0 * w.error,
        w.largest,
        w.at[0],
        w.at[1],
        w.size,
        w.got,
        w.exact
    );
    assert!(w.elements >= 20, "too few floor elements near the block to judge: {}", w.elements);
    assert!(w.error <= ELEMENT_TOL, "a floor element beside the block is off by {:.2}% of the largest", 100.0 * w.error);
}
