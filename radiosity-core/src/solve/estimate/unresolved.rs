//! The error that polygons left whole put into the others' means.

use super::receiver_polygons;

/// The error that polygons left whole put into the others' means, relative to the largest
/// non-emitting mean. A polygon that is a single element is the same on the coarser meshes of
/// [`richardson_estimate`](super::richardson_estimate), which then show nothing of it (Ward's room at `--eps 0.64`, every
/// polygon whole: a 7.6% error estimated at 0.001%), yet its radiosity is not uniform where its
/// irradiance is not. Its irradiance is taken from its chain of links at the centre and halfway
/// to each vertex ([`crate::formfactor::point_to_element`] times each link's visibility); half
/// its range, times the reflectance, is how far its radiosity departs from its mean, and each link
/// it sends passes that on to its receiver's mean with the link's form factor (the receiver's
/// share of its polygon's area; every polygon of a receiving cluster whole), times the
/// receiver's reflectance, and times half the spread `κ` of the kernel over the source seen
/// from the receiver ([`crate::refine::source_kernel_spread`]; whole for a link partly occluded,
/// whose kernel steps where the occluder's shadow ends): what departs from the mean reaches the
/// receiver only as far as the receiver weights the source unevenly (the covariance of radiosity
/// and kernel, each within its range, is at most the product of their half ranges), so that a
/// leaf's uneven light reaches the far ones of a canopy as a tenth of it. Per polygon and channel,
/// in W/m² of radiosity. A uniform field (a furnace) gives 0.
#[must_use]
pub fn unresolved_per_polygon(h: &crate::hierarchy::Hierarchy, links: &[crate::refine::Link], radiosity: &[[f64; 3]]) -> Vec<[f64; 3]> {
    use rayon::prelude::*;
    let n = h.n_polygons as usize;
    let by_receiver = super::super::by_receiver::LinksByReceiver::new(h, links);
    // Half the range of each whole polygon's radiosity, per channel (zero for subdivided ones).
    let spread: Vec<[f64; 3]> = (0..n)
        .into_par_iter()
        .map(|p| {
            let e = h.get(p as u32);
            let Some(poly) = e.poly().filter(|_| h.children_of(p as u32).is_empty()) else {
                return [0.0; 3];
            };
            let points = std::iter::once(e.center).chain(poly.vertices().iter().map(|&v| 0.5 * (v + e.center)));
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [0.0f64; 3]);
            for x in points {
                let mut irr = [0.0; 3];
                let mut a = p as u32;
                while a != crate::hierarchy::NONE {
                    for l in by_receiver.at(a) {
                        let f = crate::formfactor::point_to_element(h, x, e.normal, l.source).max(0.0) * l.vis;
                        let b = radiosity[l.source as usize];
                        for c in 0..3 {
                            irr[c] += f * b[c];
                        }
                    }
                    a = h.get(a).parent;
                }
                for c in 0..3 {
                    lo[c] = lo[c].min(irr[c]);
                    hi[c] = hi[c].max(irr[c]);
                }
            }
            std::array::from_fn(|c| 0.5 * h.reflectance[p][c] * (hi[c] - lo[c]).max(0.0))
        })
        .collect();
    // Each link from a whole polygon with its share of the spread (κ / 2, at most 1).
    let weights: Vec<f64> = links
        .par_iter()
        .map(|l| {
            let whole = h.get(l.source).polygon().is_some_and(|p| l.source == p && spread[p as usize] != [0.0; 3]);
            if !whole {
                0.0
            } else if l.vis < 1.0 {
                1.0
            } else {
                0.5 * crate::refine::source_kernel_spread(h, l.source, l.receiver)
            }
        })
        .collect();
    let mut err = vec![[0.0; 3]; n];
    for (l, &w) in links.iter().zip(&weights) {
        if w == 0.0 {
            continue;
        }
        let s = spread[l.source as usize];
        receiver_polygons(h, l.receiver, |q, share| {
            for c in 0..3 {
                err[q][c] += h.reflectance[q][c] * share * l.ff * l.vis * w * s[c];
            }
        });
    }
    err
}
