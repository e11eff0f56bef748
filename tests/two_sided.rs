//! One leaf, two sides: a transmitting leaf written as two back-to-back faces or as one face is the
//! same surface with a front and a back, lit and counted once (checked against closed forms and
//! between the two ways of writing it).

use std::path::Path;
use std::process::Command;

/// Closed forms here are sums of a few products: they agree to rounding.
const EXACT_TOL: f64 = 1e-9;

fn solve(dir: &Path, file: &str) -> (serde_json::Value, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", file, "--quiet", "--no-image", "--out", "out"])
        .current_dir(dir)
        .output()
        .expect("the binary runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stats = serde_json::from_str(&std::fs::read_to_string(dir.join("out/stats.json")).unwrap()).unwrap();
    (stats, std::fs::read_to_string(dir.join("out/patches.csv")).unwrap())
}

/// The rows of `patches.csv` as maps from column to value.
fn rows(csv: &str) -> Vec<std::collections::HashMap<String, String>> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines.map(|l| header.iter().map(|h| h.to_string()).zip(l.split(',').map(str::to_owned)).collect()).collect()
}

fn num(row: &std::collections::HashMap<String, String>, key: &str) -> f64 {
    row[key].parse().unwrap_or_else(|_| panic!("{key}: {}", row[key]))
}

const LEAF_MATERIAL: &str = r#"bands = ["PAR", "NIR"]
[[material]]
name = "leaf"
reflectance = [0.10, 0.45]
transmittance = [0.05, 0.40]
"#;
const FRONT: &str = "[[polygon]]\nmaterial = \"leaf\"\nvertices = [[0,0,1],[1,0,1],[1,1,1],[0,1,1]]\n";
const BACK: &str = "[[polygon]]\nmaterial = \"leaf\"\nvertices = [[0,1,1],[1,1,1],[1,0,1],[0,0,1]]\n";
/// The sun (towards the ground) and its normal irradiance per band.
const SUN: [f64; 3] = [0.3, 0.2, -0.93];
const SUN_EN: [f64; 2] = [400.0, 380.0];

/// A lone 1 m² leaf (ρ 0.10/0.45, τ 0.05/0.40) under the sun alone, written as two back-to-back
/// faces and as one face: both give two rows (front and back), the front's irradiance `E·cosθ`, the
/// absorbed power `(1 − ρ − τ)·E·cosθ` counted once, the back's radiosity `τ·E·cosθ`, incident
/// `E·cosθ`, and the rest escaping (the leaf is not taken for a closed scene). Before, the two faces
/// were four sides, the sun's light counted twice, and the scene closed.
#[test]
fn a_leaf_written_as_two_faces_or_one_is_one_leaf_with_two_sides() {
    let sun = format!("[sun]\ndirection = [{}, {}, {}]\ndirect_normal = [{}, {}]\n", SUN[0], SUN[1], SUN[2], SUN_EN[0], SUN_EN[1]);
    let cos = -SUN[2] / (SUN[0] * SUN[0] + SUN[1] * SUN[1] + SUN[2] * SUN[2]).sqrt();
    let (rho, tau) = ([0.10, 0.45], [0.05, 0.40]);
    let mut outputs = Vec::new();
    for scene in [format!("{LEAF_MATERIAL}{FRONT}{BACK}{sun}"), format!("{LEAF_MATERIAL}{FRONT}{sun}")] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("leaf.toml"), &scene).unwrap();
        let (stats, csv) = solve(dir.path(), "leaf.toml");
        let rows = rows(&csv);
        assert_eq!(rows.len(), 2, "one row per side:\n{csv}");
        assert_eq!(stats["closed"], false, "a lone leaf is open");
        for (b, band) in ["PAR", "NIR"].into_iter().enumerate() {
            let e = SUN_EN[b] * cos;
            let close = |x: f64, want: f64, what: &str| {
                assert!((x - want).abs() <= EXACT_TOL * want.abs().max(1.0), "{band} {what}: {x} against {want}")
            };
            close(num(&rows[0], &format!("h_{band}")), e, "front irradiance");
            close(num(&rows[1], &format!("h_{band}")), 0.0, "back irradiance");
            close(num(&rows[1], &format!("b_{band}")), tau[b] * e, "back radiosity");
            let absorbed: f64 = rows.iter().map(|r| num(r, &format!("absorbed_{band}"))).sum();
            close(absorbed, (1.0 - rho[b] - tau[b]) * e, "absorbed");
            let p = &stats["power_by_band"][band];
            close(p["absorbed"].as_f64().unwrap(), absorbed, "power_absorbed against the rows");
            close(p["incident"].as_f64().unwrap(), e, "incident");
            close(p["escaped"].as_f64().unwrap(), (rho[b] + tau[b]) * e, "escaped");
        }
        outputs.push(csv);
    }
    assert_eq!(outputs[0], outputs[1], "two faces and one face give the same leaf");
}

