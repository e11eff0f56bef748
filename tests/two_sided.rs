//! One leaf, two sides: a transmitting leaf written as two back-to-back faces or as one face is the
//! same surface with a front and a back, lit and counted once (checked against closed forms and
//! between the two ways of writing it).

use std::path::Path;
use std::process::Command;

#[path = "support/photons.rs"]
mod photons;

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

/// `n` square leaves of side `side`, normals uniform over the sphere, centres uniform over
/// `[-half, half]²` in x, y and `[0.5, 2.5]` in z, their vertices rounded to nine decimals (as
/// other tools write them: each quad is planar only to that rounding).
fn canopy_leaves(n: usize, side: f64, half: f64, seed: u64) -> Vec<[[f64; 3]; 4]> {
    let mut rng = photons::Rng(seed);
    (0..n)
        .map(|_| {
            let c = [half * (2.0 * rng.next() - 1.0), half * (2.0 * rng.next() - 1.0), 0.5 + 2.0 * rng.next()];
            let z = 2.0 * rng.next() - 1.0;
            let phi = std::f64::consts::TAU * rng.next();
            let r = (1.0 - z * z).sqrt();
            let nrm = [r * phi.cos(), r * phi.sin(), z];
            let a = if nrm[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
            let cross = |p: [f64; 3], q: [f64; 3]| [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]];
            let u = cross(nrm, a);
            let len = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            let u = u.map(|x| x / len);
            let w = cross(nrm, u);
            [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(su, sw)| std::array::from_fn(|k| format!("{:.9}", c[k] + 0.5 * side * (su * u[k] + sw * w[k])).parse().unwrap()))
        })
        .collect()
}

/// [`canopy_leaves`] as an OBJ file: faces `f a b c d`, with the reversed face after each when
/// `backs`.
fn canopy_obj(n: usize, side: f64, half: f64, seed: u64, backs: bool) -> String {
    let (mut v, mut f) = (String::new(), String::new());
    for (i, leaf) in canopy_leaves(n, side, half, seed).iter().enumerate() {
        for p in leaf {
            v.push_str(&format!("v {:.9} {:.9} {:.9}\n", p[0], p[1], p[2]));
        }
        let b = 4 * i + 1;
        f.push_str(&format!("f {} {} {} {}\n", b, b + 1, b + 2, b + 3));
        if backs {
            f.push_str(&format!("f {} {} {} {}\n", b + 3, b + 2, b + 1, b));
        }
    }
    format!("o leaves\nusemtl leaf\n{v}{f}")
}

/// A scene file over `obj`: the leaf material, a 10 × 10 m ground, the sun (and the uniform
/// 145-cell sky when `sky`).
fn canopy_scene(leaf: &str, ground: &str, sky: bool) -> String {
    let sky = if sky { "[sky]\nmodel = \"uniform\"\ndiffuse_horizontal = [60, 40]\ndirections = 145\n" } else { "" };
    format!(
        "name = \"canopy\"\nobj = \"leaves.obj\"\nbands = [\"PAR\", \"NIR\"]\n[[material]]\nname = \"leaf\"\n{leaf}\n\
         [[material]]\nname = \"ground\"\nreflectance = {ground}\n\
         [[polygon]]\nmaterial = \"ground\"\nvertices = [[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]\n\
         [sun]\ndirection = [0.0, 0.5, -0.866025403784]\ndirect_normal = [400, 380]\n{sky}"
    )
}

/// The balance of a scene whose light partly falls on the ground and partly escapes: the escaped
/// power is measured by rays ([`radiosity::daylight::power_leaving`], 145 directions per leaf),
/// the ground's share by the links' form factors, so the two agree to the rays' resolution only.
const BALANCE_TOL: f64 = 1e-4;

/// Leaves whose quads are planar only to the nine decimals they are written with, each alone over
/// a black ground under the sun: the back of a lit leaf gets no light (nothing in the scene can
/// send it any), so its irradiance is 0 and the balance closes. Before, a face's own back (the
/// same vertices, rounded off its plane by 1e-10 m) was taken for a surface in front of it at
/// distance 0: the two exchanged all their light (form factors clamped to 1), a sunlit back got
/// up to three times the front's irradiance, and a 400-leaf canopy balanced at 1.014.
#[test]
fn a_leaf_planar_only_to_its_decimals_does_not_light_its_own_back() {
    let mut rng = photons::Rng(7);
    for k in 0..12 {
        let dir = tempfile::tempdir().unwrap();
        let obj = canopy_obj(1, 0.1 + 0.3 * rng.next(), 0.0, 1000 + k, false);
        std::fs::write(dir.path().join("leaves.obj"), obj).unwrap();
        let scene = canopy_scene("reflectance = [0.45, 0.85]\ntwo_sided = true", "0.0", false);
        std::fs::write(dir.path().join("canopy.toml"), scene).unwrap();
        let (stats, csv) = solve(dir.path(), "canopy.toml");
        let rows = rows(&csv);
        assert_eq!(rows.len(), 3, "front, back, ground:\n{csv}");
        let (h0, h1) = (num(&rows[0], "h_NIR"), num(&rows[1], "h_NIR"));
        let (lit, dark) = if h0 >= h1 { (h0, h1) } else { (h1, h0) };
        assert!(dark <= EXACT_TOL * lit, "leaf {k}: the dark side gets {dark} W/m2 (the lit side {lit})");
        for band in ["PAR", "NIR"] {
            let p = &stats["power_by_band"][band];
            let (inc, abs, esc) = (p["incident"].as_f64().unwrap(), p["absorbed"].as_f64().unwrap(), p["escaped"].as_f64().unwrap());
            assert!(
                ((abs + esc) / inc - 1.0).abs() <= BALANCE_TOL,
                "leaf {k} {band}: absorbed {abs} + escaped {esc} against incident {inc}"
            );
        }
    }
}

