//! The reference: the same scene solved fully (flattened), and the error of an instanced solve
//! against it.

use super::config::{InstancedConfig, local_pipeline};
use super::sink::{Leaf, PolygonInfo, PolygonMeans, RadiositySink, collect_leaves};
use crate::hierarchy::ElementId;
use crate::instancing::InstancingError;
use crate::instancing::flatten::FlattenOptions;
use crate::instancing::model::InstancedScene;
use crate::pipeline;
use crate::refine::{ClassicBf, first_guess_max};

/// The same scene solved fully: flattened (two-sided polygons as pairs) and given to
/// [`pipeline::run`] (with the daylight of [`InstancedConfig::daylight`], which the plain solve
/// takes like a luminaire's light, elements split along the sun's shadows); the per-polygon mean
/// radiosity is returned in flattening order, with the solve's link count.
pub fn solve_full(scene: &InstancedScene, config: &InstancedConfig) -> Result<(PolygonMeans, u64), InstancingError> {
    let mut flat = crate::instancing::flatten(scene, &FlattenOptions { two_sided_pairs: true })?;
    flat.distant.clone_from(&config.daylight);
    // Thresholds relative to the brightest radiosity, as the instanced solve's (the daylight's
    // when it is brighter than the emitters').
    let b_ref = first_guess_max(&flat).max(super::daylight::brightest(&flat.materials, &config.daylight));
    // No error estimate: the comparison measures the error, and the instanced solve has none either.
    // On a worker of the pool, as the instanced solve runs (a like-for-like comparison).
    let solved = rayon::scope(|_| pipeline::run(&flat, &ClassicBf { eps: config.bf.eps, b_ref }, &local_pipeline(config), &|_| {}));
    let mut means = PolygonMeans::default();
    let mut leaves = Vec::new();
    for i in 0..flat.polygons.len() {
        leaves.clear();
        collect_leaves(&solved.hierarchy, i as ElementId, &mut |e| {
            if let Some(p) = solved.hierarchy.get(e).poly() {
                leaves.push(Leaf { poly: *p, b: solved.solution.radiosity[e as usize], h: solved.solution.irradiance[e as usize] });
            }
        });
        means.polygon(&PolygonInfo { flat_index: i as u64, material: flat.polygons[i].material, prototype: scene.root }, &leaves)?;
    }
    Ok((means, solved.links.len() as u64))
}

/// Per polygon of `reference`: its error in `approx` (largest over the channels) as a fraction of
/// the largest radiosity of `reference`, and its area.
fn polygon_errors<'a>(reference: &'a PolygonMeans, approx: &'a PolygonMeans) -> impl Iterator<Item = (f64, f64)> + 'a {
    let b_max = reference.radiosity.iter().flat_map(|b| b.iter().copied()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    reference.radiosity.iter().enumerate().map(move |(i, r)| {
        let a = approx.radiosity.get(i).copied().unwrap_or([0.0; 3]);
        let e = (0..3).map(|c| (r[c] - a[c]).abs()).fold(0.0, f64::max);
        (e / b_max, reference.area.get(i).copied().unwrap_or(0.0))
    })
}

/// Polygons of `approx` whose error (largest over the channels) exceeds `fraction` of the largest
/// radiosity of `reference`.
#[must_use]
pub fn polygons_above(reference: &PolygonMeans, approx: &PolygonMeans, fraction: f64) -> usize {
    polygon_errors(reference, approx).filter(|&(e, _)| e > fraction).count()
}

/// Error of `approx` against `reference`, per polygon and channel, as a fraction of the largest
/// radiosity of `reference`: `(max error, area-weighted mean error)`.
#[must_use]
pub fn relative_error(reference: &PolygonMeans, approx: &PolygonMeans) -> (f64, f64) {
    let (mut worst, mut acc, mut area) = (0.0f64, 0.0, 0.0);
    for (e, w) in polygon_errors(reference, approx) {
        worst = worst.max(e);
        acc += w * e;
        area += w;
    }
    (worst, if area > 0.0 { acc / area } else { 0.0 })
}
