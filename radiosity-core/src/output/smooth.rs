//! Smooth radiosity across leaves: each leaf corner gets the mean radiosity of the leaves of the same
//! polygon that touch it, and points inside a leaf interpolate its corners.

use crate::geom::{Poly, PolyKind};
use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::solve::Solution;
use rayon::prelude::*;

/// Parameter offset used to probe the leaves around a corner.
const PROBE: f64 = 1e-7;

/// Corner radiosity of every leaf.
pub struct CornerValues {
    /// Per element: index into `values` (NONE for inner elements).
    slot: Vec<u32>,
    /// Corner values of the leaves (4 per leaf; the 4th unused for triangles).
    values: Vec<[[f64; 3]; 4]>,
}

impl CornerValues {
    /// Computes corner radiosity for every leaf of `h`.
    #[must_use]
    pub fn new(h: &Hierarchy, solution: &Solution) -> CornerValues {
        CornerValues::from_values(h, &solution.radiosity)
    }

    /// Computes corner values for every leaf of `h` from per-element `values` (radiosity,
    /// irradiance, ...), smoothed as the radiosity is.
    #[must_use]
    pub fn from_values(h: &Hierarchy, values: &[[f64; 3]]) -> CornerValues {
        let leaves: Vec<ElementId> = h.leaves().filter(|&e| !h.get(e).is_cluster()).collect();
        let mut slot = vec![NONE; h.len()];
        for (i, &e) in leaves.iter().enumerate() {
            slot[e as usize] = i as u32;
        }
        let values = leaves.par_iter().map(|&e| corner_values(h, values, e)).collect();
        CornerValues { slot, values }
    }

    /// Corner values of leaf `e`.
    #[must_use]
    pub fn corners(&self, e: ElementId) -> Option<&[[f64; 3]; 4]> {
        let s = *self.slot.get(e as usize)?;
        (s != NONE).then(|| &self.values[s as usize])
    }

    /// Interpolated radiosity at parameters `(s, t)` of leaf `e` with geometry `kind`.
    #[must_use]
    pub fn interpolate(&self, e: ElementId, kind: PolyKind, s: f64, t: f64) -> Option<[f64; 3]> {
        let c = self.corners(e)?;
        let s = s.clamp(0.0, 1.0);
        let t = t.clamp(0.0, 1.0);
        Some(std::array::from_fn(|k| match kind {
            PolyKind::Triangle => (1.0 - s - t).max(0.0) * c[0][k] + s * c[1][k] + t * c[2][k],
            PolyKind::Quad => (1.0 - s) * (1.0 - t) * c[0][k] + s * (1.0 - t) * c[1][k] + s * t * c[2][k] + (1.0 - s) * t * c[3][k],
        }))
    }
}

fn corner_values(h: &Hierarchy, values: &[[f64; 3]], leaf: ElementId) -> [[f64; 3]; 4] {
    let e = h.get(leaf);
    let (Some(poly), Some(polygon)) = (e.poly(), e.polygon()) else { return [[0.0; 3]; 4] };
    let root = h.get(polygon).poly().copied().expect("polygon roots are surfaces");
    let mut out = [[0.0; 3]; 4];
    for (k, &v) in poly.vertices().iter().enumerate() {
        let (s, t) = root.param_of_point(v);
        out[k] = around(h, values, &root, polygon, s, t);
    }
    out
}

/// Mean value of the distinct leaves touching parameter point `(s, t)` of polygon `polygon`.
fn around(h: &Hierarchy, values: &[[f64; 3]], root: &Poly, polygon: u32, s: f64, t: f64) -> [f64; 3] {
    let mut seen: [ElementId; 8] = [NONE; 8];
    let mut n = 0;
    let mut acc = [0.0; 3];
    for (ds, dt) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)] {
        let (ps, pt) = (s + ds * PROBE, t + dt * PROBE);
        let inside = match root.kind {
            PolyKind::Quad => (0.0..=1.0).contains(&ps) && (0.0..=1.0).contains(&pt),
            PolyKind::Triangle => ps >= 0.0 && pt >= 0.0 && ps + pt <= 1.0,
        };
        if !inside {
            continue;
        }
        let (leaf, _, _) = h.locate(polygon, ps, pt);
        if seen[..n].contains(&leaf) {
            continue;
        }
        seen[n] = leaf;
        n += 1;
        let b = values[leaf as usize];
        for c in 0..3 {
            acc[c] += b[c];
        }
    }
    if n == 0 {
        let (leaf, _, _) = h.locate(polygon, s.clamp(0.0, 1.0), t.clamp(0.0, 1.0));
        return values[leaf as usize];
    }
    acc.map(|v| v / n as f64)
}
