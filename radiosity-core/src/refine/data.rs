//! What refinement knows of each element: its radiosity, how much that radiosity varies over it,
//! and the irradiance its accuracy is measured against. The first pass starts from a guess
//! ([`ElementData::first_guess`]); every later pass reads the last solution
//! ([`crate::solve::element_data`]).

use crate::hierarchy::{ElementId, Hierarchy};

/// A child's radiosity variation as a fraction of its parent's until a solve measures it (regular
/// subdivision halves the element's size, and a smooth variation with it).
pub const CHILD_VARIATION_FRACTION: f64 = 0.5;

/// Thresholds are relative to a receiver's own irradiance, but never to less than this fraction of
/// the scene's mean irradiance: a surface a thousand times dimmer than the average is refined for
/// the accuracy of one a thousand times dimmer, not without end.
pub const IRRADIANCE_FLOOR_REL: f64 = 1e-3;

/// Per-element data the oracle's energy criteria read ([`crate::refine::Services::data`]).
#[derive(Clone, Debug, Default)]
pub struct ElementData {
    /// Radiosity B per element (area mean), W/m².
    pub radiosity: Vec<[f64; 3]>,
    /// How much the radiosity varies over the element: the largest channel of `max − min` over
    /// its surface (probe points of its leaves, see [`crate::solve::element_data`]), W/m².
    pub variation: Vec<f64>,
    /// The irradiance a link to the element is measured against: the element's mean irradiance
    /// (largest channel of the area-weighted mean over its leaves), W/m².
    pub irradiance: Vec<f64>,
    /// The smallest irradiance a threshold is relative to: [`IRRADIANCE_FLOOR_REL`] times the
    /// scene's area-weighted mean irradiance.
    pub irradiance_floor: f64,
    /// How many times the emitted light is reflected on average: the power leaving all surfaces
    /// over the power emitted (`1/(1 − ρ̄)` in a closed scene of reflectance ρ̄, at least 1).
    /// An error in one link's transfer is reflected as often, so thresholds are divided by it
    /// ([`ElementData::reference`]): the same eps then bounds the same relative error of the
    /// solution in a stiff enclosure as in a dim room.
    pub amplification: f64,
    /// Per element, the factor its links' thresholds are scaled by beyond the pass's (at most 1;
    /// empty: 1 everywhere): importance, set where calculation points need the light a leaf gets
    /// more accurately than the polygon means do (see [`crate::pipeline::run_with_points`]).
    /// Children inherit their parent's; an element's is at most the smallest of its descendants'.
    pub importance: Vec<f64>,
}

/// Power leaving all surfaces over the power emitted, largest channel, for per-polygon radiosity
/// and emission (at least 1; 1 for a dark scene).
#[must_use]
pub fn amplification(areas: impl Iterator<Item = (f64, [f64; 3], [f64; 3])>) -> f64 {
    let (mut leaving, mut emitted) = ([0.0; 3], [0.0; 3]);
    for (a, b, e) in areas {
        for c in 0..3 {
            leaving[c] += a * b[c];
            emitted[c] += a * e[c];
        }
    }
    (0..3).filter(|&c| emitted[c] > 0.0).map(|c| leaving[c] / emitted[c]).fold(1.0, f64::max)
}

