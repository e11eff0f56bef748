//! Refine: one refinement pass of a level (the oracle's links at the level's threshold scale, the
//! shadows of the direct light pushed down, both sides of transmitting leaves matched) and the
//! direct light's own refinement ([`DIRECT_SHARE_OF_TARGET`]).

use super::{Context, Level, Progress, State};
use crate::hierarchy::Hierarchy;
use crate::refine::{self, ElementData};
#[cfg(doc)]
use crate::solve;
use crate::visibility::{RayCaster, VisibilityConfig};
use std::time::Instant;

impl State {
    /// Refinement pass `pass` (from 1) of level `at`: refines the links at the level's threshold
    /// scale within its limits, pushes the direct light's shadows down (irradiance criterion, with
    /// visibility), refines the direct light ([`refine_direct`]) and adds the pass's counters to the
    /// run's, subdivisions refused for memory to `importance_refused` during importance rounds.
    /// Returns how many elements the pass subdivided.
    pub(super) fn refine_pass(&mut self, cx: &Context<'_>, at: Level, pass: usize, importance_refused: Option<&mut u64>) -> u64 {
        let (config, services) = (cx.config, cx.services);
        let t = Instant::now();
        let (new_links, s) = refine::refine(
            &mut self.h,
            services.use_visibility.then_some(&services.caster),
            config.visibility,
            cx.oracle,
            std::mem::take(&mut self.links),
            &mut self.data,
            at.scale,
            services.shafts(),
            at.limits,
            config.criterion,
            cx.reflected_rays,
            // Under a local level only the links whose thresholds it tightened are examined
            // again; the others are kept as the level before decided them, at the same scale.
            self.examine.as_deref(),
            &|l, p| (cx.progress)(Progress::Refine { level: at.index + 1, pass, links: l, pending: p }),
        );
        self.links = new_links;
        if pass == 1 {
            self.kept_unexamined = s.kept_unexamined;
        }
        for e in self.h.match_sides() {
            self.data.inherit(&self.h, e);
        }
        let mut s = s;
        if config.criterion == refine::Criterion::Irradiance && services.use_visibility {
            let fresh = VisibilityConfig {
                rays: config.criterion.kept_rays(config.visibility.rays),
                seed: config.visibility.seed ^ refine::FRESH_VISIBILITY_SALT,
            };
            let (pushed, form_factors) = refine::push_direct_shadows(&self.h, &services.caster, fresh, std::mem::take(&mut self.links));
            self.links = pushed;
            s.form_factors += form_factors;
            s.links = self.links.len() as u64;
        }
        let direct_limit = at.limits.max_bytes.saturating_sub(self.links.len() * refine::BYTES_PER_LINK);
        let direct_tolerance = direct_tolerance(cx.target_error, at.scale);
        s.subdivided += refine_direct(
            &mut self.h,
            &mut self.data,
            &mut self.quadrature,
            &services.lights,
            services.direct_caster(),
            direct_tolerance,
            &self.polygon_factor,
            direct_limit,
        );
        self.timings.refine += t.elapsed().as_secs_f64();
        self.stats.oracle_calls += s.oracle_calls;
        self.stats.form_factors += s.form_factors;
        self.stats.subdivided += s.subdivided;
        self.stats.dropped += s.dropped;
        self.stats.kept_unexamined += s.kept_unexamined;
        match importance_refused {
            Some(refused) => *refused += s.refused_for_memory,
            None => self.stats.refused_for_memory += s.refused_for_memory,
        }
        self.stats.links = s.links;
        self.passes += 1;
        s.subdivided
    }
}

/// The share of the target error each polygon's mean direct irradiance is held to by
/// `refine_direct`: with [`solve::ESTIMATE_SAFETY`] on it, about half the target.
pub const DIRECT_SHARE_OF_TARGET: f64 = 0.2;
/// Most rounds of `refine_direct` after one refinement pass: each about halves what a shadow
/// edge misplaces.
pub const DIRECT_MAX_ROUNDS: usize = 10;
/// Most times a leaf is quartered for its direct light's quadrature by `refine_direct` (each time
/// 4 times the shadow rays) before it is split.
pub const DIRECT_MAX_QUADRATURE_DEPTH: u8 = 3;

