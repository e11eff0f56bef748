//! Procedural poplar-like plants. A tree is made of axes (trunk, branches, twigs); every axis has a
//! kind and an age in years, and all axes of the same kind and age are instances of one prototype
//! (the trunk of age A holds branches of age ≤ A, a branch of age b holds twigs of age ≤ b, twigs
//! hold leaves). A forest shares the branch and twig prototypes between its trees. Everything is
//! seeded: the same parameters give the same scene, bit for bit.

use super::model::{Instance, InstancedScene, LocalPolygon, Prototype, PrototypeId, Transform};
use crate::geom::{DVec3, Poly};
use crate::scene::Material;
use crate::visibility::Rng;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::path::PathBuf;

/// Kind of an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AxisKind {
    /// The main stem.
    Trunk,
    /// A first-order lateral.
    Branch,
    /// A leaf-bearing shoot.
    Twig,
}

impl AxisKind {
    /// Lower-case name used in prototype names (`branch_a7`).
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            AxisKind::Trunk => "trunk",
            AxisKind::Branch => "branch",
            AxisKind::Twig => "twig",
        }
    }
}

/// Shape of the generated trees. The defaults give a columnar tree of about 20 m at 30 years.
#[derive(Clone, Copy, Debug)]
pub struct TreeParams {
    /// Trunk length grown per year, metres.
    pub trunk_internode: f64,
    /// Trunk radius at the base per year of age, metres.
    pub trunk_radius_per_year: f64,
    /// Oldest branch age (older laterals are shed and replaced).
    pub max_branch_age: u32,
    /// Oldest twig age.
    pub max_twig_age: u32,
    /// Branches per trunk node.
    pub branches_per_node: u32,
    /// Twigs per branch node.
    pub twigs_per_node: u32,
    /// Leaves per twig node.
    pub leaves_per_node: u32,
    /// Fraction of the trunk's nodes, from the base, that carry no branch (self-pruned).
    pub bare_fraction: f64,
    /// Branch insertion angle from the trunk, degrees (poplars are columnar: small).
    pub branch_angle_deg: f64,
    /// Sides of the trunk's prism.
    pub trunk_sides: u32,
}

impl Default for TreeParams {
    fn default() -> Self {
        TreeParams {
            trunk_internode: 0.66,
            trunk_radius_per_year: 0.011,
            max_branch_age: 14,
            max_twig_age: 3,
            branches_per_node: 4,
            twigs_per_node: 4,
            leaves_per_node: 8,
            bare_fraction: 0.25,
            branch_angle_deg: 30.0,
            trunk_sides: 8,
        }
    }
}

/// Names of the materials of generated plants.
pub const BARK: &str = "bark";
/// Leaf material (two-sided, transmitting).
pub const LEAF: &str = "leaf";
/// Ground material.
pub const GROUND: &str = "ground";
/// Light source material.
pub const LIGHT: &str = "light";

/// Emitted radiosity of the generated light sources, W/m².
pub const LIGHT_EMISSION: f64 = 10.0;
/// Number of light sources above a generated tree or forest.
pub const N_LIGHTS: usize = 3;

/// Builds plant prototypes on demand, one per (kind, age), into a scene.
pub struct PlantLibrary {
    scene: InstancedScene,
    params: TreeParams,
    seed: u64,
    by_key: HashMap<(AxisKind, u32), PrototypeId>,
}

impl PlantLibrary {
    /// An empty library (materials only) with the given shape and seed.
    #[must_use]
    pub fn new(name: &str, params: TreeParams, seed: u64) -> PlantLibrary {
        let mut leaf = Material::diffuse(LEAF, [0.18, 0.38, 0.12]);
        leaf.transmittance = [0.12, 0.30, 0.08];
        leaf.two_sided = true;
        let mut light = Material::diffuse(LIGHT, [0.0; 3]);
        light.emission = [LIGHT_EMISSION; 3];
        let scene = InstancedScene {
            name: name.to_owned(),
            path: PathBuf::from(format!("{name} (generated)")),
            materials: vec![Material::diffuse(BARK, [0.32, 0.27, 0.22]), leaf, Material::diffuse(GROUND, [0.25, 0.22, 0.18]), light],
            prototypes: Vec::new(),
            root: 0,
            grids: Vec::new(),
        };
        PlantLibrary { scene, params, seed, by_key: HashMap::new() }
    }

    fn material(&self, name: &str) -> u32 {
        self.scene.find_material(name).expect("plant materials are created by `new`")
    }

