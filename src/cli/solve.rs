//! `radiosity solve`.

use super::progress::Reporter;
use super::{SolveOptions, load_scene};
use anyhow::Context;
use radiosity::output::{self, OutputConfig, Stats};
use radiosity::pipeline;
use radiosity::refine::{BfHand, BfParams};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `radiosity solve`.
#[derive(clap::Args, Debug)]
pub struct SolveArgs {
    /// Scene file (.obj with its .mtl, or .mgf); the embedded Cornell box when omitted.
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
    /// No progress display and no summary.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `radiosity solve`.
pub fn run(args: &SolveArgs) -> anyhow::Result<()> {
    args.options.validate()?;
    anyhow::ensure!((1..=16384).contains(&args.size), "--size must be between 1 and 16384, got {}", args.size);
    let t0 = Instant::now();
    let reporter = Reporter::new(args.quiet);
    reporter.phase("loading scene");
    let scene = load_scene(args.scene.as_ref(), args.options.common.allow_dark)?;
    let load = t0.elapsed().as_secs_f64();
    let oracle = BfHand { params: BfParams { eps: args.options.eps } };
    let config = args.options.config();
    let solved = pipeline::run(&scene, &oracle, &config, &|p| reporter.event(p));
    reporter.phase("writing outputs");
    let t_out = Instant::now();
    let params = serde_json::json!({
        "eps": args.options.eps,
        "rays": args.options.common.rays,
        "seed": args.options.common.seed,
        "min_area": args.options.common.min_area,
        "visibility": !args.options.common.no_visibility,
    });
    let mut stats = Stats::from_solved(&scene, &solved, "bf-hand", params, (load, 0.0, 0.0));
    let out_config = OutputConfig { image: !args.no_image, render: output::RenderConfig { width: args.size, height: args.size, ..Default::default() } };
    // Write once to measure the output time, then rewrite stats.json with the final figures.
    output::write_all(&args.out, &scene, &solved, &stats, &out_config)?;
    stats.time_s.output = t_out.elapsed().as_secs_f64();
    stats.time_s.total = t0.elapsed().as_secs_f64();
    stats.peak_rss_bytes = output::peak_rss_bytes();
    let path = args.out.join("stats.json");
    let json = serde_json::to_string_pretty(&stats).context("serialising stats")?;
    std::fs::write(&path, json + "\n").with_context(|| format!("{}: cannot write", path.display()))?;
    reporter.finish();
    if !args.quiet {
        print_summary(&stats, &args.out);
    }
    Ok(())
}

fn print_summary(s: &Stats, out: &std::path::Path) {
    let w = &s.warnings;
    if w.degenerate_faces + w.triangulated_faces + w.clamped_materials > 0 {
        eprintln!(
            "warning: {} degenerate faces skipped, {} faces triangulated, {} materials clamped",
            w.degenerate_faces, w.triangulated_faces, w.clamped_materials
        );
    }
    let balance = if s.power_emitted > 0.0 { s.power_absorbed / s.power_emitted } else { f64::NAN };
    println!(
        "{}: {} polygons, {} elements ({} leaves), {} links, {} rays, {} iterations (residual {:.1e})",
        s.scene, s.polygons, s.elements, s.leaves, s.links, s.rays, s.iterations, s.residual
    );
    println!(
        "time: load {:.3}s build {:.3}s refine {:.3}s solve {:.3}s output {:.3}s total {:.3}s; peak RSS {}",
        s.time_s.load,
        s.time_s.build,
        s.time_s.refine,
        s.time_s.solve,
        s.time_s.output,
        s.time_s.total,
        s.peak_rss_bytes.map_or("n/a".to_string(), |b| format!("{:.1} MB", b as f64 / 1e6))
    );
    if s.left_out.is_empty() {
        println!("left out: nothing (the scene needs every part of the solver)");
    } else {
        println!("left out: {}", s.left_out.join("; "));
    }
    if let Some(e) = s.error_estimate {
        println!("error estimate: {:.2}% of the largest radiosity (one-step residual against a full-resolution gather), in {:.3}s", 100.0 * e, s.time_s.total);
    }
    println!("power: emitted {:.6e} W, absorbed {:.6e} W (ratio {:.5})", s.power_emitted, s.power_absorbed, balance);
    println!("wrote {}/{{image.png,solution.ply,patches.csv,stats.json}}", out.display());
}
