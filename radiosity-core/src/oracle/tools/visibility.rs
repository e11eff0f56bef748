//! Visibility questions: ray classification and the reference classifier.

use crate::oracle::Tool;
use crate::refine::LinkCtx;

/// Below this many rays, [`RayVisibility`] gives the `Probably*` answers.
pub const PROBABLE_BELOW_RAYS: u32 = 16;
/// Rays of the reference classifier.
pub const REFERENCE_RAYS: u32 = 1024;

crate::answer_enum! {
    /// Answer of [`RayVisibility`].
    pub enum VisibilityClass {
        /// Every ray passed (enough rays to be sure).
        Visible,
        /// Every ray was blocked (enough rays to be sure).
        Invisible,
        /// Some rays passed.
        Partial,
        /// Every ray passed, but rays were few.
        ProbablyVisible,
        /// Every ray was blocked, but rays were few.
        ProbablyInvisible,
        /// Some passed, rays were few.
        ProbablyPartial,
        /// Partly occluded between clusters: too many occluders to classify.
        TooComplex,
    }
}

/// Classifies visibility with `rays` rays ([`LinkCtx::visibility`], memoised: a later tool asking
/// for fewer rays reuses the value).
#[derive(Clone, Copy, Debug)]
pub struct RayVisibility(pub u32);

impl Tool for RayVisibility {
    type Answer = VisibilityClass;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> VisibilityClass {
        let v = ctx.visibility(self.0);
        let few = self.0 < PROBABLE_BELOW_RAYS;
        let partial_clusters = ctx.emitter_element().is_cluster() && ctx.receiver_element().is_cluster();
        match (v, few) {
            (v, false) if v >= 1.0 => VisibilityClass::Visible,
            (v, true) if v >= 1.0 => VisibilityClass::ProbablyVisible,
            (v, false) if v <= 0.0 => VisibilityClass::Invisible,
            (v, true) if v <= 0.0 => VisibilityClass::ProbablyInvisible,
            _ if partial_clusters => VisibilityClass::TooComplex,
            (_, false) => VisibilityClass::Partial,
            (_, true) => VisibilityClass::ProbablyPartial,
        }
    }
}

crate::answer_enum! {
    /// Answer of [`ReferenceVisibility`].
    pub enum ReferenceClass {
        /// Every reference ray passed.
        Visible,
        /// Every reference ray was blocked.
        Invisible,
        /// Some passed.
        Partial,
    }
}

/// The reference classifier of visibility studies: [`REFERENCE_RAYS`] rays.
#[derive(Clone, Copy, Debug)]
pub struct ReferenceVisibility;

impl Tool for ReferenceVisibility {
    type Answer = ReferenceClass;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> ReferenceClass {
        let v = ctx.visibility(REFERENCE_RAYS);
        if v >= 1.0 {
            ReferenceClass::Visible
        } else if v <= 0.0 {
            ReferenceClass::Invisible
        } else {
            ReferenceClass::Partial
        }
    }
}
