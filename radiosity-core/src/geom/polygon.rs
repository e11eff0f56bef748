//! Planar triangles and quads with a parametrisation used for regular subdivision.
//!
//! A triangle is parametrised by barycentric coordinates, a quad bilinearly by `(u, v)` in the unit square:
//! `P(u, v) = (1-u)(1-v) v0 + u(1-v) v1 + u v v2 + (1-u) v v3`. Regular subdivision into 4 children
//! is defined in that parameter space, so every descendant keeps the same kind.

use glam::DVec3;

/// Relative tolerance of [`Poly::is_back_of`]: how far apart (relative to the polygon's size) the
/// matching vertices of the two sides may be.
pub const BACK_TO_BACK_REL_TOL: f64 = 1e-9;

/// Triangle or quad.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PolyKind {
    /// Three vertices.
    Triangle,
    /// Four vertices, planar and convex.
    Quad,
}

/// A planar convex polygon with 3 or 4 vertices, counter-clockwise about its front normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Poly {
    /// Vertices; the fourth is unused (and equal to the third) for triangles.
    pub v: [DVec3; 4],
    /// Triangle or quad.
    pub kind: PolyKind,
}

impl Poly {
    /// A triangle.
    #[must_use]
    pub fn triangle(a: DVec3, b: DVec3, c: DVec3) -> Poly {
        Poly { v: [a, b, c, c], kind: PolyKind::Triangle }
    }

