//! Photometric luminaires: a measured intensity distribution ([`crate::photometry::Photometry`],
//! from an IES or EULUMDAT file) placed in a scene with a position, an aim and a rotation.
//!
//! A luminaire is a **point** at its photometric centre: the illuminance it gives a receiver point
//! `x` with normal `n` is `E = I(C, γ) · cos θ / d² · V`, with `I` the file's intensity toward `x`,
//! `θ` the angle of incidence, `d` the distance and `V` one shadow ray. This is the far-field
//! model of every photometric file: against a luminous square on its axis it is 1.3% high at five
//! times the square's side (the "five-times rule"), 0.3% at ten, and 33% at one (tested in
//! `tests/luminaires.rs`): place calculation points at least five opening sizes away.
//!
//! Its light enters the hierarchy as the *direct illuminance* of each element
//! ([`crate::hierarchy::Hierarchy::direct`]), averaged over the element by quadrature with a shadow
//! ray per point, so that every surface's first reflection `ρ · E_direct` is an emission of the
//! radiosity system ([`crate::hierarchy::Hierarchy::emission_of`]): the interreflections then run
//! through the links like any other light. Before refinement, surfaces are subdivided until each
//! element subtends a small angle from every luminaire that lights it ([`MAX_ANGULAR_SIZE`]) and no
//! shadow boundary crosses an element ([`MAX_SHADOW_DEPTH`]), so the quadrature is accurate
//! (under a target error, the sun's boundaries are left to the levels' error control: [`prepare`]).
//! A sharp distant source (the sun) is not sampled at points at all: its light on an element is
//! its unoccluded irradiance times the share of the element that the other polygons' shadows
//! leave lit, found exactly by projecting them onto the element's plane and taking their union's
//! area ([`crate::geom::union_area`]).
//!
//! Where it may not be (a shadow edge of a luminaire or of the sun crossing a leaf, a luminaire
//! nearer than the angular size allows), the leaf is sampled on its quarters as well and the
//! difference is its quadrature error ([`update_direct`], [`Hierarchy::direct_error`]); each
//! polygon's share ([`direct_polygon_errors`]) is in the solve's error estimate, and under a target
//! error the levels sample those leaves finer (then split them) until
//! every polygon's mean direct light is within a share of the target of its own value
//! ([`direct_splits`], [`deepen_direct`]).

use crate::geom::{Aabb, DVec3, quadrature};
use crate::hierarchy::{ElementKind, Hierarchy, NONE};
use crate::light::Lights;
use crate::visibility::RayCaster;

use crate::geom::quadrature::element_rule;
pub use crate::light::luminaire::{Luminaire, LuminaireError};
pub use crate::visibility::SHADOW_ORIGIN_OFFSET_REL;

/// Subdivide (before refinement) a surface element lit by a luminaire while its bounding radius
/// exceeds this fraction of its distance to the luminaire: the quadrature of `I cos θ / d²` over
/// it is then accurate to about 1e-4 (9-point rule, smooth intensities).
pub const MAX_ANGULAR_SIZE: f64 = 0.25;
/// Most subdivision levels below an input polygon for the luminaires' angular size.
pub const MAX_ANGULAR_DEPTH: u16 = 7;
/// Most subdivision levels below an input polygon for a shadow boundary of a luminaire crossing an
/// element (its quadrature points disagree on visibility).
pub const MAX_SHADOW_DEPTH: u16 = 6;

/// How far inside its corners (a share of the way to its centre) an element's visibility is
/// tested, besides at its rule's points, to find shadow boundaries crossing it
/// ([`update_direct`]).
pub const CORNER_INSET: f64 = 1e-3;

/// Sees the luminaires from surface points: illuminance with one shadow ray per luminaire.
pub struct DirectLight<'a> {
    luminaires: &'a [Luminaire],
    caster: Option<&'a RayCaster>,
    offset: f64,
}

