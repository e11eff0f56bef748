//! Ray casting restricted to a shaft's candidate occluders: the visibility fraction of a link from
//! jittered stratified segments, tested in `f64` only against the candidates' polygons.
//!
//! The samples are drawn and weighted exactly as [`crate::visibility::RayCaster::visibility`] does
//! (same generator, strata, order and kernel weights), so with a complete candidate list both give
//! the same estimate up to the `f32` rounding of the global caster.

use super::build::SHAFT_REL_TOL;
use super::objects::ShaftObjects;
use crate::geom::{Aabb, DVec3, Poly};
use crate::hierarchy::{ElementId, Hierarchy};
use crate::visibility::VisibilityConfig;

/// Fraction of the segment length left out at each end, as in the global ray caster, so that the
/// endpoints' neighbours that touch them (a wall meeting the floor) do not occlude.
pub const SEGMENT_END_EPS: f64 = crate::visibility::SEGMENT_END_EPS as f64;

/// Most polygons (summed over a candidate list's objects) for which a link's segments are tested
/// polygon by polygon ([`visibility_among`]); longer lists go through the scene's BVH, whose cost
/// per segment grows with its depth rather than with the list. Measured with `radiosity bench
/// shafts`: on office3 the polygon loop over long lists took 3/4 of the refinement time.
pub const MAX_LOOP_POLYGONS: usize = 48;

/// Longest inherited candidate list (objects) for which a link about to be stored is classified
/// before its segments are cast. Under longer lists a link almost never comes out visible or with
/// a short list (office3: 14 of 24,000), so culling costs what the rays it could save cost, and
/// the link goes straight to the BVH. Chosen by counting instructions (callgrind, one thread) with
/// 4, 8 and 16: 8 keeps nearly all of 16's saving on the generated scenes (stairs −1.1%,
/// sj-geometry −0.7%, duplex −0.9% of the whole solve against 4) for +0.05% on office3 (16: +0.6%).
pub const MAX_CULL_PARENT_OBJECTS: usize = 8;

/// Number of input polygons of the `candidates` objects.
#[must_use]
pub fn n_polygons_among(objects: &ShaftObjects, candidates: &[u32]) -> usize {
    candidates.iter().map(|&id| objects.polygons_of(id).len()).sum()
}

/// Whether the segment `a`–`b` (without its end fractions [`SEGMENT_END_EPS`]) misses every
/// polygon of the `candidates` objects other than `skip_a` and `skip_b`.
#[must_use]
pub fn segment_clear_among(objects: &ShaftObjects, candidates: &[u32], a: DVec3, b: DVec3, skip_a: u32, skip_b: u32) -> bool {
    let d = b - a;
    let inv = d.recip();
    for &id in candidates {
        let o = &objects.objects[id as usize];
        if !segment_meets_inv(a, inv, &o.aabb) {
            continue;
        }
        for &poly_idx in objects.polygons_of(id) {
            if poly_idx == skip_a || poly_idx == skip_b {
                continue;
            }
            if segment_hits_polygon(a, d, &objects.polys[poly_idx as usize]) {
                return false;
            }
        }
    }
    true
}

