//! Final gather at leaf resolution: once the hierarchical system is solved, every leaf gathers again
//! from every link at itself and at its ancestors, with the form factor evaluated for the leaf itself
//! instead of the ancestor's average. This removes the piecewise-constant error of links attached high
//! in the hierarchy (largest at edges and corners, where the receiver touches its sources) at the cost
//! of one pass over each leaf's chain of links.

use crate::hierarchy::{ElementId, Hierarchy};
use crate::refine::Link;
use rayon::prelude::*;

/// Recomputes leaf irradiance and radiosity from `radiosity` (per element, converged), returning new
/// per-element `(radiosity, irradiance)`; inner elements get area-weighted means.
#[must_use]
pub fn final_gather(h: &Hierarchy, links: &[Link], radiosity: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let n = h.len();
    let index = super::by_receiver::LinksByReceiver::new(h, links);
    let leaves: Vec<ElementId> = h.leaves().collect();
    let gathered: Vec<[f64; 3]> = leaves
        .par_iter()
        .map(|&leaf| {
            let mut acc = [0.0; 3];
            index.leaf_chain(h, leaf, |source, f| {
                let b = radiosity[source as usize];
                for c in 0..3 {
                    acc[c] += f * b[c];
                }
            });
            acc
        })
        .collect();
    let mut b = radiosity.to_vec();
    let mut irr = vec![[0.0; 3]; n];
    for (&leaf, g) in leaves.iter().zip(&gathered) {
        irr[leaf as usize] = *g;
    }
    // Inner elements: area-weighted means, children before parents (reverse breadth-first order).
    let order = top_down(h);
    area_means(h, &order, &mut irr);
    for (&leaf, g) in leaves.iter().zip(gathered) {
        let p = h.get(leaf).polygon().expect("leaves are surfaces") as usize;
        // A transmitting side passes on the light of its other side.
        let q = h.mate(leaf);
        let through = if q == crate::hierarchy::NONE { [0.0; 3] } else { irr[q as usize] };
        let em = h.emission_of(leaf);
        b[leaf as usize] = std::array::from_fn(|c| em[c] + h.reflectance[p][c] * g[c] + h.transmittance[p][c] * through[c]);
    }
    area_means(h, &order, &mut b);
    (b, irr)
}

/// Every element of `h`, parents before children (breadth-first from the root).
#[must_use]
pub fn top_down(h: &Hierarchy) -> Vec<ElementId> {
    let mut order = Vec::with_capacity(h.len());
    order.push(h.root);
    let mut i = 0;
    while i < order.len() {
        order.extend_from_slice(h.children_of(order[i]));
        i += 1;
    }
    order
}

/// Sets every inner element of `order` (parents before children) to the area-weighted mean of its
/// children (children first: `order` is walked backwards).
pub fn area_means(h: &Hierarchy, order: &[ElementId], values: &mut [[f64; 3]]) {
    for &e in order.iter().rev() {
        let kids = h.children_of(e);
        if kids.is_empty() {
            continue;
        }
        let mut acc = [0.0; 3];
        let mut area = 0.0;
        for &k in kids {
            let a = h.get(k).area;
            for c in 0..3 {
                acc[c] += a * values[k as usize][c];
            }
            area += a;
        }
        if area > 0.0 {
            values[e as usize] = acc.map(|v| v / area);
        }
    }
}
