//! Solve: the hierarchical solve after each refinement pass, and the leaf-resolution solve (or
//! gather) that ends each level, within its budget of stored coefficients.

use super::{Config, Context, Progress, State};
use crate::hierarchy::Hierarchy;
use crate::refine::{self, ElementData, Link};
use crate::solve::{self, Solution};
use std::time::Instant;

/// The leaf-resolution operator was over its budget ([`Config::leaf_operator_max_bytes`] or
/// what the memory budget left): coefficients computed again at every iteration instead of stored.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct LeafOverBudget {
    /// Levels whose operator was over its budget.
    pub levels: usize,
    /// The largest share of an operator's coefficients not stored.
    pub recomputed_share: f64,
    /// The budget of stored coefficients: how many.
    pub budget_entries: usize,
    /// The budget of stored coefficients in bytes.
    pub budget_bytes: usize,
}

/// A level's leaf-resolution solution, and what the estimate reads besides.
pub(super) struct LeafSolved {
    /// The solution.
    pub(super) solution: Solution,
    /// The closure's changes, per link (they outlive the coefficients, for the estimate).
    pub(super) closure_changes: Vec<f32>,
    /// The budget of the leaf-resolution coefficients, bytes: the estimate's coarser solves keep to
    /// it as well.
    pub(super) budget: usize,
    /// The leaf-resolution coefficients, kept for the estimate's coarser solves where they can
    /// be made from them ([`solve::LeafCoefficients::coarsened`]: every unknown's stored, an
    /// open scene).
    pub(super) coefficients: Option<solve::LeafCoefficients>,
    /// Chain coefficients taken from the level before's.
    pub(super) reused: usize,
}

impl State {
    /// The hierarchical solve after a refinement pass, from the radiosity refinement read; when
    /// `more_passes` follow, what they read of it ([`update_data`]).
    pub(super) fn solve_pass(&mut self, cx: &Context<'_>, more_passes: bool) -> Solution {
        let t = Instant::now();
        let sol = solve::solve(&self.h, &self.links, &self.data.radiosity, &cx.config.solve);
        self.timings.solve += t.elapsed().as_secs_f64();
        self.iterations += sol.iterations;
        (cx.progress)(Progress::Solved { pass: self.passes, iterations: sol.iterations, residual: sol.residual });
        if more_passes {
            let t = Instant::now();
            update_data(&mut self.data, &self.h, &self.links, &sol, cx.config);
            self.timings.refine += t.elapsed().as_secs_f64();
        }
        sol
    }

    /// The leaf-resolution solve ending a level, from its last hierarchical solution `sol`: its
    /// coefficients within [`Config::leaf_operator_max_bytes`] and what the memory budget leaves
    /// (what is over counted in [`LeafOverBudget`]).
    pub(super) fn leaf_solve(&mut self, cx: &Context<'_>, sol: Solution) -> LeafSolved {
        let config = cx.config;
        let (h, links) = (&self.h, &self.links);
        let t = Instant::now();
        let budget = config.max_memory_bytes.saturating_sub(h.len() * refine::BYTES_PER_ELEMENT + links.len() * refine::BYTES_PER_LINK);
        let leaf_budget = config.leaf_operator_max_bytes.min(budget);
        // The level before's chain coefficients serve where leaves and links are the same.
        let mut leaf = build_leaf_coefficients(
            h,
            links,
            config,
            leaf_budget,
            cx.services.closed,
            cx.progress,
            config.stream_leaf_operator,
            self.chain_reuse.take(),
            &mut self.timings.leaf_operator,
        );
        let reused = leaf.as_ref().map_or(0, solve::LeafCoefficients::reused_entries);
        let (sol, more_iterations, _) = finish_solve(
            h,
            links,
            sol,
            config,
            leaf_budget,
            cx.services.closed,
            cx.progress,
            self.passes,
            &mut leaf,
            config.stream_leaf_operator,
            &mut self.timings.leaf_operator,
        );
        if let Some(c) = leaf.as_ref().filter(|c| !c.is_complete()) {
            let share = c.recomputed_share();
            let over = self.over_budget.get_or_insert(LeafOverBudget {
                levels: 0,
                recomputed_share: 0.0,
                budget_entries: usize::MAX,
                budget_bytes: 0,
            });
            over.levels += 1;
            over.recomputed_share = over.recomputed_share.max(share);
            let entries = leaf_budget / c.precision().bytes();
            if entries < over.budget_entries {
                (over.budget_entries, over.budget_bytes) = (entries, leaf_budget);
            }
        }
        self.leaf_entries = leaf.as_ref().map_or(0, solve::LeafCoefficients::entries);
        // The closure's changes outlive the coefficients, for the estimate.
        let closure_changes = leaf.as_ref().map_or_else(Vec::new, |c| c.closure_changes().to_vec());
        let coefficients = leaf.filter(|c| config.estimate_error && !cx.services.closed && c.is_complete());
        self.iterations += more_iterations;
        self.timings.solve += t.elapsed().as_secs_f64();
        LeafSolved { solution: sol, closure_changes, budget: leaf_budget, coefficients, reused }
    }

