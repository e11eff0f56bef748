//! Automatic instancing of plain scenes (issue 5, "automatic instancing of plain OBJ scenes"): a room
//! with 24 copies of an asymmetric chair at random rigid placements (rotations about arbitrary
//! axes), plus a chair with one leg 1% longer and a mirrored chair. The copies become one prototype,
//! the near-copy and the mirror image stay plain, flattening gives the input back, and the instanced
//! solve agrees with the plain one within the bound used for the eight instanced cubes.

use glam::{DMat3, DVec3};
use radiosity_core::geom::Poly;
use radiosity_core::instancing::auto::flattened_polygons;
use radiosity_core::instancing::properties::PropertyConfig;
use radiosity_core::instancing::solver::relative_error;
use radiosity_core::instancing::{
    self, AutoOptions, InstancedConfig, InstancedScene, LocalPolygon, PolygonMeans, Prototype, auto_instance, solve_full, solve_instanced,
};
use radiosity_core::scene::{Material, Polygon, Scene};
use std::process::Command;
use std::time::Instant;

/// Exact copies (rotations in f64) must flatten back to their input to rounding: metres.
const FLATTEN_TOL: f64 = 1e-9;
/// A rigid transform's linear part is orthonormal with determinant +1 to rounding.
const ROTATION_TOL: f64 = 1e-9;
/// Same bounds as `tests/instancing_solve.rs` for the eight instanced cubes: area-weighted mean and
/// largest error per polygon, relative to the largest radiosity of the plain solve.
const MEAN_TOL: f64 = 0.02;
const MAX_TOL: f64 = 0.10;
/// Chairs in the room.
const N_CHAIRS: usize = 24;
/// Faces of a chair: 7 boxes of 6 quads.
const CHAIR_POLYGONS: usize = 42;

const WALL: u32 = 0;
const WOOD: u32 = 1;
const LIGHT: u32 = 2;

/// Small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A rotation about a random axis by a random angle.
    fn rotation(&mut self) -> DMat3 {
        let axis = loop {
            let v = DVec3::new(self.next(), self.next(), self.next()) * 2.0 - DVec3::ONE;
            if let Some(a) = v.try_normalize() {
                break a;
            }
        };
        DMat3::from_axis_angle(axis, std::f64::consts::TAU * self.next())
    }
}

/// The six faces of a box, front sides out (`inward` turns them in).
fn box_faces(min: DVec3, max: DVec3, inward: bool) -> Vec<Poly> {
    let c = |x: usize, y: usize, z: usize| DVec3::new([min.x, max.x][x], [min.y, max.y][y], [min.z, max.z][z]);
    let faces = [
        [c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)],
        [c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)],
        [c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)],
        [c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)],
        [c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)],
        [c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)],
    ];
    faces.iter().map(|f| if inward { Poly::quad(f[3], f[2], f[1], f[0]) } else { Poly::quad(f[0], f[1], f[2], f[3]) }).collect()
}

#[derive(Clone, Copy, PartialEq)]
enum ChairKind {
    Normal,
    /// One leg 1% longer (it reaches 1% of its length below the floor of the others).
    LongLeg,
    /// The chair mirrored in x (vertex order reversed so the front sides stay out).
    Mirrored,
}

/// A chair in its own frame: seat, back, four legs and one armrest on the −x side (so the chair
/// has no mirror symmetry and its mirror image is a different object).
fn chair(kind: ChairKind) -> Vec<Poly> {
    let b = |min: [f64; 3], max: [f64; 3]| box_faces(DVec3::from(min), DVec3::from(max), false);
    let leg_bottom = if kind == ChairKind::LongLeg { -0.0045 } else { 0.0 };
    let mut faces = Vec::new();
    faces.extend(b([-0.25, -0.25, 0.45], [0.25, 0.25, 0.5]));
    faces.extend(b([-0.25, 0.2, 0.5], [0.25, 0.25, 1.0]));
    faces.extend(b([-0.25, -0.25, leg_bottom], [-0.2, -0.2, 0.45]));
    faces.extend(b([0.2, -0.25, 0.0], [0.25, -0.2, 0.45]));
    faces.extend(b([-0.25, 0.2, 0.0], [-0.2, 0.25, 0.45]));
    faces.extend(b([0.2, 0.2, 0.0], [0.25, 0.25, 0.45]));
    faces.extend(b([-0.25, -0.2, 0.7], [-0.2, 0.2, 0.75]));
    if kind == ChairKind::Mirrored {
        let m = |v: DVec3| DVec3::new(-v.x, v.y, v.z);
        faces = faces.iter().map(|p| Poly::quad(m(p.v[3]), m(p.v[2]), m(p.v[1]), m(p.v[0]))).collect();
    }
    faces
}

