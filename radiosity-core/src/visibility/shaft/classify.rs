//! Shaft classification of a link, the entry point for the shaft oracle's tools: build the link's
//! shaft, collect its candidate occluders (from the parent link's list when there is one), and
//! decide whether the link is certainly invisible, certainly visible, or partial.

use super::build::Shaft;
use super::objects::ShaftObjects;
use super::occlusion::{convex_polygon_occludes, plate_occludes, solid_occludes};
use super::plane::aabb_corners;
use super::rays::segment_meets_inv;
use crate::geom::{Aabb, DVec3};
use crate::hierarchy::{ElementId, Hierarchy};

/// Depth, relative to the shaft's diagonal, by which an object must reach into the shaft to count
/// as a possible blocker for [`ShaftClass`]. Objects that only graze the shaft's boundary (a floor
/// meeting a wall element's edge) stay in the candidate list but do not make a link partial: the
/// segments they can block end within this distance of the shaft's boundary, which the ray caster
/// leaves out as well (its end fractions).
pub const GRAZE_REL_TOL: f64 = 1e-6;

/// Most candidates tried as single occluders per link (the largest by bounding-box diagonal).
pub const MAX_OCCLUDER_TESTS: usize = 8;

/// What a shaft says about a link's visibility.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaftClass {
    /// One candidate blocks every segment between the elements (conservative: never claimed when
    /// some segment is unblocked).
    Invisible,
    /// No object reaches into the shaft: every segment is unblocked.
    Visible,
    /// Some objects reach into the shaft and none is known to block it all.
    Partial {
        /// Number of objects that reach into the shaft.
        candidates: u32,
    },
}

/// The result of [`classify`].
#[derive(Clone, Debug, PartialEq)]
pub struct ShaftVerdict {
    /// Invisible, visible or partial.
    pub class: ShaftClass,
    /// The link's candidate list, to be passed to its children's [`classify`] and to
    /// [`super::visibility_among`]; sorted by object id. Contains every object that may meet the
    /// shaft, except objects whose only polygons in the shaft are the link's own surfaces.
    pub candidates: Vec<u32>,
    /// The object that blocks the shaft, when invisible.
    pub occluder: Option<u32>,
}

/// The shaft between two elements' bounding boxes.
#[must_use]
pub fn shaft_of(h: &Hierarchy, emitter: ElementId, receiver: ElementId) -> Shaft {
    Shaft::new(&h.get(emitter).bounds, &h.get(receiver).bounds)
}

/// The vertices of an element's convex hull: a surface's polygon, or a cluster's 8 box corners.
#[must_use]
pub fn element_vertices(h: &Hierarchy, id: ElementId) -> Vec<DVec3> {
    let e = h.get(id);
    match e.poly() {
        Some(p) => p.vertices().to_vec(),
        None => aabb_corners(&e.bounds).to_vec(),
    }
}

/// Classifies the link `emitter` → `receiver`. `parent_candidates` is the candidate list of a link
/// whose shaft contains this one (the link it was subdivided from), or `None` to search the whole
/// scene. Invisible only when a single candidate (a closed convex solid, or one polygon) blocks
/// every segment between the two elements; visible only when no candidate reaches deeper than
/// [`GRAZE_REL_TOL`] into the shaft.
#[must_use]
pub fn classify(
    objects: &ShaftObjects,
    h: &Hierarchy,
    emitter: ElementId,
    receiver: ElementId,
    parent_candidates: Option<&[u32]>,
) -> ShaftVerdict {
    classify_with(objects, h, emitter, receiver, parent_candidates, true)
}