/// The issue's canopy bar: the power balance closes within this in every band.
const CANOPY_BALANCE_TOL: f64 = 0.005;

/// A canopy of 200 random 15 cm leaves written by the test (nine decimals), once as one face per
/// leaf and once as back-to-back faces, under the sun and a 145-cell sky over a reflective and
/// over a black ground, with transmitting (ρ + τ up to 0.85) and with two-sided opaque scattering
/// leaves: both writings give the same absorbed power per band within 0.5%, and every solve
/// balances (absorbed + escaped against incident) within 0.5% in every band. Before, the
/// transmitting canopy over the reflective ground balanced at 1.014 in every band (its leaves lit
/// their own backs) and missed its target error.
#[test]
fn a_canopy_written_either_way_absorbs_the_same_and_balances() {
    let leaves = [
        ("transmitting", "reflectance = [0.10, 0.45]\ntransmittance = [0.05, 0.40]"),
        ("two-sided opaque", "reflectance = [0.10, 0.45]\ntwo_sided = true"),
    ];
    for (what, leaf) in leaves {
        for ground in ["[0.10, 0.25]", "0.0"] {
            let mut absorbed = Vec::new();
            for backs in [false, true] {
                let dir = tempfile::tempdir().unwrap();
                std::fs::write(dir.path().join("leaves.obj"), canopy_obj(200, 0.15, 2.5, 11, backs)).unwrap();
                std::fs::write(dir.path().join("canopy.toml"), canopy_scene(leaf, ground, true)).unwrap();
                let (stats, csv) = solve(dir.path(), "canopy.toml");
                let rows = rows(&csv);
                assert_eq!(rows.len(), 401, "{what}, backs {backs}: a row per side and the ground");
                let mut per_band = Vec::new();
                for band in ["PAR", "NIR"] {
                    let p = &stats["power_by_band"][band];
                    let (inc, abs, esc) =
                        (p["incident"].as_f64().unwrap(), p["absorbed"].as_f64().unwrap(), p["escaped"].as_f64().unwrap());
                    let balance = (abs + esc) / inc;
                    assert!(
                        (balance - 1.0).abs() <= CANOPY_BALANCE_TOL,
                        "{what} leaves, ground {ground}, backs {backs}, {band}: balance {balance} (absorbed {abs}, escaped {esc}, incident {inc})"
                    );
                    let rows_sum: f64 = rows.iter().map(|r| num(r, &format!("absorbed_{band}"))).sum();
                    assert!((rows_sum - abs).abs() <= 1e-9 * abs, "{band}: rows sum to {rows_sum}, power_absorbed {abs}");
                    let leaf_sum: f64 = rows.iter().filter(|r| r["material"] == "leaf").map(|r| num(r, &format!("absorbed_{band}"))).sum();
                    per_band.push(leaf_sum);
                }
                absorbed.push(per_band);
            }
            for b in 0..2 {
                let (one, two) = (absorbed[0][b], absorbed[1][b]);
                assert!(
                    (one - two).abs() <= CANOPY_BALANCE_TOL * two,
                    "{what} leaves, ground {ground}, band {b}: one face {one} W, two faces {two} W"
                );
            }
        }
    }
}

