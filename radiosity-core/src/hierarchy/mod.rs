//! Step 2, `hierarchy`: an arena of elements addressed by `u32` ids. Clusters are built top-down over
//! the input polygons; each polygon is the root of a surface hierarchy subdivided lazily and regularly
//! (triangles and quads into 4).
//!
//! Architecture invariant: element `i < n_polygons` is the root surface element of input polygon `i`;
//! the root cluster is [`Hierarchy::root`]. Ids never change once given; children of an element are
//! created together and are contiguous in [`Hierarchy::children`].

mod build;
mod sides;

pub use build::{BuildConfig, MIN_POLYGON_DEPTH, TWIN_REL_TOL, build, twins};

use crate::geom::{Aabb, DVec3, Poly};

/// Index of an element in the arena.
pub type ElementId = u32;

/// "No element".
pub const NONE: ElementId = u32::MAX;

/// Deepest surface element [`Hierarchy::mate`] follows to the other side (each level quarters the
/// area: far below any [`BuildConfig::min_area_rel`]); deeper pieces take their ancestor's mate.
pub const MAX_MATE_DEPTH: usize = 48;

/// What an element is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ElementKind {
    /// A piece of input polygon `polygon` (the whole polygon at depth 0).
    Surface {
        /// Input polygon index.
        polygon: u32,
        /// The piece's geometry.
        poly: Poly,
    },
    /// A group of elements; `polys` is its range in [`Hierarchy::cluster_polygons`].
    Cluster {
        /// First index into `cluster_polygons`.
        poly_start: u32,
        /// One past the last index.
        poly_end: u32,
    },
}

/// One node of the hierarchy.
#[derive(Clone, Debug)]
pub struct Element {
    /// Surface piece or cluster.
    pub kind: ElementKind,
    /// Parent, or [`NONE`] for the root cluster and (before clustering) polygon roots.
    pub parent: ElementId,
    /// Start of the children in [`Hierarchy::children`].
    pub child_start: u32,
    /// Number of children (0 for a leaf).
    pub n_children: u32,
    /// Surface area (sum of the surfaces' areas for a cluster), scene units².
    pub area: f64,
    /// Area centroid.
    pub center: DVec3,
    /// Unit front normal: a surface's; a cluster's when all its polygons lie in one plane facing
    /// the same way, else zero.
    pub normal: DVec3,
    /// Bounding box.
    pub bounds: Aabb,
    /// Radius of a sphere about `center` containing the element.
    pub radius: f64,
    /// Depth below its polygon root (surfaces) or below the root cluster (clusters).
    pub depth: u16,
}

impl Element {
    /// True for clusters.
    #[must_use]
    pub fn is_cluster(&self) -> bool {
        matches!(self.kind, ElementKind::Cluster { .. })
    }

    /// The surface geometry, if a surface.
    #[must_use]
    pub fn poly(&self) -> Option<&Poly> {
        match &self.kind {
            ElementKind::Surface { poly, .. } => Some(poly),
            ElementKind::Cluster { .. } => None,
        }
    }

    /// The input polygon of a surface element.
    #[must_use]
    pub fn polygon(&self) -> Option<u32> {
        match self.kind {
            ElementKind::Surface { polygon, .. } => Some(polygon),
            ElementKind::Cluster { .. } => None,
        }
    }
}

