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
//! stores one coefficient per (leaf, chain link) in a [`Precision`] (`f32`, or 16 bits for a target
//! error of [`HALF_MIN_TARGET`] or coarser), in chain order (the link is implied), and
//! one weight per (link source, leaf below it); beyond a budget of coefficients the remaining
//! leaves' coefficients are computed again at every application, so that a budget costs time but
//! never changes the answer.

use super::cut::Cut;
use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::refine::Link;
use rayon::prelude::*;

/// Default budget of the leaf-resolution operator's stored coefficients, in bytes (what 40 M
/// coefficients with their link indices in `f64` took before): beyond it the coefficients of the
/// remaining unknowns are recomputed at every application instead of stored
/// ([`LeafCoefficients::for_cut`]): the same operator, bit for bit, only slower.
pub const LEAF_OPERATOR_MAX_BYTES: usize = 480_000_000;

/// How the leaf operator stores its chain coefficients (the link each belongs to is implied by its
/// place in the unknown's chain of links, so only the value is stored).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// `f32`: 4 bytes, rounding below 1e-7 relative.
    Single,
    /// A 16-bit logarithmic code of the values in `[2⁻⁴⁶, 4)`: 2 bytes, rounding at most
    /// [`HALF_ROUNDING`] relative; smaller values (below 1.5e-14, where a form factor is 1 at most)
    /// are dropped.
    Half,
}

/// Largest relative rounding of a [`Precision::Half`] coefficient: half a step of the code,
/// `2^(24/65534) − 1` = 2.54e-4, with the `f32` rounding of the value and of its decoded form.
pub const HALF_ROUNDING: f64 = 2.6e-4;

/// Smallest target error whose solves store [`Precision::Half`] coefficients: each coefficient is
/// then rounded by at most a quarter of the target (and the rounding, of either sign from one
/// coefficient to the next, averages out over a polygon's leaves). Finer targets, and solves
/// without one, store `f32`.
pub const HALF_MIN_TARGET: f64 = 1e-3;

/// Log₂ of the smallest [`Precision::Half`] code's value.
const CODE_LOG2_MIN: f64 = -46.0;
/// Octaves the [`Precision::Half`] codes span.
const CODE_LOG2_SPAN: f64 = 48.0;
/// Steps between the smallest and the largest code (code 0 is zero).
const CODE_STEPS: f64 = 65534.0;

impl Precision {
    /// The precision of a solve with `target` error ([`HALF_MIN_TARGET`]).
    #[must_use]
    pub fn for_target(target: Option<f64>) -> Precision {
        match target {
            Some(t) if t >= HALF_MIN_TARGET => Precision::Half,
            _ => Precision::Single,
        }
    }

    /// Bytes of one stored coefficient.
    #[must_use]
    pub fn bytes(self) -> usize {
        match self {
            Precision::Single => size_of::<f32>(),
            Precision::Half => size_of::<u16>(),
        }
    }

    /// The value a coefficient `c` (non-negative) is applied with: `c` itself, or its code's value.
    #[must_use]
    pub fn round(self, c: f32) -> f32 {
        match self {
            Precision::Single => c,
            Precision::Half => decode(encode(c)),
        }
    }
}

/// The [`Precision::Half`] code of `c ≥ 0`: 0 below the smallest code's value, otherwise the
/// nearest code on the logarithmic scale (values from 4 up get the largest code; form factors are
/// below 1).
fn encode(c: f32) -> u16 {
    let c = f64::from(c);
    if c.is_nan() || c < CODE_LOG2_MIN.exp2() {
        return 0;
    }
    let t = ((c.log2() - CODE_LOG2_MIN) * (CODE_STEPS / CODE_LOG2_SPAN)).round();
    1 + t.min(CODE_STEPS) as u16
}

/// The value of a [`Precision::Half`] code.
fn decode(code: u16) -> f32 {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..=u16::MAX)
            .map(|code| if code == 0 { 0.0 } else { (CODE_LOG2_MIN + f64::from(code - 1) * (CODE_LOG2_SPAN / CODE_STEPS)).exp2() as f32 })
            .collect()
    });
    table[usize::from(code)]
}

/// Stored chain coefficients, in either [`Precision`].
#[derive(Clone, Debug)]
enum Stored {
    Single(Vec<f32>),
    Half(Vec<u16>),
}

