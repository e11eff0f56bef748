//! The sky's radiance models and its cells of equal solid angle, each cell one distant source;
//! the same cells as the hemisphere through which the light leaving a surface is followed.

use super::cie_general::CieSky;
use super::perez::PerezSky;
use super::{DaylightError, DistantSource, Site, check_levels};
use crate::geom::DVec3;
use crate::light::SkyPatch;

/// Radiance distribution of the sky over its hemisphere.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SkyModel {
    /// The same radiance everywhere.
    Uniform,
    /// CIE standard overcast sky: `L(θ) = L_z (1 + 2 cos θ) / 3`.
    CieOvercast,
    /// One of the 15 CIE standard general skies, with the sun's position ([`CieSky`]).
    CieGeneral(CieSky),
    /// The Perez all-weather sky, with the sun's position ([`PerezSky`]).
    Perez(PerezSky),
}

impl SkyModel {
    /// `∫ L(μ) μ dμ` (k = 1) or `∫ L(μ) √(1 − μ²) dμ` (k = 2) from 0 to `mu` (μ = cos θ, L
    /// relative to the zenith's): the vertical and horizontal parts of a ring's light vector.
    fn moment(self, mu: f64, k: u32) -> f64 {
        let root = (1.0 - mu * mu).max(0.0).sqrt();
        let half_disc = 0.5 * (mu * root + mu.clamp(-1.0, 1.0).asin());
        match (self, k) {
            (SkyModel::Uniform, 1) => mu * mu / 2.0,
            (SkyModel::Uniform, _) => half_disc,
            (SkyModel::CieOvercast, 1) => (mu * mu / 2.0 + 2.0 * mu.powi(3) / 3.0) / 3.0,
            (SkyModel::CieOvercast, _) => (half_disc + 2.0 * (1.0 - root.powi(3)) / 3.0) / 3.0,
            (SkyModel::CieGeneral(_) | SkyModel::Perez(_), _) => unreachable!("these skies' cells are integrated numerically"),
        }
    }
}

/// One cell of the sky's hemisphere: cos θ from `mu_low` to `mu_high`, azimuth from `phi_start`
/// over `phi_width` (radians, clockwise from north).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyCell {
    /// cos θ at the cell's lower (horizon-side) edge.
    pub mu_low: f64,
    /// cos θ at its upper edge (1 for the zenith cap).
    pub mu_high: f64,
    /// Azimuth where the cell starts.
    pub phi_start: f64,
    /// Azimuth width (2π for the zenith cap).
    pub phi_width: f64,
}

/// Rings of the 46-cell sky, zenith first (cells per ring).
pub const RINGS_46: [u32; 5] = [1, 5, 10, 15, 15];
/// Rings of the 145-cell sky, zenith first.
pub const RINGS_145: [u32; 7] = [1, 8, 16, 24, 32, 32, 32];

/// The upper hemisphere split into `n` cells of equal solid angle (2π/n each), in rings about the
/// zenith: 46 and 145 use [`RINGS_46`] and [`RINGS_145`] (cells near square); other counts use
/// rings of 1, 8, 16, 24, ... cells, the last ring taking what is left.
pub fn sky_cells(n: u32) -> Result<Vec<SkyCell>, DaylightError> {
    if n == 0 || n > 100_000 {
        return Err(DaylightError(format!("sky directions {n}: give 1 to 100000 (46 or 145 are the usual)")));
    }
    let rings: Vec<u32> = match n {
        46 => RINGS_46.to_vec(),
        145 => RINGS_145.to_vec(),
        _ => {
            let mut rings = vec![1];
            let mut total = 1;
            let mut k = 1;
            while total < n {
                let c = (8 * k).min(n - total);
                rings.push(c);
                total += c;
                k += 1;
            }
            rings
        }
    };
    let mut cells = Vec::with_capacity(n as usize);
    let mut done = 0u32;
    for (r, &count) in rings.iter().enumerate() {
        let mu_high = 1.0 - f64::from(done) / f64::from(n);
        done += count;
        let mu_low = if done == n { 0.0 } else { 1.0 - f64::from(done) / f64::from(n) };
        let width = std::f64::consts::TAU / f64::from(count);
        // Alternate rings are staggered by half a cell.
        let offset = if r % 2 == 0 { 0.0 } else { 0.5 * width };
        for i in 0..count {
            cells.push(SkyCell { mu_low, mu_high, phi_start: offset + width * f64::from(i), phi_width: width });
        }
    }
    Ok(cells)
}

