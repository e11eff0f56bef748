//! The refinement driver: evaluates candidate links in parallel batches, then applies the decisions
//! serially (creating children lazily), so the result does not depend on the number of threads.

use super::{Decision, LinkCtx, Oracle, Services};
use crate::formfactor::FormFactorQuality;
use crate::hierarchy::{ElementId, Hierarchy};
use crate::visibility::{RayCaster, VisibilityConfig};
use rayon::prelude::*;
use std::sync::Arc;

/// Form factors at or below this are dropped rather than stored as links.
pub const MIN_LINK_FORM_FACTOR: f64 = 0.0;

/// A link: light from `source` gathered by `receiver` with coefficient `ff · vis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Link {
    /// Emitter element.
    pub source: ElementId,
    /// Receiver element (links are stored with their receiver).
    pub receiver: ElementId,
    /// Form factor coefficient (see [`crate::formfactor`]).
    pub ff: f64,
    /// Visibility fraction in [0, 1].
    pub vis: f64,
    /// How many segments `vis` was sampled with: the error estimate's visibility noise of a
    /// partly visible link counts them (0 for a link without a form factor).
    pub rays: u32,
}

/// Counters of one refinement run.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct RefineStats {
    /// Oracle calls.
    pub oracle_calls: u64,
    /// Links kept.
    pub links: u64,
    /// Precise form factors computed.
    pub form_factors: u64,
    /// Links subdivided.
    pub subdivided: u64,
    /// Links dropped by the oracle or for a zero form factor.
    pub dropped: u64,
    /// Links kept as they were without being examined (their receivers not marked by
    /// `refine`'s `examine`).
    pub kept_unexamined: u64,
    /// Subdivisions refused because refinement reached its memory budget
    /// ([`RefineLimits::max_bytes`]): those links were kept where they were.
    pub refused_for_memory: u64,
}

/// Bounds on what one refinement may take.
#[derive(Clone, Copy, Debug)]
pub struct RefineLimits {
    /// Memory the hierarchy, the links and the pending candidates may hold (bytes, estimated from
    /// their counts): beyond it no link is subdivided any more, the remaining candidates are linked
    /// where they are, and [`RefineStats::refused_for_memory`] counts them.
    pub max_bytes: usize,
}

impl Default for RefineLimits {
    fn default() -> Self {
        RefineLimits { max_bytes: usize::MAX }
    }
}

/// Bytes one element costs in refinement: the element, its slot in the children list, and its
/// per-element data (radiosity, variation, irradiance reference, the solver's vectors).
pub const BYTES_PER_ELEMENT: usize = size_of::<crate::hierarchy::Element>() + 4 + 24 + 8 + 8 + 96;
/// Bytes one link costs: the link, and its entries in the solver's operators.
pub const BYTES_PER_LINK: usize = size_of::<Link>() + 16 + 24;

#[derive(Clone)]
struct Candidate {
    source: ElementId,
    receiver: ElementId,
    /// Form factor and visibility of an existing link being re-examined.
    existing: Option<(f64, f64, u32)>,
    /// Candidate occluders inherited from the link this one was split from (shaft culling), and
    /// the diagonal of the shaft they were culled for.
    cands: Option<Arc<[u32]>>,
    culled_diag: f64,
}

/// A link that inherits more than [`LONG_LIST_OBJECTS`] candidates is split without classifying
/// its shaft (its children inherit the list as it is) until its shaft is this many times smaller
/// than the one the list was culled for. Long lists seldom shrink, and
/// classifying every split link under them cost office3 a fifth of its refinement time for 109
/// dropped links out of 33,000.
pub const RECULL_SHRINK: f64 = 0.5;

/// Inherited lists longer than this (objects) count as long for [`RECULL_SHRINK`].
pub const LONG_LIST_OBJECTS: usize = 4;

/// Candidates evaluated per parallel batch by [`refine`] (the outcomes of one batch are held at a
/// time).
pub const EVALUATE_BATCH: usize = 16_384;

