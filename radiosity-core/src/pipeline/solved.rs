//! Output: the last level's solution with the direct light added, the warnings, the counters and
//! the services' figures, assembled into a [`Solved`].

use super::importance::Rounds;
use super::setup::Services;
#[cfg(doc)]
use super::{CLOSED_MAX_ESCAPE, run, run_with_points};
use super::{Config, ImportanceReport, LeafOverBudget, LevelReport, State, TargetMissed, Timings};
use crate::analysis::SceneTraits;
use crate::hierarchy::Hierarchy;
use crate::refine::{self, Link, RefineStats};
#[cfg(doc)]
use crate::solve;
use crate::solve::Solution;
use crate::visibility::RayCaster;

/// The result of [`run`].
pub struct Solved {
    /// The element hierarchy.
    pub hierarchy: Hierarchy,
    /// The scene's luminaires and distant sources, whose direct light is in
    /// [`Hierarchy::direct`].
    pub lights: crate::light::Lights,
    /// Final links.
    pub links: Vec<Link>,
    /// What the importance rounds for point sets did ([`run_with_points`]); `None` when there
    /// were none (no point set, no target, or the target not met by the levels).
    pub importance: Option<ImportanceReport>,
    /// The point sets' results as the last importance round read them from this solution (their
    /// `h_err` counts what they moved over the last round as well), one per set given to
    /// [`run_with_points`]; empty when no round ran.
    pub point_results: Vec<Vec<crate::points::PointIrradiance>>,
    /// Per polygon, the estimated error of its mean radiosity, W/m² (largest channel): its own
    /// Richardson estimate with the scene-wide terms of [`Solved::error_estimate`] (whose largest,
    /// over the largest mean, it is); empty when not estimated. What a calculation point's
    /// estimate counts for the leaves it sees.
    pub polygon_errors: Vec<f64>,
    /// Final solution.
    pub solution: Solution,
    /// Ray caster (for rendering), when visibility was used or requested.
    pub caster: RayCaster,
    /// Where each leaf's escape cells go, as far as the levels' power balances traced them (the
    /// output's balance reuses them).
    pub escapes: crate::daylight::Escapes,
    /// Refinement counters summed over passes.
    pub refine_stats: RefineStats,
    /// Rays cast during refinement.
    pub rays: u64,
    /// Refine → solve rounds done, over every level.
    pub passes: usize,
    /// What each refinement level cost and gave, coarse to fine.
    pub levels: Vec<LevelReport>,
    /// Coefficients of the leaf-resolution operator (0 when it was not used).
    pub leaf_entries: usize,
    /// Links that shaft culling classified [invisible, visible] without casting a ray.
    pub shaft_classified: [u64; 2],
    /// What the scene needs, when analysed.
    pub traits: Option<SceneTraits>,
    /// Machinery left out for this scene, in words.
    pub left_out: Vec<String>,
    /// Estimated largest error of a non-emitting polygon's mean radiosity (every channel), relative
    /// to the largest non-emitting polygon mean, from the levels' solutions (see
    /// [`solve::LevelHistory`]); `None` when [`Config::estimate_error`] is off or one level was
    /// solved.
    pub error_estimate: Option<f64>,
    /// The quantities [`Solved::error_estimate`] covers, each relative to its own largest
    /// non-emitting polygon mean: `radiosity`, and `irradiance` under the irradiance criterion;
    /// empty without an estimate.
    pub error_estimate_covers: Vec<&'static str>,
    /// Whether refinement stopped short for the memory budget ([`Config::max_memory_bytes`]).
    pub memory_limited: bool,
    /// The fraction of the light leaving the surfaces that escapes the scene, sampled
    /// ([`crate::visibility::escape_fraction`]).
    pub escape_fraction: f64,
    /// Whether the scene is closed ([`CLOSED_MAX_ESCAPE`]): every surface's light then lands on
    /// another, and the leaf-resolution solve delivers it whole.
    pub closed: bool,
    /// What the solve could not do as asked, in words (memory budget reached, target error not
    /// reached).
    pub warnings: Vec<String>,
    /// The target error, when the solve ended without reaching it: what it reached and why the
    /// levels stopped.
    pub target_missed: Option<TargetMissed>,
    /// Levels whose leaf-resolution operator was over its budget, and the largest share of its
    /// coefficients that was computed again at every iteration instead of stored.
    pub leaf_over_budget: Option<LeafOverBudget>,
    /// Operator applications summed over passes.
    pub iterations: usize,
    /// Time per phase.
    pub timings: Timings,
}

impl crate::points::AsSolveParts for Solved {
    fn solve_parts(&self) -> crate::points::SolveParts<'_> {
        crate::points::SolveParts {
            hierarchy: &self.hierarchy,
            links: &self.links,
            solution: &self.solution,
            lights: &self.lights,
            caster: &self.caster,
            convex_enclosure: self.traits.as_ref().is_some_and(|t| !t.needs_visibility),
            error_estimate: self.error_estimate,
            polygon_errors: Some(&self.polygon_errors),
            variation: None,
        }
    }
}

/// The [`Solved`] of a run whose levels ended with `solution` (`None` when no level solved, which
/// cannot be).
pub(super) fn assemble(
    config: &Config,
    state: State,
    services: Services,
    levels: Vec<LevelReport>,
    solution: Option<Solution>,
    target_missed: Option<TargetMissed>,
    points: Rounds,
) -> Solved {
    let State { h, links, stats, passes, iterations, leaf_entries, over_budget, polygon_errors, timings, escapes, .. } = state;
    let mut solution = solution.expect("at least one level solves");
    // The luminaires' direct light is part of what each surface receives.
    for (irr, d) in solution.irradiance.iter_mut().zip(&h.direct) {
        for c in 0..3 {
            irr[c] += d[c];
        }
    }
    let error_estimate = levels.last().and_then(|l| l.error_estimate);
    let mut warnings = Vec::new();
    if stats.refused_for_memory > 0 {
        warnings.push(format!(
            "memory budget of {:.0} MB reached: {} subdivisions refused, those links kept where they were",
            config.max_memory_bytes as f64 / 1e6,
            stats.refused_for_memory
        ));
    }
    if let Some(o) = &over_budget {
        warnings.push(format!(
            "leaf-resolution solve over its budget of {} stored coefficients on {} level(s): up to {:.0}% of them computed again at \
             every iteration (slower; the same answer)",
            o.budget_entries,
            o.levels,
            100.0 * o.recomputed_share
        ));
    }
    if let Some(m) = &target_missed {
        warnings.push(m.message());
    }
    let rays = services.rays();
    let shaft_classified = services.shaft_classified();
    Solved {
        hierarchy: h,
        lights: services.lights,
        links,
        importance: points.report,
        point_results: points.results,
        polygon_errors,
        solution,
        caster: services.caster,
        escapes,
        memory_limited: stats.refused_for_memory > 0,
        escape_fraction: services.escape_fraction,
        closed: services.closed,
        warnings,
        target_missed,
        leaf_over_budget: over_budget,
        refine_stats: stats,
        rays,
        passes,
        levels,
        leaf_entries,
        shaft_classified,
        traits: services.traits,
        left_out: services.left_out,
        error_estimate_covers: match (error_estimate, config.criterion) {
            (None, _) => Vec::new(),
            (Some(_), refine::Criterion::Radiosity) => vec!["radiosity"],
            (Some(_), refine::Criterion::Irradiance) => vec!["radiosity", "irradiance"],
        },
        error_estimate,
        iterations,
        timings,
    }
}
