//! `radiosity sweep`: error against run time. Solves a scene with several oracles and thresholds,
//! compares each solution with a reference (analytic where the scene has one, otherwise a converged
//! solution computed once and cached), and writes `sweep.csv` and `sweep.svg` (drawn with plotters).

use super::{CommonOptions, load_scene};
use anyhow::Context;
use plotters::prelude::*;
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
    radiosity::output::atomic::write_bytes(&svg_path, svg_plot(&scene.name, &points)?)
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

/// Colours of the plot's series, in order.
const SERIES_COLOURS: [RGBColor; 6] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x8c, 0x56, 0x4b),
];
/// Size of the plot, pixels.
const PLOT_SIZE: (u32, u32) = (760, 460);
/// Radius of the plot's marks, pixels.
const MARK_RADIUS: i32 = 4;

/// Error against run time, log–log, drawn with plotters' SVG backend: `(series, time_s, error %,
/// estimate %)` points, one line of filled marks per series (the true error), with the estimates
/// as hollow marks where positive.
pub fn svg_plot(scene: &str, points: &[(String, f64, f64, f64)]) -> anyhow::Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, PLOT_SIZE).into_drawing_area();
        draw_plot(&root, scene, points).map_err(|e| anyhow::anyhow!("drawing the plot of {scene}: {e}"))?;
    }
    Ok(svg)
}

fn draw_plot(
    root: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    scene: &str,
    points: &[(String, f64, f64, f64)],
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let usable = |v: f64| v > 0.0 && v.is_finite();
    let pos: Vec<&(String, f64, f64, f64)> = points.iter().filter(|p| usable(p.1) && usable(p.2)).collect();
    // Whole decades around every time, error and estimate.
    let decades = |values: &mut dyn Iterator<Item = f64>, empty: (f64, f64)| {
        let (lo, hi) = values
            .filter(|&v| usable(v))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v.log10().floor()), hi.max(v.log10().ceil())));
        let (lo, hi) = if lo.is_finite() { (lo, hi) } else { empty };
        (10f64.powf(lo), 10f64.powf(if hi > lo { hi } else { lo + 1.0 }))
    };
    let (x0, x1) = decades(&mut pos.iter().map(|p| p.1), (-2.0, 1.0));
    let (y0, y1) = decades(&mut pos.iter().flat_map(|p| [p.2, p.3]), (-2.0, 2.0));
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(root)
        .caption(format!("{scene}: error against run time"), ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("run time (s, log)")
        .y_desc("error, % of max (log); hollow: estimate")
        .x_label_formatter(&|v| axis_label(*v))
        .y_label_formatter(&|v| axis_label(*v))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .draw()?;
    let mut names: Vec<&str> = pos.iter().map(|p| p.0.as_str()).collect();
    names.dedup();
    for (i, name) in names.iter().enumerate() {
        let colour = SERIES_COLOURS[i % SERIES_COLOURS.len()];
        let series: Vec<&&(String, f64, f64, f64)> = pos.iter().filter(|p| p.0 == *name).collect();
        chart
            .draw_series(LineSeries::new(series.iter().map(|p| (p.1, p.2)), colour))?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour));
        chart.draw_series(series.iter().map(|p| Circle::new((p.1, p.2), MARK_RADIUS, colour.filled())))?;
        let estimates = series.iter().filter(|p| usable(p.3)).map(|p| Circle::new((p.1, p.3), MARK_RADIUS, colour.stroke_width(1)));
        chart.draw_series(estimates)?;
    }
    chart.configure_series_labels().position(SeriesLabelPosition::LowerRight).background_style(WHITE).border_style(BLACK).draw()?;
    root.present()
}

/// A tick label of a log axis: plain below 10⁴ and from 10⁻², else `1e-3`.
fn axis_label(v: f64) -> String {
    if (1e-2..1e4).contains(&v) {
        let s = format!("{v:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        format!("{v:.0e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plot_shows_each_series_error_and_estimate() {
        let points: Vec<(String, f64, f64, f64)> = vec![
            ("bf".into(), 0.1, 2.0, 3.0),
            ("bf".into(), 0.5, 0.5, 0.8),
            ("bf-dag".into(), 0.2, 1.5, f64::NAN),
            ("bf-dag".into(), 0.0, 1.0, 1.0), // no time: left out
        ];
        let svg = svg_plot("a <scene>", &points).unwrap();
        assert!(svg.starts_with("<svg"), "{svg}");
        assert!(svg.contains("a &lt;scene&gt;: error against run time"), "the title, escaped");
        for label in ["bf", "bf-dag", "run time (s, log)", "error, % of max (log); hollow: estimate"] {
            assert!(svg.contains(&format!(">\n{label}\n<")) || svg.contains(&format!(">{label}<")), "{label}");
        }
        // Three filled marks (true errors) and two hollow ones (the finite estimates).
        let circles: Vec<&str> = svg.lines().filter(|l| l.starts_with("<circle")).collect();
        assert_eq!(circles.len(), 5, "{svg}");
        assert_eq!(circles.iter().filter(|l| l.contains("fill=\"none\"")).count(), 2, "{svg}");
    }
}