    /// The prototype of an axis of `kind` and `age` (≥ 1), created with its sub-axes if needed.
    pub fn axis(&mut self, kind: AxisKind, age: u32) -> PrototypeId {
        let age = age.max(1);
        if let Some(&id) = self.by_key.get(&(kind, age)) {
            return id;
        }
        let p = self.params;
        let mut rng = Rng::for_link(self.seed, kind as u32 + 1, age);
        let mut proto = Prototype { name: format!("{}_a{age}", kind.as_str()), ..Prototype::default() };
        let bark = self.material(BARK);
        match kind {
            AxisKind::Twig => {
                let len = 0.05;
                prism(&mut proto.polygons, bark, 3, age, len, 0.002, 0.001);
                let leaf = self.material(LEAF);
                for j in 0..age {
                    for k in 0..p.leaves_per_node {
                        let phi = 2.0 * PI * (k as f64 + 0.5 * (j % 2) as f64) / p.leaves_per_node as f64 + 0.3 * (rng.next_f64() - 0.5);
                        let tilt = (20.0 + 25.0 * rng.next_f64()).to_radians();
                        let scale = 0.85 + 0.3 * rng.next_f64();
                        let z = (j as f64 + 0.6) * len;
                        proto.polygons.push(LocalPolygon { poly: leaf_quad(z, phi, tilt, scale), material: leaf });
                    }
                }
            }
            AxisKind::Branch => {
                let len = 0.3;
                prism(&mut proto.polygons, bark, 4, age, len, 0.004 + 0.002 * age as f64, 0.003);
                for j in 0..age {
                    let child = self.axis(AxisKind::Twig, (age - j).min(p.max_twig_age));
                    for k in 0..p.twigs_per_node {
                        let phi = 137.5f64.to_radians() * (j * p.twigs_per_node + k) as f64 + 0.4 * (rng.next_f64() - 0.5);
                        let tilt = (45.0 + 20.0 * rng.next_f64()).to_radians();
                        let z = (j as f64 + (k as f64 + 0.5) / p.twigs_per_node as f64) * len;
                        proto.instances.push(Instance {
                            prototype: child,
                            transform: placement(z, phi, tilt, 0.9 + 0.2 * rng.next_f64()),
                            line: 0,
                        });
                    }
                }
            }
            AxisKind::Trunk => {
                let len = p.trunk_internode;
                let r0 = p.trunk_radius_per_year * age as f64;
                prism(&mut proto.polygons, bark, p.trunk_sides.max(3), age, len, r0, 0.02);
                let first = (p.bare_fraction * age as f64).ceil() as u32;
                for j in first..age {
                    let child = self.axis(AxisKind::Branch, (age - j).min(p.max_branch_age));
                    for k in 0..p.branches_per_node {
                        let phi = 77f64.to_radians() * (j * p.branches_per_node + k) as f64 + 0.3 * (rng.next_f64() - 0.5);
                        let tilt = (p.branch_angle_deg + 8.0 * (rng.next_f64() - 0.5)).to_radians();
                        let z = (j as f64 + (k as f64 + 0.5) / p.branches_per_node as f64) * len;
                        proto.instances.push(Instance {
                            prototype: child,
                            transform: placement(z, phi, tilt, 0.9 + 0.2 * rng.next_f64()),
                            line: 0,
                        });
                    }
                }
            }
        }
        let id = self.scene.prototypes.len() as PrototypeId;
        self.scene.prototypes.push(proto);
        let _ = self.by_key.insert((kind, age), id);
        id
    }

    /// Finishes the scene with `root` as its root prototype.
    #[must_use]
    pub fn finish(mut self, root: Prototype) -> InstancedScene {
        self.scene.root = self.scene.prototypes.len() as PrototypeId;
        self.scene.prototypes.push(root);
        self.scene
    }

    /// A root prototype named `scene`: a ground square of half-size `half` at z = 0, [`N_LIGHTS`]
    /// emitters facing down at height `top`, and the given instances.
    #[must_use]
    pub fn stage(&self, half: f64, top: f64, instances: Vec<Instance>) -> Prototype {
        let g = self.material(GROUND);
        let l = self.material(LIGHT);
        let mut polygons = vec![LocalPolygon {
            poly: Poly::quad(
                DVec3::new(-half, -half, 0.0),
                DVec3::new(half, -half, 0.0),
                DVec3::new(half, half, 0.0),
                DVec3::new(-half, half, 0.0),
            ),
            material: g,
        }];
        let s = 0.15 * top.max(half);
        for k in 0..N_LIGHTS {
            let a = 2.0 * PI * k as f64 / N_LIGHTS as f64;
            let c = DVec3::new(0.6 * half * a.cos(), 0.6 * half * a.sin(), top);
            // CCW about -z: the light faces down.
            let poly =
                Poly::quad(c + DVec3::new(-s, -s, 0.0), c + DVec3::new(-s, s, 0.0), c + DVec3::new(s, s, 0.0), c + DVec3::new(s, -s, 0.0));
            polygons.push(LocalPolygon { poly, material: l });
        }
        Prototype { name: "scene".into(), polygons, instances, ..Prototype::default() }
    }
}