/// Rigidly moves `faces` (about the chair's middle), then shuffles the polygon order and rotates
/// the vertex lists, as another exporter might.
fn placed(faces: &[Poly], rot: DMat3, at: DVec3, rng: &mut Rng) -> Vec<Poly> {
    let mid = DVec3::new(0.0, 0.0, 0.5);
    let mut out: Vec<Poly> = faces
        .iter()
        .map(|p| {
            let v: Vec<DVec3> = p.vertices().iter().map(|&x| rot * (x - mid) + at).collect();
            let s = (rng.next() * 4.0) as usize % 4;
            Poly::quad(v[s], v[(s + 1) % 4], v[(s + 2) % 4], v[(s + 3) % 4])
        })
        .collect();
    for i in (1..out.len()).rev() {
        let j = (rng.next() * (i + 1) as f64) as usize % (i + 1);
        out.swap(i, j);
    }
    out
}

struct SceneParts {
    scene: Scene,
    /// Input polygon ranges of the near-copy and the mirrored chair (when present).
    odd: Vec<std::ops::Range<usize>>,
}

/// The room (8.25 × 5.55 × 3.2 m, walls inward), a ceiling light, `n` chairs on a grid at random
/// orientations, then the listed odd chairs above them.
fn room_with_chairs(n: usize, odd: &[ChairKind], seed: u64) -> SceneParts {
    let mut rng = Rng(seed);
    let mut polygons = Vec::new();
    let mut groups = vec!["room".to_string(), "light".to_string()];
    let add = |polygons: &mut Vec<Polygon>, faces: &[Poly], material: u32, group: u32| {
        polygons.extend(faces.iter().map(|&poly| Polygon { poly, material, group }));
    };
    add(&mut polygons, &box_faces(DVec3::ZERO, DVec3::new(8.25, 5.55, 3.2), true), WALL, 0);
    let light = Poly::quad(DVec3::new(3.6, 2.3, 3.19), DVec3::new(4.6, 2.3, 3.19), DVec3::new(4.6, 3.3, 3.19), DVec3::new(3.6, 3.3, 3.19));
    add(&mut polygons, &[Poly::quad(light.v[3], light.v[2], light.v[1], light.v[0])], LIGHT, 1);
    let normal = chair(ChairKind::Normal);
    for k in 0..n {
        let at = DVec3::new(0.75 + 1.35 * (k % 6) as f64, 0.75 + 1.35 * (k / 6 % 4) as f64, 0.9);
        let rot = rng.rotation();
        groups.push(format!("chair{k}"));
        add(&mut polygons, &placed(&normal, rot, at, &mut rng), WOOD, groups.len() as u32 - 1);
    }
    let mut ranges = Vec::new();
    for (k, &kind) in odd.iter().enumerate() {
        let at = DVec3::new(1.5 + 2.5 * k as f64, 2.7, 2.4);
        let rot = rng.rotation();
        groups.push(format!("odd{k}"));
        let start = polygons.len();
        add(&mut polygons, &placed(&chair(kind), rot, at, &mut rng), WOOD, groups.len() as u32 - 1);
        ranges.push(start..polygons.len());
    }
    let mut lamp = Material::diffuse("light", [0.0; 3]);
    lamp.emission = [10.0; 3];
    let scene = Scene {
        name: "chairs".into(),
        polygons,
        materials: vec![Material::diffuse("wall", [0.5; 3]), Material::diffuse("wood", [0.6, 0.4, 0.2]), lamp],
        groups,
        camera: None,
        warnings: Default::default(),
        luminaires: Vec::new(),
        distant: Vec::new(),
        units: Default::default(),
    };
    SceneParts { scene, odd: ranges }
}

