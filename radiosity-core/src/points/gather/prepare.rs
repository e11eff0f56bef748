//! Preparing the gather at points: the leaves of a solution that give light, and, from a solve
//! (finished or between its refinements), what each point's error starts from: how the radiosity
//! varies over each leaf, how far its value may be off, and the error of its polygon's mean.

use super::point::on_surface_reach;
use super::{ON_SURFACE_REL_TOL, PointGather, PointsConfig, Source};
use crate::geom::{Aabb, DVec3};
use crate::hierarchy::Hierarchy;
use crate::visibility::RayCaster;

/// What a gather at points reads of a solve, finished ([`PointGather::for_solved`]) or between
/// its refinements (the importance rounds of [`crate::pipeline::run_with_points`]).
#[derive(Clone, Copy)]
pub struct SolveParts<'a> {
    /// The hierarchy.
    pub hierarchy: &'a Hierarchy,
    /// Its links.
    pub links: &'a [crate::refine::Link],
    /// The leaf-resolution solution of the links.
    pub solution: &'a crate::solve::Solution,
    /// The luminaires and distant sources.
    pub lights: &'a crate::light::Lights,
    /// The ray caster over the scene.
    pub caster: &'a RayCaster,
    /// The scene is a convex enclosure (points inside it cast no ray).
    pub convex_enclosure: bool,
    /// The solve's error estimate (relative to its largest non-emitting polygon mean).
    pub error_estimate: Option<f64>,
    /// Per polygon, the estimated error of its mean radiosity (W/m²,
    /// [`crate::pipeline::Solved::polygon_errors`]); `None` or empty: the estimate times the
    /// largest mean for every polygon.
    pub polygon_errors: Option<&'a [f64]>,
    /// Each element's radiosity range for this solution ([`crate::solve::element_data`]'s
    /// `variation`), when known already (measured again when `None`).
    pub variation: Option<&'a [f64]>,
}

/// A finished solve, as a gather at points reads it: the pipeline's `Solved` gives its parts
/// this way, so that the points (which the pipeline's importance rounds use) need not know the
/// pipeline.
pub trait AsSolveParts {
    /// The parts of the solve a gather reads.
    fn solve_parts(&self) -> SolveParts<'_>;
}

impl<'a> PointGather<'a> {
    /// Prepares the gather from `h`, its per-element `radiosity` (W/m², leaves read) and the ray
    /// caster over the same scene (`None`, or `config.use_visibility` off: no rays).
    #[must_use]
    pub fn new(h: &'a Hierarchy, radiosity: &[[f64; 3]], caster: Option<&'a RayCaster>, config: &PointsConfig) -> PointGather<'a> {
        let mut bounds = Aabb::EMPTY;
        for p in 0..h.n_polygons {
            bounds.merge(&h.get(p).bounds);
        }
        let sources = h
            .leaves()
            .filter_map(|id| {
                let e = h.get(id);
                let (poly, polygon) = (*e.poly()?, e.polygon()?);
                let b = radiosity[id as usize];
                b.iter().any(|&v| v > 0.0).then_some(Source {
                    poly,
                    normal: e.normal,
                    center: e.center,
                    radius: e.radius,
                    polygon,
                    b,
                    variation: 0.0,
                    value_error: 0.0,
                    mean_error: f64::NAN,
                    id,
                })
            })
            .collect();
        let scale = bounds.diagonal();
        let tol = ON_SURFACE_REL_TOL * scale;
        let boxes: Vec<Aabb> = (0..h.n_polygons)
            .map(|p| {
                let e = h.get(p);
                let b = e.bounds;
                let reach = e.poly().map_or(0.0, |poly| on_surface_reach(poly, tol, scale));
                Aabb { min: b.min - DVec3::splat(reach), max: b.max + DVec3::splat(reach) }
            })
            .collect();
        PointGather {
            h,
            caster: caster.filter(|_| config.use_visibility),
            sources,
            scale,
            convex_enclosure: false,
            shadow_depth: config.shadow_depth,
            lights: None,
            mean_error: f64::NAN,
            on_surface: crate::visibility::shaft::ObjectBvh::build(&boxes),
        }
    }

    /// Prepares the gather from a solve's hierarchy, radiosity, caster and lights
    /// ([`AsSolveParts`]; the pipeline's `Solved` is one). When the solve's analysis found a
    /// convex enclosure (no visibility needed), points inside it cast no ray.
    #[must_use]
    pub fn for_solved<S: AsSolveParts + ?Sized>(solved: &'a S, config: &PointsConfig) -> PointGather<'a> {
        PointGather::for_solve(&solved.solve_parts(), config)
    }

    /// Prepares the gather from the parts of a solve (finished or between its refinements).
    #[must_use]
    pub fn for_solve(solve: &SolveParts<'a>, config: &PointsConfig) -> PointGather<'a> {
        let mut g = PointGather::new(solve.hierarchy, &solve.solution.radiosity, Some(solve.caster), config);
        g.convex_enclosure = solve.convex_enclosure;
        g.lights = Some(solve.lights);
        // What the error of each point starts from: how the radiosity varies over each leaf, and
        // the estimated error of the leaves' means.
        let measured;
        let variation = match solve.variation {
            Some(v) => v,
            None => {
                measured = crate::solve::element_data(solve.hierarchy, solve.links, solve.solution).variation;
                &measured
            }
        };
        let value_errors = crate::solve::leaf_value_errors(solve.hierarchy, solve.links, &solve.solution.radiosity, variation);
        for s in &mut g.sources {
            s.variation = variation[s.id as usize];
            s.value_error = value_errors[s.id as usize];
        }
        g.mean_error = solve
            .error_estimate
            .map_or(f64::NAN, |e| e * crate::solve::largest_non_emitting_mean(solve.hierarchy, &solve.solution.radiosity));
        if let Some(per_polygon) = solve.polygon_errors.filter(|p| p.len() == solve.hierarchy.n_polygons as usize) {
            for s in &mut g.sources {
                s.mean_error = per_polygon[s.polygon as usize];
            }
        }
        g
    }
}