const OBJ_MTL: &str =
    "newmtl leaf\nKd 0.45 0.45 0.45\nKt 0.40 0.40 0.40\nnewmtl ground\nKd 0.25 0.25 0.25\nnewmtl lamp\nKd 0 0 0\nKe 100 100 100\n";
const OBJ_GEOMETRY: &str = "mtllib leaf.mtl\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv -2 -2 0\nv 3 -2 0\nv 3 3 0\nv -2 3 0\n\
v 0.4 0.4 2\nv 0.6 0.4 2\nv 0.6 0.6 2\nv 0.4 0.6 2\n";

/// A user's OBJ leaf (`Kt` transmittance) over a ground under a small lamp: written as one face it
/// transmits, as the same face with its back written out does (the same rows, to the bit); the
/// back's radiosity is `ρ·H_back + τ·H_front`. Before, a lone face transmitted nothing (its ground
/// got 18% less light) and had one row.
#[test]
fn an_obj_leaf_of_one_face_transmits_like_one_of_two() {
    let mut outputs = Vec::new();
    for faces in ["f 1 2 3 4\n", "f 1 2 3 4\nf 4 3 2 1\n"] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("leaf.mtl"), OBJ_MTL).unwrap();
        let obj =
            format!("{OBJ_GEOMETRY}o leaf\nusemtl leaf\n{faces}o ground\nusemtl ground\nf 5 6 7 8\no lamp\nusemtl lamp\nf 12 11 10 9\n");
        std::fs::write(dir.path().join("leaf.obj"), obj).unwrap();
        let (_, csv) = solve(dir.path(), "leaf.obj");
        let rows = rows(&csv);
        assert_eq!(rows.len(), 4, "front, back, ground, lamp:\n{csv}");
        let (front, back) = (&rows[0], &rows[1]);
        let want = 0.45 * num(back, "h_r") + 0.40 * num(front, "h_r");
        assert!((num(back, "b_r") - want).abs() <= 1e-6 * want, "back radiosity {} against {want}", num(back, "b_r"));
        outputs.push(csv);
    }
    assert_eq!(outputs[0], outputs[1], "one face and two faces give the same leaf");
}

/// Two back-to-back faces of different materials stay two surfaces, each with its own back, and
/// `stats.json` counts them with a message naming the file, the polygons and the materials.
#[test]
fn back_to_back_faces_of_different_materials_stay_apart_with_a_counted_warning() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("leaf.mtl"), format!("{OBJ_MTL}newmtl other\nKd 0.3 0.3 0.3\nKt 0.2 0.2 0.2\n")).unwrap();
    let obj = format!(
        "{OBJ_GEOMETRY}o leaf\nusemtl leaf\nf 1 2 3 4\nusemtl other\nf 4 3 2 1\no ground\nusemtl ground\nf 5 6 7 8\no lamp\nusemtl lamp\nf 12 11 10 9\n"
    );
    std::fs::write(dir.path().join("leaf.obj"), obj).unwrap();
    let (stats, csv) = solve(dir.path(), "leaf.obj");
    assert_eq!(rows(&csv).len(), 6, "two faces with a back each, ground, lamp:\n{csv}");
    let w = &stats["warnings"];
    assert_eq!(w["unpaired_backs"], 1, "{w}");
    let messages = w["messages"].as_array().unwrap();
    assert!(messages.iter().any(|m| m.as_str().unwrap().contains("leaf.obj: polygon 1") && m.as_str().unwrap().contains("`other`")), "{w}");
}