/// Largest vertex distance between two polygons, over the cyclic rotations of `b` (∞ when the
/// vertex counts differ).
fn poly_distance(a: &Poly, b: &Poly) -> f64 {
    let (va, vb) = (a.vertices(), b.vertices());
    if va.len() != vb.len() {
        return f64::INFINITY;
    }
    let n = va.len();
    (0..n).map(|s| (0..n).map(|j| (va[j] - vb[(j + s) % n]).length()).fold(0.0, f64::max)).fold(f64::INFINITY, f64::min)
}

/// Checks that the flattened auto scene is the input: every input polygon exactly once, with its
/// material and its vertices within [`FLATTEN_TOL`].
fn check_flattening_gives_the_input(input: &Scene, result: &instancing::AutoResult) {
    let flat = flattened_polygons(&result.scene);
    assert_eq!(flat.len(), input.polygons.len());
    assert_eq!(result.flat_to_input.len(), flat.len());
    let mut seen = vec![false; input.polygons.len()];
    for (k, (poly, material)) in flat.iter().enumerate() {
        let i = result.flat_to_input[k] as usize;
        assert!(!seen[i], "input polygon {i} flattened twice");
        seen[i] = true;
        assert_eq!(*material, input.polygons[i].material);
        let d = poly_distance(poly, &input.polygons[i].poly);
        assert!(d <= FLATTEN_TOL, "flattened polygon {k} is {d:e} m from input polygon {i}");
    }
    // The flat scene of the library agrees with the order used here.
    let lib = instancing::flatten(&result.scene, &instancing::FlattenOptions { two_sided_pairs: false }).unwrap();
    assert_eq!(lib.polygons.len(), flat.len());
    for (p, (q, _)) in lib.polygons.iter().zip(&flat) {
        assert!(poly_distance(&p.poly, q) <= FLATTEN_TOL);
    }
}

#[test]
fn twenty_four_chairs_become_one_prototype_and_the_odd_ones_stay_plain() {
    let parts = room_with_chairs(N_CHAIRS, &[ChairKind::LongLeg, ChairKind::Mirrored], 7);
    let t0 = Instant::now();
    let result = auto_instance(&parts.scene, &AutoOptions::default());
    eprintln!("{} in {:.4}s", result.report, t0.elapsed().as_secs_f64());
    let r = result.report;
    assert_eq!(r.objects, 2 + N_CHAIRS + 2);
    assert_eq!((r.prototypes, r.instances, r.polygons_instanced), (1, N_CHAIRS, N_CHAIRS * CHAIR_POLYGONS));
    assert_eq!(r.pairs_given_up, 0);
    let scene = &result.scene;
    scene.validate().unwrap();
    let root = scene.prototype(scene.root);
    assert_eq!(root.polygons.len(), 7 + 2 * CHAIR_POLYGONS, "room, light and the two odd chairs stay plain");
    assert_eq!(root.instances.len(), N_CHAIRS);
    // The odd chairs' polygons are root polygons (the first entries of the flattening order).
    let plain: Vec<u32> = result.flat_to_input[..root.polygons.len()].to_vec();
    for range in &parts.odd {
        assert!(range.clone().all(|i| plain.contains(&(i as u32))), "odd chair {range:?} was instanced");
    }
    // Every placement is rigid: orthonormal, no mirror, no scale.
    for inst in &root.instances {
        let l = DMat3::from_mat4(inst.transform.matrix);
        let err = (l.transpose() * l - DMat3::IDENTITY).to_cols_array().iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(err <= ROTATION_TOL, "not orthonormal: {err:e}");
        assert!((l.determinant() - 1.0).abs() <= ROTATION_TOL);
    }
    check_flattening_gives_the_input(&parts.scene, &result);
}

