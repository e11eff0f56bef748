//! Occluder objects: groups of input polygons with their bounding volumes (AABB, OBB, vertex hull)
//! and, where the polygons close a convex solid, the solid itself.
//!
//! An object is a group of the scene ([`crate::scene::Polygon::group`]); a group with more than
//! [`ObjectConfig::max_polygons`] polygons is split by median cuts of the polygon centroids along the
//! longest axis until every piece is small enough. Big groups (a whole building's walls) would
//! otherwise have a bounding volume that meets every shaft; pieces keep the volumes tight.

use super::merge::{MergedPlate, merge_coplanar};
use super::obb::Obb;
use super::plane::Plane;
use crate::geom::{Aabb, DVec3, Poly};
use crate::scene::Scene;
use std::sync::OnceLock;

/// Relative tolerance for matching the vertices of shared edges and for the convexity test of
/// solids, times the object's diagonal.
pub const SOLID_REL_TOL: f64 = 1e-9;

/// How objects are formed.
#[derive(Clone, Copy, Debug)]
pub struct ObjectConfig {
    /// Most polygons per object; bigger groups are split spatially.
    pub max_polygons: usize,
    /// Most vertices for which the vertex hull is kept as a bounding volume.
    pub max_hull_vertices: usize,
    /// The bounding volume the shaft tests use.
    pub volume: BoundingVolume,
}

impl Default for ObjectConfig {
    fn default() -> Self {
        ObjectConfig { max_polygons: 16, max_hull_vertices: 32, volume: BoundingVolume::Obb }
    }
}

/// Which bounding volume of an object the shaft tests use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BoundingVolume {
    /// Axis-aligned box.
    Aabb,
    /// Oriented box.
    Obb,
    /// The convex hull of the object's vertices (exact support in every plane direction); objects
    /// with more than [`ObjectConfig::max_hull_vertices`] vertices use their OBB instead.
    Hull,
}

/// A convex polyhedron whose boundary is closed by the polygons of one object, so that it blocks
/// every segment that enters its interior and has an end outside it.
#[derive(Clone, Debug)]
pub struct ConvexSolid {
    /// Outward face planes (the solid is their intersection).
    pub planes: Vec<Plane>,
    /// Vertices.
    pub vertices: Vec<DVec3>,
    /// Bounding box.
    pub aabb: Aabb,
    /// Absolute tolerance (relative to the solid's size).
    pub tol: f64,
}

/// One occluder object.
#[derive(Clone, Debug)]
pub struct ShaftObject {
    /// Group index of its polygons.
    pub group: u32,
    /// Axis-aligned bounding box.
    pub aabb: Aabb,
    /// Oriented bounding box.
    pub obb: Obb,
    /// Whether the OBB is turned away from the world axes; when it is not, it is the AABB and the
    /// OBB tests are skipped (on axis-aligned scenes OBB culling then costs what AABB culling does).
    pub oriented: bool,
    poly_range: (u32, u32),
    hull_range: Option<(u32, u32)>,
}

/// What an object can block a whole shaft with: its closed convex solid, or else its merged
/// plates. Built on the object's first occlusion test ([`ShaftObjects::solid_of`],
/// [`ShaftObjects::merged_of`]): most objects never get one (the hospital: 14 split-link verdicts for
/// 1,080 objects), and building them all took 40% of building the objects.
#[derive(Clone, Debug)]
struct Occluder {
    solid: Option<ConvexSolid>,
    merged: Vec<MergedPlate>,
}

/// The occluder objects of a scene.
#[derive(Clone, Debug)]
pub struct ShaftObjects {
    /// The objects; candidate lists hold indices into this.
    pub objects: Vec<ShaftObject>,
    object_polygons: Vec<u32>,
    hull_points: Vec<DVec3>,
    occluders: Vec<OnceLock<Occluder>>,
    /// Geometry of every input polygon, by polygon index.
    pub polys: Vec<Poly>,
    /// Object of every input polygon.
    pub polygon_object: Vec<u32>,
    /// The bounding volume the shaft tests use.
    pub volume: BoundingVolume,
    pub(super) bvh: super::bvh::ObjectBvh,
    /// Every input polygon ready for segment tests (`None` when degenerate), with its area.
    pub(super) prepared: Vec<Option<(f64, super::rays::PreparedPolygon)>>,
}

