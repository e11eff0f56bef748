//! What part of a leaf a point gathers from: the half-spaces through the point (in front of the
//! receiver, on the point's side of every surface it lies on), the leaf clipped to them, and
//! Lambert's exact form factor of what is left.

use super::{MAX_SIDES, MAX_VERTICES, SAME_SIDE_EPS};
use crate::formfactor::point_polygon_unclipped;
use crate::geom::DVec3;

/// Half-spaces `m · (y − x) ≥ 0` through the point `x`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sides {
    pub(super) x: DVec3,
    pub(super) normals: [DVec3; MAX_SIDES],
    pub(super) len: usize,
}

impl Sides {
    /// Adds the half-space of unit normal `m` unless it is already there or there is no room;
    /// true when added.
    pub(super) fn add(&mut self, m: DVec3) -> bool {
        if self.len == MAX_SIDES || self.normals[..self.len].iter().any(|k| k.dot(m) >= 1.0 - SAME_SIDE_EPS) {
            return false;
        }
        self.normals[self.len] = m;
        self.len += 1;
        true
    }

    /// True when the sphere of `center` and `radius` lies wholly behind one of the planes.
    pub(super) fn sphere_behind(&self, center: DVec3, radius: f64) -> bool {
        self.normals[..self.len].iter().any(|m| m.dot(center - self.x) < -radius)
    }

    /// The convex polygon `poly` clipped to every half-space (Sutherland–Hodgman); fewer than 3
    /// vertices when nothing is left.
    pub(super) fn clip(&self, poly: &[DVec3]) -> Clipped {
        let mut cur = Clipped { v: [DVec3::ZERO; MAX_VERTICES], len: poly.len(), unclipped: true };
        cur.v[..poly.len()].copy_from_slice(poly);
        for m in &self.normals[..self.len] {
            let d = |v: DVec3| m.dot(v - self.x);
            let vs = cur.vertices();
            if vs.iter().all(|&v| d(v) >= 0.0) {
                continue;
            }
            let mut next = Clipped { v: [DVec3::ZERO; MAX_VERTICES], len: 0, unclipped: false };
            for i in 0..vs.len() {
                let (a, b) = (vs[i], vs[(i + 1) % vs.len()]);
                let (da, db) = (d(a), d(b));
                if da >= 0.0 {
                    next.push(a);
                }
                if (da >= 0.0) != (db >= 0.0) {
                    next.push(a + (da / (da - db)) * (b - a));
                }
            }
            cur = next;
            if cur.len < 3 {
                break;
            }
        }
        cur
    }
}

/// A convex polygon of at most [`MAX_VERTICES`] vertices.
#[derive(Clone, Copy, Debug)]
pub(super) struct Clipped {
    v: [DVec3; MAX_VERTICES],
    len: usize,
    /// No plane cut the polygon: these are its own vertices.
    pub(super) unclipped: bool,
}

impl Clipped {
    pub(super) fn vertices(&self) -> &[DVec3] {
        &self.v[..self.len]
    }

    fn push(&mut self, p: DVec3) {
        // A convex polygon of at most 4 vertices cut by MAX_SIDES planes has room.
        if self.len < MAX_VERTICES {
            self.v[self.len] = p;
            self.len += 1;
        }
    }
}

/// Lambert's form factor from `x` (unit normal `n`) to a polygon already clipped to the front of
/// every plane through `x`; 0 when fewer than 3 vertices are left.
pub(super) fn form_factor(x: DVec3, n: DVec3, clipped: &Clipped) -> f64 {
    if clipped.len < 3 { 0.0 } else { point_polygon_unclipped(x, n, clipped.vertices()).max(0.0) }
}
