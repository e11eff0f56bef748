//! Storage for the candidate lists of a link hierarchy: every list is a range of one shared vector,
//! so a refinement pass keeps its lists without one allocation per link.

/// A candidate list's place in a [`CandidateLists`] arena.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct CandidateRange {
    start: u32,
    end: u32,
}

impl CandidateRange {
    /// Number of candidates.
    #[must_use]
    pub fn len(&self) -> usize {
        (self.end - self.start) as usize
    }

    /// True when the list is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
}

/// An append-only arena of candidate lists (object ids).
#[derive(Clone, Debug, Default)]
pub struct CandidateLists {
    data: Vec<u32>,
}

impl CandidateLists {
    /// An empty arena.
    #[must_use]
    pub fn new() -> CandidateLists {
        CandidateLists::default()
    }

    /// Stores a list and returns its range.
    pub fn push(&mut self, list: &[u32]) -> CandidateRange {
        let start = self.data.len() as u32;
        self.data.extend_from_slice(list);
        CandidateRange { start, end: self.data.len() as u32 }
    }

    /// The list stored at `range`.
    #[must_use]
    pub fn get(&self, range: CandidateRange) -> &[u32] {
        &self.data[range.start as usize..range.end as usize]
    }

    /// Total number of ids stored.
    #[must_use]
    pub fn n_ids(&self) -> usize {
        self.data.len()
    }

    /// Forgets every list (ranges given before become invalid).
    pub fn clear(&mut self) {
        self.data.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_round_trip() {
        let mut a = CandidateLists::new();
        let r1 = a.push(&[3, 5, 8]);
        let r2 = a.push(&[]);
        let r3 = a.push(&[5]);
        assert_eq!((a.get(r1), a.get(r2), a.get(r3)), (&[3, 5, 8][..], &[][..], &[5][..]));
        assert_eq!((r1.len(), r2.is_empty(), a.n_ids()), (3, true, 4));
    }
}
