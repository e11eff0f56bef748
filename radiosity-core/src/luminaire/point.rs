//! The point evaluator: a surface point's illuminance from each luminaire, with one shadow ray.

use super::{Luminaire, SHADOW_ORIGIN_OFFSET_REL};
use crate::geom::DVec3;
use crate::hierarchy::NONE;
use crate::visibility::RayCaster;

/// Sees the luminaires from surface points: illuminance with one shadow ray per luminaire.
pub struct DirectLight<'a> {
    pub(super) luminaires: &'a [Luminaire],
    pub(super) caster: Option<&'a RayCaster>,
    offset: f64,
}

impl<'a> DirectLight<'a> {
    /// `caster` `None`: no occlusion.
    #[must_use]
    pub fn new(luminaires: &'a [Luminaire], caster: Option<&'a RayCaster>, scene_diagonal: f64) -> DirectLight<'a> {
        DirectLight { luminaires, caster, offset: SHADOW_ORIGIN_OFFSET_REL * scene_diagonal }
    }

    /// Illuminance at `x` (normal `n`) from luminaire `k`, and whether it is occluded; `skip` is the
    /// polygon `x` lies on ([`NONE`] for a free point).
    #[must_use]
    pub fn from_one(&self, k: usize, x: DVec3, n: DVec3, skip: u32) -> (f64, bool) {
        let lum = &self.luminaires[k];
        let e = lum.illuminance_unoccluded(x, n);
        if e <= 0.0 {
            return (0.0, false);
        }
        match self.caster {
            Some(caster) if !caster.segment_clear(x + self.offset * n, lum.position, skip, NONE) => (0.0, true),
            _ => (e, false),
        }
    }

    /// Illuminance at `x` (normal `n`) from every luminaire.
    #[must_use]
    pub fn at(&self, x: DVec3, n: DVec3, skip: u32) -> f64 {
        (0..self.luminaires.len()).map(|k| self.from_one(k, x, n, skip).0).sum()
    }
}