/// The element arena plus per-polygon radiometric constants.
#[derive(Clone, Debug)]
pub struct Hierarchy {
    /// All elements; see the module's invariant.
    pub elements: Vec<Element>,
    /// Children lists, indexed by `child_start .. child_start + n_children`.
    pub children: Vec<ElementId>,
    /// Input polygon indices in cluster order (each cluster covers a contiguous range).
    pub cluster_polygons: Vec<u32>,
    /// Prefix sums of polygon areas in `cluster_polygons` order (length + 1), for area sampling.
    pub cluster_area_prefix: Vec<f64>,
    /// Each polygon's unit normal and area in `cluster_polygons` order: a cluster's projected
    /// area ([`crate::formfactor::projected_area`]) sums over its members, and read from the
    /// elements (one cache line each, scattered) that sum was 6% of a canopy's solve.
    pub cluster_members: Vec<(crate::geom::DVec3, f64)>,
    /// Root cluster.
    pub root: ElementId,
    /// Number of input polygons.
    pub n_polygons: u32,
    /// Reflectance per input polygon.
    pub reflectance: Vec<[f64; 3]>,
    /// Emission (W/m²) per input polygon.
    pub emission: Vec<[f64; 3]>,
    /// Diffuse transmittance per input polygon (0 unless the polygon has a [`Hierarchy::twin`]).
    pub transmittance: Vec<[f64; 3]>,
    /// The other side of a two-sided, transmitting surface (the same polygon reversed, stored as
    /// the next or previous input polygon), or [`NONE`]: a piece of a side has the radiosity
    /// `E + ρ·H(this side) + t·H(other side)`, the other side's irradiance at the same piece
    /// ([`Hierarchy::mate`]).
    pub twin: Vec<u32>,
    /// Smallest area a surface element may be subdivided into (but see `min_piece_rel`).
    pub min_area: f64,
    /// Every polygon may be subdivided down to this fraction of its own area even where that is
    /// below `min_area` ([`BuildConfig::min_polygon_depth`]).
    pub min_piece_rel: f64,
    /// Direct irradiance from the scene's luminaires and distant sources (which the hierarchy
    /// does not hold: [`crate::light::Lights`]) per element and channel (the area mean over the
    /// element), filled by [`crate::luminaire::update_direct`]; empty without either.
    pub direct: Vec<[f64; 3]>,
    /// Per element, what its [`Hierarchy::direct`] is estimated to be in error by from the
    /// quadrature (signed, per channel; zero where no shadow boundary crosses it): meaningful for
    /// leaves; filled with it.
    pub direct_error: Vec<[f64; 3]>,
    /// Per element, the direct irradiance from the soft distant sources (the sky's cells) where
    /// every point of its rule and its corners see each of them alike, which its pieces then take
    /// instead of tracing it again (the same light, exact where the visibility is uniform); `None`
    /// elsewhere. Filled with [`Hierarchy::direct`].
    pub direct_soft: Vec<Option<[f64; 3]>>,
    /// Per element, the step in direct irradiance across the shadow boundaries that cross it
    /// (per channel; zero where none does): how much its direct light varies over it, which a
    /// constant value per element does not show. Filled with [`Hierarchy::direct`].
    pub direct_edge: Vec<[f64; 3]>,
}

impl Hierarchy {
    /// The element `id`.
    #[must_use]
    #[inline]
    pub fn get(&self, id: ElementId) -> &Element {
        &self.elements[id as usize]
    }

    /// Children of `id`.
    #[must_use]
    #[inline]
    pub fn children_of(&self, id: ElementId) -> &[ElementId] {
        let e = &self.elements[id as usize];
        &self.children[e.child_start as usize..(e.child_start + e.n_children) as usize]
    }

    /// Number of elements.
    #[must_use]
    pub fn len(&self) -> usize {
        self.elements.len()
    }

