//! The hierarchical transport operator: pull, gather, push.

use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::refine::Link;
use rayon::prelude::*;

/// Precomputed traversal orders and link groups of a hierarchy.
pub struct Operator<'a> {
    h: &'a Hierarchy,
    /// Elements, parents before children (breadth-first from the root).
    order: Vec<ElementId>,
    /// Leaf elements, in `order` order.
    leaves: Vec<ElementId>,
    /// Leaf index per element (NONE for inner elements).
    leaf_index: Vec<u32>,
    /// Links sorted by receiver, then source.
    links: Vec<(ElementId, f64)>,
    /// Receivers with links and their range in `links`.
    groups: Vec<(ElementId, u32, u32)>,
    /// Leaf reflectance and emission, interleaved RGB.
    rho: Vec<f64>,
    emission: Vec<f64>,
    /// Per leaf: transmittance and the other side's piece at the same place ([`Hierarchy::mate`]);
    /// empty when no leaf transmits.
    through: Vec<([f64; 3], ElementId)>,
    /// Scratch: per-element radiosity and irradiance (interior mutability avoided: rebuilt each call).
    n: usize,
}

impl<'a> Operator<'a> {
    /// Prepares the operator for `h` and `links`.
    #[must_use]
    pub fn new(h: &'a Hierarchy, links: &[Link]) -> Operator<'a> {
        let n = h.len();
        let mut order = Vec::with_capacity(n);
        order.push(h.root);
        let mut i = 0;
        while i < order.len() {
            let e = order[i];
            order.extend_from_slice(h.children_of(e));
            i += 1;
        }
        let mut leaf_index = vec![NONE; n];
        let mut leaves = Vec::new();
        for &e in &order {
            if h.get(e).n_children == 0 {
                leaf_index[e as usize] = leaves.len() as u32;
                leaves.push(e);
            }
        }
        let mut sorted: Vec<&Link> = links.iter().collect();
        sorted.sort_by_key(|l| (l.receiver, l.source));
        let mut groups = Vec::new();
        let mut packed = Vec::with_capacity(sorted.len());
        for (k, l) in sorted.iter().enumerate() {
            if k == 0 || sorted[k - 1].receiver != l.receiver {
                groups.push((l.receiver, k as u32, k as u32));
            }
            groups.last_mut().expect("pushed above").2 = k as u32 + 1;
            packed.push((l.source, l.ff * l.vis));
        }
        let mut rho = Vec::with_capacity(3 * leaves.len());
        let mut emission = Vec::with_capacity(3 * leaves.len());
        for &e in &leaves {
            let poly = h.get(e).polygon().expect("leaves are surfaces") as usize;
            rho.extend_from_slice(&h.reflectance[poly]);
            emission.extend_from_slice(&h.emission_of(e));
        }
        let mut through: Vec<([f64; 3], ElementId)> = leaves
            .iter()
            .map(|&e| {
                let p = h.get(e).polygon().expect("leaves are surfaces") as usize;
                (h.transmittance[p], h.mate(e))
            })
            .collect();
        if through.iter().all(|(_, q)| *q == NONE) {
            through.clear();
        }
        Operator { h, order, leaves, leaf_index, links: packed, groups, rho, emission, through, n }
    }

    /// Number of unknowns (3 per leaf).
    #[must_use]
    pub fn len(&self) -> usize {
        3 * self.leaves.len()
    }

    /// True when there is no leaf.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.leaves.is_empty()
    }

    /// Leaf elements in unknown order.
    #[must_use]
    pub fn leaves(&self) -> &[ElementId] {
        &self.leaves
    }

    /// Leaf index of element `e`, if a leaf.
    #[must_use]
    pub fn leaf_index(&self, e: ElementId) -> Option<usize> {
        let i = self.leaf_index[e as usize];
        (i != NONE).then_some(i as usize)
    }

    /// Emission of the leaves (the right-hand side).
    #[must_use]
    pub fn emission(&self) -> Vec<f64> {
        self.emission.clone()
    }