#[test]
fn near_copies_and_mirror_images_are_told_apart() {
    // Two copies of each kind: three prototypes, none merged with another.
    let parts = room_with_chairs(
        0,
        &[ChairKind::Normal, ChairKind::LongLeg, ChairKind::Mirrored, ChairKind::Normal, ChairKind::LongLeg, ChairKind::Mirrored],
        11,
    );
    let result = auto_instance(&parts.scene, &AutoOptions::default());
    assert_eq!((result.report.prototypes, result.report.instances), (3, 6));
    let root = result.scene.prototype(result.scene.root);
    let kinds: Vec<u32> = root.instances.iter().map(|i| i.prototype).collect();
    assert_eq!(kinds[..3], kinds[3..], "each odd chair joins its own twin");
    assert!(kinds[0] != kinds[1] && kinds[1] != kinds[2] && kinds[0] != kinds[2]);
    check_flattening_gives_the_input(&parts.scene, &result);
    // With a tolerance above the 1% leg difference (4.5 mm of a 0.61 m radius), the long leg joins.
    let loose = auto_instance(&parts.scene, &AutoOptions { rel_tol: 0.01, ..AutoOptions::default() });
    assert_eq!(loose.report.prototypes, 2, "the check above is not vacuous: only the tolerance keeps the long leg apart");
}

#[test]
fn a_scene_without_repeats_gives_no_prototype() {
    let parts = room_with_chairs(1, &[ChairKind::LongLeg, ChairKind::Mirrored], 3);
    let result = auto_instance(&parts.scene, &AutoOptions::default());
    assert_eq!((result.report.objects, result.report.prototypes, result.report.instances), (5, 0, 0));
    assert_eq!(result.scene.prototypes.len(), 1);
    assert_eq!(result.flat_to_input, (0..parts.scene.polygons.len() as u32).collect::<Vec<_>>());
    // min_copies: two chairs are not enough when three are asked for.
    let two = room_with_chairs(2, &[], 3);
    assert_eq!(auto_instance(&two.scene, &AutoOptions::default()).report.prototypes, 1);
    assert_eq!(auto_instance(&two.scene, &AutoOptions { min_copies: 3, ..AutoOptions::default() }).report.prototypes, 0);
}

#[test]
fn symmetric_objects_are_matched_in_any_orientation() {
    // Cubes have 24 rotational symmetries: many anchor candidates, every one valid.
    let mut rng = Rng(5);
    let cube = box_faces(DVec3::splat(-0.5), DVec3::splat(0.5), false);
    let mut polygons = Vec::new();
    for k in 0..5u32 {
        let faces = placed(&cube, rng.rotation(), DVec3::new(2.0 * k as f64, 0.0, 0.0), &mut rng);
        polygons.extend(faces.into_iter().map(|poly| Polygon { poly, material: 0, group: k }));
    }
    let scene = Scene {
        name: "cubes".into(),
        polygons,
        materials: vec![Material::diffuse("m", [0.5; 3])],
        groups: (0..5).map(|k| format!("cube{k}")).collect(),
        camera: None,
        warnings: Default::default(),
        luminaires: Vec::new(),
        distant: Vec::new(),
        units: Default::default(),
    };
    let result = auto_instance(&scene, &AutoOptions::default());
    assert_eq!((result.report.prototypes, result.report.instances), (1, 5));
    check_flattening_gives_the_input(&scene, &result);
}

