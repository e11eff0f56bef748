//! The leaf-resolution operator: every leaf gathers from every link at itself and at its ancestors,
//! with the form factor evaluated for the leaf itself instead of the ancestor's average, and every
//! link sends its source's radiosity weighted by how much of each source leaf's light the link
//! carries, so that the operator conserves energy exactly.
//!
//! A link stored at a coarse receiver hands the same average form factor to every leaf below it; where
//! the point form factor varies over that receiver (near edges and corners that touch the source) the
//! leaves' row sums drift from the truth, and each level of the hierarchy adds its share: in a closed
//! box the corner leaves of an `eps = 0.1` BF solution gathered 1.86 times the light they see. Here
//! the links (which sources interact with which region, and their visibility) are kept, but each leaf
//! gets its own form factor to each of its chain's sources, so its row sum is the point-sampled
//! truth up to receiver quadrature.
//!
//! The source side has the mirror problem. A source split for some receivers and not for others
//! sends its area-mean radiosity along its coarse links, while its children's own links send each
//! child's: a child then delivers its own fraction to some receivers and its parent's average
//! fraction to the rest, which sum to more or less than the light it emits (0.83 to 1.34 of it in a
//! closed room lit by a small bright source, 1 to 2% of the power created or lost). Here each
//! source `S` sends, along all its links, `Σ_y a_y B_y / Σ_y a_y` over its leaves `y`, weighted by
//! `a_y = Σ_L A_y F(y ← R_L) V_L`, the light of `y` that `S`'s links `L` carry to their receivers
//! `R_L` (reciprocity: `A_R F(R ← y) = A_y F(y ← R)`). Each leaf then delivers exactly the fraction
//! of its light that its links cover. Per link, the transfer `τ_L = A_R F(R ← S) V` is the same on
//! both sides: summed over the receiver's leaves and over the source's leaves, taken from the side
//! evaluated exactly (a surface at the other end; the cluster approximation is the other side's),
//! and the other side scaled to it.
//!
//! The operator is solved to convergence with GMRES, starting from the hierarchical solution. It
//! stores one coefficient per (leaf, chain link) and one weight per (link source, leaf below it);
//! when that exceeds the budget the caller falls back to one gather pass
//! ([`super::final_gather`]).

use super::cut::Cut;
use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::refine::Link;
use rayon::prelude::*;

/// Default budget of leaf-operator entries: (leaf, link) coefficients and (source, leaf) weights.
pub const LEAF_OPERATOR_MAX_ENTRIES: usize = 40_000_000;
/// Bytes of one leaf-operator entry (element id and coefficient).
pub const LEAF_OPERATOR_ENTRY_BYTES: usize = 12;

/// Source leaves farther from a receiver than this many times the sum of their bounding radii get
/// their weight from the point form factor at their centre rather than the precise one (the
/// weights only share a link's transfer among the source's leaves).
pub const WEIGHT_FAR_SEPARATION: f64 = 4.0;

/// Per-leaf gather lists over the chain of ancestor links, with conservative source values.
pub struct LeafOperator<'a> {
    cut: Cut<'a>,
    lists: &'a LeafCoefficients,
}

/// The coefficients of a [`LeafOperator`]: geometry only (form factors and visibility), so they
/// serve every emission of the same hierarchy and links (the instanced solver keeps them with a
/// level it reuses).
#[derive(Clone, Debug)]
pub struct LeafCoefficients {
    /// Start of each leaf's entries in `link`/`coef` (length leaves + 1), leaves in
    /// [`super::Operator`] order.
    start: Vec<usize>,
    /// The link of each entry (an index into the links the coefficients were built for).
    link: Vec<u32>,
    coef: Vec<f64>,
    /// Per link, where its source value comes from.
    value: Vec<SourceValue>,
    /// Weights of source leaves: `(leaf, weight)` ranges referred to by [`SourceValue`].
    weight_leaf: Vec<ElementId>,
    weight: Vec<f64>,
    /// Sources with shared weights: `(source, start, end)` into `weight_leaf`/`weight`.
    shared: Vec<(ElementId, usize, usize)>,
    /// Smallest and largest closure factor applied ([`LeafCoefficients::closure`]).
    closure: (f64, f64),
}

