//! The whole solve, step after step: a scene in, a [`Solved`] result with the figures
//! `stats.json` reports out. Front ends (the CLI, tests, benchmarks) call [`run`], or
//! [`run_with_points`] when calculation points or grids are asked for.
//!
//! The flow is load → analyse → build → (refine → solve)* → estimate → … → output, and each step
//! has its file:
//!
//! - **load**: the front end reads the scene ([`crate::scene`]); the pipeline takes it as given.
//! - **analyse** and **build** (`setup.rs`): what the scene needs ([`crate::analysis`]), the
//!   element hierarchy with the luminaires' direct light, the ray caster, the shafts, whether the
//!   scene is closed. Once, before the first level.
//! - Then level after level, coarse to fine ([`Config::levels`], or until
//!   [`Config::target_error`]):
//!   - **refine** (`refining.rs`): a refinement pass at the level's threshold scale, and the
//!     direct light's own refinement;
//!   - **solve** (`solving.rs`): the hierarchical solve after each pass (a few passes per level,
//!     [`Config::max_passes`]), and the leaf-resolution solve that ends the level;
//!   - **estimate** (`estimate.rs`): the change since the level before, the error estimate, the
//!     power balance with daylight;
//!   - **decide** (`stop.rs`, `local.rs`): whether the level met the target, whether the levels
//!     stop short of it and why ([`StopCause`]), and under local levels which polygons the next
//!     level refines further.
//! - **importance** (`importance.rs`): with point sets, once the levels meet the target, rounds
//!   that refine where the points' estimated errors come from ([`ImportanceReport`]).
//! - **output** (`solved.rs`): the last solution with the direct light added, the warnings and
//!   the counters, assembled into [`Solved`].
//!
//! The settings are in `config.rs` ([`Config`], [`VisibilityMethod`]) and what a solve reports as
//! it goes in `report.rs` ([`Progress`], [`LevelReport`], [`Timings`]). This file holds
//! [`run_with_points`], which reads as the data flow, and the state the levels carry from one to
//! the next. The step files are private: every public item is re-exported here, so
//! `radiosity_core::pipeline::*` is the whole API.

use crate::hierarchy::Hierarchy;
use crate::points::{CalcPoint, PointsConfig};
use crate::refine::{self, ElementData, Link, Oracle, RefineStats};
use crate::scene::Scene;
use crate::solve::{self, Solution};
use std::time::Instant;

mod config;
mod estimate;
mod importance;
mod local;
mod refining;
mod report;
mod setup;
mod solved;
mod solving;
mod stop;
#[cfg(test)]
mod tests;

pub use config::{
    CLOSED_MAX_ESCAPE, Config, DEFAULT_LEVEL_STEP, DEFAULT_LEVELS, DEFAULT_MAX_LEVELS, DEFAULT_MEMORY_FRACTION, VisibilityMethod,
    default_memory_budget, effective_visibility, physical_memory_bytes,
};
pub use importance::{
    IMPORTANCE_AIM, IMPORTANCE_MAX_GROWTH, IMPORTANCE_MAX_ROUNDS, IMPORTANCE_MIN_FALL, IMPORTANCE_OUT_OF_REACH, ImportanceReport,
};
pub use local::{LOCAL_SHARE_OF_TARGET, LOCAL_SOURCE_SHARE};
pub use refining::{DIRECT_MAX_QUADRATURE_DEPTH, DIRECT_MAX_ROUNDS, DIRECT_SHARE_OF_TARGET};
pub use report::{LevelReport, Progress, Timings};
pub use solved::Solved;
pub use solving::{LeafOverBudget, solve_links};
pub use stop::{
    BALANCE_GAP_MIN_FALL, BALANCE_SHARE_OF_TARGET, ESTIMATE_MIN_FALL, NO_CHANGE_SHARE_OF_TARGET, NO_PROGRESS_LEVELS, StopCause,
    TargetMissed,
};

/// Solves `scene` with `oracle`: level after level, coarse to fine ([`Config::levels`], or until
/// [`Config::target_error`]), each a few refine → solve rounds ending with the leaf-resolution
/// solve.
pub fn run(scene: &Scene, oracle: &dyn Oracle, config: &Config, progress: &dyn Fn(Progress)) -> Solved {
    run_with_points(scene, oracle, config, &[], progress)
}

