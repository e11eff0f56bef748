//! Decide, after a level under a target error: whether it met the target, and if not, whether
//! the levels should stop short of it (memory budget, most levels, no progress, a stuck power
//! balance) and why.

#[cfg(doc)]
use super::Config;
use super::LevelReport;

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
pub(super) struct Staleness {
    levels: usize,
    /// Whether one of them changed a polygon mean by more than [`NO_CHANGE_SHARE_OF_TARGET`].
    changed: bool,
}

impl Staleness {
    /// Takes a level's estimate (the level before's `previous`) and change of the polygon means;
    /// returns why the levels stop when they should.
    pub(super) fn push(&mut self, previous: Option<f64>, estimate: f64, change: Option<f64>, target: f64) -> Option<StopCause> {
        let stalled = previous.is_some_and(|e| estimate >= (1.0 - ESTIMATE_MIN_FALL) * e);
        let unchanged = change.is_some_and(|c| c <= NO_CHANGE_SHARE_OF_TARGET * target);
        *self = if stalled { Staleness { levels: self.levels + 1, changed: self.changed || !unchanged } } else { Staleness::default() };
        (self.levels >= NO_PROGRESS_LEVELS).then_some(if self.changed { StopCause::EstimateStalled } else { StopCause::NoProgress })
    }
}

/// A balance gap that fell by less than this fraction of itself over a level did not move
/// ([`StopCause::BalanceGap`]).
pub const BALANCE_GAP_MIN_FALL: f64 = 0.1;

/// Whether a level met `target`: its estimate within it, with daylight the power balance closed
/// within [`BALANCE_SHARE_OF_TARGET`] of it, and a change since the level before.
pub(super) fn target_met(estimate: f64, balance_gap: Option<f64>, change: Option<f64>, target: f64) -> bool {
    let gap_closed = balance_gap.is_none_or(|g| g <= BALANCE_SHARE_OF_TARGET * target);
    // The first level has no change to show what its links miss: it never meets a target.
    estimate <= target && gap_closed && change.is_some()
}

/// Why the levels stop short of `target` after the level of `now` (`previous` the one before),
/// which did not meet it: refinement refused for memory, the estimate stalled
/// ([`Staleness::push`]), the power balance gap stuck while the estimate is within the target,
/// or the last of the levels (`last_level`). `None`: the next level runs.
pub(super) fn stop_cause(
    staleness: &mut Staleness,
    refused_for_memory: bool,
    previous: Option<&LevelReport>,
    now: &LevelReport,
    target: f64,
    last_level: bool,
) -> Option<StopCause> {
    let estimate = now.error_estimate.unwrap_or(f64::INFINITY);
    let stop = if refused_for_memory {
        Some(StopCause::MemoryBudget)
    } else if let Some(prev) = previous {
        let stale = staleness.push(prev.error_estimate, estimate, now.change, target);
        let gap_stuck = estimate <= target
            && match (prev.balance_gap, now.balance_gap) {
                (Some(before), Some(now)) => now >= (1.0 - BALANCE_GAP_MIN_FALL) * before,
                _ => false,
            };
        if gap_stuck { Some(StopCause::BalanceGap) } else { stale }
    } else {
        None
    };
    stop.or(last_level.then_some(StopCause::MaxLevels))
}