/// A one-sided face lit from behind: a 1 m² face at height 1 facing the black ground (its back to
/// the sun), under the sun alone. Nothing reaches its front, so the sun's `E·cosθ` on its back is
/// all that is lost there: `power_lost_at_backs` is that, counted in `incident`, the balance closes
/// with it, and a warning names the face. Before, that light vanished from every figure.
#[test]
fn light_on_the_back_of_a_one_sided_face_is_counted_as_lost_and_named() {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!(
        "{LEAF_MATERIAL}[[material]]\nname = \"plate\"\nreflectance = 0.5\ntwo_sided = false\n[[material]]\nname = \"ground\"\nreflectance = 0.0\n\
         [[polygon]]\nmaterial = \"ground\"\nvertices = [[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]\n\
         [[polygon]]\nmaterial = \"plate\"\nvertices = [[-0.5, 0.5, 1], [0.5, 0.5, 1], [0.5, -0.5, 1], [-0.5, -0.5, 1]]\n\
         [sun]\ndirection = [{}, {}, {}]\ndirect_normal = [{}, {}]\n",
        SUN[0], SUN[1], SUN[2], SUN_EN[0], SUN_EN[1]
    );
    std::fs::write(dir.path().join("plate.toml"), scene).unwrap();
    let (stats, csv) = solve(dir.path(), "plate.toml");
    let rows = rows(&csv);
    assert_eq!(rows.len(), 2, "ground and a one-sided plate:\n{csv}");
    let cos = -SUN[2] / (SUN[0] * SUN[0] + SUN[1] * SUN[1] + SUN[2] * SUN[2]).sqrt();
    let mut lost_total = 0.0;
    for (b, band) in ["PAR", "NIR"].into_iter().enumerate() {
        let p = &stats["power_by_band"][band];
        let lost = p["lost_at_backs"].as_f64().unwrap();
        let want = SUN_EN[b] * cos;
        assert!((lost - want).abs() <= EXACT_TOL * want, "{band}: lost at backs {lost} W against E cos = {want} W");
        let (inc, abs, esc) = (p["incident"].as_f64().unwrap(), p["absorbed"].as_f64().unwrap(), p["escaped"].as_f64().unwrap());
        assert!(((abs + esc + lost) / inc - 1.0).abs() <= EXACT_TOL, "{band}: absorbed {abs} + escaped {esc} + lost {lost} against {inc}");
        lost_total += lost;
    }
    assert!((stats["power_lost_at_backs"].as_f64().unwrap() - lost_total).abs() <= EXACT_TOL * lost_total);
    let warnings = stats["solve_warnings"].as_array().unwrap();
    assert!(
        warnings.iter().any(|w| w.as_str().unwrap().contains("back of one-sided faces") && w.as_str().unwrap().contains("polygons 1 ")),
        "{warnings:?}"
    );
}

/// One-sided opaque leaves (ρ 0.10/0.45, no back) in the test's canopy over a reflective ground,
/// under the sun and sky: the light landing on their backs (from the sun, the sky and the ground)
/// is counted as lost, and the balance closes within 0.5% with it. Before, it closed at 0.9967 on
/// a 400-leaf canopy of LAI 0.04 and the lost light was in no figure.
#[test]
fn a_canopy_of_one_sided_leaves_counts_what_lands_on_their_backs() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("leaves.obj"), canopy_obj(200, 0.15, 2.5, 11, false)).unwrap();
    std::fs::write(dir.path().join("canopy.toml"), canopy_scene("reflectance = [0.10, 0.45]\ntwo_sided = false", "[0.10, 0.25]", true))
        .unwrap();
    let (stats, _) = solve(dir.path(), "canopy.toml");
    for band in ["PAR", "NIR"] {
        let p = &stats["power_by_band"][band];
        let (inc, abs, esc, lost) = (
            p["incident"].as_f64().unwrap(),
            p["absorbed"].as_f64().unwrap(),
            p["escaped"].as_f64().unwrap(),
            p["lost_at_backs"].as_f64().unwrap(),
        );
        // Without it the balance would be off by more than the bar.
        assert!(lost > CANOPY_BALANCE_TOL * inc, "{band}: lost {lost} W of {inc} W");
        let balance = (abs + esc + lost) / inc;
        assert!(
            (balance - 1.0).abs() <= CANOPY_BALANCE_TOL,
            "{band}: balance {balance} (lost {lost}, absorbed {abs}, escaped {esc}, incident {inc})"
        );
    }
    assert!(stats["solve_warnings"].as_array().unwrap().iter().any(|w| w.as_str().unwrap().contains("back of one-sided faces")));
}

/// The handbook form factor from a point to a parallel `a × b` rectangle at distance `c`, the
/// point on the normal through one of its corners (Howell, "A Catalog of Radiation Heat Transfer
/// Configuration Factors": a differential area parallel to a rectangle, on the normal to a corner).
fn corner_form_factor(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / std::f64::consts::TAU
}

/// `n`-point Gauss–Legendre nodes and weights on [0, 1] (Newton's method on the Legendre
/// polynomial from the usual cosine guesses).
fn gauss_legendre_01(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            (0.5 * (x + 1.0), 0.5 * w)
        })
        .collect()
}

/// The closed form the solve must meet on the default settings, within 0.1%.
const CLOSED_FORM_TOL: f64 = 1e-3;

