//! Instanced scenes (a `.toml` scene file, or `--instances auto`): the options that do not apply,
//! the solve streamed to the outputs with its progress, and its `stats.json`.

use super::SolveArgs;
use crate::cli::progress::Reporter;
use anyhow::Context;
use radiosity::output;
use std::time::Instant;

/// Refuses the options of plain solves for a solve by the instanced solver (an instanced scene file
/// or `--instances auto`).
pub(super) fn refuse_plain_only(args: &SolveArgs) -> anyhow::Result<()> {
    anyhow::ensure!(args.time_for == 0.0, "--time-for applies to plain scenes, not to instanced ones");
    anyhow::ensure!(args.points.is_none(), "--points applies to plain scenes, not to instanced ones (nor to --instances auto)");
    anyhow::ensure!(args.picture.view.is_none(), "--view applies to plain scenes, not to instanced ones (nor to --instances auto)");
    Ok(())
}

/// An instanced scene (a `.toml` file, or a plain scene after `--instances auto`, whose `auto`
/// report goes to `stats.json`): solved depth-first, one instance open at a time, finished polygons
/// streamed to `patches.csv` and a spool from which `solution.ply`, `solution.glb` and `image.png` are written at
/// the end (see `radiosity::instancing::output`); `stats.json` holds the instanced solver's figures.
/// `bands`: the scene file's bands (at most three, [`Lighting::needs_plain_solve`] sends more to
/// the plain solve), sun and sky.
///
/// [`Lighting::needs_plain_solve`]: radiosity::instancing::Lighting::needs_plain_solve
pub(super) fn solve_instanced(
    args: &SolveArgs,
    scene: &radiosity::instancing::InstancedScene,
    auto: Option<&radiosity::instancing::AutoReport>,
    bands: &radiosity::instancing::bands::Bands,
) -> anyhow::Result<()> {
    use radiosity::instancing::{InstancedConfig, StreamedOutput};
    let t0 = Instant::now();
    let name = args.scene.as_ref().map_or_else(|| scene.name.clone(), |p| p.display().to_string());
    let trace = std::env::var_os("RADIOSITY_TRACE").is_some();
    let mut config = InstancedConfig { cache_dir: Some(args.out.join("prototype-cache")), trace, ..InstancedConfig::default() };
    config.bf.eps = args.options.eps();
    // Instanced solves refine each local problem to the eps (no estimate of their own).
    config.pipeline = radiosity::pipeline::Config { target_error: None, ..args.options.config() };
    config.level_cache_bytes = (args.level_cache_mb * 1e6) as usize;
    config.instance_levels = args.instance_levels;
    config.direct_samples = args.direct_samples;
    config.daylight = bands.pack_distant(0);
    config.proxy_emission = args.proxy_emission;
    config.level_reuse = args.level_reuse;
    // Over MPI ranks (feature `mpi`), levels are reused within a subtree; ranks other than 0 solve
    // subtrees and write nothing.
    #[cfg(feature = "mpi")]
    if crate::cli::mpi::distributed() {
        config.level_reuse = radiosity::instancing::LevelReuse::Subtree;
        if crate::cli::mpi::rank() != 0 {
            return crate::cli::mpi::work(scene, &config);
        }
    }
    let total = scene.flattened_counts(true).get(scene.root as usize).copied().unwrap_or(0);
    let output = if bands.declared {
        StreamedOutput::with_bands(&args.out, scene, &bands.names)?
    } else {
        StreamedOutput::create(&args.out, scene)?
    };
    // Under the sun and sky, the power balance is measured beside the output.
    let output = radiosity::instancing::balance::DaylightBalance::new(output, scene, &config.daylight);
    let mut sink = Progressing { inner: output, done: 0, total, reporter: Reporter::new(args.quiet) };
    #[cfg(feature = "mpi")]
    let (stats, mpi_report) = crate::cli::mpi::solve(scene, &config, &mut sink)?;
    #[cfg(not(feature = "mpi"))]
    let stats = radiosity::instancing::solve_instanced(scene, &config, &mut sink)?;
    sink.reporter.finish();
    let t_out = Instant::now();
    let (sink, balance) = sink.inner.finish();
    let render = output::RenderConfig { width: args.size, height: args.size, ..Default::default() };
    let written = sink.finish((!args.no_image).then_some(&render))?;
    let mut doc = serde_json::to_value(&stats).context("serialising stats")?;
    doc["scene"] = serde_json::json!(name);
    if let Some(report) = auto {
        doc["auto_instancing"] = serde_json::to_value(report).context("serialising the auto-instancing report")?;
    }
    doc["oracle"] = serde_json::json!("bf-hand");
    doc["eps"] = serde_json::json!(args.options.eps());
    doc["tone_white"] = serde_json::json!(written.white);
    // Absorbed power per band (W), as groups.csv sums it; like the plain solve's `power_absorbed`,
    // the sum over named bands or the mean over r, g, b. Under daylight, the balance's terms
    // (radiosity::instancing::balance) as the plain solve's keys.
    let nb = written.bands.len();
    let combine = |v: &[f64]| -> f64 {
        let total: f64 = v[..nb].iter().sum();
        if bands.declared { total } else { total / 3.0 }
    };
    let absorbed: serde_json::Map<String, serde_json::Value> =
        written.bands.iter().zip(&written.absorbed).map(|(n, a)| (n.clone(), serde_json::json!(a))).collect();
    doc["power_absorbed"] = serde_json::json!(combine(&written.absorbed));
    doc["absorbed_by_band"] = serde_json::Value::Object(absorbed);
    if let Some(b) = &balance {
        let by_band: serde_json::Map<String, serde_json::Value> = written
            .bands
            .iter()
            .enumerate()
            .map(|(c, n)| {
                let band = output::BandPower {
                    emitted: b.emitted[c],
                    incident: b.incident[c],
                    absorbed: b.absorbed[c],
                    escaped: b.escaped[c],
                    lost_at_backs: b.lost_at_backs[c],
                };
                (n.clone(), serde_json::to_value(band).expect("plain numbers"))
            })
            .collect();
        let total = output::BandPower::sum((0..nb).map(|c| output::BandPower {
            emitted: b.emitted[c],
            incident: b.incident[c],
            absorbed: b.absorbed[c],
            escaped: b.escaped[c],
            lost_at_backs: b.lost_at_backs[c],
        }));
        doc["power_emitted"] = serde_json::json!(combine(&b.emitted));
        doc["power_incident"] = serde_json::json!(combine(&b.incident));
        doc["power_escaped"] = serde_json::json!(combine(&b.escaped));
        doc["power_lost_at_backs"] = serde_json::json!(combine(&b.lost_at_backs));
        doc["power_balance"] = serde_json::json!(total.balance(true));
        if let Some(w) = instanced_lost_warning(scene, b, nb) {
            if !args.quiet {
                eprintln!("warning: {w}");
            }
            doc["solve_warnings"] = serde_json::json!([w]);
        }
        doc["power_by_band"] = serde_json::Value::Object(by_band);
    }
    if bands.declared {
        doc["bands"] = serde_json::json!(bands.names);
    }
    if let Some(sun) = &bands.sun_report {
        doc["sun"] = serde_json::to_value(sun).context("serialising the sun")?;
    }
    doc["time_s"] =
        serde_json::json!({ "solve": stats.seconds, "output": t_out.elapsed().as_secs_f64(), "total": t0.elapsed().as_secs_f64() });
    doc["peak_rss_bytes"] = serde_json::json!(output::peak_rss_bytes());
    if config.level_reuse == radiosity::instancing::LevelReuse::Subtree {
        doc["level_reuse"] = serde_json::json!("subtree");
    }
    #[cfg(feature = "mpi")]
    if let Some(report) = mpi_report {
        doc["mpi"] = report.to_json();
    }
    let stats_path = args.out.join("stats.json");
    output::atomic::write_bytes(&stats_path, serde_json::to_string_pretty(&doc)? + "\n")
        .with_context(|| format!("{}: cannot write", stats_path.display()))?;
    if !args.quiet {
        println!(
            "{} local solves, {} polygons, {} leaves, {} links; {:.1}s; peak RSS {}",
            stats.local_solves,
            stats.polygons_out,
            stats.leaves_out,
            stats.links,
            t0.elapsed().as_secs_f64(),
            output::peak_rss_bytes().map_or("n/a".to_string(), |b| format!("{:.1} MB", b as f64 / 1e6))
        );
        if let Some(b) = &balance {
            for (c, n) in written.bands.iter().enumerate() {
                let lost = if b.lost_at_backs[c] > 0.0 { format!(", lost at backs {:.6e} W", b.lost_at_backs[c]) } else { String::new() };
                println!(
                    "{n}: incident {:.6e} W, absorbed {:.6e} W, escaped {:.6e} W{lost}, balance {}",
                    b.incident[c],
                    b.absorbed[c],
                    b.escaped[c],
                    b.ratio(c).map_or("n/a".to_string(), |r| format!("{r:.4}"))
                );
            }
        }
        let files = if args.no_image {
            "solution.ply,solution.glb,patches.csv,groups.csv,stats.json"
        } else {
            "image.png,solution.ply,solution.glb,patches.csv,groups.csv,stats.json"
        };
        println!("wrote {}/{{{files}}}", args.out.display());
    }
    Ok(())
}

