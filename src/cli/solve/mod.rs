//! `radiosity solve`.
//!
//! The command only turns arguments into a scene and a [`radiosity::pipeline::Config`], and the
//! results into text and files. [`run`] checks the arguments and picks the route; the steps beside
//! it: `plain.rs` (a plain solve, one step per function: load, solve, gather, write, report),
//! `instanced.rs` (scenes solved by the instanced solver), `grids.rs` (the grid files),
//! `report.rs` (the console summary).

mod grids;
mod instanced;
mod plain;
mod report;

use super::picture::PictureArgs;
use super::{SolveOptions, load_scene};
use instanced::{refuse_plain_only, solve_instanced};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `radiosity solve`.
#[derive(clap::Args, Debug)]
pub struct SolveArgs {
    /// Scene file (.obj with its .mtl, or .mgf), a generated scene (`gen:duplex`, ...) or a
    /// validation scene (`validation:ward-room`, ...); the embedded Cornell box when omitted.
    pub scene: Option<PathBuf>,
    /// Output directory.
    #[arg(long, short, default_value = "out")]
    pub out: PathBuf,
    #[command(flatten)]
    pub options: SolveOptions,
    /// Skip rendering image.png.
    #[arg(long)]
    pub no_image: bool,
    /// Image width and height in pixels.
    #[arg(long, default_value_t = 512)]
    pub size: u32,
    /// Refinement oracle: bf (compiled by `oracle!`), bf-dag (interpreted), bf-hand (written by
    /// hand), or a decision-graph file `*.toml`.
    #[arg(long, default_value = "bf")]
    pub oracle: String,
    /// Oracle parameters, `name=value` (eps is set by --eps unless given here).
    #[arg(long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// No progress display and no summary.
    #[arg(long, short)]
    pub quiet: bool,
    /// Accept a solve that a budget (--max-memory) stopped short of its target error: without it
    /// such a solve writes its outputs and stats.json (`target_missed`) and exits with an error.
    #[arg(long)]
    pub allow_over_budget: bool,
    /// Instancing of a plain scene: `none` solves it as given; `auto` finds objects (OBJ objects /
    /// groups) identical up to a rigid transform and solves them as instances of one prototype,
    /// like a `.toml` scene (`patches.csv` is then in flattening order).
    #[arg(long, value_enum, default_value_t = Instances::None)]
    pub instances: Instances,
    /// Instanced scenes: memory (MB) for the local problems kept for reuse by later instances of
    /// the same prototype (0: refine every instance anew; slower, a little less memory).
    #[arg(long, default_value_t = 16.0, value_name = "MB")]
    pub level_cache_mb: f64,
    /// Instanced scenes: `scene` reuses a refined level for later instances anywhere in the scene;
    /// `subtree` only within one top-level instance's subtree, so that results depend on the
    /// subtree alone: what a run over MPI ranks does (feature `mpi`), byte for byte.
    #[arg(long, default_value = "scene", value_name = "SCOPE")]
    pub level_reuse: radiosity::instancing::LevelReuse,
    /// Instanced scenes: which nesting depths keep their instances closed: `all`, `every-N`
    /// (depths N, 2N, ...; the others are opened in place), or `none` (one flattened problem).
    #[arg(long, default_value = "all", value_name = "POLICY")]
    pub instance_levels: radiosity::instancing::InstanceLevels,
    /// Instanced scenes: point pairs per (polygon, light) from which the direct light of the top
    /// level's lights is ray traced below it, through every instance's own geometry (0: carried by
    /// the parallel beams into each instance, with the instance's average visibility).
    #[arg(long, default_value_t = radiosity::instancing::InstancedConfig::default().direct_samples, value_name = "N")]
    pub direct_samples: u32,
    /// Instanced scenes: how a closed instance re-emits the light it intercepts: `directional`
    /// (through the faces of its box its prototype's face transfer matrix says) or `uniform`
    /// (back through the face it entered, with the mean albedo: the paper's proxy).
    #[arg(long, default_value_t = radiosity::instancing::InstancedConfig::default().proxy_emission, value_name = "MODE")]
    pub proxy_emission: radiosity::instancing::ProxyEmission,
    /// Plain scenes: solve again (build, refine, solve; same results) until this many seconds have
    /// passed, and report each phase's fastest time in `stats.json` (`time_s.runs` says how many
    /// solves; outputs come from the first). For timing small scenes on a noisy machine.
    #[arg(long, default_value_t = 0.0, value_name = "SECONDS")]
    pub time_for: f64,
    /// Calculation points: a CSV file of rows `x,y,z,nx,ny,nz` or `name,x,y,z,nx,ny,nz` (or a
    /// header naming those columns, in any order). Writes points.csv: the irradiance gathered from
    /// the solution on a small receiver at each point facing its normal, per channel and photopic.
    /// Plain scenes only: refused for instanced scenes and `--instances auto`.
    #[arg(long, value_name = "FILE.csv")]
    pub points: Option<PathBuf>,
    /// Calculation grid (repeatable): `name=NAME,origin=X;Y;Z,u=X;Y;Z,v=X;Y;Z,spacing=S` and
    /// optionally `,normal=X;Y;Z` (default u × v): the parallelogram origin + s·u + t·v cut into
    /// cells at most `spacing` wide, a point facing `normal` at each cell's centre. Writes
    /// grid_NAME.csv (as points.csv), grid_NAME.svg (isolux plot) and the figures (e_avg, e_min,
    /// e_max, u0, e_min/e_max) to stats.json under `grids`. Plain scenes only.
    #[arg(long = "grid", value_name = "SPEC")]
    pub grids: Vec<String>,
    /// A grid named `work` this high (scene units) above the floor, facing up, over the floor's
    /// extent less a border zone (EN 12464-1: 0.5 m). The floor: the polygons facing up (within 1°
    /// of the --up axis) at the lowest height among them; their bounding rectangle is the extent.
    #[arg(long, value_name = "HEIGHT")]
    pub work_plane: Option<f64>,
    /// The scene's up axis, for --work-plane.
    #[arg(long, value_enum, default_value_t = Up::Z)]
    pub up: Up,
    /// Width of the border zone left out of --work-plane (scene units; EN 12464-1: 0.5 m).
    #[arg(long, default_value_t = radiosity::points::grid::EN12464_BORDER_M, value_name = "WIDTH")]
    pub work_plane_border: f64,
    /// Largest spacing of the --work-plane points (scene units; default EN 12464-1's
    /// 0.2·5^log10(d), d the longer side).
    #[arg(long, value_name = "SPACING")]
    pub work_plane_spacing: Option<f64>,
    #[command(flatten)]
    pub picture: PictureArgs,
}

