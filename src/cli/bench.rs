//! `radiosity bench ...`: tables for people, JSON with `--json`. Each scene is solved in a child
//! process (this binary re-running itself) so that its peak RSS is its own.
//!
//! This file holds the list of benchmarks, the small ones (`solve`, `leave-out`, `oracle`) and the
//! helpers the others share; each larger family has its own `bench_*.rs` beside it.

use super::SolveOptions;
pub use super::bench_instancing::InstancingBenchArgs;
use super::bench_instancing::bench_instancing;
pub use super::bench_shafts::ShaftBenchArgs;
use super::bench_shafts::bench_shafts;
use anyhow::Context;
use std::path::PathBuf;
use std::process::Command;

/// Benchmarks.
#[derive(clap::Subcommand, Debug)]
pub enum BenchCommand {
    /// Full solves: elements, links, rays, time per phase and peak RSS per scene.
    Solve(SolveBenchArgs),
    /// The three BF releases (hand-written, DAG runtime, `oracle!`) side by side: refinement time
    /// and ratio to hand-written, and whether links and radiosity are identical.
    Oracle(OracleBenchArgs),
    /// Visibility by plain rays vs AABB and OBB shafts: links, elements, rays, time, peak RSS and the
    /// largest difference to the rays solution, per scene; plain rays with the next seed give the
    /// noise of both.
    Shafts(ShaftBenchArgs),
    /// A generated tree solved fully (flattened, with clustering) and by hierarchical
    /// instantiation, each in its own process: time, peak RSS, links, and the instanced solution's
    /// error as a percentage of the full solution's largest radiosity.
    Instancing(InstancingBenchArgs),
    /// What leaving out unneeded machinery saves: each scene solved with and without the scene
    /// analysis.
    LeaveOut(LeaveOutArgs),
    /// The validation scenes (exact or independently computed answers) at a range of eps and at
    /// the default target error: time, peak RSS, leaves, links, true error, estimate, power
    /// balance.
    Accuracy(super::bench_accuracy::AccuracyBenchArgs),
    /// Canopies of transmitting leaves in two bands under the sun and a sky, at the default
    /// settings, each in its own process: time, peak RSS, links, estimate, balance, and the
    /// leaves' and ground's absorbed power against an independent photon tracer.
    Canopy(super::bench_canopy::CanopyBenchArgs),
    /// Interiors lit by many small emitters (RenderPark's scenes by path, and generated ones) at a
    /// range of target errors against a finer solve: time, peak RSS, links, the estimate and the
    /// true errors of the polygons and of the worst material, beside RenderPark's default figures.
    Renderpark(super::bench_renderpark::RenderParkBenchArgs),
}

