//! `radiosity bench shafts` end to end on the Cornell box: every method's row, the repeated solves
//! of `solve --time-for`, and the shafts' results within the ray-sampling noise that the reseeded
//! plain-rays row measures.

use std::process::Command;

/// How many of the links (relative) the shafts' exact segment test may change against the BVH's
/// on the Cornell box (see `bench_shafts_rows_repeats_and_noise`).
const GRAZING_LINKS_REL: f64 = 1e-4;

#[test]
fn bench_shafts_rows_repeats_and_noise() {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["bench", "shafts", "cornell", "--repeats", "2", "--time-for", "0.05", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).expect("one JSON document");
    let methods: Vec<&str> = rows.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(methods, ["rays", "aabb", "obb", "aabb/shaft", "obb/shaft", "rays/seed+1"]);
    let row = |m: &str| rows.iter().find(|r| r["method"] == m).unwrap();
    for r in &rows {
        // Round 1 solves once; round 2 solves at least twice within its process.
        assert!(r["timed_runs"].as_u64().unwrap() >= 3, "{r}");
        for key in ["links", "elements", "rays", "time_s", "peak_rss_bytes", "max_rel_diff_to_rays"] {
            assert!(!r[key].is_null(), "{key} missing: {r}");
        }
    }
    let diff = |m: &str| row(m)["max_rel_diff_to_rays"].as_f64().unwrap();
    let noise = diff("rays/seed+1");
    assert!(noise > 0.0, "another seed changes the plain-rays solution");
    for m in ["aabb", "obb", "aabb/shaft", "obb/shaft"] {
        assert!(diff(m) <= noise, "{m}: {} against ray noise {noise}", diff(m));
    }
    // Under BF the shafts cull rays without changing the links, up to the segments that graze an
    // edge: the shafts test their candidates with the exact segment-polygon test, the scene's BVH
    // with obvhs's f32 triangles, and such a segment can be blocked in one and clear in the other
    // (1 link of 138,438 after links of reflected light took `--rays` segments, 2026-12-06; none
    // before). The shaft oracle (BF with the shaft deciding visibility where it can) drops the
    // links one occluder blocks and skips the visibility test of links nothing occludes: no more
    // links, fewer rays.
    let links = |m: &str| row(m)["links"].as_f64().unwrap();
    assert!(
        (links("obb") - links("rays")).abs() <= GRAZING_LINKS_REL * links("rays"),
        "obb {} against rays {}",
        links("obb"),
        links("rays")
    );
    assert!(row("obb")["rays"].as_u64() < row("rays")["rays"].as_u64());
    assert!(row("obb/shaft")["links"].as_u64() <= row("rays")["links"].as_u64());
    assert!(row("obb/shaft")["rays"].as_u64() < row("rays")["rays"].as_u64());
}

/// `radiosity bench canopy` end to end on a small canopy: one row per leaf count with the solve's
/// figures, and the leaves' and ground's absorbed power within 1% of the photon tracer's (plus
/// three of its standard errors) in each band.
#[test]
fn bench_canopy_rows_and_reference() {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["bench", "canopy", "--leaves", "60", "--photons", "1000000", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).expect("one JSON document");
    assert_eq!(rows.len(), 1);
    let r = &rows[0];
    assert_eq!(r["leaves"], 60);
    assert_eq!(r["finished"], true);
    assert_eq!(r["target_met"], true, "{r}");
    for key in ["time_s", "peak_rss_bytes", "links", "elements", "error_estimate", "trace_s"] {
        assert!(r[key].as_f64().is_some_and(|v| v > 0.0), "{key}: {r}");
    }
    let bands = r["bands"].as_array().unwrap();
    assert_eq!(bands.len(), 2);
    for b in bands {
        assert!((b["balance"].as_f64().unwrap() - 1.0).abs() <= 5e-3, "{b}");
        for (solved, traced) in [("leaves_absorbed", "traced_leaves"), ("ground_absorbed", "traced_ground")] {
            let (s, t, e) = (b[solved].as_f64().unwrap(), b[traced]["mean"].as_f64().unwrap(), b[traced]["std_error"].as_f64().unwrap());
            assert!((s - t).abs() <= 0.01 * t + 3.0 * e, "{} {solved}: {s} against {t} ± {e}", b["band"]);
        }
    }
}

/// `radiosity bench renderpark` end to end on the Cornell box: one row per target with the solve's
/// figures and its true errors against the kept reference (another seed, a finer target), each
/// estimate not below its polygons' true error; a second run reuses the reference.
#[test]
fn bench_renderpark_rows_errors_and_kept_reference() {
    let dir = tempfile::tempdir().unwrap();
    let run = || {
        let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
            .args(["bench", "renderpark", "cornell", "--targets", "0.3,0.1", "--reference-target", "0.02", "--json", "--out"])
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let rows: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).expect("one JSON document");
        rows
    };
    let rows = run();
    assert_eq!(rows.len(), 2);
    for (r, target) in rows.iter().zip([0.3, 0.1]) {
        assert_eq!(r["target"], target);
        assert_eq!(r["finished"], true, "{r}");
        for key in ["time_s", "peak_rss_bytes", "links", "error_estimate", "polygon_error", "worst_material_error"] {
            assert!(r[key].as_f64().is_some_and(|v| v > 0.0), "{key}: {r}");
        }
        assert!(r["error_estimate"].as_f64() >= r["polygon_error"].as_f64(), "{r}");
        assert!(r["worst_material"].as_str().is_some_and(|m| !m.is_empty()), "{r}");
    }
    let kept = dir.path().join("cornell/reference/stats.json");
    let modified = std::fs::metadata(&kept).unwrap().modified().unwrap();
    let again = run();
    assert_eq!(std::fs::metadata(&kept).unwrap().modified().unwrap(), modified, "the reference was solved again");
    assert_eq!(again[0]["polygon_error"], rows[0]["polygon_error"]);
    let csv = std::fs::read_to_string(dir.path().join("renderpark.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
}
