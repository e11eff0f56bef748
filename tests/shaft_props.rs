//! Property tests of shaft culling (issue 4): the occlusion test never claims "invisible" when some
//! segment between the two elements is unblocked, and candidate lists never miss an object that
//! meets the shaft.
//!
//! Each case is generated from a seed drawn by proptest (the generator below is deterministic in
//! the seed, so a failure names the seed that reproduces it). The ground truth is an independent
//! `f64` segment test against every occluder polygon on a dense grid of segments: 8 × 8 points on
//! each element (corners and edges included), 64 × 64 segments per claim.

use glam::DQuat;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use radiosity_core::geom::{Aabb, DVec3, Poly};
use radiosity_core::hierarchy::{self, BuildConfig};
use radiosity_core::scene::shapes::box_faces;
use radiosity_core::scene::{Material, Scene, SceneBuilder};
use radiosity_core::visibility::shaft::{self, BoundingVolume, ObjectConfig, Shaft, ShaftClass, ShaftObjects};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Cases per occlusion property; four properties, 100,000 cases in all.
const CASES: u32 = 25_000;
/// Grid points per element side (8 × 8 = 64 points, 64 × 64 segments).
const GRID: usize = 8;
/// Ground truth: hits closer than this fraction of the segment to an end do not count (the
/// occlusion test keeps its crossings farther away than that).
const END_FRACTION: f64 = 1e-9;
/// Ground truth: relative tolerance of the point-in-polygon test (edges count as hits).
const EDGE_REL_TOL: f64 = 1e-9;

/// SplitMix64: the case generator.
struct Gen(u64);

impl Gen {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn f(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f()
    }
    fn chance(&mut self, p: f64) -> bool {
        self.f() < p
    }
    fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0));
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
    fn rotation(&mut self) -> DQuat {
        DQuat::from_axis_angle(self.unit(), self.range(0.0, std::f64::consts::TAU))
    }
    /// A normal within `max_tilt` radians of `axis`.
    fn tilted(&mut self, axis: DVec3, max_tilt: f64) -> DVec3 {
        let side = axis.any_orthonormal_vector();
        let tilt = DQuat::from_axis_angle(side, self.range(0.0, max_tilt));
        let spin = DQuat::from_axis_angle(axis, self.range(0.0, std::f64::consts::TAU));
        spin * (tilt * axis)
    }
}

/// A scene under construction plus the polygon indices of the two elements.
struct Case {
    b: SceneBuilder,
    mat: u32,
    p: Option<u32>,
    q: Option<u32>,
}

impl Case {
    fn new() -> Case {
        let mut b = SceneBuilder::new(Path::new("shaft property case"), "case");
        let mat = b.material(Material::diffuse("grey", [0.5; 3])).expect("valid material");
        Case { b, mat, p: None, q: None }
    }

    fn face(&mut self, vs: &[DVec3], group: &str) -> Option<u32> {
        let g = self.b.group(group);
        let before = self.b.n_polygons();
        self.b.face(vs, self.mat, g, 0).expect("finite vertices");
        (self.b.n_polygons() == before + 1).then_some(before as u32)
    }

    /// A closed box (outward faces), rotated by `rot` about its centre; returns its first polygon.
    fn solid_box(&mut self, lo: DVec3, hi: DVec3, rot: DQuat, group: &str) -> u32 {
        let first = self.b.n_polygons() as u32;
        let c = 0.5 * (lo + hi);
        for (_, q) in box_faces(lo, hi, false) {
            let vs = q.map(|v| c + rot * (v - c));
            self.face(&vs, group);
        }
        first
    }
}

/// A random quad or triangle centred near `c` with a normal near `n`.
fn element(g: &mut Gen, c: DVec3, n: DVec3, max_tilt: f64) -> Vec<DVec3> {
    let n = g.tilted(n, max_tilt);
    let u0 = n.any_orthonormal_vector();
    let u = DQuat::from_axis_angle(n, g.range(0.0, 6.3)) * u0;
    let v = n.cross(u);
    let (su, sv) = (g.range(0.05, 0.6), g.range(0.05, 0.6));
    if g.chance(0.7) {
        vec![c - u * su - v * sv, c + u * su - v * sv, c + u * su + v * sv, c - u * su + v * sv]
    } else {
        let t = [c - u * su - v * sv, c + u * su - v * sv * g.f(), c + u * su * g.range(-1.0, 1.0) + v * sv];
        t.to_vec()
    }
}

