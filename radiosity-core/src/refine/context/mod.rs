//! The link context an oracle reads: the two elements, shared services, and memoised link terms.
//!
//! The contract of this folder: an oracle sees one link through [`LinkCtx`], which borrows the
//! pass's read-only [`Services`] and memoises each term it computes (form factors, visibility,
//! the axis) in [`LinkData`], so that the tools of one decision share them. Nothing here decides;
//! the oracle does, and the driver applies the decision.
//!
//! - `criterion.rs`: what the link criteria bound the error of ([`Criterion`]) and how many
//!   segments a kept link's visibility is sampled with.
//! - `services.rs`: the read-only services a refinement pass shares ([`Services`],
//!   [`ShaftServices`]).
//! - `terms.rs`: the memoised terms of a link ([`LinkData`]), the constants of the link error
//!   model and [`source_kernel_spread`].
//! - `link.rs`: [`LinkCtx`] itself, its elements, form factors, nearness, axis and energy terms.
//! - `visibility.rs`: the visibility a link is decided and kept with, through shafts or rays.

mod criterion;
mod link;
mod services;
mod terms;
mod visibility;

pub use criterion::{Criterion, KEPT_VISIBILITY_FACTOR, UNSEEN_FRACTION};
pub use link::{CROSSING_SPLIT_DEPTH, FRESH_VISIBILITY_SALT, LinkCtx};
pub use services::{Services, ShaftServices};
pub use terms::{
    CLUSTER_ERROR_COEF, CLUSTER_NEAR_FACTOR, CLUSTER_PROJECTED_FRACTION, LinkAxis, LinkData, MAX_SOURCE_KERNEL_VARIATION,
    SOURCE_VARIATION_WEIGHT, source_kernel_spread,
};
