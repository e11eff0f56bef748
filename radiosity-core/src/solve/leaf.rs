//! The leaf-resolution operator: every leaf gathers from every link at itself and at its ancestors,
//! with the form factor evaluated for the leaf itself instead of the ancestor's average.
//!
//! A link stored at a coarse receiver hands the same average form factor to every leaf below it; where
//! the point form factor varies over that receiver (near edges and corners that touch the source) the
//! leaves' row sums drift from the truth, and each level of the hierarchy adds its share: in a closed
//! box the corner leaves of an `eps = 0.1` BF solution gathered 1.86 times the light they see. Here
//! the links (which sources interact with which region, and their visibility) are kept, but each leaf
//! gets its own form factor to each of its chain's sources, so its row sum is the point-sampled
//! truth up to receiver quadrature. The operator is solved to convergence with GMRES, starting from
//! the hierarchical solution. It stores one coefficient per (leaf, chain link); when that exceeds
//! the budget the caller falls back to one gather pass ([`super::final_gather`]).

use super::Operator;
use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::refine::Link;
use rayon::prelude::*;

/// Default budget of (leaf, link) coefficients for the leaf-resolution operator (12 bytes each).
pub const LEAF_OPERATOR_MAX_ENTRIES: usize = 40_000_000;

/// Per-leaf gather lists over the chain of ancestor links.
pub struct LeafOperator<'a> {
    op: Operator<'a>,
    lists: &'a LeafCoefficients,
}

/// The coefficients of a [`LeafOperator`]: geometry only (form factors and visibility), so they
/// serve every emission of the same hierarchy and links (the instanced solver keeps them with a
/// level it reuses).
#[derive(Clone, Debug)]
pub struct LeafCoefficients {
    /// Start of each leaf's entries in `src`/`coef` (length leaves + 1), leaves in
    /// [`Operator`] order.
    start: Vec<usize>,
    src: Vec<ElementId>,
    coef: Vec<f64>,
}

impl LeafCoefficients {
    /// Evaluates `link_form_factor(source, leaf)` for every leaf and every link on its chain.
    #[must_use]
    pub fn new(h: &Hierarchy, links: &[Link]) -> LeafCoefficients {
        let index = LinksByReceiver::new(h, links);
        let lists: Vec<Vec<(ElementId, f64)>> = Operator::new(h, links)
            .leaves()
            .par_iter()
            .map(|&leaf| {
                let mut list = Vec::new();
                index.leaf_chain(h, leaf, |source, c| {
                    if c > 0.0 {
                        list.push((source, c));
                    }
                });
                list
            })
            .collect();
        let mut start = Vec::with_capacity(lists.len() + 1);
        let total: usize = lists.iter().map(Vec::len).sum();
        let mut src = Vec::with_capacity(total);
        let mut coef = Vec::with_capacity(total);
        start.push(0);
        for list in lists {
            for (s, c) in list {
                src.push(s);
                coef.push(c);
            }
            start.push(src.len());
        }
        LeafCoefficients { start, src, coef }
    }

    /// Stored coefficients.
    #[must_use]
    pub fn entries(&self) -> usize {
        self.coef.len()
    }

    /// Heap bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        self.start.len() * size_of::<usize>() + self.src.len() * size_of::<ElementId>() + self.coef.len() * size_of::<f64>()
    }
}

/// Number of (leaf, chain link) coefficients the leaf operator would store.
#[must_use]
pub fn leaf_operator_entries(h: &Hierarchy, links: &[Link]) -> usize {
    let mut per = vec![0usize; h.len()];
    for l in links {
        per[l.receiver as usize] += 1;
    }
    // Chain counts: parents before children (element ids of children are larger than parents'
    // only for lazily created surface elements, so walk the chain explicitly).
    h.leaves()
        .map(|leaf| {
            let mut n = 0;
            let mut a = leaf;
            while a != NONE {
                n += per[a as usize];
                a = h.get(a).parent;
            }
            n
        })
        .sum()
}

/// Links grouped by receiver (sorted by receiver, then source).
pub(super) struct LinksByReceiver<'l> {
    sorted: Vec<&'l Link>,
    range: Vec<(u32, u32)>,
}

