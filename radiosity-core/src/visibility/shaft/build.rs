//! Shaft construction (Haines & Wallace): the extent box of two axis-aligned boxes plus the side
//! planes that join them, built from their relative position on each axis.
//!
//! For each of the 12 edges of the extent box (a pair of adjacent faces, one on axis `i` and one on
//! axis `j`), each face is "owned" by the box that reaches it (the box with the smaller minimum for a
//! `min` face, the larger maximum for a `max` face). When the two faces have different owners, the
//! plane through the corresponding edges of both boxes (parallel to the third axis) bounds the
//! shaft. Each such plane supports both boxes, so the shaft contains their convex hull; projected on
//! any coordinate plane it is exactly the convex hull of the two projected rectangles.
//!
//! Degenerate cases, all handled by the same rule:
//! - one box inside the other (possibly sharing faces): the outer box owns every face, there are no
//!   side planes and the shaft is the outer box ([`ShaftKind::Nested`]);
//! - boxes with equal bounds on a face: the face has no single owner, no plane is built on its edges
//!   (such a plane would coincide with the face);
//! - boxes that touch or overlap on an axis, and flat or point boxes: nothing special, the planes are
//!   built from the corner coordinates only (their normals never vanish, see [`Shaft::new`]).

use super::plane::{Plane, aabb_corners, min_dot_aabb};
use crate::geom::{Aabb, DVec3};

/// Relative tolerance of shaft tests, times the diagonal of the shaft's extent box: the planes are
/// pushed outwards by this much, so rounding never drops a real intersection.
pub const SHAFT_REL_TOL: f64 = 1e-9;

/// At most 8 side planes: the largest number of extent-box edges whose two faces have different
/// owners (the maximum cut of the cube's face adjacency).
pub const MAX_SIDE_PLANES: usize = 8;

/// How the two boxes of a shaft relate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaftKind {
    /// One box contains the other: the shaft is the outer box, without side planes.
    Nested,
    /// The general case: extent box plus side planes.
    Joined,
}

/// A shaft between two boxes: the extent box of both intersected with up to 8 side planes, at most
/// 14 planes in all. Conservative: contains the convex hull of the two boxes.
#[derive(Clone, Copy, Debug)]
pub struct Shaft {
    /// The first box (the emitter's).
    pub a: Aabb,
    /// The second box (the receiver's).
    pub b: Aabb,
    /// The bounding box of both.
    pub extent: Aabb,
    /// Nested or joined.
    pub kind: ShaftKind,
    /// Absolute tolerance of every test: [`SHAFT_REL_TOL`] times the extent's diagonal.
    pub tol: f64,
    sides: [Plane; MAX_SIDE_PLANES],
    n_sides: u8,
}

/// Which box reaches a face of the extent box.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Owner {
    A,
    B,
    Both,
}

