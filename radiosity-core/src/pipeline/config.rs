//! The settings of a solve ([`Config`]) and their defaults, the memory budget, and the visibility
//! method a solve uses.

#[cfg(doc)]
use super::{LOCAL_SHARE_OF_TARGET, LOCAL_SOURCE_SHARE, Solved};
use crate::hierarchy::BuildConfig;
use crate::refine::{self, Oracle};
use crate::solve::{self, SolveConfig};
use crate::visibility::VisibilityConfig;

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
    /// A level's leaf-resolution coefficients take from the level before's those of a leaf on a
    /// link both have (the same leaf receiving from the same source with the same visibility and
    /// form factor, through the same element: the same value, bit for bit) instead of computing
    /// them again ([`solve::LeafCoefficients::for_cut_reusing`]); off: every level computes all
    /// of them (the same answer, slower; the tests compare the two).
    pub reuse_leaf_coefficients: bool,
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
            reuse_leaf_coefficients: true,
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