    /// True when there is no element.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.elements.is_empty()
    }

    /// Whether `id` can be subdivided: clusters always (they have children), surfaces while their
    /// children would not fall below [`Hierarchy::smallest_piece`] of their polygon.
    #[must_use]
    pub fn can_subdivide(&self, id: ElementId) -> bool {
        let e = self.get(id);
        e.n_children > 0 || matches!(e.kind, ElementKind::Surface { polygon, .. } if e.area * 0.25 >= self.smallest_piece(polygon))
    }

    /// The smallest area a piece of input polygon `polygon` may have: `min_area`, or
    /// `min_piece_rel` of the polygon's own area where that is smaller.
    #[must_use]
    pub fn smallest_piece(&self, polygon: u32) -> f64 {
        self.min_area.min(self.min_piece_rel * self.elements[polygon as usize].area)
    }

    /// Creates the 4 children of surface `id` if it has none yet (lazy regular subdivision).
    /// Returns false when `id` cannot be subdivided.
    pub fn subdivide(&mut self, id: ElementId) -> bool {
        let e = &self.elements[id as usize];
        if e.n_children > 0 {
            return true;
        }
        let ElementKind::Surface { polygon, poly } = e.kind else {
            return false;
        };
        if e.area * 0.25 < self.smallest_piece(polygon) {
            return false;
        }
        let depth = e.depth + 1;
        let normal = e.normal;
        let child_start = self.children.len() as u32;
        for child in poly.subdivide() {
            let cid = self.elements.len() as ElementId;
            self.elements.push(surface_element(polygon, child, normal, id, depth));
            self.children.push(cid);
        }
        let e = &mut self.elements[id as usize];
        e.child_start = child_start;
        e.n_children = 4;
        true
    }

    /// Leaves (elements without children), in id order.
    pub fn leaves(&self) -> impl Iterator<Item = ElementId> + '_ {
        (0..self.elements.len() as ElementId).filter(|&i| self.elements[i as usize].n_children == 0)
    }

    /// The emission of surface element `id` in the radiosity system: its polygon's own emission
    /// plus the reflection of the luminaires' direct light, `E + ρ·E_direct + t·Ē_direct(other
    /// side)`, `Ē_direct` the other side's at the same piece ([`Hierarchy::mate`]; see
    /// [`crate::luminaire`]).
    #[must_use]
    #[inline]
    pub fn emission_of(&self, id: ElementId) -> [f64; 3] {
        let Some(p) = self.get(id).polygon() else { return [0.0; 3] };
        let p = p as usize;
        let own = self.emission[p];
        if self.direct.is_empty() {
            return own;
        }
        let d = self.direct.get(id as usize).copied().unwrap_or_default();
        let mate = self.mate(id);
        let other = if mate == NONE { [0.0; 3] } else { self.direct.get(mate as usize).copied().unwrap_or_default() };
        std::array::from_fn(|c| own[c] + self.reflectance[p][c] * d[c] + self.transmittance[p][c] * other[c])
    }

    /// Whether element `id` holds an emitting polygon (a surface of one, or a cluster with one
    /// among its members).
    #[must_use]
    pub fn holds_emitter(&self, id: ElementId) -> bool {
        let emits = |p: u32| self.emission[p as usize].iter().any(|&x| x > 0.0);
        match self.get(id).kind {
            ElementKind::Surface { polygon, .. } => emits(polygon),
            ElementKind::Cluster { poly_start, poly_end } => {
                self.cluster_polygons[poly_start as usize..poly_end as usize].iter().any(|&p| emits(p))
            }
        }
    }

    /// The length of the diagonal of the scene's bounding box.
    #[must_use]
    pub fn diagonal(&self) -> f64 {
        let b = &self.get(self.root).bounds;
        (b.max - b.min).length()
    }

    /// Reflectance of a surface element's polygon; the area-weighted mean for a cluster.
    #[must_use]
    pub fn reflectance_of(&self, id: ElementId) -> [f64; 3] {
        match self.get(id).kind {
            ElementKind::Surface { polygon, .. } => self.reflectance[polygon as usize],
            ElementKind::Cluster { poly_start, poly_end } => {
                let mut acc = [0.0; 3];
                let mut area = 0.0;
                for &p in &self.cluster_polygons[poly_start as usize..poly_end as usize] {
                    let a = self.get(p).area;
                    for c in 0..3 {
                        acc[c] += a * self.reflectance[p as usize][c];
                    }
                    area += a;
                }
                acc.map(|x| if area > 0.0 { x / area } else { 0.0 })
            }
        }
    }

    /// Finds the leaf of polygon `polygon` containing the parameter point `(s, t)`, and the
    /// parameters in that leaf.
    #[must_use]
    pub fn locate(&self, polygon: u32, mut s: f64, mut t: f64) -> (ElementId, f64, f64) {
        let mut id = polygon;
        loop {
            let e = self.get(id);
            if e.n_children == 0 {
                return (id, s, t);
            }
            let ElementKind::Surface { poly, .. } = e.kind else { return (id, s, t) };
            let (c, s2, t2) = Poly::child_of_param(poly.kind, s, t);
            id = self.children_of(id)[c];
            s = s2;
            t = t2;
        }
    }

    /// Picks a point on the surfaces of `id` from two uniform numbers in [0, 1) plus a third for
    /// choosing the polygon of a cluster (by area). Returns the point and its input polygon.
    #[must_use]
    pub fn sample_point(&self, id: ElementId, u: f64, v: f64, w: f64) -> (DVec3, u32) {
        match self.get(id).kind {
            ElementKind::Surface { polygon, poly } => (poly.sample(u, v), polygon),
            ElementKind::Cluster { poly_start, poly_end } => {
                let (a, b) = (poly_start as usize, poly_end as usize);
                let lo = self.cluster_area_prefix[a];
                let hi = self.cluster_area_prefix[b];
                let target = lo + w * (hi - lo);
                // Binary search for the polygon whose prefix interval holds `target`.
                let k = match self.cluster_area_prefix[a..=b].partition_point(|&x| x <= target) {
                    0 => a,
                    k => (a + k - 1).min(b - 1),
                };
                let p = self.cluster_polygons[k];
                let ElementKind::Surface { poly, .. } = self.get(p).kind else { unreachable!("cluster polygons are surfaces") };
                (poly.sample(u, v), p)
            }
        }
    }
}

