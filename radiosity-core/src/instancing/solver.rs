//! The instanced solver: a chain of small hierarchical radiosity problems solved depth-first.
//!
//! At one level the local problem holds the level's own polygons and one proxy per closed instance;
//! below the top, the light that arrived at the instance is held fixed:
//! - a closed instance is a proxy box: its prototype's box shrunk about its centre by
//!   `√(1 − τ̄)` (so that its projected area is the mean effective area ā = (1 − τ̄)·Ā_box), with the
//!   prototype's mean escape albedo as reflectance; it blocks, absorbs and reflects like the
//!   prototype on average over directions and takes no self-link (a box face sees no other face);
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

use super::InstancingError;
use super::flatten::{FlattenOptions, reversed};
use super::model::{InstancedScene, PrototypeId, Transform};
use super::properties::{CacheOutcome, PropertyCache, PropertyConfig, RadiativeProperties, content_hashes};
use crate::geom::{Aabb, DVec3, Poly};
use crate::hierarchy::{ElementId, Hierarchy};
use crate::pipeline;
use crate::refine::{BfParams, ClassicBf, Link, first_guess_max};
use crate::scene::{Material, SceneBuilder, shapes::box_faces};
use crate::solve::Solution;
use glam::{DMat3, DMat4};
use std::collections::HashMap;
use std::path::PathBuf;

/// Largest reflectance given to a proxy (the builder requires ρ < 1).
pub const MAX_PROXY_REFLECTANCE: f64 = 0.99;

/// Smallest extent of a proxy box on any axis, relative to its diagonal (flat prototypes such as a
/// single leaf still get a box with six faces of positive area).
pub const MIN_PROXY_EXTENT_REL: f64 = 1e-3;

/// Settings of [`solve_instanced`].
#[derive(Clone, Debug)]
pub struct InstancedConfig {
    /// Settings of every local solve.
    pub pipeline: pipeline::Config,
    /// BF oracle parameters of every local solve.
    pub bf: BfParams,
    /// Sampling of the prototypes' properties.
    pub properties: PropertyConfig,
    /// Folder of the property cache; `None` computes properties in memory only.
    pub cache_dir: Option<PathBuf>,
    /// Instances of prototypes with more flattened polygons than this are opened in place.
    pub max_closed_polygons: u64,
    /// Print one line per local solve to standard error.
    pub trace: bool,
    /// Linear solver of every local solve (and of [`solve_full`], for a like-for-like comparison):
    /// a short GMRES restart bounds the Krylov basis, which is the largest allocation of a local
    /// problem (one vector of all elements per iteration), and a relative residual of 1e-7 is far
    /// below the method's approximation error.
    pub local_solve: crate::solve::SolveConfig,
    /// Budget of a local problem's leaf-resolution operator (coefficients of 12 bytes); a larger
    /// problem (the top level of a forest) does one leaf-level gather pass instead. It caps the
    /// second-largest allocation of a local problem.
    pub local_leaf_operator_max_entries: usize,
    /// An instance whose box lies nearer to an emitter of its level than this many times its own
    /// diagonal is opened in place: a closed instance receives the light as parallel beams, which
    /// misses how much brighter its near side is under a close light.
    pub open_near_emitter: f64,
    /// Which nesting depths keep their instances closed (the rest are opened in place).
    pub instance_levels: InstanceLevels,
    /// Instances too close to each other are opened in place: one whose box shares more than
    /// this fraction of the smaller box's volume with a sibling's (two proxies would interpenetrate
    /// and block each other's light twice). 1 or more disables the rule, the default: on the age-30
    /// tree at eps 0.05 it made the answer no closer to the full solve (0.9: max error 5.62%
    /// against 5.54%, mean 0.169% against 0.150%; 0.5: 5.89%, and 58 MB instead of 20 MB).
    pub open_overlap: f64,
    /// Point pairs per (polygon, emitter) from which the light that every polygon below the top
    /// level receives straight from the top level's emitters is ray traced through the nested
    /// per-prototype BVHs ([`super::InstanceCaster`]: every instance blocks with its own geometry),
    /// instead of arriving with the parallel beams, whose visibility is the instance's average.
    /// 0 leaves all light to the beams.
    pub direct_samples: u32,
    /// Budget (approximate bytes) of the levels kept for reuse: a level lit from outside is
    /// refined once and reused, solve only, for every later instance of its prototype that lies a
    /// similarity away and whose light is no brighter (see [`solve_instanced`]). 0 disables reuse.
    pub level_cache_bytes: usize,
}

impl Default for InstancedConfig {
    fn default() -> Self {
        InstancedConfig {
            pipeline: pipeline::Config::default(),
            bf: BfParams::default(),
            properties: PropertyConfig::default(),
            cache_dir: None,
            max_closed_polygons: 20_000,
            trace: false,
            local_solve: crate::solve::SolveConfig { tolerance: 1e-7, max_iterations: 2000, restart: 10 },
            local_leaf_operator_max_entries: 250_000,
            open_near_emitter: 1.0,
            level_cache_bytes: 16_000_000,
            instance_levels: InstanceLevels::All,
            open_overlap: 1.0,
            direct_samples: 16,
        }
    }
}

/// The levels to instance: which nesting depths (the scene's own instances are depth 1, theirs 2,
/// ...) are solved as closed instances; instances at other depths are opened in place, their
/// content joining the level above (larger local problems, fewer approximations).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum InstanceLevels {
    /// Every depth.
    #[default]
    All,
    /// Depths that are multiples of `n` (`Every(2)`: 2, 4, ...; `Every(1)` is [`InstanceLevels::All`]).
    Every(u32),
    /// None: the whole scene is one local problem (the flattened solve, streamed).
    None,
}

impl InstanceLevels {
    /// Are instances at nesting depth `depth` (≥ 1) closed?
    #[must_use]
    pub fn closes(self, depth: u32) -> bool {
        match self {
            InstanceLevels::All => true,
            InstanceLevels::Every(n) => n > 0 && depth.is_multiple_of(n),
            InstanceLevels::None => false,
        }
    }
}

impl std::str::FromStr for InstanceLevels {
    type Err = String;
    fn from_str(s: &str) -> Result<InstanceLevels, String> {
        match s {
            "all" => Ok(InstanceLevels::All),
            "none" => Ok(InstanceLevels::None),
            _ => match s.strip_prefix("every-").and_then(|n| n.parse::<u32>().ok()) {
                Some(n) if n >= 1 => Ok(InstanceLevels::Every(n)),
                _ => Err(format!("`{s}` is not a level policy (all, none, every-N with N ≥ 1)")),
            },
        }
    }
}

/// Figures of one instanced solve.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct InstancedStats {
    /// Local problems solved.
    pub local_solves: u64,
    /// Flattened polygons streamed to the sink.
    pub polygons_out: u64,
    /// Leaf elements streamed.
    pub leaves_out: u64,
    /// Links summed over local problems.
    pub links: u64,
    /// Most input polygons in one local problem (own + proxy faces).
    pub max_local_polygons: usize,
    /// Most links in one local problem.
    pub max_local_links: u64,
    /// Prototype properties read from the cache.
    pub cache_hits: u64,
    /// Prototype properties computed.
    pub cache_computed: u64,
    /// Local problems that reused the refinement of an earlier instance.
    pub levels_reused: u64,
    /// Most bytes (approximate) held by the level cache at once.
    pub levels_cached_peak_bytes: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// A finished leaf element of a streamed polygon.
#[derive(Clone, Copy, Debug)]
pub struct Leaf {
    /// The element's polygon (world coordinates).
    pub poly: Poly,
    /// Radiosity B (W/m², RGB).
    pub b: [f64; 3],
    /// Front-side irradiance H (W/m², RGB), light from outside an opened instance included.
    pub h: [f64; 3],
}