impl Stored {
    fn len(&self) -> usize {
        match self {
            Stored::Single(v) => v.len(),
            Stored::Half(v) => v.len(),
        }
    }

    fn precision(&self) -> Precision {
        match self {
            Stored::Single(_) => Precision::Single,
            Stored::Half(_) => Precision::Half,
        }
    }

    /// The value coefficient `j` is applied with.
    fn get(&self, j: usize) -> f32 {
        match self {
            Stored::Single(v) => v[j],
            Stored::Half(v) => decode(v[j]),
        }
    }
}

/// Source leaves farther from a receiver than this many times the sum of their bounding radii get
/// their weight from the point form factor at their centre rather than the precise one (the
/// weights only share a link's transfer among the source's leaves).
pub const WEIGHT_FAR_SEPARATION: f64 = 4.0;

/// Per-leaf gather lists over the chain of ancestor links, with conservative source values.
pub struct LeafOperator<'a> {
    cut: Cut<'a>,
    links: &'a [Link],
    lists: &'a LeafCoefficients,
}

/// The coefficients of a [`LeafOperator`]: geometry only (form factors and visibility), so they
/// serve every emission of the same hierarchy and links (the instanced solver keeps them with a
/// level it reuses).
///
/// Each unknown's coefficients along its chain of links (`F(unknown ← source) V`, rounded to
/// `f32`) are stored in chain order for the first [`LeafCoefficients::stored_unknowns`] unknowns,
/// and recomputed, identically, at every application for the rest (beyond the budget the
/// coefficients were built with). What makes the operator conserve energy is kept per link, in
/// `f64`: the receiver side's scale and the source side's weights.
#[derive(Clone, Debug)]
pub struct LeafCoefficients {
    /// Link indices sorted by (receiver, source), and each element's range in it.
    sorted: Vec<u32>,
    range: Vec<(u32, u32)>,
    /// Start of each stored unknown's chain coefficients in `coef` (length stored + 1).
    start: Vec<usize>,
    coef: Stored,
    /// Chain coefficients of every unknown, stored or not.
    chain_entries: usize,
    /// Links received inside an unknown (below it, on a coarsened cut): `(link, coefficient)`
    /// ranges per unknown (empty at leaf resolution).
    inside_start: Vec<u32>,
    inside: Vec<(u32, f64)>,
    /// Per link: the factor on its receiver-side coefficients that makes them carry the link's
    /// transfer (and, in a closed scene, the closure factor of its source).
    scale: Vec<f64>,
    /// Per link, where its source value comes from.
    value: Vec<SourceValue>,
    /// The leaves below each source with weights, once per source (every range of weights of a
    /// source is over the same leaves, in the same order).
    weight_leaf: Vec<ElementId>,
    /// Weights of source leaves: ranges referred to by [`SourceValue`], each with the start of
    /// its source's leaves in `weight_leaf`.
    weight: Vec<f64>,
    /// Sources with shared weights: `(source, start, end, leaves)` into `weight`, and the start
    /// of its leaves in `weight_leaf`.
    shared: Vec<(ElementId, usize, usize, usize)>,
    /// Smallest and largest closure factor applied ([`LeafCoefficients::closure`]).
    closure: (f64, f64),
    /// Per link, the closure factor on its transfer less 1 (empty in an open scene).
    closure_change: Vec<f32>,
}

/// Smallest closure factor of one unknown: delivering more than twice its light means something
/// other than sampling noise, and is not corrected beyond this.
pub const CLOSURE_MIN: f64 = 0.5;
/// Largest change `|factor − 1|` of the closure taken as correcting sampled visibility and
/// quadrature ([`LeafCoefficients::closure_changes`], counted in the error estimate): those are
/// 1e-5 to 1e-3 (CIE 171 5.8: 5e-4; a 5 cm lamp in a 4 m room: 1e-4). Larger factors make up for
/// an unknown partly covered by something standing on it ([`CLOSURE_MAX`]), which is geometry,
/// not error: counting them kept the 1990 room with partitions refining to 8.8M links.
pub const CLOSURE_NOISE_MAX: f64 = 0.02;
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
    /// The link's own weights (`start..end` of `weight`, summing to 1), and the start of its
    /// source's leaves in `weight_leaf`.
    Own(u32, u32, u32),
    /// The weights shared by the source's far links (entry of `shared`).
    Shared(u32),
}

