//! `radiosity sweep`: error against run time. Solves a scene with several oracles and thresholds,
//! compares each solution with a reference (analytic where the scene has one, otherwise a converged
//! solution computed once and cached), and writes `sweep.csv` and `sweep.svg`.

use super::{CommonOptions, load_scene};
use anyhow::Context;
use radiosity::geom::DVec3;
use radiosity::output::polygon_results;
use radiosity::pipeline::{self, Solved};
use radiosity::refine::Oracle;
use radiosity::scene::Scene;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Reflectance and emission of the built-in `furnace` scene (exact answer E/(1−ρ)).
const FURNACE_RHO: f64 = 0.9;
/// The reference solution's threshold, relative to the finest threshold swept.
const REFERENCE_EPS_FACTOR: f64 = 0.25;
/// Visibility rays of the reference solution.
const REFERENCE_RAYS: u32 = 64;

/// Arguments of `radiosity sweep`.
#[derive(clap::Args, Debug)]
pub struct SweepArgs {
    /// Scene file, `furnace` (a closed box with an analytic answer), or none for the Cornell box.
    pub scene: Option<String>,
    /// Oracles to compare, comma-separated (names as in `radiosity oracle list`, or graph files).
    #[arg(long, value_delimiter = ',', default_value = "bf,bf-dag")]
    pub oracle: Vec<String>,
    /// Thresholds, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "0.5,0.2,0.1,0.05,0.02")]
    pub eps: Vec<f64>,
    /// Reference: `analytic` (furnace only), `auto` (analytic when known, else a converged solve,
    /// cached in the output directory), or a `patches.csv` file of a previous solve.
    #[arg(long, default_value = "auto")]
    pub reference: String,
    /// Output directory.
    #[arg(long, short, default_value = "sweep")]
    pub out: PathBuf,
    #[command(flatten)]
    pub options: CommonOptions,
    /// No per-solve progress lines.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Per-polygon mean radiosity of a reference or a solve.
type PerPolygon = Vec<[f64; 3]>;

/// Builds an oracle by name.
pub fn oracle_by_name(name: &str, eps: f64) -> anyhow::Result<Box<dyn Oracle>> {
    Ok(radiosity::oracle::registry::oracle(name, &[("eps".to_string(), eps)])?)
}

/// Runs `radiosity sweep`.
pub fn run(args: &SweepArgs) -> anyhow::Result<()> {
    args.options.validate()?;
    anyhow::ensure!(!args.eps.is_empty() && args.eps.iter().all(|e| e.is_finite() && *e > 0.0), "--eps must be positive numbers");
    for o in &args.oracle {
        oracle_by_name(o, 0.1)?;
    }
    let (scene, analytic) = match args.scene.as_deref() {
        Some("furnace") => {
            let scene = radiosity::scene::shapes::furnace_box(DVec3::new(1.0, 1.3, 0.8), FURNACE_RHO, 1.0);
            let n = scene.polygons.len();
            (scene, Some(vec![[1.0 / (1.0 - FURNACE_RHO); 3]; n]))
        }
        other => (load_scene(other.map(PathBuf::from).as_ref(), args.options.allow_dark)?, None),
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("{}: cannot create", args.out.display()))?;
    let config = args.options.config();
    let reference: PerPolygon = match (args.reference.as_str(), analytic) {
        ("analytic" | "auto", Some(a)) => a,
        ("analytic", None) => anyhow::bail!("--reference analytic: this scene has no analytic solution (use auto or a file)"),
        ("auto", None) => {
            let finest = args.eps.iter().copied().fold(f64::INFINITY, f64::min);
            cached_reference(&scene, &args.out, finest * REFERENCE_EPS_FACTOR, &config, args.quiet)?
        }
        (path, _) => super::read_patches(Path::new(path))?,
    };
    anyhow::ensure!(
        reference.len() == scene.polygons.len(),
        "reference has {} polygons, the scene {}",
        reference.len(),
        scene.polygons.len()
    );
    let max_ref = reference.iter().flatten().fold(0.0f64, |m, v| m.max(*v)).max(f64::MIN_POSITIVE);
    let areas: Vec<f64> = scene.polygons.iter().map(|p| p.poly.area()).collect();
    let total_area: f64 = areas.iter().sum();

    let mut csv = String::from("oracle,eps,time_s,elements,links,rays,error_estimate,error_l1,error_linf,error_pct_of_max\n");
    let mut points = Vec::new();
    for name in &args.oracle {
        for &eps in &args.eps {
            let oracle = oracle_by_name(name, eps)?;
            let t = Instant::now();
            let solved = pipeline::run(&scene, oracle.as_ref(), &config, &|_| {});
            let time = t.elapsed().as_secs_f64();
            let b = per_polygon(&solved);
            let (mut l1, mut linf) = (0.0, 0.0f64);
            for (i, (x, y)) in b.iter().zip(&reference).enumerate() {
                for c in 0..3 {
                    let d = (x[c] - y[c]).abs();
                    l1 += areas[i] * d / 3.0;
                    linf = linf.max(d);
                }
            }
            l1 /= total_area;
            let pct = 100.0 * linf / max_ref;
            let est = solved.error_estimate.unwrap_or(f64::NAN);
            writeln!(
                csv,
                "{name},{eps},{time:.6},{},{},{},{est:.6e},{l1:.6e},{linf:.6e},{pct:.4}",
                solved.hierarchy.len(),
                solved.links.len(),
                solved.rays
            )?;
            if !args.quiet {
                println!(
                    "{name} eps {eps}: {time:.3}s, {} links, error {pct:.3}% of max (estimate {:.3}%)",
                    solved.links.len(),
                    100.0 * est
                );
            }
            points.push((name.clone(), time, pct, 100.0 * est));
        }
    }
    let csv_path = args.out.join("sweep.csv");
    radiosity::output::atomic::write_bytes(&csv_path, csv).with_context(|| format!("{}: cannot write", csv_path.display()))?;
    let svg_path = args.out.join("sweep.svg");
    radiosity::output::atomic::write_bytes(&svg_path, svg_plot(&scene.name, &points))
        .with_context(|| format!("{}: cannot write", svg_path.display()))?;
    println!("wrote {} and {}", csv_path.display(), svg_path.display());
    Ok(())
}

fn per_polygon(solved: &Solved) -> PerPolygon {
    polygon_results(&solved.hierarchy, &solved.solution).iter().map(|r| r.b).collect()
}

/// A content key of the scene and the reference settings, so a changed scene is not compared with
/// a stale reference.
fn scene_key(scene: &Scene, eps: f64, rays: u32) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in &scene.polygons {
        for v in p.poly.vertices() {
            v.to_array().map(f64::to_bits).hash(&mut h);
        }
        let m = &scene.materials[p.material as usize];
        m.reflectance.map(f64::to_bits).hash(&mut h);
        m.emission.map(f64::to_bits).hash(&mut h);
    }
    eps.to_bits().hash(&mut h);
    rays.hash(&mut h);
    h.finish()
}