impl ElementData {
    /// The guess refinement starts from, before anything is solved: emission plus a uniform
    /// ambient irradiance (the closed-scene estimate `Φ / (A (1 − ρ̄))`, reflected by each
    /// polygon), no variation over any element (the first solve measures it), and that ambient
    /// irradiance as every receiver's reference.
    #[must_use]
    pub fn first_guess(h: &Hierarchy) -> ElementData {
        let n = h.n_polygons as usize;
        let mut power = [0.0; 3];
        let mut area = 0.0;
        let mut rho_area = [0.0; 3];
        for p in 0..n {
            let a = h.get(p as u32).area;
            let em = h.emission_of(p as u32);
            area += a;
            for c in 0..3 {
                power[c] += a * em[c];
                rho_area[c] += a * h.reflectance[p][c];
            }
        }
        let ambient: [f64; 3] =
            std::array::from_fn(|c| if area > 0.0 { power[c] / area / (1.0 - rho_area[c] / area).max(1e-3) } else { 0.0 });
        let mut b = vec![[0.0; 3]; h.len()];
        // Surfaces (input polygons and the pieces the luminaires' light made, `crate::luminaire`).
        for e in 0..h.len() {
            if let Some(p) = h.get(e as u32).polygon() {
                let em = h.emission_of(e as u32);
                b[e] = std::array::from_fn(|c| em[c] + h.reflectance[p as usize][c] * ambient[c]);
            }
        }
        // Clusters: area-weighted means, children before parents. The build reserves a cluster's
        // slot before building its children (pre-order), so every descendant of a cluster has a
        // larger id: going down the ids reaches the children first.
        for e in (n..h.len()).rev() {
            let el = h.get(e as u32);
            if el.is_cluster() {
                let mut acc = [0.0; 3];
                for &k in h.children_of(e as u32) {
                    let a = h.get(k).area;
                    for c in 0..3 {
                        acc[c] += a * b[k as usize][c];
                    }
                }
                b[e] = acc.map(|v| if el.area > 0.0 { v / el.area } else { 0.0 });
            }
        }
        let h_ambient = ambient.iter().copied().fold(0.0, f64::max);
        let amplification = amplification((0..n).map(|p| (h.get(p as u32).area, b[p], h.emission_of(p as u32))));
        ElementData {
            radiosity: b,
            variation: vec![0.0; h.len()],
            irradiance: vec![h_ambient; h.len()],
            irradiance_floor: IRRADIANCE_FLOOR_REL * h_ambient,
            amplification,
            importance: Vec::new(),
        }
    }

    /// Gives the new children of `parent` their parent's radiosity and irradiance reference and
    /// [`CHILD_VARIATION_FRACTION`] of its variation (the arrays grow to `h.len()`).
    pub fn inherit(&mut self, h: &Hierarchy, parent: ElementId) {
        let n = h.len();
        let (b, v, e) = (self.radiosity[parent as usize], self.variation[parent as usize], self.irradiance[parent as usize]);
        self.radiosity.resize(n, [0.0; 3]);
        self.variation.resize(n, 0.0);
        self.irradiance.resize(n, 0.0);
        for &k in h.children_of(parent) {
            self.radiosity[k as usize] = b;
            self.variation[k as usize] = CHILD_VARIATION_FRACTION * v;
            self.irradiance[k as usize] = e;
        }
        if !self.importance.is_empty() {
            let w = self.importance.get(parent as usize).copied().unwrap_or(1.0);
            self.importance.resize(n, 1.0);
            for &k in h.children_of(parent) {
                self.importance[k as usize] = w;
            }
        }
    }

    /// Scales the thresholds of links to `element` and to its ancestors by `factor` (at most 1)
    /// more than they are now.
    pub fn tighten(&mut self, h: &Hierarchy, element: ElementId, factor: f64) {
        self.importance.resize(h.len(), 1.0);
        let w = self.importance[element as usize] * factor;
        let mut e = element;
        while e != crate::hierarchy::NONE {
            let slot = &mut self.importance[e as usize];
            *slot = slot.min(w);
            e = h.get(e).parent;
        }
    }

    /// Scales the thresholds of links to `element` and to every element below it by `factor` (at
    /// most 1), and to its ancestors as far as the element's new factor: a whole polygon refined
    /// further than the rest (local levels, see `pipeline`'s `Config::local_levels`).
    pub fn tighten_subtree(&mut self, h: &Hierarchy, element: ElementId, factor: f64) {
        self.importance.resize(h.len(), 1.0);
        let mut stack = vec![element];
        while let Some(e) = stack.pop() {
            self.importance[e as usize] *= factor;
            stack.extend_from_slice(h.children_of(e));
        }
        let w = self.importance[element as usize];
        let mut e = h.get(element).parent;
        while e != crate::hierarchy::NONE {
            let slot = &mut self.importance[e as usize];
            *slot = slot.min(w);
            e = h.get(e).parent;
        }
    }

