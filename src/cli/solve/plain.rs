//! The plain solve of `radiosity solve`, one step per function: load the scene with its points and
//! grids, build the oracle and the configuration, solve (again for `--time-for`, and once per
//! further pack of three named bands), gather at the points and grids, write the outputs, and say
//! whether the target holds.

use super::grids::write_grids;
use super::report::print_summary;
use super::{SolveArgs, load_scene};
use crate::cli::progress::Reporter;
use anyhow::Context;
use radiosity::instancing::bands::Bands;
use radiosity::output::{self, FalseColourConfig, OutputConfig, PolygonResult, Stats, ViewSpec};
use radiosity::pipeline::{self, Config, Solved};
use radiosity::points::{CalcPoint, Grid, GridSpec, PointIrradiance};
use radiosity::refine::Oracle;
use radiosity::scene::Scene;
use std::time::Instant;

/// The oracle's parameters, by name.
type OracleParams = Vec<(String, f64)>;

/// Most solves `--time-for` times.
const MAX_TIMED_RUNS: u32 = 1000;

/// A scene file's scene, flattened, with what the plain solve needs of the file besides.
pub(super) struct LitScene {
    /// The flattened scene, its luminaires and distant sources set.
    pub(super) scene: Scene,
    /// The file's bands, where it names bands or has daylight.
    pub(super) bands: Option<Bands>,
    /// The file's `[[grid]]` entries.
    pub(super) grids: Vec<GridSpec>,
}

/// Solves a plain scene (`lit`, or the scene `args` names when `None`) and writes its outputs.
pub(super) fn solve(
    args: &SolveArgs,
    lit: Option<LitScene>,
    view: Option<ViewSpec>,
    false_colour: Option<FalseColourConfig>,
) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let reporter = Reporter::new(args.quiet);
    reporter.phase("loading scene");
    let Loaded { scene, bands, points, grids } = load(args, lit)?;
    let load = t0.elapsed().as_secs_f64();
    // The daylight factor's reference: the sky's light on an open horizontal plane, in a scene lit
    // by a sky alone (RGB: the photopic value of named bands means nothing).
    let outside = radiosity::daylight::sky_alone_horizontal(&scene)
        .filter(|_| bands.as_ref().is_none_or(|b| !b.declared))
        .map(radiosity::points::photopic);
    let false_colour = match false_colour {
        Some(fc) if fc.quantity == output::Quantity::DaylightFactor => {
            let outside = outside.with_context(|| {
                format!(
                    "--false-colour daylight-factor: {} is not lit by a sky alone (a daylight factor needs a [sky] with no sun, luminaires or emitting materials, and no named bands)",
                    scene.name
                )
            })?;
            Some(FalseColourConfig { factor: 100.0 / outside, unit: "%", ..fc })
        }
        other => other.map(|fc| photometric_unit(fc, &scene)),
    };
    let (params, oracle, config) = oracle_and_config(args)?;
    // The target applies to the calculation points and every grid as well (importance rounds).
    let point_sets: Vec<&[CalcPoint]> = points.iter().map(Vec::as_slice).chain(grids.iter().map(|g| g.points.as_slice())).collect();
    let (mut solved, runs, repeats) = solve_timed(args, &scene, oracle.as_ref(), &config, &point_sets, &reporter);
    // Named bands beyond the first three: one more solve per pack of three.
    let declared = bands.as_ref().filter(|b| b.declared);
    anyhow::ensure!(
        declared.is_none() || (points.is_none() && grids.is_empty()),
        "--points, --grid, --work-plane and [[grid]] take RGB scenes for now, not scenes with named `bands`"
    );
    let packs = declared.map(|b| solve_other_packs(&scene, b, oracle.as_ref(), &config, &mut solved, &reporter));
    let gathered = gather(&mut solved, points.as_ref(), &grids, &config, &reporter);
    reporter.phase("writing outputs");
    let t_out = Instant::now();
    let mut stats = stats(args, &scene, &solved, &params, &config, load);
    if let Some(b) = &bands {
        stats.sun.clone_from(&b.sun_report);
    }
    if let (Some(b), Some((_, powers))) = (declared, &packs) {
        stats.set_band_powers(&b.names, powers, b.has_daylight());
        stats.bands.clone_from(&b.names);
        // Pictures show the first band in grey.
        for v in solved.solution.radiosity.iter_mut().chain(solved.solution.irradiance.iter_mut()) {
            *v = [v[0]; 3];
        }
    }
    let out_config = OutputConfig {
        image: !args.no_image,
        render: output::RenderConfig { width: args.size, height: args.size, ..Default::default() },
        view,
        false_colour,
    };
    output::write_solution(&args.out, &scene, &solved, &out_config)?;
    if let (Some(b), Some((results, _))) = (declared, &packs) {
        write_band_files(args, &scene, b, results)?;
    }
    if let Some((points, (results, seconds))) = points.as_ref().zip(gathered.points.as_ref()) {
        let path = args.out.join("points.csv");
        output::atomic::write_file(&path, |w| output::write_points_csv_with(w, points, results, scene.units, outside))
            .with_context(|| format!("{}: cannot write", path.display()))?;
        stats.points = Some(points.len());
        stats.point_rays = Some(results.iter().map(|r| r.rays).sum());
        stats.time_s.points = Some(*seconds);
    }
    if !grids.is_empty() {
        stats.grids = Some(write_grids(&args.out, &grids, &gathered.grids, scene.units, outside)?);
        stats.time_s.grids = Some(gathered.grid_seconds);
    }
    stats.solve_warnings.extend(target_warnings(&config, &solved, &gathered, &grids));
    stats.time_s.output = t_out.elapsed().as_secs_f64();
    stats.time_s.total = t0.elapsed().as_secs_f64();
    stats.time_s.runs = runs;
    stats.time_s.repeats = repeats;
    stats.peak_rss_bytes = output::peak_rss_bytes();
    output::write_stats(&args.out, &stats)?;
    reporter.finish();
    finish(args, &scene, &stats, false_colour.is_some())
}

