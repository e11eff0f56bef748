//! Step 3, `refine`: the oracle decides for every link (emitter → receiver) whether to link here or
//! subdivide; the driver applies the decisions, subdividing elements lazily, until every candidate
//! is linked or dropped.

mod bf_classic;
mod bf_hand;
mod context;
mod data;
mod driver;

pub use bf_classic::{ClassicBf, first_guess_max};
pub use bf_hand::{BfHand, BfParams, bf_decide, emitter_first};
pub use context::{
    CLUSTER_ERROR_COEF, CROSSING_SPLIT_DEPTH, Criterion, FRESH_VISIBILITY_SALT, KEPT_VISIBILITY_FACTOR, LinkCtx, LinkData,
    MAX_SOURCE_KERNEL_VARIATION, SOURCE_VARIATION_WEIGHT, Services, ShaftServices, UNSEEN_FRACTION, source_kernel_spread,
};
pub use data::{CHILD_VARIATION_FRACTION, ElementData, IRRADIANCE_FLOOR_REL, amplification};
pub use driver::{BYTES_PER_ELEMENT, BYTES_PER_LINK, Link, RefineLimits, RefineStats, push_direct_shadows, refine};

/// What an oracle decides for a link.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Decision {
    /// Keep the link at this level (its form factor and visibility are computed precisely).
    Link,
    /// Replace the link by links from each child of the emitter.
    SubdivideEmitter,
    /// Replace the link by links to each child of the receiver.
    SubdivideReceiver,
    /// Replace the link by links between every pair of children.
    SubdivideBoth,
    /// Drop the link (no interaction).
    Stop,
}

/// A refinement oracle. Implementations must be pure functions of the link context (they run in
/// parallel, and the driver's result must not depend on the order of evaluation).
pub trait Oracle: Sync {
    /// Short name (shown in `stats.json`).
    fn name(&self) -> &str;
    /// Decides for one link. The driver never asks about a self-link (emitter == receiver).
    fn decide(&self, ctx: &mut LinkCtx<'_>) -> Decision;
    /// What the oracle needs the pipeline to provide beyond the defaults ([`crate::pipeline::run`]
    /// turns it on). An oracle compiled by `oracle!` needs what any of its tools needs
    /// ([`crate::oracle::Tool::NEEDS`]).
    fn needs(&self) -> Needs {
        Needs::NONE
    }
}

/// Pipeline services an oracle or a tool needs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Needs {
    /// Shaft culling, for [`LinkCtx::shaft_verdict`] (without it every link is "partly
    /// occluded"): [`crate::pipeline::run`] then uses OBB shafts if the configuration asks for
    /// plain rays.
    pub shafts: bool,
}

impl Needs {
    /// Nothing beyond the defaults.
    pub const NONE: Needs = Needs { shafts: false };
    /// Shaft culling.
    pub const SHAFTS: Needs = Needs { shafts: true };

    /// Both sets of needs.
    #[must_use]
    pub const fn union(self, other: Needs) -> Needs {
        Needs { shafts: self.shafts || other.shafts }
    }
}
