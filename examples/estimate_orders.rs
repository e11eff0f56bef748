//! How far the error estimate's extrapolation is from the truth, on the validation scenes: for each
//! scene and eps, the polygon with the largest true error, its changes `d₁` (fine − one level
//! coarser) and `d₂` (one − two levels coarser), and its true error over `|d₁|`, the factor
//! [`radiosity::solve::CHANGE_FACTOR_MAX`] must stay above; then the largest such factor over the
//! rows the estimate's visibility-noise term does not cover by itself (on CIE 5.8, with its
//! obstruction, visibility sampling's error is larger than the mesh's) and where `d₁` is not 0
//! (every polygon whole: the estimate's term for polygons left whole covers those).
//!
//! `cargo run --release --example estimate_orders`

use radiosity::pipeline::{self, Config};
use radiosity::refine::{BfHand, BfParams};
use radiosity::{output, solve, validation};

fn main() {
    let mut largest = (0.0f64, String::new());
    println!("{:<24} {:>9} {:>8} {:>9} {:>9} {:>9} {:>7}", "scene", "eps", "polygon", "true %", "d1 %", "d2 %", "true/d1");
    for c in validation::cases() {
        for eps in [0.64, 0.16, 0.04, 0.01, 0.0025, 0.000625] {
            let config = Config::default();
            let s = pipeline::run(&c.scene, &BfHand { params: BfParams { eps } }, &config, &|_| {});
            let h = &s.hierarchy;
            let mut means = vec![output::polygon_results(h, &s.solution).into_iter().map(|r| r.b).collect::<Vec<[f64; 3]>>()];
            for levels in 1..=2 {
                let cut = solve::Cut::coarsened(h, levels);
                let coefficients = solve::LeafCoefficients::for_cut(&cut, &s.links, s.closed, usize::MAX, solve::Precision::Single);
                let op = solve::LeafOperator::for_cut(cut, &s.links, &coefficients);
                let coarse = solve::solve_leaf_operator(&op, &s.solution.radiosity, &config.solve);
                means.push(output::polygon_results(h, &coarse).into_iter().map(|r| r.b).collect());
            }
            let top = c.reference.iter().flatten().flat_map(|r| r.iter().copied()).fold(0.0, f64::max);
            let worst = c
                .reference
                .iter()
                .enumerate()
                .filter_map(|(p, r)| r.map(|r| (p, r)))
                .flat_map(|(p, r)| (0..3).map(move |ch| (p, ch, r[ch])))
                .max_by(|a, b| (means[0][a.0][a.1] - a.2).abs().total_cmp(&(means[0][b.0][b.1] - b.2).abs()));
            let Some((p, ch, r)) = worst else { continue };
            let err = (means[0][p][ch] - r).abs();
            if err <= 1e-5 * top {
                continue;
            }
            let (d1, d2) = (means[0][p][ch] - means[1][p][ch], means[1][p][ch] - means[2][p][ch]);
            let factor = if d1 == 0.0 { f64::INFINITY } else { err / d1.abs() };
            println!(
                "{:<24} {eps:>9} {p:>8} {:>9.3} {:>9.3} {:>9.3} {factor:>7.2}",
                c.name,
                100.0 * err / top,
                100.0 * d1 / top,
                100.0 * d2 / top
            );
            let noise = solve::ESTIMATE_SAFETY * solve::visibility_noise(h, &s.links, &s.solution.radiosity, None);
            if noise * top < err && factor.is_finite() && factor > largest.0 {
                largest = (factor, format!("{} eps {eps}", c.name));
            }
        }
    }
    println!("largest true/|d1| where the noise term does not cover the error: {:.2} ({})", largest.0, largest.1);
}
