//! Subcommands.

mod bench;
mod generate;
mod oracle;
mod progress;
mod solve;
mod sweep;

use clap::{Parser, Subcommand};
use std::path::PathBuf;

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
    /// image.png, solution.ply, patches.csv and stats.json.
    Solve(solve::SolveArgs),
    /// Error against run time: solves with several oracles and thresholds, compares with a
    /// reference, writes sweep.csv and sweep.svg.
    Sweep(sweep::SweepArgs),
    /// Procedural plants as instanced scenes (solve them with `radiosity solve DIR/tree.toml`).
    Generate {
        #[command(subcommand)]
        which: generate::GenerateCommand,
    },
    /// Refinement oracles: list them, export their graphs, trace their decisions.
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
    /// Refinement threshold: links are refined while B·F exceeds eps times the brightest expected
    /// radiosity.
    #[arg(long, default_value_t = radiosity::refine::BfParams::default().eps)]
    pub eps: f64,
    #[command(flatten)]
    pub common: CommonOptions,
}

/// Solver options other than the threshold.
#[derive(clap::Args, Debug, Clone)]
pub struct CommonOptions {
    /// Visibility rays per link.
    #[arg(long, default_value_t = radiosity::visibility::VisibilityConfig::default().rays)]
    pub rays: u32,
    /// Seed of the visibility sampling.
    #[arg(long, default_value_t = radiosity::visibility::VisibilityConfig::default().seed)]
    pub seed: u64,
    /// Smallest element, as a fraction of the scene's total area.
    #[arg(long, default_value_t = radiosity::hierarchy::BuildConfig::default().min_area_rel)]
    pub min_area: f64,
    /// Accept a scene with no emitter.
    #[arg(long)]
    pub allow_dark: bool,
    /// Take every link as fully visible (no rays).
    #[arg(long)]
    pub no_visibility: bool,
}

impl SolveOptions {
    /// Checks the values clap cannot.
    pub fn validate(&self) -> anyhow::Result<()> {
        anyhow::ensure!(self.eps.is_finite() && self.eps > 0.0, "--eps must be a positive number, got {}", self.eps);
        self.common.validate()
    }

    /// The pipeline configuration these options describe.
    pub fn config(&self) -> radiosity::pipeline::Config {
        self.common.config()
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
        Ok(())
    }

    /// The pipeline configuration these options describe.
    pub fn config(&self) -> radiosity::pipeline::Config {
        let mut config = radiosity::pipeline::Config::default();
        config.visibility.rays = self.rays;
        config.visibility.seed = self.seed;
        config.build.min_area_rel = self.min_area;
        config.use_visibility = !self.no_visibility;
        config
    }
}

/// Loads `path`, or the embedded Cornell box when `None`.
pub fn load_scene(path: Option<&PathBuf>, allow_dark: bool) -> anyhow::Result<radiosity::scene::Scene> {
    match path {
        None => Ok(radiosity::scene::cornell_box()),
        Some(p) => Ok(radiosity::scene::load(p, &radiosity::scene::LoadOptions { allow_dark })?),
    }
}
