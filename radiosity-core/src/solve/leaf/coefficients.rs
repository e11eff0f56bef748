//! Building the leaf operator's coefficients ([`LeafCoefficients`]) for a cut: the receiver side
//! along each unknown's chain (stored within the budget), the links received inside an unknown,
//! each link's transfer, the source side's weights, the closure of a closed scene, and the value
//! each link sends. The contract they keep is in the folder's `mod.rs`.

use super::chain::{Chain, LeavesBelow, fill_each};
use super::precision::{Precision, Stored, encode};
use super::reuse::ChainReuse;
use super::weights::{SourceWeights, own_weights, source_weights};
use super::{
    CLOSURE_MAX, CLOSURE_MIN, CLOSURE_NOISE_MAX, LeafCoefficients, STREAM_BATCH_ENTRIES, SourceValue, WEIGHT_CHUNK, WEIGHT_CHUNK_ENTRIES,
};
use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::refine::Link;
use crate::solve::by_receiver::LinksByReceiver;
use crate::solve::cut::Cut;
use rayon::prelude::*;

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
        LeafCoefficients::for_cut_reusing(cut, links, closed, max_bytes, precision, None)
    }

    /// [`LeafCoefficients::for_cut`] taking from `earlier` (an earlier level's, of the same run)
    /// the chain coefficients it holds of the same unknown on the same link: the same values,
    /// bit for bit, without their form factors ([`LeafCoefficients::reused_entries`] counts them).
    /// `earlier` is dropped as soon as the chain coefficients are made, before the source weights.
    #[must_use]
    pub fn for_cut_reusing(
        cut: &Cut<'_>,
        links: &[Link],
        closed: bool,
        max_bytes: usize,
        precision: Precision,
        earlier: Option<ChainReuse>,
    ) -> LeafCoefficients {
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
        let (coef, reused) = match precision {
            Precision::Single => {
                let mut v = vec![0.0f32; start[stored]];
                let reused = chain.fill(&unknowns[..stored], &start, &mut v, |c| c, earlier.as_ref().and_then(ChainReuse::single));
                (Stored::Single(v), reused)
            }
            Precision::Half => {
                let mut v = vec![0u16; start[stored]];
                let reused = chain.fill(&unknowns[..stored], &start, &mut v, encode, earlier.as_ref().and_then(ChainReuse::half));
                (Stored::Half(v), reused)
            }
        };
        // The earlier level's coefficients go before the source weights are made.
        drop(earlier);
        let (inside_start, inside) = inside_links(h, unknowns, &sorted, &range, links);
        // The receiver side's total per link, `Σ_unknowns A F V`, summed in cut order (unstored
        // unknowns' coefficients computed a batch at a time).
        let mut receiver_total = vec![0.0; links.len()];
        // Adds unknown `i`'s `A F V` to its links' totals, its `j`th chain coefficient `coef(j)`.
        let mut add_unknown = |i: usize, coef: &dyn Fn(usize) -> f32| {
            let inside = &inside[inside_start[i] as usize..inside_start[i + 1] as usize];
            add_receiver_totals(&mut receiver_total, &chain, unknowns[i], inside, coef);
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
            chain.fill(&unknowns[first..last], &batch_start, &mut buffer, |c| precision.round(c), None);
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
        // A chunk holds at most WEIGHT_CHUNK sources and WEIGHT_CHUNK_ENTRIES weights, or one source.
        let mut chunk_ends = Vec::new();
        let (mut in_chunk, mut chunk_sources) = (0, 0);
        for (i, group) in groups.iter().enumerate() {
            let s = links[group[0] as usize].source;
            let n = below.below(s).len();
            let own = group.iter().filter(|&&k| own_weights(h, &below, &links[k as usize])).count();
            let entries = n * (own + usize::from(own < group.len()));
            if chunk_sources > 0 && (chunk_sources == WEIGHT_CHUNK || in_chunk + entries > WEIGHT_CHUNK_ENTRIES) {
                chunk_ends.push(i);
                (in_chunk, chunk_sources) = (0, 0);
            }
            in_chunk += entries;
            chunk_sources += 1;
            n_leaves += n;
            n_weights += entries;
        }
        chunk_ends.push(groups.len());
        // A closed scene's closure rescales the weights in place, in `f32`.
        let weight_precision = if closed { Precision::Single } else { precision };
        let (mut weight_leaf, mut weight) = (Vec::with_capacity(n_leaves), Stored::with_capacity(weight_precision, n_weights));
        let mut shared = Vec::new();
        let mut chunk_start = 0;
        for &chunk_end in &chunk_ends {
            let chunk = &groups[chunk_start..chunk_end];
            chunk_start = chunk_end;
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
                    weight.extend_f64(&w);
                    value[k as usize] = SourceValue::Own(begin, weight.len() as u32, leaves as u32);
                }
                if let Some(w) = r.shared {
                    let begin = weight.len();
                    weight.extend_f64(&w);
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
            reused,
            chain_entries,
            inside_start,
            inside,
            scale,
            transfer,
            value,
            weight_leaf,
            weight,
            shared,
            closed,
            closure: (1.0, 1.0),
            closure_change: Vec::new(),
        };
        c.normalise_weights();
        if closed {
            c.close(cut);
        }
        c
    }

    /// The coefficients of the same links on `coarse`, a cut whose every unknown lies at or above
    /// unknowns of `fine` (a [`Cut::coarsened`] further than `fine`), made from `self`, built for
    /// `fine`, without evaluating a form factor again. Both sides are additive over the area of
    /// an unknown: a coarse unknown `u`'s coefficient on a link of its chain is the area-weighted
    /// mean `Σ_c A_c F(c ← S) V / Σ_c A_c` of the finer unknowns `c` below it on the same link
    /// (whose chains end with `u`'s), and a source's weight on `u` is the sum of its weights on
    /// those `c`; each link carries the transfer it carries on `fine`. The coarse cut then differs
    /// from the fine one by its unknowns alone, not by the quadrature of its form factors. Links
    /// received below a coarse unknown spread their transfer over it as in
    /// [`LeafCoefficients::for_cut`].
    ///
    /// `None` where `self` does not hold every unknown's chain coefficients, or in a closed scene
    /// (the closure has rescaled its weights to `fine`'s unknowns): there
    /// [`LeafCoefficients::for_cut`] builds them anew.
    ///
    /// `self` is consumed: its source side goes as soon as the coarse one is made from it, before
    /// the coarse chain coefficients are (on the 3,200-leaf canopy the fine and the coarse
    /// coefficients held together were the run's heap peak). With `keep_chain`, what is left of
    /// it comes back as the next level's [`ChainReuse`] ([`LeafCoefficients::into_reuse`]).
    #[must_use]
    pub fn coarsened(
        mut self,
        fine: &Cut<'_>,
        coarse: &Cut<'_>,
        links: &[Link],
        keep_chain: bool,
    ) -> (Option<LeafCoefficients>, Option<ChainReuse>) {
        let reuse = |c: LeafCoefficients| keep_chain.then(|| c.into_reuse(fine, links));
        if self.closed || !self.is_complete() || self.scale.len() != links.len() {
            return (None, reuse(self));
        }
        let h = coarse.hierarchy();
        let precision = self.precision();
        let unknowns = coarse.elements();
        let fine_below = LeavesBelow::new(fine);
        let (start, chain_entries) = {
            let chain = Chain { h, links, sorted: &self.sorted, range: &self.range, precision };
            let lens: Vec<usize> = unknowns.par_iter().map(|&u| chain.len(u)).collect();
            // Every coarse unknown has finer ones below it, whose chains end with its own.
            let chains_end_alike = unknowns.iter().zip(&lens).all(|(&u, &n)| {
                let below = fine_below.below(u);
                !below.is_empty() && below.iter().all(|&c| fine.unknown_of(c).is_some_and(|f| self.start[f + 1] - self.start[f] >= n))
            });
            if !chains_end_alike {
                return (None, reuse(self));
            }
            let mut start = Vec::with_capacity(unknowns.len() + 1);
            start.push(0);
            for &len in &lens {
                start.push(start[start.len() - 1] + len);
            }
            let chain_entries = start[start.len() - 1];
            (start, chain_entries)
        };
        // The source side first: each weight range summed over the coarse unknowns its leaves
        // lie in. Then the fine weights go.
        let sources = self.coarse_sources(coarse, links);
        self.weight = Stored::with_capacity(self.weight.precision(), 0);
        self.weight_leaf = Vec::new();
        self.shared = Vec::new();
        self.value = Vec::new();
        let Some((value, weight_leaf, weight, shared)) = sources else { return (None, reuse(self)) };
        // A coarse unknown's coefficients: the area-weighted means of the finer unknowns' on the
        // same links, the last `out.len()` of each finer chain.
        let mean = |u: ElementId, out: &mut [f64]| {
            let n = out.len();
            let mut area = 0.0;
            for &c in fine_below.below(u) {
                let f = fine.unknown_of(c).expect("checked above");
                let from = self.start[f + 1] - n;
                let w = h.get(c).area;
                for (j, o) in out.iter_mut().enumerate() {
                    *o += w * f64::from(self.coef.get(from + j));
                }
                area += w;
            }
            let inv = if area > 0.0 { 1.0 / area } else { 0.0 };
            out.iter_mut().for_each(|o| *o *= inv);
        };
        let coef = match precision {
            Precision::Single => Stored::Single(means_stored(unknowns, &start, &mean, |x| x)),
            Precision::Half => Stored::Half(means_stored(unknowns, &start, &mean, encode)),
        };
        let chain = Chain { h, links, sorted: &self.sorted, range: &self.range, precision };
        let (inside_start, inside) = inside_links(h, unknowns, &self.sorted, &self.range, links);
        let mut receiver_total = vec![0.0; links.len()];
        for (i, w) in start.windows(2).enumerate() {
            let inside = &inside[inside_start[i] as usize..inside_start[i + 1] as usize];
            add_receiver_totals(&mut receiver_total, &chain, unknowns[i], inside, &|j| coef.get(w[0] + j));
        }
        let scale: Vec<f64> = self.transfer.iter().zip(&receiver_total).map(|(&t, &r)| if r > 0.0 { t / r } else { 1.0 }).collect();
        let mut c = LeafCoefficients {
            sorted: self.sorted.clone(),
            range: self.range.clone(),
            start,
            coef,
            reused: 0,
            chain_entries,
            inside_start,
            inside,
            scale,
            transfer: self.transfer.clone(),
            value,
            weight_leaf,
            weight,
            shared,
            closed: false,
            closure: (1.0, 1.0),
            closure_change: Vec::new(),
        };
        c.normalise_weights();
        (Some(c), reuse(self))
    }

    /// The source side of `self`'s links on `coarse`: each link's [`SourceValue`], the coarse
    /// weights (each range of `self`'s summed over the coarse unknowns its leaves lie in) and
    /// their leaves, and the shared ranges. `None` where a weighted leaf lies on no coarse unknown.
    #[expect(clippy::type_complexity, reason = "the four parts of the source side, taken apart at once by the one caller")]
    fn coarse_sources(
        &self,
        coarse: &Cut<'_>,
        links: &[Link],
    ) -> Option<(Vec<SourceValue>, Vec<ElementId>, Stored, Vec<(ElementId, usize, usize, usize)>)> {
        let unknowns = coarse.elements();
        let coarse_below = LeavesBelow::new(coarse);
        let (fine_leaf, fine_weight) = (&self.weight_leaf, &self.weight);
        let mut value = vec![SourceValue::Leaf(NONE); links.len()];
        // Made at their size: grown by doubling, they were held up to twice over.
        let mut entries = 0;
        let mut counted = vec![false; self.shared.len()];
        for (k, l) in links.iter().enumerate() {
            match self.value[k] {
                _ if coarse.unknown_of(l.source).is_some() => {}
                SourceValue::Leaf(_) => {}
                SourceValue::Own(..) => entries += coarse_below.below(l.source).len(),
                SourceValue::Shared(i) => {
                    if !std::mem::replace(&mut counted[i as usize], true) {
                        entries += coarse_below.below(self.shared[i as usize].0).len();
                    }
                }
            }
        }
        let (mut weight_leaf, mut weight, mut shared) = (Vec::new(), Stored::with_capacity(fine_weight.precision(), entries), Vec::new());
        let mut leaves_of: std::collections::HashMap<usize, u32> = std::collections::HashMap::new();
        let mut shared_of: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
        // Appends the coarse weights of the range `lo..hi` (fine leaves from `leaves`) of source
        // `s`; returns the start of its coarse leaves in `weight_leaf`.
        let mut sums = Vec::new();
        let mut aggregate = |s: ElementId, lo: usize, hi: usize, leaves: usize, weight: &mut Stored| -> Option<u32> {
            let list = coarse_below.below(s);
            let at = *leaves_of.entry(leaves).or_insert_with(|| {
                weight_leaf.extend_from_slice(list);
                (weight_leaf.len() - list.len()) as u32
            });
            sums.clear();
            sums.resize(list.len(), 0.0);
            let (mut p, mut found) = (0, true);
            fine_weight.for_each_in(lo..hi, |j, w| {
                let Some(i) = coarse.unknown_of(fine_leaf[leaves + j - lo]) else {
                    found = false;
                    return;
                };
                let u = unknowns[i];
                while list.get(p).is_some_and(|&x| x != u) {
                    p += 1;
                }
                match sums.get_mut(p) {
                    Some(x) => *x += w,
                    None => found = false,
                }
            });
            if !found {
                return None;
            }
            weight.extend_f64(&sums);
            Some(at)
        };
        for (k, l) in links.iter().enumerate() {
            if let Some(i) = coarse.unknown_of(l.source) {
                value[k] = SourceValue::Leaf(unknowns[i]);
                continue;
            }
            value[k] = match self.value[k] {
                SourceValue::Leaf(e) => SourceValue::Leaf(e),
                SourceValue::Own(lo, hi, leaves) => {
                    let begin = weight.len() as u32;
                    let at = aggregate(l.source, lo as usize, hi as usize, leaves as usize, &mut weight)?;
                    SourceValue::Own(begin, weight.len() as u32, at)
                }
                SourceValue::Shared(i) => {
                    if let Some(&j) = shared_of.get(&i) {
                        SourceValue::Shared(j)
                    } else {
                        let (s, lo, hi, leaves) = self.shared[i as usize];
                        let begin = weight.len();
                        let at = aggregate(s, lo, hi, leaves, &mut weight)?;
                        shared.push((s, begin, weight.len(), at as usize));
                        shared_of.insert(i, (shared.len() - 1) as u32);
                        SourceValue::Shared((shared.len() - 1) as u32)
                    }
                }
            };
        }
        Some((value, weight_leaf, weight, shared))
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
    /// it makes up for a cover); empty in an open scene. See [`super::closure_error`](crate::solve::closure_error).
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
    fn close(&mut self, cut: &Cut<'_>) {
        let (h, transfer) = (cut.hierarchy(), &self.transfer);
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
            self.weight.for_each_in(lo..hi, |j, q| add(self.weight_leaf[leaves + j - lo], transfer[k] * q));
        }
        let factor: Vec<f64> = delivered.iter().map(|&d| if d > 0.0 { (1.0 / d).clamp(CLOSURE_MIN, CLOSURE_MAX) } else { 1.0 }).collect();
        let f = |y: ElementId| cut.unknown_of(y).map_or(1.0, |i| factor[i]);
        // Rescale the weights of each range by the factors, renormalise, and keep each range's
        // mean factor: a link's transfer scales by its range's mean factor.
        // (A closed scene's weights are stored in `f32`, see `for_cut_reusing`.)
        let mut rescale = |lo: usize, hi: usize, leaves: usize| -> f64 {
            let Stored::Single(weight) = &mut self.weight else { return 1.0 };
            let scaled: Vec<f64> =
                self.weight_leaf[leaves..leaves + hi - lo].iter().zip(&weight[lo..hi]).map(|(&y, &w)| f64::from(w) * f(y)).collect();
            let sum: f64 = scaled.iter().sum();
            let norm = if sum > 0.0 { sum } else { 1.0 };
            for (w, x) in weight[lo..hi].iter_mut().zip(&scaled) {
                *w = (x / norm) as f32;
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

    /// Chain coefficients taken from an earlier level's ([`LeafCoefficients::for_cut_reusing`])
    /// instead of computed.
    #[must_use]
    pub fn reused_entries(&self) -> usize {
        self.reused
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
            + self.transfer.len() * size_of::<f64>()
            + self.value.len() * size_of::<SourceValue>()
            + self.weight_leaf.len() * size_of::<ElementId>()
            + self.weight.len() * self.weight.precision().bytes()
            + self.shared.len() * size_of::<(ElementId, usize, usize, usize)>()
    }

    /// Weights stored in [`Precision::Half`] are rounded each by up to [`super::HALF_ROUNDING`],
    /// so a range no longer sums to 1: each link's receiver-side scale is divided by its range's
    /// sum as applied, and the light a link sends is its transfer again, exactly. (`f32` weights
    /// sum to 1 within 1e-7 and are left as they are.)
    fn normalise_weights(&mut self) {
        if self.weight.precision() != Precision::Half {
            return;
        }
        let shared: Vec<f64> = self.shared.iter().map(|&(_, lo, hi, _)| self.weight.sum(lo..hi)).collect();
        for (s, v) in self.scale.iter_mut().zip(&self.value) {
            let sum = match *v {
                SourceValue::Leaf(_) => continue,
                SourceValue::Own(lo, hi, _) => self.weight.sum(lo as usize..hi as usize),
                SourceValue::Shared(i) => shared[i as usize],
            };
            if sum > 0.0 {
                *s /= sum;
            }
        }
    }

    /// The radiosity each link sends (see the module docs), for leaf radiosity read from `b` (per
    /// element), times the link's receiver-side scale.
    pub(super) fn link_values(&self, b: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let weighted = |lo: usize, hi: usize, leaves: usize| {
            let mut acc = [0.0; 3];
            self.weight.for_each_in(lo..hi, |j, w| {
                let by = b[self.weight_leaf[leaves + j - lo] as usize];
                for c in 0..3 {
                    acc[c] += w * by[c];
                }
            });
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

/// The links received inside each of `unknowns` (below it), each with its transfer spread over the
/// unknown's area: `(start per unknown, (link, coefficient))`.
fn inside_links(
    h: &Hierarchy,
    unknowns: &[ElementId],
    sorted: &[u32],
    range: &[(u32, u32)],
    links: &[Link],
) -> (Vec<u32>, Vec<(u32, f64)>) {
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
    (inside_start, inside)
}

/// Adds unknown `u`'s `A F V` to its links' totals in `totals`: its `j`th chain coefficient
/// `coef(j)`, and `inside`, the links received below it.
fn add_receiver_totals(totals: &mut [f64], chain: &Chain<'_>, u: ElementId, inside: &[(u32, f64)], coef: &dyn Fn(usize) -> f32) {
    let area = chain.h.get(u).area;
    let mut j = 0;
    chain.for_each_link(u, |k| {
        totals[k as usize] += area * f64::from(coef(j));
        j += 1;
    });
    for &(k, c) in inside {
        totals[k as usize] += area * c;
    }
}

/// The chain coefficients of `unknowns` (in order, `start` their offsets, length
/// `unknowns.len() + 1`), each unknown's from `mean(unknown, its values)`, stored as `store`
/// turns them, in parallel.
fn means_stored<T: Clone + Default + Send>(
    unknowns: &[ElementId],
    start: &[usize],
    mean: &(dyn Fn(ElementId, &mut [f64]) + Sync),
    store: impl Fn(f32) -> T + Sync,
) -> Vec<T> {
    let mut v = vec![T::default(); start[start.len() - 1]];
    fill_each(unknowns, start, &mut v, |u, out| {
        let mut acc = vec![0.0; out.len()];
        mean(u, &mut acc);
        for (o, &x) in out.iter_mut().zip(&acc) {
            *o = store(x as f32);
        }
    });
    v
}