/// Points of a polygon on a GRID × GRID parameter grid, corners and edges included.
fn grid_points(poly: &Poly) -> Vec<DVec3> {
    let k = (GRID - 1) as f64;
    let mut out = Vec::with_capacity(GRID * GRID);
    for i in 0..GRID {
        for j in 0..GRID {
            let (s, t) = (i as f64 / k, j as f64 / k);
            match poly.n_vertices() {
                4 => out.push(poly.point(s, t)),
                // Triangles: the fold keeps the grid on the triangle and covers its edges.
                _ => out.push(if s + t > 1.0 { poly.point(1.0 - s, 1.0 - t) } else { poly.point(s, t) }),
            }
        }
    }
    out
}

/// Independent ground truth: whether segment a–b crosses the convex polygon away from its ends.
fn blocks(a: DVec3, b: DVec3, poly: &Poly, scale: f64) -> bool {
    let n = poly.normal();
    let d = b - a;
    let denom = n.dot(d);
    if denom == 0.0 {
        return false;
    }
    let t = n.dot(poly.v[0] - a) / denom;
    if !(END_FRACTION..=1.0 - END_FRACTION).contains(&t) {
        return false;
    }
    let x = a + d * t;
    let vs = poly.vertices();
    (0..vs.len()).all(|k| {
        let e = (vs[(k + 1) % vs.len()] - vs[k]).normalize_or_zero();
        e.cross(x - vs[k]).dot(n) >= -EDGE_REL_TOL * scale
    })
}

/// Asserts that every segment between the point sets is blocked by some polygon of `scene` other
/// than `skip`, testing the polygons of `first` (the claimed occluder) before the others.
fn assert_all_blocked(
    scene: &Scene,
    pa: &[DVec3],
    pb: &[DVec3],
    skip: [Option<u32>; 2],
    first: &[u32],
    seed: u64,
) -> Result<(), TestCaseError> {
    let scale = scene.bounds().diagonal();
    let mut order: Vec<u32> = first.to_vec();
    order.extend((0..scene.polygons.len() as u32).filter(|k| !first.contains(k)));
    order.retain(|k| !skip.contains(&Some(*k)));
    for &a in pa {
        for &b in pb {
            let blocked = order.iter().any(|&k| blocks(a, b, &scene.polygons[k as usize].poly, scale));
            prop_assert!(blocked, "false occlusion (seed {seed:#x}): segment {a} -> {b} is unblocked");
        }
    }
    Ok(())
}

/// What a generated configuration contains.
#[derive(Clone, Copy, Debug)]
enum Kind {
    AxisBox,
    RotatedBox,
    Plate,
    ThinRotatedBox,
    SplitPlate,
    Behind,
    TouchingSeparate,
    TouchingOwnFace,
    Inside,
    Several,
}