/// What [`refine_direct`] holds each polygon's mean direct irradiance to, relative to its own
/// value, at a level of threshold scale `scale` under `target`: [`DIRECT_SHARE_OF_TARGET`] of
/// the target, and beyond the oracle's own thresholds (`scale` below 1, levels run on for the
/// target) as much finer as the links' thresholds are: the direct light is refined by the same
/// levels, and does not hold the estimate up while the links go finer alone (a 200-leaf canopy
/// ran from 31k to 2.7M links over four levels whose estimate stayed at 1.0–1.16%).
pub(super) fn direct_tolerance(target: Option<f64>, scale: f64) -> Option<f64> {
    target.map(|t| DIRECT_SHARE_OF_TARGET * t * scale.min(1.0))
}

/// Computes the direct light of the leaves made since the last call
/// ([`crate::luminaire::update_direct`]), then samples finer the leaves whose direct light's
/// quadrature keeps a polygon's mean direct irradiance from `tolerance` of its own
/// ([`crate::luminaire::direct_splits`]; [`crate::luminaire::deepen_direct`], its depth in
/// `quadrature`, up to [`DIRECT_MAX_QUADRATURE_DEPTH`]), and splits those sampled that finely
/// already, computing the new leaves' direct light, until none is left, for
/// [`DIRECT_MAX_ROUNDS`] rounds or until the elements would take more than `max_bytes`. Finer
/// quadrature first: it costs shadow rays, a split costs links as well, and where a shadow edge's
/// unevenness matters to a receiver the oracle splits the leaf for it (its radiosity range counts
/// the edge, [`crate::hierarchy::Hierarchy::direct_edge`]); on an 800-leaf canopy a quarter fewer
/// elements at the same accuracy. Returns how many leaves were split (their children inherit
/// `data`). Nothing without a tolerance (a target error, [`direct_tolerance`]).
#[expect(clippy::too_many_arguments, reason = "the pipeline's state this step reads and writes, passed explicitly")]
pub(super) fn refine_direct(
    h: &mut Hierarchy,
    data: &mut ElementData,
    quadrature: &mut Vec<u8>,
    lights: &crate::light::Lights,
    caster: Option<&RayCaster>,
    tolerance: Option<f64>,
    polygon_factor: &[f64],
    max_bytes: usize,
) -> u64 {
    crate::luminaire::update_direct(h, lights, caster);
    let Some(tolerance) = tolerance else { return 0 };
    let mut made = 0;
    for _ in 0..DIRECT_MAX_ROUNDS {
        let over = crate::luminaire::direct_splits(h, tolerance, polygon_factor);
        quadrature.resize(h.len(), 1);
        // Finer quadrature first (shadow rays only), then smaller elements (links as well).
        let (mut split, mut deepen): (Vec<u32>, Vec<(u32, u32)>) = (Vec::new(), Vec::new());
        for l in over {
            let depth = &mut quadrature[l as usize];
            if *depth < DIRECT_MAX_QUADRATURE_DEPTH {
                *depth += 1;
                deepen.push((l, u32::from(*depth)));
            } else if h.can_subdivide(l) {
                split.push(l);
            }
        }
        if (split.is_empty() && deepen.is_empty()) || (h.len() + 4 * split.len()) * refine::BYTES_PER_ELEMENT > max_bytes {
            break;
        }
        for &leaf in &split {
            if h.subdivide(leaf) {
                data.inherit(h, leaf);
                made += 1;
            }
        }
        for e in h.match_sides() {
            data.inherit(h, e);
        }
        crate::luminaire::update_direct(h, lights, caster);
        crate::luminaire::deepen_direct(h, lights, caster, &deepen);
    }
    made
}
