//! The whole solve, step after step: hierarchy → (refine → solve)* → a [`Solved`] result with the
//! figures `stats.json` reports. Front ends (the CLI, tests, benchmarks) call [`run`].

use crate::analysis::SceneTraits;
use crate::hierarchy::{self, BuildConfig, Hierarchy};
use crate::refine::{self, Link, Oracle, RefineStats};
use crate::scene::Scene;
use crate::solve::{self, Solution, SolveConfig};
use crate::visibility::{RayCaster, VisibilityConfig};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Settings of a full solve.
#[derive(Clone, Copy, Debug)]
pub struct Config {
    /// Hierarchy construction.
    pub build: BuildConfig,
    /// Visibility sampling.
    pub visibility: VisibilityConfig,
    /// Linear solver.
    pub solve: SolveConfig,
    /// Most refine → solve rounds (refinement stops earlier when a round subdivides nothing).
    pub max_passes: usize,
    /// Cast rays for visibility (false: every link is taken as fully visible).
    pub use_visibility: bool,
    /// How link visibility is computed.
    pub visibility_method: VisibilityMethod,
    /// Analyse the scene first and leave out what it does not need (visibility in a convex
    /// enclosure); see [`crate::analysis`].
    pub analyse: bool,
    /// After the last hierarchical solve, solve again at leaf resolution (every leaf gathers from
    /// its chain of links with its own form factors, see [`solve::LeafOperator`]); when that would
    /// store more than `leaf_operator_max_entries` coefficients, one gather pass is done instead.
    pub final_gather: bool,
    /// Budget of the leaf-resolution operator (coefficients, 12 bytes each).
    pub leaf_operator_max_entries: usize,
    /// Estimate the solution's error after the solve ([`Solved::error_estimate`]); costs a
    /// full-resolution gather at sampled leaves, which dominates small solves.
    pub estimate_error: bool,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            build: BuildConfig::default(),
            visibility: VisibilityConfig::default(),
            solve: SolveConfig::default(),
            max_passes: 3,
            use_visibility: true,
            analyse: true,
            visibility_method: VisibilityMethod::Rays,
            final_gather: true,
            leaf_operator_max_entries: solve::LEAF_OPERATOR_MAX_ENTRIES,
            estimate_error: true,
        }
    }
}

/// How link visibility is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisibilityMethod {
    /// Rays against a BVH of every input triangle.
    Rays,
    /// Shaft culling with the given bounding volumes: a link whose shaft one occluder blocks is
    /// invisible and one whose shaft nothing enters is visible, both without a ray; other links cast
    /// rays against the shaft's candidate occluders (or, for long lists, through the BVH); a
    /// link's candidates are searched among those of the link it was subdivided from.
    Shafts(crate::visibility::shaft::BoundingVolume),
}

impl VisibilityMethod {
    /// Every method.
    pub const ALL: [VisibilityMethod; 4] = {
        use crate::visibility::shaft::BoundingVolume::{Aabb, Hull, Obb};
        [VisibilityMethod::Rays, VisibilityMethod::Shafts(Aabb), VisibilityMethod::Shafts(Obb), VisibilityMethod::Shafts(Hull)]
    };

    /// The method's name, as the command line and `stats.json` spell it.
    #[must_use]
    pub fn name(self) -> &'static str {
        use crate::visibility::shaft::BoundingVolume::{Aabb, Hull, Obb};
        match self {
            VisibilityMethod::Rays => "rays",
            VisibilityMethod::Shafts(Aabb) => "aabb",
            VisibilityMethod::Shafts(Obb) => "obb",
            VisibilityMethod::Shafts(Hull) => "hull",
        }
    }

    /// The method called `name` (see [`VisibilityMethod::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<VisibilityMethod> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// Seconds spent per phase.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Timings {
    /// Building clusters and the ray-casting BVH.
    pub build: f64,
    /// Refinement (oracle calls, form factors, visibility).
    pub refine: f64,
    /// Linear solves.
    pub solve: f64,
}

