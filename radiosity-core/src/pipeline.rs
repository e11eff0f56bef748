//! The whole solve, step after step: hierarchy → (refine → solve)* → a [`Solved`] result with the
//! figures `stats.json` reports. Front ends (the CLI, tests, benchmarks) call [`run`].

use crate::analysis::SceneTraits;
use crate::hierarchy::{self, BuildConfig, Hierarchy};
use crate::refine::{self, ElementData, Link, Oracle, RefineStats};
use crate::scene::Scene;
use crate::solve::{self, Solution, SolveConfig};
use crate::visibility::{RayCaster, VisibilityConfig};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

mod importance;
pub use importance::{
    IMPORTANCE_AIM, IMPORTANCE_MAX_GROWTH, IMPORTANCE_MAX_ROUNDS, IMPORTANCE_MIN_FALL, IMPORTANCE_OUT_OF_REACH, ImportanceReport,
};

/// Settings of a full solve.
#[derive(Clone, Copy, Debug)]
pub struct Config {
    /// Hierarchy construction.
    pub build: BuildConfig,
    /// Visibility sampling.
    pub visibility: VisibilityConfig,
    /// Linear solver.
    pub solve: SolveConfig,
    /// Most refine → solve rounds per level (a level stops earlier when a round subdivides nothing).
    pub max_passes: usize,
    /// Refinement levels, coarse to fine: level `k` of `n` scales every threshold of the oracle by
    /// `level_step^(n − 1 − k)`, so the last one refines to the oracle's eps. Each level reuses the
    /// hierarchy and links of the one before and ends with a solve; the differences between the
    /// levels' polygon means give the error estimate ([`crate::solve::LevelHistory`]).
    pub levels: usize,
    /// Ratio of the thresholds of consecutive levels.
    pub level_step: f64,
    /// Refine level after level (thresholds falling by `level_step`, from the first level's) until
    /// the error estimate is below this, instead of stopping at the oracle's eps.
    pub target_error: Option<f64>,
    /// Most levels a target error may take.
    pub max_levels: usize,
    /// Under a target error, from the third level on refine further only the polygons whose own
    /// estimate (of their mean radiosity, or under the irradiance criterion of their mean
    /// irradiance) is over [`LOCAL_SHARE_OF_TARGET`] of the target, and of the polygons that send
    /// one of them [`LOCAL_SOURCE_SHARE`] of its light or more the elements that send it (their
    /// links' thresholds, and their direct light's tolerance, divided by `level_step`), not every
    /// polygon. A polygon not over keeps the largest change since it last was as its estimate's
    /// floor ([`solve::LevelHistory::refining`]).
    pub local_levels: bool,
    /// Memory refinement may use (bytes, estimated): beyond it no link is subdivided any more
    /// (see [`refine::RefineLimits`]); the leaf-resolution solve stays within what is left.
    pub max_memory_bytes: usize,
    /// Cast rays for visibility (false: every link is taken as fully visible).
    pub use_visibility: bool,
    /// How link visibility is computed.
    pub visibility_method: VisibilityMethod,
    /// What the link criteria bound the error of (radiosity or irradiance).
    pub criterion: refine::Criterion,
    /// Analyse the scene first and leave out what it does not need (visibility in a convex
    /// enclosure); see [`crate::analysis`].
    pub analyse: bool,
    /// After the last hierarchical solve of a level, solve again at leaf resolution (every leaf
    /// gathers from its chain of links with its own form factors, see [`solve::LeafOperator`]);
    /// when that would store more than `leaf_operator_max_bytes` of coefficients, one gather pass is
    /// done instead.
    pub final_gather: bool,
    /// Budget of the leaf-resolution operator's stored coefficients, in bytes (each takes
    /// [`solve::Precision::bytes`]: 2 with a target error of at least [`solve::HALF_MIN_TARGET`],
    /// 4 otherwise).
    pub leaf_operator_max_bytes: usize,
    /// Over that budget, store what fits and compute the rest again at every iteration (the same
    /// answer, slower); off: do one gather pass instead of the leaf-resolution solve (an
    /// approximation, what the instanced solver's local problems do to stay small).
    pub stream_leaf_operator: bool,
    /// Estimate the solution's error ([`Solved::error_estimate`]).
    pub estimate_error: bool,
    /// Measure each element's radiosity variation after every solve ([`solve::element_data`]), for
    /// oracles whose criteria read it (off: only the radiosity is updated).
    pub measure_variation: bool,
    /// Find out whether the scene is closed ([`crate::visibility::escape_fraction`]) and, if so,
    /// deliver each surface's light whole ([`solve::LeafCoefficients::for_cut`]).
    pub detect_closure: bool,
}

/// Default number of refinement levels ([`Config::levels`]).
pub const DEFAULT_LEVELS: usize = 3;
/// Default ratio of consecutive levels' thresholds ([`Config::level_step`]).
pub const DEFAULT_LEVEL_STEP: f64 = 4.0;
/// Default most levels of a target error ([`Config::max_levels`]).
pub const DEFAULT_MAX_LEVELS: usize = 10;

impl Default for Config {
    fn default() -> Self {
        Config {
            build: BuildConfig::default(),
            visibility: VisibilityConfig::default(),
            solve: SolveConfig::default(),
            max_passes: 2,
            levels: DEFAULT_LEVELS,
            level_step: DEFAULT_LEVEL_STEP,
            target_error: None,
            max_levels: DEFAULT_MAX_LEVELS,
            local_levels: true,
            max_memory_bytes: default_memory_budget(),
            use_visibility: true,
            analyse: true,
            visibility_method: VisibilityMethod::Rays,
            criterion: refine::Criterion::Irradiance,
            final_gather: true,
            leaf_operator_max_bytes: solve::LEAF_OPERATOR_MAX_BYTES,
            stream_leaf_operator: true,
            estimate_error: true,
            measure_variation: true,
            detect_closure: true,
        }
    }
}

/// A scene whose [`crate::visibility::escape_fraction`] is at most this is closed (a ray or two
/// of the 4,096 may slip through a shared edge).
pub const CLOSED_MAX_ESCAPE: f64 = 2.0 / crate::visibility::ESCAPE_SAMPLES as f64;

/// Fraction of the machine's physical memory refinement may use by default.
pub const DEFAULT_MEMORY_FRACTION: f64 = 0.5;

/// The default memory budget: [`DEFAULT_MEMORY_FRACTION`] of physical memory (`MemTotal` of
/// `/proc/meminfo`), or 4 GB where that cannot be read.
#[must_use]
pub fn default_memory_budget() -> usize {
    physical_memory_bytes().map_or(4_000_000_000, |m| (m as f64 * DEFAULT_MEMORY_FRACTION) as usize)
}

