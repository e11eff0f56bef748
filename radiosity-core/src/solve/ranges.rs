//! What the next refinement pass reads of a solution ([`crate::refine::ElementData`]): each
//! element's radiosity, how much it varies over the element, and its irradiance reference.
//!
//! The variation over a leaf is measured at probe points (its centre and its corners pulled a
//! little toward it, as [`crate::formfactor::estimate_max`] probes): the irradiance there is
//! gathered from every link on the leaf's chain with the point form factor, and turned into
//! radiosity (`E + ρH + t·H̄`), and widened by the step a shadow edge of the direct light makes
//! where one crosses the leaf or its other side ([`crate::hierarchy::Hierarchy::direct_edge`]),
//! which the probes may all miss. A parent's range is the union of its children's. A source whose
//! radiosity does not vary (a lamp of uniform exitance, a furnace wall) needs no subdivision however
//! much light it sends: what the receiver gets from it is exact with the link's form factor.

use super::Solution;
use super::by_receiver::LinksByReceiver;
use crate::formfactor::{MAX_PROBE_PULL, point_to_element};
use crate::geom::DVec3;
use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::refine::{ElementData, IRRADIANCE_FLOOR_REL, Link, amplification};
use rayon::prelude::*;

/// Sources farther from a leaf than this many times the sum of their bounding radii light it
/// uniformly for the purpose of its radiosity range (their point form factor is evaluated once, at
/// the leaf's centre).
pub const PROBE_FAR_SEPARATION: f64 = 6.0;

/// Sources at least this far from a leaf (and nearer than [`PROBE_FAR_SEPARATION`]) are seen
/// from each probe as a point at their centre (the kernel times their area, within a few percent
/// of Lambert's formula there, and no arc tangents).
pub const PROBE_KERNEL_SEPARATION: f64 = 2.0;

/// The point form factor from `x` (normal `n`) to surface element `source` seen as a point at its
/// centre: `A cos θ_x cos θ_s / (π r²)`.
fn point_kernel(h: &Hierarchy, x: DVec3, n: DVec3, source: ElementId) -> f64 {
    let s = h.get(source);
    let d = s.center - x;
    let r2 = d.length_squared();
    if r2 <= 0.0 {
        return 0.0;
    }
    (s.area * n.dot(d).max(0.0) * (-s.normal.dot(d)).max(0.0) / (std::f64::consts::PI * r2 * r2)).min(1.0)
}

/// Radiosity ranges and irradiance references of every element of `h` for the solution `sol` of
/// `links`.
#[must_use]
pub fn element_data(h: &Hierarchy, links: &[Link], sol: &Solution) -> ElementData {
    let n = h.len();
    let index = LinksByReceiver::new(h, links);
    let leaves: Vec<ElementId> = h.leaves().collect();
    let leaf_ranges: Vec<([f64; 3], [f64; 3])> = leaves.par_iter().map(|&leaf| leaf_range(h, &index, sol, leaf)).collect();
    let mut lo = vec![[f64::INFINITY; 3]; n];
    let mut hi = vec![[f64::NEG_INFINITY; 3]; n];
    let mut irradiance = vec![f64::INFINITY; n];
    let (mut h_sum, mut area) = (0.0, 0.0);
    for (&leaf, &(l, u)) in leaves.iter().zip(&leaf_ranges) {
        lo[leaf as usize] = l;
        hi[leaf as usize] = u;
        // What the leaf receives in all: the links' light and the luminaires' and distant
        // sources' direct light, which the user reads in the same number.
        let direct = h.direct.get(leaf as usize).copied().unwrap_or_default();
        let hl = max3(std::array::from_fn(|c| sol.irradiance[leaf as usize][c] + direct[c]));
        irradiance[leaf as usize] = hl;
        let a = h.get(leaf).area;
        h_sum += a * hl;
        area += a;
    }
    // Parents from children: reverse breadth-first order visits children first.
    let mut order = vec![h.root];
    let mut i = 0;
    while i < order.len() {
        order.extend_from_slice(h.children_of(order[i]));
        i += 1;
    }
    for &e in order.iter().rev() {
        let kids = h.children_of(e);
        if kids.is_empty() {
            continue;
        }
        let mut mean = 0.0;
        for &k in kids {
            for c in 0..3 {
                lo[e as usize][c] = lo[e as usize][c].min(lo[k as usize][c]);
                hi[e as usize][c] = hi[e as usize][c].max(hi[k as usize][c]);
            }
            mean += h.get(k).area * irradiance[k as usize];
        }
        irradiance[e as usize] = mean / h.get(e).area.max(f64::MIN_POSITIVE);
    }
    let variation = lo.iter().zip(&hi).map(|(l, u)| (0..3).map(|c| u[c] - l[c]).fold(0.0, f64::max).max(0.0)).collect();
    // Elements outside the tree (none in practice) read 0.
    let irradiance = irradiance.into_iter().map(|x| if x.is_finite() { x } else { 0.0 }).collect();
    let mean = if area > 0.0 { h_sum / area } else { 0.0 };
    let amplification = amplification(leaves.iter().map(|&l| {
        let e = h.get(l);
        (e.area, sol.radiosity[l as usize], h.emission_of(l))
    }));
    ElementData {
        radiosity: sol.radiosity.clone(),
        variation,
        irradiance,
        irradiance_floor: IRRADIANCE_FLOOR_REL * mean,
        amplification,
        importance: Vec::new(),
    }
}