    /// What the next level's (or importance round's) refinement reads of the level's solution
    /// `sol` ([`update_data`]); called only where one follows.
    pub(super) fn read_level_solution(&mut self, cx: &Context<'_>, sol: &Solution) {
        let t = Instant::now();
        update_data(&mut self.data, &self.h, &self.links, sol, cx.config);
        self.timings.refine += t.elapsed().as_secs_f64();
    }
}

/// What the next refinement pass reads of solution `sol`: everything ([`solve::element_data`]), or
/// only the radiosity when [`Config::measure_variation`] is off.
pub(super) fn update_data(data: &mut ElementData, h: &Hierarchy, links: &[Link], sol: &Solution, config: &Config) {
    if config.measure_variation {
        let importance = std::mem::take(&mut data.importance);
        *data = solve::element_data(h, links, sol);
        data.importance = importance;
    } else {
        data.radiosity.clone_from(&sol.radiosity);
    }
}

/// Solves the radiosity system of links already refined, with the emission now in `h` (a level of
/// the instanced solver reuses one refinement for every instance of a prototype): the
/// hierarchical solve, then the leaf-resolution solve or gather of [`Config::final_gather`]. `leaf`
/// keeps the leaf-resolution coefficients between calls for the same hierarchy and links (computed
/// at the first call when within [`Config::leaf_operator_max_bytes`]). Returns the solution, the
/// iterations and the leaf-operator entries (0 when gathered).
#[must_use]
pub fn solve_links(h: &Hierarchy, links: &[Link], leaf: &mut Option<solve::LeafCoefficients>, config: &Config) -> (Solution, usize, usize) {
    let sol = solve::solve(h, links, &ElementData::first_guess(h).radiosity, &config.solve);
    let first = sol.iterations;
    let (sol, more, entries) =
        finish_solve(h, links, sol, config, config.leaf_operator_max_bytes, false, &|_| {}, 1, leaf, false, &mut 0.0);
    (sol, first + more, entries)
}

/// The leaf-resolution coefficients of `links` at the leaves of `h`, in the [`solve::Precision`]
/// of the target error, within `max_bytes` of stored coefficients, or beyond it with `stream`
/// (`None` otherwise), taking from `earlier` what it holds of the same leaves on the same links;
/// the seconds spent are added to `built_s`.
#[allow(clippy::too_many_arguments)]
fn build_leaf_coefficients(
    h: &Hierarchy,
    links: &[Link],
    config: &Config,
    max_bytes: usize,
    closed: bool,
    progress: &dyn Fn(Progress),
    stream: bool,
    earlier: Option<solve::ChainReuse>,
    built_s: &mut f64,
) -> Option<solve::LeafCoefficients> {
    let precision = solve::Precision::for_target(config.target_error);
    let entries = solve::leaf_operator_entries(h, links);
    let over_budget = entries.saturating_mul(precision.bytes()) > max_bytes;
    if !config.final_gather || (over_budget && !stream) {
        return None;
    }
    progress(Progress::LeafSolve { entries, over_budget });
    let t = Instant::now();
    let c = solve::LeafCoefficients::for_cut_reusing(&solve::Cut::leaves(h), links, closed, max_bytes, precision, earlier);
    *built_s += t.elapsed().as_secs_f64();
    Some(c)
}

/// The final gather step after the hierarchical solve, with the leaf-resolution coefficients of
/// `leaf` (computed and kept there when absent, in the [`solve::Precision`] of the target error):
/// `(solution, iterations, leaf entries)`. Over `max_bytes` of coefficients, with `stream` the coefficients beyond the budget are computed again
/// at every iteration (the same answer, slower); without, one gather pass is done instead
/// ([`solve::final_gather`]). The seconds spent building the coefficients are added to `built_s`.
#[allow(clippy::too_many_arguments)]
fn finish_solve(
    h: &Hierarchy,
    links: &[Link],
    mut solution: Solution,
    config: &Config,
    max_bytes: usize,
    closed: bool,
    progress: &dyn Fn(Progress),
    passes: usize,
    leaf: &mut Option<solve::LeafCoefficients>,
    stream: bool,
    built_s: &mut f64,
) -> (Solution, usize, usize) {
    if !config.final_gather {
        return (solution, 0, 0);
    }
    if leaf.is_none() {
        *leaf = build_leaf_coefficients(h, links, config, max_bytes, closed, progress, stream, None, built_s);
    }
    match leaf {
        Some(coefficients) => {
            let op = solve::LeafOperator::new(h, links, coefficients);
            let sol = solve::solve_leaf_operator(&op, &solution.radiosity, &config.solve);
            progress(Progress::Solved { pass: passes + 1, iterations: sol.iterations, residual: sol.residual });
            let iterations = sol.iterations;
            (sol, iterations, coefficients.entries())
        }
        None => {
            let (b, irr) = solve::final_gather(h, links, &solution.radiosity);
            solution.radiosity = b;
            solution.irradiance = irr;
            (solution, 0, 0)
        }
    }
}