/// Smallest closure factor of one unknown: delivering more than twice its light means something
/// other than sampling noise, and is not corrected beyond this.
pub const CLOSURE_MIN: f64 = 0.5;
/// Largest closure factor of one unknown. An unknown partly covered by something standing on it (a
/// floor piece under a chair's foot) is sampled over its whole area but sends light from its
/// uncovered part only, so its links deliver that part's share of its light; the factor then makes
/// up for the cover (4 for a piece three quarters covered). Beyond this the unknown is taken as
/// covered whole (it also receives next to nothing).
pub const CLOSURE_MAX: f64 = 1000.0;

/// What a link sends: its source's radiosity, weighted over the source's leaves.
#[derive(Clone, Copy, Debug)]
enum SourceValue {
    /// The source is a leaf: its radiosity.
    Leaf(ElementId),
    /// The link's own weights (`start..end` of the weight arrays, summing to 1).
    Own(u32, u32),
    /// The weights shared by the source's far links (entry of `shared`).
    Shared(u32),
}

/// Links nearer than this (centre distance over the sum of the bounding radii) weight their
/// source's leaves by their own kernel; farther links share one set of weights per source (the
/// kernel varies little over a far source).
pub const OWN_WEIGHTS_SEPARATION: f64 = 4.0;

/// The unknowns of a cut below each element, as ranges of one depth-first list (an element at or
/// below the cut has none: its value is its cut ancestor's).
struct LeavesBelow {
    leaves: Vec<ElementId>,
    range: Vec<(u32, u32)>,
}

impl LeavesBelow {
    fn new(cut: &Cut<'_>) -> LeavesBelow {
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

    fn below(&self, e: ElementId) -> &[ElementId] {
        let (a, b) = self.range[e as usize];
        &self.leaves[a as usize..b as usize]
    }
}

/// Whether `link` weights its source's unknowns by its own kernel.
fn own_weights(h: &Hierarchy, below: &LeavesBelow, l: &Link) -> bool {
    let (s, r) = (h.get(l.source), h.get(l.receiver));
    below.below(l.source).len() > 1 && (s.center - r.center).length() < OWN_WEIGHTS_SEPARATION * (s.radius + r.radius)
}

impl LeafCoefficients {
    /// Evaluates `link_form_factor(source, leaf)` for every leaf and every link on its chain, and
    /// the source weights, each link's two sides scaled to the same transfer (see the module docs).
    #[must_use]
    pub fn new(h: &Hierarchy, links: &[Link]) -> LeafCoefficients {
        LeafCoefficients::for_cut(&Cut::leaves(h), links, false)
    }

