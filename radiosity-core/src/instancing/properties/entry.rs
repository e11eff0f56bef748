//! The properties of one prototype as computed and cached: per sampled direction τ, the areas,
//! the albedo and the phase, and the face transfer matrix.

use crate::geom::DVec3;
use crate::instancing::face_transfer::FaceTransfer;
use serde::{Deserialize, Serialize};

/// The properties of one prototype (see the module docs). All per-direction vectors are indexed
/// like `directions`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RadiativeProperties {
    /// Content hash the entry was computed for (hex).
    pub key: String,
    /// Prototype name (informative).
    pub prototype: String,
    /// Local bounding box, smallest corner.
    pub bounds_min: [f64; 3],
    /// Local bounding box, largest corner.
    pub bounds_max: [f64; 3],
    /// Unit directions toward the light.
    pub directions: Vec<[f64; 3]>,
    /// τ(ω) in [0, 1].
    pub transmittance: Vec<f64>,
    /// Projected area of the bounding box, m².
    pub box_area: Vec<f64>,
    /// a(ω) = (1 − τ(ω))·A_box(ω), m².
    pub effective_area: Vec<f64>,
    /// Escape albedo α(ω) per channel, in [0, 1].
    pub albedo: Vec<[f64; 3]>,
    /// P(ω) per channel: outgoing radiosity per unit projected area per unit irradiance.
    pub phase: Vec<[f64; 3]>,
    /// Total surface area of the prototype's polygons, m².
    pub surface_area: f64,
    /// The face transfer matrix of the bounding box, row-major per channel (see
    /// [`super::face_transfer`](crate::instancing::face_transfer)); empty in entries written
    /// before it was measured.
    #[serde(default)]
    pub face_transfer: Vec<[f64; 3]>,
}

impl RadiativeProperties {
    /// Mean of τ over the sampled directions.
    #[must_use]
    pub fn mean_transmittance(&self) -> f64 {
        mean(&self.transmittance)
    }

    /// Mean of a(ω) over the sampled directions, m².
    #[must_use]
    pub fn mean_effective_area(&self) -> f64 {
        mean(&self.effective_area)
    }

    /// Area-weighted mean albedo: the fraction of power intercepted from an isotropic light field
    /// that escapes.
    #[must_use]
    pub fn mean_albedo(&self) -> [f64; 3] {
        let total: f64 = self.effective_area.iter().sum();
        std::array::from_fn(|c| {
            if total > 0.0 { self.albedo.iter().zip(&self.effective_area).map(|(al, a)| al[c] * a).sum::<f64>() / total } else { 0.0 }
        })
    }

    /// The face transfer matrix; the uniform one of [`Self::mean_albedo`] when none was stored
    /// or the stored one is malformed.
    #[must_use]
    pub fn face_transfer(&self) -> FaceTransfer {
        FaceTransfer::from_entries(&self.face_transfer).unwrap_or_else(|| FaceTransfer::uniform(self.mean_albedo()))
    }

    /// Index of the sampled direction closest to `dir`.
    #[must_use]
    pub fn nearest(&self, dir: DVec3) -> usize {
        let d = dir.normalize_or_zero();
        let mut best = (0, f64::NEG_INFINITY);
        for (i, w) in self.directions.iter().enumerate() {
            let c = d.dot(DVec3::from_array(*w));
            if c > best.1 {
                best = (i, c);
            }
        }
        best.0
    }
}

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() { 0.0 } else { v.iter().sum::<f64>() / v.len() as f64 }
}
