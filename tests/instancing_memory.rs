//! The point of hierarchical instantiation: a generated forest of 1.2 million polygons solves end
//! to end (`radiosity generate forest` then `radiosity solve forest.toml`, outputs streamed to disk)
//! in no more peak memory than the source paper's 49 MB. The CLI runs in its own process, so the
//! peak resident set size it records in `stats.json` is the solve's alone.

use std::path::Path;
use std::process::Command;

/// The bound: the paper's figure for its 1.2-million-polygon forest, in bytes (10⁶, the stricter
/// reading of "MB").
const PEAK_RSS_BOUND_BYTES: u64 = 49_000_000;
/// The forest's size, two-sided leaves counted twice (as the solver sees them).
const FOREST_POLYGONS: u64 = 1_200_000;
/// Trees of the default generator (ages 10 to 20) that reach that size.
const FOREST_TREES: u32 = 22;

fn radiosity(args: &[&str], dir: &Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).current_dir(dir).output().expect("the binary runs");
    assert!(out.status.success(), "radiosity {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
#[cfg(target_os = "linux")]
fn forest_of_1_2_million_polygons_solves_within_49_mb() {
    let dir = tempfile::tempdir().unwrap();
    let text = radiosity(&["generate", "forest", "--trees", &FOREST_TREES.to_string(), "--out", "forest"], dir.path());
    radiosity(&["solve", "forest/forest.toml", "--out", "out", "--quiet", "--size", "256"], dir.path());
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/stats.json")).unwrap()).unwrap();
    let polygons = stats["polygons_out"].as_u64().unwrap();
    assert!(polygons >= FOREST_POLYGONS, "the forest has {polygons} polygons ({text})");
    let peak = stats["peak_rss_bytes"].as_u64().expect("Linux reports the peak RSS");
    eprintln!(
        "forest: {polygons} polygons, peak RSS {:.1} MB, {:.1} s",
        peak as f64 / 1e6,
        stats["time_s"]["total"].as_f64().unwrap_or(f64::NAN)
    );
    assert!(peak <= PEAK_RSS_BOUND_BYTES, "peak RSS {:.1} MB exceeds {:.0} MB", peak as f64 / 1e6, PEAK_RSS_BOUND_BYTES as f64 / 1e6);
    for file in ["solution.ply", "solution.glb", "patches.csv", "image.png"] {
        assert!(dir.path().join("out").join(file).metadata().unwrap().len() > 0, "{file} is empty");
    }
}
