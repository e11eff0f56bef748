//! MGF colours: CIE 1931 (x, y) chromaticities set by `cxy`, `cspec` (a sampled spectrum), `cct`
//! (a black body) and `cmix` (a luminance-weighted mix), and their conversion to linear RGB.
//!
//! MGF's neutral colour is the equal-energy white (1/3, 1/3), as in mgflib, Radiance and RenderPark.
//! [`to_linear_rgb`] adapts it to D65 with the Bradford transform and then applies the standard
//! XYZ → linear sRGB matrix (Rec. 709 primaries), so that neutral MGF colours become grey.

use glam::{DMat3, DVec3};

/// A CIE 1931 chromaticity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Chroma {
    /// CIE x.
    pub x: f64,
    /// CIE y.
    pub y: f64,
}

impl Chroma {
    /// MGF's default colour: the equal-energy white.
    pub const NEUTRAL: Chroma = Chroma { x: 1.0 / 3.0, y: 1.0 / 3.0 };

    /// The chromaticity from `cxy x y`, or `None` outside the triangle x, y ≥ 0, x + y ≤ 1.
    #[must_use]
    pub fn new(x: f64, y: f64) -> Option<Chroma> {
        (x >= 0.0 && y >= 0.0 && x + y <= 1.0).then_some(Chroma { x, y })
    }

    /// Chromaticity of tristimulus values, or `None` when they sum to (almost) nothing.
    fn from_xyz(xyz: DVec3) -> Option<Chroma> {
        let sum = xyz.x + xyz.y + xyz.z;
        (sum > MIN_TRISTIMULUS_SUM && xyz.min_element() >= 0.0).then(|| Chroma { x: xyz.x / sum, y: xyz.y / sum })
    }
}

/// Tristimulus sums at or below this (relative to the spectrum's peak × 400 nm) count as no light.
const MIN_TRISTIMULUS_SUM: f64 = 1e-12;
/// Chromaticities with y at or below this have no defined luminance: they convert to black.
const MIN_CHROMA_Y: f64 = 1e-9;
/// Lowest colour temperature `cct` accepts (mgflib refuses lower ones).
pub(super) const MIN_COLOR_TEMPERATURE: f64 = 1000.0;

/// Shortest wavelength of [`CIE_1931`] in nm.
const CIE_MIN_WL: f64 = 380.0;
/// Longest wavelength of [`CIE_1931`] in nm.
const CIE_MAX_WL: f64 = 780.0;
/// Wavelength step of [`CIE_1931`] in nm.
const CIE_STEP_WL: f64 = 10.0;
/// Integration step for spectra in nm.
const INTEGRATION_STEP_WL: f64 = 1.0;

/// CIE 1931 2° colour-matching functions x̄, ȳ, z̄ from 380 to 780 nm in 10 nm steps.
const CIE_1931: [[f64; 3]; 41] = [
    [0.001368, 0.000039, 0.006450],
    [0.004243, 0.000120, 0.020050],
    [0.014310, 0.000396, 0.067850],
    [0.043510, 0.001210, 0.207400],
    [0.134380, 0.004000, 0.645600],
    [0.283900, 0.011600, 1.385600],
    [0.348280, 0.023000, 1.747060],
    [0.336200, 0.038000, 1.772110],
    [0.290800, 0.060000, 1.669200],
    [0.195360, 0.090980, 1.287640],
    [0.095640, 0.139020, 0.812950],
    [0.032010, 0.208020, 0.465180],
    [0.004900, 0.323000, 0.272000],
    [0.009300, 0.503000, 0.158200],
    [0.063270, 0.710000, 0.078250],
    [0.165500, 0.862000, 0.042160],
    [0.290400, 0.954000, 0.020300],
    [0.433450, 0.994950, 0.008750],
    [0.594500, 0.995000, 0.003900],
    [0.762100, 0.952000, 0.002100],
    [0.916300, 0.870000, 0.001650],
    [1.026300, 0.757000, 0.001100],
    [1.062200, 0.631000, 0.000800],
    [1.002600, 0.503000, 0.000340],
    [0.854450, 0.381000, 0.000190],
    [0.642400, 0.265000, 0.000050],
    [0.447900, 0.175000, 0.000020],
    [0.283500, 0.107000, 0.000000],
    [0.164900, 0.061000, 0.000000],
    [0.087400, 0.032000, 0.000000],
    [0.046770, 0.017000, 0.000000],
    [0.022700, 0.008210, 0.000000],
    [0.011359, 0.004102, 0.000000],
    [0.005790, 0.002091, 0.000000],
    [0.002899, 0.001047, 0.000000],
    [0.001440, 0.000520, 0.000000],
    [0.000690, 0.000249, 0.000000],
    [0.000332, 0.000120, 0.000000],
    [0.000166, 0.000060, 0.000000],
    [0.000083, 0.000030, 0.000000],
    [0.000042, 0.000015, 0.000000],
];