/// Values of `--up`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Up {
    /// +x is up.
    X,
    /// +y is up.
    Y,
    /// +z is up.
    Z,
}

impl Up {
    fn axis(self) -> radiosity::points::grid::UpAxis {
        use radiosity::points::grid::UpAxis;
        match self {
            Up::X => UpAxis::X,
            Up::Y => UpAxis::Y,
            Up::Z => UpAxis::Z,
        }
    }
}

/// Values of `--instances`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Instances {
    /// Solve the scene as given.
    None,
    /// Instance repeated objects automatically.
    Auto,
}

/// Runs `radiosity solve`: checks the arguments, then solves the scene the way it asks (instanced,
/// instanced automatically, or plain) and writes the outputs.
pub fn run(args: &SolveArgs) -> anyhow::Result<()> {
    check_args(args)?;
    let (view, false_colour) = args.picture.settings(args.instances == Instances::Auto)?;
    let lit = match scene_file(args)? {
        SceneFile::Instanced(scene, bands) => {
            refuse_plain_only(args)?;
            return solve_instanced(args, &scene, None, &bands);
        }
        SceneFile::Plain(lit) => lit,
    };
    #[cfg(feature = "mpi")]
    super::mpi::refuse_plain()?;
    if args.instances == Instances::Auto {
        return solve_auto_instanced(args);
    }
    plain::solve(args, lit, view, false_colour)
}

