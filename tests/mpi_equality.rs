//! The instanced solve over MPI ranks (feature `mpi`) writes the files one process writes, byte for
//! byte: a small generated forest solved by one process (`--level-reuse subtree`, no mpirun), by
//! `mpirun -n 1` (reading the prototype properties the first run cached) and by
//! `mpirun --oversubscribe -n 2` (rank 0 solves the top level, rank 1 every
//! subtree), the files compared; stats.json compared but for the keys that legitimately differ.
//! And a rank that dies mid-job ends the job with an error, not a hang.
//!
//! Run with `cargo test --release --features mpi --test mpi_equality` (needs Open MPI's `mpirun`).
#![cfg(feature = "mpi")]

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// stats.json keys that differ between runs or between one process and several: timings, memory,
/// prototype properties read from the shared cache rather than computed (each rank computes
/// those it needs), and the MPI report itself.
const STATS_KEYS_THAT_DIFFER: [&str; 6] = ["time_s", "seconds", "peak_rss_bytes", "cache_hits", "cache_computed", "mpi"];

/// Longest a run may take before it counts as a hang.
const TIMEOUT: Duration = Duration::from_secs(300);

/// Runs `program args` in `dir` (allowed to run as root, as CI does), killed after [`TIMEOUT`].
fn run(program: &str, args: &[&str], envs: &[(&str, &str)], dir: &Path) -> Output {
    let mut child = Command::new(program)
        .args(args)
        .envs(envs.iter().copied())
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {program} (is Open MPI installed?): {e}"));
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > TIMEOUT {
            let _ = child.kill();
            panic!("{program} {args:?} hung (killed after {TIMEOUT:?})");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    child.wait_with_output().unwrap()
}

fn ok(out: &Output, what: &str) {
    assert!(out.status.success(), "{what} failed: {}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
}

const BIN: &str = env!("CARGO_BIN_EXE_radiosity");

/// The solve's arguments, output into `out`.
fn solve_args(out: &str) -> Vec<&str> {
    vec![BIN, "solve", "forest/forest.toml", "--out", out, "--quiet", "--size", "96", "--level-reuse", "subtree"]
}

fn stats(dir: &Path, out: &str) -> serde_json::Map<String, serde_json::Value> {
    let text = std::fs::read_to_string(dir.join(out).join("stats.json")).unwrap();
    let serde_json::Value::Object(map) = serde_json::from_str(&text).unwrap() else { panic!("stats.json is not an object") };
    map
}

/// The output files of `out` but stats.json and the property cache, by name.
fn files(dir: &Path, out: &str) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir.join(out))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "stats.json" && n != "prototype-cache")
        .collect();
    names.sort();
    names
}

#[test]
fn two_ranks_write_the_files_of_one_process_and_a_dead_rank_ends_the_job() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&run(BIN, &["generate", "forest", "--trees", "2", "--min-age", "3", "--max-age", "4", "--out", "forest"], &[], d), "generate");
    // The feature build without mpirun is one process.
    ok(&run(BIN, &solve_args("one")[1..], &[], d), "one process");
    // `mpirun -n 1` starts with the property cache one process wrote: properties read back must be
    // the bits computed (ranks read what other ranks cached).
    std::fs::create_dir_all(d.join("n1/prototype-cache")).unwrap();
    for entry in std::fs::read_dir(d.join("one/prototype-cache")).unwrap() {
        let entry = entry.unwrap();
        let _ = std::fs::copy(entry.path(), d.join("n1/prototype-cache").join(entry.file_name())).unwrap();
    }
    let mut n1 = vec!["--oversubscribe", "-n", "1"];
    n1.extend(solve_args("n1"));
    ok(&run("mpirun", &n1, &[], d), "mpirun -n 1");
    let mut n2 = vec!["--oversubscribe", "-n", "2"];
    n2.extend(solve_args("n2"));
    ok(&run("mpirun", &n2, &[], d), "mpirun -n 2");

    let one = files(d, "one");
    assert!(one.len() >= 4 && one.contains(&"patches.csv".to_string()), "outputs: {one:?}");
    let mut base = stats(d, "one");
    assert!(base.get("mpi").is_none(), "one process reports no MPI run");
    for run in ["n1", "n2"] {
        assert_eq!(files(d, run), one, "{run} writes other files");
        for name in &one {
            let (a, b) = (std::fs::read(d.join("one").join(name)).unwrap(), std::fs::read(d.join(run).join(name)).unwrap());
            assert!(a == b, "{run}/{name} differs from one process's ({} and {} bytes)", a.len(), b.len());
        }
        let mut s = stats(d, run);
        if run == "n1" {
            assert_eq!(s["cache_computed"], 0, "n1 reads every property from the cache");
        }
        if run == "n2" {
            let mpi = &s["mpi"];
            assert_eq!(mpi["ranks"], 2, "{mpi}");
            assert!(mpi["subtrees"].as_u64().unwrap() > 1 && mpi["bytes_from_workers"].as_u64().unwrap() > 0, "{mpi}");
        }
        for key in STATS_KEYS_THAT_DIFFER {
            let _ = s.remove(key);
            let _ = base.remove(key);
        }
        assert_eq!(s, base, "{run}/stats.json differs from one process's beyond timings and memory");
    }

    // Rank 1 exits abruptly on its first subtree: the job ends (non-zero), naming rank 1.
    let mut dead = vec!["--oversubscribe", "-n", "2"];
    dead.extend(solve_args("dead"));
    let out = run("mpirun", &dead, &[("RADIOSITY_MPI_FAIL", "1:1")], d);
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(!out.status.success(), "the job survived a dead rank: {text}");
    assert!(text.contains("rank 1: RADIOSITY_MPI_FAIL"), "{text}");
}
