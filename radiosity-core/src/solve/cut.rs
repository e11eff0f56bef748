//! A cut of the hierarchy: surface elements that cover every polygon exactly once, the unknowns of
//! a leaf-resolution solve. The leaves are the finest cut; coarser ones stop one or more levels
//! above them ([`Cut::coarsened`]), which is how the error estimate compares the solution with the
//! ones a mesh two and four times coarser gives, with the same links.

use crate::hierarchy::{ElementId, Hierarchy, NONE};

/// Surface elements partitioning every polygon, and how per-element values follow from theirs.
pub struct Cut<'a> {
    h: &'a Hierarchy,
    /// The unknowns, in breadth-first order from the root.
    elements: Vec<ElementId>,
    /// Per element: the unknown it lies in (itself, or its ancestor on the cut); [`NONE`] above
    /// the cut.
    index: Vec<u32>,
    /// Elements above the cut, parents before children.
    above: Vec<ElementId>,
    /// Reflectance and emission per unknown, interleaved RGB.
    rho: Vec<f64>,
    emission: Vec<f64>,
    /// Per unknown: transmittance and the other side's piece at the same place
    /// ([`Hierarchy::mate`]); empty when nothing transmits.
    through: Vec<([f64; 3], ElementId)>,
}

impl<'a> Cut<'a> {
    /// The finest cut: every leaf (in the order of [`super::Operator::leaves`]).
    #[must_use]
    pub fn leaves(h: &'a Hierarchy) -> Cut<'a> {
        Cut::coarsened(h, 0)
    }

    /// The cut `levels` levels above the leaves: every surface element whose subtree is at most
    /// `levels` deep and whose parent's is deeper (or whose parent is a cluster). `0` gives the
    /// leaves; each further level merges the deepest pieces into their parents, about doubling the
    /// mesh size everywhere the mesh is that deep.
    #[must_use]
    pub fn coarsened(h: &'a Hierarchy, levels: u32) -> Cut<'a> {
        let n = h.len();
        let mut order = Vec::with_capacity(n);
        order.push(h.root);
        let mut i = 0;
        while i < order.len() {
            order.extend_from_slice(h.children_of(order[i]));
            i += 1;
        }
        let mut height = vec![0u32; n];
        for &e in order.iter().rev() {
            height[e as usize] = h.children_of(e).iter().map(|&k| height[k as usize] + 1).max().unwrap_or(0);
        }
        let on_cut = |e: ElementId| {
            let el = h.get(e);
            !el.is_cluster()
                && height[e as usize] <= levels
                && (el.parent == NONE || h.get(el.parent).is_cluster() || height[el.parent as usize] > levels)
        };
        let mut index = vec![NONE; n];
        let mut elements = Vec::new();
        let mut above = Vec::new();
        for &e in &order {
            let p = h.get(e).parent;
            if p != NONE && index[p as usize] != NONE {
                index[e as usize] = index[p as usize];
            } else if on_cut(e) {
                index[e as usize] = elements.len() as u32;
                elements.push(e);
            } else {
                above.push(e);
            }
        }
        let mut rho = Vec::with_capacity(3 * elements.len());
        let mut emission = Vec::with_capacity(3 * elements.len());
        let mut through = Vec::with_capacity(elements.len());
        for &e in &elements {
            let p = h.get(e).polygon().expect("cut elements are surfaces") as usize;
            rho.extend_from_slice(&h.reflectance[p]);
            emission.extend_from_slice(&h.emission_of(e));
            through.push((h.transmittance[p], h.mate(e)));
        }
        if through.iter().all(|(_, q)| *q == NONE) {
            through.clear();
        }
        Cut { h, elements, index, above, rho, emission, through }
    }

    /// The hierarchy.
    #[must_use]
    pub fn hierarchy(&self) -> &'a Hierarchy {
        self.h
    }

    /// The unknowns.
    #[must_use]
    pub fn elements(&self) -> &[ElementId] {
        &self.elements
    }

    /// Number of unknowns.
    #[must_use]
    pub fn len(&self) -> usize {
        self.elements.len()
    }

    /// True when there is no unknown.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.elements.is_empty()
    }

    /// The unknown element `e` lies in (itself or its ancestor on the cut), if at or below the cut.
    #[must_use]
    pub fn unknown_of(&self, e: ElementId) -> Option<usize> {
        let i = self.index[e as usize];
        (i != NONE).then_some(i as usize)
    }

    /// Emission of the unknowns, interleaved RGB (the right-hand side).
    #[must_use]
    pub fn emission(&self) -> Vec<f64> {
        self.emission.clone()
    }

    /// Reflectance of the unknowns, interleaved RGB.
    #[must_use]
    pub fn reflectance(&self) -> &[f64] {
        &self.rho
    }

    /// The unknowns' values read from a per-element array, interleaved RGB.
    #[must_use]
    pub fn from_elements(&self, per_element: &[[f64; 3]]) -> Vec<f64> {
        let mut x = Vec::with_capacity(3 * self.elements.len());
        for &e in &self.elements {
            x.extend_from_slice(per_element.get(e as usize).unwrap_or(&[0.0; 3]));
        }
        x
    }

    /// Per-element values from the unknowns' `x` (interleaved RGB): at and below the cut the
    /// unknown's value, above it the area-weighted mean of the children.
    #[must_use]
    pub fn pull(&self, x: &[f64]) -> Vec<[f64; 3]> {
        let h = self.h;
        let mut b = vec![[0.0; 3]; h.len()];
        for (e, &i) in self.index.iter().enumerate() {
            if i != NONE {
                let i = i as usize;
                b[e] = [x[3 * i], x[3 * i + 1], x[3 * i + 2]];
            }
        }
        super::final_gather::area_means(h, &self.above, &mut b);
        b
    }

    /// Adds `t·H̄(other side)` to every transmitting unknown's entry of `y`, for the unknowns'
    /// irradiance `hs` (`H̄` the mean over the other side's piece at the same place: its own
    /// unknown's value below that side's cut).
    pub fn add_transmitted(&self, hs: &[[f64; 3]], y: &mut [f64]) {
        if self.through.is_empty() {
            return;
        }
        let mean = self.pull(hs.as_flattened());
        for (i, &(t, q)) in self.through.iter().enumerate() {
            if q != NONE {
                for k in 0..3 {
                    y[3 * i + k] += t[k] * mean[q as usize][k];
                }
            }
        }
    }
}