/// The issue's closed form: a 1 m² transmitting leaf (ρ 0.10/0.45, τ 0.05/0.40) at height 1 over a
/// black 10 × 10 m ground under the sun alone. The front gets `E = E_n·cosθ`, the back nothing; the
/// back sends `τ·E` down, of which the ground catches the share `F` (the handbook's corner form
/// factor, integrated over the leaf by Gauss–Legendre), and the ground gets the sun on 99 m² (the
/// leaf's whole shadow falls on it). Rows, their sum against `power_absorbed`, incident and the
/// balance: within 0.1%. Before, the leaf's shadow fell between the ground's 9 quadrature points
/// and the ground got the sun on all 100 m² (incident 1% high).
#[test]
fn a_leaf_over_a_black_ground_meets_its_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let sun = format!("[sun]\ndirection = [{}, {}, {}]\ndirect_normal = [{}, {}]\n", SUN[0], SUN[1], SUN[2], SUN_EN[0], SUN_EN[1]);
    let scene = format!(
        "{LEAF_MATERIAL}[[material]]\nname = \"ground\"\nreflectance = 0.0\n\
         [[polygon]]\nmaterial = \"leaf\"\nvertices = [[-0.5, -0.5, 1], [0.5, -0.5, 1], [0.5, 0.5, 1], [-0.5, 0.5, 1]]\n\
         [[polygon]]\nmaterial = \"ground\"\nvertices = [[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]\n{sun}"
    );
    std::fs::write(dir.path().join("leaf.toml"), scene).unwrap();
    let (stats, csv) = solve(dir.path(), "leaf.toml");
    let rows = rows(&csv);
    assert_eq!(rows.len(), 3, "front, back, ground:\n{csv}");
    let (front, back, ground) = (&rows[0], &rows[1], &rows[2]);
    let cos = -SUN[2] / (SUN[0] * SUN[0] + SUN[1] * SUN[1] + SUN[2] * SUN[2]).sqrt();
    // F(leaf's back -> ground): the point form factor to the ground, four corner rectangles
    // around the point's foot, averaged over the leaf.
    let gl = gauss_legendre_01(20);
    let mut f = 0.0;
    for &(u, wu) in &gl {
        for &(v, wv) in &gl {
            let (x, y) = (u - 0.5, v - 0.5);
            let point: f64 = [(5.0 - x, 5.0 - y), (5.0 + x, 5.0 - y), (5.0 - x, 5.0 + y), (5.0 + x, 5.0 + y)]
                .iter()
                .map(|&(a, b)| corner_form_factor(a, b, 1.0))
                .sum();
            f += wu * wv * point;
        }
    }
    assert!(f > 0.9 && f < 0.99, "F = {f}");
    let (rho, tau) = ([0.10, 0.45], [0.05, 0.40]);
    for (b, band) in ["PAR", "NIR"].into_iter().enumerate() {
        let e = SUN_EN[b] * cos;
        let close = |x: f64, want: f64, scale: f64, what: &str| {
            assert!((x - want).abs() <= CLOSED_FORM_TOL * scale, "{band} {what}: {x} against {want}")
        };
        close(num(front, &format!("h_{band}")), e, e, "front irradiance");
        close(num(back, &format!("h_{band}")), 0.0, e, "back irradiance");
        close(num(back, &format!("b_{band}")), tau[b] * e, tau[b] * e, "back radiosity");
        close(num(front, &format!("b_{band}")), rho[b] * e, rho[b] * e, "front radiosity");
        let ground_h = (99.0 * e + tau[b] * e * f) / 100.0;
        close(num(ground, &format!("h_{band}")), ground_h, ground_h, "ground irradiance");
        close(num(front, &format!("absorbed_{band}")), (1.0 - rho[b] - tau[b]) * e, e, "leaf absorbed");
        let absorbed: f64 = rows.iter().map(|r| num(r, &format!("absorbed_{band}"))).sum();
        let want = (1.0 - rho[b] - tau[b]) * e + 100.0 * ground_h;
        close(absorbed, want, want, "absorbed");
        let p = &stats["power_by_band"][band];
        close(p["absorbed"].as_f64().unwrap(), absorbed, 1e-6 * want, "power_absorbed against the rows");
        close(p["incident"].as_f64().unwrap(), 100.0 * e, 100.0 * e, "incident");
        // The escape is measured by 145 rays per element (the leaf's back sends 3% past the
        // ground's edge, resolved to a few percent of that): checked as a share of the balance.
        close(p["escaped"].as_f64().unwrap(), rho[b] * e + tau[b] * e * (1.0 - f), 100.0 * e, "escaped");
        let balance = (p["absorbed"].as_f64().unwrap() + p["escaped"].as_f64().unwrap()) / p["incident"].as_f64().unwrap();
        close(balance, 1.0, 1.0, "balance");
    }
}

/// Under the sun and sky, leaves written as one face each with a plain opaque material are
/// two-sided by default, as Radiance and CARIBU take them: the test's canopy gives the same rows
/// as with `two_sided = true`, and `stats.json` counts the backs given; `two_sided = false` keeps
/// them one-sided; the ground, whose underside sees nothing, keeps one side. Before, such leaves
/// blocked the light reaching their backs and lost it (46% less absorbed, in the issue's canopy).
#[test]
fn lone_faces_under_the_sky_are_two_sided_unless_declared_one_sided() {
    let run = |leaf: &str| {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("leaves.obj"), canopy_obj(60, 0.15, 2.5, 5, false)).unwrap();
        std::fs::write(dir.path().join("canopy.toml"), canopy_scene(leaf, "[0.10, 0.25]", true)).unwrap();
        solve(dir.path(), "canopy.toml")
    };
    let (default_stats, default_rows) = run("reflectance = [0.10, 0.45]");
    let (_, declared_rows) = run("reflectance = [0.10, 0.45]\ntwo_sided = true");
    let (one_stats, one_rows) = run("reflectance = [0.10, 0.45]\ntwo_sided = false");
    assert_eq!(rows(&default_rows).len(), 121, "a row per side and the ground");
    assert_eq!(default_rows, declared_rows, "by default as declared two-sided");
    assert_eq!(default_stats["warnings"]["two_sided_by_default"], 60);
    assert_eq!(rows(&one_rows).len(), 61, "declared one-sided: a row per leaf and the ground");
    assert_eq!(one_stats["warnings"]["two_sided_by_default"], 0);
    assert!(one_stats["power_lost_at_backs"].as_f64().unwrap() > 0.0);
}

