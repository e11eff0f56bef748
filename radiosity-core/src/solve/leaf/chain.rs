//! The links along an unknown's chain: the unknowns of a cut below each element ([`LeavesBelow`]),
//! the links received at each element (`super::super::by_receiver`), and the chain of links of one unknown
//! with its coefficients, stored or recomputed ([`Chain`]).

use super::precision::Precision;
use super::reuse::{ChainReuse, LinkKey};
use super::weights::shape_form_factor;
use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::refine::Link;
use crate::solve::cut::Cut;
use rayon::prelude::*;

/// The unknowns of a cut below each element, as ranges of one depth-first list (an element at or
/// below the cut has none: its value is its cut ancestor's).
pub(super) struct LeavesBelow {
    leaves: Vec<ElementId>,
    range: Vec<(u32, u32)>,
}

impl LeavesBelow {
    pub(super) fn new(cut: &Cut<'_>) -> LeavesBelow {
        let h = cut.hierarchy();
        let mut leaves = Vec::new();
        let mut range = vec![(0u32, 0u32); h.len()];
        // Iterative post-order: an element's range closes after its children's.
        let mut stack = vec![(h.root, false)];
        while let Some((e, done)) = stack.pop() {
            if done {
                let kids = h.children_of(e);
                if !kids.is_empty() {
                    range[e as usize] = (range[kids[0] as usize].0, range[kids[kids.len() - 1] as usize].1);
                }
                continue;
            }
            if cut.unknown_of(e).is_some() {
                range[e as usize] = (leaves.len() as u32, leaves.len() as u32 + 1);
                leaves.push(e);
                continue;
            }
            stack.push((e, true));
            for &k in h.children_of(e).iter().rev() {
                stack.push((k, false));
            }
        }
        LeavesBelow { leaves, range }
    }

    pub(super) fn below(&self, e: ElementId) -> &[ElementId] {
        let (a, b) = self.range[e as usize];
        &self.leaves[a as usize..b as usize]
    }
}

/// The chain of links of one unknown: every link received at the unknown or an ancestor, in the
/// order coefficients are stored in.
#[derive(Clone, Copy)]
pub(super) struct Chain<'c> {
    pub(super) h: &'c Hierarchy,
    pub(super) links: &'c [Link],
    pub(super) sorted: &'c [u32],
    pub(super) range: &'c [(u32, u32)],
    pub(super) precision: Precision,
}