/// Sources whose leaf weights are made at a time when the leaf operator is built (in parallel
/// within a chunk): their weights are held twice until copied into place.
pub const WEIGHT_CHUNK: usize = 4096;

/// Links nearer than this (centre distance over the sum of the bounding radii) weight their
/// source's leaves by their own kernel; farther links share one set of weights per source (the
/// kernel varies little over a far source).
pub const OWN_WEIGHTS_SEPARATION: f64 = 4.0;

/// Chain coefficients computed at a time while the receiver totals of unstored unknowns are
/// summed (a bounded buffer, filled in parallel, summed in order).
const STREAM_BATCH_ENTRIES: usize = 1 << 20;

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

/// The chain of links of one unknown: every link received at the unknown or an ancestor, in the
/// order coefficients are stored in.
#[derive(Clone, Copy)]
struct Chain<'c> {
    h: &'c Hierarchy,
    links: &'c [Link],
    sorted: &'c [u32],
    range: &'c [(u32, u32)],
    precision: Precision,
}

impl Chain<'_> {
    /// Number of links on the chain of `leaf`.
    fn len(&self, leaf: ElementId) -> usize {
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
    fn for_each_link(&self, leaf: ElementId, mut f: impl FnMut(u32)) {
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
                let l = &self.links[k as usize];
                let ff = if a == leaf { l.ff } else { shape_form_factor(self.h, l.source, leaf) };
                let c = ff * l.vis;
                f(k, if c > 0.0 { c as f32 } else { 0.0 });
            }
            a = self.h.get(a).parent;
        }
    }

    /// [`Chain::for_each_raw`] with every value as it is applied in the chain's [`Precision`]: what
    /// a stored coefficient decodes to.
    fn for_each(&self, leaf: ElementId, mut f: impl FnMut(u32, f32)) {
        let p = self.precision;
        self.for_each_raw(leaf, |k, c| f(k, p.round(c)));
    }

    /// Fills `coef` with the chain coefficients of `unknowns` (in order, `start` their offsets
    /// relative to `coef`, length `unknowns.len() + 1`), each as `store` turns it, in parallel.
    fn fill<T: Send>(&self, unknowns: &[ElementId], start: &[usize], coef: &mut [T], store: impl Fn(f32) -> T + Sync) {
        let mut slices: Vec<&mut [T]> = Vec::with_capacity(unknowns.len());
        let mut rest = coef;
        for w in start.windows(2) {
            let (a, b) = std::mem::take(&mut rest).split_at_mut(w[1] - w[0]);
            slices.push(a);
            rest = b;
        }
        slices.into_par_iter().zip(unknowns.par_iter()).with_min_len(16).for_each(|(out, &u)| {
            let mut j = 0;
            self.for_each_raw(u, |_, c| {
                out[j] = store(c);
                j += 1;
            });
        });
    }
}

impl LeafCoefficients {
    /// Evaluates `link_form_factor(source, leaf)` for every leaf and every link on its chain, and
    /// the source weights, each link's two sides scaled to the same transfer (see the module docs).
    #[must_use]
    pub fn new(h: &Hierarchy, links: &[Link]) -> LeafCoefficients {
        LeafCoefficients::for_cut(&Cut::leaves(h), links, false, usize::MAX, Precision::Single)
    }