/// A material that transmits cannot be declared one-sided: a one-line error naming the file and
/// the material, and a failing exit.
#[test]
fn a_transmitting_material_declared_one_sided_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let scene = "[[material]]\nname = \"leaf\"\nreflectance = 0.4\ntransmittance = 0.3\ntwo_sided = false\n\
                 [[polygon]]\nmaterial = \"leaf\"\nvertices = [[0,0,1],[1,0,1],[1,1,1],[0,1,1]]\n\
                 [sun]\ndirection = [0, 0, -1]\ndirect_normal = 100\n";
    std::fs::write(dir.path().join("bad.toml"), scene).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", "bad.toml", "--quiet", "--no-image", "--out", "out"])
        .current_dir(dir.path())
        .output()
        .expect("the binary runs");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("bad.toml") && stderr.contains("`leaf`") && stderr.contains("one-sided"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
}

/// The form factor from a point to the parallel rectangle `[x0, x1] × [y0, y1]` at height `c` above
/// it (the point at `(px, py)`): the corner form factors of the four rectangles with a corner above
/// the point, added and subtracted.
fn rectangle_form_factor(x: [f64; 2], y: [f64; 2], p: [f64; 2], c: f64) -> f64 {
    let corner = |u: f64, v: f64| u.signum() * v.signum() * corner_form_factor(u.abs(), v.abs(), c);
    corner(x[1] - p[0], y[1] - p[1]) - corner(x[0] - p[0], y[1] - p[1]) - corner(x[1] - p[0], y[0] - p[1])
        + corner(x[0] - p[0], y[0] - p[1])
}

/// A leaf passes light through where it is lit, not as its whole side's mean. A 1 m² leaf
/// (ρ .10/.45/.30, τ .05/.40/.20) at height 1 under the sun from the zenith, a black plate
/// shading its quarter `[0, ½]²`, a black ground 0.1 m below it: the leaf's back shines `τ·E` on
/// its three lit quarters and nothing under the shaded one, so the ground's irradiance at a point
/// is `τ·E·F` with `F` the point's form factor to the lit L (whole square less the quarter).
/// Checked at four points, under the shade and the light. Before, the back shone `τ·E·¾` all
/// over: the point under the shade got 15 times its light (13.96 W/m² against 0.920 in red), the
/// points under the light 25% too little.
#[test]
fn a_leaf_passes_light_through_where_it_is_lit() {
    const SCENE: &str = r#"[[material]]
name = "leaf"
reflectance = [0.10, 0.45, 0.30]
transmittance = [0.05, 0.40, 0.20]
[[material]]
name = "black"
reflectance = [0, 0, 0]
[[polygon]]
material = "leaf"
vertices = [[0,0,1],[1,0,1],[1,1,1],[0,1,1]]
[[polygon]]
material = "black"
vertices = [[-0.5,-0.5,1.5],[0.5,-0.5,1.5],[0.5,0.5,1.5],[-0.5,0.5,1.5]]
[[polygon]]
material = "black"
vertices = [[-2,-2,0.9],[3,-2,0.9],[3,3,0.9],[-2,3,0.9]]
[sun]
direction = [0, 0, -1]
direct_normal = [400, 380, 390]
"#;
    let (tau, sun) = ([0.05, 0.40, 0.20], [400.0, 380.0, 390.0]);
    let points = [[0.25, 0.25], [0.75, 0.75], [0.5, 0.5], [0.25, 0.75]];
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("leaf.toml"), SCENE).unwrap();
    let csv: String =
        std::iter::once("x,y,z,nx,ny,nz\n".to_owned()).chain(points.iter().map(|p| format!("{},{},0.9,0,0,1\n", p[0], p[1]))).collect();
    std::fs::write(dir.path().join("points.csv"), csv).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", "leaf.toml", "--points", "points.csv", "--quiet", "--no-image", "--out", "out"])
        .current_dir(dir.path())
        .output()
        .expect("the binary runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let got = rows(&std::fs::read_to_string(dir.path().join("out/points.csv")).unwrap());
    assert_eq!(got.len(), points.len());
    for (row, p) in got.iter().zip(points) {
        let f = rectangle_form_factor([0.0, 1.0], [0.0, 1.0], p, 0.1) - rectangle_form_factor([0.0, 0.5], [0.0, 0.5], p, 0.1);
        for (c, channel) in ["r", "g", "b"].into_iter().enumerate() {
            let want = tau[c] * sun[c] * f;
            let h = num(row, &format!("h_{channel}"));
            assert!((h - want).abs() <= EXACT_TOL * want, "point {p:?} {channel}: {h} against {want}");
        }
    }
}

