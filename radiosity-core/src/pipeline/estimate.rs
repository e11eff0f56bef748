//! Estimate: after a level's leaf-resolution solve, the change of the polygon means since the
//! level before, the error estimate (scene-wide and per polygon, floored by the change under a
//! target), and with daylight the power balance gap.

use super::solving::LeafSolved;
use super::{Config, Context, State};
use crate::hierarchy::Hierarchy;
use crate::refine::{self, Link};
use crate::solve::{self, Solution};
use std::time::Instant;

/// What the estimate found after a level.
pub(super) struct LevelEstimate {
    /// The largest non-emitting polygon mean radiosity.
    pub(super) top: f64,
    /// The largest change of a non-emitting polygon mean since the level before, relative to `top`
    /// (`None` for the first level).
    pub(super) change: Option<f64>,
    /// The error estimate, when made.
    pub(super) estimate: Option<f64>,
    /// Under the irradiance criterion, each polygon's mean irradiance's share of the estimate
    /// ([`estimate_error`]); empty otherwise.
    pub(super) irradiance_errors: Vec<f64>,
    /// With daylight and a target error, the power balance gap.
    pub(super) balance_gap: Option<f64>,
}

impl State {
    /// Pushes the level's polygon means to the history and, under a target error or at the last
    /// level (`last_level`, or refinement refused for memory), estimates the error of `leaf`'s
    /// solution ([`estimate_error`]), each polygon's in `polygon_errors`.
    pub(super) fn estimate_level(&mut self, cx: &Context<'_>, leaf: &mut LeafSolved, last_level: bool) -> LevelEstimate {
        let (config, target_error, services) = (cx.config, cx.target_error, cx.services);
        let (h, links, sol) = (&self.h, &self.links, &leaf.solution);
        let t = Instant::now();
        let means: Vec<[f64; 3]> = crate::solve::polygon_results(h, sol).into_iter().map(|r| r.b).collect();
        let top = solve::largest_non_emitting_mean(h, &sol.radiosity);
        let change = self.history.push(means);
        let last = last_level || self.stats.refused_for_memory > 0;
        // The leaf coefficients go to the estimate, or are dropped here when none is made.
        let fine = leaf.coefficients.take();
        let estimated = (config.estimate_error && config.final_gather && (target_error.is_some() || last))
            .then(|| estimate_error(h, links, sol, services.closed, &leaf.closure_changes, config, leaf.budget, fine));
        let (estimated, irradiance_errors) = match estimated {
            Some(Estimated { estimate, per_polygon, irradiance_errors, reuse }) => {
                self.chain_reuse = reuse;
                (Some((estimate, per_polygon)), irradiance_errors)
            }
            None => (None, Vec::new()),
        };
        // Under a target, at least what the last level changed (solve::LEVEL_CHANGE_SAFETY).
        let estimated = estimated.map(|(e, per_polygon)| match target_error {
            Some(_) => self.history.floor_by_change(e, per_polygon),
            None => (e, per_polygon),
        });
        let estimate = estimated.as_ref().map(|e| e.0);
        self.polygon_errors = estimated.map(|e| e.1).unwrap_or_default();
        let balance_gap = (!services.lights.distant.is_empty() && target_error.is_some()).then(|| {
            self.escapes.cover(h.len());
            crate::daylight::balance_gap(h, &services.lights.distant, sol, &services.caster, &self.escapes)
        });
        self.timings.estimate += t.elapsed().as_secs_f64();
        LevelEstimate { top, change, estimate, irradiance_errors, balance_gap }
    }
}