/// A split decided during a wave, applied after it: source, receiver, decision, the candidates
/// its children inherit and the diagonal they were culled for.
type PendingSplit = (ElementId, ElementId, Decision, Option<Arc<[u32]>>, f64);

enum Outcome {
    /// Keep the link: whether its form factor was computed now, and whether a subdivision was
    /// refused for memory.
    Keep(Link, bool, bool),
    Split(Decision, Option<Arc<[u32]>>, f64),
    Drop,
}

/// Refines `links` (or, when empty, the root self-link) with `oracle` until every candidate is linked
/// or dropped. `data` holds what is known of each element; it is extended for new elements
/// (children inherit from their parent, see [`super::ElementData::inherit`]); every threshold of
/// the pass is scaled by `threshold_scale`. With `examine`, only the links whose receiver it marks
/// (elements beyond it count as marked) are examined again; the others are kept as they are.
/// `progress` is called after each batch with (links so far, candidates pending).
#[allow(clippy::too_many_arguments)]
pub fn refine(
    h: &mut Hierarchy,
    caster: Option<&RayCaster>,
    visibility: VisibilityConfig,
    oracle: &dyn Oracle,
    links: Vec<Link>,
    data: &mut super::ElementData,
    threshold_scale: f64,
    shafts: Option<super::ShaftServices<'_>>,
    limits: RefineLimits,
    criterion: super::Criterion,
    reflected_rays: u32,
    examine: Option<&[bool]>,
    progress: &dyn Fn(u64, u64),
) -> (Vec<Link>, RefineStats) {
    let mut stats = RefineStats::default();
    let examined = |l: &Link| examine.is_none_or(|mask| mask.get(l.receiver as usize).copied().unwrap_or(true));
    let mut out = Vec::with_capacity(links.len().max(1024));
    out.extend(links.iter().filter(|l| !examined(l)));
    stats.kept_unexamined = out.len() as u64;
    let mut pending: Vec<Candidate> = if links.is_empty() {
        vec![Candidate { source: h.root, receiver: h.root, existing: None, cands: None, culled_diag: f64::INFINITY }]
    } else {
        links
            .iter()
            .filter(|l| examined(l))
            .map(|l| Candidate {
                source: l.source,
                receiver: l.receiver,
                existing: Some((l.ff, l.vis, l.rays)),
                cands: None,
                culled_diag: f64::INFINITY,
            })
            .collect()
    };
    drop(links);
    let senders = Senders::of(h);
    while !pending.is_empty() {
        // Every candidate of the wave is evaluated against the hierarchy as it was before the
        // wave, in parallel batches; kept links go out at once (they do not touch the
        // hierarchy), and the splits are applied afterwards, in candidate order. Holding one
        // batch's outcomes instead of the wave's keeps the peak memory of a large local problem
        // down (the top level of a forest: 137,000 links re-examined per pass).
        let mut splits: Vec<PendingSplit> = Vec::new();
        for batch in pending.chunks(EVALUATE_BATCH) {
            let bytes = h.len() * BYTES_PER_ELEMENT + (out.len() + pending.len() + 4 * splits.len()) * BYTES_PER_LINK;
            let full = bytes > limits.max_bytes;
            let outcomes: Vec<Outcome> = {
                let services = Services { hierarchy: h, caster, visibility, data, threshold_scale, shafts, criterion, reflected_rays };
                batch.par_iter().map(|c| evaluate(&services, oracle, c, full, &senders)).collect()
            };
            for (c, outcome) in batch.iter().zip(outcomes) {
                stats.oracle_calls += u64::from(c.source != c.receiver);
                match outcome {
                    Outcome::Keep(link, computed, refused) => {
                        stats.form_factors += u64::from(computed);
                        stats.refused_for_memory += u64::from(refused);
                        if link.ff * link.vis > MIN_LINK_FORM_FACTOR || c.existing.is_some() {
                            out.push(link);
                        } else {
                            stats.dropped += 1;
                        }
                    }
                    Outcome::Drop => stats.dropped += 1,
                    Outcome::Split(d, cands, culled_diag) => {
                        stats.subdivided += 1;
                        splits.push((c.source, c.receiver, d, cands, culled_diag));
                    }
                }
            }
        }
        drop(pending);
        let mut next = Vec::new();
        for s in splits {
            split(h, data, s, &mut next);
        }
        pending = next;
        progress(out.len() as u64, pending.len() as u64);
    }
    stats.links = out.len() as u64;
    (out, stats)
}

