//! `radiosity bench accuracy`: every validation scene (exact or independently computed answers,
//! `radiosity::validation`) solved at a range of eps and at the default target error, each solve in
//! its own process: time, peak RSS, leaves, links, the true error, the estimate and the power
//! balance; for Ward's room the surface-class means too, beside RenderPark's measured figures.

use anyhow::Context;
use radiosity::pipeline::{self, Config};
use radiosity::refine::{BfHand, BfParams, Criterion};
use radiosity::validation;
use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

/// Arguments of `bench accuracy`.
#[derive(clap::Args, Debug)]
pub struct AccuracyBenchArgs {
    /// Thresholds solved at (fixed-eps solves), besides the default target error.
    #[arg(long, value_delimiter = ',', default_value = "0.04,0.01,0.0025,0.000625")]
    pub eps: Vec<f64>,
    /// Only the validation scenes whose name contains this.
    #[arg(long, default_value = "")]
    pub only: String,
    /// Directory for `accuracy.csv` and `accuracy.svg` (error against run time).
    #[arg(long, default_value = "bench-accuracy")]
    pub out: PathBuf,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
    /// What the link criteria bound the error of (as `radiosity solve --criterion`).
    #[arg(long, default_value = "irradiance", value_parser = ["radiosity", "irradiance"])]
    pub criterion: String,
    /// Internal: solve one case (`NAME EPS CRITERION`, EPS `target` for the default target error)
    /// and print its row as JSON.
    #[arg(long, num_args = 3, hide = true)]
    pub child: Vec<String>,
}

/// RenderPark's Galerkin hierarchical radiosity with clustering on Ward's room (measured on this
/// machine class, `shared/notes/crates.md`): threshold, CPU s, RSS MB, and the worst of the
/// floor / ceiling / walls mean errors (%).
pub const RENDERPARK_WARD: [(f64, f64, f64, f64); 5] =
    [(1e-3, 0.01, 7.0, 10.8), (1e-4, 0.03, 8.0, 5.0), (1e-5, 0.3, 13.0, 0.53), (1e-6, 1.2, 33.0, 0.18), (1e-7, 5.3, 120.0, 0.06)];

/// Runs `bench accuracy`.
pub fn run(args: &AccuracyBenchArgs) -> anyhow::Result<()> {
    if let [name, eps, criterion] = args.child.as_slice() {
        return child(name, eps, criterion);
    }
    anyhow::ensure!(args.eps.iter().all(|e| e.is_finite() && *e > 0.0 && *e <= 1.0), "--eps must be numbers in (0, 1]");
    let exe = std::env::current_exe().context("locating this executable")?;
    let names: Vec<String> = validation::cases().into_iter().map(|c| c.name).filter(|n| n.contains(&args.only)).collect();
    anyhow::ensure!(!names.is_empty(), "no validation scene's name contains `{}`", args.only);
    let mut rows = Vec::new();
    if !args.json {
        println!(
            "{:<24} {:>10} {:>8} {:>8} {:>7} {:>7} {:>10} {:>10} {:>6} {:>9}  classes (ward)",
            "scene", "eps", "time_s", "peak_MB", "leaves", "links", "true_err%", "estimate%", "ratio", "balance"
        );
    }
    for name in &names {
        let settings: Vec<String> = std::iter::once("target".to_string()).chain(args.eps.iter().map(|e| e.to_string())).collect();
        for eps in settings {
            let out = Command::new(&exe)
                .args(["bench", "accuracy", "--child", name, &eps, &args.criterion])
                .output()
                .context("running a child solve")?;
            anyhow::ensure!(out.status.success(), "{name} at {eps}: {}", String::from_utf8_lossy(&out.stderr).trim());
            let row: serde_json::Value = serde_json::from_slice(&out.stdout).context("reading a child's row")?;
            if !args.json {
                print_row(&row);
            }
            rows.push(row);
        }
    }
    write_files(&args.out, &rows)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        println!("wrote {}/{{accuracy.csv,accuracy.svg}}", args.out.display());
    }
    Ok(())
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

fn print_row(r: &serde_json::Value) {
    let classes = r["class_errors"]
        .as_array()
        .map_or(String::new(), |c| c.iter().map(|x| format!("{:+.2}%", 100.0 * f(x))).collect::<Vec<_>>().join(" "));
    println!(
        "{:<24} {:>10} {:>8.3} {:>8.1} {:>7} {:>7} {:>10.3} {:>10.3} {:>6.2} {:>9.5}  {classes}",
        r["scene"].as_str().unwrap_or("?"),
        r["eps_label"].as_str().unwrap_or("?"),
        f(&r["time_s"]),
        f(&r["peak_rss_bytes"]) / 1e6,
        r["leaves"],
        r["links"],
        100.0 * f(&r["true_error"]),
        100.0 * f(&r["error_estimate"]),
        f(&r["error_estimate"]) / f(&r["true_error"]),
        f(&r["power_balance"]),
    );
}

