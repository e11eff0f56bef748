//! Directional proxies: the light a proxy box intercepts through one face and sends out through
//! the others ([`ProxyEmission::Directional`](super::ProxyEmission::Directional)).
//!
//! In the local problem a proxy face `j` reflects its own irradiance with the diagonal entry
//! `T[j][j]` of its prototype's face transfer matrix as reflectance; what the other faces `i` of
//! the same box intercept and send out through `j`, `Σᵢ T[i][j]·Hᵢ·Aᵢ / Aⱼ`, is added to its
//! emission (a linear solve cannot couple two polygons other than by links). Below the top the
//! irradiance `Hᵢ` is the light from outside (the beams, known before the solve, so the refinement
//! sees it too); at the top, where the lamps' light reaches the proxies by links, it is the
//! irradiance of a first solve, and the level is solved again with it.

use super::level::Level;
use super::sink::collect_leaves;
use crate::geom::Poly;
use crate::hierarchy::ElementId;
use crate::instancing::face_transfer::BOX_FACES;
use crate::solve::Solution;

/// The cross-face terms of a level's proxies: per proxy face `j` (polygon index), the other faces
/// `i` of its box with their coefficients `T[i][j]·Aᵢ / Aⱼ` per channel.
#[derive(Default)]
pub(super) struct CrossTerms {
    rows: Vec<CrossRow>,
}

/// A proxy face (polygon index) and the other faces of its box with their coefficients.
type CrossRow = (u32, [(u32, [f64; 3]); BOX_FACES - 1]);

impl CrossTerms {
    /// The terms of the boxes whose faces are `faces[slot] = polygon index per face` (a box whose
    /// faces did not each become one polygon is left out, uniform), with transfer matrices
    /// `transfer(slot)` (row-major, entry face first).
    pub(super) fn new(
        polys: &[Poly],
        faces: &[Option<[u32; BOX_FACES]>],
        transfer: impl Fn(usize) -> [[f64; 3]; BOX_FACES * BOX_FACES],
    ) -> CrossTerms {
        let mut rows = Vec::new();
        for (slot, box_faces) in faces.iter().enumerate() {
            let Some(box_faces) = box_faces else { continue };
            let t = transfer(slot);
            let area = |f: usize| polys.get(box_faces[f] as usize).map_or(0.0, Poly::area);
            for j in 0..BOX_FACES {
                let a_j = area(j);
                if a_j.is_nan() || a_j <= 0.0 {
                    continue;
                }
                let mut from = [(0u32, [0.0; 3]); BOX_FACES - 1];
                for (k, i) in (0..BOX_FACES).filter(|&i| i != j).enumerate() {
                    let ratio = area(i) / a_j;
                    from[k] = (box_faces[i], t[i * BOX_FACES + j].map(|x| if ratio.is_finite() { x * ratio } else { 0.0 }));
                }
                rows.push((box_faces[j], from));
            }
        }
        CrossTerms { rows }
    }

    /// True when no proxy face takes light from another.
    pub(super) fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Approximate heap bytes.
    pub(super) fn bytes(&self) -> usize {
        self.rows.len() * std::mem::size_of::<CrossRow>()
    }

    /// Adds to `emission` (per polygon) each proxy face's cross-face emission, from the
    /// irradiance `irradiance(i)` of the other faces of its box, times `scale`.
    pub(super) fn add_emission(&self, emission: &mut [[f64; 3]], irradiance: impl Fn(usize) -> [f64; 3], scale: f64) {
        for (j, from) in &self.rows {
            let mut e = [0.0; 3];
            for (i, coef) in from {
                let h = irradiance(*i as usize);
                for c in 0..3 {
                    e[c] += coef[c] * h[c];
                }
            }
            if let Some(out) = emission.get_mut(*j as usize) {
                for c in 0..3 {
                    out[c] += scale * e[c];
                }
            }
        }
    }
}

/// Mean irradiance over the leaves of polygon `i` of a solved `level` (the light from outside
/// excluded).
pub(super) fn polygon_irradiance(level: &Level, solution: &Solution, i: usize) -> [f64; 3] {
    let (mut acc, mut area) = ([0.0; 3], 0.0);
    collect_leaves(&level.h, i as ElementId, &mut |e| {
        let a = level.h.get(e).area;
        let irr = solution.irradiance.get(e as usize).copied().unwrap_or([0.0; 3]);
        for c in 0..3 {
            acc[c] += a * irr[c];
        }
        area += a;
    });
    acc.map(|v| if area > 0.0 { v / area } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::DVec3;
    use crate::scene::shapes::box_faces;

    #[test]
    fn light_entering_the_top_leaves_by_the_bottom_in_the_transfer_fraction() {
        // A 2 × 1 × 1 box: the x faces have area 1, the others 2.
        let polys: Vec<Poly> =
            box_faces(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0), false).into_iter().map(|(_, q)| Poly::quad(q[0], q[1], q[2], q[3])).collect();
        let mut t = [[0.0; 3]; BOX_FACES * BOX_FACES];
        t[5 * BOX_FACES + 4] = [0.2, 0.3, 0.1]; // top (z+) to bottom (z−)
        t[5 * BOX_FACES] = [0.1; 3]; // top to x− (half the area)
        let cross = CrossTerms::new(&polys, &[Some([0, 1, 2, 3, 4, 5]), None], |_| t);
        assert!(!cross.is_empty());
        let mut emission = vec![[0.0; 3]; 6];
        cross.add_emission(&mut emission, |i| if i == 5 { [1.0; 3] } else { [0.0; 3] }, 1.0);
        assert_eq!(emission[4], [0.2, 0.3, 0.1]);
        assert_eq!(emission[0], [0.2; 3], "twice the flux density on a face of half the area");
        assert_eq!(emission[5], [0.0; 3], "the diagonal is the face's reflectance, not emission");
        assert!(CrossTerms::new(&polys, &[None], |_| t).is_empty());
    }
}