    /// [`LeafCoefficients::new`] with the unknowns of `cut` in place of the leaves: a link received
    /// below an unknown adds its transfer to the unknown's mean (area-weighted), a link sent from
    /// below one sends the unknown's radiosity. In a `closed` scene every unknown's light is
    /// delivered whole ([`LeafCoefficients::closure`]).
    #[must_use]
    pub fn for_cut(cut: &Cut<'_>, links: &[Link], closed: bool) -> LeafCoefficients {
        let h = cut.hierarchy();
        let index = LinksByReceiver::new(h, links);
        // Receiver side: per unknown, (link index, F(unknown ← source) V).
        let lists: Vec<Vec<(u32, f64)>> = cut
            .elements()
            .par_iter()
            .map(|&leaf| {
                let mut list = Vec::new();
                let mut a = leaf;
                while a != NONE {
                    for &k in index.indices_at(a) {
                        let l = &links[k as usize];
                        let ff = if a == leaf { l.ff } else { shape_form_factor(h, l.source, leaf) };
                        let c = ff * l.vis;
                        if c > 0.0 {
                            list.push((k, c));
                        }
                    }
                    a = h.get(a).parent;
                }
                // Links received inside the unknown: their transfer, spread over its area.
                let area = h.get(leaf).area;
                let mut stack: Vec<ElementId> = h.children_of(leaf).to_vec();
                while let Some(d) = stack.pop() {
                    for &k in index.indices_at(d) {
                        let l = &links[k as usize];
                        let c = h.get(d).area / area * l.ff * l.vis;
                        if c > 0.0 {
                            list.push((k, c));
                        }
                    }
                    stack.extend_from_slice(h.children_of(d));
                }
                list
            })
            .collect();
        let mut receiver_total = vec![0.0; links.len()];
        for (&leaf, list) in cut.elements().iter().zip(&lists) {
            let area = h.get(leaf).area;
            for &(k, c) in list {
                receiver_total[k as usize] += area * c;
            }
        }
        // Source side: per link, A_y F(y ← receiver) V for every unknown y below the source.
        let below = LeavesBelow::new(cut);
        let source_shares: Vec<Vec<f64>> = links
            .par_iter()
            .map(|l| below.below(l.source).iter().map(|&y| h.get(y).area * weight_form_factor(h, l.receiver, y) * l.vis).collect())
            .collect();
        // The transfer each link carries, from the side evaluated exactly: between surfaces the
        // link's own `A_R F V` (its precise form factor); from a surface to a cluster the sum over
        // the receiver's unknowns (each with its precise form factor from the surface); from a
        // cluster to a surface the sum over the source's unknowns (likewise, by reciprocity);
        // between clusters the receiver's sum.
        let transfer: Vec<f64> = links
            .iter()
            .enumerate()
            .map(|(k, l)| {
                let (s_surface, r_surface) = (h.get(l.source).poly().is_some(), h.get(l.receiver).poly().is_some());
                let source_total: f64 = source_shares[k].iter().sum();
                match (s_surface, r_surface) {
                    (true, true) => h.get(l.receiver).area * l.ff * l.vis,
                    (false, true) if source_total > 0.0 => source_total,
                    _ => receiver_total[k],
                }
            })
            .collect();
        let mut start = Vec::with_capacity(lists.len() + 1);
        let total: usize = lists.iter().map(Vec::len).sum();
        let mut link = Vec::with_capacity(total);
        let mut coef = Vec::with_capacity(total);
        start.push(0);
        for list in lists {
            for (k, c) in list {
                let scale = if receiver_total[k as usize] > 0.0 { transfer[k as usize] / receiver_total[k as usize] } else { 1.0 };
                link.push(k);
                coef.push(c * scale);
            }
            start.push(link.len());
        }
        // Source values: an unknown's own radiosity (a source at or below the cut sends its cut
        // ancestor's); a near link's own weights; the shared weights of a source's far links (each
        // link's shares scaled to its transfer, then summed).
        let (mut weight_leaf, mut weight) = (Vec::new(), Vec::new());
        let mut value = vec![SourceValue::Leaf(NONE); links.len()];
        let mut far: Vec<u32> = Vec::new();
        for (k, l) in links.iter().enumerate() {
            if let Some(i) = cut.unknown_of(l.source) {
                value[k] = SourceValue::Leaf(cut.elements()[i]);
            } else if own_weights(h, &below, l) {
                let shares = &source_shares[k];
                let sum: f64 = shares.iter().sum();
                let begin = weight.len() as u32;
                weight_leaf.extend_from_slice(below.below(l.source));
                if sum > 0.0 {
                    weight.extend(shares.iter().map(|x| x / sum));
                } else {
                    let area = h.get(l.source).area;
                    weight.extend(below.below(l.source).iter().map(|&y| h.get(y).area / area));
                }
                value[k] = SourceValue::Own(begin, weight.len() as u32);
            } else {
                far.push(k as u32);
            }
        }
        far.sort_by_key(|&k| (links[k as usize].source, k));
        let mut shared = Vec::new();
        let mut i = 0;
        while i < far.len() {
            let s = links[far[i] as usize].source;
            let leaves = below.below(s);
            let begin = weight.len();
            weight_leaf.extend_from_slice(leaves);
            weight.resize(begin + leaves.len(), 0.0);
            while i < far.len() && links[far[i] as usize].source == s {
                let k = far[i] as usize;
                let shares = &source_shares[k];
                let total: f64 = shares.iter().sum();
                if total > 0.0 {
                    let scale = transfer[k] / total;
                    for (w, x) in weight[begin..].iter_mut().zip(shares) {
                        *w += scale * x;
                    }
                }
                value[k] = SourceValue::Shared(shared.len() as u32);
                i += 1;
            }
            let sum: f64 = weight[begin..].iter().sum();
            if sum > 0.0 {
                weight[begin..].iter_mut().for_each(|w| *w /= sum);
            } else {
                let area = h.get(s).area;
                for (w, &y) in weight[begin..].iter_mut().zip(leaves) {
                    *w = h.get(y).area / area;
                }
            }
            shared.push((s, begin, weight.len()));
        }
        let mut c = LeafCoefficients { start, link, coef, value, weight_leaf, weight, shared, closure: (1.0, 1.0) };
        if closed {
            c.close(cut, &transfer);
        }
        c
    }

