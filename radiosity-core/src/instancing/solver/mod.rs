//! The instanced solver: a chain of small hierarchical radiosity problems solved depth-first.
//!
//! At one level the local problem holds the level's own polygons and one proxy per closed instance;
//! below the top, the light that arrived at the instance is held fixed:
//! - a closed instance is a proxy box: its prototype's box shrunk about its centre by
//!   `√(1 − τ̄)` (so that its projected area is the mean effective area ā = (1 − τ̄)·Ā_box), with the
//!   prototype's mean escape albedo as reflectance; it blocks, absorbs and reflects like the
//!   prototype on average over directions and takes no self-link (a box face sees no other face);
//! - directional proxies ([`ProxyEmission::Directional`], the default): the light a box intercepts
//!   through one face leaves through each face in the fraction its prototype's face transfer
//!   matrix gives ([`crate::instancing::face_transfer`], measured with the albedo), not all back
//!   through the face it entered: a crown lit from above also shines down through its leaves.
//!   Each face reflects with the matrix's diagonal; what the other faces send out through it is
//!   its emission (`directional`);
//! - opening an instance: the links that arrived at its proxy (at a face, below it, or at a cluster
//!   holding it) are sorted by the direction toward their source into [`LIGHT_DIRECTIONS`] bins, and
//!   each face's irradiance is split over the bins in those proportions; the flux per bin over the
//!   proxy's projected area in that direction is a field of parallel beams (a distant-light
//!   model). Every polygon of the opened level gathers the beams where its level's visibility
//!   table ([`TABLE_DIRECTIONS`] directions × [`TABLE_RAYS`] rays per polygon, cast once per level)
//!   says the beam's direction leaves the level unblocked (and, per instance, where it misses the
//!   polygons of the levels above that cross the instance's box, [`MAX_INHERITED_OCCLUDERS`] at
//!   most: a trunk through a branch's box), and reflects the result once as its
//!   emission. The local problem is then refined and solved with that outside held fixed (its root
//!   self-link is the local interreflection), its own polygons are streamed to the sink, and its
//!   hierarchy is dropped (or cached, below) before its sub-instances are opened in turn; the beams
//!   that reach a sub-instance's proxy are passed on to it bin by bin.
//! - direct light (visibility through instances): the part of each field that came straight from
//!   the top level's emitters is tracked apart (at the top, a link's share `E_source / B_source`;
//!   below, the direct beams that reach a proxy). Proxy faces still receive it as beams, but every
//!   own polygon below the top gets it ray traced instead, from
//!   [`InstancedConfig::direct_samples`] point pairs per emitter, through
//!   [`super::InstanceCaster`]: one BVH per prototype over its triangles and its instances' boxes,
//!   shared by all its instances, so each ray is blocked by every instance's own geometry (the
//!   other branches of a crown), not by the instance's average visibility. The brightness class
//!   (below) bounds the traced light too.
//! - daylight ([`InstancedConfig::daylight`]: the sun and the sky's cells as distant sources):
//!   every own polygon, at the top and in every opened instance, gets it ray traced from its
//!   place in the scene through the same nested BVHs (a beam is seen where a ray against it leaves
//!   the scene); the top level's proxies get it as beams (the top level's own visibility) and hand
//!   it on as direct light, so that below the top only the interreflected light travels in the
//!   beams. See `daylight`.
//!
//! Reuse: the refinement of a level (hierarchy, links, leaf-resolution coefficients, visibility
//! table) depends on its geometry and, through the BF criterion, on how bright its light is; it is
//! kept, within [`InstancedConfig::level_cache_bytes`], for the later instances of the same
//! prototype that lie a similarity away (rotation, uniform scale, translation) and whose light is
//! of the same brightness class (`brightness_class`: a factor of two); the level is refined for the top of its
//! class, and each such instance only solves the linear system for its own light. Form factors and
//! visibility are invariant under a similarity, so a reused level is the level that would be
//! refined for the class's top light, exactly; beams are turned into the level's frame.
//!
//! Instances whose flattened polygon count exceeds [`InstancedConfig::max_closed_polygons`] are
//! opened in place (their content joins the current level): the policy that keeps property
//! computation and every local problem bounded. So are instances nearer to an emitter of their level
//! than [`InstancedConfig::open_near_emitter`] times their size, where parallel beams would miss
//! how much brighter their near side is. Memory is bounded by the largest local problem, plus the
//! level cache's budget, plus one field ([`LIGHT_DIRECTIONS`] RGB values, and the few bins of its
//! direct part) per pending instance, plus one BVH per prototype (built once the top level is
//! freed); the flattened scene is never built.
//!
//! # Layout
//! One file per step an instance goes through, in the order [`solve_instanced`] takes them:
//! `task` (the stack of instances to open; the level each gathers), `occluders` (the polygons
//! above that cross a closed instance's box), `proxy` (closed instances' boxes from their
//! properties), `direct` (the traced direct light), `daylight` (the sun and the sky), `cache` (brightness class, similarity and
//! the level cache), `level` (building, refining and solving a local problem), `outside` (the
//! beams from outside and the visibility table), `sink` (streaming the finished polygons),
//! `handoff` (the light passed on to the closed instances), `directional` (the proxies' light
//! sent out through other faces than it entered). `config` holds the settings and
//! figures, `reference` the full solve and the error measures it is compared by.

