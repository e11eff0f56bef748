//! Energy questions: the BF criterion, irradiance change, form factor gradient.

use super::YesNo;
use crate::formfactor::FormFactorQuality;
use crate::oracle::Tool;
use crate::refine::LinkCtx;

/// Is `B_S · F_max` above `eps · B_ref`? (the classic BF criterion, with the largest point form
/// factor over the receiver, as the hand-written BF oracle).
#[derive(Clone, Copy, Debug)]
pub struct BfAbove(pub f64);

impl Tool for BfAbove {
    type Answer = YesNo;
    #[inline]
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> YesNo {
        let f = ctx.form_factor_max();
        let b = ctx.emitter_radiosity();
        if b * f <= self.0 * ctx.services.b_ref { YesNo::No } else { YesNo::Yes }
    }
}

crate::answer_enum! {
    /// Answer of [`IrradianceChange`].
    pub enum Irradiance {
        /// The link would change the receiver's irradiance noticeably.
        Significant,
        /// It would not.
        Negligible,
    }
}

/// Would the link add more than `threshold · B_ref` to the receiver's irradiance (`B_S · F`, form
/// factor estimated at the receiver's centre)?
#[derive(Clone, Copy, Debug)]
pub struct IrradianceChange(pub f64);

impl Tool for IrradianceChange {
    type Answer = Irradiance;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Irradiance {
        let f = ctx.form_factor(FormFactorQuality::Estimate);
        if ctx.emitter_radiosity() * f > self.0 * ctx.services.b_ref { Irradiance::Significant } else { Irradiance::Negligible }
    }
}

crate::answer_enum! {
    /// Answer of [`FfGradient`] and [`super::ShaftFfError`].
    pub enum FfSpread {
        /// The point form factor (or the transfer `B_S · F`) varies by more than the threshold over
        /// the receiver.
        Above,
        /// It does not.
        Below,
    }
}

/// Is the spread `max − min` of the point form factor over the receiver above the threshold?
#[derive(Clone, Copy, Debug)]
pub struct FfGradient(pub f64);

impl Tool for FfGradient {
    type Answer = FfSpread;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> FfSpread {
        let (lo, hi) = ctx.form_factor_range();
        if hi - lo > self.0 { FfSpread::Above } else { FfSpread::Below }
    }
}
