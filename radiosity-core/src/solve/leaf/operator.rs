//! Applying the leaf operator: every unknown's irradiance gathered along its chain from the
//! coefficients ([`LeafOperator`]), the system `I − M` it applies, and the number of entries it
//! would store ([`leaf_operator_entries`]).

use super::LeafCoefficients;
use super::chain::{Chain, LeavesBelow};
use super::precision::{Stored, decode_table};
use super::weights::own_weights;
use crate::hierarchy::{Hierarchy, NONE};
use crate::refine::Link;
use crate::solve::cut::Cut;
use rayon::prelude::*;

/// Per-leaf gather lists over the chain of ancestor links, with conservative source values.
pub struct LeafOperator<'a> {
    cut: Cut<'a>,
    links: &'a [Link],
    lists: &'a LeafCoefficients,
}

/// Number of entries the leaf operator would store: (leaf, chain link) coefficients, and weights
/// of source leaves (per near link, and shared per source of far links).
#[must_use]
pub fn leaf_operator_entries(h: &Hierarchy, links: &[Link]) -> usize {
    let mut per = vec![0usize; h.len()];
    let mut far_source = vec![false; h.len()];
    let below = LeavesBelow::new(&Cut::leaves(h));
    let mut weights = 0;
    for l in links {
        per[l.receiver as usize] += 1;
        if h.get(l.source).n_children > 0 {
            if own_weights(h, &below, l) {
                weights += below.below(l.source).len();
            } else {
                far_source[l.source as usize] = true;
            }
        }
    }
    weights += (0..h.len() as u32).filter(|&e| far_source[e as usize]).map(|e| below.below(e).len()).sum::<usize>();
    // Chain counts: parents before children (element ids of children are larger than parents'
    // only for lazily created surface elements, so walk the chain explicitly).
    let coefficients: usize = h
        .leaves()
        .map(|leaf| {
            let mut n = 0;
            let mut a = leaf;
            while a != NONE {
                n += per[a as usize];
                a = h.get(a).parent;
            }
            n
        })
        .sum();
    coefficients + weights
}

impl<'a> LeafOperator<'a> {
    /// The operator of `h` and `links` with coefficients computed by [`LeafCoefficients::new`] for
    /// the same hierarchy and links (the emission may have changed since).
    #[must_use]
    pub fn new(h: &'a Hierarchy, links: &'a [Link], coefficients: &'a LeafCoefficients) -> LeafOperator<'a> {
        LeafOperator { cut: Cut::leaves(h), links, lists: coefficients }
    }

    /// The operator on the unknowns of `cut`, with coefficients computed by
    /// [`LeafCoefficients::for_cut`] for the same cut and `links`.
    #[must_use]
    pub fn for_cut(cut: Cut<'a>, links: &'a [Link], coefficients: &'a LeafCoefficients) -> LeafOperator<'a> {
        LeafOperator { cut, links, lists: coefficients }
    }

    /// The unknowns (leaf order, pull, emission).
    #[must_use]
    pub fn cut(&self) -> &Cut<'a> {
        &self.cut
    }

    /// Stored coefficients.
    #[must_use]
    pub fn entries(&self) -> usize {
        self.lists.entries()
    }

    /// Irradiance of every unknown (in cut order) for the unknowns' radiosity `x`. Unknowns whose
    /// chain coefficients are not stored compute them again, to the same values.
    #[must_use]
    pub fn gather_leaves(&self, x: &[f64]) -> Vec<[f64; 3]> {
        let b = self.cut.pull(x);
        let l = self.lists;
        let values = l.link_values(&b);
        let chain = Chain { h: self.cut.hierarchy(), links: self.links, sorted: &l.sorted, range: &l.range, precision: l.coef.precision() };
        let stored = l.stored_unknowns();
        let unknowns = self.cut.elements();
        let table = decode_table();
        (0..self.cut.len())
            .into_par_iter()
            .map(|i| {
                let mut acc = [0.0; 3];
                let mut add = |k: u32, c: f32| {
                    let bs = values[k as usize];
                    let c = f64::from(c);
                    acc[0] += c * bs[0];
                    acc[1] += c * bs[1];
                    acc[2] += c * bs[2];
                };
                if i < stored {
                    let mut j = l.start[i];
                    match &l.coef {
                        Stored::Single(v) => chain.for_each_link(unknowns[i], |k| {
                            add(k, v[j]);
                            j += 1;
                        }),
                        Stored::Half(v) => chain.for_each_link(unknowns[i], |k| {
                            add(k, table[usize::from(v[j])]);
                            j += 1;
                        }),
                    }
                } else {
                    chain.for_each(unknowns[i], &mut add);
                }
                for &(k, c) in &l.inside[l.inside_start[i] as usize..l.inside_start[i + 1] as usize] {
                    let bs = values[k as usize];
                    for ch in 0..3 {
                        acc[ch] += c * bs[ch];
                    }
                }
                acc
            })
            .collect()
    }

    /// `y = (I − M) x` with the leaf-resolution transport `M`.
    pub fn apply_system(&self, x: &[f64], y: &mut [f64]) {
        let hs = self.gather_leaves(x);
        let rho = self.cut.reflectance();
        for (i, h) in hs.iter().enumerate() {
            for k in 0..3 {
                y[3 * i + k] = rho[3 * i + k] * h[k];
            }
        }
        self.cut.add_transmitted(&hs, y);
        for (yi, xi) in y.iter_mut().zip(x) {
            *yi = xi - *yi;
        }
    }

    /// Radiosity (pulled) and irradiance of every element for the unknowns' radiosity `x`;
    /// elements above the cut get the area-weighted mean of their unknowns, those below their
    /// unknown's value.
    #[must_use]
    pub fn expand(&self, x: &[f64]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let b = self.cut.pull(x);
        let hs = self.gather_leaves(x);
        let irr = self.cut.pull(hs.as_flattened());
        (b, irr)
    }
}