/// Progress events for front ends.
#[derive(Clone, Copy, Debug)]
pub enum Progress {
    /// Refinement pass `pass`: `links` kept so far, `pending` candidates.
    Refine {
        /// Pass number from 1.
        pass: usize,
        /// Links so far.
        links: u64,
        /// Candidates waiting.
        pending: u64,
    },
    /// The leaf-resolution operator is being built with this many coefficients.
    LeafSolve {
        /// Stored (leaf, link) coefficients.
        entries: usize,
    },
    /// A solve finished.
    Solved {
        /// Pass number from 1.
        pass: usize,
        /// Operator applications.
        iterations: usize,
        /// Relative residual.
        residual: f64,
    },
}

/// The result of [`run`].
pub struct Solved {
    /// The element hierarchy.
    pub hierarchy: Hierarchy,
    /// Final links.
    pub links: Vec<Link>,
    /// Final solution.
    pub solution: Solution,
    /// Ray caster (for rendering), when visibility was used or requested.
    pub caster: RayCaster,
    /// Refinement counters summed over passes.
    pub refine_stats: RefineStats,
    /// Rays cast during refinement.
    pub rays: u64,
    /// Refine → solve rounds done.
    pub passes: usize,
    /// Coefficients of the leaf-resolution operator (0 when it was not used).
    pub leaf_entries: usize,
    /// Links that shaft culling classified [invisible, visible] without casting a ray.
    pub shaft_classified: [u64; 2],
    /// What the scene needs, when analysed.
    pub traits: Option<SceneTraits>,
    /// Machinery left out for this scene, in words.
    pub left_out: Vec<String>,
    /// A-posteriori error estimate, relative to the largest leaf radiosity: the one-step residual
    /// against a full-resolution gather at sampled leaves (see [`solve::error_estimate`]); `None`
    /// when [`Config::estimate_error`] is off.
    pub error_estimate: Option<f64>,
    /// Operator applications summed over passes.
    pub iterations: usize,
    /// Time per phase.
    pub timings: Timings,
}

/// Solves `scene` with `oracle`.
pub fn run(scene: &Scene, oracle: &dyn Oracle, config: &Config, progress: &dyn Fn(Progress)) -> Solved {
    let t0 = Instant::now();
    let traits = config.analyse.then(|| SceneTraits::of(scene));
    let left_out = traits.as_ref().map(SceneTraits::left_out).unwrap_or_default();
    let use_visibility = config.use_visibility && traits.as_ref().is_none_or(|t| t.needs_visibility);
    let mut h = hierarchy::build(scene, &config.build);
    let caster = RayCaster::new(scene);
    let shaft_objects = match effective_visibility(oracle, config.visibility_method) {
        VisibilityMethod::Shafts(volume) if use_visibility => Some(crate::visibility::shaft::ShaftObjects::new(
            scene,
            &crate::visibility::shaft::ObjectConfig { volume, ..Default::default() },
        )),
        _ => None,
    };
    let (shaft_rays, shaft_invisible, shaft_visible) = (AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0));
    let shafts = shaft_objects.as_ref().map(|objects| refine::ShaftServices {
        objects,
        rays: &shaft_rays,
        invisible: &shaft_invisible,
        visible: &shaft_visible,
    });
    let mut timings = Timings { build: t0.elapsed().as_secs_f64(), ..Timings::default() };

    let mut radiosity = initial_radiosity(&h);
    // Thresholds are relative to the brightest radiosity expected (emission plus the closed-scene
    // ambient estimate), so the same eps means the same relative accuracy in a dim room and in a
    // stiff enclosure where B is 1/(1−ρ) times the emission.
    let b_ref = radiosity.iter().flat_map(|e| e.iter().copied()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let mut links = Vec::new();
    let mut stats = RefineStats::default();
    let mut solution = None;
    let mut passes = 0;
    let mut iterations = 0;
    for pass in 1..=config.max_passes.max(1) {
        let t = Instant::now();
        let (new_links, s) = refine::refine(
            &mut h,
            use_visibility.then_some(&caster),
            config.visibility,
            oracle,
            links,
            &mut radiosity,
            b_ref,
            shafts,
            &|l, p| progress(Progress::Refine { pass, links: l, pending: p }),
        );
        links = new_links;
        timings.refine += t.elapsed().as_secs_f64();
        stats.oracle_calls += s.oracle_calls;
        stats.form_factors += s.form_factors;
        stats.subdivided += s.subdivided;
        stats.dropped += s.dropped;
        stats.links = s.links;
        passes = pass;
        if pass > 1 && s.subdivided == 0 {
            break;
        }
        let t = Instant::now();
        let sol = solve::solve(&h, &links, &radiosity, &config.solve);
        timings.solve += t.elapsed().as_secs_f64();
        iterations += sol.iterations;
        progress(Progress::Solved { pass, iterations: sol.iterations, residual: sol.residual });
        radiosity.clone_from(&sol.radiosity);
        solution = Some(sol);
    }
    let solution = solution.expect("at least one pass solves");
    let t = Instant::now();
    let (solution, more_iterations, leaf_entries) = finish_solve(&h, &links, solution, config, progress, passes, &mut None);
    iterations += more_iterations;
    timings.solve += t.elapsed().as_secs_f64();
    let error_estimate = config.estimate_error.then(|| solve::error_estimate(&h, &links, &solution.radiosity, &solution.irradiance));
    let rays = caster.rays_cast() + shaft_rays.load(Ordering::Relaxed);
    let shaft_classified = [shaft_invisible.load(Ordering::Relaxed), shaft_visible.load(Ordering::Relaxed)];
    Solved {
        hierarchy: h,
        links,
        solution,
        caster,
        refine_stats: stats,
        rays,
        passes,
        leaf_entries,
        shaft_classified,
        traits,
        left_out,
        error_estimate,
        iterations,
        timings,
    }
}

