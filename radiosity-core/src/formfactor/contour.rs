//! Polygon-to-polygon form factor by Stokes' double contour integral (Sparrow 1963):
//!
//! `F(1→2) = 1/(2π A1) Σ_i Σ_j (e_i · e_j) ∫₀¹∫₀¹ ln |a_i + s e_i − b_j − t e_j| ds dt`
//!
//! over the edges `a_i → a_i + e_i` of P1 and `b_j → b_j + e_j` of P2, both wound counter-clockwise
//! about their front normals, fronts facing each other. Parallel edge pairs (including the collinear
//! pair of a shared edge, where `ln r` is singular) are integrated in closed form; other pairs
//! integrate the inner integral exactly and the outer one by adaptive Gauss–Legendre, graded toward
//! the logarithmic singularity where the edges meet (a shared vertex, or a touching line). Formulas as in the project's
//! `reference/formfactors.md` (e).
//!
//! It gives the *unoccluded* form factor of polygons that lie wholly in front of each other. For
//! touching pairs (a wall meeting the floor) it replaces receiver quadrature, whose error at the shared
//! edge the stiff cases amplify by ρ/(1−ρ). Small, far pairs lose precision (cancellation), so callers
//! use it for near pairs only.

use crate::geom::DVec3;
use std::f64::consts::PI;

/// Edges closer to parallel than this (sine of the angle) use the parallel closed form.
pub const PARALLEL_SIN_TOL: f64 = 1e-9;
/// Relative tolerance of the adaptive outer integral.
pub const OUTER_REL_TOL: f64 = 1e-9;
/// Edges shorter than this (in the normalised frame, where the pair spans 1) are dropped.
pub const MIN_EDGE: f64 = 1e-9;
/// Deepest bisection of the outer integral.
pub const OUTER_MAX_DEPTH: u32 = 20;

/// `F(1→2)` for planar polygons `p1`, `p2` (counter-clockwise about their front normals, fronts facing).
#[must_use]
pub fn polygon_polygon(p1: &[DVec3], p2: &[DVec3]) -> f64 {
    let a1 = polygon_area(p1);
    if a1 <= 0.0 {
        return 0.0;
    }
    // Work relative to a common origin and scale: ln r's additive constant cancels on closed
    // contours, so scaling only improves conditioning.
    let origin = p1[0];
    let scale = p1.iter().chain(p2).map(|v| (*v - origin).length()).fold(0.0, f64::max);
    if scale <= 0.0 {
        return 0.0;
    }
    let norm = |v: &DVec3| (*v - origin) / scale;
    let q1: Vec<DVec3> = p1.iter().map(norm).collect();
    let q2: Vec<DVec3> = p2.iter().map(norm).collect();
    let mut sum = 0.0;
    for i in 0..q1.len() {
        let (a, ea) = (q1[i], q1[(i + 1) % q1.len()] - q1[i]);
        for j in 0..q2.len() {
            let (b, eb) = (q2[j], q2[(j + 1) % q2.len()] - q2[j]);
            sum += edge_pair(a, ea, b, eb);
        }
    }
    sum / (2.0 * PI * (a1 / (scale * scale)))
}

/// Area of a planar polygon.
pub(crate) fn polygon_area(p: &[DVec3]) -> f64 {
    let mut n = DVec3::ZERO;
    for i in 1..p.len().saturating_sub(1) {
        n += (p[i] - p[0]).cross(p[i + 1] - p[0]);
    }
    0.5 * n.length()
}

/// `(e_a · e_b) ∫₀¹∫₀¹ ln |a + s e_a − b − t e_b| ds dt`.
fn edge_pair(a: DVec3, ea: DVec3, b: DVec3, eb: DVec3) -> f64 {
    let dot = ea.dot(eb);
    let (la, lb) = (ea.length(), eb.length());
    if la <= MIN_EDGE || lb <= MIN_EDGE || dot.abs() <= 1e-15 * la * lb {
        // Perpendicular edges contribute nothing; a vanishing edge contributes at most
        // `ℓ·|ln r|`, and its integrand would be rounding noise.
        return 0.0;
    }
    if ea.cross(eb).length() <= PARALLEL_SIN_TOL * la * lb {
        return parallel_pair(a, ea, b, eb);
    }
    dot * outer_integral(a, ea, b, eb)
}

