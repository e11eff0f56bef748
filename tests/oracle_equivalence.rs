//! The three releases of the BF oracle (hand-written, DAG runtime, `oracle!`) must make the same
//! decisions: identical links and bit-identical radiosity on every benchmark scene.

use radiosity::lab::bench::{self, BenchConfig, same_solution};
use radiosity::oracle::bf::{BfFlat, BfFlatParams, bf_dag};
use radiosity::oracle::scenes;
use radiosity::pipeline::{self, Config};
use radiosity::refine::{BfHand, BfParams, Oracle};
use radiosity::scene::Scene;

/// Smallest element area relative to the scene's: coarser than the default, to keep the test short
/// while every scene still refines to thousands of links.
const TEST_MIN_AREA_REL: f64 = 1e-4;

fn check(scene: &Scene, eps: f64, min_area_rel: f64) {
    let hand = BfHand { params: BfParams { eps } };
    let flat = BfFlat::new(BfFlatParams { eps, ..BfFlatParams::default() });
    let dag = bf_dag(eps).expect("valid BF graph");
    let mut config = Config::default();
    config.build.min_area_rel = min_area_rel;
    let run = |o: &dyn Oracle| pipeline::run(scene, o, &config, &|_| {});
    let (h, d, f) = (run(&hand), run(&dag), run(&flat));
    assert!(h.links.len() > 200, "{}: too few links ({}) for a meaningful comparison", scene.name, h.links.len());
    assert_eq!(h.links.len(), d.links.len(), "{}: DAG link count", scene.name);
    assert_eq!(h.links.len(), f.links.len(), "{}: flat link count", scene.name);
    assert_eq!(h.refine_stats.oracle_calls, f.refine_stats.oracle_calls, "{}: flat oracle calls", scene.name);
    assert!(same_solution(&h, &d), "{}: DAG links or radiosity differ from hand-written", scene.name);
    assert!(same_solution(&h, &f), "{}: flat links or radiosity differ from hand-written", scene.name);
}

#[test]
fn three_releases_agree_on_the_cornell_box() {
    // The default smallest element (the box has few polygons, so refinement goes deep).
    let min_area_rel = Config::default().build.min_area_rel;
    check(&radiosity::scene::cornell_box(), 0.002, min_area_rel);
    check(&radiosity::scene::cornell_box(), 0.01, min_area_rel);
}

#[test]
fn three_releases_agree_on_every_bench_scene() {
    let mut config = BenchConfig { repeats: 1, ..BenchConfig::default() };
    config.pipeline.build.min_area_rel = TEST_MIN_AREA_REL;
    let rows = bench::run(&scenes::bench_scenes(), &config);
    println!("{}", bench::format_table(&rows));
    assert_eq!(rows.len(), 5);
    for r in &rows {
        assert!(r.links > 500, "{}: too few links ({}) for a meaningful comparison", r.scene, r.links);
        assert!(r.identical, "{}: the three releases disagree", r.scene);
        assert!(r.hand_s > 0.0 && r.dag_s > 0.0 && r.flat_s > 0.0, "{r:?}");
    }
}