impl ShaftObjects {
    /// Builds the objects of `scene` and their bounding-volume hierarchy.
    #[must_use]
    pub fn new(scene: &Scene, config: &ObjectConfig) -> ShaftObjects {
        let polys: Vec<Poly> = scene.polygons.iter().map(|p| p.poly).collect();
        let mut by_group: Vec<Vec<u32>> = vec![Vec::new(); scene.groups.len().max(1)];
        for (i, p) in scene.polygons.iter().enumerate() {
            let g = (p.group as usize).min(by_group.len() - 1);
            by_group[g].push(i as u32);
        }
        let mut out = ShaftObjects {
            objects: Vec::new(),
            object_polygons: Vec::with_capacity(polys.len()),
            hull_points: Vec::new(),
            occluders: Vec::new(),
            polygon_object: vec![u32::MAX; polys.len()],
            prepared: polys
                .iter()
                .enumerate()
                .map(|(k, p)| super::rays::PreparedPolygon::new(p, k as u32).map(|q| (p.area(), q)))
                .collect(),
            polys,
            volume: config.volume,
            bvh: super::bvh::ObjectBvh::default(),
        };
        let max_polygons = config.max_polygons.max(1);
        let centroids: Vec<DVec3> = out.polys.iter().map(Poly::centroid).collect();
        for (g, mut members) in by_group.into_iter().enumerate() {
            if members.is_empty() {
                continue;
            }
            let mut pieces = Vec::new();
            split(&centroids, &mut members, max_polygons, &mut pieces);
            for piece in pieces {
                out.push_object(g as u32, &piece, config);
            }
        }
        let boxes: Vec<Aabb> = out.objects.iter().map(|o| o.aabb).collect();
        out.bvh = super::bvh::ObjectBvh::build(&boxes);
        out
    }

    fn push_object(&mut self, group: u32, members: &[u32], config: &ObjectConfig) {
        let id = self.objects.len() as u32;
        let start = self.object_polygons.len() as u32;
        self.object_polygons.extend_from_slice(members);
        for &p in members {
            self.polygon_object[p as usize] = id;
        }
        let points = distinct_vertices(&self.polys, members);
        let aabb = Aabb::from_points(&points);
        let mut frames: Vec<(f64, DVec3, DVec3)> = members
            .iter()
            .map(|&p| {
                let poly = &self.polys[p as usize];
                (poly.area(), poly.normal(), poly.v[1] - poly.v[0])
            })
            .collect();
        frames.sort_by(|x, y| y.0.total_cmp(&x.0));
        let frames: Vec<(DVec3, DVec3)> = frames.into_iter().map(|(_, n, e)| (n, e)).collect();
        let obb = Obb::fit(&points, &frames);
        let hull_range = (points.len() <= config.max_hull_vertices).then(|| {
            let s = self.hull_points.len() as u32;
            self.hull_points.extend_from_slice(&points);
            (s, self.hull_points.len() as u32)
        });
        self.objects.push(ShaftObject {
            group,
            aabb,
            oriented: !obb.is_axis_aligned(),
            obb,
            poly_range: (start, self.object_polygons.len() as u32),
            hull_range,
        });
        self.occluders.push(OnceLock::new());
    }

    /// The occluder of object `id`, built on first use.
    fn occluder(&self, id: u32) -> &Occluder {
        self.occluders[id as usize].get_or_init(|| {
            let members = self.polygons_of(id);
            let aabb = &self.objects[id as usize].aabb;
            let points = distinct_vertices(&self.polys, members);
            let solid = convex_solid(&self.polys, members, &points, aabb);
            let merged = if solid.is_none() { merge_coplanar(&self.polys, members, aabb.diagonal()) } else { Vec::new() };
            Occluder { solid, merged }
        })
    }

    /// Number of objects.
    #[must_use]
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// True when the scene has no polygon.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// Input polygons of object `id`.
    #[must_use]
    pub fn polygons_of(&self, id: u32) -> &[u32] {
        let (s, e) = self.objects[id as usize].poly_range;
        &self.object_polygons[s as usize..e as usize]
    }

    /// Vertices of object `id` when small enough to serve as its hull.
    #[must_use]
    pub fn hull_of(&self, id: u32) -> Option<&[DVec3]> {
        self.objects[id as usize].hull_range.map(|(s, e)| &self.hull_points[s as usize..e as usize])
    }

    /// The closed convex solid of object `id`, if it is one (found on first use).
    #[must_use]
    pub fn solid_of(&self, id: u32) -> Option<&ConvexSolid> {
        self.occluder(id).solid.as_ref()
    }

    /// The merged plates of object `id` (coplanar polygons joined into convex unions; none for
    /// solids; built on first use).
    #[must_use]
    pub fn merged_of(&self, id: u32) -> &[MergedPlate] {
        &self.occluder(id).merged
    }

    /// Number of merged plates in all objects (builds every object's occluder).
    #[must_use]
    pub fn n_merged(&self) -> usize {
        (0..self.len() as u32).map(|id| self.merged_of(id).len()).sum()
    }

    /// Number of objects that are closed convex solids (builds every object's occluder).
    #[must_use]
    pub fn n_solids(&self) -> usize {
        (0..self.len() as u32).filter(|&id| self.solid_of(id).is_some()).count()
    }
}

/// The vertices of the `members` polygons, each once, in first-seen order.
fn distinct_vertices(polys: &[Poly], members: &[u32]) -> Vec<DVec3> {
    let mut points: Vec<DVec3> = Vec::new();
    for &p in members {
        for &v in polys[p as usize].vertices() {
            if !points.contains(&v) {
                points.push(v);
            }
        }
    }
    points
}