/// The scene and what is computed on it besides its surfaces.
struct Loaded {
    scene: Scene,
    bands: Option<Bands>,
    points: Option<Vec<CalcPoint>>,
    grids: Vec<Grid>,
}

/// Loads the scene, the calculation points and the grids.
fn load(args: &SolveArgs, lit: Option<LitScene>) -> anyhow::Result<Loaded> {
    // The points file is read first, so that a bad row stops the command before the solve.
    let points = args.points.as_deref().map(radiosity::points::read_points).transpose()?;
    let mut grid_specs = args.grids.iter().map(|g| GridSpec::parse_arg(g)).collect::<Result<Vec<_>, _>>()?;
    let (scene, bands) = match lit {
        Some(lit) => {
            grid_specs.extend(lit.grids);
            (lit.scene, lit.bands)
        }
        None => (load_scene(args.scene.as_ref(), args.options.common.allow_dark)?, None),
    };
    if let Some(height) = args.work_plane {
        let spec = radiosity::points::grid::work_plane(&scene, height, args.up.axis(), args.work_plane_border, args.work_plane_spacing)?;
        grid_specs.push(spec);
    }
    let mut grids = Vec::with_capacity(grid_specs.len());
    for spec in &grid_specs {
        anyhow::ensure!(!grids.iter().any(|g: &Grid| g.spec.name == spec.name), "grid `{}` given twice", spec.name);
        grids.push(spec.grid()?);
    }
    Ok(Loaded { scene, bands, points, grids })
}

/// The oracle's parameters (`eps` added when not given), the oracle, and the solve's
/// configuration with the visibility method the solve will use (an oracle that needs shafts gets
/// them), as `stats.json` reports it.
fn oracle_and_config(args: &SolveArgs) -> anyhow::Result<(OracleParams, Box<dyn Oracle>, Config)> {
    let mut params = crate::cli::oracle::parse_params(&args.params)?;
    if !params.iter().any(|(k, _)| k == "eps") {
        params.push(("eps".to_string(), args.options.eps()));
    }
    let oracle = radiosity::oracle::registry::oracle(&args.oracle, &params)?;
    let mut config = args.options.config();
    config.visibility_method = pipeline::effective_visibility(oracle.as_ref(), config.visibility_method);
    Ok((params, oracle, config))
}

/// Solves, then solves again for `--time-for` seconds keeping each phase's fastest time: the
/// solution, the number of solves and the seconds the further ones took.
fn solve_timed(
    args: &SolveArgs,
    scene: &Scene,
    oracle: &dyn Oracle,
    config: &Config,
    point_sets: &[&[CalcPoint]],
    reporter: &Reporter,
) -> (Solved, u32, Option<f64>) {
    let mut solved = pipeline::run_with_points(scene, oracle, config, point_sets, &|p| reporter.event(p));
    let mut runs = 1;
    let mut repeats = None;
    if args.time_for > 0.0 {
        reporter.phase("timing further solves");
        let t_runs = Instant::now();
        while runs < MAX_TIMED_RUNS && t_runs.elapsed().as_secs_f64() < args.time_for {
            let t = pipeline::run_with_points(scene, oracle, config, point_sets, &|_| {}).timings;
            let best = &mut solved.timings;
            (best.build, best.refine, best.solve) = (best.build.min(t.build), best.refine.min(t.refine), best.solve.min(t.solve));
            (best.estimate, best.importance) = (best.estimate.min(t.estimate), best.importance.min(t.importance));
            runs += 1;
        }
        repeats = Some(t_runs.elapsed().as_secs_f64());
    }
    (solved, runs, repeats)
}