/// The warning for light lost at the backs of one-sided faces in an instanced solve (as the plain
/// solve's `radiosity::output::stats::lost_at_backs_warning`, with the one-sided materials named
/// instead of the faces): above `LOST_AT_BACKS_WARN_REL` of the incident light in some of the
/// `bands` channels.
fn instanced_lost_warning(
    scene: &radiosity::instancing::InstancedScene,
    b: &radiosity::instancing::balance::PowerBalance,
    bands: usize,
) -> Option<String> {
    let share = (0..bands.min(3)).filter(|&c| b.incident[c] > 0.0).map(|c| b.lost_at_backs[c] / b.incident[c]).fold(0.0, f64::max);
    if share <= radiosity::output::LOST_AT_BACKS_WARN_REL {
        return None;
    }
    let one_sided: Vec<String> =
        scene.materials.iter().filter(|m| !m.two_sided && !m.is_emitter()).map(|m| format!("`{}`", m.name)).collect();
    Some(format!(
        "{}: {:.2}% of the incident light lands on the back of one-sided faces and is lost there (one-sided materials: {}): give their material `two_sided = true` for a back that reflects like the front, or leave them one-sided where the backs are really hidden",
        scene.name,
        100.0 * share,
        one_sided.join(", ")
    ))
}

/// Shows the share of flattened polygons finished while passing them on.
struct Progressing<S> {
    inner: S,
    done: u64,
    total: u64,
    reporter: Reporter,
}

impl<S: radiosity::instancing::RadiositySink> radiosity::instancing::RadiositySink for Progressing<S> {
    fn polygon(
        &mut self,
        info: &radiosity::instancing::PolygonInfo,
        leaves: &[radiosity::instancing::Leaf],
    ) -> Result<(), radiosity::instancing::InstancingError> {
        self.done += 1;
        if self.done.is_multiple_of(4096) {
            self.reporter.phase(&format!("instanced solve: {} of {} polygons finished", self.done, self.total));
        }
        self.inner.polygon(info, leaves)
    }
}