/// Which flattened polygon a streamed polygon is.
#[derive(Clone, Copy, Debug)]
pub struct PolygonInfo {
    /// Index in [`super::flatten()`] order with two-sided pairs.
    pub flat_index: u64,
    /// Scene material.
    pub material: u32,
    /// Prototype that holds the polygon.
    pub prototype: PrototypeId,
}

/// Receives finished polygons, in flattening order of each local problem (not globally sorted).
pub trait RadiositySink: Send {
    /// Polygon `info` finished, with its leaf elements.
    fn polygon(&mut self, info: &PolygonInfo, leaves: &[Leaf]) -> Result<(), InstancingError>;
}

/// Keeps the area-weighted mean radiosity of every flattened polygon (memory linear in the
/// polygons: for comparisons with the full solve, not for large scenes).
#[derive(Clone, Debug, Default)]
pub struct PolygonMeans {
    /// Mean radiosity by flattened index (zero until received).
    pub radiosity: Vec<[f64; 3]>,
    /// Area by flattened index.
    pub area: Vec<f64>,
}

impl RadiositySink for PolygonMeans {
    fn polygon(&mut self, info: &PolygonInfo, leaves: &[Leaf]) -> Result<(), InstancingError> {
        let i = info.flat_index as usize;
        if self.radiosity.len() <= i {
            self.radiosity.resize(i + 1, [0.0; 3]);
            self.area.resize(i + 1, 0.0);
        }
        let (area, b, _) = leaf_means(leaves);
        self.radiosity[i] = b;
        self.area[i] = area;
        Ok(())
    }
}

/// Total area and area-weighted mean radiosity and irradiance of a polygon's leaves.
#[must_use]
pub fn leaf_means(leaves: &[Leaf]) -> (f64, [f64; 3], [f64; 3]) {
    let (mut area, mut b, mut h) = (0.0, [0.0; 3], [0.0; 3]);
    for leaf in leaves {
        let a = leaf.poly.area();
        area += a;
        for c in 0..3 {
            b[c] += a * leaf.b[c];
            h[c] += a * leaf.h[c];
        }
    }
    let mean = |x: f64| if area > 0.0 { x / area } else { 0.0 };
    (area, b.map(mean), h.map(mean))
}

/// A closed instance's stand-in, per prototype.
#[derive(Clone, Copy, Debug)]
struct Proxy {
    /// Shrunk local box.
    shrunk: Aabb,
    /// Mean escape albedo.
    albedo: [f64; 3],
}

/// A polygon of a level's own: geometry (world), material, flattened index, prototype holding it.
type OwnPolygon = (Poly, u32, u64, PrototypeId);

/// An instance waiting to be opened.
struct Task {
    prototype: PrototypeId,
    transform: Transform,
    flat_base: u64,
    /// Nesting depth of the instance (the scene is 0, its instances 1, theirs 2, ...).
    depth: u32,
    /// The light that arrived at the instance: irradiance perpendicular to each direction of
    /// [`light_directions`] (a distant-light field); `None` at the top.
    incoming: Option<Vec<[f64; 3]>>,
    /// The part of `incoming` that came straight from the top level's emitters, per direction
    /// bin (the few bins that hold any): below the top, each polygon's own share of it is ray
    /// traced instead (see [`InstancedConfig::direct_samples`]); proxy faces keep the beams.
    direct: Vec<(u32, [f64; 3])>,
    /// Polygons of the levels above (scene frame) that cross the instance's box (a trunk through
    /// a branch's box): the beams from outside are tested against them too (see
    /// [`inherited_occluders`]).
    occluders: Occluders,
}

/// Polygons of the levels above that an instance's beams are tested against: indices into a pool
/// shared by the instance's siblings (their level's own polygons and its inherited occluders),
/// so that a level with a thousand closed instances around a trunk holds its polygons once.
#[derive(Clone, Default)]
struct Occluders {
    pool: Option<std::sync::Arc<[Poly]>>,
    index: Vec<u32>,
}

impl Occluders {
    fn iter(&self) -> impl Iterator<Item = &Poly> {
        self.pool.iter().flat_map(|pool| self.index.iter().map(move |&i| &pool[i as usize]))
    }
}

/// Most polygons of the levels above handed to an instance as occluders (the largest kept).
pub const MAX_INHERITED_OCCLUDERS: usize = 64;

/// The polygons of `pool` (scene frame) whose box meets `bx`, largest first, at most
/// [`MAX_INHERITED_OCCLUDERS`]. The polygons of a closed instance see only their own level's
/// geometry in its visibility table; a trunk passing through a branch's box, or leaves hugging it,
/// are otherwise lit as if it were not there (on the age-30 tree, crown-centre leaves next to the
/// trunk got ten times the light the full solve gives them).
fn inherited_occluders(pool: &[Poly], grid: &PoolGrid, bx: &Aabb) -> Vec<u32> {
    let mut index = grid.meeting(bx);
    if index.len() > MAX_INHERITED_OCCLUDERS {
        index.sort_by(|&a, &b| pool[b as usize].area().total_cmp(&pool[a as usize].area()));
        index.truncate(MAX_INHERITED_OCCLUDERS);
    }
    index
}

/// The instances' occluder lists (indices into `pool`) over one shared pool that keeps only the
/// polygons some list names (a forest's top level has 190,000 trunk polygons, of which the
/// pending instances name a few thousand); each list without spare capacity.
fn share_pool(pool: &[Poly], lists: &mut [Vec<u32>]) -> Vec<Occluders> {
    let mut remap = vec![u32::MAX; pool.len()];
    let mut kept: Vec<Poly> = Vec::new();
    for list in lists.iter_mut() {
        for i in list.iter_mut() {
            if remap[*i as usize] == u32::MAX {
                remap[*i as usize] = kept.len() as u32;
                kept.push(pool[*i as usize]);
            }
            *i = remap[*i as usize];
        }
    }
    let shared: std::sync::Arc<[Poly]> = kept.into();
    lists
        .iter_mut()
        .map(|list| {
            let mut index = std::mem::take(list);
            index.shrink_to_fit();
            Occluders { pool: (!index.is_empty()).then(|| shared.clone()), index }
        })
        .collect()
}

/// The boxes of a level's pool of occluders in a grid over x and y (CSR layout), so that finding
/// those that meet an instance's box does not scan the pool once per instance (a forest's top
/// level: 69,000 instances, 190,000 trunk polygons).
struct PoolGrid {
    boxes: Vec<Aabb>,
    lo: DVec3,
    cell: DVec3,
    n: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl PoolGrid {
    fn new(pool: &[Poly]) -> PoolGrid {
        let boxes: Vec<Aabb> = pool.iter().map(|p| Aabb::from_points(p.vertices())).collect();
        let mut all = Aabb::EMPTY;
        for b in &boxes {
            all.merge(b);
        }
        let n = ((boxes.len() as f64).sqrt().ceil() as usize).clamp(1, 256);
        let (lo, size) = if boxes.is_empty() { (DVec3::ZERO, DVec3::ONE) } else { (all.min, all.extent()) };
        let cell = (size / n as f64).max(DVec3::splat(f64::MIN_POSITIVE));
        let mut grid = PoolGrid { boxes, lo, cell, n, start: vec![0; n * n + 1], items: Vec::new() };
        for pass in 0..2 {
            let mut fill = grid.start.clone();
            for (i, b) in grid.boxes.iter().enumerate() {
                let ((x0, x1), (y0, y1)) = grid.span(b);
                for x in x0..=x1 {
                    for y in y0..=y1 {
                        let c = x * n + y;
                        if pass == 0 {
                            grid.start[c + 1] += 1;
                        } else {
                            grid.items[fill[c] as usize] = i as u32;
                            fill[c] += 1;
                        }
                    }
                }
            }
            if pass == 0 {
                for c in 0..n * n {
                    grid.start[c + 1] += grid.start[c];
                }
                grid.items = vec![0; grid.start[n * n] as usize];
            }
        }
        grid
    }

    /// Cells covered by `b` along x and y (clamped to the grid).
    fn span(&self, b: &Aabb) -> ((usize, usize), (usize, usize)) {
        let at = |v: f64, k: usize| (((v - self.lo[k]) / self.cell[k]).floor().max(0.0) as usize).min(self.n - 1);
        ((at(b.min.x, 0), at(b.max.x, 0)), (at(b.min.y, 1), at(b.max.y, 1)))
    }

    /// Indices of the pool's polygons whose box meets `bx`, ascending.
    fn meeting(&self, bx: &Aabb) -> Vec<u32> {
        let mut found = Vec::new();
        if self.boxes.is_empty() {
            return found;
        }
        let ((x0, x1), (y0, y1)) = self.span(bx);
        for x in x0..=x1 {
            for y in y0..=y1 {
                let c = x * self.n + y;
                for &i in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
                    let b = &self.boxes[i as usize];
                    if (0..3).all(|k| b.min[k] <= bx.max[k] && b.max[k] >= bx.min[k]) {
                        found.push(i);
                    }
                }
            }
        }
        found.sort_unstable();
        found.dedup();
        found
    }
}

