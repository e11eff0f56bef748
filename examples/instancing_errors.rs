//! Where an instanced solve of a generated tree differs from the full solve (development aid).
//!
//! `cargo run --release --example instancing_errors -- AGE REF FILE...`: REF and each FILE hold
//! per-polygon means written by `radiosity bench instancing --age AGE --child METHOD FILE`. For each
//! FILE: the error as the bench reports it (largest and area-weighted mean, % of REF's largest
//! radiosity), then per kind of innermost prototype (scene, trunk, branch, twig) and material the
//! polygons' share of the summed error, their signed mean error (green), and the ten worst
//! polygons with the chain of prototypes holding them.
use radiosity::instancing::{self, InstancedScene, PrototypeId, bench::load_means, solver};
use std::collections::BTreeMap;
use std::path::Path;

/// Per flattened polygon (two-sided as pairs): material and the chain of prototypes holding it.
fn owners(scene: &InstancedScene) -> Vec<(u32, Vec<PrototypeId>)> {
    let counts = scene.flattened_counts(true);
    let mut out = vec![(0u32, Vec::new()); counts[scene.root as usize] as usize];
    let mut stack = vec![(scene.root, 0u64, vec![scene.root])];
    while let Some((id, base, chain)) = stack.pop() {
        let p = scene.prototype(id);
        let mut k = base;
        for q in &p.polygons {
            let n = if scene.materials[q.material as usize].two_sided { 2 } else { 1 };
            for j in 0..n {
                out[(k + j) as usize] = (q.material, chain.clone());
            }
            k += n;
        }
        for inst in &p.instances {
            let mut c = chain.clone();
            c.push(inst.prototype);
            stack.push((inst.prototype, k, c));
            k += counts[inst.prototype as usize];
        }
    }
    out
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    anyhow::ensure!(args.len() >= 4, "usage: instancing_errors AGE REF FILE...");
    let scene = instancing::generate_tree(args[1].parse()?, 1);
    let reference = load_means(Path::new(&args[2]))?;
    let own = owners(&scene);
    anyhow::ensure!(own.len() == reference.radiosity.len(), "REF is not of this tree");
    let max = reference.radiosity.iter().flat_map(|b| b.iter().copied()).fold(0.0, f64::max);
    let kind = |id: PrototypeId| scene.prototype(id).name.split('_').next().unwrap_or("?").to_string();
    for file in &args[3..] {
        let means = load_means(Path::new(file))?;
        let (worst, mean) = solver::relative_error(&reference, &means);
        println!("{file}: max {:.2}%, mean {:.4}%", 100.0 * worst, 100.0 * mean);
        // group -> (polygons, area, area·|err|, area·signed green err)
        let mut groups: BTreeMap<String, (usize, f64, f64, f64)> = BTreeMap::new();
        let mut total = 0.0;
        let mut errs: Vec<(f64, usize)> = Vec::with_capacity(own.len());
        for (i, (m, chain)) in own.iter().enumerate() {
            let (r, a, area) = (reference.radiosity[i], means.radiosity[i], reference.area[i]);
            let e = (0..3).map(|c| (a[c] - r[c]).abs()).fold(0.0, f64::max) / max;
            let key = format!("{} / {}", kind(*chain.last().unwrap_or(&scene.root)), scene.materials[*m as usize].name);
            let g = groups.entry(key).or_default();
            g.0 += 1;
            g.1 += area;
            g.2 += area * e;
            g.3 += area * (a[1] - r[1]) / max;
            total += area * e;
            errs.push((e, i));
        }
        let area_all: f64 = reference.area.iter().sum();
        println!("  {:<22} {:>8} {:>9} {:>10} {:>12} {:>12}", "group", "polygons", "area%", "err share", "mean |err|%", "signed G %");
        for (k, (n, area, abs, signed)) in &groups {
            println!(
                "  {k:<22} {n:>8} {:>9.2} {:>9.1}% {:>12.4} {:>12.4}",
                100.0 * area / area_all,
                100.0 * abs / total.max(f64::MIN_POSITIVE),
                100.0 * abs / area.max(f64::MIN_POSITIVE),
                100.0 * signed / area.max(f64::MIN_POSITIVE)
            );
        }
        errs.sort_by(|a, b| b.0.total_cmp(&a.0));
        for &(e, i) in errs.iter().take(10) {
            let chain: Vec<String> = own[i].1.iter().map(|&c| scene.prototype(c).name.clone()).collect();
            println!(
                "    polygon {i}: err {:.2}%, {:.3} vs {:.3} of max (G), {}",
                100.0 * e,
                means.radiosity[i][1] / max,
                reference.radiosity[i][1] / max,
                chain.join(">")
            );
        }
        let above: usize = errs.iter().filter(|e| e.0 > 0.01).count();
        println!("  polygons above 1%: {above}, above 2%: {}", errs.iter().filter(|e| e.0 > 0.02).count());
    }
    Ok(())
}