/// A leaf seen edge-on shades a sliver of the leaf below it: a 10 cm square leaf at height 1
/// under the sun from the zenith, and 20 cm above it a tilted one whose shadow is a strip 8 mm
/// wide running right across it, between the 9 points of the leaf's rule and its corners. Both
/// black, so the leaf's irradiance is the sun's on its unshaded 92%: `0.92 E` exactly. Before
/// (2026-12-06) the leaf was left whole with the sun's full `E`, 8% high: a shadow was split for
/// only where it was smaller than the leaf in size, and the sliver is longer than the leaf. On an
/// 800-leaf canopy two leaves read 6.5% of the largest mean high this way while the estimate said
/// 0.6%.
#[test]
fn a_sliver_of_shadow_between_the_points_of_a_leaf_is_seen() {
    let dir = tempfile::tempdir().unwrap();
    let scene = "bands = [\"PAR\", \"NIR\"]\n[[material]]\nname = \"black\"\nreflectance = [0, 0]\n\
                 [[polygon]]\nmaterial = \"black\"\nvertices = [[0, 0, 1], [0.1, 0, 1], [0.1, 0.1, 1], [0, 0.1, 1]]\n\
                 [[polygon]]\nmaterial = \"black\"\nvertices = [[0.025, -0.05, 1.2], [0.033, -0.05, 1.3], [0.033, 0.15, 1.3], [0.025, 0.15, 1.2]]\n\
                 [sun]\ndirection = [0, 0, -1]\ndirect_normal = [400, 380]\n";
    std::fs::write(dir.path().join("sliver.toml"), scene).unwrap();
    let (_, csv) = solve(dir.path(), "sliver.toml");
    let rows = rows(&csv);
    for (band, e) in [("PAR", 400.0), ("NIR", 380.0)] {
        let want = e * (1.0 - 0.008 * 0.1 / 0.01);
        let h = num(&rows[0], &format!("h_{band}"));
        assert!((h - want).abs() <= SLIVER_TOL * e, "{band}: {h} W/m² against {want}");
    }
}

/// How close the shaded leaf's irradiance is to its exact value, relative to the sun's (half the
/// default target error).
const SLIVER_TOL: f64 = 5e-3;

/// The canopy [`a_canopy_absorbs_what_an_independent_photon_tracer_finds`] traces: leaf count,
/// side (m), half the plot's width (m) and seed of [`canopy_leaves`].
const TRACED_CANOPY: (usize, f64, f64, u64) = (200, 0.15, 2.5, 11);

/// [`TRACED_CANOPY`]'s leaves (ρ .10/.45, τ .05/.40, one face each) over the ground (ρ .10/.25)
/// under the sun and the sky, written as `canopy.toml` and `leaves.obj` in a new folder.
fn traced_canopy() -> tempfile::TempDir {
    let (n, side, half, seed) = TRACED_CANOPY;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("leaves.obj"), canopy_obj(n, side, half, seed, false)).unwrap();
    let leaf = "reflectance = [0.10, 0.45]\ntransmittance = [0.05, 0.40]";
    std::fs::write(dir.path().join("canopy.toml"), canopy_scene(leaf, "[0.10, 0.25]", true)).unwrap();
    dir
}

