//! Shaft questions (Haines & Wallace shafts): the link's shaft classification and the form factor
//! error bounded with it. Both need shaft culling ([`crate::refine::Needs::SHAFTS`]), which
//! [`crate::pipeline::run`] turns on for any oracle that asks them.

use super::FfSpread;
use crate::oracle::Tool;
use crate::refine::LinkCtx;
use crate::visibility::shaft::ShaftClass;

crate::answer_enum! {
    /// Answer of [`ShaftClassify`].
    pub enum ShaftAnswer {
        /// One candidate blocks every segment between the elements.
        Invisible,
        /// No object enters the shaft.
        Visible,
        /// Some object enters the shaft and none is known to block it whole.
        Partial,
    }
}

impl From<ShaftClass> for ShaftAnswer {
    fn from(class: ShaftClass) -> ShaftAnswer {
        match class {
            ShaftClass::Invisible => ShaftAnswer::Invisible,
            ShaftClass::Visible => ShaftAnswer::Visible,
            ShaftClass::Partial { .. } => ShaftAnswer::Partial,
        }
    }
}

/// Classifies the link by its shaft (memoised in the link context, candidates inherited from the
/// parent link). Partial when shaft culling is off.
#[derive(Clone, Copy, Debug)]
pub struct ShaftClassify;

impl Tool for ShaftClassify {
    type Answer = ShaftAnswer;
    const NEEDS: crate::refine::Needs = crate::refine::Needs::SHAFTS;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> ShaftAnswer {
        ctx.shaft_verdict().map_or(ShaftAnswer::Partial, ShaftAnswer::from)
    }
}

/// Is `B_S · (F_max − F_min)` above `eps` times the receiver's irradiance ([`LinkCtx::threshold`])? `F_min` is the smallest point form factor over the
/// receiver when the shaft is empty, and 0 when some candidate may occlude (a spread over the
/// receiver, so the answer is [`FfSpread`], as [`super::FfGradient`]'s).
#[derive(Clone, Copy, Debug)]
pub struct ShaftFfError(pub f64);

impl Tool for ShaftFfError {
    type Answer = FfSpread;
    const NEEDS: crate::refine::Needs = crate::refine::Needs::SHAFTS;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> FfSpread {
        let f_max = ctx.form_factor_max();
        let f_min = match ctx.shaft_verdict() {
            Some(ShaftClass::Visible) => ctx.form_factor_range().0.min(f_max),
            _ => 0.0,
        };
        if ctx.emitter_radiosity() * (f_max - f_min) > ctx.threshold(self.0) { FfSpread::Above } else { FfSpread::Below }
    }
}