/// Splits `members` into pieces of at most `max` polygons by median cuts of their `centroids` along
/// the longest axis.
fn split(centroids: &[DVec3], members: &mut [u32], max: usize, out: &mut Vec<Vec<u32>>) {
    if members.len() <= max {
        out.push(members.to_vec());
        return;
    }
    let centroid = |p: u32| centroids[p as usize];
    let mut b = Aabb::EMPTY;
    for &p in members.iter() {
        b.grow(centroid(p));
    }
    let axis = b.longest_axis();
    let mid = members.len() / 2;
    members.select_nth_unstable_by(mid, |&x, &y| centroid(x)[axis].total_cmp(&centroid(y)[axis]).then(x.cmp(&y)));
    let (lo, hi) = members.split_at_mut(mid);
    split(centroids, lo, max, out);
    split(centroids, hi, max, out);
}

/// The solid closed by `members`, when they bound a convex polyhedron: every vertex lies behind
/// every face's plane (outward normals, convex), and every directed edge is matched by the reverse
/// edge of another face (closed, consistently oriented).
fn convex_solid(polys: &[Poly], members: &[u32], points: &[DVec3], aabb: &Aabb) -> Option<ConvexSolid> {
    if members.len() < 4 {
        return None;
    }
    let tol = SOLID_REL_TOL * aabb.diagonal().max(f64::MIN_POSITIVE);
    let mut planes = Vec::with_capacity(members.len());
    for &m in members {
        let poly = &polys[m as usize];
        let plane = Plane::try_through(poly.normal(), poly.centroid())?;
        if points.iter().any(|&v| plane.distance(v) > tol) {
            return None;
        }
        // The same plane twice would make a face double-covered; keep one copy.
        if !planes.iter().any(|q: &Plane| q.normal.dot(plane.normal) > 1.0 - 1e-12 && (q.offset - plane.offset).abs() <= tol) {
            planes.push(plane);
        }
    }
    let edges = |m: u32| {
        let vs = polys[m as usize].vertices();
        (0..vs.len()).map(move |k| (vs[k], vs[(k + 1) % vs.len()]))
    };
    let close = |x: DVec3, y: DVec3| (x - y).abs().max_element() <= tol;
    for &m in members {
        for (a, b) in edges(m) {
            let matched = members.iter().any(|&o| o != m && edges(o).any(|(c, d)| close(a, d) && close(b, c)));
            if !matched {
                return None;
            }
        }
    }
    Some(ConvexSolid { planes, vertices: points.to_vec(), aabb: *aabb, tol })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shapes::box_faces;
    use crate::scene::{Material, SceneBuilder};
    use std::path::Path;

    fn scene_with(boxes: &[(DVec3, DVec3, bool)]) -> Scene {
        let mut b = SceneBuilder::new(Path::new("t"), "t");
        let m = b.material(Material::diffuse("w", [0.5; 3])).unwrap();
        for (k, &(lo, hi, inward)) in boxes.iter().enumerate() {
            let g = b.group(&format!("box{k}"));
            for (_, q) in box_faces(lo, hi, inward) {
                b.face(&q, m, g, 0).unwrap();
            }
        }
        b.finish()
    }

    #[test]
    fn closed_outward_box_is_a_solid_and_a_room_is_not() {
        let s = scene_with(&[(DVec3::ZERO, DVec3::ONE, false), (DVec3::splat(2.0), DVec3::splat(5.0), true)]);
        let o = ShaftObjects::new(&s, &ObjectConfig::default());
        assert_eq!(o.len(), 2);
        let solid = o.solid_of(0).expect("outward box is a solid");
        assert_eq!((solid.planes.len(), solid.vertices.len()), (6, 8));
        assert!(o.solid_of(1).is_none(), "inward-facing room is not convex with outward normals");
    }

    #[test]
    fn open_box_is_not_a_solid() {
        let mut b = SceneBuilder::new(Path::new("t"), "t");
        let m = b.material(Material::diffuse("w", [0.5; 3])).unwrap();
        let g = b.group("tube");
        for (name, q) in box_faces(DVec3::ZERO, DVec3::ONE, false) {
            if name != "z+" && name != "z-" {
                b.face(&q, m, g, 0).unwrap();
            }
        }
        let o = ShaftObjects::new(&b.finish(), &ObjectConfig::default());
        assert!(o.solid_of(0).is_none(), "a tube does not block along its axis");
    }

    #[test]
    fn big_groups_are_split() {
        let s = scene_with(&[(DVec3::ZERO, DVec3::ONE, false)]);
        let o = ShaftObjects::new(&s, &ObjectConfig { max_polygons: 2, ..ObjectConfig::default() });
        assert_eq!(o.len(), 4, "6 = (1 + 2) + (1 + 2)");
        assert!((0..4).all(|k| o.polygons_of(k).len() <= 2));
        let mut all: Vec<u32> = (0..4).flat_map(|k| o.polygons_of(k).to_vec()).collect();
        all.sort_unstable();
        assert_eq!(all, (0..6).collect::<Vec<u32>>());
        assert!(o.polygon_object.iter().all(|&k| k < 4));
    }
}