/// What a polygon of a local problem stands for.
#[derive(Clone, Copy)]
enum Role {
    Own(PolygonInfo),
    ProxyFace { slot: usize },
}

/// Is polygon `i` of a level with `roles` a proxy face? (False past the end.)
fn is_proxy(roles: &[Role], i: usize) -> bool {
    matches!(roles.get(i), Some(Role::ProxyFace { .. }))
}

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
    rayon::scope(|_| solve_depth_first(scene, config, sink))
}

fn solve_depth_first(
    scene: &InstancedScene,
    config: &InstancedConfig,
    sink: &mut dyn RadiositySink,
) -> Result<InstancedStats, InstancingError> {
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
    // Direct light: the top level's emitters (scene frame) and the caster that sees every
    // instance's own geometry, built after the top level (the largest local problem) is freed.
    let tracing = config.direct_samples > 0;
    let mut caster: Option<super::InstanceCaster> = None;
    let mut direct_emitters: Vec<(Poly, [f64; 3])> = Vec::new();
    // Every local BF threshold stays relative to the scene's largest emission (see `build_level`).
    let b_ref_scene = scene.materials.iter().flat_map(|m| m.emission).fold(0.0, f64::max);
    // The smallest element is as large in every local problem as in the flattened solve (its
    // relative minimum times the whole scene's area), not relative to the small area of a twig,
    // which let a twig's leaves split ten thousand times finer than the full solve splits them.
    let min_area = config.pipeline.build.min_area_rel * scene.flattened_areas(true)[scene.root as usize];
    let dirs = light_directions();
    let mut levels = LevelCache::new(config.level_cache_bytes);
    while let Some(task) = stack.pop() {
        // Gather the level: own polygons of the task and of instances opened in place, and the
        // closed instances; `inlined` records which instances were opened in place (part of the
        // key under which the level is cached).
        let mut own: Vec<OwnPolygon> = Vec::new();
        let mut closed: Vec<(PrototypeId, Transform, u64, u32)> = Vec::new();
        let mut emitters: Vec<Aabb> = Vec::new();
        let mut inlined: Vec<bool> = Vec::new();
        let mut pending = vec![(task.prototype, task.transform, task.flat_base, task.depth)];
        while let Some((pid, t, base, depth)) = pending.pop() {
            let p = scene.prototype(pid);
            let mut k = base;
            for q in &p.polygons {
                let poly = t.poly(&q.poly);
                if scene.materials[q.material as usize].is_emitter() {
                    emitters.push(Aabb::from_points(poly.vertices()));
                }
                own.push((poly, q.material, k, pid));
                k += 1;
                if scene.materials[q.material as usize].two_sided {
                    k += 1;
                }
            }
            let mut inline = Vec::new();
            let boxes: Vec<Aabb> = if config.open_overlap < 1.0 {
                p.instances.iter().map(|inst| t.then(&inst.transform).aabb(&padded(&bounds[inst.prototype as usize]))).collect()
            } else {
                Vec::new()
            };
            for (i, inst) in p.instances.iter().enumerate() {
                let c = inst.prototype;
                let child_t = t.then(&inst.transform);
                let open = !config.instance_levels.closes(depth + 1)
                    || counts[c as usize] > config.max_closed_polygons
                    || bounds[c as usize].is_empty()
                    || near_an_emitter(&child_t.aabb(&bounds[c as usize]), &emitters, config.open_near_emitter)
                    || (!boxes.is_empty()
                        && boxes.iter().enumerate().any(|(j, b)| j != i && overlap_fraction(&boxes[i], b) > config.open_overlap));
                inlined.push(open);
                if open {
                    inline.push((c, child_t, k, depth + 1));
                } else {
                    closed.push((c, child_t, k, depth + 1));
                }
                k += counts[c as usize];
            }
            for item in inline.into_iter().rev() {
                pending.push(item);
            }
        }
        own.sort_by_key(|o| o.2);
        if task.incoming.is_none() && tracing {
            direct_emitters = own
                .iter()
                .filter(|o| scene.materials[o.1 as usize].is_emitter())
                .map(|o| (o.0, scene.materials[o.1 as usize].emission))
                .collect();
        }
        let pool: std::sync::Arc<[Poly]> = if closed.is_empty() {
            std::sync::Arc::from([])
        } else {
            own.iter().map(|o| o.0).chain(task.occluders.iter().copied()).collect()
        };
        let grid = PoolGrid::new(&pool);
        let mut child_occluders: Vec<Vec<u32>> =
            closed.iter().map(|&(c, t, _, _)| inherited_occluders(&pool, &grid, &t.aabb(&padded(&bounds[c as usize])))).collect();
        drop(grid);
        let mut child_occluders = share_pool(&pool, &mut child_occluders);
        drop(pool);

        // Properties of the closed prototypes.
        for &(c, _, _, _) in &closed {
            if proxies.contains_key(&c) {
                continue;
            }
            let props = match &cache {
                Some(cache) => {
                    let (props, outcome) = cache.get_or_compute(scene, &hashes, c, &config.properties)?;
                    match outcome {
                        CacheOutcome::Hit => stats.cache_hits += 1,
                        CacheOutcome::Computed => stats.cache_computed += 1,
                    }
                    props
                }
                None => {
                    stats.cache_computed += 1;
                    super::properties::compute(scene, c, &config.properties)?
                }
            };
            let _ = proxies.insert(c, proxy_of(&bounds[c as usize], &props));
        }

        // The level: reused from an earlier instance of the same prototype whose light was of the
        // same brightness class and which lies a similarity (rigid motion and uniform scale)
        // away, else built, refined and (below the top) cached.
        let t_local = std::time::Instant::now();
        // Below the top, the light straight from the top level's emitters is split off the field
        // and ray traced to every own polygon (see `InstancedConfig::direct_samples`).
        if tracing && task.incoming.is_some() && caster.is_none() {
            let c = super::InstanceCaster::new(scene);
            if config.trace {
                eprintln!("direct light: nested BVHs of {} prototypes, {:.1} MB", scene.prototypes.len(), c.bytes() as f64 / 1e6);
            }
            caster = Some(c);
        }
        let split = match (&task.incoming, &caster) {
            (Some(field), Some(caster)) => {
                let mut direct = vec![[0.0; 3]; field.len()];
                for &(b, e) in &task.direct {
                    direct[b as usize] = e;
                }
                let rest = field.iter().zip(&direct).map(|(f, d)| std::array::from_fn(|c| (f[c] - d[c]).max(0.0))).collect();
                let traced = traced_direct(scene, &own, task.flat_base, &direct_emitters, caster, config.direct_samples);
                Some(DirectSplit { rest, direct, traced })
            }
            _ => None,
        };
        // The brightness class bounds every polygon's light from outside: the beams', and the
        // traced direct light (which a polygon may get unattenuated where the beams are the
        // instance's average).
        let class = task.incoming.as_ref().map(|field| {
            let mut bound = irradiance_bound(&dirs, field);
            if let Some(split) = &split {
                let rest = irradiance_bound(&dirs, &split.rest);
                for c in 0..3 {
                    let traced = split.traced.iter().map(|t| t[c]).fold(0.0, f64::max);
                    bound[c] = bound[c].max(rest[c] + traced);
                }
            }
            brightness_class(bound)
        });
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
            let Some(level) = build_level(scene, &task, &own, &closed, &proxies, light, (b_ref_scene, min_area), config)? else { continue };
            fresh = Some(level);
        }
        drop(own);
        let (level, similarity) = match (&mut fresh, reused) {
            (Some(level), _) => (level, None),
            (None, Some(similarity)) => (levels.get(&key), Some(similarity)),
            (None, None) => unreachable!("a level is built when none is reused"),
        };
        stats.max_local_polygons = stats.max_local_polygons.max(level.polys.len());

        // The light that arrived at the instance, a field of parallel beams (one per direction
        // bin), reaches each polygon where the level's visibility table says it leaves the level
        // unblocked. Its first reflection becomes the polygon's emission; the solve adds every
        // further interreflection. Proxy faces keep their share per direction, for their own
        // opening. Directions are taken into the level's own frame.
        let rotation = similarity.as_ref().map_or(DMat3::IDENTITY, |s: &Similarity| s.rotation);
        let dirs_level: Vec<DVec3> = dirs.iter().map(|d| rotation.transpose() * *d).collect();
        let world_to_level = similarity.as_ref().map_or(DMat4::IDENTITY, |s| s.matrix.inverse());
        let occluders: Vec<Poly> = task.occluders.iter().map(|p| Transform { matrix: world_to_level }.poly(p)).collect();
        let (external, external_bins, direct_bins) = match (&task.incoming, &level.table) {
            (Some(field), Some(table)) => {
                outside_irradiance(&level.polys, table, &dirs_level, field, split.as_ref(), &level.roles, &occluders)
            }
            _ => (Vec::new(), Vec::new(), Vec::new()),
        };
        let solution = match level.solution.take() {
            Some(solution) => solution,
            None => {
                let h = &mut level.h;
                for i in 0..h.emission.len() {
                    // The first reflection of the light from outside, and its transmission from
                    // the other side of a transmitting leaf.
                    let ext = external.get(i).copied().unwrap_or([0.0; 3]);
                    let other = external.get(h.twin[i] as usize).copied().unwrap_or([0.0; 3]);
                    h.emission[i] = std::array::from_fn(|c| {
                        level.base_emission[i][c] + h.reflectance[i][c] * ext[c] + h.transmittance[i][c] * other[c]
                    });
                }
                let (solution, iterations, _) = pipeline::solve_links(&level.h, &level.links, &mut level.leaf, &local_pipeline(config));
                level.iterations = iterations;
                solution
            }
        };
        if config.trace {
            eprintln!(
                "local solve {}: `{}` {} polygons ({} proxies), {} elements, {} links, {} iterations, {}, {:.3}s, peak RSS {:.1} MB",
                stats.local_solves + 1,
                scene.prototype(task.prototype).name,
                level.polys.len(),
                closed.len(),
                level.h.len(),
                level.links.len(),
                level.iterations,
                if similarity.is_some() { "reused" } else { "refined" },
                t_local.elapsed().as_secs_f64(),
                crate::output::peak_rss_bytes().unwrap_or(0) as f64 / 1e6
            );
        }
        stats.local_solves += 1;
        stats.levels_reused += u64::from(similarity.is_some());
        stats.links += level.links.len() as u64;
        stats.max_local_links = stats.max_local_links.max(level.links.len() as u64);

        // Stream the own polygons, keep only the proxies' irradiance.
        let to_world = similarity.as_ref().map(|s| Transform { matrix: s.matrix });
        let h = &level.h;
        let mut leaves = Vec::new();
        let mut face_irradiance = vec![[0.0; 3]; level.polys.len()];
        for (i, role) in level.roles.iter().enumerate() {
            match *role {
                Role::Own(info) => {
                    leaves.clear();
                    let ext = external.get(i).copied().unwrap_or([0.0; 3]);
                    collect_leaves(h, i as ElementId, &mut |e| {
                        if let Some(p) = h.get(e).poly() {
                            let irr = solution.irradiance[e as usize];
                            leaves.push(Leaf {
                                poly: to_world.as_ref().map_or(*p, |t| t.poly(p)),
                                b: solution.radiosity[e as usize],
                                h: std::array::from_fn(|c| irr[c] + ext[c]),
                            });
                        }
                    });
                    stats.leaves_out += leaves.len() as u64;
                    stats.polygons_out += 1;
                    sink.polygon(&PolygonInfo { flat_index: task.flat_base + info.flat_index, ..info }, &leaves)?;
                }
                Role::ProxyFace { .. } => {
                    let (mut acc, mut area) = ([0.0; 3], 0.0);
                    collect_leaves(h, i as ElementId, &mut |e| {
                        let a = h.get(e).area;
                        let irr = solution.irradiance[e as usize];
                        for c in 0..3 {
                            acc[c] += a * irr[c];
                        }
                        area += a;
                    });
                    face_irradiance[i] = acc.map(|v| if area > 0.0 { v / area } else { 0.0 });
                }
            }
        }
        // Per proxy face: how the links that brought its irradiance split over directions, plus
        // its share of the beams from outside, as a field per closed instance. Two passes over the
        // links (per-face totals, then shares), so that no per-face field is ever held.
        let mut face_total = vec![[0.0; 3]; level.polys.len()];
        for_each_link_direction(h, &level.links, &solution.radiosity, &level.roles, &dirs_level, |face, _, w, _| {
            for c in 0..3 {
                face_total[face][c] += w[c];
            }
        });
        let mut fields = vec![vec![[0.0; 3]; dirs.len()]; closed.len()];
        // The part from the top level's emitters, sparse (a few bins per instance).
        let mut direct_fields: Vec<Vec<(u32, [f64; 3])>> = vec![Vec::new(); closed.len()];
        let emitted = if tracing && task.incoming.is_none() { Some(EmittedShare::new(h, &level.base_emission)) } else { None };
        let mut projected = vec![vec![0.0; dirs.len()]; closed.len()];
        for (i, role) in level.roles.iter().enumerate() {
            let Role::ProxyFace { slot, .. } = *role else { continue };
            let (area, n) = (level.polys[i].area(), level.polys[i].normal());
            let along_normal = nearest_direction(&dirs_level, n);
            let h_local = face_irradiance[i];
            for (b, u) in dirs_level.iter().enumerate() {
                projected[slot][b] += area * n.dot(*u).max(0.0);
                for c in 0..3 {
                    let ext = external_bins.get(i).and_then(|v| v.get(b)).map_or(0.0, |x| x[c]);
                    // No link to attribute (none arrived, or all from behind): along the normal.
                    let unattributed = if face_total[i][c] <= 0.0 && b == along_normal { h_local[c] } else { 0.0 };
                    fields[slot][b][c] += area * (ext + unattributed);
                }
                if let Some(d) = direct_bins.get(i).and_then(|v| v.get(b)) {
                    add_to_bin(&mut direct_fields[slot], b, d.map(|x| area * x));
                }
            }
        }
        for_each_link_direction(h, &level.links, &solution.radiosity, &level.roles, &dirs_level, |face, b, w, source| {
            let Role::ProxyFace { slot } = level.roles[face] else { return };
            let area = level.polys[face].area();
            let share: [f64; 3] = std::array::from_fn(|c| {
                if face_total[face][c] > 0.0 { area * face_irradiance[face][c] * w[c] / face_total[face][c] } else { 0.0 }
            });
            for c in 0..3 {
                fields[slot][b][c] += share[c];
            }
            if let Some(emitted) = &emitted {
                let (e, b_src) = (emitted.of(h, source), solution.radiosity[source as usize]);
                add_to_bin(
                    &mut direct_fields[slot],
                    b,
                    std::array::from_fn(|c| if b_src[c] > 0.0 { share[c] * (e[c] / b_src[c]).min(1.0) } else { 0.0 }),
                );
            }
        });
        drop(solution);
        if let Some(level) = fresh
            && class.is_some()
        {
            levels.insert(key, level, task.transform.matrix);
        }
        for (slot, &(c, t, base, depth)) in closed.iter().enumerate().rev() {
            let mut field = std::mem::take(&mut fields[slot]);
            for (flux, p) in field.iter_mut().zip(&projected[slot]) {
                *flux = flux.map(|f| if *p > 0.0 { f / p } else { 0.0 });
            }
            let occluders = std::mem::take(&mut child_occluders[slot]);
            let mut direct = std::mem::take(&mut direct_fields[slot]);
            for (b, flux) in &mut direct {
                let p = projected[slot][*b as usize];
                *flux = flux.map(|f| if p > 0.0 { f / p } else { 0.0 });
            }
            direct.retain(|(_, e)| e.iter().any(|&x| x > 0.0));
            stack.push(Task { prototype: c, transform: t, flat_base: base, depth, incoming: Some(field), direct, occluders });
        }
    }
    stats.levels_cached_peak_bytes = levels.peak_bytes as u64;
    stats.seconds = t0.elapsed().as_secs_f64();
    Ok(stats)
}