impl<'a> DirectLight<'a> {
    /// `caster` `None`: no occlusion.
    #[must_use]
    pub fn new(luminaires: &'a [Luminaire], caster: Option<&'a RayCaster>, scene_diagonal: f64) -> DirectLight<'a> {
        DirectLight { luminaires, caster, offset: SHADOW_ORIGIN_OFFSET_REL * scene_diagonal }
    }

    /// Illuminance at `x` (normal `n`) from luminaire `k`, and whether it is occluded; `skip` is the
    /// polygon `x` lies on ([`NONE`] for a free point).
    #[must_use]
    pub fn from_one(&self, k: usize, x: DVec3, n: DVec3, skip: u32) -> (f64, bool) {
        let lum = &self.luminaires[k];
        let e = lum.illuminance_unoccluded(x, n);
        if e <= 0.0 {
            return (0.0, false);
        }
        match self.caster {
            Some(caster) if !caster.segment_clear(x + self.offset * n, lum.position, skip, NONE) => (0.0, true),
            _ => (e, false),
        }
    }

    /// Illuminance at `x` (normal `n`) from every luminaire.
    #[must_use]
    pub fn at(&self, x: DVec3, n: DVec3, skip: u32) -> f64 {
        (0..self.luminaires.len()).map(|k| self.from_one(k, x, n, skip).0).sum()
    }
}

/// Whether surface element `id` should be split for the direct light: too large seen from a
/// luminaire that lights it, crossed by a shadow boundary of a luminaire or of a sharp distant
/// source (the sun; not the sky's cells, whose shadows are soft), or lit by such a source with a
/// smaller shadow on it that its rule's points may all miss ([`smaller_shadow_falls_on`]).
/// `error_controlled` (a target error): nothing is split for a distant source (its boundaries and
/// its smaller shadows alike), nor are its rays traced here; the element's lit share is exact and
/// the levels' control of the direct light's error splits where it matters (see [`prepare`]).
fn needs_split(
    h: &Hierarchy,
    id: u32,
    light: &DirectLight<'_>,
    distant: &crate::daylight::DistantLight<'_>,
    occluders: &crate::visibility::shaft::ObjectBvh,
    error_controlled: bool,
) -> bool {
    let e = h.get(id);
    let ElementKind::Surface { polygon, poly } = e.kind else { return false };
    let depth = e.depth;
    for (k, lum) in light.luminaires.iter().enumerate() {
        // Does the luminaire light any part of the element? (its centre or a corner)
        let lit = std::iter::once(e.center).chain(poly.vertices().iter().copied()).any(|x| lum.illuminance_unoccluded(x, e.normal) > 0.0);
        if !lit {
            continue;
        }
        let dist = (e.center - lum.position).length();
        if depth < MAX_ANGULAR_DEPTH && e.radius > MAX_ANGULAR_SIZE * dist {
            return true;
        }
        if depth < MAX_SHADOW_DEPTH && light.caster.is_some() {
            let mut seen = [false; 2];
            for (x, _) in quadrature::weighted_points(&poly, element_rule(&poly)) {
                let (v, occluded) = light.from_one(k, x, e.normal, polygon);
                if v > 0.0 || occluded {
                    seen[usize::from(occluded)] = true;
                }
            }
            if seen[0] && seen[1] {
                return true;
            }
        }
    }
    // Under a target error the element's lit share of a sharp distant source is exact
    // ([`ParallelShadows`]) and its edge steps its radiosity range: where that matters to a
    // receiver, the oracle splits, and nothing is split for it here.
    if depth < MAX_SHADOW_DEPTH && light.caster.is_some() && !error_controlled {
        for (k, s) in distant.sources().iter().enumerate() {
            if !s.sharp || s.on(e.normal).iter().all(|&v| v <= 0.0) {
                continue;
            }
            let mut seen = [false; 2];
            for (x, _) in quadrature::weighted_points(&poly, element_rule(&poly)) {
                seen[usize::from(distant.from_one(k, x, e.normal, polygon).1)] = true;
            }
            if seen[0] && (seen[1] || smaller_shadow_falls_on(h, id, s.toward, occluders)) {
                return true;
            }
        }
    }
    false
}