/// Puts the elements P (near z = 0, facing +z) and Q (near z = h, facing −z) and the occluders of
/// `kind` into a scene, then scales and moves the whole scene at random.
fn generate(seed: u64, kind: Kind) -> (Scene, u32, u32) {
    let mut g = Gen(seed);
    let mut c = Case::new();
    let h = g.range(0.8, 3.0);
    let flat_p = matches!(kind, Kind::TouchingSeparate | Kind::TouchingOwnFace);
    let pc = DVec3::new(g.range(-0.3, 0.3), g.range(-0.3, 0.3), 0.0);
    // With P on top of a box, Q is sometimes below it: every segment then runs through the box.
    let q_below = flat_p && g.chance(0.5);
    let qc = DVec3::new(g.range(-0.5, 0.5), g.range(-0.5, 0.5), if q_below { -h } else { h });
    let pv = element(&mut g, pc, DVec3::Z, if flat_p { 0.0 } else { 1.0 });
    let qv = element(&mut g, qc, if q_below { DVec3::Z } else { -DVec3::Z }, 1.0);
    let mid_box = |g: &mut Gen, thin: (f64, f64)| {
        let cz = g.range(0.25 * h, 0.75 * h);
        let cc = DVec3::new(g.range(-0.5, 0.5), g.range(-0.5, 0.5), cz);
        let half = DVec3::new(g.range(0.1, 1.6), g.range(0.1, 1.6), g.range(thin.0, thin.1));
        (cc - half, cc + half)
    };
    match kind {
        Kind::AxisBox => {
            let (lo, hi) = mid_box(&mut g, (0.01, 0.4));
            c.solid_box(lo, hi, DQuat::IDENTITY, "box");
        }
        Kind::RotatedBox => {
            let (lo, hi) = mid_box(&mut g, (0.01, 0.4));
            let rot = DQuat::from_axis_angle(g.unit(), g.range(0.0, 0.8));
            c.solid_box(lo, hi, rot, "box");
        }
        Kind::ThinRotatedBox => {
            let (lo, hi) = mid_box(&mut g, (1e-4, 1e-2));
            let rot = DQuat::from_axis_angle(g.unit(), g.range(0.0, 0.6));
            c.solid_box(lo, hi, rot, "plate box");
        }
        Kind::Plate => {
            let centre = DVec3::new(g.range(-0.5, 0.5), g.range(-0.5, 0.5), g.range(0.1 * h, 0.9 * h));
            let plate = element(&mut g, centre, DVec3::Z, 0.7);
            let grow = g.range(1.5, 5.0);
            let big: Vec<DVec3> = plate.iter().map(|&v| centre + (v - centre) * grow).collect();
            if g.chance(0.5) {
                let rev: Vec<DVec3> = big.iter().rev().copied().collect();
                c.face(&rev, "plate");
            } else {
                c.face(&big, "plate");
            }
        }
        Kind::SplitPlate => {
            // A rectangle split into coplanar pieces sharing exact vertices: two triangles, a 2 × 2
            // grid or three strips (only their merged union can block the shaft).
            let centre = DVec3::new(g.range(-0.5, 0.5), g.range(-0.5, 0.5), g.range(0.2 * h, 0.8 * h));
            let n = g.tilted(DVec3::Z, 0.6);
            let u = DQuat::from_axis_angle(n, g.range(0.0, 6.3)) * n.any_orthonormal_vector();
            let v = n.cross(u);
            let (su, sv) = (g.range(0.5, 2.0), g.range(0.5, 2.0));
            let (nu, nv) = match g.next() % 3 {
                0 => (1, 1),
                1 => (2, 2),
                _ => (3, 1),
            };
            let pt =
                |i: usize, j: usize| centre + u * (su * (2.0 * i as f64 / nu as f64 - 1.0)) + v * (sv * (2.0 * j as f64 / nv as f64 - 1.0));
            for i in 0..nu {
                for j in 0..nv {
                    let (a, b, cc, d) = (pt(i, j), pt(i + 1, j), pt(i + 1, j + 1), pt(i, j + 1));
                    if nu == 1 {
                        c.face(&[a, b, cc], "split plate");
                        c.face(&[a, cc, d], "split plate");
                    } else {
                        c.face(&[a, b, cc, d], "split plate");
                    }
                }
            }
        }
        Kind::Behind => {
            // Below P (beyond P seen from Q), possibly reaching up through P's plane, or above Q.
            let (z0, z1) =
                if g.chance(0.5) { (g.range(-2.0, -0.3), g.range(-0.2, 0.3)) } else { (h + g.range(-0.3, 0.2), h + g.range(0.3, 2.0)) };
            let half = DVec3::new(g.range(0.2, 2.0), g.range(0.2, 2.0), 0.0);
            let rot = if g.chance(0.5) { DQuat::IDENTITY } else { DQuat::from_axis_angle(g.unit(), g.range(0.0, 0.4)) };
            c.solid_box(DVec3::new(-half.x, -half.y, z0), DVec3::new(half.x, half.y, z1), rot, "behind");
        }
        Kind::TouchingSeparate | Kind::TouchingOwnFace => {
            // A box whose top face lies in P's plane (z = 0): P on the box, or beside it.
            let half = DVec3::new(g.range(0.05, 1.5), g.range(0.05, 1.5), 0.0);
            let off = DVec3::new(g.range(-0.8, 0.8), g.range(-0.8, 0.8), 0.0);
            let depth = g.range(0.05, 1.0);
            let (lo, hi) = (off - half - DVec3::Z * depth, off + half);
            let first = c.solid_box(lo, hi, DQuat::IDENTITY, "stand");
            if matches!(kind, Kind::TouchingOwnFace) {
                c.p = Some(first + 5); // the box's z+ face is the element
            }
        }
        Kind::Inside => {
            // A closed box around P; Q outside or inside it.
            let lo = DVec3::new(-1.2, -1.2, g.range(-0.8, -0.05));
            let top = if g.chance(0.5) { g.range(0.1, 0.7) * h } else { h + g.range(0.05, 0.5) };
            c.solid_box(lo, DVec3::new(1.2, 1.2, top), DQuat::IDENTITY, "shell");
        }
        Kind::Several => {
            for k in 0..(2 + g.next() % 3) {
                let (lo, hi) = mid_box(&mut g, (0.005, 0.3));
                let rot = if g.chance(0.5) { DQuat::IDENTITY } else { DQuat::from_axis_angle(g.unit(), g.range(0.0, 0.5)) };
                c.solid_box(lo * DVec3::new(0.7, 0.7, 1.0), hi * DVec3::new(0.7, 0.7, 1.0), rot, &format!("box{k}"));
            }
        }
    }
    if c.p.is_none() {
        c.p = c.face(&pv, "p");
    }
    c.q = c.face(&qv, "q");
    let (p, q) = (c.p.expect("non-degenerate element"), c.q.expect("non-degenerate element"));
    let mut scene = c.b.finish();
    if g.chance(0.3) {
        let s = 10f64.powf(g.range(-3.0, 3.0));
        let t = DVec3::new(g.range(-1e3, 1e3), g.range(-1e3, 1e3), g.range(-1e3, 1e3)) * s;
        scene.transform(|v| v * s + t);
    }
    (scene, p, q)
}