    /// A quad (the caller guarantees it is planar and convex).
    #[must_use]
    pub fn quad(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Poly {
        Poly { v: [a, b, c, d], kind: PolyKind::Quad }
    }

    /// Number of vertices (3 or 4).
    #[must_use]
    pub fn n_vertices(&self) -> usize {
        match self.kind {
            PolyKind::Triangle => 3,
            PolyKind::Quad => 4,
        }
    }

    /// The vertices as a slice.
    #[must_use]
    pub fn vertices(&self) -> &[DVec3] {
        &self.v[..self.n_vertices()]
    }

    /// The polygon with its vertex order reversed (the back side becomes the front).
    #[must_use]
    pub fn reversed(&self) -> Poly {
        let v = self.vertices();
        match v.len() {
            3 => Poly::triangle(v[2], v[1], v[0]),
            _ => Poly::quad(v[3], v[2], v[1], v[0]),
        }
    }

    /// Whether `other` is this polygon's back: the same outline facing the other way (its vertices
    /// those of this polygon in reverse order, from any start, each within [`BACK_TO_BACK_REL_TOL`]
    /// of the polygon's size), as a leaf's two faces are. Vertices, not centroids and areas: a quad
    /// written with a few decimals is planar only to its rounding, and then its two triangulations
    /// (the front's and the reversed back's split along different diagonals) have centroids
    /// 1e-10 m apart on a 10 cm leaf.
    #[must_use]
    pub fn is_back_of(&self, other: &Poly) -> bool {
        let (a, b) = (self.vertices(), other.vertices());
        if a.len() != b.len() || self.normal().dot(other.normal()) >= 0.0 {
            return false;
        }
        let scale = a.iter().map(|v| v.abs().max_element()).fold(0.0, f64::max);
        let tol = BACK_TO_BACK_REL_TOL * self.area().sqrt() + 8.0 * f64::EPSILON * scale;
        let n = a.len();
        (0..n).any(|k| (0..n).all(|j| (b[j] - a[(k + n - j) % n]).length() <= tol))
    }

    /// Area vector (normal times area), by Newell's method.
    #[must_use]
    pub fn area_vector(&self) -> DVec3 {
        let vs = self.vertices();
        let mut n = DVec3::ZERO;
        for i in 0..vs.len() {
            n += vs[i].cross(vs[(i + 1) % vs.len()]);
        }
        0.5 * n
    }

    /// Where the line `a + t·d` crosses the polygon (convex, edges included): its parameter `t`,
    /// or `None` when it misses the polygon or runs parallel to its plane.
    #[must_use]
    pub fn crossing(&self, a: DVec3, d: DVec3) -> Option<f64> {
        let n = self.area_vector();
        let denom = n.dot(d);
        if denom == 0.0 {
            return None;
        }
        let t = n.dot(self.v[0] - a) / denom;
        let x = a + d * t;
        let vs = self.vertices();
        (0..vs.len()).all(|k| (vs[(k + 1) % vs.len()] - vs[k]).cross(x - vs[k]).dot(n) >= 0.0).then_some(t)
    }

    /// The point of the polygon (convex, edges included) nearest to `x`.
    #[must_use]
    pub fn nearest_point(&self, x: DVec3) -> DVec3 {
        let n = self.normal();
        let p = x - n * n.dot(x - self.v[0]);
        let vs = self.vertices();
        let inside = (0..vs.len()).all(|k| (vs[(k + 1) % vs.len()] - vs[k]).cross(p - vs[k]).dot(n) >= 0.0);
        if inside {
            return p;
        }
        let mut best = vs[0];
        let mut best_d = f64::INFINITY;
        for k in 0..vs.len() {
            let (a, b) = (vs[k], vs[(k + 1) % vs.len()]);
            let e = b - a;
            let len2 = e.length_squared();
            let t = if len2 > 0.0 { (e.dot(p - a) / len2).clamp(0.0, 1.0) } else { 0.0 };
            let q = a + e * t;
            let d = (q - p).length_squared();
            if d < best_d {
                best_d = d;
                best = q;
            }
        }
        best
    }

    /// Area in square scene units.
    #[must_use]
    pub fn area(&self) -> f64 {
        self.area_vector().length()
    }

    /// Unit front normal, or zero for a degenerate polygon.
    #[must_use]
    pub fn normal(&self) -> DVec3 {
        self.area_vector().normalize_or_zero()
    }

    /// Area centroid.
    #[must_use]
    pub fn centroid(&self) -> DVec3 {
        match self.kind {
            PolyKind::Triangle => (self.v[0] + self.v[1] + self.v[2]) / 3.0,
            PolyKind::Quad => {
                let t1 = Poly::triangle(self.v[0], self.v[1], self.v[2]);
                let t2 = Poly::triangle(self.v[0], self.v[2], self.v[3]);
                let (a1, a2) = (t1.area(), t2.area());
                if a1 + a2 > 0.0 {
                    (t1.centroid() * a1 + t2.centroid() * a2) / (a1 + a2)
                } else {
                    0.25 * (self.v[0] + self.v[1] + self.v[2] + self.v[3])
                }
            }
        }
    }

    /// Point at parameter `(s, t)`: bilinear for quads; for triangles `P = v0 + s (v1 - v0) + t (v2 - v0)`
    /// with `s, t >= 0`, `s + t <= 1`.
    #[must_use]
    pub fn point(&self, s: f64, t: f64) -> DVec3 {
        match self.kind {
            PolyKind::Triangle => self.v[0] + s * (self.v[1] - self.v[0]) + t * (self.v[2] - self.v[0]),
            PolyKind::Quad => (1.0 - s) * (1.0 - t) * self.v[0] + s * (1.0 - t) * self.v[1] + s * t * self.v[2] + (1.0 - s) * t * self.v[3],
        }
    }

    /// Maps a point of the unit square to the polygon so that uniform `(s, t)` gives (nearly, for
    /// non-parallelogram quads) uniform points. Triangles use the square-to-triangle fold.
    #[must_use]
    pub fn sample(&self, s: f64, t: f64) -> DVec3 {
        match self.kind {
            PolyKind::Triangle => {
                if s + t > 1.0 {
                    self.point(1.0 - s, 1.0 - t)
                } else {
                    self.point(s, t)
                }
            }
            PolyKind::Quad => self.point(s, t),
        }
    }

    /// The 4 children of regular subdivision, in a fixed order (corner children first).
    #[must_use]
    pub fn subdivide(&self) -> [Poly; 4] {
        let v = &self.v;
        match self.kind {
            PolyKind::Triangle => {
                let m01 = 0.5 * (v[0] + v[1]);
                let m12 = 0.5 * (v[1] + v[2]);
                let m20 = 0.5 * (v[2] + v[0]);
                [
                    Poly::triangle(v[0], m01, m20),
                    Poly::triangle(m01, v[1], m12),
                    Poly::triangle(m20, m12, v[2]),
                    Poly::triangle(m12, m20, m01),
                ]
            }
            PolyKind::Quad => {
                let m01 = 0.5 * (v[0] + v[1]);
                let m12 = 0.5 * (v[1] + v[2]);
                let m23 = 0.5 * (v[2] + v[3]);
                let m30 = 0.5 * (v[3] + v[0]);
                let c = self.point(0.5, 0.5);
                [Poly::quad(v[0], m01, c, m30), Poly::quad(m01, v[1], m12, c), Poly::quad(c, m12, v[2], m23), Poly::quad(m30, c, m23, v[3])]
            }
        }
    }

    /// Maps a point given in this polygon's parameters to (child index, parameters in that child),
    /// consistent with [`Poly::subdivide`]. Triangle parameters are `(s, t)` as in [`Poly::point`].
    #[must_use]
    pub fn child_of_param(kind: PolyKind, s: f64, t: f64) -> (usize, f64, f64) {
        match kind {
            PolyKind::Quad => {
                let (i, s2) = if s < 0.5 { (0, 2.0 * s) } else { (1, 2.0 * s - 1.0) };
                let (j, t2) = if t < 0.5 { (0, 2.0 * t) } else { (1, 2.0 * t - 1.0) };
                let child = match (i, j) {
                    (0, 0) => 0,
                    (1, 0) => 1,
                    (1, 1) => 2,
                    _ => 3,
                };
                (child, s2, t2)
            }
            PolyKind::Triangle => {
                // Barycentrics (a, b, c) of v0, v1, v2.
                let (a, b, c) = (1.0 - s - t, s, t);
                if a >= 0.5 {
                    // Child 0: (v0, m01, m20): P = v0 + s' (m01 - v0) + t' (m20 - v0).
                    (0, 2.0 * b, 2.0 * c)
                } else if b >= 0.5 {
                    // Child 1: (m01, v1, m12): barycentrics there: a' = 2a, c' = 2c.
                    (1, 1.0 - 2.0 * a - 2.0 * c, 2.0 * c)
                } else if c >= 0.5 {
                    // Child 2: (m20, m12, v2).
                    (2, 2.0 * b, 1.0 - 2.0 * a - 2.0 * b)
                } else {
                    // Child 3: (m12, m20, m01): barycentrics (1-2a, 1-2b, 1-2c).
                    (3, 1.0 - 2.0 * b, 1.0 - 2.0 * c)
                }
            }
        }
    }

    /// Parameters `(s, t)` of a point lying on (or near) the polygon's plane: exact for triangles and
    /// parallelograms, Newton-refined for general quads.
    #[must_use]
    pub fn param_of_point(&self, p: DVec3) -> (f64, f64) {
        let n = self.area_vector();
        // Project on the dominant plane for a 2D solve.
        let ax = n.abs();
        let (i, j) = if ax.x >= ax.y && ax.x >= ax.z {
            (1, 2)
        } else if ax.y >= ax.z {
            (2, 0)
        } else {
            (0, 1)
        };
        let to2 = |q: DVec3| [q[i], q[j]];
        let p2 = to2(p);
        match self.kind {
            PolyKind::Triangle => {
                let (a, b, c) = (to2(self.v[0]), to2(self.v[1]), to2(self.v[2]));
                let e1 = [b[0] - a[0], b[1] - a[1]];
                let e2 = [c[0] - a[0], c[1] - a[1]];
                let d = [p2[0] - a[0], p2[1] - a[1]];
                let det = e1[0] * e2[1] - e1[1] * e2[0];
                if det == 0.0 {
                    return (1.0 / 3.0, 1.0 / 3.0);
                }
                ((d[0] * e2[1] - d[1] * e2[0]) / det, (e1[0] * d[1] - e1[1] * d[0]) / det)
            }
            PolyKind::Quad => {
                let q: Vec<[f64; 2]> = self.v.iter().map(|&v| to2(v)).collect();
                let (mut s, mut t) = (0.5, 0.5);
                for _ in 0..8 {
                    let f = |s: f64, t: f64, k: usize| {
                        (1.0 - s) * (1.0 - t) * q[0][k] + s * (1.0 - t) * q[1][k] + s * t * q[2][k] + (1.0 - s) * t * q[3][k]
                    };
                    let r = [f(s, t, 0) - p2[0], f(s, t, 1) - p2[1]];
                    let ds = [
                        (1.0 - t) * (q[1][0] - q[0][0]) + t * (q[2][0] - q[3][0]),
                        (1.0 - t) * (q[1][1] - q[0][1]) + t * (q[2][1] - q[3][1]),
                    ];
                    let dt = [
                        (1.0 - s) * (q[3][0] - q[0][0]) + s * (q[2][0] - q[1][0]),
                        (1.0 - s) * (q[3][1] - q[0][1]) + s * (q[2][1] - q[1][1]),
                    ];
                    let det = ds[0] * dt[1] - ds[1] * dt[0];
                    if det == 0.0 {
                        break;
                    }
                    let step_s = (r[0] * dt[1] - r[1] * dt[0]) / det;
                    let step_t = (ds[0] * r[1] - ds[1] * r[0]) / det;
                    s -= step_s;
                    t -= step_t;
                    if step_s.abs() + step_t.abs() < 1e-13 {
                        break;
                    }
                }
                (s, t)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn child_param_round_trip() {
        let tri = Poly::triangle(DVec3::ZERO, DVec3::X * 2.0, DVec3::new(0.3, 1.7, 0.0));
        let quad = Poly::quad(DVec3::ZERO, DVec3::new(2.0, 0.1, 0.0), DVec3::new(2.3, 1.5, 0.0), DVec3::new(-0.2, 1.2, 0.0));
        for poly in [tri, quad] {
            let children = poly.subdivide();
            for &(s, t) in &[(0.1, 0.2), (0.6, 0.1), (0.2, 0.7), (0.3, 0.3), (0.45, 0.45)] {
                let p = poly.point(s, t);
                let (c, s2, t2) = Poly::child_of_param(poly.kind, s, t);
                let q = children[c].point(s2, t2);
                assert!((p - q).length() < 1e-12, "{:?} child {c}: {p} vs {q}", poly.kind);
                let (s3, t3) = poly.param_of_point(p);
                assert!((s3 - s).abs() < 1e-9 && (t3 - t).abs() < 1e-9);
            }
            let area: f64 = children.iter().map(|c| c.area()).sum();
            assert!((area - poly.area()).abs() < 1e-12);
        }
    }
}
