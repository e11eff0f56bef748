//! Per-polygon results of a solution: each input polygon's area-weighted mean radiosity and
//! irradiance over its leaves, and the power its side absorbs (what `patches.csv` holds, and what
//! the error estimate and the levels compare).

use super::Solution;
use crate::hierarchy::Hierarchy;

/// Area-weighted radiosity and irradiance of one input polygon.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PolygonResult {
    /// Area (scene units²).
    pub area: f64,
    /// Mean radiosity B (W/m²).
    pub b: [f64; 3],
    /// Mean front-side irradiance H (W/m²).
    pub h: [f64; 3],
    /// Power absorbed by the polygon's side, `A·(1 − ρ − t)·H` (W; what is neither reflected nor
    /// transmitted), summed over its leaves.
    pub absorbed: [f64; 3],
}

/// Means over each polygon's leaves, in input order.
#[must_use]
pub fn polygon_results(h: &Hierarchy, solution: &Solution) -> Vec<PolygonResult> {
    let mut out = vec![PolygonResult::default(); h.n_polygons as usize];
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let Some(p) = e.polygon() else { continue };
        let r = &mut out[p as usize];
        r.area += e.area;
        for c in 0..3 {
            r.b[c] += e.area * solution.radiosity[leaf as usize][c];
            r.h[c] += e.area * solution.irradiance[leaf as usize][c];
        }
    }
    for (p, r) in out.iter_mut().enumerate() {
        let (rho, t) = (h.reflectance[p], h.transmittance[p]);
        r.absorbed = std::array::from_fn(|c| (1.0 - rho[c] - t[c]) * r.h[c]);
        if r.area > 0.0 {
            r.b = r.b.map(|v| v / r.area);
            r.h = r.h.map(|v| v / r.area);
        }
    }
    out
}
