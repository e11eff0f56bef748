//! Settings and figures of the instanced solve, and the settings of every local solve.

use crate::instancing::properties::PropertyConfig;
use crate::pipeline;
use crate::refine::BfParams;
use std::path::PathBuf;

/// Settings of [`solve_instanced`](super::solve_instanced).
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
    /// Linear solver of every local solve (and of [`solve_full`](super::solve_full), for a like-for-like comparison):
    /// a short GMRES restart bounds the Krylov basis, which is the largest allocation of a local
    /// problem (one vector of all elements per iteration), and a relative residual of 1e-7 is far
    /// below the method's approximation error.
    pub local_solve: crate::solve::SolveConfig,
    /// Budget of a local problem's leaf-resolution operator, in bytes of stored coefficients (4
    /// each: local problems have no target error); a larger problem (the top level of a forest)
    /// does one leaf-level gather pass instead. It caps the second-largest allocation of a local
    /// problem.
    pub local_leaf_operator_max_bytes: usize,
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
    /// per-prototype BVHs ([`InstanceCaster`](crate::instancing::InstanceCaster): every instance blocks with its own geometry),
    /// instead of arriving with the parallel beams, whose visibility is the instance's average.
    /// 0 leaves all light to the beams.
    pub direct_samples: u32,
    /// Budget (approximate bytes) of the levels kept for reuse: a level lit from outside is
    /// refined once and reused, solve only, for every later instance of its prototype that lies a
    /// similarity away and whose light is no brighter (see [`solve_instanced`](super::solve_instanced)). 0 disables reuse.
    pub level_cache_bytes: usize,
    /// The scene's distant sources (the sun and the sky's cells, in the scene's frame; see
    /// [`crate::daylight`]): they light every own polygon through the whole instanced structure
    /// and the top level's proxies as beams (see the `daylight` step of
    /// [`solve_instanced`](super::solve_instanced)). Empty: no daylight.
    pub daylight: Vec<crate::daylight::DistantSource>,
    /// Whether a level refined under one top-level instance may be reused under another (see
    /// [`LevelReuse`]).
    pub level_reuse: LevelReuse,
    /// How the light a closed instance's proxy sends on leaves it: by the face it entered,
    /// uniformly (the paper's proxy), or by the faces the prototype's face transfer matrix says
    /// (see [`ProxyEmission`]).
    pub proxy_emission: ProxyEmission,
}

/// How a proxy box re-emits the light it intercepts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ProxyEmission {
    /// Each face reflects its own irradiance with the prototype's mean escape albedo: the light
    /// leaves by the face it entered, the same fraction whatever the face (the paper's proxy).
    Uniform,
    /// Directional: the power intercepted through face `i` leaves through face `j` in the
    /// fraction the prototype's face transfer matrix gives
    /// ([`face_transfer`](crate::instancing::face_transfer)); a twig lit from above also shines
    /// downward, by what its leaves transmit.
    #[default]
    Directional,
}

impl std::str::FromStr for ProxyEmission {
    type Err = String;
    fn from_str(s: &str) -> Result<ProxyEmission, String> {
        match s {
            "uniform" => Ok(ProxyEmission::Uniform),
            "directional" => Ok(ProxyEmission::Directional),
            _ => Err(format!("`{s}` is not a proxy emission (uniform, directional)")),
        }
    }
}

impl std::fmt::Display for ProxyEmission {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ProxyEmission::Uniform => "uniform",
            ProxyEmission::Directional => "directional",
        })
    }
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
            local_leaf_operator_max_bytes: 1_000_000,
            open_near_emitter: 1.0,
            level_cache_bytes: 16_000_000,
            instance_levels: InstanceLevels::All,
            open_overlap: 1.0,
            direct_samples: 16,
            daylight: Vec::new(),
            proxy_emission: ProxyEmission::default(),
            level_reuse: LevelReuse::Scene,
        }
    }
}

/// How far the level cache reaches. A reused level is the level refined for the light of the
/// instance that first built it (raised to its brightness class), in that instance's frame: the
/// results of an instance depend on which instances were solved before it. A distributed solve
/// (see [`distributed`](super::distributed)) hands each top-level instance's subtree to whichever
/// process is free, so it keeps reuse within a subtree, which one process reproduces exactly.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LevelReuse {
    /// Levels are reused across the whole scene (one process; the default).
    #[default]
    Scene,
    /// The level cache is emptied before each top-level instance's subtree: results depend on the
    /// subtree alone, so one process and any number of MPI ranks give the same bytes.
    Subtree,
}

impl std::str::FromStr for LevelReuse {
    type Err = String;
    fn from_str(s: &str) -> Result<LevelReuse, String> {
        match s {
            "scene" => Ok(LevelReuse::Scene),
            "subtree" => Ok(LevelReuse::Subtree),
            _ => Err(format!("`{s}` is not a level reuse scope (scene, subtree)")),
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

/// Refine → solve rounds of a local solve (the classic BF criterion reads the last solution's
/// radiosity).
pub(super) const LOCAL_PASSES: usize = 3;

/// Settings of every local solve (and of the full solve it is compared with): one level of the
/// classic BF oracle ([`ClassicBf`](crate::refine::ClassicBf)), no variation measured, no estimate, no closure (a local
/// problem is open to the rest of the scene), and the radiosity criterion whatever
/// `config.pipeline` says: the level cache, the proxies and their measured errors are the classic
/// criterion's (`--criterion` is for plain scenes).
pub(super) fn local_pipeline(config: &InstancedConfig) -> pipeline::Config {
    pipeline::Config {
        criterion: crate::refine::Criterion::Radiosity,
        estimate_error: false,
        detect_closure: false,
        levels: 1,
        max_passes: LOCAL_PASSES,
        measure_variation: false,
        target_error: None,
        solve: config.local_solve,
        leaf_operator_max_bytes: config.local_leaf_operator_max_bytes,
        stream_leaf_operator: false,
        // The instanced levels and their flattened reference keep the smallest element relative
        // to the scene alone, as their costs, proxies and tolerances were measured with it.
        build: crate::hierarchy::BuildConfig { min_polygon_depth: 0, ..config.pipeline.build },
        ..config.pipeline
    }
}
