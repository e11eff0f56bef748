//! What a solve reports as it goes: the progress events front ends show, each level's figures,
//! and the time spent per phase.

#[cfg(doc)]
use super::{Config, run_with_points};

/// Seconds spent per phase.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Timings {
    /// Building clusters and the ray-casting BVH.
    pub build: f64,
    /// Refinement (oracle calls, form factors, visibility).
    pub refine: f64,
    /// Linear solves, with the leaf-resolution coefficients they are made with.
    pub solve: f64,
    /// Of [`Timings::solve`]: building the leaf-resolution coefficients.
    pub leaf_operator: f64,
    /// The error estimate (the solves on coarsened meshes, the visibility noise) and, with
    /// daylight, the power balance measured per level.
    pub estimate: f64,
    /// The importance rounds for calculation points and grids (their gathers, subdivisions and
    /// solves; see [`run_with_points`]).
    pub importance: f64,
}

impl Timings {
    /// The time spent per phase since `earlier` (taken from the same run).
    #[must_use]
    pub fn since(&self, earlier: &Timings) -> Timings {
        Timings {
            build: self.build - earlier.build,
            refine: self.refine - earlier.refine,
            solve: self.solve - earlier.solve,
            leaf_operator: self.leaf_operator - earlier.leaf_operator,
            estimate: self.estimate - earlier.estimate,
            importance: self.importance - earlier.importance,
        }
    }
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
    /// Links the oracle examined in this level's passes (existing links re-examined and new
    /// candidates): under local levels, only those whose thresholds the level tightened are
    /// examined again.
    pub oracle_calls: u64,
    /// Under a local level, the links its first pass kept without examining them (decided at the
    /// same threshold scale by the level before, their thresholds not tightened); 0 otherwise.
    pub links_kept_unexamined: usize,
    /// Leaf-resolution chain coefficients this level took from the level before's (the same
    /// leaf on the same link: the same value) instead of computing them.
    pub leaf_coefficients_reused: usize,
    /// Largest change of a non-emitting polygon mean since the level before, relative to the
    /// largest such mean (`None` for the first level).
    pub change: Option<f64>,
    /// The error estimate after this level (`None` until two levels are solved).
    pub error_estimate: Option<f64>,
    /// Wall time since the solve started, seconds.
    pub time_s: f64,
    /// What this level took per phase, seconds (the build counts in the first level's).
    pub phases: Timings,
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