/// Bradford cone-response matrix (rows).
const BRADFORD: [[f64; 3]; 3] = [[0.8951, 0.2664, -0.1614], [-0.7502, 1.7135, 0.0367], [0.0389, -0.0685, 1.0296]];
/// CIE XYZ → linear sRGB (Rec. 709 primaries, D65 white), rows.
const XYZ_TO_SRGB: [[f64; 3]; 3] =
    [[3.2404542, -1.5371385, -0.4985314], [-0.9692660, 1.8760108, 0.0415560], [0.0556434, -0.2040259, 1.0572252]];
/// Luminance (Y) of linear sRGB.
const SRGB_LUMINANCE: [f64; 3] = [0.2126729, 0.7151522, 0.0721750];
/// XYZ of the D65 white with Y = 1.
const D65_XYZ: [f64; 3] = [0.95047, 1.0, 1.08883];

/// A matrix from rows.
fn rows(m: &[[f64; 3]; 3]) -> DMat3 {
    DMat3::from_cols_array_2d(m).transpose()
}

/// XYZ (equal-energy white) → linear sRGB: Bradford adaptation E → D65, then the sRGB matrix.
fn xyz_e_to_srgb() -> DMat3 {
    let bradford = rows(&BRADFORD);
    let cone_e = bradford * DVec3::ONE;
    let cone_d65 = bradford * DVec3::from_array(D65_XYZ);
    let adapt = bradford.inverse() * DMat3::from_diagonal(cone_d65 / cone_e) * bradford;
    rows(&XYZ_TO_SRGB) * adapt
}

/// Linear RGB of chromaticity `c` with luminance Y = 1: negative channels (out of gamut) are
/// clamped to 0 and the result rescaled to Y = 1. Black when `c.y` is (almost) 0.
#[must_use]
pub(super) fn to_linear_rgb(c: Chroma) -> [f64; 3] {
    if c.y <= MIN_CHROMA_Y {
        return [0.0; 3];
    }
    let xyz = DVec3::new(c.x / c.y, 1.0, (1.0 - c.x - c.y) / c.y);
    let rgb = (xyz_e_to_srgb() * xyz).max(DVec3::ZERO);
    let lum = rgb.dot(DVec3::from_array(SRGB_LUMINANCE));
    if lum > 0.0 { (rgb / lum).to_array() } else { [0.0; 3] }
}

/// Colour-matching functions at wavelength `wl` nm (linear interpolation; zero outside the table).
fn cmf(wl: f64) -> DVec3 {
    if !(CIE_MIN_WL..=CIE_MAX_WL).contains(&wl) {
        return DVec3::ZERO;
    }
    let pos = (wl - CIE_MIN_WL) / CIE_STEP_WL;
    let i = (pos.floor() as usize).min(CIE_1931.len() - 2);
    let f = pos - i as f64;
    DVec3::from_array(CIE_1931[i]).lerp(DVec3::from_array(CIE_1931[i + 1]), f)
}

/// Tristimulus values of a spectral power distribution `power(wl)` over the visible range.
fn integrate(power: impl Fn(f64) -> f64) -> DVec3 {
    let n_steps = ((CIE_MAX_WL - CIE_MIN_WL) / INTEGRATION_STEP_WL).round() as usize;
    (0..=n_steps)
        .map(|k| {
            let wl = CIE_MIN_WL + k as f64 * INTEGRATION_STEP_WL;
            cmf(wl) * power(wl)
        })
        .sum()
}

/// Chromaticity of `cspec wl_min wl_max s1 s2 ...`: `samples` evenly spaced from `wl_min` to
/// `wl_max` nm, linearly interpolated and zero outside. `None` when the range is empty or the
/// spectrum carries no visible light.
#[must_use]
pub(super) fn from_spectrum(wl_min: f64, wl_max: f64, samples: &[f64]) -> Option<Chroma> {
    if samples.len() < 2 || wl_max <= wl_min || wl_max <= CIE_MIN_WL || wl_min >= CIE_MAX_WL {
        return None;
    }
    let step = (wl_max - wl_min) / (samples.len() - 1) as f64;
    let power = |wl: f64| {
        if wl < wl_min || wl > wl_max {
            return 0.0;
        }
        let pos = (wl - wl_min) / step;
        let i = (pos.floor() as usize).min(samples.len() - 2);
        let f = pos - i as f64;
        samples[i] * (1.0 - f) + samples[i + 1] * f
    };
    let peak = samples.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    let xyz = integrate(power);
    if peak <= 0.0 {
        return None;
    }
    Chroma::from_xyz(xyz / peak)
}