/// [`run`], with point sets the target error applies to as well (calculation points, each grid):
/// once the levels meet the target on the polygon means, the leaves that the points' estimated
/// errors come from are subdivided until every set's worst estimated error, relative to its
/// largest value, is within the target too ([`importance`](ImportanceReport)). Without a target
/// error, or with no sets, the same as [`run`].
pub fn run_with_points(
    scene: &Scene,
    oracle: &dyn Oracle,
    config: &Config,
    point_sets: &[&[CalcPoint]],
    progress: &dyn Fn(Progress),
) -> Solved {
    let t0 = Instant::now();
    // Analyse the scene, build its hierarchy and what every level uses.
    let (h, services) = setup::build(scene, oracle, config);
    let timings = Timings { build: t0.elapsed().as_secs_f64(), ..Timings::default() };
    let cx = Context::new(config, oracle, &services, point_sets, progress);
    let mut state = State::new(h, timings);
    let (mut points, mut local) = (importance::Rounds::new(), local::LocalLevels::default());
    let (mut levels, mut solution, mut target_missed, mut staleness) = (Vec::new(), None, None, stop::Staleness::default());
    let (mut level_start, mut level_start_calls) = (Timings::default(), 0);
    // Whether the refinement data still reflect the solution before the last level's: read only
    // where another level or an importance round follows (the last level's would be unused).
    let mut data_stale = false;
    for level in 0..cx.n_levels + cx.max_rounds {
        if std::mem::take(&mut data_stale) {
            state.read_level_solution(&cx, solution.as_ref().expect("solved above"));
        }
        let scale = cx.first_scale / config.level_step.powi((level - points.rounds - local.held_levels) as i32);
        // Importance rounds refine within their own cap (see `IMPORTANCE_MAX_GROWTH`).
        let at = Level { index: level, scale, limits: points.limits(config) };
        // Refine → solve rounds, then the leaf-resolution solve.
        let sol = refine_and_solve(&cx, &mut state, at, &mut points);
        state.examine = None;
        let mut leaf = state.leaf_solve(&cx, sol);
        // Estimate (first, while the leaf coefficients it reuses are held), and report the level.
        let last_level = level - points.rounds + 1 == cx.n_levels;
        let est = state.estimate_level(&cx, &mut leaf, last_level);
        data_stale = true;
        let report = LevelReport {
            balance_gap: est.balance_gap,
            points_error: None,
            threshold_scale: scale,
            elements: state.h.len(),
            leaves: state.h.leaves().count(),
            links: state.links.len(),
            oracle_calls: state.stats.oracle_calls - level_start_calls,
            links_kept_unexamined: std::mem::take(&mut state.kept_unexamined) as usize,
            leaf_coefficients_reused: leaf.reused,
            change: est.change,
            error_estimate: est.estimate,
            time_s: t0.elapsed().as_secs_f64(),
            phases: state.timings.since(&level_start),
            polygons_refined: local.polygons_refined.take(),
        };
        (level_start, level_start_calls) = (state.timings, state.stats.oracle_calls);
        progress(Progress::Level { level: level + 1, report });
        let previous = levels.last().copied();
        levels.push(report);
        solution = Some(leaf.solution);
        // Decide: without a target the levels run their course.
        let Some(target) = cx.target_error else {
            if state.stats.refused_for_memory > 0 {
                break;
            }
            continue;
        };
        let estimate = est.estimate.unwrap_or(f64::INFINITY);
        if stop::target_met(estimate, est.balance_gap, est.change, target) {
            if !cx.has_points || state.stats.refused_for_memory > 0 {
                break;
            }
            // Point sets: an importance round, a level of its own when it refined something.
            let sol = solution.as_ref().expect("solved above");
            if std::mem::take(&mut data_stale) {
                state.read_level_solution(&cx, sol);
            }
            if points.run(&cx, &mut state, sol, levels.last_mut(), estimate, target, scale) {
                continue;
            }
            break;
        }
        let memory = state.stats.refused_for_memory > 0;
        if let Some(cause) = stop::stop_cause(&mut staleness, memory, previous.as_ref(), &report, target, last_level) {
            target_missed = Some(TargetMissed {
                target,
                error_estimate: estimate,
                balance_gap: est.balance_gap,
                stopped_by: cause,
                budget_bytes: cause.is_budget().then_some(config.max_memory_bytes),
                levels: levels.len(),
            });
            break;
        }
        // Under local levels, the next level refines further only where polygons are over.
        if cx.local && est.change.is_some() {
            let sol = solution.as_ref().expect("solved above");
            local.refine_over_target(&mut state, sol, &est.irradiance_errors, est.top, target, config.level_step);
        }
    }
    solved::assemble(config, state, services, levels, solution, target_missed, points)
}

/// A level's refine → solve rounds ([`Config::max_passes`]): each refinement pass is followed by
/// the hierarchical solve, until a pass after the first subdivides nothing. Returns the last
/// solution.
fn refine_and_solve(cx: &Context<'_>, state: &mut State, at: Level, points: &mut importance::Rounds) -> Solution {
    let max_passes = cx.config.max_passes.max(1);
    let mut level_solution = None;
    for pass in 1..=max_passes {
        let subdivided = state.refine_pass(cx, at, pass, points.refused_in_rounds());
        if pass > 1 && subdivided == 0 && level_solution.is_some() {
            break;
        }
        level_solution = Some(state.solve_pass(cx, pass < max_passes));
    }
    level_solution.expect("every level solves at least once")
}

/// One level's place in the run.
#[derive(Clone, Copy)]
struct Level {
    /// The level's number from 0 (importance rounds count as levels).
    index: usize,
    /// The oracle's thresholds are scaled by this.
    scale: f64,
    /// What the level's refinement may take.
    limits: refine::RefineLimits,
}

