//! Budgets and the refinement loop (issue "no wrong answer presented as right"): a budget costs
//! time or says that the target was missed, never silently changes the answer; levels stop when
//! they stop helping; every second of a solve is in a phase of `stats.json`.

use radiosity::pipeline::{self, Config, StopCause};
use radiosity::refine::BfHand;
use radiosity::validation;
use std::path::Path;
use std::process::{Command, Output};

/// `time_s`'s phases must add up to its `total` within this share (the issue's bar).
const PHASES_TOL: f64 = 0.02;

fn case(name: &str) -> validation::Case {
    validation::cases().into_iter().find(|c| c.name == name).expect("a validation case")
}

fn means(solved: &pipeline::Solved) -> Vec<[f64; 3]> {
    radiosity::output::polygon_results(&solved.hierarchy, &solved.solution).into_iter().map(|r| r.b).collect()
}

fn run_cli(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).current_dir(dir).output().expect("the binary runs")
}

fn stats(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("out/stats.json")).expect("stats.json")).expect("JSON")
}

/// The `b_r,b_g,b_b` columns of a `patches.csv`, in input order.
fn patch_means(path: &Path) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(path).expect("patches.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect("column");
    let (r, g, b) = (col("b_r"), col("b_g"), col("b_b"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            [f[r].parse().unwrap(), f[g].parse().unwrap(), f[b].parse().unwrap()]
        })
        .collect()
}

/// Ward's room with the leaf-resolution operator far over its budget (every coefficient beyond
/// 20,000 computed again at each iteration): the very same answer, bit for bit, as with every
/// coefficient stored, within its target against the reference, and the budget reported.
#[test]
fn a_leaf_operator_over_its_budget_costs_time_not_the_answer() {
    let c = case("ward-room");
    let target = 0.01;
    let config = Config { target_error: Some(target), ..Config::default() };
    let stored = pipeline::run(&c.scene, &BfHand::default(), &config, &|_| {});
    let tight = Config { leaf_operator_max_bytes: 40_000, ..config };
    let streamed = pipeline::run(&c.scene, &BfHand::default(), &tight, &|_| {});
    assert!(stored.leaf_over_budget.is_none(), "{:?}", stored.leaf_over_budget);
    let over = streamed.leaf_over_budget.expect("the budget is reported");
    assert_eq!(over.budget_entries, 20_000, "2 bytes a coefficient: {over:?}");
    assert!(over.recomputed_share > 0.5, "most coefficients recomputed: {over:?}");
    assert!(streamed.warnings.iter().any(|w| w.contains("leaf-resolution solve over its budget")), "{:?}", streamed.warnings);
    assert_eq!(means(&stored), means(&streamed), "a budget must not change the answer");
    assert_eq!(stored.error_estimate, streamed.error_estimate);
    let truth = validation::true_error(&c.reference, &means(&streamed));
    assert!(truth <= target, "true error {truth:.3e} over the target {target}");
    assert!(streamed.target_missed.is_none());
}

/// The same with `f32` coefficients (a solve without a target error stores them in `f32`, one
/// with a target of 0.01 in 16 bits): over its budget, bit for bit the same answer.
#[test]
fn a_single_precision_leaf_operator_over_its_budget_gives_the_same_answer() {
    let c = case("ward-room");
    let config = Config { target_error: None, ..Config::default() };
    let stored = pipeline::run(&c.scene, &BfHand::default(), &config, &|_| {});
    let tight = Config { leaf_operator_max_bytes: 4_000, ..config };
    let streamed = pipeline::run(&c.scene, &BfHand::default(), &tight, &|_| {});
    assert!(stored.leaf_over_budget.is_none(), "{:?}", stored.leaf_over_budget);
    let over = streamed.leaf_over_budget.unwrap_or_else(|| panic!("the budget is reported ({} entries)", stored.leaf_entries));
    assert_eq!(over.budget_entries, 1_000, "4 bytes a coefficient: {over:?}");
    assert!(over.recomputed_share > 0.5, "most coefficients recomputed: {over:?}");
    assert_eq!(means(&stored), means(&streamed), "a budget must not change the answer");
}

/// A memory budget that stops refinement short of the target: the command writes its outputs,
/// says in `stats.json` and on stderr what it reached, which target it missed and which budget
/// stopped it, and exits with an error, unless `--allow-over-budget`. What it reports is honest:
/// the error estimate is not below the true error against the shipped reference.
#[test]
fn a_memory_budget_that_misses_the_target_says_so_and_fails() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["solve", "validation:ward-room", "--target-error", "0.001", "--max-memory", "2", "--no-image", "--quiet", "--out", "out"];
    let out = run_cli(dir.path(), &args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "a missed target must fail: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    assert!(stderr.contains("target error 0.001 not reached") && stderr.contains("memory budget of 2 MB"), "{stderr}");
    let s = stats(dir.path());
    let missed = &s["target_missed"];
    assert_eq!(missed["stopped_by"], "memory_budget", "{missed}");
    assert_eq!(missed["budget_bytes"], 2_000_000, "{missed}");
    assert_eq!(missed["target"], 0.001, "{missed}");
    let reached = missed["error_estimate"].as_f64().unwrap();
    assert!(reached > 0.001 && reached == s["error_estimate"].as_f64().unwrap(), "{missed}");
    assert!(s["memory_limited"].as_bool().unwrap());
    let c = case("ward-room");
    let truth = validation::true_error(&c.reference, &patch_means(&dir.path().join("out/patches.csv")));
    assert!(truth <= reached, "reported {reached:.3e}, true error {truth:.3e}");
    // Accepted on request: the same files, exit 0, the warning kept.
    let allowed: Vec<&str> = args.iter().copied().chain(["--allow-over-budget"]).collect();
    let out = run_cli(dir.path(), &allowed);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.starts_with("warning: target error 0.001 not reached"), "{stderr}");
    assert_eq!(stats(dir.path())["target_missed"]["stopped_by"], "memory_budget");
}