/// Closed form for parallel or antiparallel edges.
fn parallel_pair(a: DVec3, ea: DVec3, b: DVec3, eb: DVec3) -> f64 {
    let u = ea / ea.length();
    let d = b - a;
    let h = (d - d.dot(u) * u).length();
    let (a0, a1) = (0.0, ea.length());
    let (b0, b1) = (d.dot(u), d.dot(u) + eb.dot(u));
    let psi = |w: f64| -> f64 {
        if h <= 1e-14 {
            if w == 0.0 { 0.0 } else { 0.5 * w * w * w.abs().ln() - 0.75 * w * w }
        } else {
            0.25 * (w * w - h * h) * (w * w + h * h).ln() - 0.75 * w * w + h * w * (w / h).atan()
        }
    };
    -(psi(a1 - b1) - psi(a1 - b0) - psi(a0 - b1) + psi(a0 - b0))
}

/// Edges shorter than this fraction of their distance from the point are integrated by
/// Gauss–Legendre in [`inner`]: its closed form divides by the squared edge length and cancels
/// catastrophically for short edges (an edge 1e-9 long, 0.9 away, left 1e-8 of noise, which the
/// outer integral's adaptive bisection then chased to its depth limit: office2's refinement
/// spent 95% of its time there). Below this ratio the integrand `ln|w + t e|` has its nearest
/// complex singularity at least 1/ratio away from `[0, 1]`, and 8 Gauss–Legendre points are exact
/// to rounding (error of order ratio^16).
pub const SHORT_EDGE_RATIO: f64 = 0.25;

/// `∫₀¹ ln |p − b − t e| dt`, exactly (in closed form, or by quadrature for an edge short
/// compared with its distance, see [`SHORT_EDGE_RATIO`]).
fn inner(p: DVec3, b: DVec3, e: DVec3) -> f64 {
    let w = b - p;
    let qa = e.length_squared();
    let qc = w.length_squared();
    if qa < SHORT_EDGE_RATIO * SHORT_EDGE_RATIO * qc {
        return GL8.iter().map(|&(x, wt)| wt * 0.5 * (w + x * e).length_squared().ln()).sum();
    }
    let qb = 2.0 * e.dot(w);
    let disc = 4.0 * qa * qc - qb * qb;
    let scale = qa * qc;
    if disc <= 1e-14 * scale.max(f64::MIN_POSITIVE) {
        // p on the edge's line: q = a (t − t0)².
        let t0 = -qb / (2.0 * qa);
        let g = |t: f64| {
            let x = t - t0;
            let xl = if x == 0.0 { 0.0 } else { x * x.abs().ln() };
            t * qa.ln() + 2.0 * (xl - x)
        };
        return 0.5 * (g(1.0) - g(0.0));
    }
    let d = disc.sqrt();
    let g = |t: f64| {
        let q = (qa * t + qb) * t + qc;
        let ql = if q > 0.0 { q.ln() } else { 0.0 };
        (t + qb / (2.0 * qa)) * ql - 2.0 * t + (d / qa) * ((2.0 * qa * t + qb) / d).atan()
    };
    0.5 * (g(1.0) - g(0.0))
}

