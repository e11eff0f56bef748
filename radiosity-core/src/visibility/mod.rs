//! Visibility by ray casting against an `obvhs` BVH of all input triangles.
//!
//! The BVH works in `f32`, so the scene is mapped into a normalised frame (centred, scaled to a unit
//! diagonal) before building; ray offsets are then relative to the scene's size, which keeps scenes
//! scaled by 1e-6 or translated by 1e6 correct. The endpoints' own polygons are excluded by id in the
//! intersection callback instead of relying on epsilons (the triangle test is not watertight).

mod rays;
pub mod shaft;

pub(crate) use rays::BvhFrame;

/// Shadow rays start this far (relative to the scene's diagonal) off the receiver, along its normal.
pub const SHADOW_ORIGIN_OFFSET_REL: f64 = 1e-5;

pub use rays::{
    ESCAPE_SAMPLES, KERNEL_REGULARISATION, MIN_DIRECTION_COMPONENT, RayCaster, Rng, SEGMENT_END_EPS, VisibilityConfig, back_of,
    escape_fraction, sampled_visibility,
};