/// Physical memory in bytes, from `/proc/meminfo` (Linux).
#[must_use]
pub fn physical_memory_bytes() -> Option<usize> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kb: usize = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// How link visibility is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisibilityMethod {
    /// Rays against a BVH of every input triangle.
    Rays,
    /// Shaft culling with the given bounding volumes: a link whose shaft one occluder blocks is
    /// invisible and one whose shaft nothing enters is visible, both without a ray; other links cast
    /// rays against the shaft's candidate occluders (or, for long lists, through the BVH); a
    /// link's candidates are searched among those of the link it was subdivided from.
    Shafts(crate::visibility::shaft::BoundingVolume),
}

impl VisibilityMethod {
    /// Every method.
    pub const ALL: [VisibilityMethod; 4] = {
        use crate::visibility::shaft::BoundingVolume::{Aabb, Hull, Obb};
        [VisibilityMethod::Rays, VisibilityMethod::Shafts(Aabb), VisibilityMethod::Shafts(Obb), VisibilityMethod::Shafts(Hull)]
    };

    /// The method's name, as the command line and `stats.json` spell it.
    #[must_use]
    pub fn name(self) -> &'static str {
        use crate::visibility::shaft::BoundingVolume::{Aabb, Hull, Obb};
        match self {
            VisibilityMethod::Rays => "rays",
            VisibilityMethod::Shafts(Aabb) => "aabb",
            VisibilityMethod::Shafts(Obb) => "obb",
            VisibilityMethod::Shafts(Hull) => "hull",
        }
    }

    /// The method called `name` (see [`VisibilityMethod::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<VisibilityMethod> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// Seconds spent per phase.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Timings {
    /// Building clusters and the ray-casting BVH.
    pub build: f64,
    /// Refinement (oracle calls, form factors, visibility).
    pub refine: f64,
    /// Linear solves.
    pub solve: f64,
    /// The error estimate (the solves on coarsened meshes, the visibility noise) and, with
    /// daylight, the power balance measured per level.
    pub estimate: f64,
    /// The importance rounds for calculation points and grids (their gathers, subdivisions and
    /// solves; see [`run_with_points`]).
    pub importance: f64,
}

/// Progress events for front ends.
#[derive(Clone, Copy, Debug)]
pub enum Progress {
    /// Refinement pass `pass` of level `level`: `links` kept so far, `pending` candidates.
    Refine {
        /// Level number from 1.
        level: usize,
        /// Pass number from 1 within the level.
        pass: usize,
        /// Links so far.
        links: u64,
        /// Candidates waiting.
        pending: u64,
    },
    /// The leaf-resolution operator is being built with this many coefficients.
    LeafSolve {
        /// (leaf, link) coefficients and source weights.
        entries: usize,
        /// Whether they exceed the budget: the coefficients beyond it are computed again at every
        /// iteration (slower, same answer).
        over_budget: bool,
    },
    /// A solve finished.
    Solved {
        /// Pass number from 1.
        pass: usize,
        /// Operator applications.
        iterations: usize,
        /// Relative residual.
        residual: f64,
    },
    /// A level finished.
    Level {
        /// Level number from 1.
        level: usize,
        /// Its figures.
        report: LevelReport,
    },
}

/// What one refinement level cost and gave.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct LevelReport {
    /// The oracle's thresholds were scaled by this (1 at the oracle's own eps).
    pub threshold_scale: f64,
    /// Elements after the level.
    pub elements: usize,
    /// Leaves after the level.
    pub leaves: usize,
    /// Links after the level.
    pub links: usize,
    /// Largest change of a non-emitting polygon mean since the level before, relative to the
    /// largest such mean (`None` for the first level).
    pub change: Option<f64>,
    /// The error estimate after this level (`None` until two levels are solved).
    pub error_estimate: Option<f64>,
    /// Wall time since the solve started, seconds.
    pub time_s: f64,
    /// With daylight: how far the power balance is from closing, `|absorbed + escaped − incident
    /// − emitted|` over `incident + emitted`, largest over channels
    /// ([`crate::daylight::balance_gap`]); absent without.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub balance_gap: Option<f64>,
    /// With point sets, once the polygon means met the target: the worst estimated error of a
    /// point read after this level, relative to its value (see [`run_with_points`]); absent
    /// otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub points_error: Option<f64>,
    /// Under local levels ([`Config::local_levels`]): how many polygons this level refined
    /// further than the level before; absent where it refined every polygon.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub polygons_refined: Option<usize>,
}

/// With daylight and a target error, the levels also run on until the power balance closes within
/// this share of the target ([`LevelReport::balance_gap`]): the balance is measured apart from the
/// links (the escape is ray cast), so it catches light the links lose, which the estimate, made
/// from the links, cannot see.
pub const BALANCE_SHARE_OF_TARGET: f64 = 0.5;

/// Why the refinement levels stopped short of the target error.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopCause {
    /// The memory budget ([`Config::max_memory_bytes`]) refused subdivisions.
    MemoryBudget,
    /// The most levels ([`Config::max_levels`]) were solved.
    MaxLevels,
    /// A level subdivided nothing, or changed no polygon mean while the estimate did not fall:
    /// refinement no longer moves the answer.
    NoProgress,
    /// The estimate fell by less than [`ESTIMATE_MIN_FALL`] of itself over each of the last
    /// [`NO_PROGRESS_LEVELS`] levels while the answer still moved: finer links do not lower the
    /// estimated error here (each level costing several times the one before).
    EstimateStalled,
    /// The estimate is below the target but the power balance gap (daylight) did not move with
    /// the last level: light lost or created outside the links, which refinement cannot recover.
    BalanceGap,
}

impl StopCause {
    /// Whether a budget stopped the levels (the answer could have met its target with more).
    #[must_use]
    pub fn is_budget(self) -> bool {
        self == StopCause::MemoryBudget
    }
}

/// A target error the solve did not reach (`stats.json` `target_missed`).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct TargetMissed {
    /// The target error.
    pub target: f64,
    /// The error estimate reached.
    pub error_estimate: f64,
    /// With daylight, the power balance gap reached ([`LevelReport::balance_gap`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub balance_gap: Option<f64>,
    /// Why the levels stopped.
    pub stopped_by: StopCause,
    /// The memory budget, bytes, when it stopped them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub budget_bytes: Option<usize>,
    /// Levels solved.
    pub levels: usize,
}