/// Places a child axis at height `z` on its parent (along +z), turned by `phi` about the parent's
/// axis and tilted by `tilt` away from it, scaled by `scale`.
fn placement(z: f64, phi: f64, tilt: f64, scale: f64) -> Transform {
    Transform {
        matrix: glam::DMat4::from_translation(DVec3::new(0.0, 0.0, z))
            * glam::DMat4::from_rotation_z(phi)
            * glam::DMat4::from_rotation_y(tilt)
            * glam::DMat4::from_scale(DVec3::splat(scale)),
    }
}

/// A rhombic leaf of 6 × 4 cm (times `scale`) on a petiole at height `z`, pointing out along
/// azimuth `phi`, raised by `tilt`.
fn leaf_quad(z: f64, phi: f64, tilt: f64, scale: f64) -> Poly {
    let (l, w) = (0.06 * scale, 0.04 * scale);
    let t =
        glam::DMat4::from_translation(DVec3::new(0.0, 0.0, z)) * glam::DMat4::from_rotation_z(phi) * glam::DMat4::from_rotation_y(-tilt);
    let p = |x: f64, y: f64| t.transform_point3(DVec3::new(x + 0.004, y, 0.0));
    Poly::quad(p(0.0, 0.0), p(0.5 * l, -0.5 * w), p(l, 0.0), p(0.5 * l, 0.5 * w))
}

/// Bark of an axis along +z: `n_seg` segments of length `len`, `sides` outward quads each, radius
/// tapering linearly from `r0` to `r1`.
fn prism(out: &mut Vec<LocalPolygon>, material: u32, sides: u32, n_seg: u32, len: f64, r0: f64, r1: f64) {
    let ring = |i: u32, k: u32| {
        let r = r0 + (r1 - r0) * i as f64 / n_seg as f64;
        let a = 2.0 * PI * k as f64 / sides as f64;
        DVec3::new(r * a.cos(), r * a.sin(), i as f64 * len)
    };
    for i in 0..n_seg {
        for k in 0..sides {
            let poly = Poly::quad(ring(i, k), ring(i, k + 1), ring(i + 1, k + 1), ring(i + 1, k));
            out.push(LocalPolygon { poly, material });
        }
    }
}

/// A poplar-like tree of `age` years (≥ 1) on a ground square with three lights, from `seed`.
#[must_use]
pub fn generate_tree(age: u32, seed: u64) -> InstancedScene {
    generate_tree_with(age, seed, &TreeParams::default())
}

/// [`generate_tree`] with explicit shape parameters.
#[must_use]
pub fn generate_tree_with(age: u32, seed: u64, params: &TreeParams) -> InstancedScene {
    let age = age.max(1);
    let mut lib = PlantLibrary::new(&format!("tree-a{age}-s{seed}"), *params, seed);
    let trunk = lib.axis(AxisKind::Trunk, age);
    let height = params.trunk_internode * age as f64;
    let root =
        lib.stage(0.5 * height.max(2.0), 1.5 * height + 1.0, vec![Instance { prototype: trunk, transform: Transform::IDENTITY, line: 0 }]);
    lib.finish(root)
}

/// Parameters of [`generate_forest`].
#[derive(Clone, Copy, Debug)]
pub struct ForestParams {
    /// Number of trees (placed on a square grid, row by row).
    pub trees: u32,
    /// Grid spacing, metres.
    pub spacing: f64,
    /// Youngest tree, years.
    pub min_age: u32,
    /// Oldest tree, years.
    pub max_age: u32,
    /// Seed.
    pub seed: u64,
    /// Tree shape.
    pub tree: TreeParams,
}

impl Default for ForestParams {
    fn default() -> Self {
        ForestParams { trees: 64, spacing: 8.0, min_age: 20, max_age: 30, seed: 1, tree: TreeParams::default() }
    }
}

/// A forest: trees of random age on a grid, randomly turned and scaled, sharing their branch and
/// twig prototypes; one ground square and three lights.
#[must_use]
pub fn generate_forest(params: &ForestParams) -> InstancedScene {
    let n = params.trees.max(1);
    let side = (n as f64).sqrt().ceil() as u32;
    let mut lib = PlantLibrary::new(&format!("forest-{n}-s{}", params.seed), params.tree, params.seed);
    let mut rng = Rng::for_link(params.seed, 0xF0, n);
    let (lo, hi) = (params.min_age.max(1), params.max_age.max(params.min_age.max(1)));
    let mut instances = Vec::with_capacity(n as usize);
    let mut oldest = lo;
    for i in 0..n {
        let age = lo + (rng.next_u64() % u64::from(hi - lo + 1)) as u32;
        oldest = oldest.max(age);
        let trunk = lib.axis(AxisKind::Trunk, age);
        let (gx, gy) = ((i % side) as f64, (i / side) as f64);
        let off = 0.5 * (side as f64 - 1.0);
        let pos = DVec3::new((gx - off) * params.spacing, (gy - off) * params.spacing, 0.0);
        let t = Transform::from_trs(pos, DVec3::new(0.0, 0.0, 360.0 * rng.next_f64()), DVec3::splat(0.9 + 0.2 * rng.next_f64()));
        instances.push(Instance { prototype: trunk, transform: t, line: 0 });
    }
    let half = 0.5 * side as f64 * params.spacing;
    let top = 1.5 * params.tree.trunk_internode * oldest as f64 + 1.0;
    let root = lib.stage(half, top, instances);
    lib.finish(root)
}

