//! Daylight: the sun and the sky as distant sources.
//!
//! A distant source is a field of parallel beams: a direction of travel and the irradiance it gives
//! a plane facing it, per channel ([`DistantSource`]). The **sun** is one such source, its
//! direction given or computed from a place and a time by the `spa` crate (the PSA algorithm,
//! 0.5 arc minute), its irradiance the direct normal irradiance. The **sky** is a set of them: the
//! upper hemisphere split into cells of equal solid angle ([`sky_cells`]: 46 or 145 cells, like
//! the "turtle" skies canopy models use, or any count from 1 up), each cell one source: its light
//! vector `∫ L ω dω` under the chosen radiance distribution ([`SkyModel`]: uniform, the CIE
//! standard overcast sky `L(θ) ∝ (1 + 2 cos θ) / 3`, one of the 15 CIE standard general skies
//! with the sun's position, [`CieSky`], or the Perez all-weather sky of a clearness and a
//! brightness, [`PerezSky`]), scaled so that the sky delivers the given
//! diffuse horizontal irradiance. A plane that sees a whole cell gets exactly that cell's light, so
//! the discretised sky gives an unobstructed horizontal plane the diffuse horizontal irradiance
//! exactly, whatever the cell count, and a vertical one within 1% (145 cells: 0.5% uniform, 0.6% overcast).
//!
//! Directions are in the scene's frame through a [`Site`]: which way is up and which is north
//! (default z up, y north, x east).
//!
//! Light enters the solve like the luminaires' (see [`crate::luminaire`]): each element's direct
//! irradiance, a shadow ray per quadrature point and source, becomes the emission `ρ·E` of the
//! radiosity system. Light that leaves the scene is measured after the solve ([`power_leaving`]):
//! the power balance of an open scene is `incident = absorbed + escaped`.
//!
//! One file per step: where the sun is and the site's frame (`sun.rs`); the sky models, their
//! cells and the hemisphere of cells the escaped light is looked for through (`sky.rs`); the CIE
//! general skies' luminance (`cie_general.rs`) and the Perez sky's (`perez.rs`), and the light
//! vectors of cells under either (`quadrature.rs`);
//! [`DistantLight`], the distant sources seen from a point with a shadow ray (`distant.rs`); which
//! one-sided faces get a back and which backs are open (`backs.rs`); the power that arrives, leaves
//! the scene or is lost at open backs, and the balance of a solve (`balance.rs`); the daylight
//! factor's reference, the sky's light on an open horizontal plane (`factor.rs`).

mod backs;
mod balance;
mod cie_general;
mod distant;
mod factor;
mod perez;
mod quadrature;
mod sky;
mod sun;

use crate::geom::DVec3;

pub use crate::light::DistantSource;
pub use backs::{open_backs, two_sided_where_backs_see_light};
pub use balance::{Escapes, Leaving, OutsideLinks, balance_gap, outside_links, power_incident, power_incident_on_backs, power_leaving};
pub use cie_general::{CIE_GENERAL_TYPES, CieSky};
pub use distant::{DistantLight, FAR_REL};
pub use factor::{outside_horizontal, sky_alone_horizontal};
pub use perez::{
    PEREZ_BRIGHTNESS_RANGE, PEREZ_CLEARNESS_BINS, PEREZ_CLEARNESS_RANGE, PEREZ_MIN_BRIGHTNESS_MID_BINS, PerezSky, SOLAR_CONSTANT,
    perez_parameters,
};
pub use sky::{ESCAPE_CELLS, RINGS_46, RINGS_145, SkyCell, SkyModel, escape_cells, sky, sky_cells};
pub use sun::{Site, SunReport, sun, sun_position};

/// A daylight input that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct DaylightError(pub String);

fn check_levels(what: &str, v: &[f64; 3]) -> Result<(), DaylightError> {
    if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
        return Err(DaylightError(format!("`{what}` {v:?} must be finite and non-negative")));
    }
    Ok(())
}

/// A sky model (`what`, for the message) needs the sun above the horizon, at zenith angle
/// `sun_zenith` and azimuth `sun_azimuth` (radians).
fn check_sun_above(what: &str, sun_zenith: f64, sun_azimuth: f64) -> Result<(), DaylightError> {
    if sun_zenith.is_finite() && (0.0..std::f64::consts::FRAC_PI_2).contains(&sun_zenith) && sun_azimuth.is_finite() {
        return Ok(());
    }
    Err(DaylightError(format!("{what}: the sun must be above the horizon (zenith angle {:.2}°)", sun_zenith.to_degrees())))
}

/// The cosine of the angle between the sky point at `zenith`, `azimuth` and the sun at
/// `sun_zenith`, `sun_azimuth` (radians; azimuths clockwise from north).
fn cos_angle_from_sun(sun_zenith: f64, sun_azimuth: f64, zenith: f64, azimuth: f64) -> f64 {
    (sun_zenith.cos() * zenith.cos() + sun_zenith.sin() * zenith.sin() * (azimuth - sun_azimuth).cos()).clamp(-1.0, 1.0)
}

fn any_perpendicular(n: DVec3) -> DVec3 {
    if n.x.abs() < 0.9 { DVec3::X.cross(n) } else { DVec3::Y.cross(n) }
}

#[cfg(test)]
mod tests;