mod cache;
mod config;
mod daylight;
mod direct;
mod directional;
pub mod distributed;
mod handoff;
mod level;
mod occluders;
mod outside;
mod proxy;
mod reference;
mod sink;
mod sky_sample;
mod task;

pub use cache::SIMILARITY_TOLERANCE;
pub use config::{InstanceLevels, InstancedConfig, InstancedStats, LevelReuse, ProxyEmission};
pub use daylight::{SKY_MAX_CELLS, SKY_RAYS_DIVISOR, TOP_MAX_POINTS, TOP_POINT_AREA_REL, brightest as daylight_brightest};
pub use occluders::MAX_INHERITED_OCCLUDERS;
pub use outside::{FIELD_REL_MIN, LIGHT_DIRECTIONS, TABLE_DIRECTIONS, TABLE_RAYS};
pub use proxy::{MAX_PROXY_REFLECTANCE, MIN_PROXY_EXTENT_REL};
pub use reference::{polygons_above, relative_error, solve_full};
pub use sink::{Leaf, PolygonInfo, PolygonMeans, RadiositySink, leaf_means};

use crate::geom::Poly;
use crate::instancing::InstancingError;
use crate::instancing::model::{InstancedScene, PrototypeId, Transform};
use crate::instancing::properties::{PropertyCache, content_hashes};
use cache::{LevelCache, light_class};
use direct::{build_caster, direct_split, top_emitters};
use distributed::{Alone, Driver};
use handoff::{child_fields, push_children};
use level::{Level, build_level, solve_level};
use occluders::{Occluders, child_occluders};
use outside::{OutsideLight, light_directions, light_in_level};
use proxy::{Proxy, ensure_proxies};
use sink::stream_own;
use std::collections::HashMap;
use task::{Gathered, Task, gather_level};

/// Solves `scene` depth-first with instances (see the module docs), streaming every finished
/// flattened polygon to `sink`.
pub fn solve_instanced(
    scene: &InstancedScene,
    config: &InstancedConfig,
    sink: &mut dyn RadiositySink,
) -> Result<InstancedStats, InstancingError> {
    // Run on a worker of the thread pool: the many small parallel loops of the local problems then
    // start on this thread and are shared by work stealing, instead of each being handed to the
    // pool and waited for (a futex round trip per loop, which dominated small levels).
    rayon::scope(|_| solve_depth_first(scene, config, &mut Alone::new(sink, config.level_reuse)))
}

