//! The error the closure of a closed scene may leave: where the light it restores lands.

use super::{receiver_polygons, worst_relative};

/// The error the closure of a closed scene may leave ([`super::LeafCoefficients::closure`](crate::solve::LeafCoefficients::closure)): it
/// scales each source's links so that they deliver its light whole, which corrects how much light
/// arrives in all but not where it lands (CIE 171 case 5.8 at eps 0.0025: links 5.5e-4 short,
/// 4.5e-5 off after the closure, in opposite signs on different walls). Each link's change,
/// `|factor − 1| F V B_S` at its receiver, is counted whole as a possible error of where it landed,
/// summed over each polygon (weighted by the share of its area the receiver covers); relative to
/// the largest non-emitting mean as [`visibility_noise`](super::visibility_noise) is: the radiosity through the
/// reflectance and, with `irradiance`, the mean irradiance itself. 0 in an open scene (`changes`
/// empty); `changes` per link, as [`super::LeafCoefficients::closure_changes`](crate::solve::LeafCoefficients::closure_changes) gives them.
#[must_use]
pub fn closure_error(
    h: &crate::hierarchy::Hierarchy,
    links: &[crate::refine::Link],
    changes: &[f32],
    radiosity: &[[f64; 3]],
    irradiance: Option<&[[f64; 3]]>,
) -> f64 {
    if changes.is_empty() {
        return 0.0;
    }
    let mut moved = vec![[0.0; 3]; h.n_polygons as usize];
    for (l, &change) in links.iter().zip(changes) {
        let m = f64::from(change).abs() * l.ff * l.vis;
        if m == 0.0 {
            continue;
        }
        let b = radiosity[l.source as usize];
        receiver_polygons(h, l.receiver, |p, share| {
            for c in 0..3 {
                moved[p][c] += share * m * b[c];
            }
        });
    }
    let of_radiosity = worst_relative(h, radiosity, |p, c| h.reflectance[p][c] * moved[p][c]);
    let of_irradiance = irradiance.map_or(0.0, |means| worst_relative(h, means, |p, c| moved[p][c]));
    of_radiosity.max(of_irradiance)
}
