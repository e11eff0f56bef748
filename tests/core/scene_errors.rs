//! Bad input gives one clear error naming the file, the place and the reason; degenerate faces are
//! skipped with a counted warning and the scene still solves.

use radiosity::scene::{LoadOptions, load};
use std::path::{Path, PathBuf};

use crate::support::solve;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write test file");
    p
}

const MTL: &str = "newmtl white\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 10 10 10\n";
const GOOD_FACES: &str =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 0 1 1\nv 1 1 1\nv 1 0 1\nusemtl white\nf 1 2 3 4\nusemtl lamp\nf 5 6 7 8\n";

fn load_err(path: &Path, allow_dark: bool) -> String {
    match load(path, &LoadOptions { allow_dark }) {
        Ok(_) => panic!("{} loaded but should fail", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn missing_file_names_the_file() {
    let msg = load_err(Path::new("/nonexistent/room.obj"), false);
    assert!(msg.contains("/nonexistent/room.obj") && msg.contains("cannot read"), "{msg}");
    // The operating system's reason is the source, so a chain of causes prints it once.
    let err = load(Path::new("/nonexistent/room.obj"), &LoadOptions::default()).expect_err("no such file");
    let source = std::error::Error::source(&err).expect("the reason is the source");
    assert!(!msg.contains(&source.to_string()), "the message repeats its source: {msg}");
}

#[test]
fn unknown_extension_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "room.xyz", "v 0 0 0\n");
    let msg = load_err(&p, false);
    assert!(msg.contains("room.xyz") && msg.contains("unknown scene format"), "{msg}");
}

#[test]
fn parse_error_names_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", MTL);
    let p = write(dir.path(), "room.obj", &format!("mtllib room.mtl\n{GOOD_FACES}v 1 2 banana\n"));
    let msg = load_err(&p, false);
    assert!(msg.contains("room.obj:14"), "{msg}");
}

#[test]
fn nan_coordinate_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", MTL);
    let p = write(dir.path(), "room.obj", &format!("mtllib room.mtl\n{}", GOOD_FACES.replacen("v 1 1 0", "v 1 NaN 0", 1)));
    let msg = load_err(&p, false);
    assert!(msg.contains("room.obj") && msg.to_lowercase().contains("non-finite"), "{msg}");
}

#[test]
fn reflectance_outside_unit_interval_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", &MTL.replace("Kd 0.5 0.5 0.5\nnewmtl lamp", "Kd 1.2 0.5 0.5\nnewmtl lamp"));
    let p = write(dir.path(), "room.obj", &format!("mtllib room.mtl\n{GOOD_FACES}"));
    let msg = load_err(&p, false);
    assert!(msg.contains("white") && msg.contains("reflectance 1.2 outside [0, 1)"), "{msg}");
}

#[test]
fn no_emitter_is_an_error_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", "newmtl white\nKd 0.5 0.5 0.5\n");
    let p = write(dir.path(), "room.obj", &format!("mtllib room.mtl\n{}", GOOD_FACES.replace("usemtl lamp\n", "")));
    let msg = load_err(&p, false);
    assert!(msg.contains("room.obj") && msg.contains("no emitter") && msg.contains("--allow-dark"), "{msg}");
    let scene = load(&p, &LoadOptions { allow_dark: true }).expect("dark scene allowed");
    assert_eq!(scene.polygons.len(), 2);
}

#[test]
fn malformed_mgf_names_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "room.mgf", "c\nrd 0.5\nv a =\np 0 0 0\nv b =\np 1 0 0\nv c = \np 1 1 zz\n");
    let msg = load_err(&p, false);
    assert!(msg.contains("room.mgf:8"), "{msg}");
}

#[test]
fn degenerate_faces_are_counted_and_the_scene_still_solves() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", MTL);
    // Two zero-area faces: a repeated vertex triangle and a collinear one.
    let extra = "v 2 0 0\nv 3 0 0\nusemtl white\nf 1 1 2\nf 1 2 10\n";
    let p = write(dir.path(), "room.obj", &format!("mtllib room.mtl\n{GOOD_FACES}{extra}"));
    let scene = load(&p, &LoadOptions::default()).expect("degenerate faces are skipped, not fatal");
    assert_eq!(scene.warnings.degenerate_faces, 2, "{:?}", scene.warnings);
    assert_eq!(scene.polygons.len(), 2);
    let solved = solve(&scene, 0.05, 1e-3);
    let floor_h = solved.solution.irradiance[0];
    assert!(floor_h.iter().all(|v| v.is_finite() && *v > 0.0), "floor irradiance {floor_h:?}");
}
