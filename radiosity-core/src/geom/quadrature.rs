//! Quadrature rules over triangles and quads in the polygons' parameter space.

/// A rule: points `(s, t)` in parameter space and weights summing to 1 (relative to the area).
pub struct Rule {
    /// Parameter-space points.
    pub points: &'static [(f64, f64)],
    /// Weights, summing to 1.
    pub weights: &'static [f64],
}

const G2A: f64 = 0.211_324_865_405_187_1; // (1 - 1/sqrt 3) / 2
const G2B: f64 = 0.788_675_134_594_812_9;

/// Centroid rule for quads (1 point).
pub const QUAD_1: Rule = Rule { points: &[(0.5, 0.5)], weights: &[1.0] };
/// 2x2 Gauss rule for quads (exact for bicubics on parallelograms).
pub const QUAD_4: Rule = Rule { points: &[(G2A, G2A), (G2B, G2A), (G2B, G2B), (G2A, G2B)], weights: &[0.25; 4] };

const G3: [f64; 3] = [0.112_701_665_379_258_3, 0.5, 0.887_298_334_620_741_7];
const W3: [f64; 3] = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];
macro_rules! gauss3x3 {
    () => {
        [
            (G3[0], G3[0]),
            (G3[1], G3[0]),
            (G3[2], G3[0]),
            (G3[0], G3[1]),
            (G3[1], G3[1]),
            (G3[2], G3[1]),
            (G3[0], G3[2]),
            (G3[1], G3[2]),
            (G3[2], G3[2]),
        ]
    };
}
/// 3x3 Gauss rule for quads.
pub const QUAD_9: Rule = Rule {
    points: &gauss3x3!(),
    weights: &[
        W3[0] * W3[0],
        W3[1] * W3[0],
        W3[2] * W3[0],
        W3[0] * W3[1],
        W3[1] * W3[1],
        W3[2] * W3[1],
        W3[0] * W3[2],
        W3[1] * W3[2],
        W3[2] * W3[2],
    ],
};

/// Centroid rule for triangles (1 point).
pub const TRI_1: Rule = Rule { points: &[(1.0 / 3.0, 1.0 / 3.0)], weights: &[1.0] };
/// 3-point rule for triangles, degree 2 (interior points).
pub const TRI_3: Rule =
    Rule { points: &[(1.0 / 6.0, 1.0 / 6.0), (2.0 / 3.0, 1.0 / 6.0), (1.0 / 6.0, 2.0 / 3.0)], weights: &[1.0 / 3.0; 3] };

const T6A: f64 = 0.445_948_490_915_965;
const T6B: f64 = 0.091_576_213_509_771;
const T6WA: f64 = 0.223_381_589_678_011;
const T6WB: f64 = 0.109_951_743_655_322;
/// 6-point rule for triangles, degree 4 (Dunavant).
pub const TRI_6: Rule = Rule {
    points: &[(T6A, T6A), (1.0 - 2.0 * T6A, T6A), (T6A, 1.0 - 2.0 * T6A), (T6B, T6B), (1.0 - 2.0 * T6B, T6B), (T6B, 1.0 - 2.0 * T6B)],
    weights: &[T6WA, T6WA, T6WA, T6WB, T6WB, T6WB],
};

/// The points of `rule` on `poly` with their weights: the rule's weights times the local Jacobian
/// of the bilinear map on quads (so non-parallelograms integrate correctly), the rule's weights on
/// triangles. Divide by the weights' sum for a mean.
pub fn weighted_points<'a>(poly: &'a crate::geom::Poly, rule: &'a Rule) -> impl Iterator<Item = (glam::DVec3, f64)> + 'a {
    rule.points.iter().zip(rule.weights).map(move |(&(u, v), &w)| match poly.kind {
        crate::geom::PolyKind::Quad => {
            let du = (1.0 - v) * (poly.v[1] - poly.v[0]) + v * (poly.v[2] - poly.v[3]);
            let dv = (1.0 - u) * (poly.v[3] - poly.v[0]) + u * (poly.v[2] - poly.v[1]);
            (poly.point(u, v), w * du.cross(dv).length())
        }
        crate::geom::PolyKind::Triangle => (poly.point(u, v), w),
    })
}

/// The quadrature rule of a surface element: 9 points on quads, 6 on triangles.
pub(crate) fn element_rule(poly: &crate::geom::Poly) -> &'static Rule {
    match poly.kind {
        crate::geom::PolyKind::Quad => &QUAD_9,
        crate::geom::PolyKind::Triangle => &TRI_6,
    }
}

/// The mean of `f` per channel over a surface element by its [`element_rule`].
pub(crate) fn element_mean3(poly: &crate::geom::Poly, mut f: impl FnMut(glam::DVec3) -> [f64; 3]) -> [f64; 3] {
    let (mut sum, mut wsum) = ([0.0; 3], 0.0);
    for (x, w) in weighted_points(poly, element_rule(poly)) {
        let v = f(x);
        for c in 0..3 {
            sum[c] += w * v[c];
        }
        wsum += w;
    }
    if wsum > 0.0 { sum.map(|s| s / wsum) } else { [0.0; 3] }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one() {
        for r in [&QUAD_1, &QUAD_4, &QUAD_9, &TRI_1, &TRI_3, &TRI_6] {
            let s: f64 = r.weights.iter().sum();
            assert!((s - 1.0).abs() < 1e-12, "{s}");
            assert_eq!(r.points.len(), r.weights.len());
        }
    }

    #[test]
    fn tri6_integrates_quartic() {
        // ∫ s^2 t^2 over the unit triangle / area(1/2) = 2 * 2!2!/6! = 2 * 4/720.
        let exact = 2.0 * 4.0 / 720.0;
        let got: f64 = TRI_6.points.iter().zip(TRI_6.weights).map(|(&(s, t), w)| w * s * s * t * t).sum();
        assert!((got - exact).abs() < 1e-10, "{got} vs {exact}");
    }
}
