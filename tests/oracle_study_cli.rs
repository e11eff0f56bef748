//! `radiosity oracle study` end to end: the visibility study's JSON on the Cornell box (structure
//! and sane figures), and a convex enclosure, where there is no visibility to study.

use std::process::Command;

fn radiosity(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).output().expect("the binary runs")
}

#[test]
fn study_on_the_cornell_box_gives_sane_rates_per_threshold() {
    let out = radiosity(&["oracle", "study", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON document");
    assert_eq!(doc["needs_visibility"], true, "{doc}");
    assert_eq!(doc["rays"], serde_json::json!([4, 16, 64]));
    assert!(doc["reference_rays"].as_u64().unwrap() > 64, "{doc}");
    let n_links = doc["links"].as_u64().unwrap();
    let total_area = doc["total_area"].as_f64().unwrap();
    assert!(n_links > 100 && total_area > 0.0, "{doc}");
    let rows = doc["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 5, "the default thresholds: {doc}");
    assert_eq!(rows[0]["threshold_rel"], 1.0, "the largest threshold first: {doc}");
    assert_eq!(rows[0]["links"].as_u64(), Some(n_links), "below the total area lies every link");
    for pair in rows.windows(2) {
        let (t, l) = (|r: &serde_json::Value| r["threshold_rel"].as_f64().unwrap(), |r: &serde_json::Value| r["links"].as_u64().unwrap());
        assert!(t(&pair[1]) < t(&pair[0]), "thresholds fall row by row: {doc}");
        assert!(l(&pair[1]) <= l(&pair[0]), "links below a threshold cannot grow as it falls: {doc}");
    }
    for r in rows {
        let (rel, abs) = (r["threshold_rel"].as_f64().unwrap(), r["threshold"].as_f64().unwrap());
        assert!((abs - rel * total_area).abs() <= 1e-12 * abs, "absolute threshold = fraction × total area: {r}");
        let links = r["links"].as_u64().unwrap() as f64;
        let rates: Vec<f64> = r["error_rate"].as_array().unwrap().iter().map(|e| e.as_f64().unwrap()).collect();
        assert_eq!(rates.len(), 3, "{r}");
        for e in &rates {
            assert!((0.0..=1.0).contains(e), "a rate in [0, 1]: {r}");
            // A share of whole links.
            assert!((e * links - (e * links).round()).abs() < 1e-6, "{r}");
        }
    }
    // The Cornell box's boxes occlude partly: 4 rays misclassify some links, 64 rays fewer.
    let all: Vec<f64> = rows[0]["error_rate"].as_array().unwrap().iter().map(|e| e.as_f64().unwrap()).collect();
    assert!(all[0] > 0.0 && all[2] < all[0], "64 rays err less than 4: {all:?}");
}

/// A closed unit cube seen from inside, its top a lamp: a convex enclosure.
const CUBE_OBJ: &str = "mtllib cube.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
usemtl white\nf 1 2 3 4\nf 1 4 8 5\nf 2 6 7 3\nf 1 5 6 2\nf 4 3 7 8\nusemtl lamp\nf 5 8 7 6\n";
const CUBE_MTL: &str = "newmtl white\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n";

#[test]
fn study_of_a_convex_enclosure_says_there_is_nothing_to_study() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("cube.mtl"), CUBE_MTL).unwrap();
    let cube = dir.path().join("cube.obj");
    std::fs::write(&cube, CUBE_OBJ).unwrap();
    let cube = cube.to_str().unwrap();
    let out = radiosity(&["oracle", "study", cube]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("convex enclosure") && !text.contains('|'), "a sentence, not a table: {text}");
    let out = radiosity(&["oracle", "study", cube, "--json"]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON document");
    assert_eq!(doc["needs_visibility"], false, "{doc}");
    assert_eq!(doc["rows"], serde_json::json!([]), "{doc}");
}

#[test]
fn study_refuses_a_threshold_that_is_not_positive() {
    let out = radiosity(&["oracle", "study", "--thresholds", "0.1,0"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--thresholds must be positive numbers, got 0"), "{stderr}");
}