    /// [`LeafCoefficients::new`] with the unknowns of `cut` in place of the leaves: a link received
    /// below an unknown adds its transfer to the unknown's mean (area-weighted), a link sent from
    /// below one sends the unknown's radiosity. In a `closed` scene every unknown's light is
    /// delivered whole ([`LeafCoefficients::closure`]). Chain coefficients are stored in
    /// `precision` for the unknowns, in cut order, whose coefficients fit in `max_bytes` with
    /// those before them; the others' are recomputed at every application (see
    /// [`LeafCoefficients::stored_unknowns`]).
    #[must_use]
    pub fn for_cut(cut: &Cut<'_>, links: &[Link], closed: bool, max_bytes: usize, precision: Precision) -> LeafCoefficients {
        let h = cut.hierarchy();
        let LinksByReceiver { sorted, range, .. } = LinksByReceiver::new(h, links);
        let chain = Chain { h, links, sorted: &sorted, range: &range, precision };
        let max_stored = max_bytes / precision.bytes();
        let unknowns = cut.elements();
        // Receiver side, along each unknown's chain: stored while within the budget.
        let lens: Vec<usize> = unknowns.par_iter().map(|&u| chain.len(u)).collect();
        let chain_entries: usize = lens.iter().sum();
        let mut start = Vec::with_capacity(unknowns.len() + 1);
        start.push(0);
        for &len in &lens {
            let next = start[start.len() - 1] + len;
            if next > max_stored {
                break;
            }
            start.push(next);
        }
        let stored = start.len() - 1;
        let coef = match precision {
            Precision::Single => {
                let mut v = vec![0.0f32; start[stored]];
                chain.fill(&unknowns[..stored], &start, &mut v, |c| c);
                Stored::Single(v)
            }
            Precision::Half => {
                let mut v = vec![0u16; start[stored]];
                chain.fill(&unknowns[..stored], &start, &mut v, encode);
                Stored::Half(v)
            }
        };
        // Links received inside an unknown: their transfer, spread over its area.
        let inside_lists: Vec<Vec<(u32, f64)>> = unknowns
            .par_iter()
            .map(|&u| {
                let area = h.get(u).area;
                let mut list = Vec::new();
                let mut stack: Vec<ElementId> = h.children_of(u).to_vec();
                while let Some(d) = stack.pop() {
                    let (lo, hi) = range[d as usize];
                    for &k in &sorted[lo as usize..hi as usize] {
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
        let mut inside_start = Vec::with_capacity(unknowns.len() + 1);
        inside_start.push(0u32);
        let mut inside = Vec::new();
        for list in inside_lists {
            inside.extend(list);
            inside_start.push(inside.len() as u32);
        }
        // The receiver side's total per link, `Σ_unknowns A F V`, summed in cut order (unstored
        // unknowns' coefficients computed a batch at a time).
        let mut receiver_total = vec![0.0; links.len()];
        // Adds unknown `i`'s `A F V` to its links' totals, its `j`th chain coefficient `coef(j)`.
        let mut add_unknown = |i: usize, coef: &dyn Fn(usize) -> f32| {
            let u = unknowns[i];
            let area = h.get(u).area;
            let mut j = 0;
            chain.for_each_link(u, |k| {
                receiver_total[k as usize] += area * f64::from(coef(j));
                j += 1;
            });
            for &(k, c) in &inside[inside_start[i] as usize..inside_start[i + 1] as usize] {
                receiver_total[k as usize] += area * c;
            }
        };
        for (i, w) in start.windows(2).enumerate() {
            add_unknown(i, &|j| coef.get(w[0] + j));
        }
        let mut first = stored;
        let mut buffer = Vec::new();
        while first < unknowns.len() {
            let mut batch_start = vec![0];
            let mut last = first;
            while last < unknowns.len() && (last == first || batch_start[batch_start.len() - 1] + lens[last] <= STREAM_BATCH_ENTRIES) {
                batch_start.push(batch_start[batch_start.len() - 1] + lens[last]);
                last += 1;
            }
            buffer.clear();
            buffer.resize(batch_start[batch_start.len() - 1], 0.0f32);
            chain.fill(&unknowns[first..last], &batch_start, &mut buffer, |c| precision.round(c));
            for i in first..last {
                let b = &buffer[batch_start[i - first]..];
                add_unknown(i, &|j| b[j]);
            }
            first = last;
        }
        drop(buffer);
        // The transfer each link carries, from the side evaluated exactly: between surfaces the
        // link's own `A_R F V` (its precise form factor); from a surface to a cluster the sum over
        // the receiver's unknowns (each with its precise form factor from the surface); from a
        // cluster to a surface the sum over the source's unknowns (likewise, by reciprocity, set
        // with the source side below); between clusters the receiver's sum.
        let mut transfer: Vec<f64> = links
            .iter()
            .enumerate()
            .map(|(k, l)| {
                if h.get(l.source).poly().is_some() && h.get(l.receiver).poly().is_some() {
                    h.get(l.receiver).area * l.ff * l.vis
                } else {
                    receiver_total[k]
                }
            })
            .collect();
        // Source side: per link, `A_y F(y ← receiver) V` for every unknown `y` below a source
        // above the cut, computed per source (its links together) and kept only as weights.
        let below = LeavesBelow::new(cut);
        let mut value = vec![SourceValue::Leaf(NONE); links.len()];
        let mut by_source: Vec<u32> = Vec::new();
        for (k, l) in links.iter().enumerate() {
            match cut.unknown_of(l.source) {
                Some(i) => value[k] = SourceValue::Leaf(unknowns[i]),
                None => by_source.push(k as u32),
            }
        }
        by_source.sort_by_key(|&k| (links[k as usize].source, k));
        let groups: Vec<&[u32]> = by_source.chunk_by(|&a, &b| links[a as usize].source == links[b as usize].source).collect();
        // The weights are made a chunk of sources at a time into vectors of their exact size:
        // made all at once, then copied into vectors grown by doubling, they held up to three
        // times their size (573 MB of a 1.01 GB heap peak on a 3,200-leaf canopy).
        let (mut n_leaves, mut n_weights) = (0, 0);
        for group in &groups {
            let s = links[group[0] as usize].source;
            let n = below.below(s).len();
            let own = group.iter().filter(|&&k| own_weights(h, &below, &links[k as usize])).count();
            n_leaves += n;
            n_weights += n * (own + usize::from(own < group.len()));
        }
        let (mut weight_leaf, mut weight) = (Vec::with_capacity(n_leaves), Vec::with_capacity(n_weights));
        let mut shared = Vec::new();
        for chunk in groups.chunks(WEIGHT_CHUNK) {
            let results: Vec<SourceWeights> = chunk.par_iter().map(|group| source_weights(h, links, &below, group, &transfer)).collect();
            for (group, r) in chunk.iter().zip(results) {
                let s = links[group[0] as usize].source;
                for (k, t) in r.transfer {
                    transfer[k as usize] = t;
                }
                if r.own.is_empty() && r.shared.is_none() {
                    continue;
                }
                let leaves = weight_leaf.len();
                weight_leaf.extend_from_slice(below.below(s));
                for (k, w) in r.own {
                    let begin = weight.len() as u32;
                    weight.extend(w);
                    value[k as usize] = SourceValue::Own(begin, weight.len() as u32, leaves as u32);
                }
                if let Some(w) = r.shared {
                    let begin = weight.len();
                    weight.extend(w);
                    for &k in r.far.iter() {
                        value[k as usize] = SourceValue::Shared(shared.len() as u32);
                    }
                    shared.push((s, begin, weight.len(), leaves));
                }
            }
        }
        let scale: Vec<f64> = transfer.iter().zip(&receiver_total).map(|(&t, &r)| if r > 0.0 { t / r } else { 1.0 }).collect();
        let mut c = LeafCoefficients {
            sorted,
            range,
            start,
            coef,
            chain_entries,
            inside_start,
            inside,
            scale,
            value,
            weight_leaf,
            weight,
            shared,
            closure: (1.0, 1.0),
            closure_change: Vec::new(),
        };
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

    /// Per link (in the order of the links given), the factor the closure applied to the light
    /// it carries, less 1, where that is a correction of sampling (`CLOSURE_NOISE_MAX`, 2%; 0 where
    /// it makes up for a cover); empty in an open scene. See [`super::closure_error`].
    #[must_use]
    pub fn closure_changes(&self) -> &[f32] {
        &self.closure_change
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
            let (lo, hi, leaves) = match *v {
                SourceValue::Leaf(e) => {
                    add(e, transfer[k]);
                    continue;
                }
                SourceValue::Own(lo, hi, leaves) => (lo as usize, hi as usize, leaves as usize),
                SourceValue::Shared(i) => {
                    let (_, lo, hi, leaves) = self.shared[i as usize];
                    (lo, hi, leaves)
                }
            };
            for (&y, &q) in self.weighted_leaves(lo, hi, leaves) {
                add(y, transfer[k] * q);
            }
        }
        let factor: Vec<f64> = delivered.iter().map(|&d| if d > 0.0 { (1.0 / d).clamp(CLOSURE_MIN, CLOSURE_MAX) } else { 1.0 }).collect();
        let f = |y: ElementId| cut.unknown_of(y).map_or(1.0, |i| factor[i]);
        // Rescale the weights of each range by the factors, renormalise, and keep each range's
        // mean factor: a link's transfer scales by its range's mean factor.
        let mut rescale = |lo: usize, hi: usize, leaves: usize| -> f64 {
            let mut sum = 0.0;
            for (&y, w) in self.weight_leaf[leaves..leaves + hi - lo].iter().zip(&mut self.weight[lo..hi]) {
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
                SourceValue::Own(lo, hi, leaves) => Some(rescale(lo as usize, hi as usize, leaves as usize)),
                _ => None,
            })
            .collect();
        let shared_scale: Vec<f64> = (0..self.shared.len())
            .map(|i| {
                let (_, lo, hi, leaves) = self.shared[i];
                rescale(lo, hi, leaves)
            })
            .collect();
        self.closure_change = Vec::with_capacity(self.scale.len());
        for ((s, v), own) in self.scale.iter_mut().zip(&self.value).zip(&own_scale) {
            let m = match *v {
                SourceValue::Leaf(e) => f(e),
                SourceValue::Own(..) => own.unwrap_or(1.0),
                SourceValue::Shared(i) => shared_scale[i as usize],
            };
            *s *= m;
            // Beyond sampling's reach the factor makes up for a cover, which is geometry.
            let noise = if (m - 1.0).abs() <= CLOSURE_NOISE_MAX { m - 1.0 } else { 0.0 };
            self.closure_change.push(noise as f32);
        }
        let (lo, hi) = factor.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        self.closure = if factor.is_empty() { (1.0, 1.0) } else { (lo, hi) };
    }

    /// How the chain coefficients are stored.
    #[must_use]
    pub fn precision(&self) -> Precision {
        self.coef.precision()
    }

    /// Stored coefficients and weights.
    #[must_use]
    pub fn entries(&self) -> usize {
        self.coef.len() + self.inside.len() + self.weight.len()
    }

    /// Chain coefficients of every unknown, stored or recomputed at every application.
    #[must_use]
    pub fn chain_entries(&self) -> usize {
        self.chain_entries
    }

    /// How many unknowns (the first ones, in cut order) have their chain coefficients stored; the
    /// others' are recomputed at every application, giving the same values.
    #[must_use]
    pub fn stored_unknowns(&self) -> usize {
        self.start.len() - 1
    }

    /// The share of the chain coefficients computed again at every application (0 when all are
    /// stored).
    #[must_use]
    pub fn recomputed_share(&self) -> f64 {
        if self.chain_entries == 0 { 0.0 } else { 1.0 - self.coef.len() as f64 / self.chain_entries as f64 }
    }

    /// Whether every unknown's chain coefficients are stored.
    #[must_use]
    pub fn is_complete(&self) -> bool {
        self.stored_unknowns() + 1 == self.inside_start.len()
    }

    /// Heap bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        self.sorted.len() * size_of::<u32>()
            + self.range.len() * size_of::<(u32, u32)>()
            + self.start.len() * size_of::<usize>()
            + self.coef.len() * self.coef.precision().bytes()
            + self.inside_start.len() * size_of::<u32>()
            + self.inside.len() * size_of::<(u32, f64)>()
            + self.scale.len() * size_of::<f64>()
            + self.value.len() * size_of::<SourceValue>()
            + self.weight_leaf.len() * size_of::<ElementId>()
            + self.weight.len() * size_of::<f64>()
            + self.shared.len() * size_of::<(ElementId, usize, usize, usize)>()
    }

    /// The leaves and weights of the range `lo..hi` of `weight`, whose source's leaves start at
    /// `leaves` in `weight_leaf`.
    fn weighted_leaves(&self, lo: usize, hi: usize, leaves: usize) -> impl Iterator<Item = (&ElementId, &f64)> {
        self.weight_leaf[leaves..leaves + hi - lo].iter().zip(&self.weight[lo..hi])
    }

    /// The radiosity each link sends (see the module docs), for leaf radiosity read from `b` (per
    /// element), times the link's receiver-side scale.
    fn link_values(&self, b: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let weighted = |lo: usize, hi: usize, leaves: usize| {
            let mut acc = [0.0; 3];
            for (&y, &w) in self.weighted_leaves(lo, hi, leaves) {
                let by = b[y as usize];
                for c in 0..3 {
                    acc[c] += w * by[c];
                }
            }
            acc
        };
        let shared: Vec<[f64; 3]> = self.shared.par_iter().map(|&(_, lo, hi, leaves)| weighted(lo, hi, leaves)).collect();
        self.value
            .par_iter()
            .zip(&self.scale)
            .map(|(v, &s)| {
                let x = match *v {
                    SourceValue::Leaf(e) => b[e as usize],
                    SourceValue::Own(lo, hi, leaves) => weighted(lo as usize, hi as usize, leaves as usize),
                    SourceValue::Shared(i) => shared[i as usize],
                };
                x.map(|x| x * s)
            })
            .collect()
    }
}

/// What the source side of one source's links gives: the transfer of its links from a cluster to
/// a surface (the sum over the source's unknowns), each near link's own weights, and the far
/// links' shared weights.
struct SourceWeights {
    transfer: Vec<(u32, f64)>,
    own: Vec<(u32, Vec<f64>)>,
    far: Vec<u32>,
    shared: Option<Vec<f64>>,
}

/// The source side of the links of `group` (one source above the cut): each link's shares
/// `A_y F(y ← receiver) V` over the source's unknowns `y`, normalised into its own weights (a near
/// link) or, scaled to the link's transfer, summed into the source's shared weights (far links).
fn source_weights(h: &Hierarchy, links: &[Link], below: &LeavesBelow, group: &[u32], transfer: &[f64]) -> SourceWeights {
    let s = links[group[0] as usize].source;
    let leaves = below.below(s);
    let area_weights = || -> Vec<f64> {
        let area = h.get(s).area;
        leaves.iter().map(|&y| h.get(y).area / area).collect()
    };
    let mut out = SourceWeights { transfer: Vec::new(), own: Vec::new(), far: Vec::new(), shared: None };
    let mut acc: Vec<f64> = Vec::new();
    let mut shares = Vec::with_capacity(leaves.len());
    for &k in group {
        let l = &links[k as usize];
        shares.clear();
        shares.extend(leaves.iter().map(|&y| h.get(y).area * weight_form_factor(h, l.receiver, y) * l.vis));
        let total: f64 = shares.iter().sum();
        let mut t = transfer[k as usize];
        if h.get(l.source).poly().is_none() && h.get(l.receiver).poly().is_some() && total > 0.0 {
            t = total;
            out.transfer.push((k, t));
        }
        if own_weights(h, below, l) {
            let w = if total > 0.0 { shares.iter().map(|x| x / total).collect() } else { area_weights() };
            out.own.push((k, w));
        } else {
            acc.resize(leaves.len(), 0.0);
            if total > 0.0 {
                let scale = t / total;
                for (w, x) in acc.iter_mut().zip(&shares) {
                    *w += scale * x;
                }
            }
            out.far.push(k);
        }
    }
    if !out.far.is_empty() {
        let sum: f64 = acc.iter().sum();
        out.shared = Some(if sum > 0.0 { acc.iter().map(|w| w / sum).collect() } else { area_weights() });
    }
    out
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
                            add(k, decode(v[j]));
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value in the code's range comes back within [`HALF_ROUNDING`], in order; zero and
    /// values below the range come back as zero; `f32` values are kept as they are.
    #[test]
    fn half_coefficients_round_by_at_most_half_rounding() {
        let (lo, hi) = (CODE_LOG2_MIN.exp2(), 3.99f64);
        let n = 400_000;
        let mut worst = 0.0f64;
        let mut last = 0.0f32;
        for i in 0..=n {
            let c = (lo * (hi / lo).powf(f64::from(i) / f64::from(n))) as f32;
            let r = Precision::Half.round(c);
            worst = worst.max((f64::from(r) - f64::from(c)).abs() / f64::from(c));
            assert!(r >= last, "decoded values out of order at {c}: {r} < {last}");
            last = r;
        }
        assert!(worst <= HALF_ROUNDING, "relative rounding {worst:.3e} over {HALF_ROUNDING:.1e}");
        assert!(worst > 0.5 * HALF_ROUNDING, "the bound is tight: {worst:.3e}");
        assert_eq!(Precision::Half.round(0.0), 0.0);
        assert_eq!(Precision::Half.round((0.4 * lo) as f32), 0.0);
        assert_eq!(Precision::Single.round(0.123_456_78), 0.123_456_78);
        assert_eq!(Precision::for_target(Some(0.01)), Precision::Half);
        assert_eq!(Precision::for_target(Some(HALF_MIN_TARGET)), Precision::Half);
        assert_eq!(Precision::for_target(Some(0.0003)), Precision::Single);
        assert_eq!(Precision::for_target(None), Precision::Single);
    }
}
