//! `solution.glb` (issue 17, item 6): the Cornell box solved coarsely, its GLB read back with the
//! `gltf` crate against `solution.ply` (same vertices, colours whose sRGB encoding is the PLY's
//! bytes, `_RADIOSITY` holding the PLY's linear radiosity), and every output written atomically.

use radiosity::output::{self, GLB_RADIOSITY_ATTRIBUTE, OutputConfig};
use radiosity::pipeline::{self, Config};
use radiosity::refine::{BfHand, BfParams};
use radiosity::scene::cornell_box;
use std::path::Path;

/// A coarse BF tolerance: a few hundred leaves, a fraction of a second.
const COARSE_EPS: f64 = 0.05;
/// Largest difference (bytes) between the sRGB encoding of a GLB colour, stored as `f32`, and the
/// PLY's byte from `f64`: rounding can move a value across a half-byte boundary.
const BYTE_TOL: i32 = 1;
/// Relative tolerance on radiosity: both files store `f32` of the same `f64`.
const RADIOSITY_REL_TOL: f32 = 0.0;

/// One vertex of `solution.ply`: position, radiosity, colour bytes.
struct PlyVertex {
    p: [f32; 3],
    b: [f32; 3],
    rgb: [u8; 3],
}

fn read_ply(path: &Path) -> Vec<PlyVertex> {
    let bytes = std::fs::read(path).expect("solution.ply");
    let end = bytes.windows(11).position(|w| w == b"end_header\n").expect("PLY header") + 11;
    let header = std::str::from_utf8(&bytes[..end]).expect("ASCII header");
    let n: usize = header.lines().find_map(|l| l.strip_prefix("element vertex ")).expect("vertex count").trim().parse().expect("count");
    let f = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    (0..n)
        .map(|i| {
            let o = end + 27 * i;
            PlyVertex {
                p: [f(o), f(o + 4), f(o + 8)],
                b: [f(o + 12), f(o + 16), f(o + 20)],
                rgb: [bytes[o + 24], bytes[o + 25], bytes[o + 26]],
            }
        })
        .collect()
}

/// The display encoding of `radiosity::output::ToneMap::map`, applied to a GLB colour.
fn srgb_byte(x: f32) -> u8 {
    let x = f64::from(x).clamp(0.0, 1.0);
    let srgb = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
    (srgb * 255.0 + 0.5) as u8
}

/// Positions, colours, radiosity and triangle count of the only primitive of a GLB.
struct GlbMesh {
    positions: Vec<[f32; 3]>,
    colors: Vec<[f32; 3]>,
    radiosity: Vec<[f32; 3]>,
    n_indices: usize,
    max_index: u32,
    bounds: ([f32; 3], [f32; 3]),
    unlit: bool,
}

fn read_glb(path: &Path) -> GlbMesh {
    let bytes = std::fs::read(path).expect("solution.glb");
    assert_eq!(&bytes[..4], b"glTF", "GLB magic");
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes")) as usize, bytes.len(), "GLB length field");
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let blob = gltf.blob.clone().expect("binary chunk");
    let mesh = gltf.meshes().next().expect("one mesh");
    let prim = mesh.primitives().next().expect("one primitive");
    assert_eq!(prim.mode(), gltf::mesh::Mode::Triangles);
    let reader = prim.reader(|_| Some(&blob));
    let positions: Vec<[f32; 3]> = reader.read_positions().expect("POSITION").collect();
    let colors: Vec<[f32; 3]> = reader.read_colors(0).expect("COLOR_0").into_rgb_f32().collect();
    let indices: Vec<u32> = reader.read_indices().expect("indices").into_u32().collect();
    let bounds = prim.bounding_box();
    let attr = prim
        .attributes()
        .find(|(s, _)| matches!(s, gltf::Semantic::Extras(name) if format!("_{name}") == GLB_RADIOSITY_ATTRIBUTE))
        .expect("_RADIOSITY attribute")
        .1;
    assert_eq!((attr.data_type(), attr.dimensions()), (gltf::accessor::DataType::F32, gltf::accessor::Dimensions::Vec3));
    let view = attr.view().expect("buffer view");
    let start = view.offset() + attr.offset();
    let radiosity = (0..attr.count())
        .map(|i| {
            std::array::from_fn(|k| {
                f32::from_le_bytes(blob[start + 12 * i + 4 * k..start + 12 * i + 4 * k + 4].try_into().expect("4 bytes"))
            })
        })
        .collect();
    let unlit = prim.material().unlit();
    GlbMesh {
        n_indices: indices.len(),
        max_index: indices.iter().copied().max().unwrap_or(0),
        positions,
        colors,
        radiosity,
        bounds: (bounds.min, bounds.max),
        unlit,
    }
}

