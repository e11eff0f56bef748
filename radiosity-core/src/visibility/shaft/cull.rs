//! Shaft against object tests (interval arithmetic on the shaft's plane equations) and candidate
//! lists through the objects' BVH, with the shaft hierarchy: a child link's shaft is tested only
//! against its parent's candidates.

use super::build::Shaft;
use super::obb::Obb;
use super::objects::{BoundingVolume, ShaftObjects};
use super::plane::min_dot_aabb;
use crate::geom::Aabb;

/// Conservative shaft against oriented box: false only when the box lies entirely outside one of
/// the shaft's planes (the extent box's faces included).
#[must_use]
pub fn may_intersect_obb(shaft: &Shaft, obb: &Obb) -> bool {
    shaft.extent_overlaps(&obb.aabb()) && shaft.side_planes().iter().all(|pl| obb.min_along(pl) <= pl.offset + shaft.tol)
}

/// Conservative shaft against axis-aligned box (see [`Shaft::may_intersect_aabb`]).
#[must_use]
pub fn may_intersect_aabb(shaft: &Shaft, b: &Aabb) -> bool {
    shaft.may_intersect_aabb(b)
}

impl ShaftObjects {
    /// Conservative test of object `id`'s bounding volume (the one chosen in
    /// [`super::ObjectConfig::volume`]) against `shaft`. Never false when some polygon of the object
    /// meets the shaft; touching counts as meeting.
    #[must_use]
    pub fn may_intersect(&self, shaft: &Shaft, id: u32) -> bool {
        let o = &self.objects[id as usize];
        if !shaft.may_intersect_aabb(&o.aabb) {
            return false;
        }
        match self.volume {
            BoundingVolume::Aabb => true,
            BoundingVolume::Obb => !o.oriented || may_intersect_obb(shaft, &o.obb),
            BoundingVolume::Hull => match self.hull_of(id) {
                Some(points) => shaft.may_intersect_points(points),
                None => !o.oriented || may_intersect_obb(shaft, &o.obb),
            },
        }
    }

    /// How deep object `id`'s bounding volume (the one chosen in [`super::ObjectConfig::volume`],
    /// intersected with its axis-aligned box) reaches into `shaft`: the smallest, over the shaft's
    /// planes, of how far the volume's deepest point lies inside the plane. Below `-shaft.tol` the
    /// volume lies outside the shaft (exactly when [`ShaftObjects::may_intersect`] is false); the
    /// value returned may then stop short of the smallest.
    #[must_use]
    pub fn depth_in(&self, shaft: &Shaft, id: u32) -> f64 {
        let o = &self.objects[id as usize];
        let mut depth = shaft.extent_depth(&o.aabb);
        if o.aabb.is_empty() {
            return f64::NEG_INFINITY;
        }
        let hull = match self.volume {
            BoundingVolume::Hull => self.hull_of(id),
            _ => None,
        };
        for pl in shaft.side_planes() {
            if depth < -shaft.tol {
                return depth;
            }
            let lowest = min_dot_aabb(pl.normal, &o.aabb);
            let lowest = match (self.volume, hull) {
                (BoundingVolume::Aabb, _) => lowest,
                (BoundingVolume::Hull, Some(points)) => lowest.max(pl.min_over_points(points)),
                (BoundingVolume::Obb | BoundingVolume::Hull, _) if o.oriented => lowest.max(o.obb.min_along(pl)),
                (BoundingVolume::Obb | BoundingVolume::Hull, _) => lowest,
            };
            depth = depth.min(pl.offset - lowest);
        }
        depth
    }

    /// Calls `visit(id, depth)` for every object whose bounding volume may meet `shaft` (depth as in
    /// [`ShaftObjects::depth_in`], at least `-shaft.tol`): the `parent_candidates` in their order, or
    /// without them the whole scene through the BVH in its fixed traversal order.
    pub fn visit_candidates(&self, shaft: &Shaft, parent_candidates: Option<&[u32]>, mut visit: impl FnMut(u32, f64)) {
        let mut test = |id: u32| {
            let depth = self.depth_in(shaft, id);
            if depth >= -shaft.tol {
                visit(id, depth);
            }
        };
        match parent_candidates {
            Some(list) => list.iter().for_each(|&id| test(id)),
            None => self.bvh.traverse(|b| shaft.may_intersect_aabb(b), test),
        }
    }

    /// Objects whose bounding volume may meet `shaft`, in increasing id order. With
    /// `parent_candidates` (the list of a link whose shaft contains this one, e.g. the parent link of
    /// a subdivided link), only those are tested; otherwise the BVH is traversed. Exact for the
    /// conservative test: no object whose geometry meets the shaft is ever missing, provided the
    /// parent's shaft contains this shaft.
    #[must_use]
    pub fn candidates(&self, shaft: &Shaft, parent_candidates: Option<&[u32]>) -> Vec<u32> {
        let mut out = Vec::new();
        self.candidates_into(&mut out, shaft, parent_candidates);
        out
    }

    /// [`ShaftObjects::candidates`] appending to `out` (which is cleared first).
    pub fn candidates_into(&self, out: &mut Vec<u32>, shaft: &Shaft, parent_candidates: Option<&[u32]>) {
        out.clear();
        self.visit_candidates(shaft, parent_candidates, |id, _| out.push(id));
        if parent_candidates.is_none() {
            out.sort_unstable();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::DVec3;
    use glam::DQuat;

    #[test]
    fn obb_test_is_tighter_than_its_box() {
        let a = Aabb { min: DVec3::ZERO, max: DVec3::ONE };
        let b = Aabb { min: DVec3::new(10.0, 10.0, 0.0), max: DVec3::new(11.0, 11.0, 1.0) };
        let s = Shaft::new(&a, &b);
        // A thin plank along the anti-diagonal, beside the shaft near its corner; its world box
        // reaches into the shaft, the plank itself does not.
        let rot = DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4);
        let obb =
            Obb { center: DVec3::new(8.0, 3.0, 0.5), axes: [rot * DVec3::X, rot * DVec3::Y, DVec3::Z], half: DVec3::new(3.0, 0.05, 0.5) };
        assert!(may_intersect_aabb(&s, &obb.aabb()));
        assert!(!may_intersect_obb(&s, &obb));
        let inside = Obb { center: DVec3::new(5.5, 5.5, 0.5), ..obb };
        assert!(may_intersect_obb(&s, &inside));
    }
}
