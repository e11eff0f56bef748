//! Axis-aligned bounding boxes in `f64`.

use glam::DVec3;

/// An axis-aligned box. `Aabb::EMPTY` is the identity for [`Aabb::merge`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf).
    pub const EMPTY: Aabb = Aabb { min: DVec3::splat(f64::INFINITY), max: DVec3::splat(f64::NEG_INFINITY) };

    /// The box of a set of points.
    #[must_use]
    pub fn from_points(points: &[DVec3]) -> Aabb {
        let mut b = Aabb::EMPTY;
        for &p in points {
            b.grow(p);
        }
        b
    }

    /// Grows the box to contain `p`.
    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Grows the box to contain `other`.
    pub fn merge(&mut self, other: &Aabb) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    /// The union of two boxes.
    #[must_use]
    pub fn merged(&self, other: &Aabb) -> Aabb {
        let mut b = *self;
        b.merge(other);
        b
    }

    /// True when the box contains no point.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// Centre of the box.
    #[must_use]
    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Edge lengths.
    #[must_use]
    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    /// Length of the diagonal.
    #[must_use]
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() { 0.0 } else { self.extent().length() }
    }

    /// Index (0, 1, 2) of the longest axis.
    #[must_use]
    pub fn longest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// Surface area of the box.
    #[must_use]
    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}
