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
    }
}

/// RenderPark's Galerkin hierarchical radiosity on this machine class (CPU seconds, MB), for the
/// scenes it was measured on; `None` where it had not finished.
fn renderpark_reference(name: &str) -> Option<(&'static str, &'static str)> {
    match name {
        "cube.mgf" => Some(("0.31", "19")),
        "office2.mgf" => Some(("3.5", "46")),
        "office3.mgf" => Some(("96", "193")),
        "soda.mgf" => Some((">233 (unfinished)", ">677")),
        _ => None,
    }
}

fn bench_solve(args: &SolveBenchArgs) -> anyhow::Result<()> {
    args.options.validate()?;
    let scenes = if args.scenes.is_empty() {
        vec!["cornell".to_string()]
    } else {
        args.scenes.clone()
    };
    let exe = std::env::current_exe().context("locating this executable")?;
    let tmp = std::env::temp_dir().join(format!("radiosity-bench-{}", std::process::id()));
    let mut rows = Vec::new();
    if !args.json {
        print_header();
    }
    for (i, scene) in scenes.iter().enumerate() {
        let out = tmp.join(format!("{i}"));
        let mut cmd = Command::new(&exe);
        cmd.arg("solve")
            .arg("--quiet")
            .arg("--no-image")
            .arg("--out")
            .arg(&out);
        if scene != "cornell" {
            let p = PathBuf::from(scene);
            anyhow::ensure!(p.exists(), "{scene}: no such file");
            cmd.arg(&p);
        }
        let o = &args.options;
        cmd.args([
            "--eps",
            &o.eps.to_string(),
            "--rays",
            &o.common.rays.to_string(),
            "--seed",
            &o.common.seed.to_string(),
            "--min-area",
            &o.common.min_area.to_string(),
        ]);
        if o.common.allow_dark {
            cmd.arg("--allow-dark");
        }
        if o.common.no_visibility {
            cmd.arg("--no-visibility");
        }
        let status = cmd
            .status()
            .with_context(|| format!("running {}", exe.display()))?;
        anyhow::ensure!(status.success(), "{scene}: solve failed ({status})");
        let path = out.join("stats.json");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("{}: cannot read", path.display()))?;
        let stats: serde_json::Value = serde_json::from_str(&text)
            .with_context(|| format!("{}: invalid JSON", path.display()))?;
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
    let name = std::path::Path::new(scene)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or(scene);
    let t = &s["time_s"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    let rp = renderpark_reference(name).map_or("-".to_string(), |(t, m)| format!("{t} / {m}"));
    println!(
        "{:<16} {:>8} {:>9} {:>10} {:>11} {:>6} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>9.1} {:>22}",
        name,
        s["polygons"],
        s["elements"],
        s["links"],
        s["rays"],
        s["iterations"],
        f(&t["build"]),
        f(&t["refine"]),
        f(&t["solve"]),
        f(&t["total"]),
        f(&s["peak_rss_bytes"]) / 1e6,
        rp
    );
}
