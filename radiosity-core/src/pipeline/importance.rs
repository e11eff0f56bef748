//! Importance: when calculation points or grids are asked for, the target error applies to them as
//! well. After the levels have brought the polygon means within the target, each point's estimated
//! error ([`crate::points::PointGather`]) is read, and the leaves that most of the error of a point
//! over the target comes from are subdivided (their radiosity is uniform over them where the light
//! they get varies, or a shadow edge crosses them as the point sees them). The leaf-resolution
//! solve then gives each piece its own value: it gathers over the same links with each leaf's own
//! form factors, so no link is added; only the pieces are. Rounds repeat until every point set is
//! within the target, nothing is left to split, or [`IMPORTANCE_MAX_ROUNDS`].
//!
//! Measured on the 1990 test room's 480 points at the default target: the worst point's true
//! error falls from 2.6% to within 1%, at a fraction of the cost of a finer target everywhere (see
//! `tests/accuracy.rs`).

use super::refining::{direct_tolerance, refine_direct};
use super::{Config, Context, LevelReport, State};
use crate::hierarchy::ElementId;
use crate::points::{CalcPoint, LeafError, PointGather, PointIrradiance, PointsConfig, SolveParts};
use crate::refine;
use crate::solve::Solution;
use rayon::prelude::*;
use std::time::Instant;

/// Most rounds of importance subdivision after the levels.
pub const IMPORTANCE_MAX_ROUNDS: usize = 8;

/// The rounds may hold at most this times the memory (elements and links, as the refinement
/// counts it) the levels ended with: beyond it their refinement links what is left where it is,
/// and no further round runs ([`ImportanceReport::capped`]). Ward's 480 points end at 4.1 times;
/// a 32×32 grid over the Cornell box's floor, whose points 9 mm from the walls and beside the
/// blocks' bases stay far above the target, would grow without end.
pub const IMPORTANCE_MAX_GROWTH: f64 = 6.0;

/// After a round, the rounds still needed are projected from its fall of the worst point's
/// estimate and its growth of memory; beyond this times [`IMPORTANCE_MAX_GROWTH`]'s cap the
/// target is out of reach and the rounds stop ([`ImportanceReport::capped`]). A 32×32 grid over
/// the Cornell box's floor (points 9 mm from the walls) stops after one round, 78% -> 43% with
/// the memory grown 3.4 times; Ward's 480 points project 7 times after their first round.
pub const IMPORTANCE_OUT_OF_REACH: f64 = 4.0;

/// A round whose worst point estimate is above this fraction of the round before's stops the
/// rounds ([`ImportanceReport::stalled`]): what they refine no longer brings it down.
pub const IMPORTANCE_MIN_FALL: f64 = 0.9;

/// A point over the target gets the leaves with the largest errors of each kind marked (to
/// subdivide, or to tighten the links to) until what is left of that kind is at most this fraction
/// of the point's limit (a subdivided leaf's pieces carry about a quarter of its shape error: half
/// the radiosity range under half the kernel's).
pub const IMPORTANCE_AIM: f64 = 0.25;

/// A round tightens the thresholds of the links to a marked leaf (and its ancestors) by this
/// factor, the levels' step ([`super::DEFAULT_LEVEL_STEP`]).
pub const IMPORTANCE_TIGHTEN: f64 = 1.0 / super::DEFAULT_LEVEL_STEP;

/// A point's estimated error is at least this times what it moved since the round before: the
/// rounds at least halve what they refine (a quarter for a subdivided leaf's shape, the levels'
/// step for a link), so what the last one moved bounds what is left.
pub const IMPORTANCE_CHANGE_FACTOR: f64 = 1.0;

/// What the importance rounds did.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ImportanceReport {
    /// Rounds that split leaves.
    pub rounds: usize,
    /// Leaves split over all rounds.
    pub leaves_split: usize,
    /// The worst estimated error of a point set (relative to the set's largest value) when the
    /// levels were done.
    pub worst_before: f64,
    /// The same after the last round.
    pub worst_after: f64,
    /// Whether every set is within the target.
    pub met: bool,
    /// The rounds stopped at their memory cap ([`IMPORTANCE_MAX_GROWTH`], or the solve's budget),
    /// or before it when the target was out of its reach ([`IMPORTANCE_OUT_OF_REACH`]).
    pub capped: bool,
    /// The rounds stopped for the worst point's estimate not falling ([`IMPORTANCE_MIN_FALL`]).
    pub stalled: bool,
}

