//! Checks tree solutions against ray-traced direct light (a lower bound on radiosity).
//!
//! `cargo run --release --example direct_bound -- AGE SAMPLES FILE...`: for every 7th flattened
//! polygon of the generated tree of age AGE (seed 1), [`radiosity::solve::direct_lower_bound`]
//! with SAMPLES point pairs per (polygon, lamp); each FILE holds per-polygon means written by
//! `radiosity bench instancing --age AGE --child METHOD FILE` (METHOD `full` or `instanced`). Prints
//! how many checked polygons fall below the bound by more than 1% of the file's largest radiosity,
//! the worst and the mean shortfall; with `REF=FILE` in the environment, also each file's error
//! against that reference (as the bench reports it).
use radiosity::instancing::{self, FlattenOptions, bench::load_means, solver};
use radiosity::visibility::RayCaster;
use std::path::Path;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    anyhow::ensure!(args.len() >= 4, "usage: direct_bound AGE SAMPLES FILE...");
    let age: u32 = args[1].parse()?;
    let samples: u32 = args[2].parse()?;
    let scene = instancing::generate_tree(age, 1);
    let flat = instancing::flatten(&scene, &FlattenOptions { two_sided_pairs: true })?;
    let caster = RayCaster::new(&flat);
    let twin = radiosity::hierarchy::twins(&flat);
    let checked: Vec<u32> = (0..flat.polygons.len() as u32).step_by(7).collect();
    let bound = radiosity::solve::direct_lower_bound(&flat, &caster, &twin, &checked, samples, 7);
    let reference = std::env::var_os("REF").map(|r| load_means(Path::new(&r))).transpose()?;
    for file in &args[3..] {
        let means = load_means(Path::new(file))?;
        let max = means.radiosity.iter().flat_map(|b| b.iter().copied()).fold(0.0, f64::max);
        let (mut below, mut worst, mut sum) = (0usize, 0.0f64, 0.0f64);
        for (&i, g) in checked.iter().zip(&bound) {
            let b = means.radiosity[i as usize];
            let short = (0..3).map(|c| (g[c] - b[c]) / max).fold(f64::MIN, f64::max);
            below += usize::from(short > 0.01);
            worst = worst.max(short);
            sum += short.max(0.0);
        }
        println!(
            "{file}: {} polygons checked; below the direct bound by > 1% of max: {below}; worst shortfall {:.2}%; mean shortfall {:.4}%",
            checked.len(),
            100.0 * worst,
            100.0 * sum / checked.len() as f64
        );
        if let Some(reference) = &reference {
            let (worst, mean) = solver::relative_error(reference, &means);
            let above = solver::polygons_above(reference, &means, 0.03);
            println!("  against REF: error max {:.2}%, mean {:.3}%, {above} polygons above 3%", 100.0 * worst, 100.0 * mean);
            if std::env::var_os("SHOW").is_some() {
                // The largest differences (green channel), with the bound where it was estimated.
                let rmax = reference.radiosity.iter().flat_map(|b| b.iter().copied()).fold(0.0, f64::max);
                let mut order: Vec<usize> = (0..means.radiosity.len()).collect();
                order.sort_by(|&a, &b| {
                    let d = |i: usize| (means.radiosity[i][1] - reference.radiosity[i][1]).abs();
                    d(b).total_cmp(&d(a))
                });
                for &i in &order[..10] {
                    let g = checked.binary_search(&(i as u32)).map_or(f64::NAN, |k| bound[k][1] / rmax);
                    let p = &flat.polygons[i].poly;
                    println!(
                        "    polygon {i} ({}): {:.3} vs {:.3} of max, bound {g:.3}, centre {:.2}, normal {:.2}",
                        flat.material_of(i).name,
                        means.radiosity[i][1] / rmax,
                        reference.radiosity[i][1] / rmax,
                        p.centroid(),
                        p.normal()
                    );
                }
            }
        }
    }
    Ok(())
}
