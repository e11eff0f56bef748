//! Lambert's contour formula: the form factor from a differential area to a polygon.
//! Reference: `shared/reference/formfactors.md`, section (a) (Lambert 1760; Baum, Rushmeier & Winget 1989).

use crate::geom::DVec3;

/// Largest number of vertices after clipping a quad by a plane (and a little room).
pub const MAX_CLIPPED: usize = 8;

/// Relative distance (to the polygon's size) under which a point counts as lying in the source's plane.
pub const COPLANAR_REL_EPS: f64 = 1e-10;

/// Form factor from the differential area at `x` with unit normal `n` to the polygon `poly` (CCW about
/// its front normal `poly_normal`). The polygon emits from its front side only: a point behind its
/// plane (or in it) gets 0. The part of the polygon behind `x`'s tangent plane is clipped away.
/// Result in [0, 1].
#[must_use]
pub fn point_polygon(x: DVec3, n: DVec3, poly: &[DVec3], poly_normal: DVec3) -> f64 {
    let size = poly.iter().map(|v| (*v - poly[0]).length_squared()).fold(0.0, f64::max).sqrt();
    let height = poly_normal.dot(x - poly[0]);
    if height <= COPLANAR_REL_EPS * size {
        return 0.0;
    }
    let mut buf = [DVec3::ZERO; MAX_CLIPPED];
    let m = clip_to_halfspace(poly, x, n, &mut buf);
    if m < 3 {
        return 0.0;
    }
    point_polygon_unclipped(x, n, &buf[..m]).clamp(0.0, 1.0)
}

/// Lambert's formula without clipping or facing checks: `(1/2π) Σ θ_i (n · γ̂_i)` with
/// `γ̂_i = (R_i × R_{i+1}) / |R_i × R_{i+1}|` and `R_i = v_i − x`. Positive when the polygon is CCW
/// as seen from `x` (i.e. its front faces `x`) and in front of `x`'s tangent plane.
#[must_use]
pub fn point_polygon_unclipped(x: DVec3, n: DVec3, poly: &[DVec3]) -> f64 {
    let m = poly.len();
    let mut sum = 0.0;
    for i in 0..m {
        let a = poly[i] - x;
        let b = poly[(i + 1) % m] - x;
        let c = b.cross(a);
        let len = c.length();
        if len == 0.0 {
            continue;
        }
        let d = a.dot(b);
        let theta = if d > 0.0 {
            (len / d).atan()
        } else if d < 0.0 {
            std::f64::consts::PI - (len / -d).atan()
        } else {
            std::f64::consts::FRAC_PI_2
        };
        sum += theta * n.dot(c) / len;
    }
    sum / (2.0 * std::f64::consts::PI)
}

/// Sutherland–Hodgman clip of `poly` to the closed half-space `n · (y − x) ≥ 0`; writes the result
/// into `out` and returns its vertex count.
pub fn clip_to_halfspace(poly: &[DVec3], x: DVec3, n: DVec3, out: &mut [DVec3; MAX_CLIPPED]) -> usize {
    let mut count = 0;
    let m = poly.len();
    let d: [f64; 4] = std::array::from_fn(|i| if i < m { n.dot(poly[i] - x) } else { 0.0 });
    for i in 0..m {
        let j = (i + 1) % m;
        let (di, dj) = (d[i], d[j]);
        if di >= 0.0 && count < MAX_CLIPPED {
            out[count] = poly[i];
            count += 1;
        }
        if (di >= 0.0) != (dj >= 0.0) {
            let t = di / (di - dj);
            if count < MAX_CLIPPED {
                out[count] = poly[i] + t * (poly[j] - poly[i]);
                count += 1;
            }
        }
    }
    count
}

/// How much the transfer kernel `cos θ_x cos θ_y / r²` from point `x` (normal `n`) varies over a
/// surface (unit `normal`, `center`, `vertices`): `(max − min) / (max + min)` over its centre and
/// vertices, 1 where part of it is behind the point's tangent plane or faces away. The share of a
/// non-uniform radiosity over the surface that `x` sees beyond the surface's mean (0: a far surface
/// is seen as its mean; 1: its shape shows whole).
#[must_use]
pub fn kernel_variation(x: DVec3, n: DVec3, normal: DVec3, center: DVec3, vertices: &[DVec3]) -> f64 {
    let k = |y: DVec3| {
        let v = y - x;
        let d2 = v.length_squared();
        if d2 > 0.0 { n.dot(v).max(0.0) * (-normal.dot(v)).max(0.0) / (d2 * d2) } else { 0.0 }
    };
    let (lo, hi) =
        std::iter::once(center).chain(vertices.iter().copied()).map(k).fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if hi > 0.0 { ((hi - lo) / (hi + lo)).min(1.0) } else { 1.0 }
}
