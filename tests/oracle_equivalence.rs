//! The three releases of the BF oracle (hand-written, DAG runtime, `oracle!`) must make the same
//! decisions: identical links and bit-identical radiosity on every benchmark scene.

use radiosity::oracle::bench::same_solution;
use radiosity::oracle::bf::{BfFlat, BfFlatParams, bf_dag};
use radiosity::oracle::scenes;
use radiosity::pipeline::{self, Config};
use radiosity::refine::{BfHand, BfParams, Oracle};
use radiosity::scene::Scene;

fn check(scene: &Scene, eps: f64) {
    let hand = BfHand { params: BfParams { eps } };
    let flat = BfFlat::new(BfFlatParams { eps, ..BfFlatParams::default() });
    let dag = bf_dag(eps).expect("valid BF graph");
    let config = Config::default();
    let run = |o: &dyn Oracle| pipeline::run(scene, o, &config, &|_| {});
    let (h, d, f) = (run(&hand), run(&dag), run(&flat));
    assert!(h.links.len() > 10, "{}: too few links ({}) for a meaningful comparison", scene.name, h.links.len());
    assert_eq!(h.links.len(), d.links.len(), "{}: DAG link count", scene.name);
    assert_eq!(h.links.len(), f.links.len(), "{}: flat link count", scene.name);
    assert_eq!(h.refine_stats.oracle_calls, f.refine_stats.oracle_calls, "{}: flat oracle calls", scene.name);
    assert!(same_solution(&h, &d), "{}: DAG links or radiosity differ from hand-written", scene.name);
    assert!(same_solution(&h, &f), "{}: flat links or radiosity differ from hand-written", scene.name);
}

#[test]
fn three_releases_agree_on_the_cornell_box() {
    check(&radiosity::scene::cornell_box(), 0.01);
    check(&radiosity::scene::cornell_box(), 0.002);
}

#[test]
fn three_releases_agree_on_every_bench_scene() {
    for scene in scenes::bench_scenes() {
        check(&scene, 0.01);
    }
}

#[test]
fn bench_reports_identical_rows() {
    let config = radiosity::oracle::bench::BenchConfig { repeats: 1, ..Default::default() };
    let rows = radiosity::oracle::bench::run(&[scenes::simple_room()], &config);
    assert_eq!(rows.len(), 1);
    assert!(rows[0].identical, "{rows:?}");
    assert!(rows[0].hand_s > 0.0 && rows[0].dag_s > 0.0 && rows[0].flat_s > 0.0, "{rows:?}");
}