    /// The smallest and largest factor the closure applied to a source unknown's delivered light
    /// (1 and 1 in an open scene): how far the links' visibility and form factors were from
    /// delivering each unknown's light whole.
    #[must_use]
    pub fn closure(&self) -> (f64, f64) {
        self.closure
    }

    /// In a closed scene every bit of light leaving a surface lands on another, so the fractions of
    /// each unknown's light that its links deliver sum to 1. Sampled visibility misses small
    /// occluders (a 5 cm lamp in a 4 m room, every wall seeing the others through it and the lamp
    /// too: 1e-4 of each wall's light counted twice, 0.26% of the power at ρ = 0.95) and quadrature
    /// leaves ~1e-5: scale each unknown's shares in all its links so that they sum to 1, and each
    /// link's receiver side with them. Energy is then conserved exactly.
    fn close(&mut self, cut: &Cut<'_>, transfer: &[f64]) {
        let h = cut.hierarchy();
        let n = cut.len();
        // Delivered fraction of every unknown: Σ_links τ q_y / A_y.
        let mut delivered = vec![0.0; n];
        let mut add = |y: ElementId, x: f64| {
            if let Some(i) = cut.unknown_of(y) {
                delivered[i] += x / h.get(cut.elements()[i]).area;
            }
        };
        for (k, v) in self.value.iter().enumerate() {
            match *v {
                SourceValue::Leaf(e) => add(e, transfer[k]),
                SourceValue::Own(lo, hi) => {
                    for (&y, &q) in self.weight_leaf[lo as usize..hi as usize].iter().zip(&self.weight[lo as usize..hi as usize]) {
                        add(y, transfer[k] * q);
                    }
                }
                SourceValue::Shared(i) => {
                    let (_, lo, hi) = self.shared[i as usize];
                    for (&y, &q) in self.weight_leaf[lo..hi].iter().zip(&self.weight[lo..hi]) {
                        add(y, transfer[k] * q);
                    }
                }
            }
        }
        let factor: Vec<f64> = delivered.iter().map(|&d| if d > 0.0 { (1.0 / d).clamp(CLOSURE_MIN, CLOSURE_MAX) } else { 1.0 }).collect();
        let f = |y: ElementId| cut.unknown_of(y).map_or(1.0, |i| factor[i]);
        // Rescale the weights of each range by the factors, renormalise, and keep each range's
        // mean factor: a link's transfer scales by its range's mean factor.
        let mut rescale = |lo: usize, hi: usize| -> f64 {
            let mut sum = 0.0;
            for (&y, w) in self.weight_leaf[lo..hi].iter().zip(&mut self.weight[lo..hi]) {
                *w *= f(y);
                sum += *w;
            }
            if sum > 0.0 {
                self.weight[lo..hi].iter_mut().for_each(|w| *w /= sum);
            }
            sum
        };
        let own_scale: Vec<Option<f64>> = self
            .value
            .iter()
            .map(|v| match *v {
                SourceValue::Own(lo, hi) => Some(rescale(lo as usize, hi as usize)),
                _ => None,
            })
            .collect();
        let shared_scale: Vec<f64> = (0..self.shared.len())
            .map(|i| {
                let (_, lo, hi) = self.shared[i];
                rescale(lo, hi)
            })
            .collect();
        let link_scale: Vec<f64> = self
            .value
            .iter()
            .zip(&own_scale)
            .map(|(v, own)| match *v {
                SourceValue::Leaf(e) => f(e),
                SourceValue::Own(..) => own.unwrap_or(1.0),
                SourceValue::Shared(i) => shared_scale[i as usize],
            })
            .collect();
        for (c, &k) in self.coef.iter_mut().zip(&self.link) {
            *c *= link_scale[k as usize];
        }
        let (lo, hi) = factor.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        self.closure = if factor.is_empty() { (1.0, 1.0) } else { (lo, hi) };
    }

    /// Stored coefficients and weights.
    #[must_use]
    pub fn entries(&self) -> usize {
        self.coef.len() + self.weight.len()
    }

    /// Heap bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        self.start.len() * size_of::<usize>()
            + self.link.len() * size_of::<u32>()
            + self.coef.len() * size_of::<f64>()
            + self.value.len() * size_of::<SourceValue>()
            + self.weight_leaf.len() * size_of::<ElementId>()
            + self.weight.len() * size_of::<f64>()
            + self.shared.len() * size_of::<(ElementId, usize, usize)>()
    }

