//! `radiosity oracle study`: the visibility study (`radiosity::lab::study`) on one scene. For
//! the links of a BF solve whose projected areas lie below each threshold, how often 4, 16 and 64
//! rays put a link in another visibility class than the reference classifier does: the figures a
//! `ProjectedAreaBelow` node in front of `RayVisibility` trades against.

use super::{SolveOptions, load_scene};
use radiosity::lab::study::{STUDY_RAYS, StudyRow, visibility_study};
use radiosity::oracle::tools::REFERENCE_RAYS;
use radiosity::pipeline;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `radiosity oracle study`.
#[derive(clap::Args, Debug)]
pub struct StudyArgs {
    /// Scene (the Cornell box when omitted; generated scene names as for `solve`).
    pub scene: Option<PathBuf>,
    /// Projected-area thresholds as fractions of the scene's total area (like `--min-area`),
    /// comma-separated; a link counts below a threshold when the larger of its two areas projected
    /// along the link is. At 1 every link counts.
    #[arg(long, value_delimiter = ',', default_value = "1,0.1,0.01,0.001,0.0001")]
    pub thresholds: Vec<f64>,
    #[command(flatten)]
    pub options: SolveOptions,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `radiosity oracle study`.
pub fn run(args: &StudyArgs) -> anyhow::Result<()> {
    args.options.validate()?;
    anyhow::ensure!(!args.thresholds.is_empty(), "--thresholds needs at least one threshold");
    for &t in &args.thresholds {
        anyhow::ensure!(t.is_finite() && t > 0.0, "--thresholds must be positive numbers, got {t}");
    }
    // Largest first: the links below a threshold can only fall as it does.
    let mut thresholds_rel = args.thresholds.clone();
    thresholds_rel.sort_by(|a, b| b.total_cmp(a));
    thresholds_rel.dedup();
    let scene = load_scene(args.scene.as_ref(), args.options.common.allow_dark)?;
    let name = args.scene.as_ref().map_or_else(|| scene.name.clone(), |p| p.display().to_string());
    if !radiosity::analysis::SceneTraits::of(&scene).needs_visibility {
        if args.json {
            let doc = serde_json::json!({ "scene": name, "needs_visibility": false, "rows": [] });
            println!("{}", serde_json::to_string_pretty(&doc)?);
        } else {
            println!(
                "{name} is a convex enclosure: no polygon can occlude another, so every link is fully visible and there is no visibility to study"
            );
        }
        return Ok(());
    }
    let t0 = Instant::now();
    let oracle = radiosity::oracle::registry::oracle("bf", &[("eps".to_string(), args.options.eps())])?;
    let mut config = args.options.config();
    config.estimate_error = false;
    // The study classifies the links of one solve at the given eps.
    config.target_error = None;
    let solved = pipeline::run(&scene, oracle.as_ref(), &config, &|_| {});
    let solve_s = t0.elapsed().as_secs_f64();
    let total_area = scene.total_area();
    let thresholds: Vec<f64> = thresholds_rel.iter().map(|t| t * total_area).collect();
    let t1 = Instant::now();
    let rows = visibility_study(&solved, config.visibility, &thresholds);
    let study_s = t1.elapsed().as_secs_f64();
    if args.json {
        let doc = serde_json::json!({
            "scene": name,
            "needs_visibility": true,
            "eps": args.options.eps(),
            "seed": args.options.common.seed,
            "links": solved.links.len(),
            "total_area": total_area,
            "rays": STUDY_RAYS,
            "reference_rays": REFERENCE_RAYS,
            "rows": rows.iter().zip(&thresholds_rel).map(|(r, &rel)| serde_json::json!({
                "threshold_rel": rel,
                "threshold": r.threshold,
                "links": r.links,
                "error_rate": r.error_rate,
            })).collect::<Vec<_>>(),
            "time_s": { "solve": solve_s, "study": study_s },
        });
        println!("{}", serde_json::to_string_pretty(&doc)?);
    } else {
        print_table(&name, args, solved.links.len(), &rows, &thresholds_rel, (solve_s, study_s));
    }
    Ok(())
}

fn print_table(name: &str, args: &StudyArgs, n_links: usize, rows: &[StudyRow], thresholds_rel: &[f64], (solve_s, study_s): (f64, f64)) {
    println!(
        "{name}: {n_links} links of a BF solve (eps {}, seed {}); each link classified as visible, invisible or partly \
         visible by {} rays (reference) and by {}, {} and {} rays",
        args.options.eps(),
        args.options.common.seed,
        REFERENCE_RAYS,
        STUDY_RAYS[0],
        STUDY_RAYS[1],
        STUDY_RAYS[2]
    );
    println!();
    println!(
        "| projected area below (of total) | links below | error {} rays | error {} rays | error {} rays |",
        STUDY_RAYS[0], STUDY_RAYS[1], STUDY_RAYS[2]
    );
    println!("|---|---:|---:|---:|---:|");
    for (r, rel) in rows.iter().zip(thresholds_rel) {
        let rate = |k: usize| {
            let wrong = (r.error_rate[k] * r.links as f64).round();
            if r.links == 0 { "–".to_string() } else { format!("{} ({wrong})", percent(r.error_rate[k])) }
        };
        println!("| {} | {} | {} | {} | {} |", radiosity::oracle::graph::format_number(*rel), r.links, rate(0), rate(1), rate(2));
    }
    println!();
    println!(
        "(error: share of the links below the threshold that the rays put in another class than the reference does, and \
         their number; solve {solve_s:.2}s, study {study_s:.2}s)"
    );
}

/// A share as a percentage with two decimals, or two significant digits when smaller (a share of
/// 1 link in 42,424 is `0.0024%`, not `0.00%`).
fn percent(share: f64) -> String {
    let p = 100.0 * share;
    let decimals = if p > 0.0 && p < 0.1 { (1.0 - p.log10().floor()) as usize } else { 2 };
    format!("{p:.decimals$}%")
}

#[cfg(test)]
mod tests {
    use super::percent;

    #[test]
    fn small_shares_keep_two_significant_digits() {
        assert_eq!(percent(0.1325102880658436), "13.25%");
        assert_eq!(percent(0.0), "0.00%");
        assert_eq!(percent(16.0 / 47291.0), "0.034%");
        assert_eq!(percent(1.0 / 42424.0), "0.0024%");
        assert_eq!(percent(1.0), "100.00%");
    }
}
