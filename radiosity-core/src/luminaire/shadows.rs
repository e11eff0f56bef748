//! Where the polygons' shadows fall along a distant source's direction (the sun): the shadows
//! smaller than an element that its points may miss, and each element's exactly lit share.

use super::SHADOW_ORIGIN_OFFSET_REL;
use crate::geom::{Aabb, DVec3};
use crate::hierarchy::{Hierarchy, NONE};
use crate::visibility::RayCaster;

/// Whether some polygon casts a shadow along `toward` (a distant source's direction of travel) on
/// part of surface element `id` smaller than the element (in size or in area: a sliver cast by a
/// leaf seen edge-on): one that its quadrature points may all miss (a 1 m² leaf's shadow on a 100 m² ground fell between the 9 points of the ground's rule,
/// which then got the sun as if nothing stood over it). Found through `occluders` (a box
/// hierarchy over the input polygons, see [`polygon_boxes`]) with the shaft the element's box
/// sweeps toward the source, then exactly: the candidate's part in front of the element's plane,
/// projected along `toward` onto it, overlapping the element (separating axes).
pub(super) fn smaller_shadow_falls_on(h: &Hierarchy, id: u32, toward: DVec3, occluders: &crate::visibility::shaft::ObjectBvh) -> bool {
    let e = h.get(id);
    let (Some(poly), Some(polygon)) = (e.poly(), e.polygon()) else { return false };
    let n = e.normal;
    let own = poly.vertices();
    let mut found = false;
    for_each_shadow(h, poly, n, polygon, toward, occluders, |shadow| {
        let centre = shadow.iter().copied().sum::<DVec3>() / shadow.len() as f64;
        let radius = shadow.iter().map(|&v| (v - centre).length()).fold(0.0, f64::max);
        // Small, or thin: a leaf seen edge-on casts a sliver longer than the element and
        // narrower than its points' spacing.
        let area = 0.5 * (1..shadow.len() - 1).map(|k| (shadow[k] - shadow[0]).cross(shadow[k + 1] - shadow[0]).dot(n).abs()).sum::<f64>();
        if radius < e.radius || area < e.area {
            found = convex_overlap(own, shadow, n);
        }
        !found
    });
    found
}

/// Calls `visit` with the shadow that each polygon of `h` but `own` casts along `toward` (a
/// distant source's direction of travel) on the plane of element `poly` (normal `n`): the
/// polygon's part in front of the plane (Sutherland–Hodgman, one plane), projected along `toward`
/// onto it; until `visit` returns `false`. The element's other side (its polygon's twin) casts
/// none. The candidates come from `occluders` (a box hierarchy
/// over the input polygons, [`polygon_boxes`]) through the shaft the element's box sweeps toward
/// the source; a shadow may still miss the element. Nothing on a plane the light does not face.
fn for_each_shadow(
    h: &Hierarchy,
    poly: &crate::geom::Poly,
    n: DVec3,
    own: u32,
    toward: DVec3,
    occluders: &crate::visibility::shaft::ObjectBvh,
    mut visit: impl FnMut(&[DVec3]) -> bool,
) {
    let dn = toward.dot(n);
    if dn >= 0.0 {
        return;
    }
    let bounds = Aabb::from_points(poly.vertices());
    let reach = 2.0 * h.diagonal();
    let swept = Aabb { min: bounds.min - toward * reach, max: bounds.max - toward * reach };
    let shaft = crate::visibility::shaft::Shaft::new(&bounds, &swept);
    let x0 = poly.v[0];
    // What lies this near the plane is on it, as for a shadow ray, which starts this far off it
    // (a leaf's other side, or a polygon sharing an edge, written with a few decimals in a file).
    let tol = SHADOW_ORIGIN_OFFSET_REL * h.diagonal();
    let twin = h.twin.get(own as usize).copied().unwrap_or(NONE);
    let stopped = std::cell::Cell::new(false);
    let mut front: Vec<DVec3> = Vec::with_capacity(8);
    occluders.traverse(
        |b| !stopped.get() && shaft.may_intersect_aabb(b),
        |q| {
            if stopped.get() || q == own || q == twin {
                return;
            }
            let Some(other) = h.get(q).poly() else { return };
            let vs = other.vertices();
            front.clear();
            for k in 0..vs.len() {
                let (a, b) = (vs[k], vs[(k + 1) % vs.len()]);
                let (da, db) = (n.dot(a - x0) - tol, n.dot(b - x0) - tol);
                if da > 0.0 {
                    front.push(a);
                }
                if (da > 0.0) != (db > 0.0) {
                    front.push(a + (b - a) * (da / (da - db)));
                }
            }
            if front.len() < 3 {
                return;
            }
            let shadow: Vec<DVec3> = front.iter().map(|&v| v - toward * (n.dot(v - x0) / dn)).collect();
            if !visit(&shadow) {
                stopped.set(true);
            }
        },
    );
}