impl Chain<'_> {
    /// Number of links on the chain of `leaf`.
    pub(super) fn len(&self, leaf: ElementId) -> usize {
        let mut n = 0;
        let mut a = leaf;
        while a != NONE {
            let (lo, hi) = self.range[a as usize];
            n += (hi - lo) as usize;
            a = self.h.get(a).parent;
        }
        n
    }

    /// Calls `f(link)` for every link on the chain of `leaf`, in storage order.
    pub(super) fn for_each_link(&self, leaf: ElementId, mut f: impl FnMut(u32)) {
        let mut a = leaf;
        while a != NONE {
            let (lo, hi) = self.range[a as usize];
            for &k in &self.sorted[lo as usize..hi as usize] {
                f(k);
            }
            a = self.h.get(a).parent;
        }
    }

    /// Calls `f(link, F(leaf ← source) V)` for every link on the chain of `leaf`, in storage order:
    /// a link at the leaf with its stored form factor, one at an ancestor with the leaf's own
    /// ([`shape_form_factor`]); negative values (quadrature noise) as 0, every value rounded to
    /// `f32` (and then to the chain's [`Precision`] by [`Chain::for_each`]).
    fn for_each_raw(&self, leaf: ElementId, mut f: impl FnMut(u32, f32)) {
        let mut a = leaf;
        while a != NONE {
            let (lo, hi) = self.range[a as usize];
            for &k in &self.sorted[lo as usize..hi as usize] {
                f(k, self.raw(leaf, a, &self.links[k as usize]));
            }
            a = self.h.get(a).parent;
        }
    }

    /// The coefficient of `leaf` on link `l`, received at `a` (the leaf or an ancestor), as
    /// [`Chain::for_each_raw`] gives it: it depends on the two elements, the link's source, its
    /// visibility and, at the leaf, its form factor, and on nothing else.
    fn raw(&self, leaf: ElementId, a: ElementId, l: &Link) -> f32 {
        let ff = if a == leaf { l.ff } else { shape_form_factor(self.h, l.source, leaf) };
        let c = ff * l.vis;
        if c > 0.0 { c as f32 } else { 0.0 }
    }

    /// [`Chain::for_each_raw`] with every value as it is applied in the chain's [`Precision`]: what
    /// a stored coefficient decodes to.
    pub(super) fn for_each(&self, leaf: ElementId, mut f: impl FnMut(u32, f32)) {
        let p = self.precision;
        self.for_each_raw(leaf, |k, c| f(k, p.round(c)));
    }

    /// Fills `coef` with the chain coefficients of `unknowns` (in order, `start` their offsets
    /// relative to `coef`, length `unknowns.len() + 1`), each as `store` turns it, in parallel;
    /// with `earlier` (the coefficients of an earlier level of the same hierarchy, `old` as they
    /// were stored), every coefficient of an unknown that was one then, on a link received at the
    /// same element from the same source with the same visibility and form factor, is taken from
    /// there: that is all [`Chain::raw`] depends on, so the value is the one it would compute
    /// again. Returns how many were taken.
    pub(super) fn fill<T: Copy + Send + Sync>(
        &self,
        unknowns: &[ElementId],
        start: &[usize],
        coef: &mut [T],
        store: impl Fn(f32) -> T + Sync,
        earlier: Option<(&ChainReuse, &[T])>,
    ) -> usize {
        let taken = std::sync::atomic::AtomicUsize::new(0);
        fill_each(unknowns, start, coef, |u, out| {
            let Some((earlier, old, i)) = earlier.and_then(|(e, old)| Some((e, old, e.unknown_of(u)?))) else {
                let mut j = 0;
                self.for_each_raw(u, |_, c| {
                    out[j] = store(c);
                    j += 1;
                });
                return;
            };
            let (mut j, mut from, mut n) = (0, earlier.start[i], 0);
            let mut a = u;
            while a != NONE {
                let (lo, hi) = self.range[a as usize];
                let (olo, ohi) = earlier.range.get(a as usize).map_or((0, 0), |&(l, h)| (l as usize, h as usize));
                let mut p = olo;
                for &k in &self.sorted[lo as usize..hi as usize] {
                    let l = &self.links[k as usize];
                    // Both runs are sorted by source.
                    while p < ohi && earlier.keys[p].0 < l.source {
                        p += 1;
                    }
                    out[j] = if p < ohi && earlier.keys[p] == LinkKey::of(l) {
                        n += 1;
                        p += 1;
                        old[from + p - 1 - olo]
                    } else {
                        store(self.raw(u, a, l))
                    };
                    j += 1;
                }
                from += ohi - olo;
                a = self.h.get(a).parent;
            }
            taken.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
        });
        taken.into_inner()
    }
}

/// Calls `f(unknown, its slice of coef)` for every one of `unknowns` (in order, `start` their
/// offsets relative to `coef`, length `unknowns.len() + 1`), in parallel.
pub(super) fn fill_each<T: Send>(unknowns: &[ElementId], start: &[usize], coef: &mut [T], f: impl Fn(ElementId, &mut [T]) + Sync) {
    let mut slices: Vec<&mut [T]> = Vec::with_capacity(unknowns.len());
    let mut rest = coef;
    for w in start.windows(2) {
        let (a, b) = std::mem::take(&mut rest).split_at_mut(w[1] - w[0]);
        slices.push(a);
        rest = b;
    }
    slices.into_par_iter().zip(unknowns.par_iter()).with_min_len(16).for_each(|(out, &u)| f(u, out));
}