/// Solves the named bands beyond the first pack of three, one solve per pack: each pack's polygon
/// results and each band's power, the first pack's from `solved`. Every second in a phase and
/// every missed target of a further pack is added to `solved`.
fn solve_other_packs(
    scene: &Scene,
    b: &Bands,
    oracle: &dyn Oracle,
    config: &Config,
    solved: &mut Solved,
    reporter: &Reporter,
) -> (Vec<Vec<PolygonResult>>, Vec<output::BandPower>) {
    let mut pack_results = vec![output::polygon_results(&solved.hierarchy, &solved.solution)];
    let mut pack_powers: Vec<output::BandPower> = Vec::new();
    pack_powers.extend(&output::channel_powers(solved)[..b.pack_range(0).len()]);
    for k in 1..b.packs() {
        reporter.phase(&format!("solving bands {}", b.names[b.pack_range(k)].join(", ")));
        let mut pack = scene.clone();
        pack.materials = b.pack_materials(k, &scene.materials);
        pack.distant = b.pack_distant(k);
        let s = pipeline::run(&pack, oracle, config, &|p| reporter.event(p));
        pack_results.push(output::polygon_results(&s.hierarchy, &s.solution));
        pack_powers.extend(&output::channel_powers(&s)[..b.pack_range(k).len()]);
        let (t, all) = (s.timings, &mut solved.timings);
        (all.build, all.refine, all.solve, all.estimate) =
            (all.build + t.build, all.refine + t.refine, all.solve + t.solve, all.estimate + t.estimate);
        solved.warnings.extend(s.warnings.iter().map(|w| format!("bands {}: {w}", b.names[b.pack_range(k)].join(", "))));
        if solved.target_missed.is_none() {
            solved.target_missed = s.target_missed;
        }
    }
    (pack_results, pack_powers)
}

/// Irradiance at the calculation points (with the seconds it took) and on each grid.
struct Gathered {
    points: Option<(Vec<PointIrradiance>, f64)>,
    grids: Vec<Vec<PointIrradiance>>,
    grid_seconds: f64,
}

/// Irradiance at the points and on the grids. The importance rounds read every set from the final
/// solution already (their errors count what the last round moved); without them, each set is
/// gathered now.
fn gather(solved: &mut Solved, points: Option<&Vec<CalcPoint>>, grids: &[Grid], config: &Config, reporter: &Reporter) -> Gathered {
    let mut read = std::mem::take(&mut solved.point_results).into_iter();
    let solved = &*solved;
    let points_config = radiosity::points::PointsConfig { use_visibility: config.use_visibility, ..Default::default() };
    let points = points.map(|points| {
        reporter.phase(&format!("gathering at {} calculation points", points.len()));
        let t = Instant::now();
        let results = read.next().unwrap_or_else(|| radiosity::points::gather(solved, points, &points_config));
        (results, t.elapsed().as_secs_f64())
    });
    let t_grids = Instant::now();
    let grids = grids
        .iter()
        .map(|g| {
            reporter.phase(&format!("gathering at grid `{}` ({} points)", g.spec.name, g.points.len()));
            read.next().unwrap_or_else(|| radiosity::points::gather(solved, &g.points, &points_config))
        })
        .collect();
    Gathered { points, grids, grid_seconds: t_grids.elapsed().as_secs_f64() }
}

/// `stats.json` of the solve, before the points, grids and timings are added.
fn stats(args: &SolveArgs, scene: &Scene, solved: &Solved, params: &[(String, f64)], config: &Config, load: f64) -> Stats {
    let oracle_params: serde_json::Map<String, serde_json::Value> = params.iter().map(|(k, v)| (k.clone(), serde_json::json!(v))).collect();
    let params = serde_json::json!({
        "oracle": oracle_params,
        "eps": args.options.eps(),
        "target_error": config.target_error,
        "max_memory_bytes": config.max_memory_bytes,
        "rays": args.options.common.rays,
        "seed": args.options.common.seed,
        "min_area": args.options.common.min_area,
        "visibility": if args.options.common.no_visibility { "none" } else { config.visibility_method.name() },
        "criterion": config.criterion.name(),
    });
    let mut stats = Stats::from_solved(scene, solved, &args.oracle, params, (load, 0.0, 0.0));
    stats.target_error = config.target_error;
    stats
}