/// The solver against an independent photon tracer ([`photons`]): 200 transmitting leaves
/// (ρ .10/.45, τ .05/.40, written as one face each) over a 10 × 10 m ground (ρ .10/.25), the sun
/// and the uniform sky, at the default settings. The power absorbed by the leaves and by the
/// ground in each band is within [`PHOTON_TOL`] of the tracer's, whose own standard error is kept
/// below a fifth of that. (The solver's sky is 145 cells, the tracer's continuous.)
#[test]
fn a_canopy_absorbs_what_an_independent_photon_tracer_finds() {
    let (n, side, half, seed) = TRACED_CANOPY;
    let dir = traced_canopy();
    let (stats, csv) = solve(dir.path(), "canopy.toml");
    let rows = rows(&csv);
    let leaves = canopy_leaves(n, side, half, seed);
    let ground = [[-5.0, -5.0, 0.0], [5.0, -5.0, 0.0], [5.0, 5.0, 0.0], [-5.0, 5.0, 0.0]];
    let (rho, tau, rho_ground, sun, sky) = ([0.10, 0.45], [0.05, 0.40], [0.10, 0.25], [400.0, 380.0], [60.0, 40.0]);
    for (b, band) in ["PAR", "NIR"].into_iter().enumerate() {
        let mut surfaces: Vec<photons::Surface> =
            leaves.iter().map(|&v| photons::Surface { v, reflectance: rho[b], transmittance: tau[b], two_sided: true }).collect();
        surfaces.push(photons::Surface { v: ground, reflectance: rho_ground[b], transmittance: 0.0, two_sided: false });
        let light = photons::Light { sun_direction: [0.0, 0.5, -0.866025403784], sun_normal: sun[b], sky_horizontal: sky[b] };
        let tally = photons::trace(&surfaces, light, 2_000_000, 16, 0x5eed + b as u64);
        let traced_leaves = photons::absorbed_by(&tally, |i| i < n);
        let traced_ground = photons::absorbed_by(&tally, |i| i == n);
        let solved_leaves: f64 = rows.iter().filter(|r| r["material"] == "leaf").map(|r| num(r, &format!("absorbed_{band}"))).sum();
        let solved_ground: f64 = rows.iter().filter(|r| r["material"] == "ground").map(|r| num(r, &format!("absorbed_{band}"))).sum();
        let incident = stats["power_by_band"][band]["incident"].as_f64().unwrap();
        eprintln!(
            "{band}: leaves {solved_leaves:.3} W against {:.3} ± {:.3}; ground {solved_ground:.3} against {:.3} ± {:.3}; incident {incident:.3} against {:.3} ± {:.3}; escaped {:.3}, lost {:.3}",
            traced_leaves.mean,
            traced_leaves.std_error,
            traced_ground.mean,
            traced_ground.std_error,
            tally.incident.mean,
            tally.incident.std_error,
            tally.escaped.mean,
            tally.lost.mean
        );
        for (what, solved, traced) in [("leaves", solved_leaves, traced_leaves), ("ground", solved_ground, traced_ground)] {
            assert!(traced.std_error <= 0.2 * PHOTON_TOL * traced.mean, "{band} {what}: the tracer's noise {traced:?}");
            assert!(
                (solved - traced.mean).abs() <= PHOTON_TOL * traced.mean,
                "{band} {what}: solved {solved} W, traced {} ± {} W",
                traced.mean,
                traced.std_error
            );
        }
    }
}

/// How close the solver's absorbed power is to the photon tracer's (issue: within 1%).
const PHOTON_TOL: f64 = 1e-2;

/// A degenerate leaf (its vertices on a line, or repeated) in a scene file's OBJ or inline is
/// skipped with a counted warning naming the file and line. Before, a scene file dropped it
/// silently (the count stayed 0: the prototypes' readers' counts were thrown away).
#[test]
fn degenerate_leaves_are_skipped_with_a_warning_naming_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("leaves.obj"),
        "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 2 0 1\nusemtl leaf\nf 1 2 3 4\nf 1 2 5\nf 1 2 1\n",
    )
    .unwrap();
    let scene = format!(
        "obj = \"leaves.obj\"\n{LEAF_MATERIAL}[[polygon]]\nmaterial = \"leaf\"\nvertices = [[0,0,2],[1,0,2],[2,0,2]]\n\
         [sun]\ndirection = [0, 0, -1]\ndirect_normal = [400, 380]\n"
    );
    std::fs::write(dir.path().join("leaves.toml"), scene).unwrap();
    let (stats, csv) = solve(dir.path(), "leaves.toml");
    assert_eq!(rows(&csv).len(), 2, "the one good leaf, two sides:\n{csv}");
    let w = &stats["warnings"];
    assert_eq!(w["degenerate_faces"], 3, "{w}");
    let messages: Vec<&str> = w["messages"].as_array().unwrap().iter().map(|m| m.as_str().unwrap()).collect();
    for place in ["leaves.obj:8", "leaves.obj:9", "leaves.toml:7"] {
        assert!(messages.iter().any(|m| m.contains(place) && m.contains("degenerate")), "{place} in {messages:?}");
    }
}

