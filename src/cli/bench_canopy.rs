//! `radiosity bench canopy`: a plant scientist's canopy, solved at the default settings and checked
//! against the tests' independent photon tracer (`tests/support/photons.rs`, which shares no code
//! with the solver).
//!
//! Each canopy is what `radiosity generate canopy` places (square leaves of 10 cm with normals
//! uniform over the sphere, centres uniform in a 10 × 10 × 2 m slab 0.5 m above the ground), with
//! optics a user of two bands would give it: transmitting leaves (PAR ρ 0.10 τ 0.05, NIR ρ 0.45
//! τ 0.40) over a 10 × 10 m ground (ρ 0.10, 0.25), the sun 30° from the zenith (400 and 380 W/m²
//! normal) and a uniform 145-cell sky (60 and 40 W/m² horizontal). Each is solved in its own process
//! (`radiosity solve`, default settings): time, peak memory, links, the error estimate and the
//! power balance per band; then the power the leaves and the ground absorb per band against the
//! tracer's, with the tracer's own standard error. (The solver's sky is 145 cells, the tracer's
//! continuous.)

use anyhow::Context;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

#[allow(dead_code)]
#[path = "../../tests/support/photons.rs"]
mod photons;

/// Arguments of `bench canopy`.
#[derive(clap::Args, Debug)]
pub struct CanopyBenchArgs {
    /// Leaf counts, comma-separated (one canopy each, in the same 10 × 10 m plot).
    #[arg(long, value_delimiter = ',', default_value = "800,3200")]
    pub leaves: Vec<usize>,
    /// Photons per band for the reference (0: no reference).
    #[arg(long, default_value_t = 4_000_000)]
    pub photons: usize,
    /// Seed of the leaves' placement.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Keep each canopy's scene file and outputs in a folder here (default: a temporary folder).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Seconds a solve may take; one past it is stopped and reported as unfinished.
    #[arg(long, default_value_t = 900.0)]
    pub timeout: f64,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
    /// An option passed on to every `radiosity solve` (repeatable), e.g.
    /// `--solve-arg=--target-error=0.005`.
    #[arg(long = "solve-arg", value_name = "ARG", allow_hyphen_values = true)]
    pub solve_args: Vec<String>,
}

/// The bands, and the optics and light in each.
const BANDS: [&str; 2] = ["PAR", "NIR"];
const LEAF_REFLECTANCE: [f64; 2] = [0.10, 0.45];
const LEAF_TRANSMITTANCE: [f64; 2] = [0.05, 0.40];
const GROUND_REFLECTANCE: [f64; 2] = [0.10, 0.25];
const SUN_NORMAL: [f64; 2] = [400.0, 380.0];
const SKY_HORIZONTAL: [f64; 2] = [60.0, 40.0];
const SUN_ZENITH_DEG: f64 = 30.0;
/// Half the side of the plot (and of the ground).
const HALF: f64 = 5.0;
/// Photon batches (the reference's standard error comes from their spread).
const BATCHES: usize = 16;

/// One band of one canopy.
#[derive(Clone, Debug)]
struct BandRow {
    band: &'static str,
    /// `(absorbed + escaped) / incident` as the solver reports it.
    balance: f64,
    leaves_absorbed: f64,
    ground_absorbed: f64,
    /// The tracer's figures and standard errors (absent without photons).
    traced_leaves: Option<(f64, f64)>,
    traced_ground: Option<(f64, f64)>,
}

/// One canopy.
#[derive(Clone, Debug)]
struct Row {
    leaves: usize,
    lai: f64,
    /// Whether the solve finished within the time limit.
    finished: bool,
    time_s: f64,
    peak_rss_bytes: u64,
    links: u64,
    elements: u64,
    error_estimate: Option<f64>,
    target_met: bool,
    bands: Vec<BandRow>,
    trace_s: f64,
}