/// Photometric scenes show lux (irradiance) or lm/m² (radiosity); the values are already in lm.
fn photometric_unit(mut fc: FalseColourConfig, scene: &Scene) -> FalseColourConfig {
    if scene.units == radiosity::photometry::Units::Photometric {
        fc.unit = match fc.quantity {
            output::Quantity::Irradiance => "lx",
            output::Quantity::Radiosity => "lm/m²",
            output::Quantity::DaylightFactor => fc.unit,
        };
    }
    fc
}

/// `patches.csv` and `groups.csv` with one column per named band, from each pack's results.
fn write_band_files(args: &SolveArgs, scene: &Scene, b: &Bands, pack_results: &[Vec<PolygonResult>]) -> anyhow::Result<()> {
    let packs: Vec<&[PolygonResult]> = pack_results.iter().map(Vec::as_slice).collect();
    for (name, write) in [
        ("patches.csv", output::write_patches_csv_bands as fn(&mut output::atomic::AtomicFile, &_, &[String], &[&[PolygonResult]]) -> _),
        ("groups.csv", output::write_groups_csv_bands),
    ] {
        let path = args.out.join(name);
        output::atomic::write_file(&path, |w| write(w, scene, &b.names, &packs))
            .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    Ok(())
}

/// The target holds for the points and grids too, or the answer says it does not: one warning
/// per set whose estimated error is over the target.
fn target_warnings(config: &Config, solved: &Solved, gathered: &Gathered, grids: &[Grid]) -> Vec<String> {
    let mut warnings = Vec::new();
    let sets = gathered.points.iter().map(|(r, _)| ("the calculation points".to_owned(), r.as_slice()));
    let sets = sets.chain(grids.iter().zip(&gathered.grids).map(|(g, r)| (format!("grid `{}`", g.spec.name), r.as_slice())));
    for (what, results) in sets {
        if let (Some(target), Some(worst)) = (config.target_error, radiosity::points::worst_relative_error(results))
            && worst > target
        {
            // What the sky's cells alone leave, which no refinement lowers.
            let sky = radiosity::points::error_scales(results)
                .map(|s| results.iter().zip(s).map(|(r, s)| radiosity::points::photopic(r.sky_err) / s).fold(0.0, f64::max))
                .unwrap_or(0.0);
            let sky = if sky > target {
                format!(
                    "; the sky's cells alone leave up to {:.3}% (more `directions` in [sky] lower it, refinement does not)",
                    100.0 * sky
                )
            } else {
                String::new()
            };
            warnings.push(format!(
                "{what}: estimated error up to {:.3}% of a point's value (or of 1% of the largest), above the target {:.3}%{}{sky} \
                 (see h_err)",
                100.0 * worst,
                100.0 * target,
                match solved.importance {
                    Some(r) if r.capped =>
                        format!(" after {} importance round(s), stopped at their memory cap or with the target out of its reach", r.rounds),
                    Some(r) if r.stalled => format!(" after {} importance round(s), which stopped bringing it down", r.rounds),
                    Some(r) => format!(" after {} importance round(s)", r.rounds),
                    None => " (the levels did not meet the target, so no importance round ran)".to_owned(),
                }
            ));
        }
    }
    warnings
}

/// The console summary, and the exit: an error when the solve stopped at its budget short of the
/// target (unless `--allow-over-budget`); a missed target is said even with `--quiet`.
fn finish(args: &SolveArgs, scene: &Scene, stats: &Stats, false_colour: bool) -> anyhow::Result<()> {
    if !args.quiet {
        let pictures = match (args.no_image, false_colour) {
            (true, _) => "",
            (false, true) => "image.png,view.vf,falsecolor.png,",
            (false, false) => "image.png,view.vf,",
        };
        print_summary(stats, &args.out, pictures);
    }
    let fails = stats.target_missed.filter(|m| m.stopped_by.is_budget() && !args.allow_over_budget);
    if let Some(m) = stats.target_missed.filter(|_| args.quiet && fails.is_none()) {
        eprintln!("warning: {}", m.message());
    }
    if let Some(m) = fails {
        anyhow::bail!("{}: {} (outputs written to {}, stats.json `target_missed`)", scene.name, m.message(), args.out.display());
    }
    Ok(())
}
