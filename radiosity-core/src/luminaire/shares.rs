//! Each light source's share of the light: the power it brings to the surfaces directly, for a
//! scene lit by several kinds of source (daylight and luminaires in one solve).

use super::ParallelShadows;
use super::point::DirectLight;
use super::rule::{LeafSources, leaf_direct};
use crate::hierarchy::{ElementKind, Hierarchy};
use crate::light::{DistantSource, Luminaire};
use crate::visibility::RayCaster;

/// What a source is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SourceKind {
    /// A photometric luminaire.
    Luminaire,
    /// A sharp distant source (the sun).
    Sun,
    /// The sky's cells, together.
    Sky,
}

/// One source's direct light on the scene's surfaces.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SourceShare {
    /// The luminaire's name, or `sun` / `sky`.
    pub name: String,
    /// What it is.
    pub kind: SourceKind,
    /// Power arriving directly on the surfaces (the front of every leaf; W or lm), per channel.
    pub onto_surfaces: [f64; 3],
    /// Its share of all the sources' direct power on the surfaces (mean over the channels; the
    /// shares sum to 1).
    pub share: f64,
}

/// The power each source brings directly to the surfaces of `h`: every luminaire on its own, the
/// sun, and the sky's cells together; the same quadrature with shadow rays as the elements' direct
/// light ([`update_direct`](super::update_direct)), one pass over the leaves per source. Linear in
/// the sources, so the parts add up to what all of them bring together (to the quadrature's
/// accuracy, which chooses its points per source).
#[must_use]
pub fn source_shares(h: &Hierarchy, luminaires: &[Luminaire], distant: &[DistantSource], caster: Option<&RayCaster>) -> Vec<SourceShare> {
    let mut out: Vec<SourceShare> = luminaires
        .iter()
        .map(|l| share(l.name.clone(), SourceKind::Luminaire, direct_power(h, std::slice::from_ref(l), &[], caster)))
        .collect();
    let (sun, sky): (Vec<DistantSource>, Vec<DistantSource>) = distant.iter().partition(|d| d.sharp);
    for s in &sun {
        out.push(share("sun".into(), SourceKind::Sun, direct_power(h, &[], std::slice::from_ref(s), caster)));
    }
    if !sky.is_empty() {
        out.push(share("sky".into(), SourceKind::Sky, direct_power(h, &[], &sky, caster)));
    }
    let total: f64 = out.iter().map(|s| s.onto_surfaces.iter().sum::<f64>()).sum();
    for s in &mut out {
        s.share = if total > 0.0 { s.onto_surfaces.iter().sum::<f64>() / total } else { 0.0 };
    }
    out
}

/// The power all `luminaires` bring directly to the surfaces of `h` (front sides, per channel): in
/// a scene open to daylight, what of their flux stays in the scene at its first bounce.
#[must_use]
pub fn luminaires_onto_surfaces(h: &Hierarchy, luminaires: &[Luminaire], caster: Option<&RayCaster>) -> [f64; 3] {
    direct_power(h, luminaires, &[], caster)
}

fn share(name: String, kind: SourceKind, onto_surfaces: [f64; 3]) -> SourceShare {
    SourceShare { name, kind, onto_surfaces, share: 0.0 }
}

/// `Σ area · E_direct` over the surface leaves of `h`, from `luminaires` and `distant` only.
fn direct_power(h: &Hierarchy, luminaires: &[Luminaire], distant: &[DistantSource], caster: Option<&RayCaster>) -> [f64; 3] {
    use rayon::prelude::*;
    let light = DirectLight::new(luminaires, caster, h.diagonal());
    let distant_light = crate::daylight::DistantLight::new(distant, caster, h.diagonal());
    let shadows = ParallelShadows::new(h, distant, caster);
    let leaves: Vec<u32> = h.leaves().collect();
    leaves
        .par_iter()
        .filter_map(|&id| {
            let e = h.get(id);
            let ElementKind::Surface { polygon, poly } = e.kind else { return None };
            let at = LeafSources { normal: e.normal, polygon, light: &light, distant: &distant_light, shadows: shadows.as_ref() };
            Some(leaf_direct(&poly, &at, 1, None).direct.map(|d| d * e.area))
        })
        .reduce(|| [0.0; 3], |a, b| std::array::from_fn(|c| a[c] + b[c]))
}
