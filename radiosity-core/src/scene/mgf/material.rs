//! MGF material contexts (`m`, `rd`, `td`, `ed`, `sides`; `rs`, `ts`, `ir` are checked and dropped)
//! and their conversion to a diffuse [`Material`].
//!
//! Each of `rd`, `td` and `ed` takes the colour current when it is given. A value v with chromaticity
//! c becomes v × RGB(c), where RGB(c) has luminance 1 (see [`super::color::to_linear_rgb`]): the
//! luminance of the diffuse reflectance is `rd`, and the emitted radiosity is `ed` taken directly as
//! W/m² (MGF gives lm/m²; no luminous-efficacy factor is applied). Reflectances whose largest
//! channel reaches 1, or reflectance + transmittance reaching 1, are scaled down (keeping their hue)
//! to [`MAX_ALBEDO`], as RenderPark scales "total reflectance ≥ 1" materials.

use super::color::{Chroma, to_linear_rgb};
use crate::scene::Material;
use std::path::Path;
use std::rc::Rc;

/// Largest reflectance (and reflectance + transmittance) per channel kept after clamping.
pub(super) const MAX_ALBEDO: f64 = 0.999;

/// Where a context was last changed, for messages.
#[derive(Clone, Debug)]
pub(super) struct Location {
    /// File.
    pub path: Rc<Path>,
    /// 1-based line.
    pub line: usize,
}

/// One MGF material context.
#[derive(Clone, Debug)]
pub(super) struct MaterialCtx {
    /// `sides 1` (true) or `sides 2` (false, MGF's default).
    pub one_sided: bool,
    /// Diffuse reflectance (luminance) and its colour.
    pub rd: (f64, Chroma),
    /// Diffuse transmittance and its colour.
    pub td: (f64, Chroma),
    /// Diffuse emission and its colour.
    pub ed: (f64, Chroma),
    /// Last change.
    pub at: Location,
}

impl MaterialCtx {
    /// MGF's default material: black, non-emitting, two-sided, neutral colours.
    #[must_use]
    pub fn new(at: Location) -> MaterialCtx {
        MaterialCtx { one_sided: false, rd: (0.0, Chroma::NEUTRAL), td: (0.0, Chroma::NEUTRAL), ed: (0.0, Chroma::NEUTRAL), at }
    }

    /// The diffuse material named `name`, and a description of the clamping applied, if any.
    /// `force_one_sided` ignores `sides` (every surface one-sided).
    #[must_use]
    pub fn to_material(&self, name: &str, force_one_sided: bool) -> (Material, Option<String>) {
        let scaled = |(v, c): (f64, Chroma)| to_linear_rgb(c).map(|x| x * v);
        let mut rd = scaled(self.rd);
        let mut td = scaled(self.td);
        let mut clamped = None;
        let rd_max = rd.iter().copied().fold(0.0, f64::max);
        if rd_max >= 1.0 {
            rd = rd.map(|x| x * MAX_ALBEDO / rd_max);
            clamped = Some(format!("diffuse reflectance reaches {rd_max:.4} in some channel; scaled to {MAX_ALBEDO}"));
        }
        let total_max = (0..3).map(|i| rd[i] + td[i]).fold(0.0, f64::max);
        if total_max >= 1.0 {
            let k = MAX_ALBEDO / total_max;
            rd = rd.map(|x| x * k);
            td = td.map(|x| x * k);
            clamped = Some(format!("diffuse reflectance + transmittance reaches {total_max:.4}; scaled to {MAX_ALBEDO}"));
        }
        let material = Material {
            name: name.to_owned(),
            reflectance: rd,
            emission: scaled(self.ed),
            transmittance: td,
            two_sided: !force_one_sided && !self.one_sided,
            // MGF's `sides 1` is a rendering hint, not a declaration against the default backs
            // under the sun and sky (MGF scenes have none): its transmitting materials keep
            // their backs as before.
            one_sided: false,
        };
        (material, clamped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx() -> MaterialCtx {
        MaterialCtx::new(Location { path: Rc::from(Path::new("t.mgf")), line: 1 })
    }

    #[test]
    fn grey_material_keeps_its_value() {
        let mut m = ctx();
        m.rd = (0.5, Chroma::NEUTRAL);
        m.ed = (10.0, Chroma::NEUTRAL);
        let (mat, clamped) = m.to_material("grey", true);
        assert!(clamped.is_none());
        for c in 0..3 {
            assert!((mat.reflectance[c] - 0.5).abs() < 1e-3, "{mat:?}");
            assert!((mat.emission[c] - 10.0).abs() < 1e-2, "{mat:?}");
        }
        assert!(!mat.two_sided);
        assert!(m.to_material("grey", false).0.two_sided, "MGF default is two-sided");
    }

    #[test]
    fn saturated_or_total_reflectance_is_scaled_below_one() {
        let mut m = ctx();
        m.rd = (0.6, Chroma::new(0.64, 0.33).unwrap());
        let (mat, clamped) = m.to_material("red", true);
        assert!(clamped.is_some());
        assert!(mat.reflectance.iter().all(|&r| r <= MAX_ALBEDO + 1e-12), "{mat:?}");
        let mut m = ctx();
        m.rd = (0.6, Chroma::NEUTRAL);
        m.td = (0.6, Chroma::NEUTRAL);
        let (mat, clamped) = m.to_material("glass", true);
        assert!(clamped.is_some());
        assert!((0..3).all(|c| mat.reflectance[c] + mat.transmittance[c] < 1.0), "{mat:?}");
    }
}
