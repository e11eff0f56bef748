//! The 15 CIE standard general skies (ISO 15469:2004 / CIE S 011/E:2003): the sky's luminance
//! relative to the zenith's, `L(Z, α) / L_z = φ(Z) f(χ) / (φ(0) f(Z_s))`, with the gradation
//! `φ(Z) = 1 + a exp(b / cos Z)` (`φ(90°) = 1`) and the indicatrix
//! `f(χ) = 1 + c (exp(d χ) − exp(d π/2)) + e cos² χ`, `Z` a sky point's zenith angle, `χ` its
//! angular distance from the sun, `Z_s` the sun's zenith angle. Each type pairs one of six
//! gradation groups (`a`, `b`) with one of six indicatrix groups (`c`, `d`, `e`)
//! ([`CIE_GENERAL_TYPES`]): types 1–5 overcast (5: uniform luminance), 6–10 intermediate, 11–15
//! clear (12: the CIE standard clear sky).
//!
//! A sky cell's light vector `∫ L ω dω` is a Gauss–Legendre quadrature over the cell
//! (`quadrature.rs`; smooth integrands: the gradation has every derivative zero at the horizon,
//! the indicatrix is smooth through the sun).

use super::quadrature::{light_vector, scaled_sources};
use super::{DaylightError, DistantSource, Site, SkyCell, check_sun_above, cos_angle_from_sun};

/// A CIE general sky: its type (1–15) and the sun's position in the site's frame (radians;
/// azimuth clockwise from north, as [`Site::direction`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CieSky {
    /// Sky type, 1 to 15.
    pub sky_type: u8,
    /// The sun's zenith angle (radians, below π/2).
    pub sun_zenith: f64,
    /// The sun's azimuth (radians, clockwise from north).
    pub sun_azimuth: f64,
}

/// Gradation groups I–VI: `(a, b)`.
const GRADATION: [(f64, f64); 6] = [(4.0, -0.70), (1.1, -0.8), (0.0, -1.0), (-1.0, -0.55), (-1.0, -0.32), (-1.0, -0.15)];

/// Indicatrix groups 1–6: `(c, d, e)`.
const INDICATRIX: [(f64, f64, f64); 6] =
    [(0.0, -1.0, 0.0), (2.0, -1.5, 0.15), (5.0, -2.5, 0.30), (10.0, -3.0, 0.45), (16.0, -3.0, 0.30), (24.0, -2.8, 0.15)];

/// The 15 types: `(gradation group, indicatrix group)`, 1-based as the standard numbers them.
pub const CIE_GENERAL_TYPES: [(u8, u8); 15] =
    [(1, 1), (1, 2), (2, 1), (2, 2), (3, 1), (3, 2), (3, 3), (3, 4), (4, 2), (4, 3), (4, 4), (5, 4), (5, 5), (6, 5), (6, 6)];

impl CieSky {
    /// A sky of type `sky_type` with the sun at `sun_zenith`, `sun_azimuth` (radians).
    pub fn new(sky_type: u8, sun_zenith: f64, sun_azimuth: f64) -> Result<CieSky, DaylightError> {
        if !(1..=15).contains(&sky_type) {
            return Err(DaylightError(format!("CIE general sky type {sky_type}: give 1 to 15")));
        }
        check_sun_above("CIE general sky", sun_zenith, sun_azimuth)?;
        Ok(CieSky { sky_type, sun_zenith, sun_azimuth })
    }

    fn parameters(self) -> ((f64, f64), (f64, f64, f64)) {
        let (g, i) = CIE_GENERAL_TYPES[usize::from(self.sky_type - 1)];
        (GRADATION[usize::from(g - 1)], INDICATRIX[usize::from(i - 1)])
    }

    /// `L / L_z` at zenith angle `zenith` and azimuth `azimuth` (radians, clockwise from north).
    #[must_use]
    pub fn relative_luminance(self, zenith: f64, azimuth: f64) -> f64 {
        let ((a, b), (c, d, e)) = self.parameters();
        let gradation = |z: f64| {
            let cz = z.cos();
            if cz <= 0.0 { 1.0 } else { 1.0 + a * (b / cz).exp() }
        };
        let indicatrix = |chi: f64| 1.0 + c * ((d * chi).exp() - (d * std::f64::consts::FRAC_PI_2).exp()) + e * chi.cos().powi(2);
        let chi = cos_angle_from_sun(self.sun_zenith, self.sun_azimuth, zenith, azimuth).acos();
        gradation(zenith) * indicatrix(chi) / (gradation(0.0) * indicatrix(self.sun_zenith))
    }

    /// The sky as one distant source per cell, delivering `diffuse_horizontal` to an
    /// unobstructed horizontal plane (see [`super::sky`]).
    pub(super) fn sources(self, cells: &[SkyCell], diffuse_horizontal: [f64; 3], site: &Site) -> Vec<DistantSource> {
        let vectors: Vec<[f64; 3]> =
            cells.iter().map(|c| light_vector(c, |zenith, azimuth| self.relative_luminance(zenith, azimuth))).collect();
        scaled_sources(cells, &vectors, diffuse_horizontal, site)
    }
}