/// `accuracy.csv` and `accuracy.svg`: every row, and the error against run time of every scene
/// (Ward's room as the worst surface-class mean error, beside RenderPark's figures).
fn write_files(out: &std::path::Path, rows: &[serde_json::Value]) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    let mut csv = String::from("scene,eps,time_s,peak_rss_bytes,leaves,links,true_error,error_estimate,power_balance\n");
    for r in rows {
        csv += &format!(
            "{},{},{},{},{},{},{},{},{}\n",
            r["scene"].as_str().unwrap_or("?"),
            r["eps_label"].as_str().unwrap_or("?"),
            f(&r["time_s"]),
            f(&r["peak_rss_bytes"]),
            r["leaves"],
            r["links"],
            f(&r["true_error"]),
            f(&r["error_estimate"]),
            f(&r["power_balance"])
        );
    }
    let path = out.join("accuracy.csv");
    radiosity::output::atomic::write_bytes(&path, csv).with_context(|| format!("{}: cannot write", path.display()))?;
    // The plot: Ward's room (worst surface-class mean, as RenderPark's figures are; and worst
    // polygon mean with its estimate) beside RenderPark, and the corner rooms (worst polygon mean,
    // estimates hollow). Furnaces and CIE 5.8 are exact to 1e-5 and would only stretch the axis.
    let mut points: Vec<(String, f64, f64, f64)> = Vec::new();
    for r in rows.iter().filter(|r| r["eps"].is_number()) {
        let scene = r["scene"].as_str().unwrap_or("?");
        if let Some(c) = r["class_errors"].as_array() {
            let worst_class = c.iter().map(|x| f(x).abs()).fold(0.0, f64::max);
            points.push((format!("{scene} (worst class)"), f(&r["time_s"]), 100.0 * worst_class, 0.0));
        }
        if scene.starts_with("ward") || scene.starts_with("corner") {
            points.push((
                format!("{scene} (worst polygon)"),
                f(&r["time_s"]),
                100.0 * f(&r["true_error"]),
                100.0 * f(&r["error_estimate"]),
            ));
        }
    }
    points.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    for (_, time, _, err) in RENDERPARK_WARD {
        points.push(("RenderPark ward-room (worst class)".to_string(), time, err, 0.0));
    }
    let path = out.join("accuracy.svg");
    radiosity::output::atomic::write_bytes(&path, super::sweep::svg_plot("Ward's room and the corner rooms", &points)?)
        .with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(())
}

/// The surface classes of Ward's room and their reference means (`globillum1990_room.md`).
const WARD_CLASSES: [(&str, f64); 3] = [("floor", 0.033361), ("ceiling", 0.022187), ("wall", 0.027126)];

/// Solves one case and prints its row.
fn child(name: &str, eps: &str, criterion: &str) -> anyhow::Result<()> {
    let case = validation::cases().into_iter().find(|c| c.name == name).with_context(|| format!("no validation scene `{name}`"))?;
    let criterion = Criterion::from_name(criterion).with_context(|| format!("no criterion `{criterion}`"))?;
    let (mut config, oracle_eps) = if eps == "target" {
        (Config { target_error: Some(super::DEFAULT_TARGET_ERROR), ..Config::default() }, BfParams::default().eps)
    } else {
        (Config::default(), eps.parse::<f64>().with_context(|| format!("bad eps `{eps}`"))?)
    };
    config.criterion = criterion;
    let t0 = Instant::now();
    let solved = pipeline::run(&case.scene, &BfHand { params: BfParams { eps: oracle_eps } }, &config, &|_| {});
    let time = t0.elapsed().as_secs_f64();
    let results = radiosity::output::polygon_results(&solved.hierarchy, &solved.solution);
    let means: Vec<[f64; 3]> = results.iter().map(|r| r.b).collect();
    let (emitted, absorbed, _) = radiosity::output::power_balance(&solved.hierarchy, &solved.lights, &solved.solution);
    let class_errors = (name == "ward-room").then(|| {
        WARD_CLASSES
            .iter()
            .map(|(class, reference)| {
                let (mut sum, mut area) = (0.0, 0.0);
                for (p, r) in case.scene.polygons.iter().zip(&results) {
                    if case.scene.materials[p.material as usize].name == *class {
                        sum += r.area * r.b[0];
                        area += r.area;
                    }
                }
                sum / area / reference - 1.0
            })
            .collect::<Vec<f64>>()
    });
    let row = serde_json::json!({
        "scene": name,
        "eps": if eps == "target" { serde_json::Value::Null } else { serde_json::json!(oracle_eps) },
        "eps_label": if eps == "target" { format!("target {}", super::DEFAULT_TARGET_ERROR) } else { eps.to_string() },
        "target_error": config.target_error,
        "criterion": criterion.name(),
        "time_s": time,
        "peak_rss_bytes": radiosity::output::peak_rss_bytes(),
        "leaves": solved.hierarchy.leaves().count(),
        "links": solved.links.len(),
        "true_error": validation::true_error(&case.reference, &means),
        "error_estimate": solved.error_estimate,
        "power_balance": if emitted > 0.0 { absorbed / emitted } else { f64::NAN },
        "class_errors": class_errors,
        "reference": case.source,
    });
    println!("{}", serde_json::to_string(&row)?);
    Ok(())
}
