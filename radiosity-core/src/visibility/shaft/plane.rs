//! Planes as closed half-spaces and the interval bounds of a linear form over boxes and point sets.

use crate::geom::{Aabb, DVec3};

/// The closed half-space `normal · x <= offset`; `normal` points out of it and is unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit outward normal.
    pub normal: DVec3,
    /// Offset: the half-space is `normal · x <= offset`.
    pub offset: f64,
}

impl Plane {
    /// The plane through `point` with outward `normal`; `None` when `normal` cannot be normalised.
    #[must_use]
    pub fn try_through(normal: DVec3, point: DVec3) -> Option<Plane> {
        let n = normal.try_normalize()?;
        Some(Plane { normal: n, offset: n.dot(point) })
    }

    /// Signed distance of `p` (positive outside).
    #[must_use]
    #[inline]
    pub fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }

    /// Smallest value of `normal · x` over the box (interval arithmetic, exact for a box).
    #[must_use]
    #[inline]
    pub fn min_over_aabb(&self, b: &Aabb) -> f64 {
        min_dot_aabb(self.normal, b)
    }

    /// Largest value of `normal · x` over the box.
    #[must_use]
    #[inline]
    pub fn max_over_aabb(&self, b: &Aabb) -> f64 {
        -min_dot_aabb(-self.normal, b)
    }

    /// Smallest value of `normal · x` over a finite point set (`+inf` when empty).
    #[must_use]
    #[inline]
    pub fn min_over_points(&self, points: &[DVec3]) -> f64 {
        points.iter().map(|&p| self.normal.dot(p)).fold(f64::INFINITY, f64::min)
    }
}

/// `min { n · x : x in b }`, computed per axis from the interval `[b.min_k, b.max_k]`.
#[must_use]
#[inline]
pub fn min_dot_aabb(n: DVec3, b: &Aabb) -> f64 {
    let lo = n * b.min;
    let hi = n * b.max;
    lo.x.min(hi.x) + lo.y.min(hi.y) + lo.z.min(hi.z)
}

/// The 8 corners of a box (bit k of the index selects `max` on axis k).
#[must_use]
pub fn aabb_corners(b: &Aabb) -> [DVec3; 8] {
    std::array::from_fn(|c| {
        DVec3::new(
            if c & 1 == 0 { b.min.x } else { b.max.x },
            if c & 2 == 0 { b.min.y } else { b.max.y },
            if c & 4 == 0 { b.min.z } else { b.max.z },
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_bounds_match_corners() {
        let b = Aabb { min: DVec3::new(-1.0, 2.0, 0.5), max: DVec3::new(3.0, 2.5, 4.0) };
        let p = Plane::try_through(DVec3::new(0.3, -0.8, 0.5), DVec3::ZERO).unwrap();
        let corners = aabb_corners(&b);
        let lo = corners.iter().map(|&c| p.normal.dot(c)).fold(f64::INFINITY, f64::min);
        let hi = corners.iter().map(|&c| p.normal.dot(c)).fold(f64::NEG_INFINITY, f64::max);
        assert!((p.min_over_aabb(&b) - lo).abs() < 1e-12, "min {} vs {lo}", p.min_over_aabb(&b));
        assert!((p.max_over_aabb(&b) - hi).abs() < 1e-12, "max {} vs {hi}", p.max_over_aabb(&b));
        assert!((p.min_over_points(&corners) - lo).abs() < 1e-15);
    }
}
