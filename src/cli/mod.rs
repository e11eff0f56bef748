//! Subcommands.

mod bench;
mod bench_accuracy;
mod bench_canopy;
mod bench_instancing;
mod bench_reference;
mod bench_renderpark;
mod bench_shafts;
mod generate;
#[cfg(feature = "mpi")]
pub mod mpi;
mod oracle;
mod picture;
mod progress;
mod solve;
mod study;
mod sweep;

use anyhow::Context;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};

/// Hierarchical radiosity with refinement oracles as decision graphs.
#[derive(Parser, Debug)]
#[command(name = "radiosity", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Solve a scene (OBJ or MGF; the embedded Cornell box when none is given) and write
    /// image.png, falsecolor.png, solution.ply, solution.glb, patches.csv and stats.json.
    Solve(solve::SolveArgs),
    /// Error against run time: solves with several oracles and thresholds, compares with a
    /// reference, writes sweep.csv and sweep.svg.
    Sweep(sweep::SweepArgs),
    /// Procedural plants as instanced scenes (solve them with `radiosity solve DIR/tree.toml`).
    Generate {
        #[command(subcommand)]
        which: generate::GenerateCommand,
    },
    /// Refinement oracles: list them, export their graphs, trace their decisions, study their
    /// visibility classification.
    Oracle {
        #[command(subcommand)]
        which: oracle::OracleCommand,
    },
    /// Benchmarks that print tables (and JSON with --json).
    Bench {
        #[command(subcommand)]
        which: bench::BenchCommand,
    },
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    #[cfg(feature = "mpi")]
    if !matches!(cli.command, Command::Solve(_)) {
        mpi::refuse_plain()?;
    }
    match cli.command {
        Command::Solve(args) => solve::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Oracle { which } => oracle::run(which),
        Command::Generate { which } => generate::run(which),
        Command::Bench { which } => bench::run(which),
    }
}

/// Options shared by the commands that solve.
#[derive(clap::Args, Debug, Clone)]
pub struct SolveOptions {
    /// Refinement threshold: every error term of a link is kept below eps times its receiver's
    /// irradiance (divided by how often light is reflected in the scene). With --eps and no
    /// --target-error, refinement stops at this eps; with --target-error it is where the levels
    /// start from (divided by 4 per level, after two levels at 16 and 4 times it).
    #[arg(long)]
    pub eps: Option<f64>,
    /// Refine, level after level, until the estimated error (the largest error of a non-emitting
    /// polygon's mean radiosity relative to the largest such mean) is below this. The default when
    /// --eps is not given: 0.01.
    #[arg(long, value_name = "X")]
    pub target_error: Option<f64>,
    #[command(flatten)]
    pub common: CommonOptions,
}

/// The target error of a solve given neither `--eps` nor `--target-error`.
pub const DEFAULT_TARGET_ERROR: f64 = 0.01;

/// Solver options other than the threshold.
#[derive(clap::Args, Debug, Clone)]
pub struct CommonOptions {
    /// Visibility rays per link.
    #[arg(long, default_value_t = radiosity::visibility::VisibilityConfig::default().rays)]
    pub rays: u32,
    /// Seed of the visibility sampling.
    #[arg(long, default_value_t = radiosity::visibility::VisibilityConfig::default().seed)]
    pub seed: u64,
    /// Smallest element, as a fraction of the scene's total area (every polygon may still be quartered
    /// 6 times, down to 1/4096 of its own area).
    #[arg(long, default_value_t = radiosity::hierarchy::BuildConfig::default().min_area_rel)]
    pub min_area: f64,
    /// Accept a scene with no emitter.
    #[arg(long)]
    pub allow_dark: bool,
    /// Take every link as fully visible (no rays).
    #[arg(long)]
    pub no_visibility: bool,
    /// Visibility: `rays` (every triangle, through a BVH) or shaft culling with `aabb`, `obb` or
    /// `hull` bounding volumes.
    #[arg(long, default_value = "rays", value_parser = ["rays", "aabb", "obb", "hull"])]
    pub visibility: String,
    /// What the link criteria bound the error of: `radiosity` (B = E + ρH: a shadow within a
    /// receiver counts in proportion to its reflectance) or `irradiance` (H, whatever the
    /// reflectance: black sensors and dark floors refined like white walls).
    #[arg(long, default_value = "irradiance", value_parser = ["radiosity", "irradiance"])]
    pub criterion: String,
    /// Under a target error, refine every polygon at every level, instead of only those whose own
    /// estimate is over half the target and where they get a tenth of their light or more from
    /// (from the third level on).
    #[arg(long)]
    pub global_levels: bool,
    /// Memory refinement may use, MB (default: half the machine's physical memory): beyond it no
    /// link is subdivided any more, and stats.json says so.
    #[arg(long, value_name = "MB")]
    pub max_memory: Option<f64>,
}

