//! What a level's chain coefficients leave to the next level's ([`ChainReuse`]): the next level
//! refines only part of the hierarchy (local levels keep most links as they were), and a leaf
//! that stays a leaf keeps the coefficient of every link that stays, bit for bit.

use super::LeafCoefficients;
use super::precision::Stored;
use crate::hierarchy::{ElementId, NONE};
use crate::refine::Link;
use crate::solve::cut::Cut;

/// What a chain coefficient depends on besides its leaf and the element receiving the link: the
/// link's source, visibility and form factor (bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct LinkKey(pub(super) ElementId, u64, u64);

impl LinkKey {
    pub(super) fn of(l: &Link) -> LinkKey {
        LinkKey(l.source, l.vis.to_bits(), l.ff.to_bits())
    }
}

/// A level's stored chain coefficients at leaf resolution, kept for the next level of the same
/// run ([`LeafCoefficients::for_cut_reusing`]): each leaf's, with the links they were on.
#[derive(Debug)]
pub struct ChainReuse {
    /// Per element of the hierarchy then: the index of its stored unknown, or `NONE`.
    index: Vec<u32>,
    pub(super) start: Vec<usize>,
    pub(super) range: Vec<(u32, u32)>,
    /// Per position of the links sorted by receiver, the link's key.
    pub(super) keys: Vec<LinkKey>,
    pub(super) coef: Stored,
}

impl ChainReuse {
    /// The stored unknown that element `e` was, if one.
    pub(super) fn unknown_of(&self, e: ElementId) -> Option<usize> {
        self.index.get(e as usize).filter(|&&i| i != NONE).map(|&i| i as usize)
    }

    /// The kept coefficients with themselves, where stored in `f32`.
    pub(super) fn single(&self) -> Option<(&ChainReuse, &[f32])> {
        match &self.coef {
            Stored::Single(v) => Some((self, v)),
            Stored::Half(_) => None,
        }
    }

    /// The kept coefficients with themselves, where stored in 16-bit codes.
    pub(super) fn half(&self) -> Option<(&ChainReuse, &[u16])> {
        match &self.coef {
            Stored::Half(v) => Some((self, v)),
            Stored::Single(_) => None,
        }
    }

    /// Chain coefficients kept.
    #[must_use]
    pub fn entries(&self) -> usize {
        self.start.last().copied().unwrap_or(0)
    }
}

impl LeafCoefficients {
    /// The chain coefficients of `self`, built for `cut` and `links`, kept for the next level
    /// ([`ChainReuse`]); the rest is dropped.
    #[must_use]
    pub fn into_reuse(self, cut: &Cut<'_>, links: &[Link]) -> ChainReuse {
        let h = cut.hierarchy();
        let mut index = vec![NONE; h.len()];
        let stored = self.stored_unknowns();
        for (i, &u) in cut.elements()[..stored].iter().enumerate() {
            index[u as usize] = i as u32;
        }
        let keys = self.sorted.iter().map(|&k| LinkKey::of(&links[k as usize])).collect();
        let LeafCoefficients { start, range, coef, .. } = self;
        ChainReuse { index, start, range, keys, coef }
    }
}