/// The checks on arguments that need no scene.
fn check_args(args: &SolveArgs) -> anyhow::Result<()> {
    args.options.validate()?;
    anyhow::ensure!(
        args.time_for.is_finite() && (0.0..=3600.0).contains(&args.time_for),
        "--time-for must be between 0 and 3600 s, got {}",
        args.time_for
    );
    anyhow::ensure!((1..=16384).contains(&args.size), "--size must be between 1 and 16384, got {}", args.size);
    anyhow::ensure!(
        args.level_cache_mb.is_finite() && (0.0..=1e6).contains(&args.level_cache_mb),
        "--level-cache-mb must be between 0 and 1e6, got {}",
        args.level_cache_mb
    );
    anyhow::ensure!(
        !has_grids(args) || args.instances == Instances::None,
        "--grid and --work-plane apply to plain scenes, not to --instances auto"
    );
    Ok(())
}

/// Whether the command line asks for grids.
fn has_grids(args: &SolveArgs) -> bool {
    !args.grids.is_empty() || args.work_plane.is_some()
}

/// What a scene file (`.toml`) asks for: the instanced solve, or a plain solve of its flattened
/// scene (`None` for any other scene, which the plain route loads itself).
enum SceneFile {
    Instanced(radiosity::instancing::InstancedScene, radiosity::instancing::bands::Bands),
    Plain(Option<plain::LitScene>),
}

/// Reads a scene file and picks its route: a scene file with luminaires, photometric units or
/// grids is flattened and solved as a plain scene.
fn scene_file(args: &SolveArgs) -> anyhow::Result<SceneFile> {
    let Some(path) = args.scene.as_ref().filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"))) else {
        return Ok(SceneFile::Plain(None));
    };
    let (scene, lighting) = radiosity::instancing::load_with_lighting(path)?;
    // Daylight on a scene without instances takes the plain solve, which splits elements
    // along the sun's shadows and refines to the error target; with instances, the instanced
    // solve traces it through the nested BVHs.
    let flat_daylight = lighting.bands.has_daylight() && scene.prototypes[scene.root as usize].instances.is_empty();
    if !(lighting.needs_plain_solve() || flat_daylight || !scene.grids.is_empty() || has_grids(args)) {
        return Ok(SceneFile::Instanced(scene, lighting.bands));
    }
    anyhow::ensure!(args.instances == Instances::None, "--instances auto applies to plain OBJ / MGF scenes");
    let instanced = !scene.prototypes[scene.root as usize].instances.is_empty();
    if instanced && lighting.bands.packs() > 1 && !args.quiet {
        eprintln!(
            "note: {} bands: the scene is flattened and solved plain, one solve per three bands \
             (up to three bands solve instanced, which on plants is much faster)",
            lighting.bands.len()
        );
    }
    let mut plain = radiosity::instancing::flatten(&scene, &radiosity::instancing::FlattenOptions::default())?;
    plain.luminaires = lighting.luminaires;
    plain.units = lighting.units;
    plain.distant = lighting.bands.pack_distant(0);
    // Under the sun and sky a lone face whose back can receive light is two-sided.
    radiosity::daylight::two_sided_where_backs_see_light(&mut plain);
    let bands = (lighting.bands.declared || lighting.bands.has_daylight()).then_some(lighting.bands);
    Ok(SceneFile::Plain(Some(plain::LitScene { scene: plain, bands, grids: scene.grids.clone() })))
}

/// `--instances auto`: finds the repeated objects of a plain scene and solves it instanced.
fn solve_auto_instanced(args: &SolveArgs) -> anyhow::Result<()> {
    refuse_plain_only(args)?;
    let scene = load_scene(args.scene.as_ref(), args.options.common.allow_dark)?;
    let t0 = Instant::now();
    let auto = radiosity::instancing::auto_instance(&scene, &radiosity::instancing::AutoOptions::default());
    if !args.quiet {
        if let Some(w) = scene.warnings.summary() {
            eprintln!("warning: {w}");
        }
        println!("{} in {:.3}s", auto.report, t0.elapsed().as_secs_f64());
    }
    solve_instanced(args, &auto.scene, Some(&auto.report), &radiosity::instancing::bands::Bands::default())
}
