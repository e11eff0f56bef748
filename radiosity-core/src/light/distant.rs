//! A distant source: a field of parallel beams (the sun, or one cell of a sky; see
//! [`crate::daylight`] for how they are made and how their light enters a solve).

use crate::geom::DVec3;

/// A field of parallel beams.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistantSource {
    /// Unit direction the light travels (toward the ground for the sun).
    pub toward: DVec3,
    /// Irradiance on a plane facing the beam, per channel (W/m²).
    pub irradiance: [f64; 3],
    /// Whether the source is small enough to cast sharp shadows (the sun): surfaces are split
    /// along its shadow boundaries before the solve, as for a luminaire.
    pub sharp: bool,
    /// The patch of sky a sky cell stands for (`None` for the sun and for sources made otherwise):
    /// where a receiver sees part of the cell, it samples the patch ray by ray.
    pub patch: Option<SkyPatch>,
}

/// The patch of sky of one cell: cos θ (θ from the zenith) from `mu[0]` to `mu[1]`, azimuth
/// (clockwise from north) from `phi[0]` over a width `phi[1]`, in the frame `frame` = (east,
/// north, up), with the cell's mean radiance per channel taken as uniform over it (its light
/// vector's vertical part over `∫ cos θ dω`, so that a horizontal plane seeing the whole patch
/// receives the cell's light exactly).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyPatch {
    /// East, north and up.
    pub frame: [DVec3; 3],
    /// cos θ at the horizon-side and at the zenith-side edge.
    pub mu: [f64; 2],
    /// Azimuth where the patch starts, and its width (radians).
    pub phi: [f64; 2],
    /// Mean radiance per channel (W/m²/sr).
    pub radiance: [f64; 3],
}

impl SkyPatch {
    /// The patch of a cell whose light travels along `toward` with `irradiance` on a plane facing
    /// it (see [`SkyPatch`]).
    #[must_use]
    pub fn new(frame: [DVec3; 3], mu: [f64; 2], phi: [f64; 2], toward: DVec3, irradiance: [f64; 3]) -> SkyPatch {
        let projected = 0.5 * phi[1] * (mu[1] * mu[1] - mu[0] * mu[0]);
        let vertical = -toward.dot(frame[2]);
        let radiance = irradiance.map(|e| if projected > 0.0 { e * vertical / projected } else { 0.0 });
        SkyPatch { frame, mu, phi, radiance }
    }

    /// The direction light travels from the point of the patch at fractions `s` of its way in
    /// cos θ and `t` in azimuth (0 to 1 each).
    #[must_use]
    pub fn toward(&self, s: f64, t: f64) -> DVec3 {
        let mu = self.mu[0] + s * (self.mu[1] - self.mu[0]);
        let phi = self.phi[0] + t * self.phi[1];
        let sin = (1.0 - mu * mu).max(0.0).sqrt();
        let (sp, cp) = phi.sin_cos();
        let [east, north, up] = self.frame;
        -(east * (sin * sp) + north * (sin * cp) + up * mu).normalize()
    }

    /// The solid angle of each of the patch's `k × k` pieces ([`SkyPatch::pieces`]).
    #[must_use]
    pub fn piece_solid_angle(&self, k: usize) -> f64 {
        (self.mu[1] - self.mu[0]) * self.phi[1] / (k * k) as f64
    }

    /// The patch split into `k × k` pieces of equal solid angle (in cos θ and azimuth): the
    /// direction light travels through each piece's middle and the piece's solid angle, row by
    /// row (`i * k + j`, `i` along cos θ).
    pub fn pieces(&self, k: usize) -> impl Iterator<Item = (DVec3, f64)> + '_ {
        let omega = self.piece_solid_angle(k);
        let middle = move |i: usize| (i as f64 + 0.5) / k as f64;
        (0..k * k).map(move |n| (self.toward(middle(n / k), middle(n % k)), omega))
    }
}

impl DistantSource {
    /// Irradiance on a surface with unit normal `n`, unoccluded.
    #[must_use]
    pub fn on(&self, n: DVec3) -> [f64; 3] {
        let cos = -n.dot(self.toward);
        if cos <= 0.0 { [0.0; 3] } else { self.irradiance.map(|e| e * cos) }
    }
}