/// A lamp sealed in a closed box (its faces one-sided, outward) beside a grey ground under sun and
/// sky: the lamp's light lands on the box's inner backs, which no link reaches and no one can
/// see, so the power balance misses by about 1% and refinement does not move it (the links'
/// light is right, the gap is outside them). The levels stop as soon as the estimate meets the
/// target and the gap has not moved (at most one level after the estimate first met it), with a
/// warning that names the gap, instead of running ten levels of nothing. (This test's scene was
/// once black one-sided leaves, whose lost backs are now counted: `tests/two_sided.rs`. Its
/// ground took two levels while the sun's small shadows cut it into 125 pieces before refinement;
/// with the sun's exact lit share it starts in 35 and takes four.)
#[test]
fn a_gap_refinement_cannot_close_ends_the_levels_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), SEALED_LAMP).unwrap();
    let out = run_cli(dir.path(), &["solve", "scene.toml", "--no-image", "--quiet", "--out", "out"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "not a budget: the answer is written and the command succeeds: {stderr}");
    let s = stats(dir.path());
    let levels = s["levels"].as_array().unwrap();
    let first_met = levels.iter().position(|l| l["error_estimate"].as_f64().unwrap() <= 0.01).expect("the estimate meets the target");
    assert!(levels.len() <= (first_met + 2).min(5), "{} levels, the estimate met the target at level {}", levels.len(), first_met + 1);
    let gap = levels.last().unwrap()["balance_gap"].as_f64().unwrap();
    assert!(gap > pipeline::BALANCE_SHARE_OF_TARGET * 0.01, "the scene must have a gap the levels do not close: {gap}");
    assert_eq!(s["target_missed"]["stopped_by"], "balance_gap", "{}", s["target_missed"]);
    assert!(stderr.contains("power balance gap") && stderr.contains("did not move"), "{stderr}");
}

/// A 6 × 6 m ground of reflectance 0.25 under a sun 30° from the zenith and a uniform sky, beside
/// a closed grey box with a 320 W lamp sealed inside it.
const SEALED_LAMP: &str = r#"
[[material]]
name = "ground"
reflectance = 0.25
[[material]]
name = "shell"
reflectance = 0.5
[[material]]
name = "lamp"
reflectance = 0.0
emission = 2000.0
[[polygon]]
material = "ground"
vertices = [[-3,-3,0],[3,-3,0],[3,3,0],[-3,3,0]]
[[box]]
material = "shell"
min = [-0.5, -0.5, 0.5]
max = [0.5, 0.5, 1.0]
[[polygon]]
material = "lamp"
vertices = [[-0.2,-0.2,0.6],[0.2,-0.2,0.6],[0.2,0.2,0.6],[-0.2,0.2,0.6]]
[sun]
direction = [0.0, 0.5, -0.866025403784]
direct_normal = 800
[sky]
model = "uniform"
diffuse_horizontal = 100
directions = 145
"#;

/// Every second of a solve is in a phase: `time_s`'s phases (load, build, refine, solve,
/// estimate, output) add up to its total within [`PHASES_TOL`].
#[test]
fn time_phases_add_up_to_the_total() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_cli(dir.path(), &["solve", "validation:ward-room", "--target-error", "0.003", "--no-image", "--quiet", "--out", "out"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let t = &stats(dir.path())["time_s"];
    let phases: f64 = ["load", "build", "refine", "solve", "estimate", "output"].iter().map(|k| t[k].as_f64().unwrap()).sum();
    let total = t["total"].as_f64().unwrap();
    assert!((total - phases).abs() <= PHASES_TOL * total, "phases {phases:.3} s, total {total:.3} s: {t}");
    assert!(t["estimate"].as_f64().unwrap() > 0.0, "the estimate is a phase of its own: {t}");
}

/// With the levels stopped early for a budget the reported stop cause is the budget (the API's
/// view of the same solve as the command line's test above).
#[test]
fn the_stop_cause_of_a_memory_budget_is_the_budget() {
    let c = case("ward-room");
    let config = Config { target_error: Some(0.001), max_memory_bytes: 2_000_000, ..Config::default() };
    let solved = pipeline::run(&c.scene, &BfHand::default(), &config, &|_| {});
    let missed = solved.target_missed.expect("missed");
    assert_eq!(missed.stopped_by, StopCause::MemoryBudget);
    assert!(missed.stopped_by.is_budget());
    assert_eq!(Some(missed.error_estimate), solved.error_estimate);
}