/// Centre and half-extents of `b` with every extent at least [`MIN_PROXY_EXTENT_REL`] of its
/// diagonal: the box a proxy is shrunk from.
fn padded_half(b: &Aabb) -> (DVec3, DVec3) {
    let min_extent = MIN_PROXY_EXTENT_REL * b.diagonal().max(f64::MIN_POSITIVE);
    (b.center(), (0.5 * b.extent()).max(DVec3::splat(0.5 * min_extent)))
}

/// `b` padded as a proxy's box is (see [`padded_half`]).
fn padded(b: &Aabb) -> Aabb {
    if b.is_empty() {
        return *b;
    }
    let (c, half) = padded_half(b);
    Aabb { min: c - half, max: c + half }
}

/// Volume of the intersection of `a` and `b` over the smaller one's volume (0 when disjoint).
fn overlap_fraction(a: &Aabb, b: &Aabb) -> f64 {
    let common = (a.max.min(b.max) - a.min.max(b.min)).max(DVec3::ZERO);
    let vol = |e: DVec3| e.x * e.y * e.z;
    let smaller = vol(a.extent()).min(vol(b.extent()));
    if smaller > 0.0 { vol(common) / smaller } else { 0.0 }
}

/// True when box `b` lies within `rel` times its diagonal of one of the `emitters` boxes.
fn near_an_emitter(b: &Aabb, emitters: &[Aabb], rel: f64) -> bool {
    let reach = rel * b.diagonal();
    emitters.iter().any(|e| {
        let gap = DVec3::ZERO.max(e.min - b.max).max(b.min - e.max);
        gap.length() < reach
    })
}