#[test]
fn cornell_glb_matches_the_ply() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = cornell_box();
    let solved = pipeline::run(&scene, &BfHand { params: BfParams { eps: COARSE_EPS } }, &Config::default(), &|_| {});
    let config = OutputConfig { image: false, ..OutputConfig::default() };
    output::write_solution(dir.path(), &scene, &solved, &config).expect("outputs");

    let ply = read_ply(&dir.path().join("solution.ply"));
    let glb = read_glb(&dir.path().join("solution.glb"));
    assert!(ply.len() > 100, "a coarse solve still has a few hundred vertices: {}", ply.len());
    assert_eq!(glb.positions.len(), ply.len(), "GLB and PLY vertex counts");
    assert_eq!(glb.colors.len(), ply.len());
    assert_eq!(glb.radiosity.len(), ply.len());
    assert!(glb.unlit, "KHR_materials_unlit material");
    // Triangle fans of triangles and quads: between one and two triangles per three-or-four vertices.
    assert_eq!(glb.n_indices % 3, 0);
    assert!((glb.max_index as usize) < ply.len());
    assert!(glb.n_indices / 3 >= ply.len() / 4 && glb.n_indices / 3 <= ply.len() / 3 * 2, "{} triangles", glb.n_indices / 3);

    let mut n_exact = 0;
    let mut n_lit = 0;
    for (i, v) in ply.iter().enumerate() {
        assert_eq!(glb.positions[i], v.p, "vertex {i} position");
        for k in 0..3 {
            let byte = srgb_byte(glb.colors[i][k]);
            assert!((i32::from(byte) - i32::from(v.rgb[k])).abs() <= BYTE_TOL, "vertex {i} channel {k}: GLB {byte} vs PLY {}", v.rgb[k]);
            n_exact += usize::from(byte == v.rgb[k]);
            let (a, b) = (glb.radiosity[i][k], v.b[k]);
            assert!((a - b).abs() <= RADIOSITY_REL_TOL * b.abs(), "vertex {i} channel {k}: _RADIOSITY {a} vs PLY {b}");
            for (lo, hi) in [(glb.bounds.0[k], v.p[k]), (v.p[k], glb.bounds.1[k])] {
                assert!(lo <= hi, "vertex {i} outside POSITION min/max");
            }
        }
        n_lit += usize::from(v.b.iter().any(|&x| x > 0.0));
    }
    assert!(n_exact * 100 >= 99 * 3 * ply.len(), "colours equal to the PLY's: {n_exact} of {}", 3 * ply.len());
    assert!(n_lit * 2 > ply.len(), "most vertices are lit: {n_lit} of {}", ply.len());
    // The light (Ke 17 12 4) is the brightest: its radiosity is the linear value, not the tone-mapped one.
    let max_r = glb.radiosity.iter().map(|b| b[0]).fold(0.0, f32::max);
    assert!(max_r >= 17.0, "the light's red radiosity is at least its emission: {max_r}");
    assert!(glb.colors.iter().all(|c| c.iter().all(|&x| (0.0..=1.0).contains(&x))), "colours are display values in [0, 1]");

    // Every file at its final name, no temporary file left.
    let mut names: Vec<String> =
        std::fs::read_dir(dir.path()).expect("dir").map(|e| e.expect("entry").file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(names, ["groups.csv", "patches.csv", "solution.glb", "solution.ply"]);
}