#[test]
fn bad_input_never_panics() {
    let mut parts = room_with_chairs(3, &[], 9);
    let n = parts.scene.polygons.len();
    parts.scene.polygons[n - 1].poly.v[0].x = f64::NAN;
    parts.scene.polygons[n - 1 - CHAIR_POLYGONS].material = 99;
    parts.scene.polygons[0].group = 1000;
    let zero = Poly::triangle(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    parts.scene.polygons.push(Polygon { poly: zero, material: 0, group: 2000 });
    parts.scene.polygons.push(Polygon { poly: zero, material: 0, group: 2001 });
    let result = auto_instance(&parts.scene, &AutoOptions { min_copies: 0, rel_tol: f64::NAN });
    // Only the first chair is intact, so it is its own (single-copy) prototype; the rest stays plain.
    assert_eq!(result.flat_to_input.len(), parts.scene.polygons.len());
    assert!(result.report.instances >= 1);
    let empty = Scene { polygons: Vec::new(), ..parts.scene };
    let result = auto_instance(&empty, &AutoOptions::default());
    assert_eq!(result.report.objects, 0);
    assert!(result.scene.validate().is_ok());
}

fn solver_config() -> InstancedConfig {
    InstancedConfig {
        properties: PropertyConfig { n_directions: 16, rays_per_direction: 400, ..PropertyConfig::default() },
        ..InstancedConfig::default()
    }
}

#[test]
fn instanced_solve_of_the_chairs_matches_the_plain_solve() {
    let parts = room_with_chairs(N_CHAIRS, &[ChairKind::LongLeg, ChairKind::Mirrored], 7);
    let input = &parts.scene;
    let auto = auto_instance(input, &AutoOptions::default());
    let config = solver_config();
    // The plain pipeline on the input, polygons in input order (a scene of root polygons only).
    let plain_scene = InstancedScene {
        name: input.name.clone(),
        materials: input.materials.clone(),
        prototypes: vec![Prototype {
            name: "plain".into(),
            polygons: input.polygons.iter().map(|p| LocalPolygon { poly: p.poly, material: p.material }).collect(),
            ..Prototype::default()
        }],
        ..InstancedScene::default()
    };
    let t0 = Instant::now();
    let (plain, _) = solve_full(&plain_scene, &config).unwrap();
    let t_plain = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let mut flat = PolygonMeans::default();
    let stats = solve_instanced(&auto.scene, &config, &mut flat).unwrap();
    let t_inst = t0.elapsed().as_secs_f64();
    assert_eq!(stats.polygons_out as usize, input.polygons.len());
    // Back to input order.
    let mut inst = PolygonMeans { radiosity: vec![[0.0; 3]; input.polygons.len()], area: vec![0.0; input.polygons.len()] };
    for (k, &i) in auto.flat_to_input.iter().enumerate() {
        inst.radiosity[i as usize] = flat.radiosity[k];
        inst.area[i as usize] = flat.area[k];
    }
    let (worst, mean) = relative_error(&plain, &inst);
    eprintln!(
        "24 chairs: plain {t_plain:.2}s, instanced {t_inst:.2}s ({} local solves); max error {:.3}%, mean error {:.3}% of max radiosity",
        stats.local_solves,
        100.0 * worst,
        100.0 * mean
    );
    assert!(mean <= MEAN_TOL, "mean error {mean}");
    assert!(worst <= MAX_TOL, "max error {worst}");
}

#[test]
fn cli_solves_an_obj_with_automatic_instances() {
    let dir = tempfile::tempdir().unwrap();
    let parts = room_with_chairs(3, &[ChairKind::Mirrored], 13);
    let mut obj = String::from("mtllib chairs.mtl\n");
    let mut n_vertices = 0;
    let mut group = u32::MAX;
    for p in &parts.scene.polygons {
        if p.group != group {
            group = p.group;
            obj.push_str(&format!(
                "o {}\nusemtl {}\n",
                parts.scene.groups[group as usize], parts.scene.materials[p.material as usize].name
            ));
        }
        for v in p.poly.vertices() {
            obj.push_str(&format!("v {:.9} {:.9} {:.9}\n", v.x, v.y, v.z));
        }
        let idx: Vec<String> = (1..=p.poly.n_vertices()).map(|k| (n_vertices + k).to_string()).collect();
        n_vertices += p.poly.n_vertices();
        obj.push_str(&format!("f {}\n", idx.join(" ")));
    }
    std::fs::write(dir.path().join("chairs.obj"), obj).unwrap();
    std::fs::write(
        dir.path().join("chairs.mtl"),
        "newmtl wall\nKd 0.5 0.5 0.5\nnewmtl wood\nKd 0.6 0.4 0.2\nnewmtl light\nKd 0 0 0\nKe 10 10 10\n",
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", "chairs.obj", "--instances", "auto", "--out", "out", "--size", "32", "--eps", "0.05"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    // Coordinates rounded to 9 decimals still match within the tolerance (with 6, the loader
    // triangulates small quads whose rounding exceeds its planarity tolerance, and copies differ).
    assert!(stdout.contains("1 prototypes, 3 instances"), "{stdout}");
    let csv = std::fs::read_to_string(dir.path().join("out/patches.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + parts.scene.polygons.len());
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/stats.json")).unwrap()).unwrap();
    assert_eq!(stats["auto_instancing"]["instances"], 3);
}
