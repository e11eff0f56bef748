//! Links grouped by receiver: the links each element receives, and the chain of links of a leaf
//! (those at the leaf and at its ancestors), which the leaf-resolution operator, the final gather,
//! the radiosity ranges and the error estimate read.

use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::refine::Link;

/// Links grouped by receiver (sorted by receiver, then source).
pub(super) struct LinksByReceiver<'l> {
    links: &'l [Link],
    pub(super) sorted: Vec<u32>,
    pub(super) range: Vec<(u32, u32)>,
}

impl<'l> LinksByReceiver<'l> {
    pub(super) fn new(h: &Hierarchy, links: &'l [Link]) -> LinksByReceiver<'l> {
        let mut sorted: Vec<u32> = (0..links.len() as u32).collect();
        sorted.sort_by_key(|&k| (links[k as usize].receiver, links[k as usize].source));
        let mut range = vec![(0u32, 0u32); h.len()];
        for (k, &i) in sorted.iter().enumerate() {
            let r = &mut range[links[i as usize].receiver as usize];
            if r.1 == 0 {
                r.0 = k as u32;
            }
            r.1 = k as u32 + 1;
        }
        LinksByReceiver { links, sorted, range }
    }

    /// The indices (into the links) of the links received by element `e`.
    pub(super) fn indices_at(&self, e: ElementId) -> &[u32] {
        let (lo, hi) = self.range[e as usize];
        &self.sorted[lo as usize..hi as usize]
    }

    /// The links received by element `e`.
    pub(super) fn at(&self, e: ElementId) -> impl Iterator<Item = &'l Link> + '_ {
        self.indices_at(e).iter().map(|&k| &self.links[k as usize])
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