    /// The radiosity each link sends (see the module docs), for leaf radiosity read from `b` (per
    /// element).
    fn link_values(&self, b: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let weighted = |lo: usize, hi: usize| {
            let mut acc = [0.0; 3];
            for (&y, &w) in self.weight_leaf[lo..hi].iter().zip(&self.weight[lo..hi]) {
                let by = b[y as usize];
                for c in 0..3 {
                    acc[c] += w * by[c];
                }
            }
            acc
        };
        let shared: Vec<[f64; 3]> = self.shared.par_iter().map(|&(_, lo, hi)| weighted(lo, hi)).collect();
        self.value
            .par_iter()
            .map(|v| match *v {
                SourceValue::Leaf(e) => b[e as usize],
                SourceValue::Own(lo, hi) => weighted(lo as usize, hi as usize),
                SourceValue::Shared(i) => shared[i as usize],
            })
            .collect()
    }
}

/// The form factor `F(leaf ← source)` that shares a link's transfer among the receiver's leaves:
/// the point value at the leaf's centre when the source is far ([`WEIGHT_FAR_SEPARATION`]), the
/// precise one otherwise. (The shares are scaled to the link's transfer, so only their ratios
/// matter.)
fn shape_form_factor(h: &Hierarchy, source: ElementId, leaf: ElementId) -> f64 {
    let (s, e) = (h.get(source), h.get(leaf));
    let separation = (s.center - e.center).length() / (s.radius + e.radius).max(f64::MIN_POSITIVE);
    if separation >= WEIGHT_FAR_SEPARATION && !formfactor::behind_surface(s, e.poly().map(|p| p.vertices().to_vec()).unwrap_or_default()) {
        formfactor::point_to_element(h, e.center, e.normal, source)
    } else if separation >= formfactor::NEAR_SEPARATION && e.poly().is_some() && s.poly().is_some() {
        formfactor::link_form_factor(h, source, leaf, FormFactorQuality::Shape)
    } else {
        formfactor::link_form_factor(h, source, leaf, FormFactorQuality::Precise)
    }
}

/// The form factor `F(y ← receiver)` that weights source leaf `y` of a link to `receiver`: the
/// point value at `y`'s centre when far, the precise one otherwise.
fn weight_form_factor(h: &Hierarchy, receiver: ElementId, y: ElementId) -> f64 {
    let (r, e) = (h.get(receiver), h.get(y));
    let separation = (r.center - e.center).length() / (r.radius + e.radius).max(f64::MIN_POSITIVE);
    if separation >= WEIGHT_FAR_SEPARATION && e.poly().is_some() {
        formfactor::point_to_element(h, e.center, e.normal, receiver)
    } else {
        formfactor::link_form_factor(h, receiver, y, FormFactorQuality::Precise)
    }
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

/// Links grouped by receiver (sorted by receiver, then source).
pub(super) struct LinksByReceiver<'l> {
    links: &'l [Link],
    sorted: Vec<u32>,
    range: Vec<(u32, u32)>,
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

impl<'a> LeafOperator<'a> {
    /// The operator of `h` and `links` with coefficients computed by [`LeafCoefficients::new`] for
    /// the same hierarchy and links (the emission may have changed since).
    #[must_use]
    pub fn new(h: &'a Hierarchy, _links: &[Link], coefficients: &'a LeafCoefficients) -> LeafOperator<'a> {
        LeafOperator { cut: Cut::leaves(h), lists: coefficients }
    }

    /// The operator on the unknowns of `cut`, with coefficients computed by
    /// [`LeafCoefficients::for_cut`] for the same cut and links.
    #[must_use]
    pub fn for_cut(cut: Cut<'a>, coefficients: &'a LeafCoefficients) -> LeafOperator<'a> {
        LeafOperator { cut, lists: coefficients }
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

    /// Irradiance of every unknown (in cut order) for the unknowns' radiosity `x`.
    #[must_use]
    pub fn gather_leaves(&self, x: &[f64]) -> Vec<[f64; 3]> {
        let b = self.cut.pull(x);
        let l = self.lists;
        let values = l.link_values(&b);
        (0..self.cut.len())
            .into_par_iter()
            .map(|i| {
                let mut acc = [0.0; 3];
                for k in l.start[i]..l.start[i + 1] {
                    let bs = values[l.link[k] as usize];
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
