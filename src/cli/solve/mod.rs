//! `radiosity solve`.

//!
//! The command only turns arguments into a scene and a [`radiosity::pipeline::Config`], and the
//! results into text and files: [`run`] checks the arguments, loads the scene (points and grids
//! with it), builds the configuration, solves, writes the outputs and reports. The steps beside it:
//! `instanced.rs` (scenes solved by the instanced solver), `grids.rs` (the grid files),
//! `report.rs` (the console summary).

mod grids;
mod instanced;
mod report;

use super::picture::PictureArgs;
use super::progress::Reporter;
use super::{SolveOptions, load_scene};
use anyhow::Context;
use grids::write_grids;
use instanced::{refuse_plain_only, solve_instanced};
use radiosity::output::{self, OutputConfig, Stats};
use radiosity::pipeline;
use report::print_summary;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `radiosity solve`.
#[derive(clap::Args, Debug)]
pub struct SolveArgs {
    /// Scene file (.obj with its .mtl, or .mgf), a generated scene (`gen:duplex`, ...) or a
    /// validation scene (`validation:ward-room`, ...); the embedded Cornell box when omitted.
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
    /// Refinement oracle: bf (compiled by `oracle!`), bf-dag (interpreted), bf-hand (written by
    /// hand), or a decision-graph file `*.toml`.
    #[arg(long, default_value = "bf")]
    pub oracle: String,
    /// Oracle parameters, `name=value` (eps is set by --eps unless given here).
    #[arg(long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// No progress display and no summary.
    #[arg(long, short)]
    pub quiet: bool,
    /// Accept a solve that a budget (--max-memory) stopped short of its target error: without it
    /// such a solve writes its outputs and stats.json (`target_missed`) and exits with an error.
    #[arg(long)]
    pub allow_over_budget: bool,
    /// Instancing of a plain scene: `none` solves it as given; `auto` finds objects (OBJ objects /
    /// groups) identical up to a rigid transform and solves them as instances of one prototype,
    /// like a `.toml` scene (`patches.csv` is then in flattening order).
    #[arg(long, value_enum, default_value_t = Instances::None)]
    pub instances: Instances,
    /// Instanced scenes: memory (MB) for the local problems kept for reuse by later instances of
    /// the same prototype (0: refine every instance anew; slower, a little less memory).
    #[arg(long, default_value_t = 16.0, value_name = "MB")]
    pub level_cache_mb: f64,
    /// Instanced scenes: `scene` reuses a refined level for later instances anywhere in the scene;
    /// `subtree` only within one top-level instance's subtree, so that results depend on the
    /// subtree alone: what a run over MPI ranks does (feature `mpi`), byte for byte.
    #[arg(long, default_value = "scene", value_name = "SCOPE")]
    pub level_reuse: radiosity::instancing::LevelReuse,
    /// Instanced scenes: which nesting depths keep their instances closed: `all`, `every-N`
    /// (depths N, 2N, ...; the others are opened in place), or `none` (one flattened problem).
    #[arg(long, default_value = "all", value_name = "POLICY")]
    pub instance_levels: radiosity::instancing::InstanceLevels,
    /// Instanced scenes: point pairs per (polygon, light) from which the direct light of the top
    /// level's lights is ray traced below it, through every instance's own geometry (0: carried by
    /// the parallel beams into each instance, with the instance's average visibility).
    #[arg(long, default_value_t = radiosity::instancing::InstancedConfig::default().direct_samples, value_name = "N")]
    pub direct_samples: u32,
    /// Instanced scenes: how a closed instance re-emits the light it intercepts: `directional`
    /// (through the faces of its box its prototype's face transfer matrix says) or `uniform`
    /// (back through the face it entered, with the mean albedo: the paper's proxy).
    #[arg(long, default_value_t = radiosity::instancing::InstancedConfig::default().proxy_emission, value_name = "MODE")]
    pub proxy_emission: radiosity::instancing::ProxyEmission,
    /// Plain scenes: solve again (build, refine, solve; same results) until this many seconds have
    /// passed, and report each phase's fastest time in `stats.json` (`time_s.runs` says how many
    /// solves; outputs come from the first). For timing small scenes on a noisy machine.
    #[arg(long, default_value_t = 0.0, value_name = "SECONDS")]
    pub time_for: f64,
    /// Calculation points: a CSV file of rows `x,y,z,nx,ny,nz` or `name,x,y,z,nx,ny,nz` (or a
    /// header naming those columns, in any order). Writes points.csv: the irradiance gathered from
    /// the solution on a small receiver at each point facing its normal, per channel and photopic.
    /// Plain scenes only: refused for instanced scenes and `--instances auto`.
    #[arg(long, value_name = "FILE.csv")]
    pub points: Option<PathBuf>,
    /// Calculation grid (repeatable): `name=NAME,origin=X;Y;Z,u=X;Y;Z,v=X;Y;Z,spacing=S` and
    /// optionally `,normal=X;Y;Z` (default u × v): the parallelogram origin + s·u + t·v cut into
    /// cells at most `spacing` wide, a point facing `normal` at each cell's centre. Writes
    /// grid_NAME.csv (as points.csv), grid_NAME.svg (isolux plot) and the figures (e_avg, e_min,
    /// e_max, u0, e_min/e_max) to stats.json under `grids`. Plain scenes only.
    #[arg(long = "grid", value_name = "SPEC")]
    pub grids: Vec<String>,
    /// A grid named `work` this high (scene units) above the floor, facing up, over the floor's
    /// extent less a border zone (EN 12464-1: 0.5 m). The floor: the polygons facing up (within 1°
    /// of the --up axis) at the lowest height among them; their bounding rectangle is the extent.
    #[arg(long, value_name = "HEIGHT")]
    pub work_plane: Option<f64>,
    /// The scene's up axis, for --work-plane.
    #[arg(long, value_enum, default_value_t = Up::Z)]
    pub up: Up,
    /// Width of the border zone left out of --work-plane (scene units; EN 12464-1: 0.5 m).
    #[arg(long, default_value_t = radiosity::points::grid::EN12464_BORDER_M, value_name = "WIDTH")]
    pub work_plane_border: f64,
    /// Largest spacing of the --work-plane points (scene units; default EN 12464-1's
    /// 0.2·5^log10(d), d the longer side).
    #[arg(long, value_name = "SPACING")]
    pub work_plane_spacing: Option<f64>,
    #[command(flatten)]
    pub picture: PictureArgs,
}