/// Arguments of `bench oracle`.
#[derive(clap::Args, Debug)]
pub struct OracleBenchArgs {
    /// Threshold.
    #[arg(long, default_value_t = 0.01)]
    pub eps: f64,
    /// Runs per release (the fastest counts).
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `bench leave-out`.
#[derive(clap::Args, Debug)]
pub struct LeaveOutArgs {
    /// Threshold.
    #[arg(long, default_value_t = 0.05)]
    pub eps: f64,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `bench solve`.
#[derive(clap::Args, Debug)]
pub struct SolveBenchArgs {
    /// Scene files; `cornell` is the embedded Cornell box (the default when none is given).
    pub scenes: Vec<String>,
    #[command(flatten)]
    pub options: SolveOptions,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Runs a benchmark.
pub fn run(which: BenchCommand) -> anyhow::Result<()> {
    match which {
        BenchCommand::Solve(args) => bench_solve(&args),
        BenchCommand::LeaveOut(args) => bench_leave_out(&args),
        BenchCommand::Oracle(args) => bench_oracle(&args),
        BenchCommand::Instancing(args) => bench_instancing(&args),
        BenchCommand::Shafts(args) => bench_shafts(&args),
        BenchCommand::Accuracy(args) => super::bench_accuracy::run(&args),
        BenchCommand::Canopy(args) => super::bench_canopy::run(&args),
        BenchCommand::Renderpark(args) => super::bench_renderpark::run(&args),
    }
}

/// RenderPark's Galerkin hierarchical radiosity with clustering at its defaults on this machine
/// class (CPU seconds, peak RSS in MB; `shared/notes/crates.md`), for the scenes it was measured
/// on, by file name; `>` where it had not finished.
pub(super) fn renderpark_reference(name: &str) -> Option<(&'static str, &'static str)> {
    match name {
        "cube.mgf" => Some(("0.31", "19")),
        "office2.mgf" => Some(("3.5", "46")),
        "office3.mgf" | "office.mgf" => Some(("96", "193")),
        "classroom.mgf" => Some(("147", "599")),
        "soda.mgf" => Some((">233 (unfinished)", ">677")),
        _ => None,
    }
}

/// Waits for `child`, killing it after `timeout` seconds: its exit status, `None` when killed.
pub(super) fn wait_or_kill(child: &mut std::process::Child, timeout: f64) -> std::io::Result<Option<std::process::ExitStatus>> {
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait()? {
            return Ok(Some(status));
        }
        if start.elapsed().as_secs_f64() > timeout {
            child.kill().ok();
            child.wait().ok();
            return Ok(None);
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

fn bench_solve(args: &SolveBenchArgs) -> anyhow::Result<()> {
    args.options.validate()?;
    let scenes = if args.scenes.is_empty() { vec!["cornell".to_string()] } else { args.scenes.clone() };
    let exe = std::env::current_exe().context("locating this executable")?;
    let tmp = std::env::temp_dir().join(format!("radiosity-bench-{}", std::process::id()));
    let mut rows = Vec::new();
    if !args.json {
        print_header();
    }
    for (i, scene) in scenes.iter().enumerate() {
        let stats = child_solve(&exe, scene, &args.options, None, None, 0.0, &tmp.join(format!("{i}")))?;
        if !args.json {
            print_row(scene, &stats);
        }
        rows.push((scene.clone(), stats));
    }
    let _ = std::fs::remove_dir_all(&tmp);
    if args.json {
        let doc: Vec<serde_json::Value> = rows
            .iter()
            .map(|(scene, s)| {
                serde_json::json!({
                    "scene": scene, "polygons": s["polygons"], "elements": s["elements"], "links": s["links"],
                    "rays": s["rays"], "iterations": s["iterations"], "time_s": s["time_s"], "peak_rss_bytes": s["peak_rss_bytes"],
                    "error_estimate": s["error_estimate"],
                })
            })
            .collect();
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(());
    }
    Ok(())
}

fn print_header() {
    println!(
        "{:<16} {:>8} {:>9} {:>10} {:>11} {:>6} {:>8} {:>8} {:>8} {:>8} {:>9} {:>22}",
        "scene",
        "polygons",
        "elements",
        "links",
        "rays",
        "iters",
        "build_s",
        "refine_s",
        "solve_s",
        "total_s",
        "peak_MB",
        "RenderPark s / MB"
    );
}

fn print_row(scene: &str, s: &serde_json::Value) {
    let name = std::path::Path::new(scene).file_name().and_then(|n| n.to_str()).unwrap_or(scene);
    let t = &s["time_s"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    let rp = renderpark_reference(name).map_or("-".to_string(), |(t, m)| format!("{t} / {m}"));
    println!(
        "{:<16} {:>8} {:>9} {:>10} {:>11} {:>6} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>9.1} {:>8.3} {:>22}",
        name,
        s["polygons"].as_u64().unwrap_or(0),
        s["elements"].as_u64().unwrap_or(0),
        s["links"].as_u64().unwrap_or(0),
        s["rays"].as_u64().unwrap_or(0),
        s["iterations"].as_u64().unwrap_or(0),
        f(&t["build"]),
        f(&t["refine"]),
        f(&t["solve"]),
        f(&t["total"]),
        f(&s["peak_rss_bytes"]) / 1e6,
        100.0 * f(&s["error_estimate"]),
        rp
    );
}

fn bench_leave_out(args: &LeaveOutArgs) -> anyhow::Result<()> {
    use radiosity::geom::DVec3;
    use radiosity::pipeline::{self, Config};
    use radiosity::refine::{BfHand, BfParams};
    use std::time::Instant;
    anyhow::ensure!(args.eps.is_finite() && args.eps > 0.0, "--eps must be positive");
    let scenes = vec![
        ("furnace box (convex)", radiosity::scene::shapes::furnace_box(DVec3::new(1.0, 1.3, 0.8), 0.8, 1.0)),
        ("cornell box", radiosity::scene::cornell_box()),
    ];
    let oracle = BfHand { params: BfParams { eps: args.eps } };
    let mut rows = Vec::new();
    for (name, scene) in &scenes {
        let mut timed = Vec::new();
        for analyse in [false, true] {
            let mut config = Config { analyse, ..Config::default() };
            config.build.min_area_rel = 1e-4;
            let t = Instant::now();
            let solved = pipeline::run(scene, &oracle, &config, &|_| {});
            timed.push((t.elapsed().as_secs_f64(), solved.rays, solved.left_out.clone(), solved.links.len()));
        }
        rows.push((name, timed));
    }
    if args.json {
        let doc: Vec<serde_json::Value> = rows
            .iter()
            .map(|(name, t)| {
                serde_json::json!({"scene": name, "full_s": t[0].0, "full_rays": t[0].1, "specialised_s": t[1].0,
                    "specialised_rays": t[1].1, "left_out": t[1].2, "links": t[1].3})
            })
            .collect();
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(());
    }
    println!("{:<22} {:>8} {:>10} {:>10} {:>10} {:>7}  left out", "scene", "links", "full_s", "special_s", "rays_full", "ratio");
    for (name, t) in &rows {
        let left = if t[1].2.is_empty() { "nothing".to_string() } else { t[1].2.join("; ") };
        println!("{:<22} {:>8} {:>10.3} {:>10.3} {:>10} {:>7.2}  {}", name, t[1].3, t[0].0, t[1].0, t[0].1, t[0].0 / t[1].0, left);
    }
    Ok(())
}

fn bench_oracle(args: &OracleBenchArgs) -> anyhow::Result<()> {
    use radiosity::lab::bench;
    use radiosity::oracle::scenes;
    anyhow::ensure!(args.eps.is_finite() && args.eps > 0.0, "--eps must be positive");
    anyhow::ensure!(args.repeats >= 1, "--repeats must be at least 1");
    let config = bench::BenchConfig { eps: args.eps, repeats: args.repeats, ..bench::BenchConfig::default() };
    let rows = bench::run(&scenes::bench_scenes(), &config);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        print!("{}", bench::format_table(&rows));
    }
    anyhow::ensure!(rows.iter().all(|r| r.identical), "the three releases disagree on some scene");
    Ok(())
}

/// Solves `scene` in a child process into `out` (with `--visibility` when given) and returns its
/// `stats.json`.
pub(super) fn child_solve(
    exe: &std::path::Path,
    scene: &str,
    o: &SolveOptions,
    visibility: Option<&str>,
    oracle: Option<&str>,
    time_for: f64,
    out: &std::path::Path,
) -> anyhow::Result<serde_json::Value> {
    let mut cmd = Command::new(exe);
    cmd.arg("solve").arg("--quiet").arg("--no-image").arg("--out").arg(out).arg("--time-for").arg(time_for.to_string());
    if !super::GENERATED_SCENES.contains(&scene) {
        let p = PathBuf::from(scene);
        anyhow::ensure!(p.exists(), "{scene}: no such file");
    }
    cmd.arg(scene);
    cmd.args([
        "--eps",
        &o.eps().to_string(),
        "--rays",
        &o.common.rays.to_string(),
        "--seed",
        &o.common.seed.to_string(),
        "--min-area",
        &o.common.min_area.to_string(),
    ]);
    if let Some(v) = visibility {
        cmd.args(["--visibility", v]);
    }
    if let Some(name) = oracle {
        cmd.args(["--oracle", name]);
    }
    if o.common.allow_dark {
        cmd.arg("--allow-dark");
    }
    if o.common.no_visibility {
        cmd.arg("--no-visibility");
    }
    let status = cmd.status().with_context(|| format!("running {}", exe.display()))?;
    anyhow::ensure!(status.success(), "{scene}: solve failed ({status})");
    let path = out.join("stats.json");
    let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{}: invalid JSON", path.display()))
}