/// 8-point Gauss–Legendre nodes and weights on [0, 1].
const GL8: [(f64, f64); 8] = {
    const X: [f64; 4] = [0.183_434_642_495_649_8, 0.525_532_409_916_329, 0.796_666_477_413_626_7, 0.960_289_856_497_536_3];
    const W: [f64; 4] = [0.362_683_783_378_362, 0.313_706_645_877_887_3, 0.222_381_034_453_374_5, 0.101_228_536_290_376_3];
    [
        (0.5 - 0.5 * X[3], 0.5 * W[3]),
        (0.5 - 0.5 * X[2], 0.5 * W[2]),
        (0.5 - 0.5 * X[1], 0.5 * W[1]),
        (0.5 - 0.5 * X[0], 0.5 * W[0]),
        (0.5 + 0.5 * X[0], 0.5 * W[0]),
        (0.5 + 0.5 * X[1], 0.5 * W[1]),
        (0.5 + 0.5 * X[2], 0.5 * W[2]),
        (0.5 + 0.5 * X[3], 0.5 * W[3]),
    ]
};

/// Distance (in the normalised frame, where the pair spans about 1) from edge `b` under which the
/// outer integrand counts as (nearly) log-singular at the closest point of edge `a`, and the outer
/// integral is graded toward that point.
pub const GRADE_DISTANCE: f64 = 0.1;
/// Power of the grading substitution `s = s* ± (…)·u^GRADE_POWER`: it turns the logarithmic
/// singularity `ln|s − s*|` into `u^(p−1) ln u`, smooth enough for Gauss–Legendre panels.
pub const GRADE_POWER: i32 = 3;

/// `∫₀¹ g(u) du` by adaptive bisection of 8-point Gauss–Legendre panels.
fn adaptive(g: &dyn Fn(f64) -> f64) -> f64 {
    fn panel(g: &dyn Fn(f64) -> f64, u0: f64, u1: f64) -> f64 {
        let len = u1 - u0;
        GL8.iter().map(|&(x, w)| w * g(u0 + x * len)).sum::<f64>() * len
    }
    fn rec(g: &dyn Fn(f64) -> f64, u0: f64, u1: f64, whole: f64, depth: u32) -> f64 {
        let m = 0.5 * (u0 + u1);
        let (l, r) = (panel(g, u0, m), panel(g, m, u1));
        let fine = l + r;
        if depth == 0 || (fine - whole).abs() <= OUTER_REL_TOL * fine.abs().max(1e-3 * (u1 - u0)) {
            return fine;
        }
        rec(g, u0, m, l, depth - 1) + rec(g, m, u1, r, depth - 1)
    }
    let whole = panel(g, 0.0, 1.0);
    rec(g, 0.0, 1.0, whole, OUTER_MAX_DEPTH)
}

/// Parameter `s ∈ [0, 1]` of the point of segment `a + s·ea` closest to segment `b + t·eb`, and
/// the distance there.
fn closest_on_a(a: DVec3, ea: DVec3, b: DVec3, eb: DVec3) -> (f64, f64) {
    let r = a - b;
    let (aa, bb, ab) = (ea.length_squared(), eb.length_squared(), ea.dot(eb));
    let (ar, br) = (ea.dot(r), eb.dot(r));
    let den = aa * bb - ab * ab;
    let mut s = if den > 0.0 { ((ab * br - ar * bb) / den).clamp(0.0, 1.0) } else { 0.0 };
    let t = ((ab * s + br) / bb).clamp(0.0, 1.0);
    s = ((ab * t - ar) / aa).clamp(0.0, 1.0);
    let t = ((ab * s + br) / bb).clamp(0.0, 1.0);
    (s, (a + s * ea - b - t * eb).length())
}