/// What the importance rounds carry from one to the next.
pub(super) struct Rounds {
    /// Rounds that split leaves or tightened links so far (each a level of its own).
    pub(super) rounds: usize,
    /// The memory the rounds may hold ([`IMPORTANCE_MAX_GROWTH`] times what the levels ended
    /// with), set by the first round.
    cap: usize,
    /// Subdivisions the rounds' refinement refused for memory.
    refused: u64,
    /// The worst point estimate of the round before.
    previous_worst: f64,
    /// The memory of the round before.
    previous_bytes: usize,
    /// What the rounds did, once one ran.
    pub(super) report: Option<ImportanceReport>,
    /// The point sets' results as the last round read them.
    pub(super) results: Vec<Vec<PointIrradiance>>,
}

impl Rounds {
    /// No round yet.
    pub(super) fn new() -> Rounds {
        Rounds {
            rounds: 0,
            cap: usize::MAX,
            refused: 0,
            previous_worst: f64::INFINITY,
            previous_bytes: 1,
            report: None,
            results: Vec::new(),
        }
    }

    /// What refinement may take: the memory budget, and during the rounds their own cap as well.
    pub(super) fn limits(&self, config: &Config) -> refine::RefineLimits {
        refine::RefineLimits { max_bytes: if self.rounds > 0 { config.max_memory_bytes.min(self.cap) } else { config.max_memory_bytes } }
    }

    /// Where refinement counts the subdivisions it refused for memory during the rounds (`None`
    /// before them: the run's own counters).
    pub(super) fn refused_in_rounds(&mut self) -> Option<&mut u64> {
        (self.rounds > 0).then_some(&mut self.refused)
    }

    /// One importance round after a level (of threshold scale `scale`, its report `last_report`)
    /// whose polygon means met `target` with estimate `estimate`: reads the point sets from
    /// `solution` ([`round`]), and unless every set is within the target, the rounds are capped
    /// or stalled, or the most rounds ran, subdivides the leaves and tightens the links the points'
    /// errors come from, and refines the direct light. Returns whether another level runs for
    /// the next round.
    #[expect(clippy::too_many_arguments, reason = "the pipeline's state this step reads and writes, passed explicitly")]
    pub(super) fn run(
        &mut self,
        cx: &Context<'_>,
        state: &mut State,
        solution: &Solution,
        last_report: Option<&mut LevelReport>,
        estimate: f64,
        target: f64,
        scale: f64,
    ) -> bool {
        let (config, services) = (cx.config, cx.services);
        let t = Instant::now();
        let parts = SolveParts {
            hierarchy: &state.h,
            links: &state.links,
            solution,
            lights: &services.lights,
            caster: &services.caster,
            convex_enclosure: services.traits.as_ref().is_some_and(|t| !t.needs_visibility),
            error_estimate: Some(estimate),
            polygon_errors: Some(&state.polygon_errors),
            variation: (config.measure_variation && state.data.variation.len() == state.h.len()).then_some(state.data.variation.as_slice()),
        };
        let round = round(&parts, cx.point_sets, target, &cx.points_config, (self.rounds > 0).then_some(self.results.as_slice()));
        if let Some(l) = last_report {
            l.points_error = Some(round.worst);
        }
        let report = self.report.get_or_insert(ImportanceReport { worst_before: round.worst, ..ImportanceReport::default() });
        (report.worst_after, report.met) = (round.worst, round.worst <= target);
        self.results = round.results;
        let bytes = state.h.len() * refine::BYTES_PER_ELEMENT + state.links.len() * refine::BYTES_PER_LINK;
        if self.rounds == 0 {
            self.cap = (bytes as f64 * IMPORTANCE_MAX_GROWTH) as usize;
        }
        // Out of reach: at the last round's fall and growth, the rounds still needed would
        // take more than IMPORTANCE_OUT_OF_REACH times the cap.
        let out_of_reach = self.rounds > 0 && round.worst < self.previous_worst && round.worst > target && {
            let needed = (round.worst / target).ln() / (self.previous_worst / round.worst).ln();
            let growth = (bytes as f64 / self.previous_bytes as f64).max(1.0);
            bytes as f64 * growth.powf(needed) > IMPORTANCE_OUT_OF_REACH * self.cap as f64
        };
        report.capped = self.refused > 0 || bytes > self.cap.min(config.max_memory_bytes) || out_of_reach;
        report.stalled = round.worst > IMPORTANCE_MIN_FALL * self.previous_worst;
        (self.previous_worst, self.previous_bytes) = (round.worst, bytes);
        let go_on = !report.met && !report.capped && !report.stalled && self.rounds < cx.max_rounds;
        let mut made = 0;
        if go_on {
            for &leaf in &round.split {
                if state.h.get(leaf).n_children == 0 && state.h.subdivide(leaf) {
                    state.data.inherit(&state.h, leaf);
                    made += 1;
                }
            }
            for &leaf in &round.tighten {
                state.data.tighten(&state.h, leaf, IMPORTANCE_TIGHTEN);
            }
            for e in state.h.match_sides() {
                state.data.inherit(&state.h, e);
            }
            let direct_limit = config.max_memory_bytes.min(self.cap).saturating_sub(state.links.len() * refine::BYTES_PER_LINK);
            refine_direct(
                &mut state.h,
                &mut state.data,
                &mut state.quadrature,
                &services.lights,
                services.direct_caster(),
                direct_tolerance(cx.target_error, scale),
                &state.polygon_factor,
                direct_limit,
            );
        }
        state.timings.importance += t.elapsed().as_secs_f64();
        if !go_on || (made == 0 && round.tighten.is_empty()) {
            return false;
        }
        report.rounds += 1;
        report.leaves_split += made;
        self.rounds += 1;
        true
    }
}