/// Directions of the light field carried into an opened instance (a Fibonacci sphere).
pub const LIGHT_DIRECTIONS: u32 = 64;
/// Beams weaker than this fraction of the strongest are not traced.
pub const FIELD_REL_MIN: f64 = 1e-4;

/// The direction bins of the light field: unit vectors toward where the light comes from.
fn light_directions() -> Vec<DVec3> {
    super::properties::sphere_directions(LIGHT_DIRECTIONS)
}

/// Index of the bin nearest to unit `u`.
fn nearest_direction(dirs: &[DVec3], u: DVec3) -> usize {
    let mut best = (0, f64::NEG_INFINITY);
    for (k, d) in dirs.iter().enumerate() {
        let c = d.dot(u);
        if c > best.1 {
            best = (k, c);
        }
    }
    best.0
}

/// Calls `f(face, bin, F·V·B_source, source)` (RGB) for every link that arrived at a proxy face (at the
/// face or below, or at a cluster holding it), with the bin of the direction toward its source (for
/// a cluster receiver, weighted by the face's cosine toward it).
fn for_each_link_direction(
    h: &Hierarchy,
    links: &[crate::refine::Link],
    radiosity: &[[f64; 3]],
    roles: &[Role],
    dirs: &[DVec3],
    mut f: impl FnMut(usize, usize, [f64; 3], ElementId),
) {
    for l in links {
        let (r, src) = (h.get(l.receiver), h.get(l.source));
        let b_src = radiosity[l.source as usize];
        match r.kind {
            crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } => {
                for &p in &h.cluster_polygons[poly_start as usize..poly_end as usize] {
                    if !is_proxy(roles, p as usize) {
                        continue;
                    }
                    let face = h.get(p);
                    let u = (src.center - face.center).normalize_or_zero();
                    let cos = face.normal.dot(u);
                    if cos > 0.0 {
                        f(p as usize, nearest_direction(dirs, u), b_src.map(|x| l.ff * l.vis * x * cos), l.source);
                    }
                }
            }
            _ => {
                let Some(p) = r.polygon() else { continue };
                if is_proxy(roles, p as usize) {
                    let u = (src.center - r.center).normalize_or_zero();
                    f(p as usize, nearest_direction(dirs, u), b_src.map(|x| l.ff * l.vis * x), l.source);
                }
            }
        }
    }
}

/// A local problem: the level's polygons and proxy faces, refined, with what reusing it for
/// another instance of the same prototype needs.
struct Level {
    /// The level's polygons, in the frame of the instance the level was built for.
    polys: Vec<Poly>,
    /// What each polygon stands for (flattened indices relative to the instance's first).
    roles: Vec<Role>,
    /// Emission of each polygon, light from outside the level excluded.
    base_emission: Vec<[f64; 3]>,
    /// The refined hierarchy (its emission is rewritten for every instance).
    h: Hierarchy,
    /// The refined links.
    links: Vec<Link>,
    /// Visibility of the table's directions from each polygon (levels lit from outside).
    table: Option<VisibilityTable>,
    /// Leaf-resolution coefficients, kept by [`pipeline::solve_links`] from the first solve of a
    /// level lit from outside.
    leaf: Option<crate::solve::LeafCoefficients>,
    /// The solution of a level with no light from outside (the top), solved while refining.
    solution: Option<Solution>,
    /// Iterations of the last solve.
    iterations: usize,
}

impl Level {
    /// Approximate heap bytes held (what the level cache counts against its budget).
    fn bytes(&self) -> usize {
        use std::mem::size_of;
        let h = &self.h;
        self.polys.len() * (size_of::<Poly>() + size_of::<Role>() + 1 + 24)
            + h.elements.len() * size_of::<crate::hierarchy::Element>()
            + (h.children.len() + h.cluster_polygons.len()) * 4
            + h.cluster_area_prefix.len() * 8
            + (h.reflectance.len() + h.emission.len()) * 24
            + self.links.len() * size_of::<Link>()
            + self.table.as_ref().map_or(0, |t| t.counts.len())
            + self.leaf.as_ref().map_or(0, crate::solve::LeafCoefficients::bytes)
    }
}