/// Two leaves crossing each other (10 cm squares, one level, one tilted 60° through its middle)
/// over a black 10 × 10 m ground under the sun, at the default settings: the levels meet the
/// target, and each leaf absorbs what the independent photon tracer finds, in each band.
/// Before (2026-12-06) the estimate stalled at 2.6% over three levels, and with the leaves allowed
/// finer pieces alone it met the target at once while their NIR was 1.1% short: the light they
/// exchange gathers along the crossing line, where three faults hid it. The smallest element,
/// relative to the scene's 100 m², was a quarter of a leaf's side (`MIN_POLYGON_DEPTH`); the two
/// were linked whole (`LinkCtx::surfaces_cross`); and a visibility segment ending on a leaf met
/// its other side, in the same plane, in the ray caster's f32 frame. A fourth lit the strip
/// along the line where the other leaf shades it: shadow rays toward the sun ignored what lay
/// within 0.6 mm of their start (`RayCaster::ray_clear_skipping`). (The ground is black, below
/// the leaves and in the way of no light they get, so the tracer leaves it out and spends its
/// photons on the leaves; light from a reflective 100 m² ground to two 0.01 m² leaves is carried
/// by a few heavy photons, 1.5% noise at a million. The sky is left out: its 145 cells, each seen
/// or not along one ray, give the tilted leaf 2.6% less PAR from the sky than the tracer's
/// continuous sky, a discretisation the estimate does not count on surfaces yet.)
#[test]
fn crossing_leaves_meet_the_target_and_absorb_what_the_photon_tracer_finds() {
    let (h, c, s) = (0.05, 0.5, 0.75f64.sqrt());
    let flat = [[-h, -h, 1.0], [h, -h, 1.0], [h, h, 1.0], [-h, h, 1.0]];
    let tilted = [[-h, -h * c, 1.0 - h * s], [h, -h * c, 1.0 - h * s], [h, h * c, 1.0 + h * s], [-h, h * c, 1.0 + h * s]];
    let mut obj = String::from("o leaves\nusemtl leaf\n");
    for p in flat.iter().chain(&tilted) {
        obj.push_str(&format!("v {:.12} {:.12} {:.12}\n", p[0], p[1], p[2]));
    }
    obj.push_str("f 1 2 3 4\nf 5 6 7 8\n");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("leaves.obj"), obj).unwrap();
    let leaf = "reflectance = [0.10, 0.45]\ntransmittance = [0.05, 0.40]";
    std::fs::write(dir.path().join("canopy.toml"), canopy_scene(leaf, "0", false)).unwrap();
    let (stats, csv) = solve(dir.path(), "canopy.toml");
    assert!(stats["target_missed"].is_null(), "{}", stats["target_missed"]);
    let estimate = stats["error_estimate"].as_f64().unwrap();
    assert!(estimate <= 0.01, "estimate {estimate}");
    let rows = rows(&csv);
    // Rows: each leaf's front and back, then the ground.
    assert_eq!(rows.len(), 5);
    let (rho, tau, sun) = ([0.10, 0.45], [0.05, 0.40], [400.0, 380.0]);
    for (b, band) in ["PAR", "NIR"].into_iter().enumerate() {
        let surfaces: Vec<photons::Surface> =
            [flat, tilted].iter().map(|&v| photons::Surface { v, reflectance: rho[b], transmittance: tau[b], two_sided: true }).collect();
        let light = photons::Light { sun_direction: [0.0, 0.5, -0.866025403784], sun_normal: sun[b], sky_horizontal: 0.0 };
        let tally = photons::trace(&surfaces, light, 4_000_000, 16, 0xc0ffee + b as u64);
        for k in 0..2 {
            let traced = photons::absorbed_by(&tally, |i| i == k);
            let solved = num(&rows[2 * k], &format!("absorbed_{band}")) + num(&rows[2 * k + 1], &format!("absorbed_{band}"));
            eprintln!("{band} leaf {k}: solved {solved:.5} W, traced {:.5} ± {:.5} W", traced.mean, traced.std_error);
            assert!(traced.std_error <= 0.2 * PHOTON_TOL * traced.mean, "{band} leaf {k}: the tracer's noise {traced:?}");
            assert!(
                (solved - traced.mean).abs() <= PHOTON_TOL * traced.mean,
                "{band} leaf {k}: solved {solved} W, traced {} ± {} W",
                traced.mean,
                traced.std_error
            );
        }
    }
}

/// A level's leaf-resolution coefficients take from the level before's those of a leaf on a link
/// both have (`Config::reuse_leaf_coefficients`, the default): on a canopy of 200 transmitting
/// leaves under the sun and the sky, solved to the default target over several levels, the
/// solution is the one every coefficient computed anew gives, bit for bit, and the levels after
/// the first took coefficients from the level before.
#[test]
fn reused_leaf_coefficients_give_the_same_solution_bit_for_bit() {
    use radiosity::pipeline::{self, Config};
    let dir = traced_canopy();
    // As `radiosity solve` reads a scene file of daylight on plain geometry.
    let (file, lighting) = radiosity::instancing::load_with_lighting(&dir.path().join("canopy.toml")).expect("the scene loads");
    let mut scene = radiosity::instancing::flatten(&file, &radiosity::instancing::FlattenOptions::default()).unwrap();
    scene.distant = lighting.bands.pack_distant(0);
    radiosity::daylight::two_sided_where_backs_see_light(&mut scene);
    let solve = |reuse: bool| {
        let config = Config { target_error: Some(0.01), reuse_leaf_coefficients: reuse, ..Config::default() };
        pipeline::run(&scene, &radiosity::refine::BfHand::default(), &config, &|_| {})
    };
    let (reusing, anew) = (solve(true), solve(false));
    let reused: Vec<usize> = reusing.levels.iter().map(|l| l.leaf_coefficients_reused).collect();
    eprintln!("levels {}, coefficients {}, reused per level {reused:?}", reusing.levels.len(), reusing.leaf_entries);
    assert!(reusing.levels.len() >= 3, "the canopy takes several levels: {}", reusing.levels.len());
    assert_eq!(reused[0], 0, "the first level has none before it");
    assert!(reused[1..].iter().all(|&r| r > 0), "every later level took coefficients: {reused:?}");
    assert!(anew.levels.iter().all(|l| l.leaf_coefficients_reused == 0));
    assert_eq!(reusing.links.len(), anew.links.len());
    assert_eq!(reusing.solution.radiosity, anew.solution.radiosity, "radiosity differs");
    assert_eq!(reusing.solution.irradiance, anew.solution.irradiance, "irradiance differs");
    assert_eq!(reusing.error_estimate, anew.error_estimate);
}
