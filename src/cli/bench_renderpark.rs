//! `radiosity bench renderpark`: interiors lit by many small emitters (RenderPark's scenes by path,
//! and the generated `gen:office` and `gen:classroom`) solved at a range of target errors against a
//! finer solve of the same scene, each solve in its own process with a time limit: time, peak RSS,
//! links, the estimate, and the true errors it claims to bound (the worst polygon mean relative to
//! the largest non-emitting one) and that a user compares programs by (the worst material's
//! luminance-weighted mean, relative to its own and to the largest material's), then the time each
//! accuracy took, beside RenderPark's default figures measured on this machine class.
//!
//! RenderPark is GPL and never runs from here: its figures are constants measured with its own
//! binary (`shared/notes/crates.md`).

use anyhow::Context;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Arguments of `bench renderpark`.
#[derive(clap::Args, Debug)]
pub struct RenderParkBenchArgs {
    /// Scenes (MGF or OBJ files, or generated names); default: `gen:office` and `gen:classroom`,
    /// and with `--dir` RenderPark's cube, office2, examp1, office3, classroom and Soda Hall.
    pub scenes: Vec<String>,
    /// RenderPark's scene folder (`renderpark_mgf`), whose scenes are added to the default list.
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// Target errors solved at (`radiosity solve --target-error`), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "0.03,0.01,0.003")]
    pub targets: Vec<f64>,
    /// Target error of the reference solve of each scene (kept under `--out` and reused).
    #[arg(long, default_value_t = 0.001)]
    pub reference_target: f64,
    /// Seed of the reference solve: another seed than the other solves' (1), so that the
    /// references' visibility noise is independent of theirs.
    #[arg(long, default_value_t = 2)]
    pub reference_seed: u64,
    /// Longest a solve may take, seconds (the reference's too); slower ones are stopped and
    /// reported as such.
    #[arg(long, default_value_t = 600.0, value_name = "SECONDS")]
    pub timeout: f64,
    /// Folder of the kept references and of `renderpark.csv`.
    #[arg(long, default_value = "bench-renderpark")]
    pub out: PathBuf,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// RenderPark's scenes under its folder `dir`, in order of size.
fn renderpark_scenes(dir: &Path) -> Vec<String> {
    ["cube.mgf", "office2/office2.mgf", "examp1.mgf", "office3/office.mgf", "salon/classroom.mgf", "soda.mgf"]
        .iter()
        .map(|p| dir.join(p).display().to_string())
        .collect()
}

/// What one finished solve wrote: its figures and its per-polygon radiosity.
struct Run {
    stats: serde_json::Value,
    radiosity: Vec<[f64; 3]>,
}

/// Solves `scene` in a child process into `out`, stopping it after `timeout`; `None` when it was
/// stopped.
fn solve(exe: &Path, scene: &str, target: f64, seed: u64, timeout: f64, out: &Path) -> anyhow::Result<Option<Run>> {
    let mut child = Command::new(exe)
        .args(["solve", "--quiet", "--no-image", "--target-error", &target.to_string(), "--seed", &seed.to_string(), "--out"])
        .arg(out)
        .arg(scene)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .with_context(|| format!("running {}", exe.display()))?;
    let Some(status) = super::bench::wait_or_kill(&mut child, timeout)? else { return Ok(None) };
    if !status.success() {
        let mut err = String::new();
        if let Some(mut e) = child.stderr.take() {
            use std::io::Read;
            e.read_to_string(&mut err)?;
        }
        anyhow::bail!("{scene} at target {target}: solve failed ({status}): {}", err.trim());
    }
    read_run(out).map(Some)
}

/// Reads the `stats.json` and `patches.csv` a solve wrote into `dir`.
fn read_run(dir: &Path) -> anyhow::Result<Run> {
    let path = dir.join("stats.json");
    let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read", path.display()))?;
    let stats: serde_json::Value = serde_json::from_str(&text).with_context(|| format!("{}: invalid JSON", path.display()))?;
    let path = dir.join("patches.csv");
    let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read", path.display()))?;
    let mut lines = text.lines();
    let headers = split_csv(lines.next().unwrap_or(""));
    let col = |name: &str| headers.iter().position(|h| h == name).with_context(|| format!("{}: no column {name}", path.display()));
    let cols = [col("b_r")?, col("b_g")?, col("b_b")?];
    let mut radiosity = Vec::new();
    for (line, record) in lines.enumerate() {
        let record = split_csv(record);
        let value = |c: usize| -> anyhow::Result<f64> {
            record.get(c).and_then(|v| v.parse().ok()).with_context(|| format!("{}: line {}: not a number", path.display(), line + 2))
        };
        radiosity.push([value(cols[0])?, value(cols[1])?, value(cols[2])?]);
    }
    Ok(Run { stats, radiosity })
}

/// The fields of one CSV line (fields in double quotes may hold commas and doubled quotes).
fn split_csv(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    fields.push(field);
    fields
}

/// Luminance of an RGB radiosity (Radiance's weights, as `radiosity solve` reads lux).
fn luminance(v: [f64; 3]) -> f64 {
    0.265 * v[0] + 0.670 * v[1] + 0.065 * v[2]
}

/// What a scene's errors are measured over: each polygon's area, material and whether it emits.
struct Layout {
    area: Vec<f64>,
    material: Vec<u32>,
    emits: Vec<bool>,
    material_names: Vec<String>,
}

impl Layout {
    fn of(scene: &radiosity::scene::Scene) -> Layout {
        Layout {
            area: scene.polygons.iter().map(|p| p.poly.area()).collect(),
            material: scene.polygons.iter().map(|p| p.material).collect(),
            emits: scene.polygons.iter().map(|p| scene.materials[p.material as usize].emission.iter().any(|&e| e > 0.0)).collect(),
            material_names: scene.materials.iter().map(|m| m.name.clone()).collect(),
        }
    }

