//! Scene files with instances: parsing, errors that name file and line, flattening, writing, the
//! poplar's layout (issue 5, "Scene description with instances").

use radiosity_core::geom::DVec3;
use radiosity_core::instancing::{self, FlattenOptions, flatten, generate_tree, poplar, write_scene};
use std::path::Path;

/// Tolerance on coordinates after a write / read round trip (Rust prints shortest round-trip decimals).
const ROUND_TRIP_TOL: f64 = 1e-12;

const NESTED: &str = r#"
name = "nested"
[[material]]
name = "white"
reflectance = 0.5
[[material]]
name = "leaf"
reflectance = [0.2, 0.4, 0.1]
transmittance = 0.2

[[polygon]]
material = "white"
vertices = [[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]]

[[instance]]
of = "branch"
translate = [1, 1, 0]

[[instance]]
of = "branch"
translate = [3, 1, 0]
rotate = [0, 0, 90]
scale = 0.5

[[prototype]]
name = "leaf"
[[prototype.polygon]]
material = "leaf"
vertices = [[0, 0, 0], [0.1, 0, 0], [0.1, 0.1, 0]]

[[prototype]]
name = "branch"
[[prototype.box]]
min = [0, 0, 0]
max = [0.1, 0.1, 1]
material = "white"
[[prototype.instance]]
of = "leaf"
translate = [0, 0, 1]
[[prototype.instance]]
of = "leaf"
matrix = [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0.5]
"#;

fn parse(text: &str) -> Result<instancing::InstancedScene, String> {
    instancing::parse(text, Path::new("scene.toml"), Path::new(".")).map_err(|e| e.to_string())
}

#[test]
fn nested_instances_flatten_with_their_transforms() {
    let s = parse(NESTED).unwrap();
    // Root: 1 quad + 2 branches × (6 box faces + 2 leaves × 2 sides).
    let counts = s.flattened_counts(true);
    assert_eq!(counts[s.root as usize], 1 + 2 * (6 + 2 * 2));
    let flat = flatten(&s, &FlattenOptions::default()).unwrap();
    assert_eq!(flat.polygons.len() as u64, counts[s.root as usize]);
    let b = flat.bounds();
    // Branch 1 reaches z = 1 + leaf; branch 2 is scaled by 0.5.
    assert!((b.max.z - 1.0).abs() < 1e-12, "top of the first branch's leaf at z = 1, got {}", b.max.z);
    // Second branch's first leaf: translate (3,1,0) · rot z 90° · scale 0.5 of (0.1, 0, 1) → (3, 1.05, 0.5).
    let want = DVec3::new(3.0, 1.05, 0.5);
    assert!(
        flat.polygons.iter().any(|p| p.poly.vertices().iter().any(|v| (*v - want).length() < 1e-12)),
        "transformed leaf vertex {want} not found"
    );
}

fn check_error(text: &str, expected: &str) {
    let e = parse(text).expect_err("the scene is invalid");
    assert_eq!(e, expected);
}

#[test]
fn malformed_syntax_names_the_line() {
    let e = parse("[[material]]\nname = \"a\"\nreflectance = [0.5,\n").unwrap_err();
    assert!(e.starts_with("scene.toml:3: ") || e.starts_with("scene.toml:4: "), "{e}");
}

#[test]
fn unknown_key_names_the_line() {
    let e = parse("[[material]]\nname = \"a\"\nreflectance = 0.5\ncolour = 1\n").unwrap_err();
    assert!(e.starts_with("scene.toml:"), "{e}");
    assert!(e.contains("colour"), "{e}");
}

#[test]
fn missing_prototype_file_names_the_line() {
    let e = parse("[[prototype]]\nname = \"twig\"\nobj = \"no_such_twig.obj\"\n").unwrap_err();
    assert!(e.starts_with("scene.toml:3: prototype `twig`: missing prototype file"), "{e}");
}

#[test]
fn instance_cycle_names_the_line_and_the_path() {
    check_error(
        "[[material]]\nname = \"w\"\nreflectance = 0.5\n[[prototype]]\nname = \"a\"\n[[prototype.instance]]\nof = \"b\"\n[[prototype]]\nname = \"b\"\n[[prototype.instance]]\nof = \"a\"\n[[instance]]\nof = \"a\"\n",
        "scene.toml:10: instance cycle: `a` -> `b` -> `a`",
    );
    check_error(
        "[[prototype]]\nname = \"self\"\n[[prototype.instance]]\nof = \"self\"\n",
        "scene.toml:3: instance cycle: `self` -> `self`",
    );
}

