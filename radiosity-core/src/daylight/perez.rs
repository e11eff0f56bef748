//! The Perez all-weather sky (Perez, Seals and Michalsky 1993, "All-weather model for sky
//! luminance distribution — preliminary configuration and validation", Solar Energy 50(3),
//! 235–245, with its erratum in 51(5), 423): the sky's relative luminance
//! `l(ζ, γ) = (1 + a exp(b / cos ζ)) (1 + c exp(d γ) + e cos² γ)`, `ζ` a sky point's zenith
//! angle and `γ` its angular distance from the sun. The five coefficients follow from the sky's
//! clearness `ε` and brightness `Δ` and the sun's zenith angle `Z` (radians):
//! `x = x₁ + x₂ Z + Δ (x₃ + x₄ Z)` for each of `a` … `e` with the paper's Table 1 row of the
//! clearness bin ([`PEREZ_CLEARNESS_BINS`]), except in the overcast bin (`ε < 1.065`), where
//! `c = exp((Δ (c₁ + c₂ Z))^c₃) − c₄` and `d = −exp(Δ (d₁ + d₂ Z)) + d₃ + Δ d₄`.
//!
//! `ε` and `Δ` are what weather files give through the direct normal and diffuse horizontal
//! irradiance ([`perez_parameters`]); the sky's cells are then scaled to the diffuse horizontal
//! irradiance, as every sky model's are.

use super::quadrature::{light_vector, scaled_sources};
use super::{DaylightError, DistantSource, Site, SkyCell, check_sun_above, cos_angle_from_sun};

/// A Perez all-weather sky: clearness `ε`, brightness `Δ`, and the sun's position in the site's
/// frame (radians; azimuth clockwise from north, as [`Site::direction`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PerezSky {
    /// Sky clearness `ε` (1 for an overcast sky, about 6 and more for a clear one).
    pub clearness: f64,
    /// Sky brightness `Δ`.
    pub brightness: f64,
    /// The sun's zenith angle (radians, below π/2).
    pub sun_zenith: f64,
    /// The sun's azimuth (radians, clockwise from north).
    pub sun_azimuth: f64,
}

/// Upper bounds of the clearness bins 1–7 (bin 8 is the rest): Perez et al. 1993, Table 1.
pub const PEREZ_CLEARNESS_BINS: [f64; 7] = [1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200];

/// The clearness and brightness the model was fitted over (Perez et al. 1990, 1993): outside, a
/// sky is refused rather than extrapolated.
pub const PEREZ_CLEARNESS_RANGE: (f64, f64) = (1.0, 12.0);
/// See [`PEREZ_CLEARNESS_RANGE`].
pub const PEREZ_BRIGHTNESS_RANGE: (f64, f64) = (0.01, 0.6);

/// In the clearness bins 2–5 (`1.065 < ε < 2.8`) a brightness below this is taken as this: below
/// it the fitted coefficients give skies darker near the sun than away from it, and negative
/// luminance (the correction Radiance's `gendaylit` makes too).
pub const PEREZ_MIN_BRIGHTNESS_MID_BINS: f64 = 0.2;