    /// The worst non-emitting polygon's error (any channel) relative to the largest non-emitting
    /// polygon mean of the reference, as the estimate states it ([`radiosity::validation::true_error`]).
    fn polygon_error(&self, run: &[[f64; 3]], reference: &[[f64; 3]]) -> f64 {
        let lit: Vec<Option<[f64; 3]>> = reference.iter().zip(&self.emits).map(|(r, &e)| (!e).then_some(*r)).collect();
        radiosity::validation::true_error(&lit, run)
    }

    /// Area-weighted luminance mean of each non-emitting material: `(mean, area)` by material.
    fn material_means(&self, radiosity: &[[f64; 3]]) -> Vec<(f64, f64)> {
        let mut sums = vec![(0.0, 0.0); self.material_names.len()];
        for p in (0..radiosity.len()).filter(|&p| !self.emits[p]) {
            let s = &mut sums[self.material[p] as usize];
            s.0 += self.area[p] * luminance(radiosity[p]);
            s.1 += self.area[p];
        }
        sums.into_iter().map(|(sum, area)| (if area > 0.0 { sum / area } else { 0.0 }, area)).collect()
    }

    /// The worst material's luminance-weighted mean error relative to its own reference mean (over
    /// materials whose mean is not black) and relative to the brightest material's, with the name
    /// of the first.
    fn material_errors(&self, run: &[[f64; 3]], reference: &[[f64; 3]]) -> (f64, String, f64) {
        let (r, m) = (self.material_means(reference), self.material_means(run));
        let top = r.iter().map(|x| x.0).fold(0.0, f64::max);
        let mut worst = (0.0, String::new(), 0.0);
        for (i, ((rm, area), (mm, _))) in r.iter().zip(&m).enumerate() {
            if *area <= 0.0 || *rm <= 0.0 {
                continue;
            }
            let own = (mm - rm).abs() / rm;
            if own > worst.0 {
                worst.0 = own;
                worst.1.clone_from(&self.material_names[i]);
            }
            worst.2 = f64::max(worst.2, (mm - rm).abs() / top);
        }
        worst
    }
}

/// The reference of `scene` kept in `dir` at `target` and `seed`, solving it when it is not there.
fn reference(exe: &Path, scene: &str, args: &RenderParkBenchArgs, dir: &Path) -> anyhow::Result<Option<Run>> {
    if dir.join("patches.csv").exists() && dir.join("stats.json").exists() {
        let run = read_run(dir)?;
        let p = &run.stats["params"];
        if p["target_error"].as_f64() == Some(args.reference_target) && p["seed"].as_u64() == Some(args.reference_seed) {
            return Ok(Some(run));
        }
    }
    solve(exe, scene, args.reference_target, args.reference_seed, args.timeout, dir)
}

/// A file-system-safe name for a scene.
fn slug(scene: &str) -> String {
    let name = Path::new(scene).file_name().and_then(|n| n.to_str()).unwrap_or(scene);
    name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '.' || c == '-' { c } else { '_' }).collect()
}