/// The sky as `n` distant sources (see [`sky_cells`]) under `model`, delivering
/// `diffuse_horizontal` (W/m² per channel) to an unobstructed horizontal plane: each cell's light
/// vector in closed form for the uniform and overcast skies, by quadrature for a CIE general or
/// a Perez sky.
pub fn sky(model: SkyModel, diffuse_horizontal: [f64; 3], n: u32, site: &Site) -> Result<Vec<DistantSource>, DaylightError> {
    check_levels("diffuse_horizontal", &diffuse_horizontal)?;
    let cells = sky_cells(n)?;
    match model {
        SkyModel::CieGeneral(general) => return Ok(general.sources(&cells, diffuse_horizontal, site)),
        SkyModel::Perez(perez) => return Ok(perez.sources(&cells, diffuse_horizontal, site)),
        SkyModel::Uniform | SkyModel::CieOvercast => {}
    }
    let weights: Vec<f64> = cells.iter().map(|c| c.phi_width * (model.moment(c.mu_high, 1) - model.moment(c.mu_low, 1))).collect();
    let total: f64 = weights.iter().sum();
    Ok(cells
        .iter()
        .zip(&weights)
        .map(|(c, &w)| {
            // The cell's light vector ∫ L ω dω: its vertical part is `w`, its horizontal part
            // points to the cell's middle azimuth. A plane that sees the whole cell receives
            // exactly the vector's projection on its normal.
            let horizontal = 2.0 * (0.5 * c.phi_width).sin() * (model.moment(c.mu_high, 2) - model.moment(c.mu_low, 2));
            let magnitude = w.hypot(horizontal);
            let zenith = horizontal.atan2(w);
            let azimuth = c.phi_start + 0.5 * c.phi_width;
            let toward = -site.direction(zenith, azimuth);
            let scale = magnitude / total;
            cell_source(c, toward, diffuse_horizontal.map(|e| e * scale), site)
        })
        .collect())
}

/// Sky cell `cell` as a distant source whose light travels along `toward` with `irradiance` on a
/// plane facing it, with its patch of sky.
pub(super) fn cell_source(cell: &SkyCell, toward: DVec3, irradiance: [f64; 3], site: &Site) -> DistantSource {
    let frame = [site.east(), site.north, site.up];
    let patch = SkyPatch::new(frame, [cell.mu_low, cell.mu_high], [cell.phi_start, cell.phi_width], toward, irradiance);
    DistantSource { toward, irradiance, sharp: false, patch: Some(patch) }
}

/// Cells of the hemisphere about a surface's normal through which [`power_leaving`](super::power_leaving) looks.
pub const ESCAPE_CELLS: u32 = 145;

/// The [`ESCAPE_CELLS`] directions of a hemisphere about +z with their cosine weights (summing to
/// 1), for [`power_leaving`](super::power_leaving).
#[must_use]
pub fn escape_cells() -> Vec<(DVec3, f64)> {
    let site = Site::default();
    let sources = sky(SkyModel::Uniform, [1.0; 3], ESCAPE_CELLS, &site).expect("a valid cell count");
    sources.iter().map(|s| (-s.toward, s.irradiance[0] * (-s.toward.z))).map(|(d, w)| (DVec3::new(d.x, d.y, d.z), w)).collect()
}
