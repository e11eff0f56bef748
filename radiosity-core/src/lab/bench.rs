//! The three releases of the BF oracle side by side (hand-written, DAG runtime, `oracle!`), on the
//! same scenes in one process: refinement time of each and whether they agree bit for bit.

use crate::oracle::bf::{BfFlat, BfFlatParams, bf_dag};
use crate::pipeline::{self, Config, Solved};
use crate::refine::{BfHand, BfParams, Oracle};
use crate::scene::Scene;

/// Settings of [`run`].
#[derive(Clone, Copy, Debug)]
pub struct BenchConfig {
    /// The BF threshold given to all three releases.
    pub eps: f64,
    /// Solves per release and scene; the fastest refinement time is kept.
    pub repeats: usize,
    /// The solve settings.
    pub pipeline: Config,
}

impl Default for BenchConfig {
    fn default() -> Self {
        BenchConfig { eps: BfParams::default().eps, repeats: 3, pipeline: Config::default() }
    }
}

/// One scene's results.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BenchRow {
    /// Scene name.
    pub scene: String,
    /// Links of the hand-written release's solution.
    pub links: u64,
    /// Refinement time of the hand-written release, seconds (fastest of the repeats).
    pub hand_s: f64,
    /// Refinement time of the DAG runtime release, seconds.
    pub dag_s: f64,
    /// Refinement time of the `oracle!` release, seconds.
    pub flat_s: f64,
    /// Whether the three produced the same links and bit-identical radiosity.
    pub identical: bool,
}

impl BenchRow {
    /// DAG time over hand-written time.
    #[must_use]
    pub fn dag_ratio(&self) -> f64 {
        self.dag_s / self.hand_s
    }

    /// `oracle!` time over hand-written time.
    #[must_use]
    pub fn flat_ratio(&self) -> f64 {
        self.flat_s / self.hand_s
    }
}

/// Whether two solves made the same links and the same radiosity, bit for bit.
#[must_use]
pub fn same_solution(a: &Solved, b: &Solved) -> bool {
    let bits = |s: &Solved| -> Vec<u64> { s.solution.radiosity.iter().flat_map(|c| c.iter().map(|x| x.to_bits())).collect() };
    let links = |s: &Solved| -> Vec<(u32, u32, u64, u64)> {
        s.links.iter().map(|l| (l.source, l.receiver, l.ff.to_bits(), l.vis.to_bits())).collect()
    };
    a.links.len() == b.links.len() && links(a) == links(b) && bits(a) == bits(b)
}

/// Runs the three BF releases on each scene (interleaved, `repeats` times each) and reports the
/// fastest refinement time of each and whether they agree.
#[must_use]
pub fn run(scenes: &[Scene], config: &BenchConfig) -> Vec<BenchRow> {
    let hand = BfHand { params: BfParams { eps: config.eps } };
    let flat = BfFlat::new(BfFlatParams { eps: config.eps, ..BfFlatParams::default() });
    let dag = bf_dag(config.eps).expect("the built-in BF graph is valid");
    let oracles: [&dyn Oracle; 3] = [&hand, &dag, &flat];
    scenes
        .iter()
        .map(|scene| {
            let mut best = [f64::INFINITY; 3];
            let mut results: [Option<Solved>; 3] = [None, None, None];
            for _ in 0..config.repeats.max(1) {
                for (k, oracle) in oracles.iter().enumerate() {
                    let solved = pipeline::run(scene, *oracle, &config.pipeline, &|_| {});
                    best[k] = best[k].min(solved.timings.refine);
                    results[k] = Some(solved);
                }
            }
            let [Some(h), Some(d), Some(f)] = results else { unreachable!("each release ran at least once") };
            BenchRow {
                scene: scene.name.clone(),
                links: h.links.len() as u64,
                hand_s: best[0],
                dag_s: best[1],
                flat_s: best[2],
                identical: same_solution(&h, &d) && same_solution(&h, &f),
            }
        })
        .collect()
}

/// The rows as a table: scene, links, times, and ratios to the hand-written release.
#[must_use]
pub fn format_table(rows: &[BenchRow]) -> String {
    let mut out = format!(
        "{:<20} {:>8} {:>10} {:>10} {:>8} {:>10} {:>8} {:>9}\n",
        "scene", "links", "hand (s)", "dag (s)", "dag/hand", "flat (s)", "flat/hand", "identical"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<20} {:>8} {:>10.4} {:>10.4} {:>8.3} {:>10.4} {:>8.3} {:>9}\n",
            r.scene,
            r.links,
            r.hand_s,
            r.dag_s,
            r.dag_ratio(),
            r.flat_s,
            r.flat_ratio(),
            r.identical
        ));
    }
    out
}