/// The depth-first solve: per task (an instance to open, the scene first), gather its level, get
/// the closed instances' proxies, split off the direct light, find or build the level, take the
/// light from outside into it, solve, stream its own polygons, and hand the light that reached
/// each proxy on to the instance as a new task. The `driver` holds the sink, and may take the top
/// level's instances once it is solved and hand them back one at a time (see [`distributed`]).
fn solve_depth_first(scene: &InstancedScene, config: &InstancedConfig, driver: &mut dyn Driver) -> Result<InstancedStats, InstancingError> {
    let t0 = std::time::Instant::now();
    scene.validate()?;
    let counts = scene.flattened_counts(true);
    let bounds = scene.local_bounds();
    let hashes = content_hashes(scene);
    let cache = config.cache_dir.as_deref().map(PropertyCache::new);
    let mut proxies: HashMap<PrototypeId, Proxy> = HashMap::new();
    let mut stats = InstancedStats::default();
    let mut stack = vec![Task {
        prototype: scene.root,
        transform: Transform::IDENTITY,
        flat_base: 0,
        depth: 0,
        incoming: None,
        direct: Vec::new(),
        occluders: Occluders::default(),
    }];
    if !driver.starts_at_top() {
        stack.clear();
    }
    // Direct light: the top level's emitters (scene frame) and the caster that sees every
    // instance's own geometry, built after the top level (the largest local problem) is freed.
    let tracing = config.direct_samples > 0;
    let mut caster: Option<crate::instancing::InstanceCaster> = None;
    let mut direct_emitters: Vec<(Poly, [f64; 3])> = Vec::new();
    // Every local BF threshold stays relative to the scene's largest emission (see `build_level`).
    // Under daylight, relative to the brightest radiosity it can give a surface.
    let b_ref_scene =
        scene.materials.iter().flat_map(|m| m.emission).fold(0.0, f64::max).max(daylight::brightest(&scene.materials, &config.daylight));
    let diag = bounds[scene.root as usize].diagonal();
    // The smallest element is as large in every local problem as in the flattened solve (its
    // relative minimum times the whole scene's area), not relative to the small area of a twig,
    // which let a twig's leaves split ten thousand times finer than the full solve splits them.
    let min_area = config.pipeline.build.min_area_rel * scene.flattened_areas(true)[scene.root as usize];
    let dirs = light_directions();
    let mut levels = LevelCache::new(config.level_cache_bytes);
    loop {
        // When the stack runs empty, the driver may hand out the next top-level instance (with
        // `LevelReuse::Subtree`, each starts with an empty level cache).
        let task = match stack.pop() {
            Some(task) => task,
            None => match driver.next(&mut direct_emitters)? {
                Some(task) => {
                    if config.level_reuse == LevelReuse::Subtree {
                        levels.clear();
                    }
                    task
                }
                None => break,
            },
        };
        let at_top = task.incoming.is_none();
        let Gathered { own, closed, inlined } = gather_level(scene, config, &counts, &bounds, &task);
        if task.incoming.is_none() && tracing {
            direct_emitters = top_emitters(scene, &own);
        }
        // Daylight is traced from the top level down: the caster is needed from the start.
        if !config.daylight.is_empty() && caster.is_none() {
            caster = Some(build_caster(scene, config.trace));
        }
        let top_daylight = match (&caster, task.incoming.is_none() && !config.daylight.is_empty()) {
            (Some(c), true) => Some(daylight::TopDaylight {
                traced: daylight::traced_daylight(scene, &own, task.flat_base, &config.daylight, c, (config.direct_samples, true), diag),
                sources: &config.daylight,
                samples: config.direct_samples,
                tracked: tracing,
            }),
            _ => None,
        };
        let child_occluders = child_occluders(&own, &task.occluders, &closed, &bounds);
        ensure_proxies(scene, &bounds, &hashes, cache.as_ref(), &closed, &mut proxies, &mut stats, &config.properties)?;

        // The level: reused from an earlier instance of the same prototype whose light was of the
        // same brightness class and which lies a similarity (rigid motion and uniform scale)
        // away, else built, refined and (below the top) cached.
        let t_local = std::time::Instant::now();
        // Below the top, the light straight from the top level's emitters is split off the field
        // and ray traced to every own polygon (see `InstancedConfig::direct_samples`).
        if tracing && task.incoming.is_some() && caster.is_none() {
            caster = Some(build_caster(scene, config.trace));
        }
        let mut split = direct_split(scene, &task, &own, &direct_emitters, caster.as_ref().filter(|_| tracing), config.direct_samples);
        if let (Some(split), Some(c)) = (&mut split, &caster)
            && !config.daylight.is_empty()
        {
            let traced = daylight::traced_daylight(scene, &own, task.flat_base, &config.daylight, c, (config.direct_samples, false), diag);
            daylight::add_into(&mut split.traced, &traced);
        }
        let class = light_class(&dirs, task.incoming.as_deref(), split.as_ref());
        let key = (task.prototype, inlined, class.map_or(i32::MIN, |c| c.0));
        let reused = if class.is_some() { levels.find(&key, &task.transform.matrix) } else { None };
        let mut fresh = None;
        if reused.is_none() {
            let light = task.incoming.as_deref().zip(class).map(|(field, (_, raise))| OutsideLight {
                dirs: &dirs,
                field,
                split: split.as_ref(),
                raise,
            });
            let Some(level) =
                build_level(scene, &task, &own, &closed, &proxies, light, top_daylight.as_ref(), (b_ref_scene, min_area), config)?
            else {
                continue;
            };
            fresh = Some(level);
        }
        drop(own);
        let (level, similarity) = match (&mut fresh, reused) {
            (Some(level), _) => (level, None),
            (None, Some(similarity)) => (levels.get(&key), Some(similarity)),
            (None, None) => unreachable!("a level is built when none is reused"),
        };
        stats.max_local_polygons = stats.max_local_polygons.max(level.polys.len());

        let mut light = light_in_level(&dirs, similarity.as_ref(), &task, level, split.as_ref());
        if let Some(daylight) = level.daylight.take() {
            light = daylight;
        }
        let solution = solve_level(level, &light.external, config);
        if config.trace {
            trace_solve(&stats, &scene.prototype(task.prototype).name, level, closed.len(), similarity.is_some(), t_local);
        }
        count_solve(&mut stats, level, similarity.is_some());
        let face_irradiance =
            stream_own(level, &solution, &light.external, similarity.as_ref(), task.flat_base, driver.sink(), &mut stats)?;
        let handoff = child_fields(level, &solution, &light, &face_irradiance, closed.len(), tracing && task.incoming.is_none());
        drop(solution);
        if let Some(level) = fresh
            && class.is_some()
        {
            levels.insert(key, level, task.transform.matrix);
        }
        push_children(&mut stack, &closed, handoff, child_occluders);
        if at_top {
            driver.top_level_done(&mut stack, &direct_emitters)?;
        }
    }
    stats.levels_cached_peak_bytes = levels.peak_bytes as u64;
    stats.seconds = t0.elapsed().as_secs_f64();
    Ok(stats)
}

/// Prints the line of a local solve just solved (the `trace` setting).
fn trace_solve(stats: &InstancedStats, name: &str, level: &Level, n_closed: usize, reused: bool, t_local: std::time::Instant) {
    eprintln!(
        "local solve {}: `{}` {} polygons ({} proxies), {} elements, {} links, {} iterations, {}, {:.3}s, peak RSS {:.1} MB",
        stats.local_solves + 1,
        name,
        level.polys.len(),
        n_closed,
        level.h.len(),
        level.links.len(),
        level.iterations,
        if reused { "reused" } else { "refined" },
        t_local.elapsed().as_secs_f64(),
        crate::output::peak_rss_bytes().unwrap_or(0) as f64 / 1e6
    );
}

/// Counts a local solve in `stats`.
fn count_solve(stats: &mut InstancedStats, level: &Level, reused: bool) {
    stats.local_solves += 1;
    stats.levels_reused += u64::from(reused);
    stats.links += level.links.len() as u64;
    stats.max_local_links = stats.max_local_links.max(level.links.len() as u64);
}
