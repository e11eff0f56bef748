//! The sampling geometry: directions on the sphere, a box's projected area and shadow, and
//! cosine-distributed directions.

use crate::geom::{Aabb, DVec3};
use crate::visibility::Rng;
use std::f64::consts::PI;

/// `n` nearly uniform unit directions (Fibonacci sphere), deterministic.
#[must_use]
pub fn sphere_directions(n: u32) -> Vec<DVec3> {
    let n = n.max(1);
    let golden = PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// Projected area of a box seen along `dir` (unit), m².
#[must_use]
pub fn box_projected_area(b: &Aabb, dir: DVec3) -> f64 {
    if b.is_empty() {
        return 0.0;
    }
    let e = b.extent();
    e.y * e.z * dir.x.abs() + e.x * e.z * dir.y.abs() + e.x * e.y * dir.z.abs()
}

/// An orthonormal pair perpendicular to unit `d`.
pub(in crate::instancing) fn basis(d: DVec3) -> (DVec3, DVec3) {
    let helper = if d.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let u = d.cross(helper).normalize();
    (u, d.cross(u))
}

/// Slab test: does the line `o + t·d`, t ≥ 0, meet the box?
pub(super) fn hits_box(b: &Aabb, o: DVec3, d: DVec3) -> bool {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        if d[a].abs() < 1e-300 {
            if o[a] < b.min[a] || o[a] > b.max[a] {
                return false;
            }
            continue;
        }
        let inv = 1.0 / d[a];
        let (mut ta, mut tb) = ((b.min[a] - o[a]) * inv, (b.max[a] - o[a]) * inv);
        if ta > tb {
            std::mem::swap(&mut ta, &mut tb);
        }
        t0 = t0.max(ta);
        t1 = t1.min(tb);
    }
    t0 <= t1
}

/// Cosine-distributed unit direction about unit `n`.
pub(super) fn cosine_dir(n: DVec3, rng: &mut Rng) -> DVec3 {
    let (r1, r2) = (rng.next_f64(), rng.next_f64());
    cosine_dir_from(n, r1, r2)
}

/// Cosine-distributed unit direction about unit `n` from two uniform numbers in [0, 1).
pub(in crate::instancing) fn cosine_dir_from(n: DVec3, r1: f64, r2: f64) -> DVec3 {
    let (u, v) = basis(n);
    let r = r1.sqrt();
    let phi = 2.0 * PI * r2;
    (u * (r * phi.cos()) + v * (r * phi.sin()) + n * (1.0 - r1).max(0.0).sqrt()).normalize_or_zero()
}