/// The visibility method a solve with `oracle` uses: `requested`, except that an oracle that needs
/// shafts ([`crate::refine::Needs::shafts`]) gets OBB shafts where plain rays were requested.
#[must_use]
pub fn effective_visibility(oracle: &dyn Oracle, requested: VisibilityMethod) -> VisibilityMethod {
    if oracle.needs().shafts && requested == VisibilityMethod::Rays {
        VisibilityMethod::Shafts(crate::visibility::shaft::BoundingVolume::Obb)
    } else {
        requested
    }
}

/// Solves the radiosity system of links already refined, with the emission now in `h` (a level of
/// the instanced solver reuses one refinement for every instance of a prototype): the
/// hierarchical solve, then the leaf-resolution solve or gather of [`Config::final_gather`]. `leaf`
/// keeps the leaf-resolution coefficients between calls for the same hierarchy and links (computed
/// at the first call when within [`Config::leaf_operator_max_entries`]). Returns the solution, the
/// iterations and the leaf-operator entries (0 when gathered).
#[must_use]
pub fn solve_links(h: &Hierarchy, links: &[Link], leaf: &mut Option<solve::LeafCoefficients>, config: &Config) -> (Solution, usize, usize) {
    let sol = solve::solve(h, links, &initial_radiosity(h), &config.solve);
    let first = sol.iterations;
    let (sol, more, entries) = finish_solve(h, links, sol, config, &|_| {}, 1, leaf);
    (sol, first + more, entries)
}

/// The final gather step after the hierarchical solve, with the leaf-resolution coefficients of
/// `leaf` (computed and kept there when absent and within budget): `(solution, iterations, leaf
/// entries)`.
fn finish_solve(
    h: &Hierarchy,
    links: &[Link],
    mut solution: Solution,
    config: &Config,
    progress: &dyn Fn(Progress),
    passes: usize,
    leaf: &mut Option<solve::LeafCoefficients>,
) -> (Solution, usize, usize) {
    if !config.final_gather {
        return (solution, 0, 0);
    }
    if leaf.is_none() {
        let entries = solve::leaf_operator_entries(h, links);
        if entries <= config.leaf_operator_max_entries {
            progress(Progress::LeafSolve { entries });
            *leaf = Some(solve::LeafCoefficients::new(h, links));
        }
    }
    match leaf {
        Some(coefficients) => {
            let op = solve::LeafOperator::new(h, links, coefficients);
            let sol = solve::solve_leaf_operator(&op, &solution.radiosity, &config.solve);
            progress(Progress::Solved { pass: passes + 1, iterations: sol.iterations, residual: sol.residual });
            let iterations = sol.iterations;
            (sol, iterations, coefficients.entries())
        }
        None => {
            let (b, irr) = solve::final_gather(h, links, &solution.radiosity);
            solution.radiosity = b;
            solution.irradiance = irr;
            (solution, 0, 0)
        }
    }
}

