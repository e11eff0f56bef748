//! Where the sun is (given, or from a place and a time) and the site's frame: which way is up
//! and which is north.

use super::{DaylightError, DistantSource, check_levels};
use crate::geom::DVec3;

/// Where the sun is, as the scene file gave it or as computed.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SunReport {
    /// Unit direction the light travels.
    pub toward: [f64; 3],
    /// Zenith angle (degrees).
    pub zenith_deg: f64,
    /// Azimuth (degrees clockwise from north), when computed from place and time.
    pub azimuth_deg: Option<f64>,
    /// Whether it is above the horizon (below, it gives no light).
    pub above_horizon: bool,
}

/// Which way is up and which is north in the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Site {
    /// Unit zenith direction.
    pub up: DVec3,
    /// Unit direction of north, perpendicular to `up`.
    pub north: DVec3,
}

impl Default for Site {
    fn default() -> Site {
        Site { up: DVec3::Z, north: DVec3::Y }
    }
}

impl Site {
    /// A site from any non-parallel `up` and `north` (north is made perpendicular to up).
    pub fn new(up: DVec3, north: DVec3) -> Result<Site, DaylightError> {
        let up_len = up.length();
        if !up_len.is_finite() || up_len <= 0.0 {
            return Err(DaylightError(format!("`up` {up} is not a direction")));
        }
        let up = up / up_len;
        let north = north - up * up.dot(north);
        let n_len = north.length();
        if !n_len.is_finite() || n_len <= 1e-9 {
            return Err(DaylightError(format!("`north` {north} is not a direction across `up`")));
        }
        Ok(Site { up, north: north / n_len })
    }

    /// East: north × up.
    #[must_use]
    pub fn east(&self) -> DVec3 {
        self.north.cross(self.up)
    }

    /// A direction given in the site's frame (x east, y north, z up) in the scene's frame.
    #[must_use]
    pub fn world(&self, d: DVec3) -> DVec3 {
        self.east() * d.x + self.north * d.y + self.up * d.z
    }

    /// The unit direction toward a point of the sky at zenith angle `zenith` and azimuth
    /// `azimuth` (radians, clockwise from north seen from above: east is π/2).
    #[must_use]
    pub fn direction(&self, zenith: f64, azimuth: f64) -> DVec3 {
        let (sz, cz) = zenith.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        (self.east() * (sz * sa) + self.north * (sz * ca) + self.up * cz).normalize()
    }
}

/// Where the sun is seen from a place at a time: `(zenith, azimuth)` in degrees (azimuth clockwise
/// from north), by the `spa` crate. `time` is RFC 3339 (`2026-06-21T12:00:00+02:00`).
pub fn sun_position(latitude: f64, longitude: f64, time: &str) -> Result<(f64, f64), DaylightError> {
    let t = chrono::DateTime::parse_from_rfc3339(time)
        .map_err(|e| DaylightError(format!("time `{time}` is not RFC 3339 ({e}), e.g. 2026-06-21T12:00:00+02:00")))?;
    if !(-90.0..=90.0).contains(&latitude) || !(-180.0..=180.0).contains(&longitude) {
        return Err(DaylightError(format!("latitude {latitude} / longitude {longitude} out of range (-90..90, -180..180 degrees)")));
    }
    let pos = spa::solar_position::<spa::StdFloatOps>(t.with_timezone(&chrono::Utc), latitude, longitude)
        .map_err(|e| DaylightError(format!("solar position: {e:?}")))?;
    Ok((pos.zenith_angle, pos.azimuth))
}

/// The sun as a distant source: light traveling along `toward`, `direct_normal` on a plane facing
/// it. A sun at or below the horizon (`toward` not downward) gives no source.
pub fn sun(toward: DVec3, direct_normal: [f64; 3], site: &Site) -> Result<Option<DistantSource>, DaylightError> {
    let len = toward.length();
    if !len.is_finite() || len <= 0.0 {
        return Err(DaylightError(format!("sun direction {toward} is not a direction")));
    }
    check_levels("direct_normal", &direct_normal)?;
    let toward = toward / len;
    Ok((toward.dot(site.up) < 0.0).then_some(DistantSource { toward, irradiance: direct_normal, sharp: true, patch: None }))
}
