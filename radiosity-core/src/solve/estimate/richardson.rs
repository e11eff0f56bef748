//! The mesh's error: the same solve on meshes one and two levels coarser, the polygon means
//! extrapolated (Richardson) with the order their changes show.

use super::ESTIMATE_SAFETY;

/// Smallest convergence order the Richardson estimate assumes.
pub const ORDER_MIN: f64 = 0.5;
/// Largest convergence order the Richardson estimate assumes.
pub const ORDER_MAX: f64 = 2.0;

/// The most the estimate takes of a polygon's change `|d₁|`, [`ESTIMATE_SAFETY`](super::ESTIMATE_SAFETY) included. Where
/// the order is low or not regular yet ([`ORDER_MIN`], `1/(2^0.5 − 1)` = 2.41) the safety factor
/// would make it 6.3: the lowest order and the margin for a misjudged one, both at once. On the
/// validation scenes at eps 0.64 to 0.000625 (`examples/estimate_orders.rs`, 2026-12-04) the
/// polygon with the largest true error had at most 3.05 times its change `|d₁|` (corner room, ρ
/// 0.95, eps 0.64; where the mesh's error dominates: on CIE 5.8 visibility sampling's does, which
/// [`visibility_noise`](super::visibility_noise) covers); 3.5 keeps 15% above it, and the whole estimate stayed at 1.08 or
/// more times the true error on every row. It makes the coarse levels' estimate 3 to 8 times the
/// true error instead of 4 to 14 (Ward's room: 10.4% and 8.7% for 2.8% and 2.4%), so that a coarse
/// target stops at a coarse level.
pub const CHANGE_FACTOR_MAX: f64 = 3.5;

/// The error of `fine` (polygon means), from the same solve on meshes two (`coarse`) and four
/// (`coarser`) times coarser. For each non-emitting polygon and channel, the changes
/// `d₁ = fine − coarse` and `d₂ = coarse − coarser` give the order `p = log₂(d₂ / d₁)` (within
/// [`ORDER_MIN`, `ORDER_MAX`]; [`ORDER_MIN`] when the changes differ in sign, the convergence not
/// yet regular) and the error still in `fine`, `|d₁| / (2^p − 1)` (at most
/// [`CHANGE_FACTOR_MAX`] / [`ESTIMATE_SAFETY`](super::ESTIMATE_SAFETY) times `|d₁|`). The largest, relative to the largest
/// non-emitting mean.
#[must_use]
pub fn richardson_estimate(emitting: &[bool], fine: &[[f64; 3]], coarse: &[[f64; 3]], coarser: &[[f64; 3]]) -> f64 {
    let all = emitting.iter().all(|&e| e);
    let (mut top, mut worst) = (0.0f64, 0.0f64);
    for (i, &e) in emitting.iter().enumerate() {
        if e && !all {
            continue;
        }
        for c in 0..3 {
            top = top.max(fine[i][c]);
            worst = worst.max(richardson_error(fine[i][c], coarse[i][c], coarser[i][c]));
        }
    }
    if top > 0.0 { worst / top } else { 0.0 }
}

/// The error still in one mean `fine` (see [`richardson_estimate`]).
pub(super) fn richardson_error(fine: f64, coarse: f64, coarser: f64) -> f64 {
    let (d1, d2) = (fine - coarse, coarse - coarser);
    if d1 == 0.0 {
        return 0.0;
    }
    let order = if d2 / d1 > 1.0 { (d2 / d1).log2().clamp(ORDER_MIN, ORDER_MAX) } else { ORDER_MIN };
    d1.abs() * (1.0 / (order.exp2() - 1.0)).min(CHANGE_FACTOR_MAX / ESTIMATE_SAFETY)
}

/// Per polygon (largest channel, absolute), the error [`richardson_estimate`] finds in its mean,
/// and at least what the change between the two coarser meshes leaves at the fastest order
/// ([`ORDER_MAX`]): a polygon whose finest change vanishes by chance (a change of sign) still
/// counts the convergence its coarser change shows.
#[must_use]
pub fn richardson_per_polygon(fine: &[[f64; 3]], coarse: &[[f64; 3]], coarser: &[[f64; 3]]) -> Vec<f64> {
    let fastest = ORDER_MAX.exp2();
    (0..fine.len())
        .map(|i| {
            (0..3)
                .map(|c| {
                    let d2 = (coarse[i][c] - coarser[i][c]).abs();
                    richardson_error(fine[i][c], coarse[i][c], coarser[i][c]).max(d2 / (fastest * (fastest - 1.0)))
                })
                .fold(0.0, f64::max)
        })
        .collect()
}
