//! Errors as `radiosity` prints them: one line naming the file and the reason, the reason once
//! (an error's source is printed by the chain of causes, not repeated in its message), exit status 1.

use std::path::Path;
use std::process::Command;

/// Runs `radiosity args` and returns its stderr, checking that it failed with one line.
fn run_err(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).output().expect("the binary runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{args:?} should fail with status 1: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: one line expected: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    stderr
}

/// What the operating system says about reading `path`.
fn os_reason(path: &Path) -> String {
    std::fs::read(path).expect_err("the file is missing").to_string()
}

#[test]
fn a_missing_scene_file_gives_its_reason_once() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["nonexist.obj", "nonexist.mgf", "nonexist.toml"] {
        let path = dir.path().join(name);
        let stderr = run_err(&["solve", "--quiet", "--out", dir.path().to_str().unwrap(), path.to_str().unwrap()]);
        let reason = os_reason(&path);
        assert!(stderr.contains(&format!("{}: cannot read file: {reason}", path.display())), "{stderr}");
        assert_eq!(stderr.matches(&reason).count(), 1, "the reason {reason:?} should appear once: {stderr}");
    }
}

#[test]
fn a_broken_prototype_file_gives_its_reason_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("twig.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, "[[material]]\nname = \"white\"\nreflectance = 0.5\n\n[[prototype]]\nname = \"twig\"\nobj = \"twig.obj\"\n")
        .unwrap();
    let stderr = run_err(&["solve", "--quiet", "--out", dir.path().to_str().unwrap(), scene.to_str().unwrap()]);
    // The scene file's line, then the prototype file's line and reason, each once.
    let reason = "face vertex index 2 out of range";
    assert!(stderr.contains(&format!("{}:", scene.display())) && stderr.contains("prototype `twig`: "), "{stderr}");
    assert!(stderr.contains("twig.obj:2: "), "{stderr}");
    assert_eq!(stderr.matches(reason).count(), 1, "the reason should appear once: {stderr}");
}