impl Shaft {
    /// The shaft between boxes `a` and `b`. An empty box contributes nothing: the shaft of a box and
    /// an empty box is that box ([`ShaftKind::Nested`]).
    #[must_use]
    pub fn new(a: &Aabb, b: &Aabb) -> Shaft {
        let extent = a.merged(b);
        let tol = SHAFT_REL_TOL * extent.diagonal().max(f64::MIN_POSITIVE);
        let mut shaft = Shaft {
            a: *a,
            b: *b,
            extent,
            kind: ShaftKind::Nested,
            tol,
            sides: [Plane { normal: DVec3::ZERO, offset: 0.0 }; MAX_SIDE_PLANES],
            n_sides: 0,
        };
        if a.is_empty() || b.is_empty() {
            return shaft;
        }
        // Owner of face (axis, side), side 0 = min, 1 = max.
        let owner_of = |axis: usize, side: usize| -> Owner {
            let (ea, eb) = if side == 0 { (-a.min[axis], -b.min[axis]) } else { (a.max[axis], b.max[axis]) };
            if ea > eb {
                Owner::A
            } else if eb > ea {
                Owner::B
            } else {
                Owner::Both
            }
        };
        let owners: [[Owner; 2]; 3] = std::array::from_fn(|axis| [owner_of(axis, 0), owner_of(axis, 1)]);
        let owner = |axis: usize, side: usize| owners[axis][side];
        let face = |bx: &Aabb, axis: usize, side: usize| if side == 0 { bx.min[axis] } else { bx.max[axis] };
        // At most 12 edges; the owners' cut has at most MAX_SIDE_PLANES of them.
        let mut planes = [(Plane { normal: DVec3::ZERO, offset: 0.0 }, 0.0f64); 12];
        let mut n_planes = 0;
        let axis_dir = b.center() - a.center();
        let (u, v) = perpendicular_basis(axis_dir);
        for i in 0..3 {
            for j in i + 1..3 {
                for si in 0..2 {
                    for sj in 0..2 {
                        let (oi, oj) = (owner(i, si), owner(j, sj));
                        let (x, y) = match (oi, oj) {
                            (Owner::A, Owner::B) => (a, b),
                            (Owner::B, Owner::A) => (b, a),
                            _ => continue,
                        };
                        // X owns face i, Y owns face j. In the (i, j) plane the line runs through
                        // X's corner (X_i, X_j) and Y's corner (Y_i, Y_j); with sigma the outward signs,
                        // the outward normal is (sigma_i |dj|, sigma_j |di|) (see the module docs).
                        let (xi, xj) = (face(x, i, si), face(x, j, sj));
                        let (yi, yj) = (face(y, i, si), face(y, j, sj));
                        let (di, dj) = ((yi - xi).abs(), (yj - xj).abs());
                        let sigma = |s: usize| if s == 0 { -1.0 } else { 1.0 };
                        let mut n = DVec3::ZERO;
                        n[i] = sigma(si) * dj;
                        n[j] = sigma(sj) * di;
                        let mut p = DVec3::ZERO;
                        p[i] = xi;
                        p[j] = xj;
                        // di and dj are both > 0 because the owners differ strictly.
                        let Some(plane) = Plane::try_through(n, p) else { continue };
                        let angle = pseudo_angle(plane.normal.dot(v), plane.normal.dot(u));
                        planes[n_planes] = (plane, angle);
                        n_planes += 1;
                    }
                }
            }
        }
        // Cyclic order: by the angle of the outward normal about the axis joining the box centres.
        let planes = &mut planes[..n_planes];
        planes.sort_by(|p, q| p.1.total_cmp(&q.1));
        shaft.kind = if planes.is_empty() && (contains(a, b) || contains(b, a)) { ShaftKind::Nested } else { ShaftKind::Joined };
        for (k, &(plane, _)) in planes.iter().take(MAX_SIDE_PLANES).enumerate() {
            shaft.sides[k] = plane;
            shaft.n_sides = (k + 1) as u8;
        }
        shaft
    }

    /// The side planes, in cyclic order about the axis joining the box centres.
    #[must_use]
    pub fn side_planes(&self) -> &[Plane] {
        &self.sides[..self.n_sides as usize]
    }

    /// Every bounding plane: the 6 faces of the extent box, then the side planes (at most 14).
    pub fn planes(&self) -> impl Iterator<Item = Plane> + '_ {
        let e = self.extent;
        (0..6)
            .map(move |f| {
                let axis = f / 2;
                let mut n = DVec3::ZERO;
                if f % 2 == 0 {
                    n[axis] = -1.0;
                    Plane { normal: n, offset: -e.min[axis] }
                } else {
                    n[axis] = 1.0;
                    Plane { normal: n, offset: e.max[axis] }
                }
            })
            .chain(self.side_planes().iter().copied())
    }

    /// True when `p` lies in the shaft, up to the shaft's tolerance.
    #[must_use]
    pub fn contains_point(&self, p: DVec3) -> bool {
        self.planes().all(|pl| pl.distance(p) <= self.tol)
    }

    /// Conservative box test: false only when the box lies entirely outside one of the shaft's planes.
    #[must_use]
    pub fn may_intersect_aabb(&self, b: &Aabb) -> bool {
        if b.is_empty() || !self.extent_overlaps(b) {
            return false;
        }
        self.side_planes().iter().all(|pl| min_dot_aabb(pl.normal, b) <= pl.offset + self.tol)
    }

    /// Whether the box overlaps the extent box (with tolerance).
    #[must_use]
    pub fn extent_overlaps(&self, b: &Aabb) -> bool {
        let e = &self.extent;
        let t = self.tol;
        b.min.x <= e.max.x + t
            && b.min.y <= e.max.y + t
            && b.min.z <= e.max.z + t
            && b.max.x >= e.min.x - t
            && b.max.y >= e.min.y - t
            && b.max.z >= e.min.z - t
    }

    /// How deep the box reaches into the extent box: the smallest, over the extent's 6 faces, of how
    /// far the box's deepest point lies inside the face (negative when it lies outside one).
    #[must_use]
    #[inline]
    pub fn extent_depth(&self, b: &Aabb) -> f64 {
        (self.extent.max - b.min).min(b.max - self.extent.min).min_element()
    }

    /// Conservative test of a finite point set's convex hull: false only when every point lies
    /// outside one same plane of the shaft. Exact for each plane (the support function of the hull).
    #[must_use]
    pub fn may_intersect_points(&self, points: &[DVec3]) -> bool {
        !points.is_empty() && self.planes().all(|pl| pl.min_over_points(points) <= pl.offset + self.tol)
    }

    /// Corners of both boxes (16 points), used by tests and by occlusion.
    #[must_use]
    pub fn box_corners(&self) -> [DVec3; 16] {
        let (ca, cb) = (aabb_corners(&self.a), aabb_corners(&self.b));
        std::array::from_fn(|k| if k < 8 { ca[k] } else { cb[k - 8] })
    }
}