/// Perez et al. 1993, Table 1: per clearness bin, `a₁ a₂ a₃ a₄ b₁ … e₄`.
const TABLE: [[f64; 20]; 8] = [
    [
        1.3525, -0.2576, -0.2690, -1.4366, -0.7670, 0.0007, 1.2734, -0.1233, 2.8000, 0.6004, 1.2375, 1.0000, 1.8734, 0.6297, 0.9738,
        0.2809, 0.0356, -0.1246, -0.5718, 0.9938,
    ],
    [
        -1.2219, -0.7730, 1.4148, 1.1016, -0.2054, 0.0367, -3.9128, 0.9156, 6.9750, 0.1774, 6.4477, -0.1239, -1.5798, -0.5081, -1.7812,
        0.1080, 0.2624, 0.0672, -0.2190, -0.4285,
    ],
    [
        -1.1000, -0.2515, 0.8952, 0.0156, 0.2782, -0.1812, -4.5000, 1.1766, 24.7219, -13.0812, -37.7000, 34.8438, -5.0000, 1.5218, 3.9229,
        -2.6204, -0.0156, 0.1597, 0.4199, -0.5562,
    ],
    [
        -0.5484, -0.6654, -0.2672, 0.7117, 0.7234, -0.6219, -5.6812, 2.6297, 33.3389, -18.3000, -62.2500, 52.0781, -3.5000, 0.0016, 1.1477,
        0.1062, 0.4659, -0.3296, -0.0876, -0.0329,
    ],
    [
        -0.6000, -0.3566, -2.5000, 2.3250, 0.2937, 0.0496, -5.6812, 1.8415, 21.0000, -4.7656, -21.5906, 7.2492, -3.5000, -0.1554, 1.4062,
        0.3988, 0.0032, 0.0766, -0.0656, -0.1294,
    ],
    [
        -1.0156, -0.3670, 1.0078, 1.4051, 0.2875, -0.5328, -3.8500, 3.3750, 14.0000, -0.9999, -7.1406, 7.5469, -3.4000, -0.1078, -1.0750,
        1.5702, -0.0672, 0.4016, 0.3017, -0.4844,
    ],
    [
        -1.0000, 0.0211, 0.5025, -0.5119, -0.3000, 0.1922, 0.7023, -1.6317, 19.0000, -5.0000, 1.2438, -1.9094, -4.0000, 0.0250, 0.3844,
        0.2656, 1.0468, -0.3788, -2.4517, 1.4656,
    ],
    [
        -1.0500, 0.0289, 0.4260, 0.3590, -0.3250, 0.1156, 0.7781, 0.0025, 31.0625, -14.5000, -46.1148, 55.3750, -7.2312, 0.4050, 13.3500,
        0.6234, 1.5000, -0.6426, 1.8564, 0.5636,
    ],
];

impl PerezSky {
    /// A sky of clearness `clearness` and brightness `brightness` with the sun at `sun_zenith`,
    /// `sun_azimuth` (radians); refused outside [`PEREZ_CLEARNESS_RANGE`] and
    /// [`PEREZ_BRIGHTNESS_RANGE`], or with the sun below the horizon.
    pub fn new(clearness: f64, brightness: f64, sun_zenith: f64, sun_azimuth: f64) -> Result<PerezSky, DaylightError> {
        let ((e0, e1), (d0, d1)) = (PEREZ_CLEARNESS_RANGE, PEREZ_BRIGHTNESS_RANGE);
        if !(clearness.is_finite() && (e0..=e1).contains(&clearness)) {
            return Err(DaylightError(format!("Perez sky: clearness {clearness} outside the model's range {e0} to {e1}")));
        }
        if !(brightness.is_finite() && (d0..=d1).contains(&brightness)) {
            return Err(DaylightError(format!("Perez sky: brightness {brightness} outside the model's range {d0} to {d1}")));
        }
        check_sun_above("Perez sky", sun_zenith, sun_azimuth)?;
        Ok(PerezSky { clearness, brightness, sun_zenith, sun_azimuth })
    }

    /// The coefficients `[a, b, c, d, e]` of the luminance distribution.
    #[must_use]
    pub fn coefficients(self) -> [f64; 5] {
        let (eps, z) = (self.clearness, self.sun_zenith);
        let bin = PEREZ_CLEARNESS_BINS.iter().take_while(|&&upper| eps >= upper).count();
        let mut delta = self.brightness;
        if eps > PEREZ_CLEARNESS_BINS[0] && eps < PEREZ_CLEARNESS_BINS[4] {
            delta = delta.max(PEREZ_MIN_BRIGHTNESS_MID_BINS);
        }
        let x = &TABLE[bin];
        let linear = |i: usize| x[4 * i] + x[4 * i + 1] * z + delta * (x[4 * i + 2] + x[4 * i + 3] * z);
        let mut k = [linear(0), linear(1), linear(2), linear(3), linear(4)];
        if bin == 0 {
            k[2] = (delta * (x[8] + x[9] * z)).powf(x[10]).exp() - x[11];
            k[3] = -(delta * (x[12] + x[13] * z)).exp() + x[14] + delta * x[15];
        }
        k
    }

