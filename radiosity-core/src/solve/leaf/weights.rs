//! The leaf operator's source side: whether a link weights its source's unknowns by its own kernel,
//! each source's weights over its unknowns, and the form factors that share a link's transfer
//! among the leaves at either end.

use super::chain::LeavesBelow;
use super::{OWN_WEIGHTS_SEPARATION, WEIGHT_FAR_SEPARATION};
use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::{ElementId, Hierarchy};
use crate::refine::Link;

/// Whether `link` weights its source's unknowns by its own kernel.
pub(super) fn own_weights(h: &Hierarchy, below: &LeavesBelow, l: &Link) -> bool {
    let (s, r) = (h.get(l.source), h.get(l.receiver));
    below.below(l.source).len() > 1 && (s.center - r.center).length() < OWN_WEIGHTS_SEPARATION * (s.radius + r.radius)
}

/// What the source side of one source's links gives: the transfer of its links from a cluster to
/// a surface (the sum over the source's unknowns), each near link's own weights, and the far
/// links' shared weights.
pub(super) struct SourceWeights {
    pub(super) transfer: Vec<(u32, f64)>,
    pub(super) own: Vec<(u32, Vec<f64>)>,
    pub(super) far: Vec<u32>,
    pub(super) shared: Option<Vec<f64>>,
}

/// The source side of the links of `group` (one source above the cut): each link's shares
/// `A_y F(y ← receiver) V` over the source's unknowns `y`, normalised into its own weights (a near
/// link) or, scaled to the link's transfer, summed into the source's shared weights (far links).
pub(super) fn source_weights(h: &Hierarchy, links: &[Link], below: &LeavesBelow, group: &[u32], transfer: &[f64]) -> SourceWeights {
    let s = links[group[0] as usize].source;
    let leaves = below.below(s);
    let area_weights = || -> Vec<f64> {
        let area = h.get(s).area;
        leaves.iter().map(|&y| h.get(y).area / area).collect()
    };
    let mut out = SourceWeights { transfer: Vec::new(), own: Vec::new(), far: Vec::new(), shared: None };
    let mut acc: Vec<f64> = Vec::new();
    let mut shares = Vec::with_capacity(leaves.len());
    for &k in group {
        let l = &links[k as usize];
        shares.clear();
        shares.extend(leaves.iter().map(|&y| h.get(y).area * weight_form_factor(h, l.receiver, y) * l.vis));
        let total: f64 = shares.iter().sum();
        let mut t = transfer[k as usize];
        if h.get(l.source).poly().is_none() && h.get(l.receiver).poly().is_some() && total > 0.0 {
            t = total;
            out.transfer.push((k, t));
        }
        if own_weights(h, below, l) {
            let w = if total > 0.0 { shares.iter().map(|x| x / total).collect() } else { area_weights() };
            out.own.push((k, w));
        } else {
            acc.resize(leaves.len(), 0.0);
            if total > 0.0 {
                let scale = t / total;
                for (w, x) in acc.iter_mut().zip(&shares) {
                    *w += scale * x;
                }
            }
            out.far.push(k);
        }
    }
    if !out.far.is_empty() {
        let sum: f64 = acc.iter().sum();
        out.shared = Some(if sum > 0.0 { acc.iter().map(|w| w / sum).collect() } else { area_weights() });
    }
    out
}

/// The form factor `F(leaf ← source)` that shares a link's transfer among the receiver's leaves:
/// the point value at the leaf's centre when the source is far ([`WEIGHT_FAR_SEPARATION`]), the
/// precise one otherwise. (The shares are scaled to the link's transfer, so only their ratios
/// matter.)
pub(super) fn shape_form_factor(h: &Hierarchy, source: ElementId, leaf: ElementId) -> f64 {
    let (s, e) = (h.get(source), h.get(leaf));
    let separation = (s.center - e.center).length() / (s.radius + e.radius).max(f64::MIN_POSITIVE);
    if separation >= WEIGHT_FAR_SEPARATION && !formfactor::behind_surface(s, e.poly().map_or(&[][..], |p| p.vertices()).iter().copied()) {
        formfactor::point_to_element(h, e.center, e.normal, source)
    } else if separation >= formfactor::NEAR_SEPARATION && e.poly().is_some() && s.poly().is_some() {
        formfactor::link_form_factor(h, source, leaf, FormFactorQuality::Shape)
    } else {
        formfactor::link_form_factor(h, source, leaf, FormFactorQuality::Precise)
    }
}

/// The form factor `F(y ← receiver)` that weights source leaf `y` of a link to `receiver`: the
/// point value at `y`'s centre when far, the precise one otherwise.
fn weight_form_factor(h: &Hierarchy, receiver: ElementId, y: ElementId) -> f64 {
    let (r, e) = (h.get(receiver), h.get(y));
    let separation = (r.center - e.center).length() / (r.radius + e.radius).max(f64::MIN_POSITIVE);
    if separation >= WEIGHT_FAR_SEPARATION && e.poly().is_some() {
        formfactor::point_to_element(h, e.center, e.normal, receiver)
    } else {
        formfactor::link_form_factor(h, receiver, y, FormFactorQuality::Precise)
    }
}
