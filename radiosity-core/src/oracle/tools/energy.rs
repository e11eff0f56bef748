//! Energy questions: how much light a link carries and how large its error can be, each compared
//! with `eps` times the receiver's own irradiance ([`LinkCtx::threshold`]), so that the same eps
//! means the same relative accuracy on a surface lit by a lamp a thousand times brighter than it as
//! in a uniformly lit furnace.

use super::YesNo;
use crate::formfactor::FormFactorQuality;
use crate::oracle::Tool;
use crate::refine::LinkCtx;

/// Is `B_S · F_max` above `eps` times the receiver's irradiance? (the BF criterion of Hanrahan,
/// Salzman & Aupperle, relative to the receiver: a link whose whole transfer is below the
/// threshold cannot be wrong by more.)
#[derive(Clone, Copy, Debug)]
pub struct BfAbove(pub f64);

impl Tool for BfAbove {
    type Answer = YesNo;
    #[inline]
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> YesNo {
        let f = ctx.form_factor_max();
        let b = ctx.emitter_radiosity();
        if b * f <= ctx.threshold(self.0) { YesNo::No } else { YesNo::Yes }
    }
}

crate::answer_enum! {
    /// Answer of the error-bound questions ([`SourceVariation`], [`PartialVisibility`],
    /// [`ClusterError`]).
    pub enum ErrorBound {
        /// The link's error may exceed the threshold.
        Above,
        /// It may not.
        Below,
    }
}

pub use crate::refine::{CLUSTER_ERROR_COEF, SOURCE_VARIATION_WEIGHT};

/// Is the error of the receiver's mean irradiance, for the source's radiosity varying within its
/// leaves where the kernel does, above the threshold? `w · ΔB_S · SOURCE_VARIATION_WEIGHT`, `ΔB_S` how much the source's radiosity
/// varies over it (measured by the last solve, [`LinkCtx::emitter_variation`]) and `w` how strongly
/// such a variation shows in the receiver's mean ([`LinkCtx::source_variation_weight`]: the link's
/// form factor times the unevenness of the kernel over the source). A source of uniform radiosity
/// (a lamp, a furnace wall) is never refined for it however bright, and neither is a far one.
#[derive(Clone, Copy, Debug)]
pub struct SourceVariation(pub f64);

impl Tool for SourceVariation {
    type Answer = ErrorBound;
    #[inline]
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> ErrorBound {
        let dv = ctx.emitter_variation();
        if dv <= 0.0 {
            return ErrorBound::Below;
        }
        let err = ctx.source_variation_weight() * dv * SOURCE_VARIATION_WEIGHT;
        if err > ctx.threshold(self.0) { ErrorBound::Above } else { ErrorBound::Below }
    }
}

/// Is the error of a partly visible link above the threshold? The receiver's leaves all get the
/// link's mean visibility `V`, so one in full shadow or full light is off by up to
/// `B_S · F_max · max(V, 1 − V)`. The receiver's mean irradiance is right whatever `V`'s
/// distribution (`V` is the kernel-weighted mean); what the shadow's shape changes is the
/// irradiance of the receiver's parts, and the light it reflects on in proportion to its
/// reflectance `ρ_R`, so the bound used is `2 V (1 − V) · w · B_S · F_max`, `w` the weight the
/// criterion gives the receiver ([`LinkCtx::receiver_weight`]: `ρ_R` for the radiosity, 1 for the
/// irradiance), 0 for a link fully visible or hidden.
/// Casts the link's rays (kept for the link) only when the transfer could exceed the threshold at
/// all. (The irradiance at a calculation point gathers its own visibility and needs no shadow
/// in the mesh.)
#[derive(Clone, Copy, Debug)]
pub struct PartialVisibility(pub f64);

impl Tool for PartialVisibility {
    type Answer = ErrorBound;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> ErrorBound {
        let transfer = ctx.emitter_radiosity() * ctx.form_factor_max() * ctx.receiver_weight();
        let threshold = ctx.threshold(self.0);
        if 0.5 * transfer <= threshold {
            return ErrorBound::Below;
        }
        let v = ctx.decision_visibility(transfer, threshold);
        if 2.0 * v * (1.0 - v) * transfer > threshold { ErrorBound::Above } else { ErrorBound::Below }
    }
}

/// Is the error of the cluster approximation above the threshold? For a link with a cluster at
/// either end, `B_S · F · CLUSTER_ERROR_COEF · ((r_S + r_R) / d)²`; `Below` between surfaces.
#[derive(Clone, Copy, Debug)]
pub struct ClusterError(pub f64);

impl Tool for ClusterError {
    type Answer = ErrorBound;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> ErrorBound {
        let (s, r) = (ctx.emitter_element(), ctx.receiver_element());
        if !s.is_cluster() && !r.is_cluster() {
            return ErrorBound::Below;
        }
        let d2 = (s.center - r.center).length_squared();
        let ratio2 = if d2 > 0.0 { (s.radius + r.radius).powi(2) / d2 } else { f64::INFINITY };
        let f = ctx.form_factor(FormFactorQuality::Precise);
        let err = ctx.emitter_radiosity() * f * CLUSTER_ERROR_COEF * ratio2;
        if err > ctx.threshold(self.0) { ErrorBound::Above } else { ErrorBound::Below }
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

/// Would the link add more than `threshold` times the receiver's irradiance to it (`B_S · F`,
/// form factor estimated at the receiver's centre)?
#[derive(Clone, Copy, Debug)]
pub struct IrradianceChange(pub f64);

impl Tool for IrradianceChange {
    type Answer = Irradiance;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Irradiance {
        let f = ctx.form_factor(FormFactorQuality::Estimate);
        if ctx.emitter_radiosity() * f > ctx.threshold(self.0) { Irradiance::Significant } else { Irradiance::Negligible }
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