/// Which elements can ever send light: those holding a polygon that emits, reflects or transmits
/// in some channel. Every other element's radiosity is zero whatever the solution, so a link from
/// it carries nothing and is not made, however near its receiver (the oracles subdivide pairs too
/// near for the cluster approximation before they look at what the source sends: a canopy of
/// 2,000 black leaves under the sun made 289,595 links that way, all carrying zero).
struct Senders {
    /// Per input polygon.
    polygon: Vec<bool>,
    /// Prefix counts of sending polygons in [`Hierarchy::cluster_polygons`] order (length + 1).
    prefix: Vec<u32>,
}

impl Senders {
    fn of(h: &Hierarchy) -> Senders {
        let positive = |v: &[f64; 3]| v.iter().any(|&x| x > 0.0);
        let polygon: Vec<bool> = (0..h.n_polygons as usize)
            .map(|p| positive(&h.emission[p]) || positive(&h.reflectance[p]) || h.transmittance.get(p).is_some_and(positive))
            .collect();
        let mut prefix = Vec::with_capacity(h.cluster_polygons.len() + 1);
        prefix.push(0);
        for &p in &h.cluster_polygons {
            prefix.push(prefix.last().copied().unwrap_or(0) + u32::from(polygon[p as usize]));
        }
        Senders { polygon, prefix }
    }

    fn sends(&self, h: &Hierarchy, id: ElementId) -> bool {
        match h.get(id).kind {
            crate::hierarchy::ElementKind::Surface { polygon, .. } => self.polygon[polygon as usize],
            crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } => {
                self.prefix[poly_end as usize] > self.prefix[poly_start as usize]
            }
        }
    }
}

/// Whether an existing link's kept visibility, sampled with `rays` segments, is the very sample the
/// oracle would draw for it now, so that re-examining the link reads it instead of casting the same
/// segments again: a sample of `--rays` segments with the unsalted seed. That is what a link keeps
/// when the oracle decided it without drawing any ([`LinkCtx::visibility`] of `--rays` segments,
/// under the radiosity criterion always); the irradiance criterion's fresh samples
/// ([`LinkCtx::fresh_visibility`]) are salted and of [`super::Criterion::kept_rays`] segments,
/// more than `--rays`, and are never reused. Segments tested against a shaft's candidates only
/// give the same fraction, but reuse is left to plain rays, where it is the same bits. On a canopy
/// of 3,200 leaves every level re-examines about 600,000 links, each casting its segments again.
fn reuses_visibility(services: &Services<'_>, rays: u32) -> bool {
    let r = services.visibility.rays;
    rays > 0
        && rays == r
        && services.shafts.is_none()
        && services.caster.is_some()
        && (services.criterion == super::Criterion::Radiosity || services.criterion.kept_rays(r) > r)
}