/// Runs `bench canopy`.
pub fn run(args: &CanopyBenchArgs) -> anyhow::Result<()> {
    anyhow::ensure!(!args.leaves.is_empty() && args.leaves.iter().all(|&n| n > 0), "--leaves: give positive leaf counts");
    anyhow::ensure!(args.timeout > 0.0, "--timeout must be positive");
    let exe = std::env::current_exe().context("finding the radiosity executable")?;
    let temp = std::env::temp_dir().join(format!("radiosity-bench-canopy-{}", std::process::id()));
    // Absolute: each solve runs in its canopy's folder.
    let base = std::path::absolute(args.out.clone().unwrap_or_else(|| temp.clone())).context("--out: cannot resolve the folder")?;
    let mut rows = Vec::new();
    for &n in &args.leaves {
        let dir = base.join(format!("canopy-{n}"));
        let leaves = write_canopy(n, args.seed, &dir)?;
        if !args.json {
            eprintln!("canopy of {n} leaves: solving ...");
        }
        let mut row = solve(&exe, &dir, args.timeout, &args.solve_args)?;
        row.leaves = n;
        row.lai = n as f64 * 0.01 / (2.0 * HALF).powi(2);
        if args.photons > 0 {
            if !args.json {
                eprintln!("canopy of {n} leaves: tracing {} photons per band ...", args.photons);
            }
            let t0 = Instant::now();
            let traced = trace(&leaves, args.photons, args.seed);
            row.trace_s = t0.elapsed().as_secs_f64();
            for (b, (l, g)) in traced.into_iter().enumerate() {
                if let Some(band) = row.bands.get_mut(b) {
                    band.traced_leaves = Some(l);
                    band.traced_ground = Some(g);
                }
            }
        }
        if !args.json {
            print!("{}", format_row(&row, rows.is_empty()));
        }
        rows.push(row);
    }
    if args.out.is_none() {
        std::fs::remove_dir_all(&temp).ok();
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows.iter().map(Row::json).collect::<Vec<_>>())?);
    }
    Ok(())
}

impl Row {
    fn json(&self) -> serde_json::Value {
        let pair = |p: Option<(f64, f64)>| p.map(|(m, e)| serde_json::json!({ "mean": m, "std_error": e }));
        serde_json::json!({
            "leaves": self.leaves,
            "lai": self.lai,
            "finished": self.finished,
            "time_s": self.time_s,
            "peak_rss_bytes": self.peak_rss_bytes,
            "links": self.links,
            "elements": self.elements,
            "error_estimate": self.error_estimate,
            "target_met": self.target_met,
            "trace_s": self.trace_s,
            "bands": self.bands.iter().map(|b| serde_json::json!({
                "band": b.band,
                "balance": b.balance,
                "leaves_absorbed": b.leaves_absorbed,
                "ground_absorbed": b.ground_absorbed,
                "traced_leaves": pair(b.traced_leaves),
                "traced_ground": pair(b.traced_ground),
            })).collect::<Vec<_>>(),
        })
    }
}

/// Writes the canopy of `n` leaves into `dir` (`canopy.toml`, `leaves.obj`) and returns its leaves.
fn write_canopy(n: usize, seed: u64, dir: &Path) -> anyhow::Result<Vec<[[f64; 3]; 4]>> {
    use radiosity::canopy::{self, CanopyParams, SceneFileOptions};
    let params =
        CanopyParams { lai: n as f64 * 0.01 / (2.0 * HALF).powi(2), leaf_size: 0.1, extent: 2.0 * HALF, seed, ..CanopyParams::default() };
    let c = canopy::random_leaves(&params)?;
    anyhow::ensure!(c.leaves.len() == n, "the canopy generator placed {} leaves for {n}", c.leaves.len());
    // The generator's OBJ of the leaves; the scene file around it is this benchmark's.
    canopy::write_scene_file(&c, &SceneFileOptions::default(), dir)?;
    let (s, z) = (SUN_ZENITH_DEG.to_radians().sin(), SUN_ZENITH_DEG.to_radians().cos());
    let list = |v: [f64; 2]| format!("[{}, {}]", v[0], v[1]);
    let text = format!(
        "# bench canopy: {n} leaves of 10 cm (seed {seed}), two bands, sun and a uniform sky\n\
         name = \"canopy\"\nobj = \"leaves.obj\"\nbands = [\"PAR\", \"NIR\"]\n\n\
         [[material]]\nname = \"leaf\"\nreflectance = {}\ntransmittance = {}\n\n\
         [[material]]\nname = \"ground\"\nreflectance = {}\n\n\
         [[polygon]]\nmaterial = \"ground\"\nvertices = [[-{HALF}, -{HALF}, 0], [{HALF}, -{HALF}, 0], [{HALF}, {HALF}, 0], [-{HALF}, {HALF}, 0]]\n\n\
         [sun]\ndirection = [0, {s:.12}, {:.12}]\ndirect_normal = {}\n\n\
         [sky]\nmodel = \"uniform\"\ndiffuse_horizontal = {}\ndirections = 145\n",
        list(LEAF_REFLECTANCE),
        list(LEAF_TRANSMITTANCE),
        list(GROUND_REFLECTANCE),
        -z,
        list(SUN_NORMAL),
        list(SKY_HORIZONTAL),
    );
    let path = dir.join("canopy.toml");
    std::fs::write(&path, text).with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(c.leaves.iter().map(|l| l.map(|v| v.to_array())).collect())
}