/// Splits every quad of material `material` among the own polygons of prototype `id` into tiles
/// at most `size` a side (bilinearly, so a parallelogram gives equal parallelograms), in place of
/// the quad. For a scene under the sun and sky: the instanced solve lights each top-level polygon
/// by its mean over its points, uniformly inside it, so a ground in one piece would be as bright
/// under the trees as in the open. Returns how many tiles replaced how many quads.
pub fn tile_quads(scene: &mut InstancedScene, id: PrototypeId, material: u32, size: f64) -> (usize, usize) {
    let Some(p) = scene.prototypes.get_mut(id as usize) else { return (0, 0) };
    if !(size > 0.0 && size.is_finite()) {
        return (0, 0);
    }
    let (mut tiles, mut quads) = (0, 0);
    let mut out = Vec::with_capacity(p.polygons.len());
    for q in p.polygons.drain(..) {
        let v = q.poly.vertices();
        if q.material != material || v.len() != 4 {
            out.push(q);
            continue;
        }
        let (a, b, c, d) = (v[0], v[1], v[2], v[3]);
        let nu = (((b - a).length().max((c - d).length())) / size).ceil().max(1.0) as usize;
        let nv = (((d - a).length().max((c - b).length())) / size).ceil().max(1.0) as usize;
        let at = |i: usize, j: usize| {
            let (u, w) = (i as f64 / nu as f64, j as f64 / nv as f64);
            a * ((1.0 - u) * (1.0 - w)) + b * (u * (1.0 - w)) + c * (u * w) + d * ((1.0 - u) * w)
        };
        for j in 0..nv {
            for i in 0..nu {
                out.push(LocalPolygon { poly: Poly::quad(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)), material });
            }
        }
        tiles += nu * nv;
        quads += 1;
    }
    p.polygons = out;
    (tiles, quads)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 1 ground in tiles of at most 0.5: 4 × 2 tiles of 0.25, covering it exactly, facing
    /// the same way; other materials untouched.
    #[test]
    fn tile_quads_covers_the_ground_exactly() {
        let mut scene = generate_tree(1, 1);
        let g = scene.materials.iter().position(|m| m.name == GROUND).unwrap() as u32;
        let root = scene.root;
        let ground = Poly::quad(DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::new(2.0, 1.0, 0.0), DVec3::new(0.0, 1.0, 0.0));
        let p = &mut scene.prototypes[root as usize];
        p.polygons.retain(|q| q.material != g);
        let others = p.polygons.len();
        p.polygons.push(LocalPolygon { poly: ground, material: g });
        assert_eq!(tile_quads(&mut scene, root, g, 0.5), (8, 1));
        let p = &scene.prototypes[root as usize];
        let tiles: Vec<&LocalPolygon> = p.polygons.iter().filter(|q| q.material == g).collect();
        assert_eq!((tiles.len(), p.polygons.len()), (8, others + 8));
        let area: f64 = tiles.iter().map(|q| q.poly.area()).sum();
        assert!((area - 2.0).abs() < 1e-12, "{area}");
        for q in tiles {
            assert!((q.poly.area() - 0.25).abs() < 1e-12 && q.poly.normal().dot(ground.normal()) > 0.999_999);
        }
    }

    #[test]
    fn thirty_year_tree_has_the_intended_size_and_is_deterministic() {
        let t = generate_tree(30, 7);
        t.validate().unwrap();
        let counts = t.flattened_counts(false);
        let n = counts[t.root as usize];
        assert!((100_000..=150_000).contains(&n), "30-year tree has {n} polygons");
        let again = generate_tree(30, 7);
        assert_eq!(format!("{:?}", t.prototypes), format!("{:?}", again.prototypes), "same seed, same tree");
        let other = generate_tree(30, 8);
        assert_ne!(format!("{:?}", t.prototypes), format!("{:?}", other.prototypes), "seed changes the tree");
        // Same kind and age, same prototype: one prototype per (kind, age).
        let mut names: Vec<&str> = t.prototypes.iter().map(|p| p.name.as_str()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), t.prototypes.len());
    }
}
