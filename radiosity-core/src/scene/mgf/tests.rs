//! Whole-reader tests on inline MGF snippets (includes are written to the temporary directory).

use super::{MgfOptions, load, load_str};
use crate::geom::{DVec3, PolyKind};
use crate::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};

/// A unit square in the z = 0 plane, CCW about +z, as vertices `a b c d`.
const SQUARE: &str = "v a =\n p 0 0 0\nv b =\n p 1 0 0\nv c =\n p 1 1 0\nv d =\n p 0 1 0\n";

fn check(text: &str) -> Scene {
    load_str(text, Path::new("test.mgf"), &MgfOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn check_err(text: &str) -> SceneError {
    load_str(text, Path::new("test.mgf"), &MgfOptions::default()).expect_err("should not load")
}

fn near(a: DVec3, b: DVec3, tol: f64) -> bool {
    (a - b).length() <= tol
}

/// A fresh directory under the system temporary directory.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiosity-mgf-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn simple_quad() {
    let s = check(&format!("{SQUARE}m white =\n c\n rd .5\nf a b c d\n"));
    assert_eq!(s.polygons.len(), 1);
    let p = &s.polygons[0];
    assert_eq!(p.poly.kind, PolyKind::Quad);
    assert_eq!(p.poly.vertices(), &[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y]);
    assert!(near(p.poly.normal(), DVec3::Z, 1e-12));
    assert_eq!(s.materials[p.material as usize].name, "white");
    assert_eq!(s.groups[p.group as usize], "(root)");
    assert_eq!(s.name, "test.mgf");
}

#[test]
fn named_vertices_are_copied_and_reselected() {
    // `v e = a` copies a; `v a` reselects a so that `p` moves it (used later at its new place).
    let s = check(&format!("{SQUARE}v e = b\n p 2 0 0\nf a e c\nv a\n p 0 0 1\nf a b d\n"));
    assert_eq!(s.polygons.len(), 2);
    assert_eq!(s.polygons[0].poly.v[1], DVec3::new(2.0, 0.0, 0.0));
    assert_eq!(s.polygons[1].poly.v[0], DVec3::Z);
    assert_eq!(s.polygons[0].poly.kind, PolyKind::Triangle);
}

#[test]
fn transforms_translate_rotate_and_nest() {
    let s = check(&format!("{SQUARE}xf -t 1 2 3\nf a b c\nxf -rz 90\nf a b c\nxf\nxf\nf a b c\n"));
    let first = s.polygons[0].poly.v;
    assert!(near(first[1], DVec3::new(2.0, 2.0, 3.0), 1e-12));
    // The inner rotation acts first, then the enclosing translation.
    assert!(near(s.polygons[1].poly.v[1], DVec3::new(1.0, 3.0, 3.0), 1e-12));
    assert!(near(s.polygons[2].poly.v[1], DVec3::X, 1e-12));
}

#[test]
fn mirrors_keep_faces_front_facing() {
    let s = check(&format!("{SQUARE}xf -mx\nf a b c d\nxf\n"));
    let p = &s.polygons[0].poly;
    assert!(near(p.normal(), DVec3::Z, 1e-12), "{:?}", p.normal());
    assert!(p.vertices().iter().all(|v| v.x <= 0.0));
}

#[test]
fn arrays_repeat_their_contents() {
    let s = check(&format!("{SQUARE}xf -a 3 -t 2 0 0\no tile\nf a b c d\no\nxf\nf a b c d\n"));
    assert_eq!(s.polygons.len(), 4);
    let xs: Vec<f64> = s.polygons.iter().map(|p| p.poly.v[0].x).collect();
    assert_eq!(xs, vec![0.0, 2.0, 4.0, 0.0]);
    let groups: Vec<&str> = s.polygons.iter().map(|p| s.groups[p.group as usize].as_str()).collect();
    assert_eq!(groups, vec!["a0/tile", "a1/tile", "a2/tile", "(root)"]);
    // Two array dimensions: 2 × 3 instances.
    let s = check(&format!("{SQUARE}xf -a 2 -t 0 5 0 -a 3 -t 2 0 0\nf a b c d\nxf\n"));
    assert_eq!(s.polygons.len(), 6);
    assert_eq!(s.groups, vec!["a0.0", "a0.1", "a0.2", "a1.0", "a1.1", "a1.2"]);
    assert!(near(s.polygons[5].poly.v[0], DVec3::new(4.0, 5.0, 0.0), 1e-12));
}

#[test]
fn includes_are_transformed_and_arrayed() {
    let dir = temp_dir("include");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(dir.join("sub/part.mgf"), format!("{SQUARE}o part\nf a b c d\no\n")).unwrap();
    let main = dir.join("main.mgf");
    std::fs::write(&main, "i sub/part.mgf -t 0 0 5\ni sub/part.mgf -a 2 -t 10 0 0\n").unwrap();
    let s = load(&main).unwrap();
    assert_eq!(s.polygons.len(), 3);
    assert!(near(s.polygons[0].poly.v[2], DVec3::new(1.0, 1.0, 5.0), 1e-12));
    assert!(near(s.polygons[2].poly.v[0], DVec3::new(10.0, 0.0, 0.0), 1e-12));
    assert_eq!(s.groups[s.polygons[2].group as usize], "a1/part");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn missing_include_names_the_file() {
    let dir = temp_dir("missing");
    let main = dir.join("main.mgf");
    std::fs::write(&main, "i nowhere/missing.mgf\n").unwrap();
    let err = load(&main).unwrap_err();
    // Named at the `i` line of the including file (issue 17: errors name the file that was read).
    assert!(matches!(&err, SceneError::Parse { path, line: 1, .. } if path == &main), "{err}");
    assert!(err.to_string().contains("cannot read included file") && err.to_string().contains("nowhere/missing.mgf"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn include_cycle_is_an_error() {
    let dir = temp_dir("cycle");
    std::fs::write(dir.join("a.mgf"), "i b.mgf\n").unwrap();
    std::fs::write(dir.join("b.mgf"), "\ni a.mgf\n").unwrap();
    let err = load(&dir.join("a.mgf")).unwrap_err();
    assert!(matches!(&err, SceneError::Parse { line: 2, path, .. } if path.ends_with("b.mgf")), "{err}");
    assert!(err.to_string().contains("include cycle"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn primitive_counts_at_four_divisions() {
    let vertices = "v c =\n p 0 0 0\n n 0 0 1\nv top =\n p 0 0 2\n";
    let count = |body: &str| check(&format!("{vertices}{body}\n")).polygons.len();
    assert_eq!(count("sph c 1"), 128);
    assert_eq!(count("cyl c 1 top"), 16);
    assert_eq!(count("cone c 1 top 0"), 16);
    assert_eq!(count("cone c 1 top .5"), 16);
    assert_eq!(count("ring c 0 1"), 16);
    assert_eq!(count("ring c .5 1"), 16);
    assert_eq!(count("torus c 1 2"), 256);
    let s = check(&format!("{vertices}sph c 1\n"));
    let quads = s.polygons.iter().filter(|p| p.poly.kind == PolyKind::Quad).count();
    assert_eq!(quads, 96);
    // Outward for a positive radius, inward for a negative one.
    let outward = |s: &Scene| s.polygons.iter().all(|p| p.poly.normal().dot(p.poly.centroid()) > 0.0);
    assert!(outward(&s));
    assert!(check(&format!("{vertices}sph c -1\n")).polygons.iter().all(|p| p.poly.normal().dot(p.poly.centroid()) < 0.0));
    let fine =
        load_str(&format!("{vertices}sph c 1\n"), Path::new("t.mgf"), &MgfOptions { quarter_circle_divisions: 2, ..MgfOptions::default() });
    assert_eq!(fine.unwrap().polygons.len(), 32);
}

#[test]
fn prism_has_sides_and_two_caps() {
    let s = check(&format!("{SQUARE}prism a b c d 2\n"));
    assert_eq!(s.polygons.len(), 6);
    let area: f64 = s.polygons.iter().map(|p| p.poly.area()).sum();
    assert!((area - 10.0).abs() < 1e-12, "{area}");
    let center = DVec3::new(0.5, 0.5, -1.0);
    assert!(s.polygons.iter().all(|p| p.poly.normal().dot(p.poly.centroid() - center) > 0.0));
}

#[test]
fn face_with_hole_has_the_area_of_the_annulus() {
    let hole = "v e =\n p .25 .25 0\nv g =\n p .75 .25 0\nv h =\n p .75 .75 0\nv k =\n p .25 .75 0\n";
    let s = check(&format!("{SQUARE}{hole}fh a b c d - k h g e\n"));
    let area: f64 = s.polygons.iter().map(|p| p.poly.area()).sum();
    assert!((area - 0.75).abs() < 1e-9, "{area}");
}

#[test]
fn neutral_colour_gives_grey_reflectance() {
    let s = check(&format!("{SQUARE}m grey =\n c\n cxy 0.333 0.333\n rd 0.5\nf a b c d\n"));
    for r in s.materials[0].reflectance {
        assert!((r - 0.5).abs() <= 0.01, "{:?}", s.materials[0].reflectance);
    }
    let named = check(&format!("{SQUARE}c red =\n cxy .64 .33\nm r =\n c red\n rd .2\nf a b c\n"));
    let rgb = named.materials[0].reflectance;
    assert!(rgb[0] > rgb[1] && rgb[0] > rgb[2], "{rgb:?}");
    let mixed = check(&format!("{SQUARE}c red =\n cxy .64 .33\nc x =\n cmix 1 red 0 red\nm r =\n rd .2\nf a b c\n"));
    for (m, n) in mixed.materials[0].reflectance.iter().zip(rgb) {
        assert!((m - n).abs() < 1e-9, "{m} vs {n}");
    }
}

#[test]
fn emitter_from_ed() {
    let s = check(&format!("{SQUARE}m light =\n c\n ed 100\nf a b c d\n"));
    let m = &s.materials[0];
    assert!(m.is_emitter());
    for e in m.emission {
        assert!((e - 100.0).abs() < 0.2, "{:?}", m.emission);
    }
    assert_eq!(m.reflectance, [0.0; 3]);
}

#[test]
fn redefined_material_gets_a_new_scene_material() {
    let s = check(&format!("{SQUARE}m w =\n rd .5\nf a b c\nm w =\n rd .5\nf a b c\nm w =\n rd .25\nf a b c\n"));
    assert_eq!(s.materials.len(), 2);
    assert_eq!(s.materials[1].name, "w#2");
    assert_eq!(s.polygons.iter().map(|p| p.material).collect::<Vec<_>>(), vec![0, 0, 1]);
}

#[test]
fn bright_material_is_clamped_with_a_warning() {
    let s = check(&format!("{SQUARE}m hot =\n c\n cxy .64 .33\n rd .9\nf a b c d\n"));
    assert_eq!(s.warnings.clamped_materials, 1);
    assert!(s.materials[0].reflectance.iter().all(|&r| r < 1.0));
    assert!(s.warnings.messages.iter().any(|m| m.contains("`hot`") && m.contains("test.mgf:12")), "{:?}", s.warnings.messages);
}

#[test]
fn parse_errors_name_the_line() {
    let err = check_err("v a =\n p 0 0 0\n p 1 2 x\n");
    assert!(matches!(&err, SceneError::Parse { line: 3, .. }), "{err}");
    assert!(err.to_string().starts_with("test.mgf:3: "), "{err}");
    let err = check_err(&format!("{SQUARE}\nf a b zz\n"));
    assert!(matches!(&err, SceneError::Parse { line: 10, .. }), "{err}");
    assert!(err.to_string().contains("`zz`"), "{err}");
    assert!(matches!(check_err("p 1 2\n"), SceneError::Parse { line: 1, .. }));
    assert!(matches!(check_err(&format!("{SQUARE}f a b\n")), SceneError::Parse { line: 9, .. }));
    assert!(matches!(check_err("xf -t 1 2\n"), SceneError::Parse { line: 1, .. }));
    assert!(matches!(check_err("xf\n"), SceneError::Parse { line: 1, .. }));
    assert!(matches!(check_err("c x =\n cxy .8 .5\n"), SceneError::Parse { line: 2, .. }));
    assert!(matches!(check_err("m x\n"), SceneError::Parse { line: 1, .. }));
    assert!(matches!(check_err("v c =\n p 0 0 0\nring c 0 1\n"), SceneError::Parse { line: 3, .. }));
}

#[test]
fn unknown_entities_warn_once_per_kind() {
    let s = check(&format!("{SQUARE}foo 1 2\nf a b c\nfoo\nbar\nies x.ies\n"));
    assert_eq!(s.polygons.len(), 1);
    let msgs = &s.warnings.messages;
    assert_eq!(msgs.iter().filter(|m| m.contains("`foo`")).count(), 1, "{msgs:?}");
    assert!(msgs.iter().any(|m| m.contains("test.mgf:9: unknown entity `foo` skipped (2 times in all)")), "{msgs:?}");
    assert!(msgs.iter().any(|m| m.contains("`bar`")));
    assert!(msgs.iter().any(|m| m.contains("unsupported entity `ies`")));
}

#[test]
fn unclosed_transform_in_an_include_stays_local() {
    let dir = temp_dir("unclosed");
    std::fs::write(dir.join("part.mgf"), format!("{SQUARE}xf -t 0 0 7\nf a b c\n")).unwrap();
    std::fs::write(dir.join("main.mgf"), format!("i part.mgf\n{SQUARE}f a b c\n")).unwrap();
    let s = load(&dir.join("main.mgf")).unwrap();
    assert_eq!(s.polygons[0].poly.v[0].z, 7.0);
    assert_eq!(s.polygons[1].poly.v[0].z, 0.0);
    assert!(s.warnings.messages.iter().any(|m| m.contains("part.mgf:9") && m.contains("not closed")), "{:?}", s.warnings.messages);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn spectra_and_temperatures() {
    let s = check(&format!(
        "{SQUARE}c flat =\n cspec 380 780 1 1 1 1\nc warm =\n cct 2856\nm w =\n c flat\n rd .5\n c warm\n ed 10\nf a b c d\n"
    ));
    let m = &s.materials[0];
    assert!(m.reflectance.iter().all(|r| (r - 0.5).abs() < 0.01), "{m:?}");
    assert!(m.emission[0] > m.emission[1] && m.emission[1] > m.emission[2], "incandescent is reddish: {m:?}");
    // A spectrum without a valid chromaticity (a daylight basis function) is accepted until used.
    let basis = format!("{SQUARE}c s1 =\n cspec 380 780 -1 -2 -3\nc\nm w =\n rd .5\n");
    assert_eq!(check(&format!("{basis}f a b c\n")).polygons.len(), 1);
    let err = check_err(&format!("{basis}c s1\nrd .5\n"));
    assert!(matches!(&err, SceneError::Parse { line: 15, .. }), "{err}");
    assert!(err.to_string().contains("test.mgf:10"), "{err}");
}

/// Issue 17 (reader fuzz): `xf -a 4294967296` tried to build four billion instances and exhausted
/// memory; arrays (with the enclosing ones) and `-i` repeats are capped.
#[test]
fn huge_arrays_are_errors_not_allocations() {
    let text = format!("{SQUARE}m white =\n c\n rd .5\nxf -a 4294967296 -t 2 0 0\nf a b c d\nxf\n");
    let e = check_err(&text).to_string();
    assert_eq!(e, "test.mgf:12: array transform makes over 1000000 instances (counting enclosing arrays)");
    let nested = format!("{SQUARE}m white =\n c\n rd .5\nxf -a 1000 -t 2 0 0\nxf -a 1001 -t 0 2 0\nf a b c d\nxf\nxf\n");
    assert!(check_err(&nested).to_string().starts_with("test.mgf:13: array transform makes over"), "{}", check_err(&nested));
    let repeat = format!("{SQUARE}m white =\n c\n rd .5\nxf -i 20000000 -t 2 0 0\nf a b c d\nxf\n");
    assert_eq!(check_err(&repeat).to_string(), "test.mgf:12: transform repeat count `-i 20000000` is over 10000000");
    // At the cap's scale but under it, arrays still work.
    assert_eq!(check(&format!("{SQUARE}m white =\n c\n rd .5\nxf -a 3 -t 2 0 0\nxf -a 2 -t 0 2 0\nf a b c d\nxf\nxf\n")).polygons.len(), 6);
}