/// Chromaticity of a black body at `kelvin` (Planck's law), `None` below
/// [`MIN_COLOR_TEMPERATURE`].
#[must_use]
pub(super) fn from_temperature(kelvin: f64) -> Option<Chroma> {
    /// Second radiation constant h·c/k in m·K.
    const C2: f64 = 1.4388e-2;
    if kelvin < MIN_COLOR_TEMPERATURE {
        return None;
    }
    // Normalised by the value at 560 nm so that the sums stay near 1.
    let planck = |wl_nm: f64| {
        let l = wl_nm * 1e-9;
        1.0 / (l.powi(5) * (C2 / (l * kelvin)).exp_m1())
    };
    let reference = planck(560.0);
    Chroma::from_xyz(integrate(|wl| planck(wl) / reference))
}

/// Mix of colours with luminance weights (`cmix w1 c1 w2 c2 ...`): the tristimulus values of each
/// colour scaled to Y = wᵢ are summed. `None` when the weights do not sum to a positive value or a
/// weighted colour has y = 0.
#[must_use]
pub(super) fn mix(parts: &[(f64, Chroma)]) -> Option<Chroma> {
    let mut xyz = DVec3::ZERO;
    let mut w_sum = 0.0;
    for &(w, c) in parts {
        if w == 0.0 {
            continue;
        }
        if c.y <= MIN_CHROMA_Y {
            return None;
        }
        xyz += w * DVec3::new(c.x / c.y, 1.0, (1.0 - c.x - c.y) / c.y);
        w_sum += w;
    }
    if w_sum <= 0.0 {
        return None;
    }
    Chroma::from_xyz(xyz)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn neutral_is_grey_and_luminance_is_one() {
        let rgb = to_linear_rgb(Chroma::NEUTRAL);
        for c in rgb {
            assert!(close(c, 1.0, 1e-3), "{rgb:?}");
        }
        let red = to_linear_rgb(Chroma::new(0.64, 0.33).unwrap());
        let lum: f64 = red.iter().zip(SRGB_LUMINANCE).map(|(c, w)| c * w).sum();
        assert!(close(lum, 1.0, 1e-12));
        assert!(red[0] > red[1] && red[0] > red[2], "{red:?}");
        assert_eq!(to_linear_rgb(Chroma { x: 0.5, y: 0.0 }), [0.0; 3]);
    }

    #[test]
    fn flat_spectrum_is_equal_energy_white() {
        let c = from_spectrum(380.0, 780.0, &[1.0; 5]).unwrap();
        assert!(close(c.x, 1.0 / 3.0, 2e-3) && close(c.y, 1.0 / 3.0, 2e-3), "{c:?}");
        // A spectrum beyond the visible range carries no light.
        assert_eq!(from_spectrum(800.0, 900.0, &[1.0, 1.0]), None);
        assert_eq!(from_spectrum(380.0, 780.0, &[0.0, 0.0]), None);
    }

    #[test]
    fn black_body_matches_daylight_locus() {
        // 6504 K is close to D65 (0.3127, 0.3290); 2856 K is illuminant A (0.4476, 0.4074).
        let d = from_temperature(6504.0).unwrap();
        assert!(close(d.x, 0.3135, 4e-3) && close(d.y, 0.3237, 4e-3), "{d:?}");
        let a = from_temperature(2856.0).unwrap();
        assert!(close(a.x, 0.4476, 3e-3) && close(a.y, 0.4074, 3e-3), "{a:?}");
        assert_eq!(from_temperature(500.0), None);
    }

    #[test]
    fn mix_weights_luminance() {
        let red = Chroma::new(0.64, 0.33).unwrap();
        let c = mix(&[(1.0, red), (0.0, Chroma::NEUTRAL)]).unwrap();
        assert!(close(c.x, red.x, 1e-12) && close(c.y, red.y, 1e-12));
        let half = mix(&[(1.0, Chroma::NEUTRAL), (1.0, Chroma::NEUTRAL)]).unwrap();
        assert!(close(half.x, 1.0 / 3.0, 1e-12));
        assert_eq!(mix(&[(0.0, red)]), None);
    }
}