/// Whether some polygon casts a shadow along `toward` (a distant source's direction of travel) on
/// part of surface element `id` smaller than the element (in size or in area: a sliver cast by a
/// leaf seen edge-on): one that its quadrature points may all miss (a 1 m² leaf's shadow on a 100 m² ground fell between the 9 points of the ground's rule,
/// which then got the sun as if nothing stood over it). Found through `occluders` (a box
/// hierarchy over the input polygons, see [`polygon_boxes`]) with the shaft the element's box
/// sweeps toward the source, then exactly: the candidate's part in front of the element's plane,
/// projected along `toward` onto it, overlapping the element (separating axes).
fn smaller_shadow_falls_on(h: &Hierarchy, id: u32, toward: DVec3, occluders: &crate::visibility::shaft::ObjectBvh) -> bool {
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
    fn new(h: &'a Hierarchy, sources: &[crate::light::DistantSource], caster: Option<&RayCaster>) -> Option<ParallelShadows<'a>> {
        (caster.is_some() && sources.iter().any(|s| s.sharp)).then(|| ParallelShadows { h, occluders: polygon_boxes(h) })
    }

    /// The share of element `poly` (normal `n`, of polygon `own`) that light travelling along
    /// `toward` reaches: 1 less the union of the other polygons' shadows on it over its area.
    fn lit_share(&self, poly: &crate::geom::Poly, n: DVec3, own: u32, toward: DVec3) -> f64 {
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
fn polygon_boxes(h: &Hierarchy) -> crate::visibility::shaft::ObjectBvh {
    let boxes: Vec<Aabb> = (0..h.n_polygons).map(|p| h.get(p).bounds).collect();
    crate::visibility::shaft::ObjectBvh::build(&boxes)
}

/// Subdivides the surfaces of `h` for the direct light (see the module docs), then computes every
/// element's direct irradiance ([`update_direct`]). Does nothing without luminaires or distant
/// sources.
///
/// `error_controlled`: the solve holds each polygon's mean direct light to a share of a target
/// error (splitting, after this, the leaves whose quadrature error keeps it from that). A shadow
/// boundary of the sun that an element's rule sees (its points or corners disagree) is then left
/// to that control, which splits only where the error is, instead of split here to
/// [`MAX_SHADOW_DEPTH`] whatever it is worth: in a canopy every leaf partly shaded by another was
/// cut into about 250 pieces along the shadow's edge, 88% of the leaves of an 800-leaf canopy, which
/// then took 25 s and 250 MB (16 s and 230 MB after, the leaves' absorbed power within 0.5%).
/// Shadows smaller than the element, which its rule's points may miss altogether (a leaf's on the
/// ground under it), are split for only without a target error: with one, the sun's light on
/// every element is its exact lit share (the union of the polygons' shadows on it, clipped to it:
/// [`crate::geom::union_area`]), and a shadow's edge steps its radiosity range
/// ([`Hierarchy::direct_edge`]), so that the oracle splits it where a receiver sees the difference.
/// On an 800-leaf canopy the ground had been cut into 3,127 pieces before refinement began.
pub fn prepare(h: &mut Hierarchy, lights: &Lights, caster: Option<&RayCaster>, error_controlled: bool) {
    if lights.is_empty() {
        return;
    }
    let (luminaires, sources) = (&lights.luminaires, &lights.distant);
    let light = DirectLight::new(luminaires, caster, h.diagonal());
    let distant = crate::daylight::DistantLight::new(sources, caster, h.diagonal());
    let occluders =
        if sources.iter().any(|s| s.sharp) && caster.is_some() { polygon_boxes(h) } else { crate::visibility::shaft::ObjectBvh::default() };
    let mut stack: Vec<u32> = (0..h.n_polygons).collect();
    while let Some(id) = stack.pop() {
        if h.can_subdivide(id) && needs_split(h, id, &light, &distant, &occluders, error_controlled) && h.subdivide(id) {
            stack.extend_from_slice(h.children_of(id));
        }
    }
    update_direct(h, lights, caster);
}

/// Computes the direct irradiance of every surface element made since the last call (leaves by
/// quadrature with shadow rays: the luminaires' illuminance in every channel, the distant
/// sources' per channel), then every inner element's as the area mean of its children
/// ([`crate::solve::area_means`]), so that every level carries the same power.
///
/// A sharp distant source (the sun) lights each leaf by its exact lit share (module docs): no
/// error. Where a shadow boundary of a luminaire crosses a leaf (its rule's
/// points or corners disagree on the luminaire's visibility), or a luminaire lights it from nearer
/// than [`MAX_ANGULAR_SIZE`] allows, the leaf's value is the area mean of the same rule over its
/// four quarters (the children it would have), and the difference from its own rule's value is
/// its quadrature error ([`Hierarchy::direct_error`]): a step along a shadow edge defeats the
/// rule's polynomial accuracy, and halving the elements about halves what it misplaces (first
/// order; a near luminaire's error falls faster), so the finer value is in error by about that
/// difference.
pub fn update_direct(h: &mut Hierarchy, lights: &Lights, caster: Option<&RayCaster>) {
    use rayon::prelude::*;
    let (n, start) = (h.len(), h.direct.len());
    if lights.is_empty() || start == n {
        return;
    }
    let light = DirectLight::new(&lights.luminaires, caster, h.diagonal());
    let distant = crate::daylight::DistantLight::new(&lights.distant, caster, h.diagonal());
    let hh: &Hierarchy = h;
    let shadows = ParallelShadows::new(hh, &lights.distant, caster);
    let new: Vec<Option<LeafDirect>> = (start as u32..n as u32)
        .into_par_iter()
        .map(|id| {
            let e = hh.get(id);
            match e.kind {
                ElementKind::Surface { polygon, poly } if e.n_children == 0 => {
                    let inherited = hh.direct_soft.get(e.parent as usize).copied().flatten();
                    Some(leaf_direct(&poly, e.normal, polygon, &light, &distant, shadows.as_ref(), 1, inherited))
                }
                _ => None,
            }
        })
        .collect();
    let mut direct = std::mem::take(&mut h.direct);
    direct.extend(new.iter().map(|v| v.as_ref().map_or([0.0; 3], |v| v.direct)));
    h.direct_error.resize(start, [0.0; 3]);
    h.direct_error.extend(new.iter().map(|v| v.as_ref().map_or([0.0; 3], |v| v.error)));
    h.direct_soft.resize(start, None);
    h.direct_soft.extend(new.iter().map(|v| v.as_ref().and_then(|v| v.soft)));
    h.direct_edge.resize(start, [0.0; 3]);
    h.direct_edge.extend(new.iter().map(|v| v.as_ref().map_or([0.0; 3], |v| v.edge)));
    crate::solve::area_means(h, &crate::solve::top_down(h), &mut direct);
    h.direct = direct;
}

/// Recomputes the direct light of surface leaves `leaves` with their quarters quartered
/// `depth` times ([`update_direct`] does it once), each leaf's error from the same one fewer
/// time, then every inner element's as the area mean of its children: more shadow rays where a
/// leaf cannot be split further (the smallest element size) and its shadow edges still leave its
/// polygon short of the target.
pub fn deepen_direct(h: &mut Hierarchy, lights: &Lights, caster: Option<&RayCaster>, leaves: &[(u32, u32)]) {
    use rayon::prelude::*;
    if lights.is_empty() || leaves.is_empty() || h.direct.len() != h.len() {
        return;
    }
    let light = DirectLight::new(&lights.luminaires, caster, h.diagonal());
    let distant = crate::daylight::DistantLight::new(&lights.distant, caster, h.diagonal());
    let hh: &Hierarchy = h;
    let shadows = ParallelShadows::new(hh, &lights.distant, caster);
    let new: Vec<(u32, [f64; 3], [f64; 3])> = leaves
        .par_iter()
        .filter_map(|&(id, depth)| {
            let e = hh.get(id);
            let ElementKind::Surface { polygon, poly } = e.kind else { return None };
            (e.n_children == 0).then(|| {
                let own = hh.direct_soft.get(id as usize).copied().flatten();
                let d = leaf_direct(&poly, e.normal, polygon, &light, &distant, shadows.as_ref(), depth.max(1), own);
                (id, d.direct, d.error)
            })
        })
        .collect();
    let mut direct = std::mem::take(&mut h.direct);
    h.direct_error.resize(h.len(), [0.0; 3]);
    for (id, d, err) in new {
        direct[id as usize] = d;
        h.direct_error[id as usize] = err;
    }
    crate::solve::area_means(h, &crate::solve::top_down(h), &mut direct);
    h.direct = direct;
}

/// A surface leaf's direct irradiance and the error estimated in it: where its rule may be
/// inaccurate ([`rule_direct`]), the mean of the rule over its pieces quartered `depth` times
/// (at least once), the error its difference from the same quartered one fewer time; elsewhere
/// the rule's, with no error. The soft sources' light is `inherited` where given (its parent's,
/// seen the same all over it), and comes back where the leaf's pieces may take it
/// ([`Hierarchy::direct_soft`]).
#[expect(clippy::too_many_arguments, reason = "the element, its sources and its quadrature, each read by the rule")]
fn leaf_direct(
    poly: &crate::geom::Poly,
    normal: DVec3,
    polygon: u32,
    light: &DirectLight<'_>,
    distant: &crate::daylight::DistantLight<'_>,
    shadows: Option<&ParallelShadows<'_>>,
    depth: u32,
    inherited: Option<[f64; 3]>,
) -> LeafDirect {
    let rule = rule_direct(poly, normal, polygon, light, distant, shadows, false, inherited);
    let (soft, edge) = (rule.soft_uniform.then_some(rule.soft), rule.edge);
    if !rule.crossed || depth == 0 {
        return LeafDirect { direct: rule.total(), error: [0.0; 3], soft, edge };
    }
    // The sky's cells cast soft shadows: the rule holds for them, and only the sharp sources are
    // sampled on the pieces.
    let coarse = if depth == 1 { rule.sharp } else { pieces_direct(poly, normal, polygon, light, distant, shadows, depth - 1) };
    let fine = pieces_direct(poly, normal, polygon, light, distant, shadows, depth);
    LeafDirect { direct: std::array::from_fn(|c| fine[c] + rule.soft[c]), error: std::array::from_fn(|c| fine[c] - coarse[c]), soft, edge }
}

/// The area mean of [`rule_direct`]'s sharp sources over the pieces of `poly` quartered `depth`
/// times.
fn pieces_direct(
    poly: &crate::geom::Poly,
    normal: DVec3,
    polygon: u32,
    light: &DirectLight<'_>,
    distant: &crate::daylight::DistantLight<'_>,
    shadows: Option<&ParallelShadows<'_>>,
    depth: u32,
) -> [f64; 3] {
    if depth == 0 {
        return rule_direct(poly, normal, polygon, light, distant, shadows, true, None).sharp;
    }
    let (mut sum, mut area) = ([0.0; 3], 0.0);
    for piece in poly.subdivide() {
        let a = piece.area();
        let d = pieces_direct(&piece, normal, polygon, light, distant, shadows, depth - 1);
        for c in 0..3 {
            sum[c] += a * d[c];
        }
        area += a;
    }
    if area > 0.0 { sum.map(|v| v / area) } else { [0.0; 3] }
}

/// The direct irradiance of a surface element (polygon `polygon`, normal `normal`) by its
/// [`element_rule`] with a shadow ray per point and source, the sharp distant sources' (the sun's)
/// by their exact lit share where `shadows` are given ([`ParallelShadows`], with visibility on);
/// and whether the rule may be inaccurate: a shadow boundary of a luminaire crosses the element
/// (its points or corners disagree on the luminaire's visibility), or a luminaire that lights it
/// is nearer than [`MAX_ANGULAR_SIZE`] allows.
#[expect(clippy::too_many_arguments, reason = "the element, its sources and its quadrature, each read by the rule")]
fn rule_direct(
    poly: &crate::geom::Poly,
    normal: DVec3,
    polygon: u32,
    light: &DirectLight<'_>,
    distant: &crate::daylight::DistantLight<'_>,
    shadows: Option<&ParallelShadows<'_>>,
    sharp_only: bool,
    inherited_soft: Option<[f64; 3]>,
) -> RuleDirect {
    let sources = distant.sources();
    // The sharp distant sources' light comes from their exact lit share where the shadows are
    // known ([`ParallelShadows`]), not from the points.
    let exact = |k: usize| shadows.is_some() && sources[k].sharp;
    let mut seen_luminaire = vec![[false; 2]; light.luminaires.len()];
    let mut brightest = vec![0.0f64; light.luminaires.len()];
    let sharp_on: Vec<bool> = sources.iter().map(|s| s.sharp && s.on(normal).iter().any(|&v| v > 0.0)).collect();
    // The soft sources traced here: none when only the sharp ones are asked for or the element
    // takes its parent's.
    let soft_traced = !sharp_only && inherited_soft.is_none();
    let soft_on: Vec<bool> = sources.iter().map(|s| soft_traced && !s.sharp && s.on(normal).iter().any(|&v| v > 0.0)).collect();
    let mut seen_distant = vec![[false; 2]; sources.len()];
    let (mut sharp, mut soft, mut wsum) = ([0.0; 3], [0.0; 3], 0.0);
    for (x, w) in quadrature::weighted_points(poly, element_rule(poly)) {
        wsum += w;
        for (k, seen) in seen_luminaire.iter_mut().enumerate() {
            let (v, occluded) = light.from_one(k, x, normal, polygon);
            if v > 0.0 || occluded {
                seen[usize::from(occluded)] = true;
            }
            brightest[k] = brightest[k].max(v);
            for s in &mut sharp {
                *s += w * v;
            }
        }
        for (k, seen) in seen_distant.iter_mut().enumerate() {
            if (!sources[k].sharp && !soft_traced) || exact(k) {
                continue;
            }
            let (v, occluded) = distant.from_one(k, x, normal, polygon);
            if sharp_on[k] || soft_on[k] {
                seen[usize::from(occluded)] = true;
            }
            let sum = if sources[k].sharp { &mut sharp } else { &mut soft };
            for c in 0..3 {
                sum[c] += w * v[c];
            }
        }
    }
    if wsum > 0.0 {
        sharp = sharp.map(|v| v / wsum);
        soft = soft.map(|v| v / wsum);
    }
    if let Some(shadows) = shadows {
        for (k, s) in sources.iter().enumerate().filter(|&(k, _)| sharp_on[k]) {
            let lit = shadows.lit_share(poly, normal, polygon, s.toward);
            let on = s.on(normal);
            for c in 0..3 {
                sharp[c] += on[c] * lit;
            }
            seen_distant[k] = [lit > 0.0, lit < 1.0];
        }
    }
    if let Some(inherited) = inherited_soft {
        soft = inherited;
    }
    // The corners too (a hair inside): an edge that passes between the rule's outermost points
    // and the element's side leaves every point on one side of it.
    let centre = poly.centroid();
    for &v in poly.vertices() {
        let x = centre + (v - centre) * (1.0 - CORNER_INSET);
        for (k, seen) in seen_luminaire.iter_mut().enumerate().filter(|(_, s)| !(s[0] && s[1])) {
            let (v, occluded) = light.from_one(k, x, normal, polygon);
            if v > 0.0 || occluded {
                seen[usize::from(occluded)] = true;
            }
        }
        for (k, seen) in seen_distant.iter_mut().enumerate().filter(|(k, s)| sharp_on[*k] && !exact(*k) && !(s[0] && s[1])) {
            seen[usize::from(distant.from_one(k, x, normal, polygon).1)] = true;
        }
    }
    // Whether the soft sources' visibility is the same all over the element (every point and
    // corner sees each of them, or none does): its pieces then get the same soft light, and take
    // it from it instead of tracing it again. The corners are traced for that only while the
    // points agree.
    let mut soft_uniform =
        inherited_soft.is_some() || (soft_traced && !seen_distant.iter().zip(sources).any(|(s, src)| !src.sharp && s[0] && s[1]));
    if soft_traced && soft_uniform {
        'corners: for &v in poly.vertices() {
            let x = centre + (v - centre) * (1.0 - CORNER_INSET);
            for (k, seen) in seen_distant.iter_mut().enumerate().filter(|(k, _)| soft_on[*k]) {
                seen[usize::from(distant.from_one(k, x, normal, polygon).1)] = true;
                if seen[0] && seen[1] {
                    soft_uniform = false;
                    break 'corners;
                }
            }
        }
    }
    // A luminaire nearer than the element's size allows (where the subdivision before refinement
    // stopped at its depth): the rule's accuracy is not assured either.
    let radius = poly.vertices().iter().map(|&v| (v - centre).length()).fold(0.0, f64::max);
    let near = light
        .luminaires
        .iter()
        .zip(&seen_luminaire)
        .any(|(lum, seen)| seen[0] && radius > MAX_ANGULAR_SIZE * (centre - lum.position).length());
    let crossed = near || seen_luminaire.iter().any(|s| s[0] && s[1]);
    let step = seen_luminaire.iter().zip(&brightest).filter(|(s, _)| s[0] && s[1]).map(|(_, v)| v).sum::<f64>();
    let mut edge = [step; 3];
    // A sharp distant source's shadow edge across the element steps its light; its lit share is
    // exact, and no quadrature misplaces the edge.
    for (k, s) in sources.iter().enumerate() {
        if sharp_on[k] && seen_distant[k][0] && seen_distant[k][1] {
            let on = s.on(normal);
            for c in 0..3 {
                edge[c] += on[c];
            }
        }
    }
    RuleDirect { sharp, soft, crossed, soft_uniform, edge }
}

/// What [`rule_direct`] finds on one element: the mean direct irradiance from the sources whose
/// shadows are sharp (luminaires, the sun) and from the others (the sky's cells), and whether the
/// rule may be inaccurate for the sharp ones.
struct RuleDirect {
    sharp: [f64; 3],
    soft: [f64; 3],
    crossed: bool,
    soft_uniform: bool,
    /// The step in direct irradiance across the shadow boundaries that cross the element: each
    /// crossing sharp distant source's unoccluded irradiance, each crossing luminaire's largest
    /// seen at a lit point.
    edge: [f64; 3],
}

/// A surface leaf's direct light ([`leaf_direct`]).
struct LeafDirect {
    direct: [f64; 3],
    error: [f64; 3],
    soft: Option<[f64; 3]>,
    edge: [f64; 3],
}

impl RuleDirect {
    fn total(&self) -> [f64; 3] {
        std::array::from_fn(|c| self.sharp[c] + self.soft[c])
    }
}

/// Per input polygon and channel, the error of its mean direct irradiance that the leaves'
/// quadrature leaves ([`Hierarchy::direct_error`], W/m² or lx): the larger of the area-weighted
/// sum of the leaves' errors (what a shadow edge misplaces the same way all along it) and their
/// root sum of squares (what varies in sign from leaf to leaf), over the polygon's area. Empty
/// without luminaires or distant sources.
#[must_use]
pub fn direct_polygon_errors(h: &Hierarchy) -> Vec<[f64; 3]> {
    if h.direct_error.is_empty() {
        return Vec::new();
    }
    let mut sums = vec![([0.0; 3], [0.0; 3], 0.0); h.n_polygons as usize];
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let Some(p) = e.polygon() else { continue };
        let s = &mut sums[p as usize];
        s.2 += e.area;
        let Some(d) = h.direct_error.get(leaf as usize) else { continue };
        for c in 0..3 {
            s.0[c] += e.area * d[c];
            s.1[c] += (e.area * d[c]).powi(2);
        }
    }
    sums.into_iter()
        .map(|(sum, squares, a)| if a > 0.0 { std::array::from_fn(|c| sum[c].abs().max(squares[c].sqrt()) / a) } else { [0.0; 3] })
        .collect()
}

/// Below this share of the brightest polygon's mean direct irradiance, a polygon's direct error
/// is held to this share instead of to its own mean ([`direct_splits`]): a wall the light
/// grazes is not refined to its own faint light's precision.
pub const DIRECT_FLOOR_REL: f64 = 1e-2;

/// The leaves to split (or to sample finer where they cannot be split) so that every polygon's
/// mean direct irradiance meets `tolerance`: those
/// with a quadrature error ([`Hierarchy::direct_error`]) on a polygon whose error
/// ([`direct_polygon_errors`]) exceeds `tolerance` times its own mean direct irradiance (at
/// least [`DIRECT_FLOOR_REL`] of the largest polygon's), in the largest channel, times the
/// polygon's entry of `polygon_factor` (1 where it has none). Empty without luminaires or distant
/// sources.
#[must_use]
pub fn direct_splits(h: &Hierarchy, tolerance: f64, polygon_factor: &[f64]) -> Vec<u32> {
    let errors = direct_polygon_errors(h);
    if errors.is_empty() {
        return Vec::new();
    }
    let means = polygon_direct_means(h);
    let top = means.iter().flatten().copied().fold(0.0, f64::max);
    let over: Vec<bool> = (errors.iter().zip(&means).enumerate())
        .map(|(p, (e, m))| {
            let tolerance = tolerance * polygon_factor.get(p).copied().unwrap_or(1.0);
            (0..3).any(|c| e[c] > tolerance * m[c].max(DIRECT_FLOOR_REL * top))
        })
        .collect();
    if !over.iter().any(|&o| o) {
        return Vec::new();
    }
    h.leaves()
        .filter(|&l| {
            let e = h.get(l);
            e.polygon().is_some_and(|p| over[p as usize]) && h.direct_error.get(l as usize).is_some_and(|d| d.iter().any(|&v| v != 0.0))
        })
        .collect()
}

/// Each polygon's mean direct irradiance ([`Hierarchy::direct`], area-weighted over its leaves);
/// empty without luminaires or distant sources.
#[must_use]
pub fn polygon_direct_means(h: &Hierarchy) -> Vec<[f64; 3]> {
    if h.direct.is_empty() {
        return Vec::new();
    }
    let mut sums = vec![([0.0; 3], 0.0); h.n_polygons as usize];
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let (Some(p), Some(d)) = (e.polygon(), h.direct.get(leaf as usize)) else { continue };
        let s = &mut sums[p as usize];
        s.1 += e.area;
        for c in 0..3 {
            s.0[c] += e.area * d[c];
        }
    }
    sums.into_iter().map(|(d, a)| if a > 0.0 { d.map(|v| v / a) } else { [0.0; 3] }).collect()
}

/// The luminous flux (lm) of all luminaires of `h` arriving on its surfaces (front sides), from the
/// leaves' direct illuminance: equal to the luminaires' flux in a closed scene.
#[must_use]
pub fn flux_received(h: &Hierarchy) -> f64 {
    if h.direct.is_empty() {
        return 0.0;
    }
    h.leaves().filter(|&l| !h.get(l).is_cluster()).map(|l| h.get(l).area * h.direct[l as usize][1]).sum()
}