/// The error estimate of the leaf-resolution solution `sol` (see [`solve::richardson_estimate`]):
/// the same links solved on the mesh one and two levels coarser ([`solve::Cut::coarsened`]), the
/// Richardson extrapolation of the three plus what polygons left whole hide from it
/// ([`solve::unresolved_per_polygon`]), with the visibility-sampling noise
/// ([`solve::visibility_noise`]) or the closure's possible misplacement of light
/// ([`solve::closure_error`], from `closure_changes`, per link) where larger, times
/// [`solve::ESTIMATE_SAFETY`]. The direct light's quadrature error
/// ([`crate::luminaire::direct_polygon_errors`]) is added to the mesh's, polygon by polygon
/// ([`solve::mesh_and_direct_estimate`]): the largest of each term may lie on different
/// polygons (on Ward's room at eps 0.64 the estimate fell from 35% to 26% for a true 7.6%).
/// The coarser solves' coefficients are made from `fine`, the solution's own, where it is given
/// and they can be ([`solve::LeafCoefficients::coarsened`]), and anew otherwise.
/// Returns the estimate, each polygon's share in W/m² of radiosity, under the irradiance
/// criterion each polygon's mean irradiance's share relative to the largest (empty otherwise),
/// and `fine`'s chain coefficients for the next level's ([`solve::ChainReuse`]).
#[expect(clippy::too_many_arguments, reason = "the level's solution and what its estimate reads of it")]
pub(super) fn estimate_error(
    h: &Hierarchy,
    links: &[Link],
    sol: &Solution,
    closed: bool,
    closure_changes: &[f32],
    config: &Config,
    max_bytes: usize,
    fine: Option<solve::LeafCoefficients>,
) -> Estimated {
    // Under the irradiance criterion the estimate covers the polygons' mean irradiance as well.
    let irradiance = config.criterion == refine::Criterion::Irradiance;
    let results = crate::solve::polygon_results(h, sol);
    let mut means = vec![results.iter().map(|r| r.b).collect::<Vec<[f64; 3]>>()];
    // The irradiance the user reads adds the luminaires' and distant sources' direct light, which
    // no coarsening changes: it leaves the changes as they are and sets what they are relative to.
    let direct = crate::luminaire::polygon_direct_means(h);
    let with_direct = |results: Vec<crate::solve::PolygonResult>| -> Vec<[f64; 3]> {
        results.iter().enumerate().map(|(p, r)| std::array::from_fn(|c| r.h[c] + direct.get(p).map_or(0.0, |d| d[c]))).collect()
    };
    let mut h_means = vec![with_direct(results.clone())];
    // Each coarser cut's coefficients from the finer cut's where they can be.
    let mut finer = fine.map(|c| (solve::Cut::leaves(h), c));
    let mut reuse = None;
    for levels in 1..=2 {
        let cut = solve::Cut::coarsened(h, levels);
        let coefficients = finer
            .take()
            .and_then(|(fine_cut, c)| {
                // The solution's own chain coefficients serve the next level's too.
                let (coarse, kept) = c.coarsened(&fine_cut, &cut, links, levels == 1 && config.reuse_leaf_coefficients);
                if kept.is_some() {
                    reuse = kept;
                }
                coarse
            })
            .unwrap_or_else(|| {
                solve::LeafCoefficients::for_cut(&cut, links, closed, max_bytes, solve::Precision::for_target(config.target_error))
            });
        let op = solve::LeafOperator::for_cut(cut, links, &coefficients);
        let coarse = solve::solve_leaf_operator(&op, &sol.radiosity, &config.solve);
        drop(op);
        finer = (levels < 2).then(|| (solve::Cut::coarsened(h, levels), coefficients));
        let results = crate::solve::polygon_results(h, &coarse);
        means.push(results.iter().map(|r| r.b).collect());
        h_means.push(with_direct(results));
    }
    let unresolved = solve::unresolved_per_polygon(h, links, &sol.radiosity);
    let polygon_noise = solve::noise_per_polygon(h, links, &sol.radiosity);
    let noise = solve::worst_noise(h, &polygon_noise, &sol.radiosity, irradiance.then_some(h_means[0].as_slice()));
    let closure = solve::closure_error(h, links, closure_changes, &sol.radiosity, irradiance.then_some(h_means[0].as_slice()));
    // The direct light's quadrature adds to the mesh's error where a shadow edge crosses leaves.
    let direct_errors = crate::luminaire::direct_polygon_errors(h);
    let mesh_direct = solve::mesh_and_direct_estimate(
        h,
        [&means[0], &means[1], &means[2]],
        irradiance.then(|| [h_means[0].as_slice(), h_means[1].as_slice(), h_means[2].as_slice()]),
        &unresolved,
        &direct_errors,
    );
    let estimate = solve::ESTIMATE_SAFETY * mesh_direct.max(noise).max(closure) + solve::ESTIMATE_FLOOR;
    // Per polygon, in W/m² of radiosity: its own mesh error and visibility noise, the closure's
    // scene-wide term as it is. The noise is each polygon's own: taken scene-wide (the noisiest
    // polygon's, 0.82% of the brightest mean with the safety factor), it put every leaf of an
    // 800-leaf canopy over half the target at its second level, where the own terms of 5 were,
    // and the next level refined them all.
    let top = solve::largest_non_emitting_mean(h, &sol.radiosity);
    let wide = closure * top;
    let per_polygon = solve::richardson_per_polygon(&means[0], &means[1], &means[2])
        .into_iter()
        .enumerate()
        .map(|(p, e)| {
            // Irradiance errors passed on as radiosity, largest channel.
            let reflected = |v: [f64; 3]| (0..3).map(|c| h.reflectance[p][c] * v[c]).fold(0.0, f64::max);
            let direct = direct_errors.get(p).map_or(0.0, |&d| reflected(d));
            let unresolved = unresolved[p].into_iter().fold(0.0, f64::max);
            solve::ESTIMATE_SAFETY * (e + unresolved + direct).max(reflected(polygon_noise[p])).max(wide) + solve::ESTIMATE_FLOOR * top
        })
        .collect();
    // Under the irradiance criterion, each polygon's mean irradiance's own share (relative to the
    // largest measured mean irradiance): what black and dark surfaces hold the estimate up by.
    let irradiance_errors = if irradiance {
        let top_h = solve::measured_polygons(h).flat_map(|p| h_means[0][p]).fold(0.0, f64::max);
        let own = solve::richardson_per_polygon(&h_means[0], &h_means[1], &h_means[2]);
        let mut errors = vec![0.0; own.len()];
        for p in solve::measured_polygons(h).filter(|_| top_h > 0.0) {
            let direct = direct_errors.get(p).map_or(0.0, |d| d.iter().copied().fold(0.0, f64::max));
            let noise = polygon_noise[p].into_iter().fold(0.0, f64::max);
            errors[p] = solve::ESTIMATE_SAFETY * (own[p] + direct).max(noise) / top_h;
        }
        errors
    } else {
        Vec::new()
    };
    Estimated { estimate, per_polygon, irradiance_errors, reuse }
}

/// What [`estimate_error`] returns.
pub(super) struct Estimated {
    /// The estimate.
    pub(super) estimate: f64,
    /// Each polygon's share, W/m² of radiosity.
    pub(super) per_polygon: Vec<f64>,
    /// Under the irradiance criterion each polygon's mean irradiance's share relative to the
    /// largest (empty otherwise).
    pub(super) irradiance_errors: Vec<f64>,
    /// The leaf-resolution chain coefficients it was given, for the next level's.
    pub(super) reuse: Option<solve::ChainReuse>,
}
