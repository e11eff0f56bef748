//! The point evaluator: a point's irradiance from each distant source, with one shadow ray.

use super::DistantSource;
use crate::geom::DVec3;
use crate::visibility::RayCaster;

/// Shadow rays toward distant sources run this far (relative to the scene's diagonal) from the
/// receiver: past every surface of the scene.
pub const FAR_REL: f64 = 4.0;

/// Sees the distant sources from points: irradiance with one shadow ray per source.
pub struct DistantLight<'a> {
    sources: &'a [DistantSource],
    caster: Option<&'a RayCaster>,
    offset: f64,
}

impl<'a> DistantLight<'a> {
    /// The sources seen.
    #[must_use]
    pub fn sources(&self) -> &'a [DistantSource] {
        self.sources
    }

    /// `caster` `None`: no occlusion.
    #[must_use]
    pub fn new(sources: &'a [DistantSource], caster: Option<&'a RayCaster>, scene_diagonal: f64) -> DistantLight<'a> {
        DistantLight { sources, caster, offset: crate::visibility::SHADOW_ORIGIN_OFFSET_REL * scene_diagonal }
    }

    /// Whether a ray from `x` (normal `n`, on polygon `skip`) against the light of source `k`
    /// leaves the scene, and the unoccluded irradiance it would bring.
    #[must_use]
    pub fn from_one(&self, k: usize, x: DVec3, n: DVec3, skip: u32) -> ([f64; 3], bool) {
        let s = &self.sources[k];
        let e = s.on(n);
        if e.iter().all(|&v| v <= 0.0) {
            return ([0.0; 3], false);
        }
        match self.caster {
            Some(caster) if !caster.ray_clear_skipping(x + self.offset * n, -s.toward, skip) => ([0.0; 3], true),
            _ => (e, false),
        }
    }

    /// Irradiance at `x` (normal `n`) from every source.
    #[must_use]
    pub fn at(&self, x: DVec3, n: DVec3, skip: u32) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for k in 0..self.sources.len() {
            let (e, _) = self.from_one(k, x, n, skip);
            for c in 0..3 {
                sum[c] += e[c];
            }
        }
        sum
    }
}
