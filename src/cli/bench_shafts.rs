//! `radiosity bench shafts`: visibility by plain rays against AABB and OBB shafts, each solve in its
//! own process (`bench::child_solve`).

use super::SolveOptions;
use super::bench::child_solve;
use anyhow::Context;

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

pub(super) fn bench_shafts(args: &ShaftBenchArgs) -> anyhow::Result<()> {
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
