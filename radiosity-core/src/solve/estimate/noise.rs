//! The noise that visibility sampling leaves in each polygon's mean, which no mesh change shows.

use super::{receiver_polygons, worst_relative};

/// How many standard deviations of visibility-sampling noise the estimate covers.
pub const NOISE_SIGMAS: f64 = 1.0;

/// The error that visibility sampling leaves in each polygon's mean radiosity, relative to the
/// largest non-emitting mean: a link whose segments ([`crate::refine::Link::rays`]) found it partly occluded has a
/// visibility of standard error `√(V (1 − V) / rays)`, which moves its receiver's irradiance by
/// `B_S F` times that; independent links add in quadrature over a polygon (each weighted by the
/// share of the polygon's area its receiver covers), and the reflectance turns irradiance into
/// radiosity. [`NOISE_SIGMAS`] standard deviations, largest over the non-emitting polygons.
/// With `irradiance` (the polygons' mean irradiance, under the irradiance criterion) the same
/// noise in each mean irradiance counts too (no reflectance turns it into radiosity: a black
/// receiver's is counted), relative to the largest non-emitting mean irradiance; the larger of
/// the two is returned.
#[must_use]
pub fn visibility_noise(
    h: &crate::hierarchy::Hierarchy,
    links: &[crate::refine::Link],
    radiosity: &[[f64; 3]],
    irradiance: Option<&[[f64; 3]]>,
) -> f64 {
    worst_noise(h, &noise_per_polygon(h, links, radiosity), radiosity, irradiance)
}

/// [`NOISE_SIGMAS`] standard deviations of each polygon's mean irradiance from visibility
/// sampling, per channel, in W/m² (what [`visibility_noise`] takes the largest of).
#[must_use]
pub fn noise_per_polygon(h: &crate::hierarchy::Hierarchy, links: &[crate::refine::Link], radiosity: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let n = h.n_polygons as usize;
    let mut var = vec![[0.0; 3]; n];
    for l in links {
        if l.vis <= 0.0 || l.vis >= 1.0 {
            continue;
        }
        let sd = (l.vis * (1.0 - l.vis) / f64::from(l.rays.max(1))).sqrt() * l.ff;
        let b = radiosity[l.source as usize];
        receiver_polygons(h, l.receiver, |p, share| {
            for c in 0..3 {
                var[p][c] += (share * sd * b[c]).powi(2);
            }
        });
    }
    var.into_iter().map(|v| v.map(|x| NOISE_SIGMAS * x.sqrt())).collect()
}

/// [`visibility_noise`] from the polygons' noise ([`noise_per_polygon`]).
#[must_use]
pub fn worst_noise(h: &crate::hierarchy::Hierarchy, noise: &[[f64; 3]], radiosity: &[[f64; 3]], irradiance: Option<&[[f64; 3]]>) -> f64 {
    let of_radiosity = worst_relative(h, radiosity, |p, c| h.reflectance[p][c] * noise[p][c]);
    let of_irradiance = irradiance.map_or(0.0, |means| worst_relative(h, means, |p, c| noise[p][c]));
    of_radiosity.max(of_irradiance)
}