/// What the value of a leaf would move by were the links to it refined further, beyond what
/// splitting each link's source once shows: the splits that follow add about as much again (each
/// finer split sees about half the radiosity difference of the one before, over pieces as near).
pub const VALUE_SERIES_FACTOR: f64 = 2.0;

/// Per element, how far a leaf's radiosity may be from what it would be were the sources of its
/// links resolved (0 for every other element), W/m². Over the links to the leaf and to its
/// ancestors: a source with children gives the leaf's centre, through the link's visibility, its
/// children's radiosity instead of its mean (point form factors to each child), and the change
/// from the mean's light is what one split of the link would show; times
/// [`VALUE_SERIES_FACTOR`]. A source without children adds half its radiosity range (`variation`,
/// see [`element_data`]) times its light times how much the kernel varies over it
/// ([`crate::formfactor::kernel_variation`]). The sum over the links times the leaf's reflectance
/// (largest channel). A link from a large, near source of uneven radiosity makes a leaf's value
/// uncertain where the polygon's mean is not: the corner of a room, whose wall gets its light
/// from a ceiling element lit unevenly. What calculation points read of such leaves
/// ([`crate::points::PointGather`]) and what importance refines ([`crate::pipeline::run_with_points`]).
#[must_use]
pub fn leaf_value_errors(h: &Hierarchy, links: &[Link], radiosity: &[[f64; 3]], variation: &[f64]) -> Vec<f64> {
    let index = LinksByReceiver::new(h, links);
    let leaves: Vec<ElementId> = h.leaves().collect();
    let errors: Vec<f64> = leaves
        .par_iter()
        .map(|&leaf| {
            let e = h.get(leaf);
            let Some(p) = e.polygon() else { return 0.0 };
            let rho = h.reflectance[p as usize].iter().copied().fold(0.0, f64::max);
            if rho <= 0.0 {
                return 0.0;
            }
            let mut sum = 0.0;
            let mut a = leaf;
            while a != NONE {
                for l in index.at(a) {
                    if l.vis <= 0.0 {
                        continue;
                    }
                    let s = h.get(l.source);
                    let children = h.children_of(l.source);
                    if children.is_empty() {
                        let dv = variation.get(l.source as usize).copied().unwrap_or(0.0);
                        if dv > 0.0 {
                            let spread = s
                                .poly()
                                .map_or(1.0, |q| crate::formfactor::kernel_variation(e.center, e.normal, s.normal, s.center, q.vertices()));
                            sum += point_to_element(h, e.center, e.normal, l.source).max(0.0) * l.vis * 0.5 * dv * spread;
                        }
                        continue;
                    }
                    // A far source is seen as its mean: its children's light differs from it by
                    // what their kernels differ, next to nothing.
                    let separation = (s.center - e.center).length() / (s.radius + e.radius).max(f64::MIN_POSITIVE);
                    if separation >= PROBE_FAR_SEPARATION {
                        continue;
                    }
                    let mean = radiosity[l.source as usize];
                    let mut change = [0.0; 3];
                    for &k in children {
                        let c = h.get(k);
                        let f = if (c.center - e.center).length() >= PROBE_KERNEL_SEPARATION * (c.radius + e.radius) && c.poly().is_some() {
                            point_kernel(h, e.center, e.normal, k)
                        } else {
                            point_to_element(h, e.center, e.normal, k).max(0.0)
                        } * l.vis;
                        for c in 0..3 {
                            change[c] += f * (radiosity[k as usize][c] - mean[c]);
                        }
                    }
                    sum += VALUE_SERIES_FACTOR * change.iter().map(|v| v.abs()).fold(0.0, f64::max);
                }
                a = h.get(a).parent;
            }
            rho * sum
        })
        .collect();
    let mut out = vec![0.0; h.len()];
    for (&leaf, err) in leaves.iter().zip(errors) {
        out[leaf as usize] = err;
    }
    out
}

