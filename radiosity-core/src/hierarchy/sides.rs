//! The two sides of a transmitting surface cut alike: each piece's mate on the other side
//! ([`Hierarchy::mate`]) and the subdivision that keeps both sides in the same pieces
//! ([`Hierarchy::match_sides`]).

use super::{ElementId, Hierarchy, MAX_MATE_DEPTH, NONE};
use crate::geom::DVec3;

impl Hierarchy {
    /// The piece of the other side that lies where surface element `id` lies, for a side of a
    /// transmitting surface ([`Hierarchy::twin`]); [`NONE`] otherwise. Both sides split the same
    /// vertices regularly, so their pieces coincide: the other side's piece at the same place and
    /// depth, or its leaf there where that side is coarser ([`Hierarchy::match_sides`] keeps the
    /// two alike). Light that one piece passes through reaches the other side at that piece only.
    #[must_use]
    pub fn mate(&self, id: ElementId) -> ElementId {
        let Some(p) = self.get(id).polygon() else { return NONE };
        let q = self.twin[p as usize];
        if q == NONE {
            return NONE;
        }
        // The path from the polygon's root down to `id`, followed on the other side.
        let mut path = [NONE; MAX_MATE_DEPTH];
        let mut depth = 0;
        let mut a = id;
        while usize::from(self.get(a).depth) > MAX_MATE_DEPTH {
            a = self.get(a).parent;
        }
        while a != p && depth < MAX_MATE_DEPTH {
            path[depth] = a;
            depth += 1;
            a = self.get(a).parent;
        }
        let mut b = q;
        for &a in path[..depth].iter().rev() {
            let Some(k) = self.piece_at(b, self.get(a).center) else { break };
            b = k;
        }
        b
    }

    /// The child of `b` whose centre is nearest `x`, or `None` for a leaf.
    fn piece_at(&self, b: ElementId, x: DVec3) -> Option<ElementId> {
        self.children_of(b).iter().copied().min_by(|&u, &v| {
            let (du, dv) = ((self.get(u).center - x).length_squared(), (self.get(v).center - x).length_squared());
            du.total_cmp(&dv)
        })
    }

    /// Subdivides each side of every transmitting surface wherever its other side is subdivided,
    /// so that both sides are cut into the same pieces and each piece passes its light through to
    /// its own [`Hierarchy::mate`]: one element with two sides. Returns the elements subdivided
    /// (their children are new leaves, lit through their ancestors' links).
    pub fn match_sides(&mut self) -> Vec<ElementId> {
        let mut made = Vec::new();
        let mut stack = Vec::new();
        for p in 0..self.n_polygons {
            let q = self.twin[p as usize];
            if q == NONE || q < p {
                continue;
            }
            stack.push((p, q));
            while let Some((a, b)) = stack.pop() {
                let (ka, kb) = (self.get(a).n_children, self.get(b).n_children);
                if ka == 0 && kb == 0 {
                    continue;
                }
                for (x, other) in [(a, kb), (b, ka)] {
                    if other > 0 && self.get(x).n_children == 0 && self.subdivide(x) {
                        made.push(x);
                    }
                }
                if self.get(a).n_children == 0 || self.get(b).n_children == 0 {
                    continue;
                }
                for &k in self.children_of(a) {
                    if let Some(m) = self.piece_at(b, self.get(k).center) {
                        stack.push((k, m));
                    }
                }
            }
        }
        made
    }
}