/// [`classify`] with the occlusion tests optional: without them the class is never invisible, and
/// partial where [`classify`] may say invisible (visible and the candidates are the same). For a
/// link about to be stored, whose segments are cast anyway: the tests cost more than the segments
/// they could save.
#[must_use]
pub fn classify_with(
    objects: &ShaftObjects,
    h: &Hierarchy,
    emitter: ElementId,
    receiver: ElementId,
    parent_candidates: Option<&[u32]>,
    occlusion: bool,
) -> ShaftVerdict {
    if parent_candidates.is_some_and(<[u32]>::is_empty) {
        // The parent link's shaft contains this one and nothing entered it: no shaft to build.
        return ShaftVerdict { class: ShaftClass::Visible, candidates: Vec::new(), occluder: None };
    }
    let shaft = shaft_of(h, emitter, receiver);
    // Polygons that are the link's own surfaces (kept by every descendant link of a surface).
    let own: [Option<u32>; 2] = [h.get(emitter).polygon(), h.get(receiver).polygon()];
    let is_own = |p: u32| own.contains(&Some(p));
    let graze = GRAZE_REL_TOL * shaft.extent.diagonal();
    let mut candidates: Vec<u32> = Vec::with_capacity(parent_candidates.map_or(16, <[u32]>::len));
    let mut blocking: Vec<u32> = Vec::new();
    objects.visit_candidates(&shaft, parent_candidates, |id, depth| {
        let polys = objects.polygons_of(id);
        if polys.iter().any(|&p| is_own(p)) {
            // The object's bounding volume holds a link surface: judge its other polygons one by one.
            // The deepest polygon's depth; stops once it is known to exceed `graze`.
            let mut reach = f64::NEG_INFINITY;
            for &p in polys.iter().filter(|&&p| !is_own(p)) {
                reach = reach.max(depth_into_above(&shaft, objects.polys[p as usize].vertices(), reach));
                if reach > graze {
                    break;
                }
            }
            if reach >= -shaft.tol {
                if reach > graze {
                    blocking.push(id);
                }
                candidates.push(id);
            }
            return;
        }
        if depth > graze {
            blocking.push(id);
        }
        candidates.push(id);
    });
    if parent_candidates.is_none() {
        // The BVH visits in its own order; lists are kept sorted by id.
        candidates.sort_unstable();
        blocking.sort_unstable();
    }
    if blocking.is_empty() {
        return ShaftVerdict { class: ShaftClass::Visible, candidates, occluder: None };
    }
    let n_blocking = blocking.len() as u32;
    if !occlusion {
        return ShaftVerdict { class: ShaftClass::Partial { candidates: n_blocking }, candidates, occluder: None };
    }
    let (pv, qv) = (element_vertices(h, emitter), element_vertices(h, receiver));
    // Try the largest candidates only: an occluder that blocks a whole shaft is big compared with
    // the others, and testing fewer never makes the answer less conservative.
    if blocking.len() > MAX_OCCLUDER_TESTS {
        let size = |id: &u32| objects.objects[*id as usize].aabb.diagonal();
        blocking.select_nth_unstable_by(MAX_OCCLUDER_TESTS, |a, b| size(b).total_cmp(&size(a)).then(a.cmp(b)));
        blocking.truncate(MAX_OCCLUDER_TESTS);
    }
    // An occluder must block every segment, so its box must meet a few chosen ones: the segment
    // between the centres and those between corresponding vertices. Only candidates that pass try
    // the exact (and costlier) test.
    let probes = probe_segments(&pv, &qv);
    blocking.retain(|&id| probes.iter().all(|&(a, inv)| segment_meets_inv(a, inv, &objects.objects[id as usize].aabb)));
    for &id in &blocking {
        if occludes(objects, id, &pv, &qv, &own) {
            return ShaftVerdict { class: ShaftClass::Invisible, candidates, occluder: Some(id) };
        }
    }
    ShaftVerdict { class: ShaftClass::Partial { candidates: n_blocking }, candidates, occluder: None }
}

/// Most probe segments per link: the centres' segment and up to this many minus one vertex pairs.
const MAX_PROBES: usize = 9;

/// Segments between the hulls of `p` and `q` that every occluder must block: centre to centre,
/// and vertex `k` of `p` to vertex `k` of `q`, each as its start and the inverse of its direction.
fn probe_segments(p: &[DVec3], q: &[DVec3]) -> Vec<(DVec3, DVec3)> {
    let mean = |v: &[DVec3]| v.iter().copied().sum::<DVec3>() / v.len().max(1) as f64;
    let mut out = Vec::with_capacity(MAX_PROBES);
    if p.is_empty() || q.is_empty() {
        return out;
    }
    let (cp, cq) = (mean(p), mean(q));
    out.push((cp, (cq - cp).recip()));
    out.extend(p.iter().zip(q).take(MAX_PROBES - 1).map(|(&a, &b)| (a, (b - a).recip())));
    out
}

/// Whether object `id` blocks every segment between the hulls of `p` and `q` on its own, as a closed
/// convex solid, through one of its polygons, or through one of its merged plates (never using the
/// `own` polygons, which the ray caster ignores). Conservative.
#[must_use]
pub fn occludes(objects: &ShaftObjects, id: u32, p: &[DVec3], q: &[DVec3], own: &[Option<u32>]) -> bool {
    if objects.solid_of(id).is_some_and(|solid| solid_occludes(p, q, solid)) {
        return true;
    }
    // A plate that blocks every segment blocks the one between the centres: the prepared polygons
    // reject the others cheaply.
    let mean = |v: &[DVec3]| v.iter().copied().sum::<DVec3>() / v.len().max(1) as f64;
    let (cp, cq) = (mean(p), mean(q));
    let crossed = |k: u32| objects.prepared[k as usize].as_ref().is_some_and(|(_, plate)| plate.crossed_by(cp, cq));
    objects
        .polygons_of(id)
        .iter()
        .filter(|&&k| !own.contains(&Some(k)) && crossed(k))
        .any(|&k| plate_occludes(p, q, &objects.polys[k as usize]))
        || objects
            .merged_of(id)
            .iter()
            .filter(|m| !m.polygons.iter().any(|&k| own.contains(&Some(k))))
            .any(|m| convex_polygon_occludes(p, q, &m.vertices))
}

/// How deep the hull of `points` reaches into the shaft: the smallest, over the shaft's planes, of
/// how far the deepest point lies inside that plane (negative when outside some plane). Stops as
/// soon as the answer is known to be at most `floor`, returning a value at most `floor` then.
fn depth_into_above(shaft: &Shaft, points: &[DVec3], floor: f64) -> f64 {
    // The extent's faces are axis-aligned: the points' box gives their depths exactly.
    let mut depth = shaft.extent_depth(&Aabb::from_points(points));
    for pl in shaft.side_planes() {
        if depth <= floor {
            break;
        }
        depth = depth.min(pl.offset - pl.min_over_points(points));
    }
    depth
}