impl TargetMissed {
    /// One line for the console and `solve_warnings`.
    #[must_use]
    pub fn message(&self) -> String {
        let why = match self.stopped_by {
            StopCause::MemoryBudget => format!(
                "the memory budget of {:.0} MB stopped refinement (raise --max-memory, or accept the answer with --allow-over-budget)",
                self.budget_bytes.unwrap_or(0) as f64 / 1e6
            ),
            StopCause::MaxLevels => format!("the most levels ({}) were solved", self.levels),
            StopCause::NoProgress => {
                format!(
                    "refinement stopped moving the answer ({NO_PROGRESS_LEVELS} levels in a row changed no polygon mean and left the estimate)"
                )
            }
            StopCause::EstimateStalled => format!(
                "the estimate did not fall over the last {NO_PROGRESS_LEVELS} levels, so finer links do not lower the error here; the answer \
                 is given with its estimate (a finer --eps to start from, or a different oracle, may do better)"
            ),
            StopCause::BalanceGap => format!(
                "the power balance gap {:.2}% did not move with refinement: light lost or created outside the links, which finer links cannot recover",
                100.0 * self.balance_gap.unwrap_or(f64::NAN)
            ),
        };
        format!("target error {} not reached: estimate {:.3e} after {} levels; {why}", self.target, self.error_estimate, self.levels)
    }
}

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

/// Below this fraction of the target a level's change of the polygon means counts as none
/// ([`StopCause::NoProgress`]).
pub const NO_CHANGE_SHARE_OF_TARGET: f64 = 0.01;
/// An estimate that fell by less than this fraction of itself over a level did not fall
/// ([`StopCause::NoProgress`]).
pub const ESTIMATE_MIN_FALL: f64 = 0.1;
/// Consecutive levels that did not lower the estimate before the levels stop
/// ([`StopCause::NoProgress`] when they changed nothing either, [`StopCause::EstimateStalled`]
/// otherwise): a level whose finer thresholds subdivide nothing, or whose estimate rises, may be
/// followed by one that does better (Ward's room: 12.2%, 14.7%, 11.2%, 0.41%), two in a row are
/// not.
pub const NO_PROGRESS_LEVELS: usize = 2;
/// The levels in a row that did not lower the estimate ([`NO_PROGRESS_LEVELS`]).
#[derive(Clone, Copy, Debug, Default)]
struct Staleness {
    levels: usize,
    /// Whether one of them changed a polygon mean by more than [`NO_CHANGE_SHARE_OF_TARGET`].
    changed: bool,
}

impl Staleness {
    /// Takes a level's estimate (the level before's `previous`) and change of the polygon means;
    /// returns why the levels stop when they should.
    fn push(&mut self, previous: Option<f64>, estimate: f64, change: Option<f64>, target: f64) -> Option<StopCause> {
        let stalled = previous.is_some_and(|e| estimate >= (1.0 - ESTIMATE_MIN_FALL) * e);
        let unchanged = change.is_some_and(|c| c <= NO_CHANGE_SHARE_OF_TARGET * target);
        *self = if stalled { Staleness { levels: self.levels + 1, changed: self.changed || !unchanged } } else { Staleness::default() };
        (self.levels >= NO_PROGRESS_LEVELS).then_some(if self.changed { StopCause::EstimateStalled } else { StopCause::NoProgress })
    }
}

