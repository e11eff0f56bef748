//! A photometric luminaire: a measured intensity distribution ([`crate::photometry::Photometry`],
//! from an IES or EULUMDAT file) placed with a position, an aim and a rotation, and seen as a
//! point at its photometric centre (the far-field model; see [`crate::luminaire`] for how its
//! light enters a solve).

use crate::geom::DVec3;
use crate::photometry::Photometry;
use std::sync::Arc;

/// A luminaire placed in a scene.
#[derive(Clone, Debug)]
pub struct Luminaire {
    /// Name (the photometric file's, or the scene file's entry).
    pub name: String,
    /// Intensity distribution, cd (the file's multipliers applied, not the placement's).
    pub photometry: Arc<Photometry>,
    /// Photometric centre.
    pub position: DVec3,
    /// Unit direction of the photometric nadir (γ = 0).
    pub aim: DVec3,
    /// Unit direction of the C = 0 half-plane (perpendicular to `aim`).
    pub c0: DVec3,
    /// Unit direction of the C = 90° half-plane: `−aim × c0` (C turns counter-clockwise seen from
    /// behind the luminaire, as seen from above a downlight).
    pub c90: DVec3,
    /// Scales every intensity.
    pub multiplier: f64,
}

/// A luminaire that cannot be placed.
#[derive(Debug, thiserror::Error)]
#[error("luminaire `{name}`: {reason}")]
pub struct LuminaireError {
    /// The luminaire.
    pub name: String,
    /// Why.
    pub reason: String,
}

impl Luminaire {
    /// Places `photometry` at `position`, its nadir along `aim` (any length but zero), its C = 0
    /// plane turned `rotate_deg` degrees about the aim from the reference direction (world +x
    /// projected onto the plane across the aim; +y when the aim is along x), every intensity
    /// times `multiplier`.
    pub fn new(
        name: &str,
        photometry: Arc<Photometry>,
        position: DVec3,
        aim: DVec3,
        rotate_deg: f64,
        multiplier: f64,
    ) -> Result<Luminaire, LuminaireError> {
        let fail = |reason: String| LuminaireError { name: name.to_string(), reason };
        if !position.is_finite() {
            return Err(fail(format!("position {position} is not finite")));
        }
        let len = aim.length();
        if !len.is_finite() || len <= 0.0 {
            return Err(fail(format!("aim {aim} is not a direction")));
        }
        if !rotate_deg.is_finite() {
            return Err(fail(format!("rotate {rotate_deg} is not finite")));
        }
        if !multiplier.is_finite() || multiplier < 0.0 {
            return Err(fail(format!("multiplier {multiplier} must be finite and non-negative")));
        }
        let aim = aim / len;
        let reference = if aim.x.abs() > 0.9 { DVec3::Y } else { DVec3::X };
        let c0 = (reference - aim * aim.dot(reference)).normalize();
        let c90 = (-aim).cross(c0);
        let (s, c) = rotate_deg.to_radians().sin_cos();
        let (c0, c90) = (c0 * c + c90 * s, c90 * c - c0 * s);
        Ok(Luminaire { name: name.to_string(), photometry, position, aim, c0, c90, multiplier })
    }

    /// The photometric angles `(C, γ)` in degrees of the unit direction `dir` leaving the luminaire.
    #[must_use]
    pub fn angles(&self, dir: DVec3) -> (f64, f64) {
        let gamma = dir.dot(self.aim).clamp(-1.0, 1.0).acos().to_degrees();
        let c = dir.dot(self.c90).atan2(dir.dot(self.c0)).to_degrees();
        (if c < 0.0 { c + 360.0 } else { c }, gamma)
    }

    /// Intensity (cd) toward the unit direction `dir` leaving the luminaire.
    #[must_use]
    pub fn intensity_toward(&self, dir: DVec3) -> f64 {
        let (c, gamma) = self.angles(dir);
        self.multiplier * self.photometry.intensity(c, gamma)
    }

    /// Luminous flux leaving the luminaire (lm): the integral of its intensity over the sphere.
    #[must_use]
    pub fn flux(&self) -> f64 {
        self.multiplier * self.photometry.flux()
    }

    /// Illuminance (lx) at `x` on a receiver with unit normal `n`, without occlusion.
    #[must_use]
    pub fn illuminance_unoccluded(&self, x: DVec3, n: DVec3) -> f64 {
        let d = x - self.position;
        let d2 = d.length_squared();
        if !(d2 > 0.0) {
            return 0.0;
        }
        let dist = d2.sqrt();
        let dir = d / dist;
        let cos = -n.dot(dir);
        if cos <= 0.0 {
            return 0.0;
        }
        self.intensity_toward(dir) * cos / d2
    }
}