/// Builds and refines a level, and solves it when it has no light from outside (the top). With
/// light from outside (`field` in the directions `dirs`, and the factor that raises it to the top
/// of its [`brightness_class`]), the links are refined for the raised light, whose first reflection
/// is the polygons' emission. `None` when the level has no polygon.
#[allow(clippy::too_many_arguments)]
fn build_level(
    scene: &InstancedScene,
    task: &Task,
    own: &[OwnPolygon],
    closed: &[(PrototypeId, Transform, u64, u32)],
    proxies: &HashMap<PrototypeId, Proxy>,
    light: Option<OutsideLight<'_>>,
    (b_ref_scene, min_area): (f64, f64),
    config: &InstancedConfig,
) -> Result<Option<Level>, InstancingError> {
    let mut b = SceneBuilder::new(&scene.path, &scene.prototype(task.prototype).name);
    for m in &scene.materials {
        let _ = b.material(m.clone())?;
    }
    let group = b.group("local");
    let mut roles: Vec<Role> = Vec::new();
    let add = |b: &mut SceneBuilder, roles: &mut Vec<Role>, poly: &Poly, material: u32, role: Role| -> Result<(), InstancingError> {
        let before = b.n_polygons();
        b.face(poly.vertices(), material, group, 0)?;
        for _ in before..b.n_polygons() {
            roles.push(role);
        }
        Ok(())
    };
    for &(poly, material, k, prototype) in own {
        let k = k - task.flat_base;
        add(&mut b, &mut roles, &poly, material, Role::Own(PolygonInfo { flat_index: k, material, prototype }))?;
        if scene.materials[material as usize].two_sided {
            add(&mut b, &mut roles, &reversed(&poly), material, Role::Own(PolygonInfo { flat_index: k + 1, material, prototype }))?;
        }
    }
    let mut proxy_material: HashMap<PrototypeId, u32> = HashMap::new();
    for (slot, &(c, t, _, _)) in closed.iter().enumerate() {
        let proxy = proxies[&c];
        let m = match proxy_material.get(&c) {
            Some(&m) => m,
            None => {
                let rho = proxy.albedo.map(|a| a.clamp(0.0, MAX_PROXY_REFLECTANCE));
                let m = b.material(Material::diffuse(&format!("(proxy {})", scene.prototype(c).name), rho))?;
                let _ = proxy_material.insert(c, m);
                m
            }
        };
        for (_, quad) in box_faces(proxy.shrunk.min, proxy.shrunk.max, false) {
            let poly = t.poly(&Poly::quad(quad[0], quad[1], quad[2], quad[3]));
            add(&mut b, &mut roles, &poly, m, Role::ProxyFace { slot })?;
        }
    }
    let mut local = b.finish();
    if local.polygons.is_empty() {
        return Ok(None);
    }
    let base_emission: Vec<[f64; 3]> = local.polygons.iter().map(|p| local.materials[p.material as usize].emission).collect();
    let polys: Vec<Poly> = local.polygons.iter().map(|p| p.poly).collect();
    let mut table = None;
    if let Some(OutsideLight { dirs, field, split, raise }) = light {
        let caster = crate::visibility::RayCaster::new(&local);
        let t = VisibilityTable::build(&polys, &caster, local.bounds().diagonal(), config.properties.seed);
        let (external, _, _) = outside_irradiance(&polys, &t, dirs, field, split, &roles, &[]);
        table = Some(t);
        let twin = crate::hierarchy::twins(&local);
        let mut materials = Vec::with_capacity(local.polygons.len());
        for (i, p) in local.polygons.iter_mut().enumerate() {
            let mut m = local.materials[p.material as usize].clone();
            m.name = format!("p{i}");
            let other = external.get(twin[i] as usize).copied().unwrap_or([0.0; 3]);
            let through = if twin[i] == crate::hierarchy::NONE { [0.0; 3] } else { m.transmittance };
            m.emission = std::array::from_fn(|c| m.emission[c] + raise * (m.reflectance[c] * external[i][c] + through[c] * other[c]));
            materials.push(m);
            p.material = i as u32;
        }
        local.materials = materials;
    }
    // The BF threshold is relative to the largest emission of the problem solved; a local problem's
    // largest emission is often a wall's, far below the scene's lights, so its threshold is rescaled
    // to stay relative to the scene's largest emission (the full solve's criterion).
    let b_ref_local = local.polygons.iter().flat_map(|p| local.materials[p.material as usize].emission).fold(0.0, f64::max);
    let mut bf = config.bf;
    if b_ref_local > 0.0 && b_ref_scene > 0.0 {
        bf.eps *= b_ref_scene / b_ref_local;
    }
    let mut pipeline_config = local_pipeline(config);
    pipeline_config.build.min_area_rel = min_area / local.total_area();
    let oracle = ClassicBf { eps: bf.eps, b_ref: first_guess_max(&local) };
    let solved = pipeline::run(&local, &oracle, &pipeline_config, &|_| {});
    Ok(Some(Level {
        polys,
        roles,
        base_emission,
        h: solved.hierarchy,
        links: solved.links,
        table,
        leaf: None,
        // Lit from outside, the level was refined for raised light: it is solved for its own below.
        solution: light.is_none().then_some(solved.solution),
        iterations: solved.iterations,
    }))
}

/// The light from outside a level: the field of beams in directions `dirs`, and the factor that
/// raises it to the top of its brightness class.
#[derive(Clone, Copy)]
struct OutsideLight<'a> {
    dirs: &'a [DVec3],
    field: &'a [[f64; 3]],
    split: Option<&'a DirectSplit>,
    raise: f64,
}

/// Refine → solve rounds of a local solve (the classic BF criterion reads the last solution's
/// radiosity).
const LOCAL_PASSES: usize = 3;

/// Settings of every local solve (and of the full solve it is compared with): one level of the
/// classic BF oracle ([`ClassicBf`]), no variation measured, no estimate, no closure (a local
/// problem is open to the rest of the scene).
fn local_pipeline(config: &InstancedConfig) -> pipeline::Config {
    pipeline::Config {
        estimate_error: false,
        detect_closure: false,
        levels: 1,
        max_passes: LOCAL_PASSES,
        measure_variation: false,
        target_error: None,
        solve: config.local_solve,
        leaf_operator_max_entries: config.local_leaf_operator_max_entries,
        ..config.pipeline
    }
}

/// The brightest irradiance (per channel) that `field` brings to a surface facing any of `dirs`,
/// ignoring blockers.
fn irradiance_bound(dirs: &[DVec3], field: &[[f64; 3]]) -> [f64; 3] {
    let mut best = [0.0f64; 3];
    for n in dirs {
        let mut e = [0.0; 3];
        for (d, f) in dirs.iter().zip(field) {
            let cos = n.dot(*d);
            if cos > 0.0 {
                for c in 0..3 {
                    e[c] += f[c] * cos;
                }
            }
        }
        for c in 0..3 {
            best[c] = best[c].max(e[c]);
        }
    }
    best
}

/// The brightness class of a level's light: `⌈log₂ m⌉` of the largest channel `m` of its
/// [`irradiance_bound`], and the factor (in [1, 2)) that raises the light to the class's top. A level
/// is refined for its light raised to the top of its class, so that its refinement serves every
/// instance of the class (the BF criterion never asks for less refinement under brighter light),
/// and instances under much dimmer light get their own, coarser level.
fn brightness_class(bound: [f64; 3]) -> (i32, f64) {
    let m = bound.into_iter().fold(0.0, f64::max);
    if !(m > 0.0 && m.is_finite()) {
        return (i32::MIN, 1.0);
    }
    let class = m.log2().ceil() as i32;
    (class, 2f64.powi(class) / m)
}

/// What a cached level is found by: its prototype, which of its instances were opened in place,
/// and the brightness class of its light.
type LevelKey = (PrototypeId, Vec<bool>, i32);

/// Relative tolerance of `similarity`: how far from orthogonal the rotation part may be.
pub const SIMILARITY_TOLERANCE: f64 = 1e-6;

/// The motion from one instance's frame to another's, when it is a similarity.
#[derive(Clone, Copy, Debug)]
struct Similarity {
    /// From the cached level's frame to the new instance's.
    matrix: DMat4,
    /// Its rotation.
    rotation: DMat3,
}