fn max3(v: [f64; 3]) -> f64 {
    v[0].max(v[1]).max(v[2])
}

/// The smallest and largest radiosity (per channel) over `leaf`: at its probe points and its mean.
fn leaf_range(h: &Hierarchy, index: &LinksByReceiver<'_>, sol: &Solution, leaf: ElementId) -> ([f64; 3], [f64; 3]) {
    let e = h.get(leaf);
    let mean = sol.radiosity[leaf as usize];
    let (mut lo, mut hi) = (mean, mean);
    let (Some(poly), Some(p)) = (e.poly(), e.polygon()) else { return (lo, hi) };
    let p = p as usize;
    let (rho, em, t, mate) = (h.reflectance[p], h.emission_of(leaf), h.transmittance[p], h.mate(leaf));
    let through = if mate == NONE { [0.0; 3] } else { sol.irradiance[mate as usize] };
    let mut probes = [DVec3::ZERO; 5];
    probes[0] = e.center;
    let vs = poly.vertices();
    for (k, v) in vs.iter().enumerate() {
        probes[k + 1] = *v + MAX_PROBE_PULL * (e.center - *v);
    }
    let probes = &probes[..vs.len() + 1];
    // Far sources light the leaf nearly uniformly: their share, taken at the centre, is the same at
    // every probe; near ones are evaluated at each.
    let mut uniform = [0.0; 3];
    let mut near: Vec<(ElementId, f64, bool)> = Vec::new();
    let mut a = leaf;
    while a != NONE {
        for l in index.at(a) {
            let s = h.get(l.source);
            let b = sol.radiosity[l.source as usize];
            let separation = (s.center - e.center).length() / (s.radius + e.radius).max(f64::MIN_POSITIVE);
            if separation >= PROBE_FAR_SEPARATION {
                let f = point_to_element(h, e.center, e.normal, l.source) * l.vis;
                for c in 0..3 {
                    uniform[c] += f * b[c];
                }
            } else {
                near.push((l.source, l.vis, separation >= PROBE_KERNEL_SEPARATION && s.poly().is_some()));
            }
        }
        a = h.get(a).parent;
    }
    for &x in probes {
        let mut hx = uniform;
        for &(source, vis, kernel) in &near {
            let f = if kernel { point_kernel(h, x, e.normal, source) } else { point_to_element(h, x, e.normal, source) } * vis;
            let b = sol.radiosity[source as usize];
            for c in 0..3 {
                hx[c] += f * b[c];
            }
        }
        for c in 0..3 {
            let bx = em[c] + rho[c] * hx[c] + t[c] * through[c];
            lo[c] = lo[c].min(bx);
            hi[c] = hi[c].max(bx);
        }
    }
    // A shadow boundary across the leaf, or across its other side, steps its direct light, and
    // its reflection and transmission with it, where the probes may not see it.
    let edge = |x: ElementId| h.direct_edge.get(x as usize).copied().unwrap_or_default();
    let (own, other) = (edge(leaf), if mate == NONE { [0.0; 3] } else { edge(mate) });
    for c in 0..3 {
        hi[c] = hi[c].max(lo[c] + rho[c] * own[c] + t[c] * other[c]);
    }
    (lo, hi)
}