/// Runs `bench renderpark`.
pub fn run(args: &RenderParkBenchArgs) -> anyhow::Result<()> {
    let valid = |t: f64| t.is_finite() && t > 0.0 && t < 1.0;
    anyhow::ensure!(args.targets.iter().all(|&t| valid(t)), "--targets must be numbers in (0, 1)");
    anyhow::ensure!(valid(args.reference_target), "--reference-target must be a number in (0, 1)");
    anyhow::ensure!(args.timeout.is_finite() && args.timeout > 0.0, "--timeout must be a positive number of seconds");
    let mut scenes = args.scenes.clone();
    if scenes.is_empty() {
        scenes = vec!["gen:office".to_string(), "gen:classroom".to_string()];
    }
    if let Some(dir) = &args.dir {
        anyhow::ensure!(dir.is_dir(), "{}: not a folder", dir.display());
        scenes.extend(renderpark_scenes(dir));
    }
    let exe = std::env::current_exe().context("locating this executable")?;
    let mut rows = Vec::new();
    if !args.json {
        println!(
            "{:<15} {:>7} {:>8} {:>8} {:>9} {:>10} {:>11} {:>8} {:>22}  largest%",
            "scene", "target", "time_s", "peak_MB", "links", "estimate%", "polygon%", "ratio", "worst material% (own)"
        );
    }
    for scene in &scenes {
        let loaded = super::load_scene(Some(&PathBuf::from(scene)), false).with_context(|| format!("{scene}: cannot load"))?;
        let layout = Layout::of(&loaded);
        let name = slug(scene);
        let dir = args.out.join(&name);
        let Some(reference) = reference(&exe, scene, args, &dir.join("reference"))? else {
            println!("{name:<15} reference at {} not finished in {} s: no errors measured", args.reference_target, args.timeout);
            continue;
        };
        anyhow::ensure!(
            reference.radiosity.len() == layout.area.len(),
            "{scene}: the reference has {} polygons, the scene {}",
            reference.radiosity.len(),
            layout.area.len()
        );
        let mut row_of = |target: f64, run: Option<&Run>| {
            let row = match run {
                None => serde_json::json!({"scene": name, "target": target, "finished": false, "timeout_s": args.timeout}),
                Some(run) => {
                    let polygon = layout.polygon_error(&run.radiosity, &reference.radiosity);
                    let (material, material_name, material_top) = layout.material_errors(&run.radiosity, &reference.radiosity);
                    serde_json::json!({
                        "scene": name, "target": target, "finished": true,
                        "time_s": run.stats["time_s"]["total"], "peak_rss_bytes": run.stats["peak_rss_bytes"],
                        "links": run.stats["links"], "error_estimate": run.stats["error_estimate"],
                        "polygon_error": polygon, "worst_material_error": material, "worst_material": material_name,
                        "worst_material_error_of_largest": material_top,
                    })
                }
            };
            if !args.json {
                print_row(&row);
            }
            rows.push(row);
        };
        for &target in &args.targets {
            let run = solve(&exe, scene, target, 1, args.timeout, &dir.join(format!("target-{target}")))?;
            row_of(target, run.as_ref());
        }
        // The reference against itself shows nothing; its own estimate is what it claims.
        if !args.json {
            let s = &reference.stats;
            println!(
                "{name:<15} {:>7} {:>8.1} {:>8.0} {:>9} {:>10.3}   (reference, seed {}){}",
                args.reference_target,
                s["time_s"]["total"].as_f64().unwrap_or(f64::NAN),
                s["peak_rss_bytes"].as_f64().unwrap_or(f64::NAN) / 1e6,
                s["links"].as_u64().unwrap_or(0),
                100.0 * s["error_estimate"].as_f64().unwrap_or(f64::NAN),
                args.reference_seed,
                super::bench::renderpark_reference(&name).map_or(String::new(), |(t, m)| format!("; RenderPark's default: {t} s, {m} MB"))
            );
        }
    }
    write_csv(&args.out.join("renderpark.csv"), &rows)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        println!("wrote {}", args.out.join("renderpark.csv").display());
    }
    Ok(())
}

fn print_row(row: &serde_json::Value) {
    let f = |k: &str| row[k].as_f64().unwrap_or(f64::NAN);
    let name = row["scene"].as_str().unwrap_or("");
    if row["finished"] != true {
        println!("{name:<15} {:>7} {:>8}", f("target"), format!("over {} s", f("timeout_s")));
        return;
    }
    println!(
        "{name:<15} {:>7} {:>8.2} {:>8.0} {:>9} {:>10.3} {:>11.3} {:>8.2} {:>13.3} {:>8}  {:.3}",
        f("target"),
        f("time_s"),
        f("peak_rss_bytes") / 1e6,
        row["links"].as_u64().unwrap_or(0),
        100.0 * f("error_estimate"),
        100.0 * f("polygon_error"),
        f("error_estimate") / f("polygon_error"),
        100.0 * f("worst_material_error"),
        row["worst_material"].as_str().unwrap_or(""),
        100.0 * f("worst_material_error_of_largest"),
    );
}

fn write_csv(path: &Path, rows: &[serde_json::Value]) -> anyhow::Result<()> {
    const COLUMNS: [&str; 11] = [
        "scene",
        "target",
        "finished",
        "time_s",
        "peak_rss_bytes",
        "links",
        "error_estimate",
        "polygon_error",
        "worst_material_error",
        "worst_material",
        "worst_material_error_of_largest",
    ];
    let mut text = COLUMNS.join(",") + "\n";
    for row in rows {
        let cells: Vec<String> = COLUMNS
            .iter()
            .map(|c| match &row[*c] {
                serde_json::Value::Null => String::new(),
                serde_json::Value::String(s) => s.clone(),
                v => v.to_string(),
            })
            .collect();
        text += &(cells.join(",") + "\n");
    }
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).with_context(|| format!("{}: cannot create", parent.display()))?;
    }
    radiosity::output::atomic::write_bytes(path, text)?;
    Ok(())
}