/// The shadows the scene's polygons cast on surface elements along the sharp distant sources'
/// directions (the sun), found exactly: each polygon's shadow on the element's plane
/// ([`for_each_shadow`]) clipped to the element, and their union's area
/// ([`crate::geom::union_area`]). The element's mean irradiance from such a source is then its
/// unoccluded irradiance times the lit share: no quadrature, no quadrature error, however small
/// or thin the shadows (a leaf's on the ground under it, a sliver cast by a leaf seen edge-on),
/// where shadow rays at a rule's points see only what falls on the points.
pub(crate) struct ParallelShadows<'a> {
    h: &'a Hierarchy,
    occluders: crate::visibility::shaft::ObjectBvh,
}

impl<'a> ParallelShadows<'a> {
    /// The shadows of `h`'s polygons, where `sources` include a sharp one and there is a `caster`
    /// (visibility is on); `None` otherwise.
    pub(super) fn new(
        h: &'a Hierarchy,
        sources: &[crate::light::DistantSource],
        caster: Option<&RayCaster>,
    ) -> Option<ParallelShadows<'a>> {
        (caster.is_some() && sources.iter().any(|s| s.sharp)).then(|| ParallelShadows { h, occluders: polygon_boxes(h) })
    }

    /// The share of element `poly` (normal `n`, of polygon `own`) that light travelling along
    /// `toward` reaches: 1 less the union of the other polygons' shadows on it over its area.
    pub(super) fn lit_share(&self, poly: &crate::geom::Poly, n: DVec3, own: u32, toward: DVec3) -> f64 {
        use crate::geom::union_area::{clip_convex, signed_area2, union_area};
        let x0 = poly.v[0];
        let u = (poly.v[1] - x0).normalize_or_zero();
        let w = n.cross(u);
        let flat = |p: DVec3| [u.dot(p - x0), w.dot(p - x0)];
        let mut window: Vec<[f64; 2]> = poly.vertices().iter().map(|&p| flat(p)).collect();
        let area2 = signed_area2(&window);
        if area2 < 0.0 {
            window.reverse();
        }
        let area = 0.5 * area2.abs();
        if area <= 0.0 {
            return 1.0;
        }
        let mut pieces: Vec<Vec<[f64; 2]>> = Vec::new();
        for_each_shadow(self.h, poly, n, own, toward, &self.occluders, |shadow| {
            let mut flat_shadow: Vec<[f64; 2]> = shadow.iter().map(|&p| flat(p)).collect();
            if signed_area2(&flat_shadow) < 0.0 {
                flat_shadow.reverse();
            }
            let piece = clip_convex(&flat_shadow, &window);
            if !piece.is_empty() {
                pieces.push(piece);
            }
            true
        });
        if pieces.is_empty() {
            return 1.0;
        }
        (1.0 - union_area(&pieces) / area).clamp(0.0, 1.0)
    }
}

/// Whether two convex polygons in one plane (normal `n`) overlap with some area: no edge normal
/// of either separates them.
fn convex_overlap(a: &[DVec3], b: &[DVec3], n: DVec3) -> bool {
    let separates = |poly: &[DVec3]| {
        (0..poly.len()).any(|k| {
            let axis = n.cross(poly[(k + 1) % poly.len()] - poly[k]);
            let span =
                |p: &[DVec3]| p.iter().map(|v| axis.dot(*v)).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
            let ((alo, ahi), (blo, bhi)) = (span(a), span(b));
            ahi <= blo || bhi <= alo
        })
    };
    !separates(a) && !separates(b)
}

/// A box hierarchy over the input polygons of `h` (its root surface elements), for
/// [`smaller_shadow_falls_on`].
pub(super) fn polygon_boxes(h: &Hierarchy) -> crate::visibility::shaft::ObjectBvh {
    let boxes: Vec<Aabb> = (0..h.n_polygons).map(|p| h.get(p).bounds).collect();
    crate::visibility::shaft::ObjectBvh::build(&boxes)
}
