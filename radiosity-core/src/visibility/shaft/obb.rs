//! Oriented bounding boxes fitted to point sets: principal axes (PCA) first, then tightened by trying
//! the frames given by the object's own faces and edges and the world axes, keeping the smallest box.

use super::plane::{Plane, aabb_corners};
use crate::geom::{Aabb, DVec3};

/// An oriented box: `center + sum_k t_k axes[k]` with `|t_k| <= half[k]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obb {
    /// Centre.
    pub center: DVec3,
    /// Orthonormal axes.
    pub axes: [DVec3; 3],
    /// Half extents along the axes (>= 0; zero for flat objects).
    pub half: DVec3,
}

/// Relative padding used when ranking candidate boxes, times the points' diameter, so that flat
/// boxes (zero volume) are ranked by area rather than all tying at zero.
const RANK_PAD_REL: f64 = 1e-3;

/// Most faces of an object whose frames are tried when tightening.
const MAX_FACE_FRAMES: usize = 8;

/// How far from 1 the largest component of a unit axis may be for the axis to count as a world
/// axis ([`Obb::is_axis_aligned`]).
pub const AXIS_ALIGNED_TOL: f64 = 1e-12;

impl Obb {
    /// The box with the world axes that equals `b`.
    #[must_use]
    pub fn from_aabb(b: &Aabb) -> Obb {
        Obb { center: b.center(), axes: [DVec3::X, DVec3::Y, DVec3::Z], half: 0.5 * b.extent() }
    }

