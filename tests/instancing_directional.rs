//! Directional proxies (issue 18, item 5): the face transfer matrix of anisotropic prototypes, and
//! directional proxies no worse than uniform ones against the full solve of a small tree.

use radiosity_core::instancing::properties::{self, PropertyConfig};
use radiosity_core::instancing::solver::relative_error;
use radiosity_core::instancing::{self, InstancedConfig, PolygonMeans, ProxyEmission, solve_full, solve_instanced};
use std::path::Path;

/// Monte Carlo tolerance of a transfer fraction (32 directions × 1024 rays; about half the rays
/// of a flat leaf come from each side).
const TRANSFER_TOL: f64 = 0.03;
/// Age of the small tree solved three ways.
const TREE_AGE: u32 = 5;
/// Directional proxies' largest error on that tree, at most this fraction of the uniform ones'
/// (measured 1.72% against 2.12% of the largest radiosity: 0.81).
const MAX_ERROR_RATIO: f64 = 0.95;
/// Their area-weighted mean error, at most this fraction of the uniform ones' (measured 0.0451%
/// against 0.0688%: 0.66).
const MEAN_ERROR_RATIO: f64 = 0.9;

/// What may leak out of the closed cup's walls and bottom: a walk's ray that grazes the edge where
/// two of its polygons meet can slip between them (the BVH holds them in `f32`). Measured
/// 1.2·10⁻⁴ from the bottom face with 8,281 rays per direction (0 with 1,024): one ray in
/// thousands.
const CRACK_TOL: f64 = 1e-3;

fn parse(text: &str) -> instancing::InstancedScene {
    instancing::parse(text, Path::new("test.toml"), Path::new(".")).unwrap()
}

fn transfer_of(text: &str, name: &str) -> (radiosity_core::instancing::face_transfer::FaceTransfer, [f64; 3]) {
    let scene = parse(text);
    let p = properties::compute(&scene, scene.find(name).unwrap(), &PropertyConfig::default()).unwrap();
    (p.face_transfer(), p.mean_albedo())
}

#[test]
fn a_leaf_lit_from_above_shines_down_by_what_it_transmits() {
    // A horizontal two-sided leaf (ρ = 0.3, t = 0.2): of the light entering its flat box from
    // above (z+, face 5), ρ leaves back up and t leaves through the bottom (z−, face 4); the
    // uniform proxy would send all of it back up.
    let (t, albedo) = transfer_of(
        "[[material]]\nname = \"leaf\"\nreflectance = 0.3\ntransmittance = 0.2\n[[prototype]]\nname = \"leaf\"\n[[prototype.polygon]]\nmaterial = \"leaf\"\nvertices = [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]\n[[instance]]\nof = \"leaf\"\n",
        "leaf",
    );
    assert!((t.get(5, 5)[1] - 0.3).abs() <= TRANSFER_TOL, "reflected up: {:?}", t.get(5, 5));
    assert!((t.get(5, 4)[1] - 0.2).abs() <= TRANSFER_TOL, "transmitted down: {:?}", t.get(5, 4));
    assert!((t.get(4, 5)[1] - 0.2).abs() <= TRANSFER_TOL, "and from below, up: {:?}", t.get(4, 5));
    for j in 0..4 {
        assert!(t.get(5, j)[1] <= 1e-12, "nothing leaves a flat leaf's box by its edges: face {j} {:?}", t.get(5, j));
    }
    assert!((albedo[1] - 0.5).abs() <= TRANSFER_TOL);
}

#[test]
fn an_open_cup_shines_only_out_of_its_opening() {
    // A unit cup open at the top (walls and bottom one-sided, facing in): light entering through
    // the opening leaves only through it; light arriving at the walls from outside meets their
    // backs and is absorbed. The uniform proxy would re-emit from every face its mean albedo.
    let mut text = String::from("[[material]]\nname = \"white\"\nreflectance = 0.8\n[[prototype]]\nname = \"cup\"\n");
    for v in [
        "[[0,0,0],[1,0,0],[1,1,0],[0,1,0]]",
        "[[0,0,0],[0,1,0],[0,1,1],[0,0,1]]",
        "[[1,0,0],[1,0,1],[1,1,1],[1,1,0]]",
        "[[0,0,0],[0,0,1],[1,0,1],[1,0,0]]",
        "[[0,1,0],[1,1,0],[1,1,1],[0,1,1]]",
    ] {
        text.push_str(&format!("[[prototype.polygon]]\nmaterial = \"white\"\nvertices = {v}\n"));
    }
    text.push_str("[[instance]]\nof = \"cup\"\n");
    let (t, albedo) = transfer_of(&text, "cup");
    let top = t.get(5, 5)[0];
    assert!(top > 0.3, "light entering the opening leaves by it: {top}");
    for i in 0..6 {
        for j in 0..5 {
            assert!(t.get(i, j)[0] <= CRACK_TOL, "nothing leaves through the walls or the bottom: {i} -> {j}: {:?}", t.get(i, j));
        }
    }
    assert!(t.row_sum(0)[0] <= CRACK_TOL, "a wall lit from outside reflects nothing");
    assert!(albedo[0] > 0.05, "while the uniform proxy's mean albedo {albedo:?} re-emits from every face");
}

fn solve(scene: &instancing::InstancedScene, proxy_emission: ProxyEmission) -> PolygonMeans {
    let config = InstancedConfig { proxy_emission, ..InstancedConfig::default() };
    let mut means = PolygonMeans::default();
    let _ = solve_instanced(scene, &config, &mut means).unwrap();
    means
}

#[test]
fn directional_proxies_are_no_worse_than_uniform_ones_on_a_small_tree() {
    let scene = instancing::generate_tree(TREE_AGE, 1);
    let (full, _) = solve_full(&scene, &InstancedConfig::default()).unwrap();
    let (uni_max, uni_mean) = relative_error(&full, &solve(&scene, ProxyEmission::Uniform));
    let (dir_max, dir_mean) = relative_error(&full, &solve(&scene, ProxyEmission::Directional));
    eprintln!(
        "tree age {TREE_AGE}: uniform {:.2}% / {:.4}%, directional {:.2}% / {:.4}%",
        100.0 * uni_max,
        100.0 * uni_mean,
        100.0 * dir_max,
        100.0 * dir_mean
    );
    assert!(dir_max <= MAX_ERROR_RATIO * uni_max, "largest error: directional {dir_max}, uniform {uni_max}");
    assert!(dir_mean <= MEAN_ERROR_RATIO * uni_mean, "mean error: directional {dir_mean}, uniform {uni_mean}");
}