    /// Leaf vector read from a per-element array.
    #[must_use]
    pub fn leaves_from_elements(&self, per_element: &[[f64; 3]]) -> Vec<f64> {
        let mut x = Vec::with_capacity(self.len());
        for &e in &self.leaves {
            x.extend_from_slice(per_element.get(e as usize).unwrap_or(&[0.0; 3]));
        }
        x
    }

    /// Radiosity of every element (pulled) and irradiance of every element (pushed) for leaf values `x`.
    #[must_use]
    pub fn expand(&self, x: &[f64]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let b = self.pull(x);
        let gathered = self.gather(&b);
        let hsum = self.push(&gathered);
        (b, hsum)
    }

    /// The hierarchy.
    #[must_use]
    pub fn hierarchy(&self) -> &'a Hierarchy {
        self.h
    }

    /// Leaf reflectance, interleaved RGB in unknown order.
    #[must_use]
    pub fn reflectance(&self) -> &[f64] {
        &self.rho
    }

    /// Per-element values from leaf values `x`: leaves copied, inner elements the area-weighted mean
    /// of their children.
    #[must_use]
    pub fn pull(&self, x: &[f64]) -> Vec<[f64; 3]> {
        let mut b = vec![[0.0; 3]; self.n];
        for (i, &e) in self.leaves.iter().enumerate() {
            b[e as usize] = [x[3 * i], x[3 * i + 1], x[3 * i + 2]];
        }
        super::final_gather::area_means(self.h, &self.order, &mut b);
        b
    }

    fn gather(&self, b: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let sums: Vec<[f64; 3]> = self
            .groups
            .par_iter()
            .map(|&(_, lo, hi)| {
                let mut acc = [0.0; 3];
                for &(s, f) in &self.links[lo as usize..hi as usize] {
                    let bs = b[s as usize];
                    acc[0] += f * bs[0];
                    acc[1] += f * bs[1];
                    acc[2] += f * bs[2];
                }
                acc
            })
            .collect();
        let mut gathered = vec![[0.0; 3]; self.n];
        for (&(r, _, _), s) in self.groups.iter().zip(sums) {
            gathered[r as usize] = s;
        }
        gathered
    }

    fn push(&self, gathered: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut hsum = vec![[0.0; 3]; self.n];
        for &e in &self.order {
            let p = self.h.get(e).parent;
            let up = if p == NONE { [0.0; 3] } else { hsum[p as usize] };
            let g = gathered[e as usize];
            hsum[e as usize] = [up[0] + g[0], up[1] + g[1], up[2] + g[2]];
        }
        hsum
    }

    /// `y = M x`: the reflected (and transmitted) radiosity of the leaves for leaf radiosity `x`.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        let b = self.pull(x);
        let gathered = self.gather(&b);
        let hsum = self.push(&gathered);
        for (i, &e) in self.leaves.iter().enumerate() {
            for k in 0..3 {
                y[3 * i + k] = self.rho[3 * i + k] * hsum[e as usize][k];
            }
        }
        let leaf_h: Vec<[f64; 3]> =
            if self.through.is_empty() { Vec::new() } else { self.leaves.iter().map(|&e| hsum[e as usize]).collect() };
        self.add_transmitted(&leaf_h, y);
    }

    /// Adds `t·H̄(other side)` to every transmitting leaf's entry of `y`, for leaf irradiance
    /// `leaf_h` (leaf order; `H̄` the area-weighted mean over the other side's piece at the same
    /// place). Nothing when no leaf transmits.
    pub fn add_transmitted(&self, leaf_h: &[[f64; 3]], y: &mut [f64]) {
        if self.through.is_empty() {
            return;
        }
        let mean = self.pull(leaf_h.as_flattened());
        for (i, &(t, q)) in self.through.iter().enumerate() {
            if q != NONE {
                for k in 0..3 {
                    y[3 * i + k] += t[k] * mean[q as usize][k];
                }
            }
        }
    }

    /// `y = (I − M) x`, the system matrix.
    pub fn apply_system(&self, x: &[f64], y: &mut [f64]) {
        self.apply(x, y);
        for (yi, xi) in y.iter_mut().zip(x) {
            *yi = xi - *yi;
        }
    }
}