/// Values of `--up`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Up {
    /// +x is up.
    X,
    /// +y is up.
    Y,
    /// +z is up.
    Z,
}

impl Up {
    fn axis(self) -> radiosity::points::grid::UpAxis {
        use radiosity::points::grid::UpAxis;
        match self {
            Up::X => UpAxis::X,
            Up::Y => UpAxis::Y,
            Up::Z => UpAxis::Z,
        }
    }
}

/// Most solves `--time-for` times.
const MAX_TIMED_RUNS: u32 = 1000;

/// Values of `--instances`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Instances {
    /// Solve the scene as given.
    None,
    /// Instance repeated objects automatically.
    Auto,
}

/// Runs `radiosity solve`.
pub fn run(args: &SolveArgs) -> anyhow::Result<()> {
    args.options.validate()?;
    anyhow::ensure!(
        args.time_for.is_finite() && (0.0..=3600.0).contains(&args.time_for),
        "--time-for must be between 0 and 3600 s, got {}",
        args.time_for
    );
    anyhow::ensure!((1..=16384).contains(&args.size), "--size must be between 1 and 16384, got {}", args.size);
    anyhow::ensure!(
        args.level_cache_mb.is_finite() && (0.0..=1e6).contains(&args.level_cache_mb),
        "--level-cache-mb must be between 0 and 1e6, got {}",
        args.level_cache_mb
    );
    let toml = args.scene.as_ref().is_some_and(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")));
    let has_grids = !args.grids.is_empty() || args.work_plane.is_some();
    anyhow::ensure!(
        !has_grids || args.instances == Instances::None,
        "--grid and --work-plane apply to plain scenes, not to --instances auto"
    );
    let (view, false_colour) = args.picture.settings(args.instances == Instances::Auto)?;
    // A scene file with luminaires, photometric units or grids is flattened and solved as a plain
    // scene.
    let mut lit_scene = None;
    let mut file_grids = Vec::new();
    let mut bands = None;
    if toml {
        let path = args.scene.as_ref().expect("checked above");
        let (scene, lighting) = radiosity::instancing::load_with_lighting(path)?;
        // Daylight on a scene without instances takes the plain solve, which splits elements
        // along the sun's shadows and refines to the error target; with instances, the instanced
        // solve traces it through the nested BVHs.
        let flat_daylight = lighting.bands.has_daylight() && scene.prototypes[scene.root as usize].instances.is_empty();
        if lighting.needs_plain_solve() || flat_daylight || !scene.grids.is_empty() || has_grids {
            anyhow::ensure!(args.instances == Instances::None, "--instances auto applies to plain OBJ / MGF scenes");
            let instanced = !scene.prototypes[scene.root as usize].instances.is_empty();
            if instanced && lighting.bands.packs() > 1 && !args.quiet {
                eprintln!(
                    "note: {} bands: the scene is flattened and solved plain, one solve per three bands \
                     (up to three bands solve instanced, which on plants is much faster)",
                    lighting.bands.len()
                );
            }
            let mut plain = radiosity::instancing::flatten(&scene, &radiosity::instancing::FlattenOptions::default())?;
            plain.luminaires = lighting.luminaires;
            plain.units = lighting.units;
            plain.distant = lighting.bands.pack_distant(0);
            // Under the sun and sky a lone face whose back can receive light is two-sided.
            radiosity::daylight::two_sided_where_backs_see_light(&mut plain);
            if lighting.bands.declared || lighting.bands.has_daylight() {
                bands = Some(lighting.bands);
            }
            file_grids.clone_from(&scene.grids);
            lit_scene = Some(plain);
        } else {
            refuse_plain_only(args)?;
            return solve_instanced(args, &scene, None, &lighting.bands);
        }
    }
    #[cfg(feature = "mpi")]
    super::mpi::refuse_plain()?;
    if args.instances == Instances::Auto {
        refuse_plain_only(args)?;
        let scene = load_scene(args.scene.as_ref(), args.options.common.allow_dark)?;
        let t0 = Instant::now();
        let auto = radiosity::instancing::auto_instance(&scene, &radiosity::instancing::AutoOptions::default());
        if !args.quiet {
            if let Some(w) = scene.warnings.summary() {
                eprintln!("warning: {w}");
            }
            println!("{} in {:.3}s", auto.report, t0.elapsed().as_secs_f64());
        }
        return solve_instanced(args, &auto.scene, Some(&auto.report), &radiosity::instancing::bands::Bands::default());
    }
    let t0 = Instant::now();
    let reporter = Reporter::new(args.quiet);
    reporter.phase("loading scene");
    // The points file is read first, so that a bad row stops the command before the solve.
    let points = args.points.as_deref().map(radiosity::points::read_points).transpose()?;
    let mut grid_specs = args.grids.iter().map(|g| radiosity::points::GridSpec::parse_arg(g)).collect::<Result<Vec<_>, _>>()?;
    grid_specs.extend(file_grids);
    let scene = match lit_scene {
        Some(scene) => scene,
        None => load_scene(args.scene.as_ref(), args.options.common.allow_dark)?,
    };
    if let Some(height) = args.work_plane {
        let spec = radiosity::points::grid::work_plane(&scene, height, args.up.axis(), args.work_plane_border, args.work_plane_spacing)?;
        grid_specs.push(spec);
    }
    let mut grids = Vec::with_capacity(grid_specs.len());
    for spec in &grid_specs {
        anyhow::ensure!(!grids.iter().any(|g: &radiosity::points::Grid| g.spec.name == spec.name), "grid `{}` given twice", spec.name);
        grids.push(spec.grid()?);
    }
    let load = t0.elapsed().as_secs_f64();
    let mut params = super::oracle::parse_params(&args.params)?;
    if !params.iter().any(|(k, _)| k == "eps") {
        params.push(("eps".to_string(), args.options.eps()));
    }
    let oracle = radiosity::oracle::registry::oracle(&args.oracle, &params)?;
    // The method the solve will use (an oracle that needs shafts gets them), as stats.json reports it.
    let mut config = args.options.config();
    config.visibility_method = pipeline::effective_visibility(oracle.as_ref(), config.visibility_method);
    // The target applies to the calculation points and every grid as well (importance rounds).
    let point_sets: Vec<&[radiosity::points::CalcPoint]> =
        points.iter().map(Vec::as_slice).chain(grids.iter().map(|g| g.points.as_slice())).collect();
    let mut solved = pipeline::run_with_points(&scene, oracle.as_ref(), &config, &point_sets, &|p| reporter.event(p));
    let mut runs = 1;
    let mut repeats = None;
    if args.time_for > 0.0 {
        reporter.phase("timing further solves");
        let t_runs = Instant::now();
        while runs < MAX_TIMED_RUNS && t_runs.elapsed().as_secs_f64() < args.time_for {
            let t = pipeline::run_with_points(&scene, oracle.as_ref(), &config, &point_sets, &|_| {}).timings;
            let best = &mut solved.timings;
            (best.build, best.refine, best.solve) = (best.build.min(t.build), best.refine.min(t.refine), best.solve.min(t.solve));
            (best.estimate, best.importance) = (best.estimate.min(t.estimate), best.importance.min(t.importance));
            runs += 1;
        }
        repeats = Some(t_runs.elapsed().as_secs_f64());
    }
    // Named bands beyond the first three: one more solve per pack of three.
    let declared = bands.as_ref().filter(|b| b.declared);
    anyhow::ensure!(
        declared.is_none() || (points.is_none() && grids.is_empty()),
        "--points, --grid, --work-plane and [[grid]] take RGB scenes for now, not scenes with named `bands`"
    );
    let mut pack_results = vec![output::polygon_results(&solved.hierarchy, &solved.solution)];
    let mut pack_powers: Vec<output::BandPower> = Vec::new();
    if let Some(b) = declared {
        pack_powers.extend(&output::channel_powers(&solved)[..b.pack_range(0).len()]);
        for k in 1..b.packs() {
            reporter.phase(&format!("solving bands {}", b.names[b.pack_range(k)].join(", ")));
            let mut pack = scene.clone();
            pack.materials = b.pack_materials(k, &scene.materials);
            pack.distant = b.pack_distant(k);
            let s = pipeline::run(&pack, oracle.as_ref(), &config, &|p| reporter.event(p));
            pack_results.push(output::polygon_results(&s.hierarchy, &s.solution));
            pack_powers.extend(&output::channel_powers(&s)[..b.pack_range(k).len()]);
            // Every second in a phase, every missed target reported.
            let (t, all) = (s.timings, &mut solved.timings);
            (all.build, all.refine, all.solve, all.estimate) =
                (all.build + t.build, all.refine + t.refine, all.solve + t.solve, all.estimate + t.estimate);
            solved.warnings.extend(s.warnings.iter().map(|w| format!("bands {}: {w}", b.names[b.pack_range(k)].join(", "))));
            if solved.target_missed.is_none() {
                solved.target_missed = s.target_missed;
            }
        }
    }
    // The importance rounds read every set from the final solution already (their errors count
    // what the last round moved); without them, each set is gathered now.
    let mut read = std::mem::take(&mut solved.point_results).into_iter();
    let gathered = points.as_ref().map(|points| {
        reporter.phase(&format!("gathering at {} calculation points", points.len()));
        let t = Instant::now();
        let config = radiosity::points::PointsConfig { use_visibility: config.use_visibility, ..Default::default() };
        let results = read.next().unwrap_or_else(|| radiosity::points::gather(&solved, points, &config));
        (points, results, t.elapsed().as_secs_f64())
    });
    let t_grids = Instant::now();
    let grid_results: Vec<Vec<radiosity::points::PointIrradiance>> = grids
        .iter()
        .map(|g| {
            reporter.phase(&format!("gathering at grid `{}` ({} points)", g.spec.name, g.points.len()));
            let config = radiosity::points::PointsConfig { use_visibility: config.use_visibility, ..Default::default() };
            read.next().unwrap_or_else(|| radiosity::points::gather(&solved, &g.points, &config))
        })
        .collect();
    let grid_seconds = t_grids.elapsed().as_secs_f64();
    reporter.phase("writing outputs");
    let t_out = Instant::now();
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
    let mut stats = Stats::from_solved(&scene, &solved, &args.oracle, params, (load, 0.0, 0.0));
    stats.target_error = config.target_error;
    if let Some(b) = &bands {
        stats.sun.clone_from(&b.sun_report);
    }
    if let Some(b) = declared {
        stats.set_band_powers(&b.names, &pack_powers, b.has_daylight());
        stats.bands.clone_from(&b.names);
        // Pictures show the first band in grey.
        for v in solved.solution.radiosity.iter_mut().chain(solved.solution.irradiance.iter_mut()) {
            *v = [v[0]; 3];
        }
    }
    // Photometric scenes show lux (irradiance) or lm/m² (radiosity); the values are already in lm.
    let false_colour = false_colour.map(|mut fc| {
        if scene.units == radiosity::photometry::Units::Photometric {
            fc.unit = match fc.quantity {
                output::Quantity::Irradiance => "lx",
                output::Quantity::Radiosity => "lm/m²",
            };
        }
        fc
    });
    let out_config = OutputConfig {
        image: !args.no_image,
        render: output::RenderConfig { width: args.size, height: args.size, ..Default::default() },
        view,
        false_colour,
    };
    output::write_solution(&args.out, &scene, &solved, &out_config)?;
    if let Some(b) = declared {
        let packs: Vec<&[output::PolygonResult]> = pack_results.iter().map(Vec::as_slice).collect();
        for (name, write) in [
            (
                "patches.csv",
                output::write_patches_csv_bands as fn(&mut output::atomic::AtomicFile, &_, &[String], &[&[output::PolygonResult]]) -> _,
            ),
            ("groups.csv", output::write_groups_csv_bands),
        ] {
            let path = args.out.join(name);
            output::atomic::write_file(&path, |w| write(w, &scene, &b.names, &packs))
                .with_context(|| format!("{}: cannot write", path.display()))?;
        }
    }
    if let Some((points, results, seconds)) = &gathered {
        let path = args.out.join("points.csv");
        output::atomic::write_file(&path, |w| output::write_points_csv_in(w, points, results, scene.units))
            .with_context(|| format!("{}: cannot write", path.display()))?;
        stats.points = Some(points.len());
        stats.point_rays = Some(results.iter().map(|r| r.rays).sum());
        stats.time_s.points = Some(*seconds);
    }
    if !grids.is_empty() {
        stats.grids = Some(write_grids(&args.out, &grids, &grid_results, scene.units)?);
        stats.time_s.grids = Some(grid_seconds);
    }
    // The target holds for the points and grids too, or the answer says it does not.
    let sets = gathered.iter().map(|(_, r, _)| ("the calculation points".to_owned(), r.as_slice()));
    let sets = sets.chain(grids.iter().zip(&grid_results).map(|(g, r)| (format!("grid `{}`", g.spec.name), r.as_slice())));
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
            stats.solve_warnings.push(format!(
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
    stats.time_s.output = t_out.elapsed().as_secs_f64();
    stats.time_s.total = t0.elapsed().as_secs_f64();
    stats.time_s.runs = runs;
    stats.time_s.repeats = repeats;
    stats.peak_rss_bytes = output::peak_rss_bytes();
    output::write_stats(&args.out, &stats)?;
    reporter.finish();
    if !args.quiet {
        let pictures = match (args.no_image, false_colour.is_some()) {
            (true, _) => "",
            (false, true) => "image.png,view.vf,falsecolor.png,",
            (false, false) => "image.png,view.vf,",
        };
        print_summary(&stats, &args.out, pictures);
    }
    let fails = stats.target_missed.filter(|m| m.stopped_by.is_budget() && !args.allow_over_budget);
    if let Some(m) = stats.target_missed.filter(|_| args.quiet && fails.is_none()) {
        // A missed target is said even with --quiet.
        eprintln!("warning: {}", m.message());
    }
    if let Some(m) = fails {
        anyhow::bail!("{}: {} (outputs written to {}, stats.json `target_missed`)", scene.name, m.message(), args.out.display());
    }
    Ok(())
}
