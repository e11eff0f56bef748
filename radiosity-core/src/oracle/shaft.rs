//! The shaft oracle (Haines & Wallace shafts, as the shaft paper uses them), declared with `oracle!`:
//! build the link's shaft; if one occluder blocks it whole, stop; if any candidate occluder enters
//! it, the smallest form factor is taken as 0; if the form factor error `B_S · (F_max − F_min)`
//! exceeds `eps · B_ref`, subdivide; otherwise link (the driver then computes the visibility by
//! rays against the shaft's candidates only). Its tools declare that they need shaft culling
//! ([`crate::refine::Needs::SHAFTS`]), so [`crate::pipeline::run`] turns OBB shafts on when the
//! configuration asks for plain rays.

use super::Tool;
use crate::refine::LinkCtx;
use crate::visibility::shaft::ShaftClass;

crate::answer_enum! {
    /// What the link's shaft says.
    pub enum ShaftAnswer {
        /// One candidate blocks every segment between the elements.
        Invisible,
        /// No object enters the shaft.
        Visible,
        /// Some object enters the shaft and none is known to block it whole.
        Partial,
    }
}

/// Classifies the link by its shaft (memoised in the link context, candidates inherited from the
/// parent link).
#[derive(Clone, Copy, Debug)]
pub struct ShaftClassify;

impl Tool for ShaftClassify {
    type Answer = ShaftAnswer;
    const NEEDS: crate::refine::Needs = crate::refine::Needs::SHAFTS;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> ShaftAnswer {
        match ctx.shaft_verdict() {
            Some(ShaftClass::Invisible) => ShaftAnswer::Invisible,
            Some(ShaftClass::Visible) => ShaftAnswer::Visible,
            Some(ShaftClass::Partial { .. }) | None => ShaftAnswer::Partial,
        }
    }
}

crate::answer_enum! {
    /// Whether a link's form factor error is significant.
    pub enum FfError {
        /// `B_S · (F_max − F_min)` exceeds the threshold.
        Above,
        /// It does not.
        Below,
    }
}

/// Is `B_S · (F_max − F_min) > eps · B_ref`? `F_min` is the smallest point form factor over the
/// receiver when the shaft is empty, and 0 when some candidate may occlude.
#[derive(Clone, Copy, Debug)]
pub struct ShaftFfError(pub f64);

impl Tool for ShaftFfError {
    type Answer = FfError;
    const NEEDS: crate::refine::Needs = crate::refine::Needs::SHAFTS;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> FfError {
        let f_max = ctx.form_factor_max();
        let f_min = match ctx.shaft_verdict() {
            Some(ShaftClass::Visible) => ctx.form_factor_range().0.min(f_max),
            _ => 0.0,
        };
        if ctx.emitter_radiosity() * (f_max - f_min) > self.0 * ctx.services.b_ref { FfError::Above } else { FfError::Below }
    }
}

oracle_macros::oracle! {
    crate = crate;

    /// The shaft oracle: shaft classification first, form factor error bounds from it.
    pub oracle ShaftOracle {
        params { eps: f64 = 0.01 in 0.0..=1.0, min_area: f64 = 0.0 in 0.0..=1e300 }
        start => facing;
        facing: Facing { No => stop, Yes => shaft }
        shaft: ShaftClassify { Invisible => stop, Visible => error, Partial => error }
        error: ShaftFfError(eps) { Below => link, Above => size }
        size: CanSubdivide(min_area) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => subdivide_receiver,
            Both => first,
        }
        first: SplitFirst { Emitter => subdivide_emitter, Receiver => subdivide_receiver }
    }
}