/// The similarity (rotation, uniform scale, translation; no mirror) that takes frame `from` to
/// frame `to`, if there is one: under it every form factor and visibility of a level is unchanged.
fn similarity(from: &DMat4, to: &DMat4) -> Option<Similarity> {
    let matrix = *to * from.inverse();
    let linear = DMat3::from_mat4(matrix);
    let det = linear.determinant();
    if !(det.is_finite() && det > 0.0) {
        return None;
    }
    let rotation = linear * det.cbrt().recip();
    let off = rotation.transpose() * rotation - DMat3::IDENTITY;
    let worst = off.to_cols_array().iter().fold(0.0f64, |a, x| a.max(x.abs()));
    (worst <= SIMILARITY_TOLERANCE).then_some(Similarity { matrix, rotation })
}

/// Levels kept for reuse, keyed by prototype and which of its instances were opened in place,
/// within a budget of bytes (least recently used evicted first).
struct LevelCache {
    budget: usize,
    entries: HashMap<LevelKey, CachedLevel>,
    bytes: usize,
    peak_bytes: usize,
    clock: u64,
}

struct CachedLevel {
    level: Level,
    /// World transform of the instance the level was built for.
    frame: DMat4,
    bytes: usize,
    last_used: u64,
}

impl LevelCache {
    fn new(budget: usize) -> LevelCache {
        LevelCache { budget, entries: HashMap::new(), bytes: 0, peak_bytes: 0, clock: 0 }
    }

    /// A cached level usable for an instance at `frame`, as the
    /// motion from the cached instance to this one.
    fn find(&mut self, key: &LevelKey, frame: &DMat4) -> Option<Similarity> {
        let entry = self.entries.get_mut(key)?;
        let s = similarity(&entry.frame, frame)?;
        self.clock += 1;
        entry.last_used = self.clock;
        Some(s)
    }

    fn get(&mut self, key: &LevelKey) -> &mut Level {
        &mut self.entries.get_mut(key).expect("found before").level
    }

    /// Keeps `level` (replacing the entry of `key`) if it fits the budget, evicting the least
    /// recently used levels as needed.
    fn insert(&mut self, key: LevelKey, level: Level, frame: DMat4) {
        if let Some(old) = self.entries.remove(&key) {
            self.bytes -= old.bytes;
        }
        let bytes = level.bytes();
        if bytes > self.budget {
            return;
        }
        while self.bytes + bytes > self.budget {
            let Some(oldest) = self.entries.iter().min_by_key(|(_, e)| e.last_used).map(|(k, _)| k.clone()) else { break };
            if let Some(e) = self.entries.remove(&oldest) {
                self.bytes -= e.bytes;
            }
        }
        self.clock += 1;
        let _ = self.entries.insert(key, CachedLevel { level, frame, bytes, last_used: self.clock });
        self.bytes += bytes;
        self.peak_bytes = self.peak_bytes.max(self.bytes);
    }
}

/// Directions of a level's visibility table (a Fibonacci sphere in the level's frame).
pub const TABLE_DIRECTIONS: u32 = 128;
/// Seed of the points from which beams are tested against inherited occluders.
const OCCLUDER_SEED: u64 = 0x0CC1;

/// Rays per polygon and table direction, stratified over the polygon.
pub const TABLE_RAYS: u32 = 4;

/// For every polygon of a level and every table direction in front of it, how many of
/// [`TABLE_RAYS`] rays leave the level unblocked: built once per level and used for every instance
/// (a beam's direction is taken to the nearest table direction).
struct VisibilityTable {
    dirs: Vec<DVec3>,
    /// `polygon × direction` counts.
    counts: Vec<u8>,
}

impl VisibilityTable {
    fn build(polys: &[Poly], caster: &crate::visibility::RayCaster, diag: f64, seed: u64) -> VisibilityTable {
        use rayon::prelude::*;
        let dirs = super::properties::sphere_directions(TABLE_DIRECTIONS);
        let offset = super::properties::RAY_OFFSET_REL * diag.max(f64::MIN_POSITIVE);
        let rows: Vec<Vec<u8>> = polys
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                let n = p.normal();
                let mut rng = crate::visibility::Rng::for_link(seed, i as u32, 0x7AB);
                dirs.iter()
                    .map(|d| {
                        if n.dot(*d) <= 0.0 {
                            return 0;
                        }
                        let mut clear = 0u8;
                        for s in 0..TABLE_RAYS {
                            let u = (f64::from(s) + rng.next_f64()) / f64::from(TABLE_RAYS);
                            let x = p.sample(u, rng.next_f64()) + n * offset;
                            clear += u8::from(caster.ray_clear(x, *d));
                        }
                        clear
                    })
                    .collect()
            })
            .collect();
        VisibilityTable { dirs, counts: rows.concat() }
    }
}

/// Irradiance from outside of every polygon of a level (see the module docs), per proxy face its
/// share of each beam, and of that share the part straight from the top level's emitters (empty
/// without a `split`). `field` is the irradiance perpendicular to each beam of `dirs` (taken into
/// the level's frame), received where the table says the beam's direction leaves the level (and
/// it misses the inherited `occluders`). With a `split`, the field's direct part reaches only the
/// proxy faces as beams; the own polygons get the traced direct light in its place.
#[allow(clippy::type_complexity)]
fn outside_irradiance(
    polys: &[Poly],
    table: &VisibilityTable,
    dirs: &[DVec3],
    field: &[[f64; 3]],
    split: Option<&DirectSplit>,
    roles: &[Role],
    occluders: &[Poly],
) -> (Vec<[f64; 3]>, Vec<Vec<[f64; 3]>>, Vec<Vec<[f64; 3]>>) {
    let (rest, direct) = match split {
        Some(split) => (&split.rest[..], Some(&split.direct[..])),
        None => (field, None),
    };
    let strongest = field.iter().flat_map(|e| e.iter().copied()).fold(0.0, f64::max);
    let active: Vec<usize> =
        (0..dirs.len()).filter(|&b| field[b].iter().copied().fold(0.0, f64::max) > FIELD_REL_MIN * strongest).collect();
    let nearest: Vec<usize> = dirs.iter().map(|d| nearest_direction(&table.dirs, *d)).collect();
    let k = table.dirs.len();
    use rayon::prelude::*;
    let rows: Vec<([f64; 3], Vec<[f64; 3]>, Vec<[f64; 3]>)> = polys
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let n = p.normal();
            let own = match roles.get(i) {
                Some(Role::Own(info)) => Some(*info),
                _ => None,
            };
            let keep = is_proxy(roles, i);
            // Points of the polygon from which the beams are tested against the occluders handed
            // down from the levels above (none for most instances).
            // Only occluders with a vertex in front of the polygon's plane can stop a beam it takes.
            let x0 = p.v[0];
            // Own polygons that get traced direct light skip them: what is left of their beams
            // is the dim indirect light. Measured on the age-30 tree (eps 0.05, 16 pairs): max
            // error 4.35% in 7.3 s so; 4.30% in 9.6 s testing every polygon; 4.56% in 7.0 s
            // testing none.
            let tested = if split.is_some() && !keep { &[][..] } else { occluders };
            let ahead: Vec<&Poly> = tested.iter().filter(|o| o.vertices().iter().any(|v| n.dot(*v - x0) > 0.0)).collect();
            let points: Vec<DVec3> = if ahead.is_empty() {
                Vec::new()
            } else {
                let mut rng = crate::visibility::Rng::for_link(OCCLUDER_SEED, i as u32, 0);
                (0..TABLE_RAYS)
                    .map(|s| {
                        p.sample((f64::from(s) + rng.next_f64()) / f64::from(TABLE_RAYS), rng.next_f64()) + n * (1e-9 * p.area().sqrt())
                    })
                    .collect()
            };
            let mut bins = if keep { vec![[0.0; 3]; dirs.len()] } else { Vec::new() };
            let mut direct_bins = if keep && direct.is_some() { vec![[0.0; 3]; dirs.len()] } else { Vec::new() };
            let mut acc = [0.0; 3];
            for &b in &active {
                let cos = n.dot(dirs[b]);
                let clear = table.counts[i * k + nearest[b]];
                // The beam's direct part only matters to proxy faces.
                let beam = if keep { field[b] } else { rest[b] };
                if cos <= 0.0 || clear == 0 || beam.iter().all(|&x| x <= 0.0) {
                    continue;
                }
                let mut v = f64::from(clear) / f64::from(TABLE_RAYS);
                if !points.is_empty() {
                    let open = points.iter().filter(|&&x| !ahead.iter().any(|o| o.crossing(x, dirs[b]).is_some_and(|t| t > 0.0))).count();
                    v *= open as f64 / points.len() as f64;
                }
                for c in 0..3 {
                    let e = beam[c] * cos * v;
                    acc[c] += e;
                    if keep {
                        bins[b][c] += e;
                        if let Some(direct) = direct {
                            direct_bins[b][c] += direct[b][c] * cos * v;
                        }
                    }
                }
            }
            if let (Some(info), Some(split)) = (own, split) {
                let traced = split.traced.get(info.flat_index as usize).copied().unwrap_or([0.0; 3]);
                for c in 0..3 {
                    acc[c] += traced[c];
                }
            }
            (acc, bins, direct_bins)
        })
        .collect();
    let mut external = Vec::with_capacity(rows.len());
    let mut bins = Vec::with_capacity(rows.len());
    let mut direct_bins = Vec::with_capacity(if split.is_some() { rows.len() } else { 0 });
    for (e, b, d) in rows {
        external.push(e);
        bins.push(b);
        if split.is_some() {
            direct_bins.push(d);
        }
    }
    (external, bins, direct_bins)
}