/// Slab test of the segment `a + t d`, `t` in `[0, 1]`, against a box (`inv` = `1 / d` per axis);
/// the box is widened by a relative margin so that rounding never misses a polygon on its face.
#[must_use]
pub(super) fn segment_meets_inv(a: DVec3, inv: DVec3, b: &Aabb) -> bool {
    let pad = 1e-9 * b.diagonal() + f64::MIN_POSITIVE;
    let (lo, hi) = (b.min - pad, b.max + pad);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        if inv[k].is_infinite() {
            if a[k] < lo[k] || a[k] > hi[k] {
                return false;
            }
            continue;
        }
        let (x, y) = ((lo[k] - a[k]) * inv[k], (hi[k] - a[k]) * inv[k]);
        t0 = t0.max(x.min(y));
        t1 = t1.min(x.max(y));
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// Whether the segment `a + t d`, `t` in `[SEGMENT_END_EPS, 1 − SEGMENT_END_EPS]`, crosses the
/// convex polygon (edges included).
fn segment_hits_polygon(a: DVec3, d: DVec3, poly: &Poly) -> bool {
    poly.crossing(a, d).is_some_and(|t| (SEGMENT_END_EPS..=1.0 - SEGMENT_END_EPS).contains(&t))
}

/// A polygon ready for many segment tests: its plane and in-plane outward edge planes.
#[derive(Clone, Debug)]
pub(super) struct PreparedPolygon {
    polygon: u32,
    normal: DVec3,
    offset: f64,
    edges: [(DVec3, f64); 4],
    n_edges: usize,
}

impl PreparedPolygon {
    pub(super) fn new(poly: &Poly, polygon: u32) -> Option<PreparedPolygon> {
        let normal = poly.area_vector().try_normalize()?;
        let vs = poly.vertices();
        let mut edges = [(DVec3::ZERO, 0.0); 4];
        for k in 0..vs.len() {
            let e = (vs[(k + 1) % vs.len()] - vs[k]).cross(normal);
            edges[k] = (e, e.dot(vs[k]));
        }
        Some(PreparedPolygon { polygon, normal, offset: normal.dot(vs[0]), edges, n_edges: vs.len() })
    }

    /// Whether the segment `a`–`b` crosses the polygon's plane (strictly, anywhere between its
    /// ends) inside the polygon, edges included.
    #[inline]
    pub(super) fn crossed_by(&self, a: DVec3, b: DVec3) -> bool {
        let sa = self.normal.dot(a) - self.offset;
        let sb = self.normal.dot(b) - self.offset;
        if (sa > 0.0) == (sb > 0.0) || sa == sb {
            return false;
        }
        let x = a + (b - a) * (sa / (sa - sb));
        self.edges[..self.n_edges].iter().all(|&(e, off)| e.dot(x) <= off)
    }

    /// Same contract as [`segment_hits_polygon`] for the segment `a`–`b`.
    #[inline]
    fn hit_by(&self, a: DVec3, b: DVec3) -> bool {
        let sa = self.normal.dot(a) - self.offset;
        let sb = self.normal.dot(b) - self.offset;
        if (sa > 0.0) == (sb > 0.0) || sa == sb {
            return false;
        }
        let t = sa / (sa - sb);
        if !(SEGMENT_END_EPS..=1.0 - SEGMENT_END_EPS).contains(&t) {
            return false;
        }
        let x = a + (b - a) * t;
        self.edges[..self.n_edges].iter().all(|&(e, off)| e.dot(x) <= off)
    }
}

/// Visibility of the link `source` → `receiver` from `config.rays` stratified segments, tested only
/// against the `candidates` objects (a shaft's list): the clear segments' share of the transfer
/// kernel `cosθ_s cosθ_r / r²` (regularised), as the global caster weighs them, or the plain clear
/// fraction when no segment carries weight. Returns the visibility and the number of segments cast. Deterministic for a given seed; correct when `candidates` holds every
/// object that meets the link's shaft (as [`ShaftObjects::candidates`] guarantees).
///
/// Before casting, the candidates are narrowed to their polygons whose bounding box meets the
/// box around both elements (which holds every segment), largest first so that blocked segments
/// stop early; the polygons' planes and edges are prepared once per scene.
#[must_use]
pub fn visibility_among(
    objects: &ShaftObjects,
    h: &Hierarchy,
    source: ElementId,
    receiver: ElementId,
    candidates: &[u32],
    config: &VisibilityConfig,
) -> (f64, u32) {
    let extent = h.get(source).bounds.merged(&h.get(receiver).bounds);
    let pad = SHAFT_REL_TOL * extent.diagonal();
    let (lo, hi) = (extent.min - pad, extent.max + pad);
    let own = [h.get(source).polygon(), h.get(receiver).polygon()];
    let mut polys: Vec<(f64, &PreparedPolygon)> = Vec::with_capacity(n_polygons_among(objects, candidates));
    for &id in candidates {
        for &k in objects.polygons_of(id) {
            let Some((area, prepared)) = &objects.prepared[k as usize] else { continue };
            let vs = objects.polys[k as usize].vertices();
            let outside = (0..3).any(|a| vs.iter().all(|v| v[a] < lo[a]) || vs.iter().all(|v| v[a] > hi[a]));
            if !outside && !own.contains(&Some(k)) {
                polys.push((*area, prepared));
            }
        }
    }
    polys.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.polygon.cmp(&b.1.polygon)));
    let v = crate::visibility::sampled_visibility(h, source, receiver, config, |pa, pb, poly_a, poly_b| {
        !polys.iter().any(|(_, p)| p.polygon != poly_a && p.polygon != poly_b && p.hit_by(pa, pb))
    });
    (v, config.rays.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygon_hits_respect_edges_and_ends() {
        let q = Poly::quad(DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y);
        let d = DVec3::new(0.0, 0.0, -2.0);
        assert!(segment_hits_polygon(DVec3::new(0.5, 0.5, 1.0), d, &q));
        assert!(!segment_hits_polygon(DVec3::new(1.5, 0.5, 1.0), d, &q));
        // Ends on the polygon are left out.
        assert!(!segment_hits_polygon(DVec3::new(0.5, 0.5, 2.0), d, &q));
        assert!(segment_meets_inv(DVec3::new(0.5, 0.5, 1.0), d.recip(), &Aabb::from_points(q.vertices())));
        // The prepared test agrees with the plain one.
        let p = PreparedPolygon::new(&q, 0).unwrap();
        for (a, b) in [
            ((0.5, 0.5, 1.0), (0.5, 0.5, -1.0)),
            ((1.5, 0.5, 1.0), (1.5, 0.5, -1.0)),
            ((0.5, 0.5, 2.0), (0.5, 0.5, 0.0)),
            ((0.0, 0.0, 1.0), (1.0, 1.0, -1.0)),
        ] {
            let (a, b) = (DVec3::from(a), DVec3::from(b));
            assert_eq!(p.hit_by(a, b), segment_hits_polygon(a, b - a, &q), "{a} -> {b}");
        }
    }
}
