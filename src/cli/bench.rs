//! `radiosity bench ...`: tables for people, JSON with `--json`. Each scene is solved in a child
//! process (this binary re-running itself) so that its peak RSS is its own.

use super::SolveOptions;
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

/// Arguments of `bench shafts`.
#[derive(clap::Args, Debug)]
pub struct ShaftBenchArgs {
    /// Scenes (files or generated names); default: cornell and the generated duplex, sj-geometry,
    /// sj-shadow, stairs and rotated scenes.
    pub scenes: Vec<String>,
    #[command(flatten)]
    pub options: SolveOptions,
    /// Rounds of solves per method and scene, interleaved (rays, aabb, obb, aabb/shaft, obb/shaft,
    /// rays/seed+1, rays, ...); the fastest counts.
    #[arg(long, default_value_t = 3)]
    pub repeats: u32,
    /// Each solve after the first round is repeated within its process for this long (`solve
    /// --time-for`): a small scene's phases are then the fastest of many runs.
    #[arg(long, default_value_t = 1.0, value_name = "SECONDS")]
    pub time_for: f64,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `bench instancing`.
#[derive(clap::Args, Debug)]
pub struct InstancingBenchArgs {
    /// Tree age in years.
    #[arg(long, default_value_t = 10)]
    pub age: u32,
    /// Tree seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Refinement threshold of the main comparison; the full solve at this threshold is the
    /// reference of every error printed.
    #[arg(long, default_value_t = 0.05)]
    pub eps: f64,
    /// Coarser thresholds of the error-against-time curve (both methods), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "0.4,0.2,0.1")]
    pub sweep: Vec<f64>,
    /// Forests to solve with instances: target polygon counts (two-sided leaves counted twice, as
    /// the solver sees them), comma-separated; `none` for no forest.
    #[arg(long, value_delimiter = ',', default_value = "1200000")]
    pub forests: Vec<String>,
    /// Folder of `instancing_error_time.csv` and `instancing_error_time.svg`.
    #[arg(long, default_value = "bench-instancing")]
    pub out: std::path::PathBuf,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Which nesting depths the instanced solves keep closed: `all`, `every-N` or `none`.
    #[arg(long, default_value = "all", value_name = "POLICY")]
    pub instance_levels: String,
    /// Point pairs per (polygon, light) from which the instanced solves ray trace the lights'
    /// direct light below the top level (0: the parallel beams carry it).
    #[arg(long, default_value_t = radiosity::instancing::InstancedConfig::default().direct_samples, value_name = "N")]
    pub direct_samples: u32,
    /// How closed instances re-emit the light they intercept: `uniform` (by the face it entered,
    /// the mean albedo) or `directional` (by the faces the prototype's face transfer matrix says).
    #[arg(long, default_value_t = radiosity::instancing::InstancedConfig::default().proxy_emission, value_name = "MODE")]
    pub proxy_emission: radiosity::instancing::ProxyEmission,
    /// Keep the full solve at `--eps` in this file (its figures in FILE.json) and, when it holds
    /// one of the same tree and threshold, reuse it instead of solving again.
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
    /// Internal: run one method (`full` or `instanced`) and write its per-polygon means here.
    #[arg(long, hide = true, num_args = 2, value_names = ["METHOD", "FILE"])]
    pub child: Vec<String>,
    /// Internal: solve a generated forest of this many trees with instances and print its row.
    #[arg(long, hide = true)]
    pub forest_child: Option<u32>,
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
    use radiosity::oracle::{bench, scenes};
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
fn child_solve(
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

/// One method's solves of one scene in `bench shafts`.
#[derive(Clone)]
struct ShaftRun {
    /// `stats.json` of the last solve (peak memory: the smallest of the solves).
    stats: serde_json::Value,
    /// Fastest build + refine + solve time (s).
    time: f64,
    /// Fastest refinement time (s).
    refine: f64,
    /// Radiosity per input polygon.
    radiosity: Vec<[f64; 3]>,
    /// Solves timed, over all repeats.
    runs: u64,
}

fn bench_shafts(args: &ShaftBenchArgs) -> anyhow::Result<()> {
    args.options.validate()?;
    anyhow::ensure!((1..=100).contains(&args.repeats), "--repeats must be between 1 and 100");
    anyhow::ensure!(args.time_for.is_finite() && (0.0..=60.0).contains(&args.time_for), "--time-for must be between 0 and 60 s");
    let scenes: Vec<String> =
        if args.scenes.is_empty() { super::GENERATED_SCENES.iter().map(|s| s.to_string()).collect() } else { args.scenes.clone() };
    let exe = std::env::current_exe().context("locating this executable")?;
    let tmp = std::env::temp_dir().join(format!("radiosity-bench-shafts-{}", std::process::id()));
    // (label, visibility, oracle, next seed): with `bf-hand` shafts only cull the rays (links as
    // with plain rays); with the shaft oracle they also decide refinement, so tighter culling
    // means fewer links. The plain-rays reference uses `bf-hand`: the shaft oracle needs shafts.
    // The last method is plain rays again with the next seed: its difference to the first is the
    // ray sampling noise, its speed-up the timing noise.
    const METHODS: [(&str, &str, &str, bool); 6] = [
        ("rays", "rays", "bf-hand", false),
        ("aabb", "aabb", "bf-hand", false),
        ("obb", "obb", "bf-hand", false),
        ("aabb/shaft", "aabb", "shaft", false),
        ("obb/shaft", "obb", "shaft", false),
        ("rays/seed+1", "rays", "bf-hand", true),
    ];
    let mut reseeded = args.options.clone();
    reseeded.common.seed = reseeded.common.seed.wrapping_add(1);
    let mut rows = Vec::new();
    if !args.json {
        println!(
            "{:<18} {:<12} {:>9} {:>9} {:>11} {:>9} {:>9} {:>9} {:>10} {:>8} {:>8} {:>6}",
            "scene", "method", "links", "elements", "rays", "time_s", "refine_s", "peak_MB", "max_diff", "speedup", "refine", "runs"
        );
    }
    for (i, scene) in scenes.iter().enumerate() {
        let mut runs: Vec<Option<ShaftRun>> = vec![None; METHODS.len()];
        for r in 0..args.repeats {
            // The first round solves once per process, for a peak memory that repeated solves
            // (which can only raise it) do not touch; the peak reported is the smallest.
            let time_for = if r == 0 && args.repeats > 1 { 0.0 } else { args.time_for };
            for (m, &(_, visibility, oracle, next_seed)) in METHODS.iter().enumerate() {
                let out = tmp.join(format!("{i}-{m}"));
                let options = if next_seed { &reseeded } else { &args.options };
                let mut s = child_solve(&exe, scene, options, Some(visibility), Some(oracle), time_for, &out)?;
                if let Some(prev) = runs[m].as_ref().and_then(|r| r.stats["peak_rss_bytes"].as_u64()) {
                    let peak = s["peak_rss_bytes"].as_u64().map_or(prev, |p| p.min(prev));
                    s["peak_rss_bytes"] = peak.into();
                }
                let refine = s["time_s"]["refine"].as_f64().unwrap_or(f64::NAN);
                let time = refine + s["time_s"]["build"].as_f64().unwrap_or(0.0) + s["time_s"]["solve"].as_f64().unwrap_or(0.0);
                let (time, refine) = runs[m].as_ref().map_or((time, refine), |r| (r.time.min(time), r.refine.min(refine)));
                let radiosity = super::read_patches(&out.join("patches.csv"))?;
                let timed = s["time_s"]["runs"].as_u64().unwrap_or(1) + runs[m].as_ref().map_or(0, |r| r.runs);
                runs[m] = Some(ShaftRun { stats: s, time, refine, radiosity, runs: timed });
            }
        }
        let ShaftRun { time: rt, refine: rr, radiosity: rb, .. } = runs[0].clone().context("at least one run")?;
        let max = rb.iter().flatten().fold(0.0f64, |m, v| m.max(*v)).max(f64::MIN_POSITIVE);
        for (&(method, visibility, oracle, _), run) in METHODS.iter().zip(runs) {
            let ShaftRun { stats: s, time, refine, radiosity: b, runs: timed } = run.context("at least one run")?;
            let d = rb.iter().zip(&b).flat_map(|(x, y)| (0..3).map(move |c| (x[c] - y[c]).abs())).fold(0.0f64, f64::max);
            let (diff, speedup, refine_speedup) = (d / max, rt / time, rr / refine);
            let row = serde_json::json!({
                "scene": scene, "method": method, "visibility": visibility, "oracle": oracle, "links": s["links"], "elements": s["elements"], "rays": s["rays"],
                "time_s": time, "refine_s": refine, "peak_rss_bytes": s["peak_rss_bytes"], "max_rel_diff_to_rays": diff, "timed_runs": timed,
            });
            if !args.json {
                let name = std::path::Path::new(scene).file_name().and_then(|n| n.to_str()).unwrap_or(scene);
                println!(
                    "{:<18} {:<12} {:>9} {:>9} {:>11} {:>9.3} {:>9.3} {:>9.1} {:>10.2e} {:>8.2} {:>8.2} {:>6}",
                    name,
                    method,
                    s["links"].as_u64().unwrap_or(0),
                    s["elements"].as_u64().unwrap_or(0),
                    s["rays"].as_u64().unwrap_or(0),
                    time,
                    refine,
                    s["peak_rss_bytes"].as_f64().unwrap_or(f64::NAN) / 1e6,
                    diff,
                    speedup,
                    refine_speedup,
                    timed
                );
            }
            rows.push(row);
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    }
    Ok(())
}

fn bench_instancing(args: &InstancingBenchArgs) -> anyhow::Result<()> {
    use radiosity::instancing::bench::{BenchRow, bench_full, bench_instanced, load_means, save_means};
    use radiosity::instancing::solver::{polygons_above, relative_error};
    // Polygons whose error exceeds this fraction of the largest radiosity are counted.
    const ERROR_COUNT_FRACTION: f64 = 0.03;
    use radiosity::instancing::{ForestParams, InstancedConfig, generate_forest, generate_tree};
    anyhow::ensure!((1..=200).contains(&args.age), "--age must be between 1 and 200");
    anyhow::ensure!(args.eps.is_finite() && args.eps > 0.0, "--eps must be positive");
    let instance_levels: radiosity::instancing::InstanceLevels =
        args.instance_levels.parse().map_err(|e: String| anyhow::anyhow!("--instance-levels: {e}"))?;
    let config = |eps: f64| {
        let mut config = InstancedConfig {
            instance_levels,
            direct_samples: args.direct_samples,
            proxy_emission: args.proxy_emission,
            ..InstancedConfig::default()
        };
        config.bf.eps = eps;
        config.cache_dir = Some(std::env::temp_dir().join("radiosity-instancing-cache"));
        config
    };
    let forest = |trees: u32| generate_forest(&ForestParams { trees, seed: args.seed, ..ForestParams::default() });
    if let Some(trees) = args.forest_child {
        let scene = forest(trees);
        let (row, _) = bench_instanced(&scene, &config(args.eps), false)?;
        println!("{}", serde_json::to_string(&row)?);
        return Ok(());
    }
    if let [method, file] = args.child.as_slice() {
        let scene = generate_tree(args.age, args.seed);
        let (row, means) = match method.as_str() {
            "full" => {
                let (row, means) = bench_full(&scene, &config(args.eps))?;
                (row, Some(means))
            }
            "instanced" => bench_instanced(&scene, &config(args.eps), true)?,
            other => anyhow::bail!("unknown method `{other}`"),
        };
        if let Some(m) = means {
            save_means(std::path::Path::new(file), &m)?;
        }
        println!("{}", serde_json::to_string(&row)?);
        return Ok(());
    }
    for &e in &args.sweep {
        anyhow::ensure!(e.is_finite() && e >= args.eps, "--sweep thresholds must be finite and at least --eps ({}), got {e}", args.eps);
    }
    let exe = std::env::current_exe().context("locating this executable")?;
    let dir = std::env::temp_dir();
    let run_child_with = |emission: radiosity::instancing::ProxyEmission, extra: &[String]| -> anyhow::Result<BenchRow> {
        let o = Command::new(&exe)
            .args(["bench", "instancing", "--age", &args.age.to_string(), "--seed", &args.seed.to_string()])
            .args(["--instance-levels", &args.instance_levels])
            .args(["--direct-samples", &args.direct_samples.to_string()])
            .args(["--proxy-emission", &emission.to_string()])
            .args(extra)
            .output()
            .with_context(|| format!("running {}", exe.display()))?;
        anyhow::ensure!(o.status.success(), "child solve failed: {}", String::from_utf8_lossy(&o.stderr).trim());
        let text = String::from_utf8_lossy(&o.stdout);
        serde_json::from_str(text.lines().last().unwrap_or("")).context("unreadable child result")
    };
    let run_child = |extra: &[String]| run_child_with(args.proxy_emission, extra);
    // The other proxy emission, solved at --eps only, so that the table shows both.
    let other_emission = match args.proxy_emission {
        radiosity::instancing::ProxyEmission::Uniform => radiosity::instancing::ProxyEmission::Directional,
        radiosity::instancing::ProxyEmission::Directional => radiosity::instancing::ProxyEmission::Uniform,
    };
    // Every threshold, finest first: both methods, each in its own process (peak RSS per process).
    let mut thresholds = vec![args.eps];
    thresholds.extend(args.sweep.iter().copied().filter(|&e| e != args.eps));
    let mut points: Vec<(BenchRow, f64, f64, usize)> = Vec::new();
    let mut reference = None;
    for (k, &eps) in thresholds.iter().enumerate() {
        let methods: &[&str] = if k == 0 { &["full", "instanced", "other"] } else { &["full", "instanced"] };
        for &method in methods {
            if k == 0
                && method == "full"
                && let Some(kept) = args.reference.as_deref()
                && let Some((row, means)) = super::bench_reference::load(kept, args.age, args.seed, eps)?
            {
                if !args.json {
                    eprintln!("tree age {}: full solve at eps {eps} read from {}", args.age, kept.display());
                }
                reference = Some(means);
                points.push((row, 0.0, 0.0, 0));
                continue;
            }
            let (emission, child) = match method {
                "other" => (other_emission, "instanced"),
                m => (args.proxy_emission, m),
            };
            if !args.json {
                let proxies = if child == "instanced" { format!(" ({emission} proxies)") } else { String::new() };
                eprintln!("tree age {}: {child} solve{proxies} at eps {eps} ...", args.age);
            }
            let file = dir.join(format!("radiosity-bench-instancing-{method}-{}.bin", std::process::id()));
            let mut row =
                run_child_with(emission, &["--eps".into(), eps.to_string(), "--child".into(), child.into(), file.display().to_string()])?;
            if method == "other" {
                row.method = format!("inst-{emission}");
            }
            let means = load_means(&file)?;
            if k == 0 && method == "full" {
                if let Some(kept) = args.reference.as_deref() {
                    super::bench_reference::keep(&file, kept, &row, args.age, args.seed, eps)?;
                }
                let _ = std::fs::remove_file(&file);
                reference = Some(means);
                points.push((row, 0.0, 0.0, 0));
                continue;
            }
            let _ = std::fs::remove_file(&file);
            let reference = reference.as_ref().expect("the full solve at --eps runs first");
            let (worst, mean) = relative_error(reference, &means);
            points.push((row, worst, mean, polygons_above(reference, &means, ERROR_COUNT_FRACTION)));
        }
    }
    let mut forests: Vec<(u32, BenchRow)> = Vec::new();
    for target in args.forests.iter().filter(|f| f.as_str() != "none") {
        let target: f64 = target.parse().with_context(|| format!("--forests: `{target}` is not a polygon count"))?;
        anyhow::ensure!(target >= 1.0 && target.is_finite(), "--forests: polygon counts must be positive");
        // Trees needed: from the mean count of a few trees, then up until the target is reached.
        let count = |trees: u32| {
            let f = forest(trees);
            f.flattened_counts(true).get(f.root as usize).copied().unwrap_or(0) as f64
        };
        let mut trees = ((target / (count(8) / 8.0).max(1.0)).ceil() as u32).max(1);
        while count(trees) < target {
            trees += 1;
        }
        if !args.json {
            eprintln!("forest of {trees} trees ({} polygons): instanced solve ...", count(trees));
        }
        forests.push((trees, run_child(&["--eps".into(), args.eps.to_string(), "--forest-child".into(), trees.to_string()])?));
    }
    // Error against time: CSV and plot.
    std::fs::create_dir_all(&args.out).with_context(|| format!("{}: cannot create", args.out.display()))?;
    let mut csv = String::from("method,eps,time_s,peak_rss_bytes,links,error_pct_of_max,error_mean_pct_of_max,polygons_above_3pct\n");
    for (r, worst, mean, above) in &points {
        csv +=
            &format!("{},{},{},{},{},{},{},{above}\n", r.method, r.eps, r.seconds, r.peak_rss_bytes, r.links, 100.0 * worst, 100.0 * mean);
    }
    let csv_path = args.out.join("instancing_error_time.csv");
    radiosity::output::atomic::write_bytes(&csv_path, csv).with_context(|| format!("{}: cannot write", csv_path.display()))?;
    let plotted: Vec<(String, f64, f64, f64)> =
        points.iter().filter(|p| p.1 > 0.0).map(|(r, worst, _, _)| (r.method.clone(), r.seconds, 100.0 * worst, 0.0)).collect();
    let svg_path = args.out.join("instancing_error_time.svg");
    let title = format!("tree age {} (reference: full at eps {})", args.age, args.eps);
    radiosity::output::atomic::write_bytes(&svg_path, super::sweep::svg_plot(&title, &plotted)?)
        .with_context(|| format!("{}: cannot write", svg_path.display()))?;

    let (rf, ri, worst, mean, above) = (&points[0].0, &points[1].0, points[1].1, points[1].2, points[1].3);
    let (ro, worst_o, mean_o, above_o) = (&points[2].0, points[2].1, points[2].2, points[2].3);
    if args.json {
        let doc = serde_json::json!({
            "tree": {
                "age": args.age,
                "polygons": rf.polygons,
                "eps": args.eps,
                "full": {"time_s": rf.seconds, "peak_rss_bytes": rf.peak_rss_bytes, "links": rf.links},
                "instanced": {"time_s": ri.seconds, "peak_rss_bytes": ri.peak_rss_bytes, "links": ri.links},
                "proxy_emission": args.proxy_emission.to_string(),
                "error_pct_of_max": 100.0 * worst,
                "error_mean_pct_of_max": 100.0 * mean,
                "polygons_above_3pct": above,
                "other_proxy_emission": {
                    "proxy_emission": other_emission.to_string(), "time_s": ro.seconds, "peak_rss_bytes": ro.peak_rss_bytes,
                    "links": ro.links, "error_pct_of_max": 100.0 * worst_o, "error_mean_pct_of_max": 100.0 * mean_o,
                    "polygons_above_3pct": above_o,
                },
            },
            "error_time": points.iter().map(|(r, w, m, a)| serde_json::json!({
                "method": r.method, "eps": r.eps, "time_s": r.seconds, "peak_rss_bytes": r.peak_rss_bytes,
                "links": r.links, "error_pct_of_max": 100.0 * w, "error_mean_pct_of_max": 100.0 * m,
                "polygons_above_3pct": a,
            })).collect::<Vec<_>>(),
            "forests": forests.iter().map(|(trees, r)| serde_json::json!({
                "trees": trees, "polygons": r.polygons, "time_s": r.seconds, "peak_rss_bytes": r.peak_rss_bytes, "links": r.links,
            })).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(());
    }
    println!("tree age {} seed {}, {} polygons (two-sided leaves as pairs), eps {}", args.age, args.seed, rf.polygons, args.eps);
    println!(
        "{:<16} {:>7} {:>10} {:>10} {:>10} {:>8} {:>10} {:>10} {:>8}",
        "method", "eps", "time_s", "peak_MB", "links", "solves", "err_max%", "err_mean%", "n>3%"
    );
    for (r, w, m, a) in &points {
        println!(
            "{:<16} {:>7} {:>10.3} {:>10.1} {:>10} {:>8} {:>10.2} {:>10.3} {:>8}",
            r.method,
            r.eps,
            r.seconds,
            r.peak_rss_bytes as f64 / 1e6,
            r.links,
            r.local_solves,
            100.0 * w,
            100.0 * m,
            a
        );
    }
    println!(
        "instanced ({} proxies) vs full at eps {}: {:.2}x faster, {:.2}x less peak memory, error max {:.2}% / mean {:.3}% of the full solution's largest radiosity ({above} of {} polygons above 3%)",
        args.proxy_emission,
        args.eps,
        rf.seconds / ri.seconds.max(1e-9),
        rf.peak_rss_bytes as f64 / ri.peak_rss_bytes.max(1) as f64,
        100.0 * worst,
        100.0 * mean,
        rf.polygons
    );
    println!(
        "with {other_emission} proxies: {:.3} s, {:.1} MB, error max {:.2}% / mean {:.3}% ({above_o} polygons above 3%)",
        ro.seconds,
        ro.peak_rss_bytes as f64 / 1e6,
        100.0 * worst_o,
        100.0 * mean_o
    );
    if !forests.is_empty() {
        println!("{:<8} {:>12} {:>10} {:>10} {:>12}", "trees", "polygons", "time_s", "peak_MB", "links");
        for (trees, r) in &forests {
            println!("{:<8} {:>12} {:>10.1} {:>10.1} {:>12}", trees, r.polygons, r.seconds, r.peak_rss_bytes as f64 / 1e6, r.links);
        }
    }
    println!("wrote {} and {}", csv_path.display(), svg_path.display());
    Ok(())
}