/// A cheap stand-in for `y.atan2(x)`, increasing with it on `(-π, π]` (the "diamond angle", in
/// `(-2, 2]`), so that sorting by it gives the same cyclic order without a transcendental call.
fn pseudo_angle(y: f64, x: f64) -> f64 {
    let l1 = x.abs() + y.abs();
    if l1 == 0.0 {
        return 0.0;
    }
    // 1 − x/l1 runs from 0 (direction +x) to 2 (direction −x) over the upper half plane.
    let half = 1.0 - x / l1;
    if y >= 0.0 { half } else { -half }
}

fn contains(outer: &Aabb, inner: &Aabb) -> bool {
    outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
}

/// Two unit vectors perpendicular to `axis` and to each other (any pair when `axis` vanishes).
fn perpendicular_basis(axis: DVec3) -> (DVec3, DVec3) {
    let w = axis.try_normalize().unwrap_or(DVec3::Z);
    let helper = if w.x.abs() < 0.6 { DVec3::X } else { DVec3::Y };
    let u = helper.cross(w).normalize();
    (u, w.cross(u))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bx(min: [f64; 3], max: [f64; 3]) -> Aabb {
        Aabb { min: DVec3::from(min), max: DVec3::from(max) }
    }

    /// Every side plane supports both boxes: both lie inside, and each touches it.
    fn check_supporting(s: &Shaft) {
        for pl in s.side_planes() {
            for bxx in [&s.a, &s.b] {
                let hi = -min_dot_aabb(-pl.normal, bxx);
                assert!((hi - pl.offset).abs() <= s.tol, "plane {pl:?} does not support {bxx:?}: max {hi}");
            }
        }
    }

    #[test]
    fn nested_boxes_give_the_outer_box() {
        let outer = bx([0.0; 3], [4.0; 3]);
        let inner = bx([1.0, 1.0, 0.0], [2.0, 3.0, 4.0]); // shares two faces with the outer box
        for (a, b) in [(outer, inner), (inner, outer)] {
            let s = Shaft::new(&a, &b);
            assert_eq!(s.kind, ShaftKind::Nested);
            assert!(s.side_planes().is_empty());
            assert_eq!(s.extent, outer);
        }
        let s = Shaft::new(&outer, &outer);
        assert_eq!((s.kind, s.side_planes().len()), (ShaftKind::Nested, 0), "identical boxes");
    }

    #[test]
    fn diagonal_boxes_have_side_planes_in_cyclic_order() {
        let s = Shaft::new(&bx([0.0; 3], [1.0; 3]), &bx([5.0; 3], [6.0; 3]));
        assert_eq!(s.kind, ShaftKind::Joined);
        assert_eq!(s.side_planes().len(), 6, "translated equal cubes: the hull's 6 side faces");
        check_supporting(&s);
        // Different sizes on a diagonal: A owns all min faces, B all max faces except the largest.
        let s = Shaft::new(&bx([0.0; 3], [1.0; 3]), &bx([5.0, 5.0, -3.0], [6.0, 6.0, 9.0]));
        check_supporting(&s);
        assert!(s.side_planes().len() <= MAX_SIDE_PLANES);
        let axis = s.b.center() - s.a.center();
        let (u, v) = perpendicular_basis(axis);
        let angles: Vec<f64> = s.side_planes().iter().map(|p| p.normal.dot(v).atan2(p.normal.dot(u))).collect();
        assert!(angles.windows(2).all(|w| w[0] <= w[1]), "side planes not in cyclic order: {angles:?}");
    }

    #[test]
    fn maximal_cut_gives_eight_planes() {
        // A owns both x faces, B owns the y and z faces: 8 edges join faces of different owners.
        let a = bx([-5.0, -1.0, -1.0], [5.0, 1.0, 1.0]);
        let b = bx([-1.0, -5.0, -5.0], [1.0, 5.0, 5.0]);
        let s = Shaft::new(&a, &b);
        assert_eq!(s.side_planes().len(), 8);
        check_supporting(&s);
    }

    #[test]
    fn touching_and_overlapping_boxes() {
        // Touching along x = 1, same y and z range: the shaft is the union box, no side planes.
        let s = Shaft::new(&bx([0.0; 3], [1.0; 3]), &bx([1.0, 0.0, 0.0], [2.0, 1.0, 1.0]));
        assert!(s.side_planes().is_empty());
        assert_eq!(s.kind, ShaftKind::Joined);
        assert!(s.contains_point(DVec3::new(1.5, 0.5, 0.5)));
        // Overlapping on x, offset on y: two side planes (z faces are shared).
        let s = Shaft::new(&bx([0.0, 0.0, 0.0], [2.0, 1.0, 1.0]), &bx([1.0, 3.0, 0.0], [3.0, 4.0, 1.0]));
        assert_eq!(s.side_planes().len(), 2);
        check_supporting(&s);
        assert!(!s.contains_point(DVec3::new(2.9, 0.1, 0.5)), "corner cut by a side plane");
        assert!(s.contains_point(DVec3::new(2.0, 2.0, 0.5)));
    }

    #[test]
    fn flat_and_point_boxes() {
        // Two parallel unit squares (zero thickness in z), offset diagonally.
        let s = Shaft::new(&bx([0.0, 0.0, 0.0], [1.0, 1.0, 0.0]), &bx([2.0, 2.0, 3.0], [3.0, 3.0, 3.0]));
        check_supporting(&s);
        assert!(s.side_planes().iter().all(|p| p.normal.is_finite()));
        assert!(s.contains_point(DVec3::new(1.5, 1.5, 1.5)));
        assert!(!s.contains_point(DVec3::new(0.0, 3.0, 1.5)));
        // A point and a box: the shaft is the pyramid-like hull.
        let s = Shaft::new(&bx([0.0; 3], [0.0; 3]), &bx([2.0, -1.0, -1.0], [2.0, 1.0, 1.0]));
        check_supporting(&s);
        assert!(s.contains_point(DVec3::new(1.0, 0.0, 0.0)));
        assert!(!s.contains_point(DVec3::new(1.0, 0.9, 0.0)));
        // Empty box: the shaft is the other box.
        let s = Shaft::new(&Aabb::EMPTY, &bx([0.0; 3], [1.0; 3]));
        assert_eq!((s.kind, s.extent), (ShaftKind::Nested, bx([0.0; 3], [1.0; 3])));
    }

    #[test]
    fn pseudo_angle_orders_like_atan2() {
        let angles: Vec<f64> = (0..720).map(|k| -std::f64::consts::PI + (k as f64 + 0.5) * std::f64::consts::TAU / 720.0).collect();
        let pseudo: Vec<f64> = angles.iter().map(|t| pseudo_angle(3.0 * t.sin(), 3.0 * t.cos())).collect();
        assert!(pseudo.windows(2).all(|w| w[0] < w[1]), "not increasing with the angle");
        assert_eq!(pseudo_angle(0.0, 0.0), 0.0);
        assert!((pseudo_angle(1.0, 0.0) - 1.0).abs() < 1e-15 && (pseudo_angle(-1.0, 0.0) + 1.0).abs() < 1e-15);
    }

    #[test]
    fn box_test_rejects_boxes_beyond_a_side_plane() {
        let s = Shaft::new(&bx([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), &bx([4.0, 4.0, 0.0], [5.0, 5.0, 1.0]));
        assert!(s.may_intersect_aabb(&bx([2.0, 2.0, 0.2], [2.5, 2.5, 0.4])), "box on the axis");
        assert!(!s.may_intersect_aabb(&bx([4.0, 0.0, 0.0], [5.0, 1.0, 1.0])), "box in the corner, outside the hull");
        assert!(!s.may_intersect_aabb(&bx([2.0, 2.0, 1.5], [2.5, 2.5, 2.0])), "box above the extent");
        // Touching counts as intersecting.
        assert!(s.may_intersect_aabb(&bx([2.0, 2.0, 1.0], [2.5, 2.5, 2.0])));
    }
}
