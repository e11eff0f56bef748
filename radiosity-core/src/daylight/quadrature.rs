//! A sky cell's light vector under a luminance distribution given as a function, and the cells as
//! distant sources scaled to a diffuse horizontal irradiance: what the skies whose cells have no
//! closed form (the CIE general skies, the Perez all-weather sky) share.
//!
//! The light vector `∫ L ω dω` is a Gauss–Legendre quadrature over the cell in zenith angle and
//! azimuth, 8 × 8 nodes: the luminance distributions are smooth over a cell (145 cells light
//! vertical planes within 0.6% of a fine integration, `daylight/tests.rs`).

use super::{DistantSource, Site, SkyCell};

/// 8-point Gauss–Legendre nodes and weights on `[−1, 1]` (positive half; the rule is symmetric).
const GL8: [(f64, f64); 4] = [
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// The light vector `∫ L ω dω` of `cell` in the site's frame (x east, y north, z up), for the
/// luminance `luminance(zenith, azimuth)` (radians, azimuth clockwise from north).
pub(super) fn light_vector(cell: &SkyCell, luminance: impl Fn(f64, f64) -> f64) -> [f64; 3] {
    let (t0, t1) = (cell.mu_high.clamp(-1.0, 1.0).acos(), cell.mu_low.clamp(-1.0, 1.0).acos());
    let (tm, th) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
    let (pm, ph) = (cell.phi_start + 0.5 * cell.phi_width, 0.5 * cell.phi_width);
    let nodes = GL8.iter().flat_map(|&(x, w)| [(-x, w), (x, w)]);
    let mut v = [0.0; 3];
    for (x, wx) in nodes.clone() {
        let theta = tm + th * x;
        let (st, ct) = theta.sin_cos();
        for (y, wy) in nodes.clone() {
            let phi = pm + ph * y;
            let (sp, cp) = phi.sin_cos();
            let w = wx * wy * th * ph * st * luminance(theta, phi);
            v[0] += w * st * sp;
            v[1] += w * st * cp;
            v[2] += w * ct;
        }
    }
    v
}

/// The cells of light vectors `vectors` as distant sources delivering `diffuse_horizontal` to an
/// unobstructed horizontal plane (see [`super::sky`]), each with its patch of sky.
pub(super) fn scaled_sources(cells: &[SkyCell], vectors: &[[f64; 3]], diffuse_horizontal: [f64; 3], site: &Site) -> Vec<DistantSource> {
    let total: f64 = vectors.iter().map(|v| v[2]).sum();
    cells
        .iter()
        .zip(vectors)
        .map(|(cell, v)| {
            let magnitude = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let zenith = v[0].hypot(v[1]).atan2(v[2]);
            let azimuth = v[0].atan2(v[1]);
            let scale = magnitude / total;
            super::sky::cell_source(cell, -site.direction(zenith, azimuth), diffuse_horizontal.map(|e| e * scale), site)
        })
        .collect()
}