fn evaluate(services: &Services<'_>, oracle: &dyn Oracle, c: &Candidate, memory_full: bool, senders: &Senders) -> Outcome {
    let h = services.hierarchy;
    if c.source == c.receiver {
        // Self-links: a cluster interacts with itself through its children; a planar surface does not.
        return if h.get(c.source).is_cluster() { Outcome::Split(Decision::SubdivideBoth, None, f64::INFINITY) } else { Outcome::Drop };
    }
    // A source that can never send light: no link, whatever the oracle would decide. A link the
    // last pass kept stays (its receiver's light is made of its links as they were).
    if c.existing.is_none() && !senders.sends(h, c.source) {
        return Outcome::Drop;
    }
    let mut ctx = LinkCtx::new(services, c.source, c.receiver);
    ctx.parent_candidates.clone_from(&c.cands);
    if let Some((_, vis, rays)) = c.existing
        && reuses_visibility(services, rays)
    {
        ctx.data.visibility = Some((vis, rays));
    }
    let keep = |ctx: &mut LinkCtx<'_>, refused: bool| {
        if let Some((ff, vis, rays)) = c.existing {
            return Outcome::Keep(Link { source: c.source, receiver: c.receiver, ff, vis, rays }, false, refused);
        }
        let ff = ctx.form_factor(FormFactorQuality::Precise);
        // Under the irradiance criterion the visibility kept for a link the oracle decided on its
        // segments is a sample it did not decide on, of more segments (see
        // `LinkCtx::fresh_visibility`); so is a link's from an emitter, whose light casts the
        // sharp shadows that black sensors read (CIE 171 case 5.7's sensor I read 2.7% low with
        // `--rays` segments on its many small links from the lamp's pieces). A link of reflected
        // light that the oracle kept without drawing any was not chosen for what segments found,
        // and its transfer is within twice the threshold: `--rays` segments keep its visibility's
        // error within a quarter of the threshold (one standard deviation), as the oracle's own
        // would, a receiver gathers such light from many sources, and the estimate counts each
        // link's segments (on a canopy of 800 leaves under the sun and sky, 40.8 M segments
        // became 30.8 M, the links and the estimate the same to 0.2%). Where calculation points
        // read the solution they take as many as the others (`Services::reflected_rays`): the
        // office example's grid needed a fifth importance round with `--rays` (seeds 1–4).
        let kept = services.criterion.kept_rays(services.visibility.rays);
        let vis = match (ff > 0.0, services.criterion) {
            (false, _) => 0.0,
            (true, super::Criterion::Irradiance) if ctx.data.visibility.is_none() && !services.hierarchy.holds_emitter(c.source) => {
                ctx.visibility(services.reflected_rays)
            }
            (true, super::Criterion::Irradiance) => ctx.fresh_visibility(kept),
            (true, super::Criterion::Radiosity) => ctx.visibility(kept),
        };
        let rays = if ff > 0.0 { ctx.sampled_rays() } else { 0 };
        Outcome::Keep(Link { source: c.source, receiver: c.receiver, ff, vis, rays }, true, refused)
    };
    match oracle.decide(&mut ctx) {
        Decision::Link => keep(&mut ctx, false),
        Decision::Stop => Outcome::Drop,
        _ if memory_full => keep(&mut ctx, true),
        d @ (Decision::SubdivideEmitter | Decision::SubdivideReceiver | Decision::SubdivideBoth) => {
            // An oracle may ask for an impossible subdivision: fall back to what can be done.
            let can_s = h.can_subdivide(c.source);
            let can_r = h.can_subdivide(c.receiver);
            let d = match (d, can_s, can_r) {
                (_, false, false) => return keep(&mut ctx, false),
                (Decision::SubdivideEmitter, false, true) | (Decision::SubdivideBoth, false, true) => Decision::SubdivideReceiver,
                (Decision::SubdivideReceiver, true, false) | (Decision::SubdivideBoth, true, false) => Decision::SubdivideEmitter,
                (d, _, _) => d,
            };
            // Shaft culling: a link one occluder blocks whole is dropped instead of refined (all
            // its children would be invisible too); children search only this link's candidates.
            // Under a long inherited list the shaft is classified again only once it has shrunk
            // by RECULL_SHRINK; until then the children inherit the list as it is.
            let diag = h.get(c.source).bounds.merged(&h.get(c.receiver).bounds).diagonal();
            let inherited_long = c.cands.as_deref().is_some_and(|l| l.len() > LONG_LIST_OBJECTS);
            if ctx.shaft.is_none() && inherited_long && diag > RECULL_SHRINK * c.culled_diag {
                return Outcome::Split(d, c.cands.clone(), c.culled_diag);
            }
            match ctx.shaft_verdict() {
                Some(crate::visibility::shaft::ShaftClass::Invisible) => Outcome::Drop,
                Some(_) => Outcome::Split(d, ctx.shaft_candidates(), diag),
                None => Outcome::Split(d, None, f64::INFINITY),
            }
        }
    }
}

