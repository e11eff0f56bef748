//! The console summary of a plain solve, from its `stats.json` figures.

use radiosity::output::Stats;

pub(super) fn print_summary(s: &Stats, out: &std::path::Path, pictures: &str) {
    if let Some(w) = s.warnings.summary() {
        eprintln!("warning: {w}");
    }
    let balance = if s.power_emitted > 0.0 { s.power_absorbed / s.power_emitted } else { f64::NAN };
    println!(
        "{}: {} polygons, {} elements ({} leaves), {} links, {} rays, {} iterations (residual {:.1e})",
        s.scene, s.polygons, s.elements, s.leaves, s.links, s.rays, s.iterations, s.residual
    );
    println!(
        "time: load {:.3}s build {:.3}s refine {:.3}s solve {:.3}s estimate {:.3}s output {:.3}s total {:.3}s; peak RSS {}",
        s.time_s.load,
        s.time_s.build,
        s.time_s.refine,
        s.time_s.solve,
        s.time_s.estimate,
        s.time_s.output,
        s.time_s.total,
        s.peak_rss_bytes.map_or("n/a".to_string(), |b| format!("{:.1} MB", b as f64 / 1e6))
    );
    if s.left_out.is_empty() {
        println!("left out: nothing (the scene needs every part of the solver)");
    } else {
        println!("left out: {}", s.left_out.join("; "));
    }
    if s.levels.len() > 1 {
        let steps: Vec<String> = s
            .levels
            .iter()
            .map(|l| {
                let mut points = l.points_error.map_or(String::new(), |p| format!(" points {:.2}%", 100.0 * p));
                if let Some(n) = l.polygons_refined {
                    points = format!(" ({n} polygons refined){points}");
                }
                match l.error_estimate {
                    Some(e) => format!("{} links {:.3}s est {:.2}%{points}", l.links, l.time_s, 100.0 * e),
                    None => format!("{} links {:.3}s{points}", l.links, l.time_s),
                }
            })
            .collect();
        println!("levels: {}", steps.join(" -> "));
    }
    if let Some(e) = s.error_estimate {
        let target = s.target_error.map_or(String::new(), |t| format!(" (target {:.2}%)", 100.0 * t));
        println!(
            "error estimate: {:.2}%{target} of the largest non-emitting polygon mean, largest error of a polygon mean (same links on meshes 2x and 4x coarser, extrapolated)",
            100.0 * e
        );
    }
    let closed = if s.closed { "closed scene: each surface's light delivered whole" } else { "open scene" };
    let unit = s.units.power_label();
    match (s.power_incident, s.power_escaped) {
        (Some(incident), Some(escaped)) => {
            let lost = s.power_lost_at_backs.unwrap_or(0.0);
            let (lost_text, lost_sum) = if lost > 0.0 {
                (format!(", lost at the backs of one-sided faces {lost:.6e} {unit}"), " + lost")
            } else {
                (String::new(), "")
            };
            println!(
                "power: incident {incident:.6e} {unit} (sun and sky), emitted {:.6e} {unit}, absorbed {:.6e} {unit}, escaped {escaped:.6e} {unit}{lost_text} (balance {:.5}: absorbed + escaped{lost_sum} over incident + emitted)",
                s.power_emitted,
                s.power_absorbed,
                s.power_balance.unwrap_or(f64::NAN)
            );
            if !s.bands.is_empty() {
                for (name, p) in s.power_by_band.iter().flatten() {
                    println!("  band {name}: incident {:.6e}, absorbed {:.6e}, escaped {:.6e} {unit}", p.incident, p.absorbed, p.escaped);
                }
            }
        }
        _ => println!(
            "power: emitted {:.6e} {unit}, absorbed {:.6e} {unit} (balance {:.5}; {closed})",
            s.power_emitted, s.power_absorbed, balance
        ),
    }
    if let Some(sun) = &s.sun {
        let az = sun.azimuth_deg.map_or(String::new(), |a| format!(", azimuth {a:.2} deg from north"));
        let state = if sun.above_horizon { "" } else { " (below the horizon: no sun light)" };
        println!("sun: zenith {:.2} deg{az}{state}", sun.zenith_deg);
    }
    for l in &s.luminaires {
        let declared = l.declared_lm.map_or(String::new(), |d| format!(" (file declares {d:.1} lm)"));
        println!("luminaire {}: {:.1} lm{declared}", l.name, l.flux_lm);
    }
    for source in &s.sources {
        let onto = source.onto_surfaces.iter().sum::<f64>() / 3.0;
        println!("source {}: {onto:.6e} {unit} onto the surfaces directly, {:.2}% of all sources'", source.name, 100.0 * source.share);
    }
    for w in &s.solve_warnings {
        eprintln!("warning: {w}");
    }
    if let Some(r) = &s.importance {
        println!(
            "importance: {} round(s) for the points and grids (the last levels above), {} leaves split, worst estimated error of a \
             point {:.2}% -> {:.2}% of its value{}",
            r.rounds,
            r.leaves_split,
            100.0 * r.worst_before,
            100.0 * r.worst_after,
            if r.met { "" } else { " (above the target)" }
        );
    }
    if let (Some(n), Some(seconds)) = (s.points, s.time_s.points) {
        let when = if s.importance.is_some() { " (read by the last importance round)".to_owned() } else { format!(" in {seconds:.3}s") };
        println!("points: irradiance at {n} calculation points{when} ({} rays)", s.point_rays.unwrap_or(0));
    }
    let units = s.units;
    let (column, unit) = (radiosity::points::grid::photopic_column(units), radiosity::points::grid::photopic_unit(units));
    let mut grid_files = String::new();
    for (name, g) in s.grids.iter().flatten() {
        let err = g.e_err_max.map_or_else(String::new, |e| format!(", estimated error at most {e:.2e} {unit}"));
        println!(
            "grid {name}: {} points, {column} avg {:.4e} {unit}, min {:.4e}, max {:.4e}, U0 {:.3}, min/max {:.3}{err}",
            g.points, g.e_avg, g.e_min, g.e_max, g.u0, g.min_over_max
        );
        grid_files.push_str(&format!(",grid_{name}.csv,grid_{name}.svg"));
        if let Some(df) = &g.daylight_factor {
            let err = df.err_max.map_or_else(String::new, |e| format!(", estimated error at most {e:.3}%"));
            println!(
                "grid {name}: daylight factor mean {:.3}%, reached by half the points {:.3}%, by 95% {:.3}%, min {:.3}%, max {:.3}% (of {:.4e} {unit} outside){err}",
                df.mean, df.median, df.over_95, df.min, df.max, df.outside
            );
            grid_files.push_str(&format!(",grid_{name}_df.svg"));
        }
    }
    let points = if s.points.is_some() { ",points.csv" } else { "" };
    println!("wrote {}/{{{pictures}solution.ply,solution.glb,patches.csv,groups.csv,stats.json{points}{grid_files}}}", out.display());
}