fn cached_reference(scene: &Scene, out: &Path, eps: f64, config: &pipeline::Config, quiet: bool) -> anyhow::Result<PerPolygon> {
    let mut config = *config;
    config.visibility.rays = config.visibility.rays.max(REFERENCE_RAYS);
    let key = scene_key(scene, eps, config.visibility.rays);
    let path = out.join(format!("reference-{key:016x}.csv"));
    if path.exists() {
        if !quiet {
            println!("reference: cached {}", path.display());
        }
        return super::read_patches(&path);
    }
    if !quiet {
        println!("reference: solving at eps {eps} with {} rays (cached in {})", config.visibility.rays, path.display());
    }
    let oracle = oracle_by_name("bf-hand", eps)?;
    let solved = pipeline::run(scene, oracle.as_ref(), &config, &|_| {});
    let results = polygon_results(&solved.hierarchy, &solved.solution);
    radiosity::output::atomic::write_file(&path, |w| radiosity::output::write_patches_csv(w, scene, &results))
        .with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(results.iter().map(|r| r.b).collect())
}

/// A log–log plot of error (% of max) against run time, one series per oracle, with the estimates
/// as hollow marks. Written by hand: a few dozen lines of SVG, no plotting dependency.
/// Error against run time, log–log: `(series, time_s, error %, estimate %)` points (estimates as
/// hollow circles where positive).
pub fn svg_plot(scene: &str, points: &[(String, f64, f64, f64)]) -> String {
    let (w, h, m) = (760.0, 460.0, 60.0);
    let pos: Vec<&(String, f64, f64, f64)> = points.iter().filter(|p| p.1 > 0.0 && p.2 > 0.0).collect();
    let lx = |v: f64| v.log10();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for p in &pos {
        x0 = x0.min(lx(p.1).floor());
        x1 = x1.max(lx(p.1).ceil());
        for y in [p.2, p.3] {
            if y > 0.0 && y.is_finite() {
                y0 = y0.min(lx(y).floor());
                y1 = y1.max(lx(y).ceil());
            }
        }
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (-2.0, 1.0, -2.0, 2.0);
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    if y1 <= y0 {
        y1 = y0 + 1.0;
    }
    let sx = |v: f64| m + (lx(v) - x0) / (x1 - x0) * (w - 1.5 * m);
    let sy = |v: f64| h - m - (lx(v) - y0) / (y1 - y0) * (h - 1.7 * m);
    let mut s =
        format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n");
    let _ = writeln!(s, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    let _ = writeln!(s, "<text x=\"{}\" y=\"20\" text-anchor=\"middle\">{}: error against run time</text>", w / 2.0, xml(scene));
    let _ = writeln!(s, "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">run time (s, log)</text>", w / 2.0, h - 12.0);
    let _ = writeln!(
        s,
        "<text x=\"14\" y=\"{}\" transform=\"rotate(-90 14 {})\" text-anchor=\"middle\">error, % of max (log); hollow: estimate</text>",
        h / 2.0,
        h / 2.0
    );
    for k in x0 as i32..=x1 as i32 {
        let x = sx(10f64.powi(k));
        let _ = writeln!(
            s,
            "<line x1=\"{x}\" y1=\"{}\" x2=\"{x}\" y2=\"{}\" stroke=\"#ddd\"/><text x=\"{x}\" y=\"{}\" text-anchor=\"middle\">1e{k}</text>",
            m * 0.7,
            h - m,
            h - m + 16.0
        );
    }
    for k in y0 as i32..=y1 as i32 {
        let y = sy(10f64.powi(k));
        let _ = writeln!(
            s,
            "<line x1=\"{m}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{}\" text-anchor=\"end\">1e{k}</text>",
            w - m / 2.0,
            m - 6.0,
            y + 4.0
        );
    }
    const COLOURS: [&str; 6] = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"];
    let mut names: Vec<&str> = pos.iter().map(|p| p.0.as_str()).collect();
    names.dedup();
    for (i, name) in names.iter().enumerate() {
        let c = COLOURS[i % COLOURS.len()];
        let series: Vec<&&(String, f64, f64, f64)> = pos.iter().filter(|p| p.0 == *name).collect();
        let path: Vec<String> = series.iter().map(|p| format!("{:.1},{:.1}", sx(p.1), sy(p.2))).collect();
        let _ = writeln!(s, "<polyline points=\"{}\" fill=\"none\" stroke=\"{c}\"/>", path.join(" "));
        for p in &series {
            let _ = writeln!(s, "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"{c}\"/>", sx(p.1), sy(p.2));
            if p.3 > 0.0 && p.3.is_finite() {
                let _ = writeln!(s, "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"none\" stroke=\"{c}\"/>", sx(p.1), sy(p.3));
            }
        }
        let _ = writeln!(
            s,
            "<text x=\"{}\" y=\"{}\" fill=\"{c}\" text-anchor=\"end\">{}</text>",
            w - m / 2.0 - 4.0,
            h - m - 8.0 - 16.0 * (names.len() - 1 - i) as f64,
            xml(name)
        );
    }
    s.push_str("</svg>\n");
    s
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}