/// Runs `cases` configurations of the given kinds through [`shaft::classify`] (a random bounding
/// volume each) and checks every "invisible" claim on the dense grid. Returns (cases, claims).
fn check_classify(kinds: &[Kind], cases: u32, salt: u64) -> (usize, usize) {
    let claims = AtomicUsize::new(0);
    let config = Config { cases, failure_persistence: None, max_shrink_iters: 0, ..Config::default() };
    let mut runner = TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let result = runner.run(&(any::<u64>(), 0..kinds.len(), 0..3u8), |(seed, kind_idx, volume)| {
        let seed = seed ^ salt;
        let (scene, p, q) = generate(seed, kinds[kind_idx]);
        let volume = [BoundingVolume::Aabb, BoundingVolume::Obb, BoundingVolume::Hull][volume as usize];
        let objects = ShaftObjects::new(&scene, &ObjectConfig { volume, ..ObjectConfig::default() });
        let h = hierarchy::build(&scene, &BuildConfig::default());
        let verdict = shaft::classify(&objects, &h, p, q, None);
        if verdict.class == ShaftClass::Invisible {
            claims.fetch_add(1, Ordering::Relaxed);
            let first = verdict.occluder.map(|o| objects.polygons_of(o).to_vec()).unwrap_or_default();
            let (pp, qp) = (&scene.polygons[p as usize].poly, &scene.polygons[q as usize].poly);
            assert_all_blocked(&scene, &grid_points(pp), &grid_points(qp), [Some(p), Some(q)], &first, seed)?;
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    (cases as usize, claims.into_inner())
}

fn report(name: &str, (cases, claims): (usize, usize), min_fraction: f64) {
    eprintln!("{name}: {claims} invisible claims in {cases} cases, all confirmed on {0}x{0} segments", GRID * GRID);
    assert!(
        claims as f64 >= min_fraction * cases as f64,
        "{name}: only {claims} claims in {cases} cases: the property is barely exercised"
    );
}

#[test]
fn no_false_occlusion_single_occluder_between() {
    let r = check_classify(&[Kind::AxisBox, Kind::RotatedBox, Kind::Plate, Kind::ThinRotatedBox, Kind::SplitPlate], CASES, 0x5eed_0001);
    report("single occluder between", r, 0.05);
}

#[test]
fn no_false_occlusion_behind_touching_or_containing() {
    let r = check_classify(&[Kind::Behind, Kind::TouchingSeparate, Kind::TouchingOwnFace, Kind::Inside], CASES, 0x5eed_0002);
    // Occluders behind or touching an element never block; only a shell around P with Q outside does.
    report("behind / touching / containing", r, 0.02);
}

#[test]
fn no_false_occlusion_several_occluders() {
    let r = check_classify(&[Kind::Several], CASES, 0x5eed_0003);
    report("several occluders", r, 0.02);
}

/// Clusters: the elements are boxes (8 corners) holding surfaces anywhere inside; the ground truth
/// uses a 4 × 4 × 4 lattice of points in each box (64 × 64 segments).
#[test]
fn no_false_occlusion_cluster_boxes() {
    let claims = AtomicUsize::new(0);
    let config = Config { cases: CASES, failure_persistence: None, max_shrink_iters: 0, ..Config::default() };
    let mut runner = TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let result = runner.run(&any::<u64>(), |seed| {
        let mut g = Gen(seed);
        let h = g.range(0.8, 3.0);
        let small_box = |g: &mut Gen, z: f64| {
            let c = DVec3::new(g.range(-0.4, 0.4), g.range(-0.4, 0.4), z);
            let half = DVec3::new(g.range(0.02, 0.5), g.range(0.02, 0.5), g.range(0.0, 0.3));
            Aabb { min: c - half, max: c + half }
        };
        let (bp, bq) = (small_box(&mut g, 0.0), small_box(&mut g, h));
        let mut c = Case::new();
        let cz = g.range(0.2 * h, 0.8 * h);
        let half = DVec3::new(g.range(0.2, 1.8), g.range(0.2, 1.8), g.range(0.005, 0.3));
        let centre = DVec3::new(g.range(-0.5, 0.5), g.range(-0.5, 0.5), cz);
        let rot = if g.chance(0.5) { DQuat::IDENTITY } else { DQuat::from_axis_angle(g.unit(), g.range(0.0, 0.5)) };
        c.solid_box(centre - half, centre + half, rot, "box");
        let scene = c.b.finish();
        let objects = ShaftObjects::new(&scene, &ObjectConfig::default());
        let pv = shaft::aabb_corners(&bp).to_vec();
        let qv = shaft::aabb_corners(&bq).to_vec();
        if shaft::occludes(&objects, 0, &pv, &qv, &[]) {
            claims.fetch_add(1, Ordering::Relaxed);
            let lattice = |b: &Aabb| -> Vec<DVec3> {
                let mut out = Vec::with_capacity(64);
                for i in 0..4 {
                    for j in 0..4 {
                        for k in 0..4 {
                            let f = DVec3::new(i as f64, j as f64, k as f64) / 3.0;
                            out.push(b.min + (b.max - b.min) * f);
                        }
                    }
                }
                out
            };
            assert_all_blocked(&scene, &lattice(&bp), &lattice(&bq), [None, None], &[], seed)?;
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    report("cluster boxes", (CASES as usize, claims.into_inner()), 0.05);
}

/// Exact polygon–shaft intersection: clip the polygon by every plane of the shaft (no tolerance).
fn polygon_meets_shaft(poly: &Poly, s: &Shaft) -> bool {
    let mut pts: Vec<DVec3> = poly.vertices().to_vec();
    for pl in s.planes() {
        let mut next = Vec::with_capacity(pts.len() + 1);
        for k in 0..pts.len() {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            let (da, db) = (pl.distance(a), pl.distance(b));
            if da <= 0.0 {
                next.push(a);
            }
            if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
                next.push(a + (b - a) * (da / (da - db)));
            }
        }
        pts = next;
        if pts.is_empty() {
            return false;
        }
    }
    true
}

/// Random clutter: triangles, quads and boxes (some rotated), in groups of 1 to 6 polygons.
fn clutter(g: &mut Gen) -> Scene {
    let mut c = Case::new();
    let n = 10 + g.next() % 30;
    for k in 0..n {
        let centre = DVec3::new(g.range(-2.0, 2.0), g.range(-2.0, 2.0), g.range(-2.0, 2.0));
        match g.next() % 3 {
            0 => {
                let half = DVec3::new(g.range(0.01, 0.6), g.range(0.01, 0.6), g.range(0.01, 0.6));
                c.solid_box(centre - half, centre + half, g.rotation(), &format!("box{k}"));
            }
            _ => {
                let group = format!("g{}", k % 7);
                let n_dir = g.unit();
                let vs = element(g, centre, n_dir, 0.0);
                c.face(&vs, &group);
            }
        }
    }
    c.b.finish()
}

/// Culling is exact for the intersection test: for random shafts and clutter, every object with a
/// polygon meeting the shaft is a candidate, for each bounding volume, through the BVH and through
/// the parent's list (the shaft of sub-boxes of the parent's boxes).
#[test]
fn candidate_lists_are_complete() {
    let n_found = AtomicUsize::new(0);
    let config = Config { cases: 3_000, failure_persistence: None, max_shrink_iters: 0, ..Config::default() };
    let mut runner = TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let result = runner.run(&any::<u64>(), |seed| {
        let mut g = Gen(seed);
        let scene = clutter(&mut g);
        let rand_box = |g: &mut Gen| {
            let c = DVec3::new(g.range(-2.5, 2.5), g.range(-2.5, 2.5), g.range(-2.5, 2.5));
            let half = DVec3::new(g.range(0.0, 0.8), g.range(0.0, 0.8), g.range(0.0, 0.8));
            Aabb { min: c - half, max: c + half }
        };
        let (a, b) = (rand_box(&mut g), rand_box(&mut g));
        let sub = |g: &mut Gen, bx: &Aabb| {
            let t0 = DVec3::new(g.f(), g.f(), g.f());
            let t1 = DVec3::new(g.f(), g.f(), g.f());
            let p0 = bx.min + bx.extent() * t0.min(t1);
            let p1 = bx.min + bx.extent() * t0.max(t1);
            Aabb { min: p0, max: p1 }
        };
        let (a2, b2) = (sub(&mut g, &a), sub(&mut g, &b));
        let (parent, child) = (Shaft::new(&a, &b), Shaft::new(&a2, &b2));
        for volume in [BoundingVolume::Aabb, BoundingVolume::Obb, BoundingVolume::Hull] {
            let objects = ShaftObjects::new(&scene, &ObjectConfig { volume, max_polygons: 3, ..ObjectConfig::default() });
            let parent_list = objects.candidates(&parent, None);
            let child_list = objects.candidates(&child, Some(&parent_list));
            let child_direct = objects.candidates(&child, None);
            // The bounding-volume tests are not monotone (different planes), so the inherited list may
            // be shorter than a fresh search; it is a subset, and complete (checked below).
            prop_assert!(child_list.iter().all(|k| child_direct.contains(k)), "seed {:#x}: inherited list not within the fresh one", seed);
            for (id, _) in objects.objects.iter().enumerate() {
                for &poly in objects.polygons_of(id as u32) {
                    let poly = &objects.polys[poly as usize];
                    if polygon_meets_shaft(poly, &parent) {
                        n_found.fetch_add(1, Ordering::Relaxed);
                        prop_assert!(parent_list.contains(&(id as u32)), "seed {:#x}: object {} missing ({:?})", seed, id, volume);
                    }
                    if polygon_meets_shaft(poly, &child) {
                        prop_assert!(
                            child_list.contains(&(id as u32)),
                            "seed {:#x}: object {} missing from child ({:?})",
                            seed,
                            id,
                            volume
                        );
                    }
                }
            }
        }
        // The shaft contains the hull of its boxes: points on segments between them.
        for _ in 0..16 {
            let pa = a.min + a.extent() * DVec3::new(g.f(), g.f(), g.f());
            let pb = b.min + b.extent() * DVec3::new(g.f(), g.f(), g.f());
            let x = pa.lerp(pb, g.f());
            prop_assert!(parent.contains_point(x), "seed {:#x}: hull point {} outside the shaft", seed, x);
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    let n_found = n_found.into_inner();
    assert!(n_found > 10_000, "too few intersecting objects ({n_found}) to exercise culling");
}