fn surface_element(polygon: u32, poly: Poly, normal: DVec3, parent: ElementId, depth: u16) -> Element {
    let center = poly.centroid();
    let bounds = Aabb::from_points(poly.vertices());
    let radius = poly.vertices().iter().map(|v| (*v - center).length()).fold(0.0, f64::max);
    Element {
        kind: ElementKind::Surface { polygon, poly },
        parent,
        child_start: 0,
        n_children: 0,
        area: poly.area(),
        center,
        normal,
        bounds,
        radius,
        depth,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, SceneBuilder};

    /// A transmitting quad and a triangle, each with its back after it ([`Scene::pair_two_sided`]).
    fn leaves() -> Hierarchy {
        let mut b = SceneBuilder::new(std::path::Path::new("test"), "test");
        let mut leaf = Material::diffuse("leaf", [0.4; 3]);
        leaf.transmittance = [0.3; 3];
        leaf.two_sided = true;
        let m = b.material(leaf).unwrap();
        let g = b.group("g");
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        b.face(&[c(0., 0., 0.), c(2., 0., 0.3), c(2., 1., 0.3), c(0., 1.5, 0.)], m, g, 0).unwrap();
        b.face(&[c(3., 0., 0.), c(4., 0., 0.), c(3.5, 1., 0.5)], m, g, 0).unwrap();
        let mut scene = b.finish();
        scene.pair_two_sided();
        build(&scene, &BuildConfig { min_area_rel: 1e-4, ..BuildConfig::default() })
    }

    /// A 10 cm leaf over a 10 m ground: the smallest element relative to the scene (2e-6 of its
    /// 100.01 m²) lets the leaf be quartered twice; with `min_polygon_depth` 4 it may be quartered
    /// four times, and the ground, whose pieces stay above the scene's smallest element anyway,
    /// as deep as before.
    #[test]
    fn a_small_polygon_may_be_quartered_min_polygon_depth_times() {
        let mut b = SceneBuilder::new(std::path::Path::new("test"), "test");
        let m = b.material(Material::diffuse("grey", [0.5; 3])).unwrap();
        let g = b.group("g");
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        b.face(&[c(-5., -5., 0.), c(5., -5., 0.), c(5., 5., 0.), c(-5., 5., 0.)], m, g, 0).unwrap();
        b.face(&[c(0., 0., 1.), c(0.1, 0., 1.), c(0.1, 0.1, 1.), c(0., 0.1, 1.)], m, g, 0).unwrap();
        let scene = b.finish();
        let depth_reached = |h: &mut Hierarchy, polygon: u32| {
            let (mut e, mut depth) = (polygon, 0);
            while h.can_subdivide(e) && h.subdivide(e) {
                e = h.children_of(e)[0];
                depth += 1;
            }
            depth
        };
        for (min_polygon_depth, leaf_depth) in [(0u8, 2), (4, 4), (6, 6)] {
            let mut h = build(&scene, &BuildConfig { min_polygon_depth, ..BuildConfig::default() });
            assert_eq!(depth_reached(&mut h, 1), leaf_depth, "min_polygon_depth {min_polygon_depth}");
            // The ground: 100 m² down to 2e-4 m² pieces, 4^-9 of it, whatever the setting.
            assert_eq!(depth_reached(&mut h, 0), 9, "min_polygon_depth {min_polygon_depth}");
        }
    }

    /// Both sides end up cut into the same pieces wherever either side was cut, and every piece's
    /// mate lies where it lies, has its area, and has it for mate in turn.
    #[test]
    fn both_sides_are_cut_alike_and_every_piece_has_its_mate_behind_it() {
        let mut h = leaves();
        assert_eq!(h.twin[..4], [1, 0, 3, 2]);
        // Cut the front of the quad two levels deep in one corner, the back of the triangle once.
        h.subdivide(0);
        let corner = h.children_of(0)[2];
        h.subdivide(corner);
        h.subdivide(3);
        let leaves_of = |h: &Hierarchy, p: u32| h.leaves().filter(|&e| h.get(e).polygon() == Some(p)).count();
        assert_eq!([leaves_of(&h, 0), leaves_of(&h, 1), leaves_of(&h, 2), leaves_of(&h, 3)], [7, 1, 1, 4]);
        // Before matching, a piece on the uncut side's mate is that side's whole polygon.
        assert_eq!(h.mate(corner), 1);
        let made = h.match_sides();
        assert_eq!(made.len(), 3, "the quad's back twice, the triangle's front once");
        assert_eq!([leaves_of(&h, 0), leaves_of(&h, 1), leaves_of(&h, 2), leaves_of(&h, 3)], [7, 7, 4, 4]);
        assert!(h.match_sides().is_empty(), "matching twice changes nothing");
        for e in 0..h.len() as ElementId {
            let el = h.get(e);
            if el.is_cluster() {
                continue;
            }
            let m = h.mate(e);
            let other = h.get(m);
            assert!((other.center - el.center).length() <= 1e-12, "{e} and its mate {m}");
            assert!((other.area - el.area).abs() <= 1e-12 * el.area);
            assert!(other.normal.dot(el.normal) < -0.999, "the mate faces the other way");
            assert_eq!(h.mate(m), e);
            assert_eq!(other.n_children, el.n_children);
        }
    }
}