/// One importance round's reading of the point sets.
pub(super) struct Round {
    /// Each set's points, their estimated error (`h_err`) at least what they moved since the
    /// round before.
    pub results: Vec<Vec<PointIrradiance>>,
    /// The worst estimated error of a point that refinement can lower (all but the sky's
    /// discretisation), relative to its value (or the floor, see
    /// [`crate::points::error_scales`]).
    pub worst: f64,
    /// Leaves to subdivide, sorted, without repeats.
    pub split: Vec<ElementId>,
    /// Leaves whose links' thresholds to tighten, sorted, without repeats.
    pub tighten: Vec<ElementId>,
}

/// Reads every point of `sets` from the solve and marks, for each point over `target`, the leaves
/// its error comes from: largest first, until what is left unmarked of each kind (shape, value;
/// see [`crate::points::LeafError`]) is at most [`IMPORTANCE_AIM`] of the point's limit, and at
/// least the largest of each kind. A point's error counts what it moved since `previous` (the
/// round before's results): the leaves' values still moving is an error no model of one solve
/// shows.
pub(super) fn round(
    parts: &SolveParts<'_>,
    sets: &[&[CalcPoint]],
    target: f64,
    config: &PointsConfig,
    previous: Option<&[Vec<PointIrradiance>]>,
) -> Round {
    let gather = PointGather::for_solve(parts, config);
    let mut out = Round { results: Vec::with_capacity(sets.len()), worst: 0.0, split: Vec::new(), tighten: Vec::new() };
    for (k, set) in sets.iter().enumerate() {
        let mut results: Vec<_> = set.par_iter().map(|p| gather.irradiance_and_leaf_errors(p)).collect();
        if let Some(before) = previous.and_then(|p| p.get(k)).filter(|b| b.len() == results.len()) {
            for ((r, _), b) in results.iter_mut().zip(before) {
                for c in 0..3 {
                    r.h_err[c] = r.h_err[c].max(IMPORTANCE_CHANGE_FACTOR * (r.h[c] - b.h[c]).abs());
                }
            }
        }
        let values: Vec<PointIrradiance> = results.iter().map(|(r, _)| *r).collect();
        let Some(scales) = crate::points::error_scales(&values) else {
            out.results.push(values);
            continue;
        };
        for ((r, leaves), scale) in results.into_iter().zip(scales) {
            // The sky's discretisation is the sky's: no round lowers it.
            let err = r.refinable_err();
            out.worst = out.worst.max(err / scale);
            let limit = target * scale;
            if err <= limit {
                continue;
            }
            let mut leaves = leaves;
            mark(&mut leaves, |l| l.shape, IMPORTANCE_AIM * limit, &mut out.split);
            mark(&mut leaves, |l| l.value, IMPORTANCE_AIM * limit, &mut out.tighten);
        }
        out.results.push(values);
    }
    for v in [&mut out.split, &mut out.tighten] {
        v.sort_unstable();
        v.dedup();
    }
    out
}

/// Pushes to `marked` the leaves of `leaves` with the largest `amount`, until what is left is at
/// most `aim`, and at least the largest one (when any has some).
fn mark(leaves: &mut [LeafError], amount: impl Fn(&LeafError) -> f64, aim: f64, marked: &mut Vec<ElementId>) {
    leaves.sort_by(|a, b| amount(b).total_cmp(&amount(a)).then(a.leaf.cmp(&b.leaf)));
    let mut left: f64 = leaves.iter().map(&amount).sum();
    for (k, l) in leaves.iter().enumerate() {
        if amount(l) <= 0.0 || (k > 0 && left <= aim) {
            break;
        }
        marked.push(l.leaf);
        left -= amount(l);
    }
}
