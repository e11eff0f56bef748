//! The direct light's quadrature error per polygon, and the leaves it asks to split.

use super::means::polygon_direct_means;
use crate::hierarchy::Hierarchy;

/// Per input polygon and channel, the error of its mean direct irradiance that the leaves'
/// quadrature leaves ([`Hierarchy::direct_error`], W/m² or lx): the larger of the area-weighted
/// sum of the leaves' errors (what a shadow edge misplaces the same way all along it) and their
/// root sum of squares (what varies in sign from leaf to leaf), over the polygon's area. Empty
/// without luminaires or distant sources.
#[must_use]
pub fn direct_polygon_errors(h: &Hierarchy) -> Vec<[f64; 3]> {
    if h.direct_error.is_empty() {
        return Vec::new();
    }
    let mut sums = vec![([0.0; 3], [0.0; 3], 0.0); h.n_polygons as usize];
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let Some(p) = e.polygon() else { continue };
        let s = &mut sums[p as usize];
        s.2 += e.area;
        let Some(d) = h.direct_error.get(leaf as usize) else { continue };
        for c in 0..3 {
            s.0[c] += e.area * d[c];
            s.1[c] += (e.area * d[c]).powi(2);
        }
    }
    sums.into_iter()
        .map(|(sum, squares, a)| if a > 0.0 { std::array::from_fn(|c| sum[c].abs().max(squares[c].sqrt()) / a) } else { [0.0; 3] })
        .collect()
}

/// Below this share of the brightest polygon's mean direct irradiance, a polygon's direct error
/// is held to this share instead of to its own mean ([`direct_splits`]): a wall the light
/// grazes is not refined to its own faint light's precision.
pub const DIRECT_FLOOR_REL: f64 = 1e-2;

/// The leaves to split (or to sample finer where they cannot be split) so that every polygon's
/// mean direct irradiance meets `tolerance`: those
/// with a quadrature error ([`Hierarchy::direct_error`]) on a polygon whose error
/// ([`direct_polygon_errors`]) exceeds `tolerance` times its own mean direct irradiance (at
/// least [`DIRECT_FLOOR_REL`] of the largest polygon's), in the largest channel, times the
/// polygon's entry of `polygon_factor` (1 where it has none). Empty without luminaires or distant
/// sources.
#[must_use]
pub fn direct_splits(h: &Hierarchy, tolerance: f64, polygon_factor: &[f64]) -> Vec<u32> {
    let errors = direct_polygon_errors(h);
    if errors.is_empty() {
        return Vec::new();
    }
    let means = polygon_direct_means(h);
    let top = means.iter().flatten().copied().fold(0.0, f64::max);
    let over: Vec<bool> = (errors.iter().zip(&means).enumerate())
        .map(|(p, (e, m))| {
            let tolerance = tolerance * polygon_factor.get(p).copied().unwrap_or(1.0);
            (0..3).any(|c| e[c] > tolerance * m[c].max(DIRECT_FLOOR_REL * top))
        })
        .collect();
    if !over.iter().any(|&o| o) {
        return Vec::new();
    }
    h.leaves()
        .filter(|&l| {
            let e = h.get(l);
            e.polygon().is_some_and(|p| over[p as usize]) && h.direct_error.get(l as usize).is_some_and(|d| d.iter().any(|&v| v != 0.0))
        })
        .collect()
}