/// Subdivides as decided (children inherit from their parent, [`super::ElementData::inherit`]) and
/// queues the children's links, which inherit the candidates and the diagonal they were culled for.
fn split(h: &mut Hierarchy, data: &mut super::ElementData, pending: PendingSplit, next: &mut Vec<Candidate>) {
    let (source, receiver, d, cands, culled_diag) = pending;
    let mut children_of = |h: &mut Hierarchy, id: ElementId| -> Vec<ElementId> {
        if h.get(id).n_children == 0 {
            h.subdivide(id);
            data.inherit(h, id);
        }
        h.children_of(id).to_vec()
    };
    match d {
        Decision::SubdivideEmitter => {
            for s in children_of(h, source) {
                next.push(Candidate { source: s, receiver, existing: None, cands: cands.clone(), culled_diag });
            }
        }
        Decision::SubdivideReceiver => {
            for r in children_of(h, receiver) {
                next.push(Candidate { source, receiver: r, existing: None, cands: cands.clone(), culled_diag });
            }
        }
        Decision::SubdivideBoth => {
            let ss = children_of(h, source);
            let rs = if receiver == source { ss.clone() } else { children_of(h, receiver) };
            for &r in &rs {
                for &s in &ss {
                    next.push(Candidate { source: s, receiver: r, existing: None, cands: cands.clone(), culled_diag });
                }
            }
        }
        Decision::Link | Decision::Stop => unreachable!("split is only called for subdivisions"),
    }
}

/// Links from an emitting surface that its receiver sees in part, pushed down to the receiver's
/// leaves: each leaf gets its own link from the same source, with its own precise form factor and
/// its own visibility ([`super::Criterion::kept_rays`] segments, drawn as a kept link's are);
/// every other link is kept as it is. `(links, form factors computed)`.
///
/// A link stored at a coarse receiver hands its mean visibility to every leaf below it. Each such
/// link is held to the oracle's threshold, but the links from the pieces of one lamp see the same
/// occluder: their errors on a leaf beside a shadow add up instead of averaging out. On a block
/// standing under a lamp split into 60 pieces, a 3 cm floor element in the block's penumbra read
/// 26% of the band's largest irradiance below its exact mean, every one of its links within the
/// threshold. Direct light carries the sharpest shadows (the light of reflecting surfaces is
/// spread over many sources and soft), so only emitters' links are pushed: the number of
/// links grows by the leaves under partly visible direct links, and nothing is subdivided.
#[must_use]
pub fn push_direct_shadows(h: &Hierarchy, caster: &RayCaster, visibility: VisibilityConfig, links: Vec<Link>) -> (Vec<Link>, u64) {
    let emits = |e: ElementId| h.get(e).polygon().is_some_and(|p| h.emission[p as usize].iter().any(|&x| x > 0.0));
    let pushed =
        |l: &Link| l.vis > 0.0 && l.vis < 1.0 && h.get(l.receiver).n_children > 0 && h.get(l.receiver).poly().is_some() && emits(l.source);
    if !links.iter().any(pushed) {
        return (links, 0);
    }
    let parts: Vec<Vec<Link>> = links
        .par_iter()
        .map(|l| {
            if !pushed(l) {
                return vec![*l];
            }
            let mut out = Vec::new();
            let mut stack = vec![l.receiver];
            while let Some(e) = stack.pop() {
                let children = h.children_of(e);
                if !children.is_empty() {
                    stack.extend_from_slice(children);
                    continue;
                }
                let ff = crate::formfactor::link_form_factor(h, l.source, e, FormFactorQuality::Precise);
                if ff > MIN_LINK_FORM_FACTOR {
                    let vis = caster.visibility(h, l.source, e, &visibility);
                    out.push(Link { source: l.source, receiver: e, ff, vis, rays: visibility.rays });
                }
            }
            out
        })
        .collect();
    let form_factors = parts.iter().zip(&links).filter(|(_, l)| pushed(l)).map(|(p, _)| p.len() as u64).sum();
    (parts.into_iter().flatten().collect(), form_factors)
}