#[test]
fn singular_transform_names_the_line() {
    let e = parse("[[prototype]]\nname = \"p\"\n[[instance]]\nof = \"p\"\nscale = [1, 0, 1]\n").unwrap_err();
    assert!(e.starts_with("scene.toml:3: instance of `p`: singular transform"), "{e}");
    let e = parse("[[prototype]]\nname = \"p\"\n[[instance]]\nof = \"p\"\nmatrix = [1, 2, 3]\n").unwrap_err();
    assert_eq!(e, "scene.toml:3: `matrix` needs 12 (3×4) or 16 (4×4) numbers, found 3");
}

#[test]
fn unknown_names_are_reported() {
    check_error("[[instance]]\nof = \"ghost\"\n", "scene.toml:1: instance of unknown prototype `ghost`");
    check_error("[[polygon]]\nmaterial = \"ghost\"\nvertices = [[0,0,0],[1,0,0],[0,1,0]]\n", "scene.toml:1: unknown material `ghost`");
    let e = parse("[[material]]\nname = \"a\"\nreflectance = 1.5\n").unwrap_err();
    assert!(e.starts_with("scene.toml:1: ") && e.contains("reflectance"), "{e}");
}

#[test]
fn generated_tree_round_trips_through_files() {
    let dir = tempfile::tempdir().unwrap();
    let tree = generate_tree(6, 3);
    let path = write_scene(&tree, dir.path(), "tree").unwrap();
    let back = instancing::load(&path).unwrap();
    let options = FlattenOptions::default();
    let (a, b) = (flatten(&tree, &options).unwrap(), flatten(&back, &options).unwrap());
    assert_eq!(a.polygons.len(), b.polygons.len());
    assert!(a.polygons.len() > 100, "a 6-year tree has {} polygons", a.polygons.len());
    for (p, q) in a.polygons.iter().zip(&b.polygons) {
        assert_eq!(p.material, q.material);
        for (u, v) in p.poly.vertices().iter().zip(q.poly.vertices()) {
            assert!((*u - *v).length() <= ROUND_TRIP_TOL * (1.0 + u.length()), "{u} vs {v}");
        }
    }
}

/// A miniature of the shared poplar folder (same file names and CSV layout), written here so the
/// test reads no shared data.
fn mini_poplar(dir: &Path) {
    std::fs::write(dir.join("twig.obj"), "v 0 0 0\nv 0.01 0 0\nv 0 0 0.3\nv 0 0.01 0.3\ng bark\nusemtl bark\nf 1 2 3\ng leaf\nusemtl leaf\nv 0 0 0.1\nv 0.05 0.02 0.12\nv 0.1 0 0.1\nv 0.05 -0.02 0.08\nf 5 6 7\nf 5 7 8\n").unwrap();
    std::fs::write(dir.join("tree_skeleton.obj"), "v 0 0 0\nv 0.3 0 0\nv 0 0 20\ng bark\nusemtl bark\nf 1 2 3\n").unwrap();
    std::fs::write(dir.join("ground.obj"), "v -32 -32 0\nv 32 -32 0\nv 32 32 0\nv -32 32 0\ng ground\nusemtl ground\nf 1 2 3 4\n").unwrap();
    let header = "# rows\nm00,m01,m02,m03,m10,m11,m12,m13,m20,m21,m22,m23\n";
    std::fs::write(
        dir.join("tree_twig_instances.csv"),
        format!("{header}1,0,0,0.2,0,1,0,0,0,0,1,2\n0,-1,0,0,1,0,0,0.2,0,0,1,3\n0.8,0,0,0,0,0.8,0,0,0,0,0.8,4\n"),
    )
    .unwrap();
    std::fs::write(dir.join("forest_tree_instances.csv"), format!("{header}1,0,0,-4,0,1,0,-4,0,0,1,0\n1,0,0,4,0,1,0,4,0,0,1,0\n")).unwrap();
}

#[test]
fn poplar_layout_is_expressible() {
    let dir = tempfile::tempdir().unwrap();
    mini_poplar(dir.path());
    for forest in [false, true] {
        let text = poplar::poplar_toml(dir.path(), "", forest).unwrap();
        let toml_path = dir.path().join("poplar.toml");
        std::fs::write(&toml_path, text).unwrap();
        let s = instancing::load(&toml_path).unwrap();
        let trees: u64 = if forest { 2 } else { 1 };
        // Ground + 3 lights + trees × (skeleton 1 + 3 twigs × (1 bark + 2 two-sided leaves × 2)).
        assert_eq!(s.flattened_counts(true)[s.root as usize], 1 + 3 + trees * (1 + 3 * (1 + 2 * 2)), "forest = {forest}");
        assert_eq!(s.flattened_counts(false)[s.root as usize], 1 + 3 + trees * (1 + 3 * 3), "forest = {forest}");
    }
}