    /// The luminance at zenith angle `zenith` and azimuth `azimuth` (radians, clockwise from
    /// north) relative to the model's unit (the cells are scaled afterwards), 0 where the fitted
    /// distribution would go negative.
    #[must_use]
    pub fn relative_luminance(self, zenith: f64, azimuth: f64) -> f64 {
        self.luminance_with(self.coefficients(), zenith, azimuth)
    }

    fn luminance_with(self, [a, b, c, d, e]: [f64; 5], zenith: f64, azimuth: f64) -> f64 {
        let cz = zenith.cos();
        let gradation = if cz <= 0.0 { 1.0 } else { 1.0 + a * (b / cz).exp() };
        let cos_gamma = cos_angle_from_sun(self.sun_zenith, self.sun_azimuth, zenith, azimuth);
        let indicatrix = 1.0 + c * (d * cos_gamma.acos()).exp() + e * cos_gamma * cos_gamma;
        (gradation * indicatrix).max(0.0)
    }

    /// The sky as one distant source per cell, delivering `diffuse_horizontal` to an
    /// unobstructed horizontal plane (see [`super::sky`]).
    pub(super) fn sources(self, cells: &[SkyCell], diffuse_horizontal: [f64; 3], site: &Site) -> Vec<DistantSource> {
        let k = self.coefficients();
        let vectors: Vec<[f64; 3]> =
            cells.iter().map(|c| light_vector(c, |zenith, azimuth| self.luminance_with(k, zenith, azimuth))).collect();
        scaled_sources(cells, &vectors, diffuse_horizontal, site)
    }
}

/// The solar constant, W/m² (what the brightness `Δ` is relative to, with the eccentricity).
pub const SOLAR_CONSTANT: f64 = 1367.0;

/// The clearness `ε` and brightness `Δ` of a sky from broadband irradiances (W/m²): the direct
/// normal `direct_normal`, the diffuse horizontal `diffuse_horizontal`, the sun's zenith angle
/// `sun_zenith` (radians) and the day of the year (1–365; it sets the sun's distance).
/// `ε = ((D + I) / D + κ Z³) / (1 + κ Z³)` with `κ = 1.041` (Perez et al. 1990), and
/// `Δ = D m / (I₀ E₀)` with the relative air mass `m` of Kasten (1966),
/// `1 / (cos Z + 0.15 (93.885 − Z°)^−1.253)`, the solar constant `I₀` ([`SOLAR_CONSTANT`]) and the
/// eccentricity correction `E₀` of Spencer (1971).
pub fn perez_parameters(
    direct_normal: f64,
    diffuse_horizontal: f64,
    sun_zenith: f64,
    day_of_year: u32,
) -> Result<(f64, f64), DaylightError> {
    if !(direct_normal.is_finite() && direct_normal >= 0.0 && diffuse_horizontal.is_finite() && diffuse_horizontal > 0.0) {
        return Err(DaylightError(format!(
            "Perez sky: direct normal {direct_normal} and diffuse horizontal {diffuse_horizontal} W/m² must be finite, the diffuse positive"
        )));
    }
    check_sun_above("Perez sky", sun_zenith, 0.0)?;
    let z3 = 1.041 * sun_zenith.powi(3);
    let clearness = ((diffuse_horizontal + direct_normal) / diffuse_horizontal + z3) / (1.0 + z3);
    let air_mass = 1.0 / (sun_zenith.cos() + 0.15 * (93.885 - sun_zenith.to_degrees()).powf(-1.253));
    let day_angle = 2.0 * std::f64::consts::PI * (f64::from(day_of_year.clamp(1, 366)) - 1.0) / 365.0;
    let eccentricity = 1.000_11
        + 0.034_221 * day_angle.cos()
        + 0.001_28 * day_angle.sin()
        + 0.000_719 * (2.0 * day_angle).cos()
        + 0.000_077 * (2.0 * day_angle).sin();
    let brightness = diffuse_horizontal * air_mass / (SOLAR_CONSTANT * eccentricity);
    Ok((clearness, brightness))
}