/// First guess for the energy criteria: emission plus a uniform ambient term (the closed-scene
/// estimate `Φ / (A (1 − ρ̄))`), reflected by each polygon.
fn initial_radiosity(h: &Hierarchy) -> Vec<[f64; 3]> {
    let n = h.n_polygons as usize;
    let mut power = [0.0; 3];
    let mut area = 0.0;
    let mut rho_area = [0.0; 3];
    for p in 0..n {
        let a = h.get(p as u32).area;
        area += a;
        for c in 0..3 {
            power[c] += a * h.emission[p][c];
            rho_area[c] += a * h.reflectance[p][c];
        }
    }
    let ambient: [f64; 3] = std::array::from_fn(|c| if area > 0.0 { power[c] / area / (1.0 - rho_area[c] / area).max(1e-3) } else { 0.0 });
    let mut b = vec![[0.0; 3]; h.len()];
    for p in 0..n {
        b[p] = std::array::from_fn(|c| h.emission[p][c] + h.reflectance[p][c] * ambient[c]);
    }
    // Clusters: area-weighted means, children before parents. The build reserves a cluster's slot
    // before building its children (pre-order), so every descendant of a cluster has a larger id:
    // going down the ids reaches the children first.
    for e in (n..h.len()).rev() {
        let el = h.get(e as u32);
        if el.is_cluster() {
            let mut acc = [0.0; 3];
            for &k in h.children_of(e as u32) {
                let a = h.get(k).area;
                for c in 0..3 {
                    acc[c] += a * b[k as usize][c];
                }
            }
            b[e] = acc.map(|v| if el.area > 0.0 { v / el.area } else { 0.0 });
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visibility_methods_are_found_by_their_names() {
        let names: Vec<&str> = VisibilityMethod::ALL.iter().map(|m| m.name()).collect();
        assert_eq!(names, ["rays", "aabb", "obb", "hull"]);
        for m in VisibilityMethod::ALL {
            assert_eq!(VisibilityMethod::from_name(m.name()), Some(m));
        }
        assert_eq!(VisibilityMethod::from_name("bvh"), None);
    }

    /// Every cluster's first guess is the area-weighted mean of its polygons' (a cluster's children
    /// are built after it, so a pass in id order would average children not yet set).
    #[test]
    fn initial_radiosity_of_clusters_is_the_mean_of_their_polygons() {
        let scene = crate::scene::cornell_box();
        let h = hierarchy::build(&scene, &hierarchy::BuildConfig { max_leaf_polygons: 2, ..Default::default() });
        let b = initial_radiosity(&h);
        let mut clusters = 0;
        for e in 0..h.len() as u32 {
            let crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } = h.get(e).kind else { continue };
            let members = &h.cluster_polygons[poly_start as usize..poly_end as usize];
            let area: f64 = members.iter().map(|&p| h.get(p).area).sum();
            for c in 0..3 {
                let mean = members.iter().map(|&p| h.get(p).area * b[p as usize][c]).sum::<f64>() / area;
                assert!((b[e as usize][c] - mean).abs() <= 1e-12 * mean.abs().max(1e-300), "cluster {e}: {} vs {mean}", b[e as usize][c]);
            }
            clusters += 1;
        }
        assert!(clusters > 3 && h.get(h.root).is_cluster(), "the test needs nested clusters");
        let top = b[h.root as usize];
        assert!(top.iter().all(|&x| x > 0.0), "the root of a lit scene has a positive first guess: {top:?}");
    }
}