/// A balance gap that fell by less than this fraction of itself over a level did not move
/// ([`StopCause::BalanceGap`]).
pub const BALANCE_GAP_MIN_FALL: f64 = 0.1;

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
    point_sets: &[&[crate::points::CalcPoint]],
    progress: &dyn Fn(Progress),
) -> Solved {
    let t0 = Instant::now();
    let traits = config.analyse.then(|| SceneTraits::of(scene));
    let left_out = traits.as_ref().map(SceneTraits::left_out).unwrap_or_default();
    let use_visibility = config.use_visibility && traits.as_ref().is_none_or(|t| t.needs_visibility);
    let mut h = hierarchy::build(scene, &config.build);
    let caster = RayCaster::new(scene);
    let lights = scene.lights();
    let direct_caster = config.use_visibility.then_some(&caster);
    // Luminaires: surfaces split for their light, every element's direct illuminance.
    crate::luminaire::prepare(&mut h, &lights, direct_caster, config.target_error.is_some());
    // Both sides of a transmitting leaf are cut into the same pieces (here and after every
    // refinement), so each piece passes its light through to the piece behind it.
    if !h.match_sides().is_empty() {
        crate::luminaire::update_direct(&mut h, &lights, direct_caster);
    }
    let shaft_objects = match effective_visibility(oracle, config.visibility_method) {
        VisibilityMethod::Shafts(volume) if use_visibility => Some(crate::visibility::shaft::ShaftObjects::new(
            scene,
            &crate::visibility::shaft::ObjectConfig { volume, ..Default::default() },
        )),
        _ => None,
    };
    let (shaft_rays, shaft_invisible, shaft_visible) = (AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0));
    let shafts = shaft_objects.as_ref().map(|objects| refine::ShaftServices {
        objects,
        rays: &shaft_rays,
        invisible: &shaft_invisible,
        visible: &shaft_visible,
    });
    // A closed scene delivers every bit of each surface's light to another: the leaf-resolution
    // solves then make it so exactly (see `solve::LeafCoefficients::for_cut`).
    let escape_fraction =
        if config.detect_closure { crate::visibility::escape_fraction(&h, &caster, config.visibility.seed) } else { f64::NAN };
    let closed = escape_fraction <= CLOSED_MAX_ESCAPE;
    let mut timings = Timings { build: t0.elapsed().as_secs_f64(), ..Timings::default() };

    // Thresholds are relative to each receiver's own irradiance (see `refine::ElementData`): the
    // first pass starts from a guess, every later one reads the last solution.
    let mut data = ElementData::first_guess(&h);
    // How many times each leaf at the smallest size is quartered for its direct light.
    let mut quadrature: Vec<u8> = Vec::new();
    let emitting: Vec<bool> = h.emission.iter().map(|e| e.iter().any(|&x| x > 0.0)).collect();
    let mut history = solve::LevelHistory::new(emitting);
    let mut links = Vec::new();
    let mut stats = RefineStats::default();
    let mut solution = None;
    let mut passes = 0;
    let mut iterations = 0;
    let mut levels = Vec::new();
    let mut leaf_entries = 0;
    let mut target_missed = None;
    let mut staleness = Staleness::default();
    let mut over_budget = None;
    // A target error needs the estimate (and the leaf-resolution solve it is made with).
    let target_error = config.target_error.filter(|_| config.estimate_error && config.final_gather);
    let n_levels = if target_error.is_some() { config.max_levels.max(1) } else { config.levels.max(1) };
    // Without a target the last level is at the oracle's eps; with one, the levels run on from the
    // same first level until the estimate is below the target.
    let first_scale = config.level_step.powi(config.levels.max(1) as i32 - 1);
    // Point sets: once the polygon means meet the target, rounds at the last level's scale
    // refine where the points need it (see `importance`), each a level of its own.
    let has_points = target_error.is_some() && point_sets.iter().any(|s| !s.is_empty());
    let points_config = crate::points::PointsConfig { use_visibility: config.use_visibility, ..Default::default() };
    let mut importance: Option<ImportanceReport> = None;
    let mut point_results: Vec<Vec<crate::points::PointIrradiance>> = Vec::new();
    let mut polygon_errors: Vec<f64> = Vec::new();
    let mut rounds = 0;
    let (mut importance_cap, mut importance_refused, mut previous_worst, mut previous_bytes) = (usize::MAX, 0u64, f64::INFINITY, 1usize);
    let max_rounds = if has_points { IMPORTANCE_MAX_ROUNDS } else { 0 };
    // Calculation points read the links' sampling noise, which their error estimate does not
    // count: every new link's visibility takes the kept count of segments where there are any.
    let reflected_rays =
        if point_sets.iter().any(|s| !s.is_empty()) { config.criterion.kept_rays(config.visibility.rays) } else { config.visibility.rays };
    // Local levels: from the third level on, the scale stays and only the polygons whose own
    // estimate is over the target (and where their light comes from) are refined further, by
    // `polygon_factor` and the elements' importance (see `Config::local_levels`).
    let local = config.local_levels && target_error.is_some();
    let (mut held_levels, mut polygon_factor, mut polygons_refined) = (0usize, Vec::<f64>::new(), None);
    for level in 0..n_levels + max_rounds {
        let scale = first_scale / config.level_step.powi((level - rounds - held_levels) as i32);
        // Importance rounds refine within their own cap (see `IMPORTANCE_MAX_GROWTH`).
        let limits = refine::RefineLimits {
            max_bytes: if rounds > 0 { config.max_memory_bytes.min(importance_cap) } else { config.max_memory_bytes },
        };
        let mut level_solution = None;
        for pass in 1..=config.max_passes.max(1) {
            let t = Instant::now();
            let (new_links, s) = refine::refine(
                &mut h,
                use_visibility.then_some(&caster),
                config.visibility,
                oracle,
                links,
                &mut data,
                scale,
                shafts,
                limits,
                config.criterion,
                reflected_rays,
                &|l, p| progress(Progress::Refine { level: level + 1, pass, links: l, pending: p }),
            );
            links = new_links;
            for e in h.match_sides() {
                data.inherit(&h, e);
            }
            let mut s = s;
            if config.criterion == refine::Criterion::Irradiance && use_visibility {
                let fresh = VisibilityConfig {
                    rays: config.criterion.kept_rays(config.visibility.rays),
                    seed: config.visibility.seed ^ refine::FRESH_VISIBILITY_SALT,
                };
                let (pushed, form_factors) = refine::push_direct_shadows(&h, &caster, fresh, links);
                links = pushed;
                s.form_factors += form_factors;
                s.links = links.len() as u64;
            }
            let direct_limit = limits.max_bytes.saturating_sub(links.len() * refine::BYTES_PER_LINK);
            let direct_tolerance = direct_tolerance(target_error, scale);
            s.subdivided +=
                refine_direct(&mut h, &mut data, &mut quadrature, &lights, direct_caster, direct_tolerance, &polygon_factor, direct_limit);
            timings.refine += t.elapsed().as_secs_f64();
            stats.oracle_calls += s.oracle_calls;
            stats.form_factors += s.form_factors;
            stats.subdivided += s.subdivided;
            stats.dropped += s.dropped;
            if rounds > 0 {
                importance_refused += s.refused_for_memory;
            } else {
                stats.refused_for_memory += s.refused_for_memory;
            }
            stats.links = s.links;
            passes += 1;
            if pass > 1 && s.subdivided == 0 && level_solution.is_some() {
                break;
            }
            let t = Instant::now();
            let sol = solve::solve(&h, &links, &data.radiosity, &config.solve);
            timings.solve += t.elapsed().as_secs_f64();
            iterations += sol.iterations;
            progress(Progress::Solved { pass: passes, iterations: sol.iterations, residual: sol.residual });
            if pass < config.max_passes.max(1) {
                let t = Instant::now();
                update_data(&mut data, &h, &links, &sol, config);
                timings.refine += t.elapsed().as_secs_f64();
            }
            level_solution = Some(sol);
        }
        let t = Instant::now();
        let sol = level_solution.expect("every level solves at least once");
        let budget = config.max_memory_bytes.saturating_sub(h.len() * refine::BYTES_PER_ELEMENT + links.len() * refine::BYTES_PER_LINK);
        let leaf_budget = config.leaf_operator_max_bytes.min(budget);
        let mut leaf = None;
        let (sol, more_iterations, _) =
            finish_solve(&h, &links, sol, config, leaf_budget, closed, progress, passes, &mut leaf, config.stream_leaf_operator);
        if let Some(c) = leaf.as_ref().filter(|c| !c.is_complete()) {
            let share = c.recomputed_share();
            let over =
                over_budget.get_or_insert(LeafOverBudget { levels: 0, recomputed_share: 0.0, budget_entries: usize::MAX, budget_bytes: 0 });
            over.levels += 1;
            over.recomputed_share = over.recomputed_share.max(share);
            let entries = leaf_budget / c.precision().bytes();
            if entries < over.budget_entries {
                (over.budget_entries, over.budget_bytes) = (entries, leaf_budget);
            }
        }
        leaf_entries = leaf.as_ref().map_or(0, solve::LeafCoefficients::entries);
        // The closure's changes outlive the coefficients, for the estimate.
        let closure_changes = leaf.as_ref().map_or_else(Vec::new, |c| c.closure_changes().to_vec());
        drop(leaf);
        iterations += more_iterations;
        timings.solve += t.elapsed().as_secs_f64();
        let t = Instant::now();
        if level + 1 < n_levels || has_points {
            update_data(&mut data, &h, &links, &sol, config);
        }
        timings.refine += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let means: Vec<[f64; 3]> = crate::output::polygon_results(&h, &sol).into_iter().map(|r| r.b).collect();
        let top = solve::largest_non_emitting_mean(&h, &sol.radiosity);
        let change = history.push(means);
        let last = level - rounds + 1 == n_levels || stats.refused_for_memory > 0;
        let estimated = (config.estimate_error && config.final_gather && (target_error.is_some() || last))
            .then(|| estimate_error(&h, &links, &sol, closed, &closure_changes, config, leaf_budget));
        let (estimated, irradiance_errors) = match estimated {
            Some((e, per_polygon, irradiance)) => (Some((e, per_polygon)), irradiance),
            None => (None, Vec::new()),
        };
        // Under a target, at least what the last level changed (solve::LEVEL_CHANGE_SAFETY).
        let estimated = estimated.map(|(e, per_polygon)| match target_error {
            Some(_) => history.floor_by_change(e, per_polygon),
            None => (e, per_polygon),
        });
        let estimate = estimated.as_ref().map(|e| e.0);
        polygon_errors = estimated.map(|e| e.1).unwrap_or_default();
        let balance_gap = (!lights.distant.is_empty() && target_error.is_some())
            .then(|| crate::daylight::balance_gap(&h, &lights.distant, &sol, &caster));
        timings.estimate += t.elapsed().as_secs_f64();
        let report = LevelReport {
            balance_gap,
            points_error: None,
            threshold_scale: scale,
            elements: h.len(),
            leaves: h.leaves().count(),
            links: links.len(),
            change,
            error_estimate: estimate,
            time_s: t0.elapsed().as_secs_f64(),
            polygons_refined: polygons_refined.take(),
        };
        progress(Progress::Level { level: level + 1, report });
        let previous = levels.last().copied();
        levels.push(report);
        solution = Some(sol);
        let Some(target) = target_error else {
            if stats.refused_for_memory > 0 {
                break;
            }
            continue;
        };
        let estimate = estimate.unwrap_or(f64::INFINITY);
        let gap_closed = balance_gap.is_none_or(|g| g <= BALANCE_SHARE_OF_TARGET * target);
        // The first level has no change to show what its links miss: it never meets a target.
        if estimate <= target && gap_closed && change.is_some() {
            if !has_points || stats.refused_for_memory > 0 {
                break;
            }
            let t = Instant::now();
            let sol = solution.as_ref().expect("solved above");
            let parts = crate::points::SolveParts {
                hierarchy: &h,
                links: &links,
                solution: sol,
                lights: &lights,
                caster: &caster,
                convex_enclosure: traits.as_ref().is_some_and(|t| !t.needs_visibility),
                error_estimate: Some(estimate),
                polygon_errors: Some(&polygon_errors),
                variation: (config.measure_variation && data.variation.len() == h.len()).then_some(data.variation.as_slice()),
            };
            let round = importance::round(&parts, point_sets, target, &points_config, (rounds > 0).then_some(point_results.as_slice()));
            if let Some(l) = levels.last_mut() {
                l.points_error = Some(round.worst);
            }
            let report = importance.get_or_insert(ImportanceReport { worst_before: round.worst, ..ImportanceReport::default() });
            (report.worst_after, report.met) = (round.worst, round.worst <= target);
            point_results = round.results;
            let bytes = h.len() * refine::BYTES_PER_ELEMENT + links.len() * refine::BYTES_PER_LINK;
            if rounds == 0 {
                importance_cap = (bytes as f64 * IMPORTANCE_MAX_GROWTH) as usize;
            }
            // Out of reach: at the last round's fall and growth, the rounds still needed would
            // take more than IMPORTANCE_OUT_OF_REACH times the cap.
            let out_of_reach = rounds > 0 && round.worst < previous_worst && round.worst > target && {
                let needed = (round.worst / target).ln() / (previous_worst / round.worst).ln();
                let growth = (bytes as f64 / previous_bytes as f64).max(1.0);
                bytes as f64 * growth.powf(needed) > IMPORTANCE_OUT_OF_REACH * importance_cap as f64
            };
            report.capped = importance_refused > 0 || bytes > importance_cap.min(config.max_memory_bytes) || out_of_reach;
            report.stalled = round.worst > IMPORTANCE_MIN_FALL * previous_worst;
            (previous_worst, previous_bytes) = (round.worst, bytes);
            let go_on = !report.met && !report.capped && !report.stalled && rounds < max_rounds;
            let mut made = 0;
            if go_on {
                for &leaf in &round.split {
                    if h.get(leaf).n_children == 0 && h.subdivide(leaf) {
                        data.inherit(&h, leaf);
                        made += 1;
                    }
                }
                for &leaf in &round.tighten {
                    data.tighten(&h, leaf, importance::IMPORTANCE_TIGHTEN);
                }
                for e in h.match_sides() {
                    data.inherit(&h, e);
                }
                let direct_limit = config.max_memory_bytes.min(importance_cap).saturating_sub(links.len() * refine::BYTES_PER_LINK);
                refine_direct(
                    &mut h,
                    &mut data,
                    &mut quadrature,
                    &lights,
                    direct_caster,
                    direct_tolerance(target_error, scale),
                    &polygon_factor,
                    direct_limit,
                );
            }
            timings.importance += t.elapsed().as_secs_f64();
            if !go_on || (made == 0 && round.tighten.is_empty()) {
                break;
            }
            report.rounds += 1;
            report.leaves_split += made;
            rounds += 1;
            continue;
        }
        let stop = if stats.refused_for_memory > 0 {
            Some(StopCause::MemoryBudget)
        } else if let Some(prev) = previous {
            let stale = staleness.push(prev.error_estimate, estimate, change, target);
            let gap_stuck = estimate <= target
                && match (prev.balance_gap, balance_gap) {
                    (Some(before), Some(now)) => now >= (1.0 - BALANCE_GAP_MIN_FALL) * before,
                    _ => false,
                };
            if gap_stuck { Some(StopCause::BalanceGap) } else { stale }
        } else {
            None
        };
        let stop = stop.or((level - rounds + 1 == n_levels).then_some(StopCause::MaxLevels));
        if let Some(cause) = stop {
            target_missed = Some(TargetMissed {
                target,
                error_estimate: estimate,
                balance_gap,
                stopped_by: cause,
                budget_bytes: cause.is_budget().then_some(config.max_memory_bytes),
                levels: levels.len(),
            });
            break;
        }
        if local && change.is_some() {
            let share = LOCAL_SHARE_OF_TARGET * target;
            let over: Vec<bool> = polygon_errors
                .iter()
                .enumerate()
                .map(|(p, &e)| e > share * top || irradiance_errors.get(p).is_some_and(|&e| e > share))
                .collect();
            // When no polygon's own estimate is over (the scene-wide terms or the irradiance of
            // black surfaces hold the whole up), every polygon is refined.
            if over.iter().any(|&o| o) {
                let radiosity = &solution.as_ref().expect("solved above").radiosity;
                let (elements, touched) = local_refinement(&h, &links, radiosity, &over);
                held_levels += 1;
                polygon_factor.resize(h.n_polygons as usize, 1.0);
                for p in (0..touched.len()).filter(|&p| touched[p]) {
                    polygon_factor[p] /= config.level_step;
                }
                for e in elements {
                    data.tighten_subtree(&h, e, 1.0 / config.level_step);
                }
                polygons_refined = Some(touched.iter().filter(|&&o| o).count());
                // A source refined in part keeps its floor (the largest of its changes since it
                // was last over) like one left as it was.
                history.refining(over);
            }
        }
    }
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
    let rays = caster.rays_cast() + shaft_rays.load(Ordering::Relaxed);
    let shaft_classified = [shaft_invisible.load(Ordering::Relaxed), shaft_visible.load(Ordering::Relaxed)];
    Solved {
        hierarchy: h,
        lights,
        links,
        importance,
        point_results,
        polygon_errors,
        solution,
        caster,
        memory_limited: stats.refused_for_memory > 0,
        escape_fraction,
        closed,
        warnings,
        target_missed,
        leaf_over_budget: over_budget,
        refine_stats: stats,
        rays,
        passes,
        levels,
        leaf_entries,
        shaft_classified,
        traits,
        left_out,
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

/// What the next refinement pass reads of solution `sol`: everything ([`solve::element_data`]), or
/// only the radiosity when [`Config::measure_variation`] is off.
fn update_data(data: &mut ElementData, h: &Hierarchy, links: &[Link], sol: &Solution, config: &Config) {
    if config.measure_variation {
        let importance = std::mem::take(&mut data.importance);
        *data = solve::element_data(h, links, sol);
        data.importance = importance;
    } else {
        data.radiosity.clone_from(&sol.radiosity);
    }
}

/// The error estimate of the leaf-resolution solution `sol` (see [`solve::richardson_estimate`]):
/// the same links solved on the mesh one and two levels coarser ([`solve::Cut::coarsened`]), the
/// Richardson extrapolation of the three plus what polygons left whole hide from it
/// ([`solve::unresolved_per_polygon`]), with the visibility-sampling noise
/// ([`solve::visibility_noise`]) or the closure's possible misplacement of light
/// ([`solve::closure_error`], from `closure_changes`, per link) where larger, times
/// [`solve::ESTIMATE_SAFETY`]. The direct light's quadrature error
/// ([`crate::luminaire::direct_polygon_errors`]) is added to the mesh's, polygon by polygon
/// ([`solve::mesh_and_direct_estimate`]): the largest of each term may lie on different
/// polygons (on Ward's room at eps 0.64 the estimate fell from 35% to 26% for a true 7.6%).
/// Returns the estimate, each polygon's share in W/m² of radiosity, and under the irradiance
/// criterion each polygon's mean irradiance's share relative to the largest (empty otherwise).
fn estimate_error(
    h: &Hierarchy,
    links: &[Link],
    sol: &Solution,
    closed: bool,
    closure_changes: &[f32],
    config: &Config,
    max_bytes: usize,
) -> (f64, Vec<f64>, Vec<f64>) {
    // Under the irradiance criterion the estimate covers the polygons' mean irradiance as well.
    let irradiance = config.criterion == refine::Criterion::Irradiance;
    let results = crate::output::polygon_results(h, sol);
    let mut means = vec![results.iter().map(|r| r.b).collect::<Vec<[f64; 3]>>()];
    // The irradiance the user reads adds the luminaires' and distant sources' direct light, which
    // no coarsening changes: it leaves the changes as they are and sets what they are relative to.
    let direct = crate::luminaire::polygon_direct_means(h);
    let with_direct = |results: Vec<crate::output::PolygonResult>| -> Vec<[f64; 3]> {
        results.iter().enumerate().map(|(p, r)| std::array::from_fn(|c| r.h[c] + direct.get(p).map_or(0.0, |d| d[c]))).collect()
    };
    let mut h_means = vec![with_direct(results.clone())];
    for levels in 1..=2 {
        let cut = solve::Cut::coarsened(h, levels);
        let coefficients =
            solve::LeafCoefficients::for_cut(&cut, links, closed, max_bytes, solve::Precision::for_target(config.target_error));
        let op = solve::LeafOperator::for_cut(cut, links, &coefficients);
        let coarse = solve::solve_leaf_operator(&op, &sol.radiosity, &config.solve);
        let results = crate::output::polygon_results(h, &coarse);
        means.push(results.iter().map(|r| r.b).collect());
        h_means.push(with_direct(results));
    }
    let unresolved = solve::unresolved_per_polygon(h, links, &sol.radiosity);
    let polygon_noise = solve::noise_per_polygon(h, links, &sol.radiosity);
    let noise = solve::worst_noise(h, &polygon_noise, &sol.radiosity, irradiance.then_some(h_means[0].as_slice()));
    let closure = solve::closure_error(h, links, closure_changes, &sol.radiosity, irradiance.then_some(h_means[0].as_slice()));
    // The direct light's quadrature adds to the mesh's error where a shadow edge crosses leaves.
    let direct_errors = crate::luminaire::direct_polygon_errors(h);
    let mesh_direct = solve::mesh_and_direct_estimate(
        h,
        [&means[0], &means[1], &means[2]],
        irradiance.then(|| [h_means[0].as_slice(), h_means[1].as_slice(), h_means[2].as_slice()]),
        &unresolved,
        &direct_errors,
    );
    let estimate = solve::ESTIMATE_SAFETY * mesh_direct.max(noise).max(closure) + solve::ESTIMATE_FLOOR;
    // Per polygon, in W/m² of radiosity: its own mesh error and visibility noise, the closure's
    // scene-wide term as it is. The noise is each polygon's own: taken scene-wide (the noisiest
    // polygon's, 0.82% of the brightest mean with the safety factor), it put every leaf of an
    // 800-leaf canopy over half the target at its second level, where the own terms of 5 were,
    // and the next level refined them all.
    let top = solve::largest_non_emitting_mean(h, &sol.radiosity);
    let wide = closure * top;
    let per_polygon = solve::richardson_per_polygon(&means[0], &means[1], &means[2])
        .into_iter()
        .enumerate()
        .map(|(p, e)| {
            // Irradiance errors passed on as radiosity, largest channel.
            let reflected = |v: [f64; 3]| (0..3).map(|c| h.reflectance[p][c] * v[c]).fold(0.0, f64::max);
            let direct = direct_errors.get(p).map_or(0.0, |&d| reflected(d));
            let unresolved = unresolved[p].into_iter().fold(0.0, f64::max);
            solve::ESTIMATE_SAFETY * (e + unresolved + direct).max(reflected(polygon_noise[p])).max(wide) + solve::ESTIMATE_FLOOR * top
        })
        .collect();
    // Under the irradiance criterion, each polygon's mean irradiance's own share (relative to the
    // largest measured mean irradiance): what black and dark surfaces hold the estimate up by.
    let irradiance_errors = if irradiance {
        let top_h = solve::measured_polygons(h).flat_map(|p| h_means[0][p]).fold(0.0, f64::max);
        let own = solve::richardson_per_polygon(&h_means[0], &h_means[1], &h_means[2]);
        let mut errors = vec![0.0; own.len()];
        for p in solve::measured_polygons(h).filter(|_| top_h > 0.0) {
            let direct = direct_errors.get(p).map_or(0.0, |d| d.iter().copied().fold(0.0, f64::max));
            let noise = polygon_noise[p].into_iter().fold(0.0, f64::max);
            errors[p] = solve::ESTIMATE_SAFETY * (own[p] + direct).max(noise) / top_h;
        }
        errors
    } else {
        Vec::new()
    };
    (estimate, per_polygon, irradiance_errors)
}

/// What a local level refines further: each polygon of `over` whole, and of every polygon that
/// sends one of them at least [`LOCAL_SOURCE_SHARE`] of the light it receives (through links
/// between surfaces), the elements that send it (each with what lies below it). Returns the
/// elements to tighten (none below another) and which polygons are touched.
fn local_refinement(h: &Hierarchy, links: &[Link], radiosity: &[[f64; 3]], over: &[bool]) -> (Vec<u32>, Vec<bool>) {
    let n = over.len();
    let mut total = vec![0.0; n];
    let mut from: std::collections::BTreeMap<(u32, u32), f64> = std::collections::BTreeMap::new();
    for l in links {
        let (Some(p), Some(q)) = (h.get(l.receiver).polygon(), h.get(l.source).polygon()) else { continue };
        if p == q || !over[p as usize] {
            continue;
        }
        let power = l.ff * l.vis * radiosity[l.source as usize].iter().copied().fold(0.0, f64::max) * h.get(l.receiver).area;
        total[p as usize] += power;
        *from.entry((p, q)).or_default() += power;
    }
    let mut marked = vec![false; h.len()];
    for p in (0..n).filter(|&p| over[p]) {
        marked[p] = true;
    }
    for l in links {
        let (Some(p), Some(q)) = (h.get(l.receiver).polygon(), h.get(l.source).polygon()) else { continue };
        if from.get(&(p, q)).is_some_and(|&power| power >= LOCAL_SOURCE_SHARE * total[p as usize]) {
            marked[l.source as usize] = true;
        }
    }
    let mut touched = over.to_vec();
    let mut elements = Vec::new();
    for e in 0..h.len() as u32 {
        if !marked[e as usize] {
            continue;
        }
        let mut a = h.get(e).parent;
        let mut covered = false;
        while a != crate::hierarchy::NONE {
            covered |= marked[a as usize];
            a = h.get(a).parent;
        }
        if !covered {
            elements.push(e);
            if let Some(p) = h.get(e).polygon() {
                touched[p as usize] = true;
            }
        }
    }
    (elements, touched)
}

/// Under local levels ([`Config::local_levels`]) the polygons that send a polygon over the target
/// at least this share of the light it receives (through links between surfaces) are refined
/// further too, where they send it from. How their light is spread over them, which their own mean does not show
/// and their own links' thresholds set, is part of what that polygon's mean reads: refining the
/// polygons over the target alone, the corner room of ρ 0.7 at the default target stopped with an
/// estimate of 0.50% for a true error of 0.95% (its brightest wall's error fell from 1.18% to
/// 0.95% over a level that changed it by 0.23%).
pub const LOCAL_SOURCE_SHARE: f64 = 0.1;

/// Under local levels ([`Config::local_levels`]) a polygon is refined further while its own
/// estimate is over this share of the target: its sources' refinement still changes it.
pub const LOCAL_SHARE_OF_TARGET: f64 = 0.5;

/// The share of the target error each polygon's mean direct irradiance is held to by
/// `refine_direct`: with [`solve::ESTIMATE_SAFETY`] on it, about half the target.
pub const DIRECT_SHARE_OF_TARGET: f64 = 0.2;
/// Most rounds of `refine_direct` after one refinement pass: each about halves what a shadow
/// edge misplaces.
pub const DIRECT_MAX_ROUNDS: usize = 10;
/// Most times a leaf is quartered for its direct light's quadrature by `refine_direct` (each time
/// 4 times the shadow rays) before it is split.
pub const DIRECT_MAX_QUADRATURE_DEPTH: u8 = 3;

/// What [`refine_direct`] holds each polygon's mean direct irradiance to, relative to its own
/// value, at a level of threshold scale `scale` under `target`: [`DIRECT_SHARE_OF_TARGET`] of
/// the target, and beyond the oracle's own thresholds (`scale` below 1, levels run on for the
/// target) as much finer as the links' thresholds are: the direct light is refined by the same
/// levels, and does not hold the estimate up while the links go finer alone (a 200-leaf canopy
/// ran from 31k to 2.7M links over four levels whose estimate stayed at 1.0–1.16%).
fn direct_tolerance(target: Option<f64>, scale: f64) -> Option<f64> {
    target.map(|t| DIRECT_SHARE_OF_TARGET * t * scale.min(1.0))
}

/// Computes the direct light of the leaves made since the last call
/// ([`crate::luminaire::update_direct`]), then samples finer the leaves whose direct light's
/// quadrature keeps a polygon's mean direct irradiance from `tolerance` of its own
/// ([`crate::luminaire::direct_splits`]; [`crate::luminaire::deepen_direct`], its depth in
/// `quadrature`, up to [`DIRECT_MAX_QUADRATURE_DEPTH`]), and splits those sampled that finely
/// already, computing the new leaves' direct light, until none is left, for
/// [`DIRECT_MAX_ROUNDS`] rounds or until the elements would take more than `max_bytes`. Finer
/// quadrature first: it costs shadow rays, a split costs links as well, and where a shadow edge's
/// unevenness matters to a receiver the oracle splits the leaf for it (its radiosity range counts
/// the edge, [`crate::hierarchy::Hierarchy::direct_edge`]); on an 800-leaf canopy a quarter fewer
/// elements at the same accuracy. Returns how many leaves were split (their children inherit
/// `data`). Nothing without a tolerance (a target error, [`direct_tolerance`]).
#[expect(clippy::too_many_arguments, reason = "the pipeline's state this step reads and writes, passed explicitly")]
fn refine_direct(
    h: &mut Hierarchy,
    data: &mut ElementData,
    quadrature: &mut Vec<u8>,
    lights: &crate::light::Lights,
    caster: Option<&RayCaster>,
    tolerance: Option<f64>,
    polygon_factor: &[f64],
    max_bytes: usize,
) -> u64 {
    crate::luminaire::update_direct(h, lights, caster);
    let Some(tolerance) = tolerance else { return 0 };
    let mut made = 0;
    for _ in 0..DIRECT_MAX_ROUNDS {
        let over = crate::luminaire::direct_splits(h, tolerance, polygon_factor);
        quadrature.resize(h.len(), 1);
        // Finer quadrature first (shadow rays only), then smaller elements (links as well).
        let (mut split, mut deepen): (Vec<u32>, Vec<(u32, u32)>) = (Vec::new(), Vec::new());
        for l in over {
            let depth = &mut quadrature[l as usize];
            if *depth < DIRECT_MAX_QUADRATURE_DEPTH {
                *depth += 1;
                deepen.push((l, u32::from(*depth)));
            } else if h.can_subdivide(l) {
                split.push(l);
            }
        }
        if (split.is_empty() && deepen.is_empty()) || (h.len() + 4 * split.len()) * refine::BYTES_PER_ELEMENT > max_bytes {
            break;
        }
        for &leaf in &split {
            if h.subdivide(leaf) {
                data.inherit(h, leaf);
                made += 1;
            }
        }
        for e in h.match_sides() {
            data.inherit(h, e);
        }
        crate::luminaire::update_direct(h, lights, caster);
        crate::luminaire::deepen_direct(h, lights, caster, &deepen);
    }
    made
}

/// The visibility method a solve with `oracle` uses: `requested`, except that an oracle that needs
/// shafts ([`crate::refine::Needs::shafts`]) gets OBB shafts where plain rays were requested.
#[must_use]
pub fn effective_visibility(oracle: &dyn Oracle, requested: VisibilityMethod) -> VisibilityMethod {
    if oracle.needs().shafts && requested == VisibilityMethod::Rays {
        VisibilityMethod::Shafts(crate::visibility::shaft::BoundingVolume::Obb)
    } else {
        requested
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
    let (sol, more, entries) = finish_solve(h, links, sol, config, config.leaf_operator_max_bytes, false, &|_| {}, 1, leaf, false);
    (sol, first + more, entries)
}

/// The final gather step after the hierarchical solve, with the leaf-resolution coefficients of
/// `leaf` (computed and kept there when absent, in the [`solve::Precision`] of the target error):
/// `(solution, iterations, leaf entries)`. Over `max_bytes` of coefficients, with `stream` the coefficients beyond the budget are computed again
/// at every iteration (the same answer, slower); without, one gather pass is done instead
/// ([`solve::final_gather`]).
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
) -> (Solution, usize, usize) {
    if !config.final_gather {
        return (solution, 0, 0);
    }
    if leaf.is_none() {
        let precision = solve::Precision::for_target(config.target_error);
        let entries = solve::leaf_operator_entries(h, links);
        let over_budget = entries.saturating_mul(precision.bytes()) > max_bytes;
        if stream || !over_budget {
            progress(Progress::LeafSolve { entries, over_budget });
            *leaf = Some(solve::LeafCoefficients::for_cut(&solve::Cut::leaves(h), links, closed, max_bytes, precision));
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A local level refines the polygon over the target whole, and of a polygon sending it a
    /// large share of its light only the element that sends it (not its parent, nor a piece below
    /// it, twice); a polygon sending it little is left as it is.
    #[test]
    fn local_refinement_takes_the_over_polygon_and_where_its_light_comes_from() {
        let scene = crate::scene::cornell_box();
        let mut h = hierarchy::build(&scene, &BuildConfig::default());
        assert!(h.subdivide(1));
        let (a, b) = (h.children_of(1)[0], h.children_of(1)[1]);
        assert!(h.subdivide(a));
        let below_a = h.children_of(a)[0];
        let radiosity = vec![[1.0; 3]; h.len()];
        let link = |source: u32, receiver: u32, ff: f64| Link { source, receiver, ff, vis: 1.0, rays: 0 };
        // Polygon 0 gets 0.5 from `a`, 0.3 from `below_a`, 0.02 from polygon 2; polygon 3 (not
        // over) gets everything from `b`.
        let links = vec![link(a, 0, 0.5), link(below_a, 0, 0.3), link(2, 0, 0.02), link(b, 3, 0.9)];
        let mut over = vec![false; h.n_polygons as usize];
        over[0] = true;
        let (elements, touched) = local_refinement(&h, &links, &radiosity, &over);
        assert_eq!(elements, vec![0, a], "the over polygon and the element sending it light");
        let want: Vec<bool> = (0..over.len()).map(|p| p == 0 || p == 1).collect();
        assert_eq!(touched, want);
    }

    /// The levels' estimates of Ward's room (percent; the estimate rises once and then falls to the
    /// target) never stop the levels; office2's (flat from the third level on while the links grow
    /// 2.7 and 3.6 times) stop them after the fourth; levels that change nothing, after two.
    #[test]
    fn levels_stop_when_the_estimate_stalls_for_two_levels() {
        let run = |estimates: &[f64], change: f64| {
            let mut s = Staleness::default();
            let mut previous = None;
            for (i, &e) in estimates.iter().enumerate() {
                if let Some(cause) = s.push(previous, e, (i > 0).then_some(change), 0.01) {
                    return Some((i + 1, cause));
                }
                previous = Some(e);
            }
            None
        };
        assert_eq!(run(&[28.2, 12.2, 14.7, 11.2, 0.41], 0.01), None);
        assert_eq!(run(&[10.42, 8.57, 10.85, 10.78, 10.87], 0.005), Some((4, StopCause::EstimateStalled)));
        assert_eq!(run(&[3.0, 3.0, 3.0], 1e-6), Some((3, StopCause::NoProgress)));
        assert_eq!(run(&[3.0, 2.8, 2.0, 1.9, 1.8], 0.01), Some((5, StopCause::EstimateStalled)));
    }

    #[test]
    fn visibility_methods_are_found_by_their_names() {
        let names: Vec<&str> = VisibilityMethod::ALL.iter().map(|m| m.name()).collect();
        assert_eq!(names, ["rays", "aabb", "obb", "hull"]);
        for m in VisibilityMethod::ALL {
            assert_eq!(VisibilityMethod::from_name(m.name()), Some(m));
        }
        assert_eq!(VisibilityMethod::from_name("bvh"), None);
    }

    /// Every cluster's first guess is the area-weighted mean of its polygons' (a cluster's children
    /// are built after it, so a pass in id order would average children not yet set).
    #[test]
    fn initial_radiosity_of_clusters_is_the_mean_of_their_polygons() {
        let scene = crate::scene::cornell_box();
        let h = hierarchy::build(&scene, &hierarchy::BuildConfig { max_leaf_polygons: 2, ..Default::default() });
        let b = ElementData::first_guess(&h).radiosity;
        let mut clusters = 0;
        for e in 0..h.len() as u32 {
            let crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } = h.get(e).kind else { continue };
            let members = &h.cluster_polygons[poly_start as usize..poly_end as usize];
            let area: f64 = members.iter().map(|&p| h.get(p).area).sum();
            for c in 0..3 {
                let mean = members.iter().map(|&p| h.get(p).area * b[p as usize][c]).sum::<f64>() / area;
                assert!((b[e as usize][c] - mean).abs() <= 1e-12 * mean.abs().max(1e-300), "cluster {e}: {} vs {mean}", b[e as usize][c]);
            }
            clusters += 1;
        }
        assert!(clusters > 3 && h.get(h.root).is_cluster(), "the test needs nested clusters");
        let top = b[h.root as usize];
        assert!(top.iter().all(|&x| x > 0.0), "the root of a lit scene has a positive first guess: {top:?}");
    }
}