/// What every step of a run reads and none changes: the settings, the services built for the
/// scene, and what the settings make of the levels.
struct Context<'a> {
    config: &'a Config,
    oracle: &'a dyn Oracle,
    services: &'a setup::Services,
    point_sets: &'a [&'a [CalcPoint]],
    progress: &'a dyn Fn(Progress),
    /// A target error needs the estimate (and the leaf-resolution solve it is made with).
    target_error: Option<f64>,
    /// Most levels: [`Config::max_levels`] under a target error, [`Config::levels`] without.
    n_levels: usize,
    /// Without a target the last level is at the oracle's eps; with one, the levels run on from
    /// the same first level until the estimate is below the target.
    first_scale: f64,
    /// Point sets: once the polygon means meet the target, rounds at the last level's scale
    /// refine where the points need it (see `importance`), each a level of its own.
    has_points: bool,
    /// How the importance rounds read the points.
    points_config: PointsConfig,
    /// Most importance rounds.
    max_rounds: usize,
    /// Calculation points read the links' sampling noise, which their error estimate does not
    /// count: every new link's visibility takes the kept count of segments where there are any.
    reflected_rays: u32,
    /// Local levels: from the third level on, the scale stays and only the polygons whose own
    /// estimate is over the target (and where their light comes from) are refined further, by
    /// `polygon_factor` and the elements' importance (see [`Config::local_levels`]).
    local: bool,
}

impl<'a> Context<'a> {
    fn new(
        config: &'a Config,
        oracle: &'a dyn Oracle,
        services: &'a setup::Services,
        point_sets: &'a [&'a [CalcPoint]],
        progress: &'a dyn Fn(Progress),
    ) -> Context<'a> {
        let target_error = config.target_error.filter(|_| config.estimate_error && config.final_gather);
        let has_points = target_error.is_some() && point_sets.iter().any(|s| !s.is_empty());
        Context {
            config,
            oracle,
            services,
            point_sets,
            progress,
            target_error,
            n_levels: if target_error.is_some() { config.max_levels.max(1) } else { config.levels.max(1) },
            first_scale: config.level_step.powi(config.levels.max(1) as i32 - 1),
            has_points,
            points_config: PointsConfig { use_visibility: config.use_visibility, ..Default::default() },
            max_rounds: if has_points { IMPORTANCE_MAX_ROUNDS } else { 0 },
            reflected_rays: if point_sets.iter().any(|s| !s.is_empty()) {
                config.criterion.kept_rays(config.visibility.rays)
            } else {
                config.visibility.rays
            },
            local: config.local_levels && target_error.is_some(),
        }
    }
}

/// What the levels carry from one to the next, and the counters [`Solved`] reports.
struct State {
    /// The element hierarchy.
    h: Hierarchy,
    /// Thresholds are relative to each receiver's own irradiance (see `refine::ElementData`): the
    /// first pass starts from a guess, every later one reads the last solution.
    data: ElementData,
    /// How many times each leaf at the smallest size is quartered for its direct light.
    quadrature: Vec<u8>,
    /// Under local levels, each polygon's factor on its direct light's tolerance (empty: none).
    polygon_factor: Vec<f64>,
    /// Under a local level, per element, whether the links it receives are examined again: those
    /// whose threshold the level tightened, and every element made after the mask (`None`: every
    /// link). The other links were decided at the same threshold scale by the level before, and
    /// are kept as they are.
    examine: Option<Vec<bool>>,
    /// Links the level's first pass kept without examining them (see `examine`).
    kept_unexamined: u64,
    /// Where each leaf's escape cells go, traced once for the power balance of every level.
    escapes: crate::daylight::Escapes,
    /// The levels' polygon means, for the change and the estimate's floor.
    history: solve::LevelHistory,
    /// The links.
    links: Vec<Link>,
    /// Refinement counters summed over passes.
    stats: RefineStats,
    /// Refine → solve rounds done, over every level.
    passes: usize,
    /// Operator applications summed over passes.
    iterations: usize,
    /// Coefficients of the last leaf-resolution operator.
    leaf_entries: usize,
    /// The last level's leaf-resolution chain coefficients, for the next level's to take from
    /// where its leaves and links are the same.
    chain_reuse: Option<solve::ChainReuse>,
    /// Levels whose leaf-resolution operator was over its budget.
    over_budget: Option<LeafOverBudget>,
    /// Per polygon, the last level's estimated error of its mean radiosity (empty without one).
    polygon_errors: Vec<f64>,
    /// Time per phase.
    timings: Timings,
}

impl State {
    fn new(h: Hierarchy, timings: Timings) -> State {
        let data = ElementData::first_guess(&h);
        let emitting: Vec<bool> = h.emission.iter().map(|e| e.iter().any(|&x| x > 0.0)).collect();
        State {
            data,
            quadrature: Vec::new(),
            polygon_factor: Vec::new(),
            examine: None,
            kept_unexamined: 0,
            escapes: crate::daylight::Escapes::default(),
            history: solve::LevelHistory::new(emitting),
            links: Vec::new(),
            stats: RefineStats::default(),
            passes: 0,
            iterations: 0,
            leaf_entries: 0,
            chain_reuse: None,
            over_budget: None,
            polygon_errors: Vec::new(),
            timings,
            h,
        }
    }
}