/// `∫₀¹ inner(a + s e_a) ds`. Where edge `a` passes close to edge `b` (edges sharing a vertex, or
/// meeting on the line where two polygons touch), the integrand is log-singular at the closest
/// point `s*`; the integral is split there and each side graded toward it by `s = s* ± ℓ·u³`.
fn outer_integral(a: DVec3, ea: DVec3, b: DVec3, eb: DVec3) -> f64 {
    let f = |s: f64| inner(a + s * ea, b, eb);
    let (s_star, dist) = closest_on_a(a, ea, b, eb);
    if dist > GRADE_DISTANCE * ea.length().max(eb.length()) {
        return adaptive(&f);
    }
    let p = f64::from(GRADE_POWER);
    let mut sum = 0.0;
    for (len, sign) in [(s_star, -1.0), (1.0 - s_star, 1.0)] {
        if len > 0.0 {
            sum += adaptive(&|u: f64| f(s_star + sign * len * u.powi(GRADE_POWER)) * p * len * u.powi(GRADE_POWER - 1));
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    // Values from reference/formfactors.md (b), (c), (e).
    #[test]
    fn parallel_unit_squares() {
        let p1 = [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)];
        let p2 = [v(0., 0., 1.), v(0., 1., 1.), v(1., 1., 1.), v(1., 0., 1.)];
        let f = polygon_polygon(&p1, &p2);
        assert!((f - 0.199_824_895_698_387).abs() < 1e-12, "{f}");
    }

    #[test]
    fn perpendicular_unit_squares_sharing_an_edge() {
        let p1 = [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)];
        let p2 = [v(0., 0., 0.), v(0., 1., 0.), v(0., 1., 1.), v(0., 0., 1.)];
        let f = polygon_polygon(&p1, &p2);
        assert!((f - 0.200_043_776_075_403).abs() < 1e-12, "{f}");
    }

    /// Midpoint rule over an n×n grid of a parallelogram `o + u·x + v·y` of the point-to-polygon
    /// formula: an independent route for smooth (non-touching) pairs.
    fn brute(o: DVec3, u: DVec3, w: DVec3, p2: &[DVec3], n2: DVec3) -> f64 {
        let n = 400;
        let normal = u.cross(w).normalize();
        let mut acc = 0.0;
        for i in 0..n {
            for j in 0..n {
                let x = o + u * ((i as f64 + 0.5) / n as f64) + w * ((j as f64 + 0.5) / n as f64);
                acc += crate::formfactor::point_polygon(x, normal, p2, n2);
            }
        }
        acc / (n * n) as f64
    }

    #[test]
    fn offset_and_tilted_pairs_match_receiver_quadrature() {
        // Offset parallel rectangles.
        let p1 = [v(0.2, -0.3, 0.), v(1.7, -0.3, 0.), v(1.7, 0.4, 0.), v(0.2, 0.4, 0.)];
        let p2 = [v(-0.4, 0.1, 0.8), v(-0.4, 1.0, 0.8), v(0.9, 1.0, 0.8), v(0.9, 0.1, 0.8)];
        let f = polygon_polygon(&p1, &p2);
        let g = brute(p1[0], p1[1] - p1[0], p1[3] - p1[0], &p2, -DVec3::Z);
        assert!((f - g).abs() < 1e-5 * g, "contour {f} vs quadrature {g}");
        // A tilted triangle above the rectangle (skew edge pairs).
        let tri = [v(0.3, 0.0, 1.0), v(1.2, 0.9, 1.4), v(1.5, -0.2, 0.9)];
        let n2 = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
        assert!(n2.z < 0.0, "triangle must face down");
        let f = polygon_polygon(&p1, &tri);
        let g = brute(p1[0], p1[1] - p1[0], p1[3] - p1[0], &tri, n2);
        assert!((f - g).abs() < 1e-5 * g, "contour {f} vs quadrature {g}");
    }

    #[test]
    fn unit_cube_rows_sum_to_one_including_triangles() {
        // A unit cube's floor split into two triangles: each triangle's form factors to the five
        // other faces sum to 1 (skew edge pairs and shared vertices exercise the outer quadrature).
        let t1 = [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.)];
        let faces = [
            [v(0., 0., 1.), v(0., 1., 1.), v(1., 1., 1.), v(1., 0., 1.)],
            [v(0., 0., 0.), v(0., 1., 0.), v(0., 1., 1.), v(0., 0., 1.)],
            [v(1., 0., 0.), v(1., 0., 1.), v(1., 1., 1.), v(1., 1., 0.)],
            [v(0., 0., 0.), v(0., 0., 1.), v(1., 0., 1.), v(1., 0., 0.)],
            [v(0., 1., 0.), v(1., 1., 0.), v(1., 1., 1.), v(0., 1., 1.)],
        ];
        let sum: f64 = faces.iter().map(|f| polygon_polygon(&t1, f)).sum();
        // The other floor triangle is coplanar (F = 0).
        assert!((sum - 1.0).abs() < 1e-9, "{sum}");
    }

    #[test]
    fn a_vanishing_edge_changes_nothing() {
        // Clipping a polygon at a vertex lying on the plane repeats that vertex up to rounding; the
        // edge of length ~1e-15 between the copies must neither change F nor stall the quadrature.
        let p1 = [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)];
        let p2 = [v(0., 0., 0.), v(0.3, 1., 0.), v(0.3, 1., 1.), v(0., 0., 1.)];
        let mut p2_rep = p2.to_vec();
        p2_rep.insert(1, v(1e-15, 3e-15, 0.));
        let (f, g) = (polygon_polygon(&p1, &p2), polygon_polygon(&p1, &p2_rep));
        assert!(f > 0.0 && (f - g).abs() < 1e-12, "{f} vs {g}");
    }

    /// `∫₀¹ f` by 64 Gauss–Legendre panels: exact to rounding for a smooth integrand.
    fn by_panels(f: impl Fn(f64) -> f64) -> f64 {
        let n = 64;
        (0..n).flat_map(|k| GL8.iter().map(move |&(x, w)| ((k as f64 + x) / n as f64, w / n as f64))).map(|(t, w)| w * f(t)).sum()
    }

    /// `∫₀¹ ln|p − b − t e| dt` by [`by_panels`].
    fn inner_by_panels(p: DVec3, b: DVec3, e: DVec3) -> f64 {
        by_panels(|t| (p - b - t * e).length().ln())
    }

    #[test]
    fn short_edges_integrate_without_cancellation() {
        // An edge 2.3e-9 long, 0.9 from the point (the office2 pair that stalled the outer
        // quadrature): the closed form would cancel to ~1e-8; the quadrature branch is exact.
        let (a, b) = (v(0.0, 0.0, 0.0), v(0.341_682, 0.350_363, 0.872_066));
        let e = v(-5.05e-10, 1.38e-10, -2.26e-9);
        let exact = inner_by_panels(a, b, e);
        assert!((inner(a, b, e) - exact).abs() < 1e-14, "{} vs {exact}", inner(a, b, e));
        // Both branches agree on either side of the switch.
        let w = b - a;
        for ratio in [0.9 * SHORT_EDGE_RATIO, 1.1 * SHORT_EDGE_RATIO, 0.5, 2.0] {
            let e = v(0.3, -0.8, 0.2).normalize() * (ratio * w.length());
            let exact = inner_by_panels(a, b, e);
            assert!((inner(a, b, e) - exact).abs() < 1e-12, "ratio {ratio}: {} vs {exact}", inner(a, b, e));
        }
    }

    #[test]
    fn the_outer_quadrature_of_a_short_edge_converges_in_few_panels() {
        use std::cell::Cell;
        // Edge b is 2.3e-9 long; edge a is an ordinary polygon edge. Before the quadrature branch,
        // the integrand's noise sent adaptive bisection to its depth limit (894,905 splits).
        let (a, ea) = (v(0.0, 0.0, 0.0), v(0.146_836, 0.403_435, 0.0));
        let (b, eb) = (v(0.341_682, 0.350_363, 0.872_066), v(-5.05e-10, 1.38e-10, -2.26e-9));
        let calls = Cell::new(0u32);
        let value = adaptive(&|s: f64| {
            calls.set(calls.get() + 1);
            inner(a + s * ea, b, eb)
        });
        assert!(calls.get() < 1_000, "{} integrand calls", calls.get());
        let exact = by_panels(|s| inner_by_panels(a + s * ea, b, eb));
        assert!((value - exact).abs() < 1e-13, "{value} vs {exact}");
    }
}