    /// The smallest box with the given orthonormal axes containing `points`.
    #[must_use]
    pub fn with_axes(axes: [DVec3; 3], points: &[DVec3]) -> Obb {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for &p in points {
            let q = DVec3::new(axes[0].dot(p), axes[1].dot(p), axes[2].dot(p));
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let mid = 0.5 * (lo + hi);
        Obb { center: axes[0] * mid.x + axes[1] * mid.y + axes[2] * mid.z, axes, half: 0.5 * (hi - lo) }
    }

    /// Fits a box to `points`. `face_frames` are optional (normal, in-plane edge) pairs of the
    /// object's faces; each gives a candidate frame. Returns the smallest of: the principal axes,
    /// the world axes, and the face frames (by padded volume). Always contains every point.
    #[must_use]
    pub fn fit(points: &[DVec3], face_frames: &[(DVec3, DVec3)]) -> Obb {
        if points.is_empty() {
            return Obb { center: DVec3::ZERO, axes: [DVec3::X, DVec3::Y, DVec3::Z], half: DVec3::ZERO };
        }
        let diam = Aabb::from_points(points).diagonal();
        let pad = RANK_PAD_REL * diam;
        let rank = |o: &Obb| (o.half.x + pad) * (o.half.y + pad) * (o.half.z + pad);
        let mut best = Obb::with_axes([DVec3::X, DVec3::Y, DVec3::Z], points);
        let mut best_rank = rank(&best);
        let mut consider = |axes: [DVec3; 3]| {
            let o = Obb::with_axes(axes, points);
            let r = rank(&o);
            if r < best_rank {
                best = o;
                best_rank = r;
            }
        };
        if let Some(axes) = principal_axes(points) {
            consider(axes);
        }
        for &(n, e) in face_frames.iter().take(MAX_FACE_FRAMES) {
            if let Some(axes) = frame(n, e) {
                consider(axes);
            }
        }
        best
    }

    /// Whether every axis is a world axis (up to [`AXIS_ALIGNED_TOL`]): the box is then its own
    /// AABB.
    #[must_use]
    pub fn is_axis_aligned(&self) -> bool {
        self.axes.iter().all(|a| a.abs().max_element() >= 1.0 - AXIS_ALIGNED_TOL)
    }

    /// The 8 corners.
    #[must_use]
    pub fn corners(&self) -> [DVec3; 8] {
        let unit = aabb_corners(&Aabb { min: -self.half, max: self.half });
        unit.map(|c| self.center + self.axes[0] * c.x + self.axes[1] * c.y + self.axes[2] * c.z)
    }

    /// The world box of the corners.
    #[must_use]
    pub fn aabb(&self) -> Aabb {
        let r = DVec3::new(self.radius_along(DVec3::X), self.radius_along(DVec3::Y), self.radius_along(DVec3::Z));
        Aabb { min: self.center - r, max: self.center + r }
    }

    /// Half the width of the box along unit direction `n`: `sum_k half_k |n · axes_k|`.
    #[must_use]
    #[inline]
    pub fn radius_along(&self, n: DVec3) -> f64 {
        self.half.x * n.dot(self.axes[0]).abs() + self.half.y * n.dot(self.axes[1]).abs() + self.half.z * n.dot(self.axes[2]).abs()
    }

    /// Smallest value of `plane.normal · x` over the box (interval arithmetic, exact for a box).
    #[must_use]
    #[inline]
    pub fn min_along(&self, plane: &Plane) -> f64 {
        plane.normal.dot(self.center) - self.radius_along(plane.normal)
    }

    /// Volume.
    #[must_use]
    pub fn volume(&self) -> f64 {
        8.0 * self.half.x * self.half.y * self.half.z
    }
}

/// The orthonormal frame (n, e⊥, n × e⊥) from a normal and an edge direction.
fn frame(n: DVec3, e: DVec3) -> Option<[DVec3; 3]> {
    let n = n.try_normalize()?;
    let e = (e - n * n.dot(e)).try_normalize()?;
    Some([n, e, n.cross(e)])
}

/// Eigenvectors of the points' covariance (Jacobi rotations), as a right-handed orthonormal frame.
fn principal_axes(points: &[DVec3]) -> Option<[DVec3; 3]> {
    let n = points.len() as f64;
    let mean = points.iter().copied().sum::<DVec3>() / n;
    let mut c = [[0.0f64; 3]; 3];
    for &p in points {
        let d = p - mean;
        for i in 0..3 {
            for j in 0..3 {
                c[i][j] += d[i] * d[j];
            }
        }
    }
    let v = jacobi_eigenvectors(c);
    let a0 = DVec3::new(v[0][0], v[1][0], v[2][0]).try_normalize()?;
    let a1 = DVec3::new(v[0][1], v[1][1], v[2][1]);
    let a1 = (a1 - a0 * a0.dot(a1)).try_normalize()?;
    Some([a0, a1, a0.cross(a1)])
}

/// Eigenvectors (columns) of a symmetric 3×3 matrix by cyclic Jacobi rotations.
#[allow(clippy::needless_range_loop)] // Rotations update rows p and q together.
fn jacobi_eigenvectors(mut a: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..32 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let diag = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= 1e-15 * diag || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    #[test]
    fn rotated_box_is_recovered_exactly() {
        let rot = DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1);
        let half = DVec3::new(2.0, 0.5, 0.1);
        let corners = aabb_corners(&Aabb { min: -half, max: half }).map(|c| rot * c + DVec3::new(1.0, 2.0, 3.0));
        // A face frame from the box's own face recovers it exactly.
        let frames = [(rot * DVec3::Z, rot * DVec3::X)];
        let o = Obb::fit(&corners, &frames);
        assert!((o.volume() - 8.0 * half.x * half.y * half.z).abs() < 1e-9, "volume {}", o.volume());
        // PCA alone is also exact for a box's 8 corners (distinct extents).
        let o = Obb::fit(&corners, &[]);
        assert!((o.volume() - 0.8).abs() < 1e-9, "pca volume {}", o.volume());
        for c in corners {
            let q = c - o.center;
            for k in 0..3 {
                assert!(q.dot(o.axes[k]).abs() <= o.half[k] + 1e-9, "corner outside");
            }
        }
    }

    #[test]
    fn obb_never_worse_than_aabb_and_contains_points() {
        let pts = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(3.0, 3.0, 0.0), DVec3::new(3.2, 2.8, 0.0), DVec3::new(0.2, -0.2, 0.0)];
        let o = Obb::fit(&pts, &[]);
        let aabb = Aabb::from_points(&pts);
        assert!(o.half.x * o.half.y <= 0.25 * aabb.extent().x * aabb.extent().y + 1e-12);
        let b = o.aabb();
        for p in pts {
            assert!(b.min.cmple(p + 1e-9).all() && b.max.cmpge(p - 1e-9).all());
        }
    }
}