impl SolveOptions {
    /// Checks the values clap cannot.
    pub fn validate(&self) -> anyhow::Result<()> {
        if let Some(eps) = self.eps {
            anyhow::ensure!(eps.is_finite() && eps > 0.0 && eps <= 1.0, "--eps must be a number in (0, 1], got {eps}");
        }
        if let Some(t) = self.target_error {
            anyhow::ensure!(t.is_finite() && t > 0.0 && t < 1.0, "--target-error must be a number in (0, 1), got {t}");
        }
        self.common.validate()
    }

    /// The oracle's eps: `--eps`, or the BF default.
    pub fn eps(&self) -> f64 {
        self.eps.unwrap_or(radiosity::refine::BfParams::default().eps)
    }

    /// The target error: `--target-error`, or [`DEFAULT_TARGET_ERROR`] when neither it nor `--eps`
    /// is given.
    pub fn target_error(&self) -> Option<f64> {
        self.target_error.or(if self.eps.is_none() { Some(DEFAULT_TARGET_ERROR) } else { None })
    }

    /// The pipeline configuration these options describe.
    pub fn config(&self) -> radiosity::pipeline::Config {
        let mut config = self.common.config();
        config.target_error = self.target_error();
        config
    }
}

impl CommonOptions {
    /// Checks the values clap cannot.
    pub fn validate(&self) -> anyhow::Result<()> {
        anyhow::ensure!(self.rays >= 1, "--rays must be at least 1");
        anyhow::ensure!(
            self.min_area.is_finite() && self.min_area > 0.0 && self.min_area < 1.0,
            "--min-area must be in (0, 1), got {}",
            self.min_area
        );
        if let Some(mb) = self.max_memory {
            anyhow::ensure!(mb.is_finite() && mb >= 1.0, "--max-memory must be at least 1 (MB), got {mb}");
        }
        Ok(())
    }

    /// The pipeline configuration these options describe.
    pub fn config(&self) -> radiosity::pipeline::Config {
        let mut config = radiosity::pipeline::Config::default();
        config.visibility.rays = self.rays;
        config.visibility.seed = self.seed;
        config.build.min_area_rel = self.min_area;
        config.use_visibility = !self.no_visibility;
        config.local_levels = !self.global_levels;
        // clap accepts only the names `VisibilityMethod::name` gives.
        use radiosity::pipeline::VisibilityMethod;
        config.visibility_method = VisibilityMethod::from_name(&self.visibility).unwrap_or(VisibilityMethod::Rays);
        // clap accepts only the names `Criterion::name` gives.
        config.criterion = radiosity::refine::Criterion::from_name(&self.criterion).unwrap_or_default();
        if let Some(mb) = self.max_memory {
            config.max_memory_bytes = (mb * 1e6) as usize;
        }
        config
    }
}

/// `SCENE` names beginning with this name a validation scene ([`radiosity::validation::cases`]):
/// `validation:ward-room`, `validation:cie58-rho0.7`, ...
pub const VALIDATION_PREFIX: &str = "validation:";

/// Scenes generated by name instead of loaded from a file.
pub const GENERATED_SCENES: &[&str] = radiosity::scene::generated::NAMES;

/// Loads `path`, or the embedded Cornell box when `None`; the names of [`GENERATED_SCENES`] build
/// a generated scene.
pub fn load_scene(path: Option<&PathBuf>, allow_dark: bool) -> anyhow::Result<radiosity::scene::Scene> {
    let Some(path) = path else { return Ok(radiosity::scene::cornell_box()) };
    if let Some(scene) = path.to_str().and_then(radiosity::scene::generated::by_name) {
        return Ok(scene);
    }
    // The validation scenes, whose exact or converged answers ship with the project.
    if let Some(name) = path.to_str().and_then(|p| p.strip_prefix(VALIDATION_PREFIX)) {
        let cases = radiosity::validation::cases();
        let names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
        let Some(case) = cases.iter().find(|c| c.name == name) else {
            anyhow::bail!("{}: no such validation scene (there are: {})", path.display(), names.join(", "));
        };
        return Ok(case.scene.clone());
    }
    Ok(radiosity::scene::load(path, &radiosity::scene::LoadOptions { allow_dark })?)
}

/// Reads `b_r,b_g,b_b` of a `patches.csv`.
pub fn read_patches(path: &Path) -> anyhow::Result<Vec<[f64; 3]>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).with_context(|| format!("{}: no column `{name}`", path.display()));
    let (r, g, b) = (col("b_r")?, col("b_g")?, col("b_b")?);
    lines
        .enumerate()
        .map(|(i, line)| {
            // The group and material columns are plain names (no commas) in files we write.
            let f: Vec<&str> = line.split(',').collect();
            let num = |k: usize| -> anyhow::Result<f64> {
                f.get(k).and_then(|s| s.parse().ok()).with_context(|| format!("{}:{}: bad number in column {k}", path.display(), i + 2))
            };
            Ok([num(r)?, num(g)?, num(b)?])
        })
        .collect()
}