/// Adds `x` to bin `b` of a sparse field.
fn add_to_bin(field: &mut Vec<(u32, [f64; 3])>, b: usize, x: [f64; 3]) {
    if x.iter().all(|&v| v == 0.0) {
        return;
    }
    match field.iter_mut().find(|(k, _)| *k as usize == b) {
        Some((_, e)) => {
            for c in 0..3 {
                e[c] += x[c];
            }
        }
        None => field.push((b as u32, x)),
    }
}

/// The emitted part of an element's radiosity at the top level (its area-weighted mean
/// emission): which share of a link's light came straight from an emitter.
struct EmittedShare<'a> {
    /// Emitting polygons: their place in the hierarchy's cluster order and their `A·E`.
    emitters: Vec<(usize, [f64; 3])>,
    emission: &'a [[f64; 3]],
}

impl<'a> EmittedShare<'a> {
    fn new(h: &Hierarchy, emission: &'a [[f64; 3]]) -> EmittedShare<'a> {
        let emitters = h
            .cluster_polygons
            .iter()
            .enumerate()
            .filter_map(|(pos, &p)| {
                let e = emission[p as usize];
                e.iter().any(|&x| x > 0.0).then(|| (pos, e.map(|x| x * h.get(p).area)))
            })
            .collect();
        EmittedShare { emitters, emission }
    }

    fn of(&self, h: &Hierarchy, e: ElementId) -> [f64; 3] {
        let el = h.get(e);
        match el.kind {
            crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } => {
                let mut sum = [0.0; 3];
                for (pos, ae) in &self.emitters {
                    if (poly_start as usize..poly_end as usize).contains(pos) {
                        for c in 0..3 {
                            sum[c] += ae[c];
                        }
                    }
                }
                sum.map(|x| if el.area > 0.0 { x / el.area } else { 0.0 })
            }
            _ => el.polygon().map_or([0.0; 3], |p| self.emission[p as usize]),
        }
    }
}

/// A field split into the light straight from the top level's emitters and the rest, with the
/// direct light ray traced to the level's own polygons.
struct DirectSplit {
    /// The field less its direct part.
    rest: Vec<[f64; 3]>,
    /// The direct part, per direction bin (what proxy faces receive and pass on).
    direct: Vec<[f64; 3]>,
    /// Traced direct irradiance per own polygon, by flattened index relative to the instance's
    /// first (a transmitting leaf's back side at the index after its front).
    traced: Vec<[f64; 3]>,
}

/// Direct irradiance of the `own` polygons of a level (scene frame) from `emitters`, ray traced
/// through `caster` from [`InstancedConfig::direct_samples`] point pairs per polygon and emitter,
/// by flattened index relative to `flat_base` (see [`DirectSplit::traced`]). A transmitting leaf's
/// two sides are estimated from one set of pairs. Seeded by flattened index.
fn traced_direct(
    scene: &InstancedScene,
    own: &[OwnPolygon],
    flat_base: u64,
    emitters: &[(Poly, [f64; 3])],
    caster: &super::InstanceCaster,
    samples: u32,
) -> Vec<[f64; 3]> {
    use rayon::prelude::*;
    let sides: Vec<(usize, [f64; 3], Option<[f64; 3]>)> = own
        .par_iter()
        .map(|(p, material, flat, _)| {
            let two_sided = scene.materials[*material as usize].two_sided;
            let (mut front, mut back) = ([0.0; 3], [0.0; 3]);
            for (k, (q, e)) in emitters.iter().enumerate() {
                let mut rng = crate::visibility::Rng::for_link(DIRECT_SEED ^ flat.wrapping_mul(0x9E37_79B9_7F4A_7C15), k as u32, 0);
                let [f, g] = crate::solve::emitter_exchange(p, q, samples, &mut rng, two_sided, |x, y| caster.segment_clear(x, y));
                for c in 0..3 {
                    front[c] += f * e[c];
                    back[c] += g * e[c];
                }
            }
            ((flat - flat_base) as usize, front, two_sided.then_some(back))
        })
        .collect();
    let len = sides.iter().map(|s| s.0 + 2).max().unwrap_or(0);
    let mut out = vec![[0.0; 3]; len];
    for (k, front, back) in sides {
        out[k] = front;
        if let Some(back) = back {
            out[k + 1] = back;
        }
    }
    out
}

/// Seed of the point pairs of [`traced_direct`].
const DIRECT_SEED: u64 = 0xD1EC7;

fn proxy_of(local: &Aabb, props: &RadiativeProperties) -> Proxy {
    let (c, half) = padded_half(local);
    let s = (1.0 - props.mean_transmittance()).clamp(0.0, 1.0).sqrt().max(MIN_PROXY_EXTENT_REL);
    Proxy { shrunk: Aabb { min: c - half * s, max: c + half * s }, albedo: props.mean_albedo() }
}

/// Calls `f` on every leaf below `e`.
fn collect_leaves(h: &Hierarchy, e: ElementId, f: &mut dyn FnMut(ElementId)) {
    let mut stack = vec![e];
    while let Some(x) = stack.pop() {
        let kids = h.children_of(x);
        if kids.is_empty() {
            f(x);
        } else {
            stack.extend_from_slice(kids);
        }
    }
}

/// The same scene solved fully: flattened (two-sided polygons as pairs) and given to
/// [`pipeline::run`]; the per-polygon mean radiosity is returned in flattening order, with the
/// solve's link count.
pub fn solve_full(scene: &InstancedScene, config: &InstancedConfig) -> Result<(PolygonMeans, u64), InstancingError> {
    let flat = super::flatten(scene, &FlattenOptions { two_sided_pairs: true })?;
    // No error estimate: the comparison measures the error, and the instanced solve has none either.
    // On a worker of the pool, as the instanced solve runs (a like-for-like comparison).
    let solved = rayon::scope(|_| {
        pipeline::run(&flat, &ClassicBf { eps: config.bf.eps, b_ref: first_guess_max(&flat) }, &local_pipeline(config), &|_| {})
    });
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