    /// The irradiance a threshold on links to `receiver` is relative to: its reference, at least
    /// the floor, divided by the [`ElementData::amplification`].
    #[must_use]
    #[inline]
    pub fn reference(&self, receiver: ElementId) -> f64 {
        self.irradiance[receiver as usize].max(self.irradiance_floor) / self.amplification
            * self.importance.get(receiver as usize).copied().unwrap_or(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hierarchy::{self, BuildConfig};

    /// Tightening a polygon's subtree scales every element of it, the deepest included, and its
    /// ancestors as far as the polygon's root; a second polygon is left as it was.
    #[test]
    fn tightening_a_subtree_scales_every_element_of_it() {
        let scene = crate::scene::cornell_box();
        let mut h = hierarchy::build(&scene, &BuildConfig::default());
        let mut data = ElementData::first_guess(&h);
        assert!(h.subdivide(0));
        data.inherit(&h, 0);
        let child = h.children_of(0)[0];
        assert!(h.subdivide(child));
        data.inherit(&h, child);
        data.tighten(&h, h.children_of(child)[0], 0.5);
        data.tighten_subtree(&h, 0, 0.25);
        let mut below = vec![0];
        let mut i = 0;
        while i < below.len() {
            below.extend_from_slice(h.children_of(below[i]));
            i += 1;
        }
        assert!(below.len() >= 9, "two levels below the root: {}", below.len());
        let deepest = h.children_of(child)[0];
        for &e in &below {
            let want = if e == deepest || e == 0 || e == child { 0.125 } else { 0.25 };
            assert!((data.importance[e as usize] - want).abs() < 1e-12, "element {e}: {}", data.importance[e as usize]);
        }
        let root = h.root as usize;
        assert!((data.importance[root] - 0.125).abs() < 1e-12);
        assert_eq!(data.importance[1], 1.0, "another polygon");
    }

    /// Tightening a leaf scales the reference of the links to it and to every ancestor, and no
    /// other element's; its children inherit its factor; a second tightening multiplies.
    #[test]
    fn tightening_reaches_the_ancestors_and_the_children() {
        let scene = crate::scene::cornell_box();
        let mut h = hierarchy::build(&scene, &BuildConfig::default());
        let mut data = ElementData::first_guess(&h);
        let leaf = h.leaves().find(|&l| h.get(l).polygon().is_some() && h.can_subdivide(l)).expect("a surface leaf");
        let other = h.leaves().find(|&l| l != leaf).expect("another leaf");
        let before: Vec<f64> = (0..h.len() as u32).map(|e| data.reference(e)).collect();
        data.tighten(&h, leaf, 0.25);
        let mut ancestors = vec![leaf];
        while let Some(&a) = ancestors.last().filter(|&&a| h.get(a).parent != crate::hierarchy::NONE) {
            ancestors.push(h.get(a).parent);
        }
        for e in 0..h.len() as u32 {
            let expected = if ancestors.contains(&e) { 0.25 } else { 1.0 };
            assert!((data.reference(e) / before[e as usize] - expected).abs() < 1e-12, "element {e}");
        }
        assert!((data.reference(other) - before[other as usize]).abs() < 1e-12);
        assert!(h.subdivide(leaf));
        data.inherit(&h, leaf);
        for &k in h.children_of(leaf) {
            assert_eq!(data.importance[k as usize], 0.25);
        }
        data.tighten(&h, leaf, 0.25);
        assert_eq!(data.importance[leaf as usize], 0.0625);
        assert_eq!(data.importance[h.root as usize], 0.0625);
    }
}