/// Solves `dir/canopy.toml` in a child process (with the `extra` options; stopped after
/// `timeout` seconds) and reads its figures.
fn solve(exe: &Path, dir: &Path, timeout: f64, extra: &[String]) -> anyhow::Result<Row> {
    let out = dir.join("out");
    let mut child = Command::new(exe)
        .args(["solve", "canopy.toml", "--quiet", "--no-image", "--out"])
        .arg(&out)
        .args(extra)
        .current_dir(dir)
        .spawn()
        .with_context(|| format!("running {}", exe.display()))?;
    let t0 = Instant::now();
    let status = super::bench::wait_or_kill(&mut child, timeout)?;
    let mut row = Row {
        leaves: 0,
        lai: 0.0,
        finished: status.is_some(),
        time_s: t0.elapsed().as_secs_f64(),
        peak_rss_bytes: 0,
        links: 0,
        elements: 0,
        error_estimate: None,
        target_met: false,
        bands: Vec::new(),
        trace_s: 0.0,
    };
    let Some(status) = status else { return Ok(row) };
    anyhow::ensure!(status.success(), "{}: solve failed ({status})", dir.join("canopy.toml").display());
    let path = out.join("stats.json");
    let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read", path.display()))?;
    let stats: serde_json::Value = serde_json::from_str(&text).with_context(|| format!("{}: invalid JSON", path.display()))?;
    row.time_s = stats["time_s"]["total"].as_f64().unwrap_or(row.time_s);
    row.peak_rss_bytes = stats["peak_rss_bytes"].as_u64().unwrap_or(0);
    row.links = stats["links"].as_u64().unwrap_or(0);
    row.elements = stats["leaves"].as_u64().unwrap_or(0);
    row.error_estimate = stats["error_estimate"].as_f64();
    row.target_met = stats["target_missed"].is_null() && row.error_estimate.is_some();
    let patches = out.join("patches.csv");
    let csv = std::fs::read_to_string(&patches).with_context(|| format!("{}: cannot read", patches.display()))?;
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).with_context(|| format!("{}: no column `{name}`", patches.display()));
    let material = col("material")?;
    let cols: Vec<usize> = BANDS.iter().map(|b| col(&format!("absorbed_{b}"))).collect::<anyhow::Result<_>>()?;
    let (mut leaves, mut ground) = ([0.0; 2], [0.0; 2]);
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let into = if f.get(material) == Some(&"ground") { &mut ground } else { &mut leaves };
        for (b, &c) in cols.iter().enumerate() {
            into[b] += f.get(c).and_then(|v| v.parse::<f64>().ok()).with_context(|| format!("{}: bad row {line}", patches.display()))?;
        }
    }
    for (b, band) in BANDS.into_iter().enumerate() {
        let p = &stats["power_by_band"][band];
        let (incident, absorbed, escaped) = (p["incident"].as_f64(), p["absorbed"].as_f64(), p["escaped"].as_f64());
        let balance = match (incident, absorbed, escaped) {
            (Some(i), Some(a), Some(e)) if i > 0.0 => (a + e) / i,
            _ => f64::NAN,
        };
        row.bands.push(BandRow {
            band,
            balance,
            leaves_absorbed: leaves[b],
            ground_absorbed: ground[b],
            traced_leaves: None,
            traced_ground: None,
        });
    }
    Ok(row)
}

