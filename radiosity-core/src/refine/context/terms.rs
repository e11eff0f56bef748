//! The terms memoised for one link, the constants of the link error model, and how unevenly a
//! receiver weights a source's surface.

use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::Hierarchy;

/// Terms computed for one link and shared by the tools that read them.
#[derive(Clone, Copy, Debug, Default)]
pub struct LinkData {
    /// Form factor and the quality it was computed with.
    pub form_factor: Option<(f64, FormFactorQuality)>,
    /// Estimate of the largest point form factor over the receiver.
    pub form_factor_max: Option<f64>,
    /// Visibility fraction and the number of rays behind it.
    pub visibility: Option<(f64, u32)>,
    /// Smallest and largest point form factor over the receiver (estimated at the probe points).
    pub form_factor_range: Option<(f64, f64)>,
    /// The centre-to-centre axis and the areas projected along it.
    pub axis: Option<LinkAxis>,
    /// How strongly the emitter's radiosity variation shows at the receiver
    /// ([`LinkCtx::source_variation_weight`](super::LinkCtx::source_variation_weight)).
    pub source_variation_weight: Option<f64>,
    /// A mark left by an oracle's command tool (studies, traces); the driver ignores it.
    pub mark: Option<u32>,
}

/// The centre-to-centre axis of a link and what is measured along it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinkAxis {
    /// Unit direction from the emitter's centre to the receiver's (zero when the centres coincide).
    pub dir: crate::geom::DVec3,
    /// Distance between the centres.
    pub distance: f64,
    /// Emitter area projected on the plane orthogonal to the axis (scene units²).
    pub projected_emitter: f64,
    /// Receiver area projected on the plane orthogonal to the axis (scene units²).
    pub projected_receiver: f64,
}

/// Weight of the source-variation error: the covariance of two quantities varying over the source
/// (the kernel and the radiosity) is at most a quarter of the product of their ranges.
pub const SOURCE_VARIATION_WEIGHT: f64 = 0.25;

/// Relative error of the point-source cluster approximation at separation `d` of elements of
/// bounding radii `r_S`, `r_R`: `CLUSTER_ERROR_COEF · ((r_S + r_R) / d)²` (the second-order term
/// of `1/r²` averaged over the two elements; the first order cancels about the area centroids).
pub const CLUSTER_ERROR_COEF: f64 = 1.0;

/// Mean fraction of a cluster's area seen from a random direction (isotropic clusters: a quarter,
/// as for the surface of a convex body).
pub const CLUSTER_PROJECTED_FRACTION: f64 = 0.25;

/// Largest kernel spread in [`LinkCtx::source_variation_weight`](super::LinkCtx::source_variation_weight) (a kernel that varies from 0 to
/// twice its mean over the emitter).
pub const MAX_SOURCE_KERNEL_VARIATION: f64 = 2.0;

/// Clusters nearer than this many times the sum of the bounding radii (centre distance) are too
/// near for the isotropic cluster approximation (the criterion of the BF oracle).
pub const CLUSTER_NEAR_FACTOR: f64 = 2.0;

/// How unevenly `receiver`, as a whole, weights the surface of `source`: the spread
/// `(max − min) / mean` of the point form factor from the source's probe points (centre, corners
/// pulled in by [`formfactor::MAX_PROBE_PULL`]) to the receiver, at most
/// [`MAX_SOURCE_KERNEL_VARIATION`] (and that for a cluster source, whose members' weights are not
/// probed, or one the receiver does not see). Near 0 for a far receiver, large for one touching
/// the source: a radiosity varying by `ΔB` over the source moves the receiver's mean irradiance by
/// at most `F · κ · ΔB / 4` (the covariance of kernel and radiosity, each within its range).
#[must_use]
pub fn source_kernel_spread(h: &Hierarchy, source: u32, receiver: u32) -> f64 {
    let s = h.get(source);
    let Some(sp) = s.poly() else { return MAX_SOURCE_KERNEL_VARIATION };
    let (mut lo, mut hi, mut sum) = (f64::INFINITY, 0.0f64, 0.0);
    let vs = sp.vertices();
    for x in std::iter::once(s.center).chain(vs.iter().map(|&v| v + formfactor::MAX_PROBE_PULL * (s.center - v))) {
        let f = formfactor::point_to_element(h, x, s.normal, receiver);
        lo = lo.min(f);
        hi = hi.max(f);
        sum += f;
    }
    let mean = sum / (vs.len() + 1) as f64;
    if mean > 0.0 { ((hi - lo) / mean).min(MAX_SOURCE_KERNEL_VARIATION) } else { MAX_SOURCE_KERNEL_VARIATION }
}
