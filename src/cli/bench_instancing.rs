//! `radiosity bench instancing`: a generated tree solved fully and by hierarchical instantiation,
//! each in its own process (this binary re-running itself with the hidden `--child` arguments),
//! then forests solved with instances.

use anyhow::Context;
use std::path::PathBuf;
use std::process::Command;

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

pub(super) fn bench_instancing(args: &InstancingBenchArgs) -> anyhow::Result<()> {
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