/// The tracer's absorbed power of the leaves and of the ground per band, each with its standard
/// error: the two bands traced at once.
fn trace(leaves: &[[[f64; 3]; 4]], photons: usize, seed: u64) -> Vec<((f64, f64), (f64, f64))> {
    let ground = [[-HALF, -HALF, 0.0], [HALF, -HALF, 0.0], [HALF, HALF, 0.0], [-HALF, HALF, 0.0]];
    let (s, z) = (SUN_ZENITH_DEG.to_radians().sin(), SUN_ZENITH_DEG.to_radians().cos());
    let n = leaves.len();
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..BANDS.len())
            .map(|b| {
                scope.spawn(move || {
                    let mut surfaces: Vec<photons::Surface> = leaves
                        .iter()
                        .map(|&v| photons::Surface {
                            v,
                            reflectance: LEAF_REFLECTANCE[b],
                            transmittance: LEAF_TRANSMITTANCE[b],
                            two_sided: true,
                        })
                        .collect();
                    surfaces.push(photons::Surface { v: ground, reflectance: GROUND_REFLECTANCE[b], transmittance: 0.0, two_sided: false });
                    let light =
                        photons::Light { sun_direction: [0.0, s, -z], sun_normal: SUN_NORMAL[b], sky_horizontal: SKY_HORIZONTAL[b] };
                    let tally = photons::trace(&surfaces, light, photons, BATCHES, seed.wrapping_mul(0x9E37_79B9).wrapping_add(b as u64));
                    let l = photons::absorbed_by(&tally, |i| i < n);
                    let g = photons::absorbed_by(&tally, |i| i == n);
                    ((l.mean, l.std_error), (g.mean, g.std_error))
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("the tracer does not panic")).collect()
    })
}

/// The row as table lines (with the header first when `header`).
fn format_row(r: &Row, header: bool) -> String {
    let mut s = String::new();
    if header {
        s.push_str(&format!(
            "{:>7} {:>6} {:>9} {:>8} {:>9} {:>9} {:>7} {:>5} {:>8} {:>12} {:>12} {:>8}\n",
            "leaves", "LAI", "time s", "RSS MB", "links", "elements", "est %", "band", "balance", "leaves err %", "ground err %", "noise %"
        ));
    }
    if !r.finished {
        s.push_str(&format!("{:>7} {:>6.3} {:>9} (stopped after {:.0} s)\n", r.leaves, r.lai, "-", r.time_s));
        return s;
    }
    for (k, b) in r.bands.iter().enumerate() {
        let err =
            |solved: f64, traced: Option<(f64, f64)>| traced.map_or("-".to_owned(), |t| format!("{:+.2}", 100.0 * (solved - t.0) / t.0));
        let noise = match (b.traced_leaves, b.traced_ground) {
            (Some(l), Some(g)) => format!("{:.2}", 100.0 * (l.1 / l.0).max(g.1 / g.0)),
            _ => "-".to_owned(),
        };
        let (left, est) = if k == 0 {
            (
                format!(
                    "{:>7} {:>6.3} {:>9.2} {:>8.1} {:>9} {:>9}",
                    r.leaves,
                    r.lai,
                    r.time_s,
                    r.peak_rss_bytes as f64 / 1e6,
                    r.links,
                    r.elements
                ),
                r.error_estimate.map_or("-".to_owned(), |e| format!("{:.2}{}", 100.0 * e, if r.target_met { "" } else { "!" })),
            )
        } else {
            (format!("{:>7} {:>6} {:>9} {:>8} {:>9} {:>9}", "", "", "", "", "", ""), String::new())
        };
        s.push_str(&format!(
            "{left} {est:>7} {:>5} {:>8.5} {:>12} {:>12} {noise:>8}\n",
            b.band,
            b.balance,
            err(b.leaves_absorbed, b.traced_leaves),
            err(b.ground_absorbed, b.traced_ground)
        ));
    }
    s
}