impl<'l> LinksByReceiver<'l> {
    pub(super) fn new(h: &Hierarchy, links: &'l [Link]) -> LinksByReceiver<'l> {
        let mut sorted: Vec<&Link> = links.iter().collect();
        sorted.sort_by_key(|l| (l.receiver, l.source));
        let mut range = vec![(0u32, 0u32); h.len()];
        for (k, l) in sorted.iter().enumerate() {
            let r = &mut range[l.receiver as usize];
            if r.1 == 0 {
                r.0 = k as u32;
            }
            r.1 = k as u32 + 1;
        }
        LinksByReceiver { sorted, range }
    }

    /// The links received by element `e`.
    pub(super) fn at(&self, e: ElementId) -> &[&'l Link] {
        let (lo, hi) = self.range[e as usize];
        &self.sorted[lo as usize..hi as usize]
    }

    /// Calls `f(source, F·V)` for every link on the chain from `leaf` to the root, with the form
    /// factor evaluated for `leaf` itself (a link at the leaf keeps its stored one).
    pub(super) fn leaf_chain(&self, h: &Hierarchy, leaf: ElementId, mut f: impl FnMut(ElementId, f64)) {
        let mut a = leaf;
        while a != NONE {
            for l in self.at(a) {
                let ff = if a == leaf { l.ff } else { formfactor::link_form_factor(h, l.source, leaf, FormFactorQuality::Precise) };
                f(l.source, ff * l.vis);
            }
            a = h.get(a).parent;
        }
    }
}

impl<'a> LeafOperator<'a> {
    /// The operator of `h` and `links` with coefficients computed by [`LeafCoefficients::new`] for
    /// the same hierarchy and links (the emission may have changed since).
    #[must_use]
    pub fn new(h: &'a Hierarchy, links: &[Link], coefficients: &'a LeafCoefficients) -> LeafOperator<'a> {
        LeafOperator { op: Operator::new(h, links), lists: coefficients }
    }

    /// The hierarchical operator underneath (leaf order, pull, emission).
    #[must_use]
    pub fn hierarchical(&self) -> &Operator<'a> {
        &self.op
    }

    /// Stored coefficients.
    #[must_use]
    pub fn entries(&self) -> usize {
        self.lists.entries()
    }

    /// Irradiance of every leaf (in leaf order) for leaf radiosity `x`.
    #[must_use]
    pub fn gather_leaves(&self, x: &[f64]) -> Vec<[f64; 3]> {
        let b = self.op.pull(x);
        let l = self.lists;
        (0..self.op.leaves().len())
            .into_par_iter()
            .map(|i| {
                let mut acc = [0.0; 3];
                for k in l.start[i]..l.start[i + 1] {
                    let bs = b[l.src[k] as usize];
                    let c = l.coef[k];
                    acc[0] += c * bs[0];
                    acc[1] += c * bs[1];
                    acc[2] += c * bs[2];
                }
                acc
            })
            .collect()
    }

    /// `y = (I − M) x` with the leaf-resolution transport `M`.
    pub fn apply_system(&self, x: &[f64], y: &mut [f64]) {
        let hs = self.gather_leaves(x);
        let rho = self.op.reflectance();
        for (i, h) in hs.iter().enumerate() {
            for k in 0..3 {
                y[3 * i + k] = rho[3 * i + k] * h[k];
            }
        }
        self.op.add_transmitted(&hs, y);
        for (yi, xi) in y.iter_mut().zip(x) {
            *yi = xi - *yi;
        }
    }

    /// Radiosity (pulled) and irradiance of every element for leaf radiosity `x`; inner elements'
    /// irradiance is the area-weighted mean of their leaves'.
    #[must_use]
    pub fn expand(&self, x: &[f64]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let h = self.op.hierarchy();
        let b = self.op.pull(x);
        let hs = self.gather_leaves(x);
        let mut flat = Vec::with_capacity(3 * hs.len());
        for v in &hs {
            flat.extend_from_slice(v);
        }
        let irr = self.op.pull(&flat);
        debug_assert_eq!(irr.len(), h.len());
        (b, irr)
    }
}
