//! Automatic instancing of a plain [`Scene`]: objects (the polygons of one OBJ object / group,
//! [`Polygon::group`](crate::scene::Polygon::group)) that are identical up to a rigid transform become instances of one
//! prototype.
//!
//! # Method
//! 1. **Signature.** Every object gets a discrete signature (polygon count, the sorted list of
//!    `(material, vertex count)` pairs); objects are only compared inside a bucket of equal
//!    signatures (a `BTreeMap`, so the order never depends on hashing). Continuous rotation
//!    invariants (radius about the area-weighted centroid, total area, trace and Frobenius norm of
//!    the area-weighted vertex covariance) are compared within a loose tolerance as a cheap filter.
//!    They only prune; they never decide a match.
//! 2. **Candidate transforms from anchor vertices.** Object B's frame is fixed by its centroid `c`,
//!    its vertex `p1` farthest from `c` and its vertex `p2` farthest from the line `c p1`. Every pair
//!    `(q1, q2)` of the representative A's vertices with the same distances (to `c`, and to each
//!    other) within tolerance gives one candidate rotation `R = F_B · F_Aᵀ`, right-handed by
//!    construction (`n = u × v`), so a mirror image is never a candidate.
//!
//!    Principal axes of the covariance (the suggestion) were not chosen: a chair has a
//!    mirror plane and a box has equal eigenvalues, and for near-equal eigenvalues an eigenvector's
//!    error is the vertex noise divided by the spectral gap, so no vertex tolerance follows from it.
//!    Anchor frames are as accurate as the anchor vertices themselves, whatever the symmetry; a
//!    symmetric object only yields more candidates (at most [`MAX_FRAME_CANDIDATES`] are tried).
//! 3. **Verification.** A candidate is accepted only if it maps every polygon of A onto a distinct
//!    polygon of B with the same material and vertex count, vertex for vertex (any cyclic rotation
//!    of the vertex list, same orientation) within [`MATCH_REL_TOL`] of the larger object radius.
//!    Polygon order within an object may differ. Nothing else decides a match, so a false match
//!    needs every vertex to agree within the tolerance.
//!
//! Objects are visited in order of their first polygon; each is compared with the representatives
//! (first members) of the classes found so far in its bucket, in order, and joins the first that
//! matches. Classes with at least [`AutoOptions::min_copies`] members become prototypes whose local
//! frame is the representative's, centred on its centroid. The output is deterministic.
//!
//! # Layout
//! This file holds the settings, the report and [`auto_instance`] (classes to prototypes and
//! instances); `objects` the objects of the input and the figures they are compared by (step 1),
//! `matching` the candidate transforms and their verification (steps 2 and 3).

mod matching;
mod objects;

use super::flatten::{FlattenOptions, for_each_polygon};
use super::model::{Instance, InstancedScene, LocalPolygon, Prototype, PrototypeId, Transform};
use crate::geom::Poly;
use crate::scene::Scene;
use glam::{DMat3, DMat4};
use matching::{Match, find_rigid_match};
use objects::collect_objects;
use std::collections::BTreeMap;

/// Largest distance between a vertex mapped by the candidate transform and its match, relative to
/// the larger object's radius (largest vertex distance from its centroid). 1e-4 accepts coordinates
/// written with 6 significant digits and rejects a chair leg 1% longer by two orders of magnitude.
pub const MATCH_REL_TOL: f64 = 1e-4;
/// The invariant filter's tolerance, as a multiple of the match tolerance (loose: it only prunes).
pub const FILTER_TOL_FACTOR: f64 = 64.0;
/// Candidate transforms tried per pair of objects before giving up on the pair (no match).
pub const MAX_FRAME_CANDIDATES: usize = 256;

/// Settings of [`auto_instance`].
#[derive(Clone, Copy, Debug)]
pub struct AutoOptions {
    /// Objects that occur fewer times than this stay plain polygons (values below 1 count as 1).
    pub min_copies: usize,
    /// Vertex match tolerance relative to the object radius.
    pub rel_tol: f64,
}

impl Default for AutoOptions {
    fn default() -> Self {
        AutoOptions { min_copies: 2, rel_tol: MATCH_REL_TOL }
    }
}

/// What [`auto_instance`] found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct AutoReport {
    /// Objects (non-empty groups) examined.
    pub objects: usize,
    /// Prototypes created (repeated object shapes).
    pub prototypes: usize,
    /// Instances placed (every copy, the first one included).
    pub instances: usize,
    /// Input polygons that are now part of an instance.
    pub polygons_instanced: usize,
    /// Input polygons in all.
    pub polygons: usize,
    /// Pairs of objects given up on after [`MAX_FRAME_CANDIDATES`] candidates (treated as different).
    pub pairs_given_up: usize,
}

impl std::fmt::Display for AutoReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "auto-instancing: {} objects examined, {} prototypes, {} instances, {} of {} polygons instanced",
            self.objects, self.prototypes, self.instances, self.polygons_instanced, self.polygons
        )?;
        if self.pairs_given_up > 0 {
            write!(f, " ({} object pairs too symmetric to compare, kept apart)", self.pairs_given_up)?;
        }
        Ok(())
    }
}

/// The instanced scene and how it relates to the input.
#[derive(Clone, Debug)]
pub struct AutoResult {
    /// Root prototype (un-instanced polygons in input order, then the instances in order of their
    /// objects' first polygon) and one prototype per repeated shape.
    pub scene: InstancedScene,
    /// Counts.
    pub report: AutoReport,
    /// Input polygon index of every polygon of [`crate::instancing::flatten()`]'s output without
    /// two-sided pairs (`FlattenOptions { two_sided_pairs: false }`), in flattening order.
    pub flat_to_input: Vec<u32>,
}

/// Finds objects of `scene` that are identical up to a rigid transform and instances them (see the
/// module docs). Never fails: an object that cannot be compared (bad indices, non-finite
/// coordinates) stays plain polygons.
#[must_use]
pub fn auto_instance(scene: &Scene, options: &AutoOptions) -> AutoResult {
    let rel_tol = if options.rel_tol.is_finite() && options.rel_tol > 0.0 { options.rel_tol } else { MATCH_REL_TOL };
    let objects = collect_objects(scene);
    let mut report = AutoReport { objects: objects.len(), polygons: scene.polygons.len(), ..AutoReport::default() };

    // Classes: representative object index, members with the map (rep polygon k → input polygon).
    struct Class {
        rep: usize,
        members: Vec<(usize, DMat3, Vec<u32>)>,
    }
    let mut classes: Vec<Class> = Vec::new();
    let mut buckets: BTreeMap<Vec<(u32, u8)>, Vec<usize>> = BTreeMap::new();
    for (o_idx, o) in objects.iter().enumerate() {
        let Some(shape) = &o.shape else { continue };
        let bucket = buckets.entry(shape.signature.clone()).or_default();
        let mut joined = false;
        for &class_idx in bucket.iter() {
            let rep = &objects[classes[class_idx].rep];
            let Some(rep_shape) = &rep.shape else { continue };
            match find_rigid_match(scene, rep, rep_shape, o, shape, rel_tol) {
                Match::Found(r, map) => {
                    classes[class_idx].members.push((o_idx, r, map));
                    joined = true;
                    break;
                }
                Match::GaveUp => report.pairs_given_up += 1,
                Match::Different => {}
            }
        }
        if !joined {
            bucket.push(classes.len());
            let identity = o.polygons.clone();
            classes.push(Class { rep: o_idx, members: vec![(o_idx, DMat3::IDENTITY, identity)] });
        }
    }

    // Classes in order of their representative's first polygon (objects are already in that order).
    let min_copies = options.min_copies.max(1);
    let mut instanced = vec![false; scene.polygons.len()];
    let mut prototypes = vec![Prototype::default()];
    let mut root_instances: Vec<(u32, Instance, Vec<u32>)> = Vec::new();
    for class in classes.iter().filter(|c| c.members.len() >= min_copies) {
        let rep = &objects[class.rep];
        let Some(rep_shape) = &rep.shape else { continue };
        let id = prototypes.len() as PrototypeId;
        let c = rep_shape.centroid;
        let polygons = rep
            .polygons
            .iter()
            .map(|&i| {
                let p = &scene.polygons[i as usize];
                let mut poly = p.poly;
                for v in &mut poly.v {
                    *v -= c;
                }
                LocalPolygon { poly, material: p.material }
            })
            .collect();
        let name = group_name(scene, rep.group);
        prototypes.push(Prototype { name, polygons, ..Prototype::default() });
        report.prototypes += 1;
        for (o_idx, r, map) in &class.members {
            let o = &objects[*o_idx];
            let Some(shape) = &o.shape else { continue };
            for &i in map {
                instanced[i as usize] = true;
            }
            report.instances += 1;
            report.polygons_instanced += map.len();
            let matrix = DMat4::from_cols(r.x_axis.extend(0.0), r.y_axis.extend(0.0), r.z_axis.extend(0.0), shape.centroid.extend(1.0));
            root_instances.push((o.first, Instance { prototype: id, transform: Transform { matrix }, line: 0 }, map.clone()));
        }
    }
    root_instances.sort_by_key(|(first, _, _)| *first);

    let mut flat_to_input = Vec::with_capacity(scene.polygons.len());
    let mut root = Prototype { name: unique_name(&scene.name, &prototypes), ..Prototype::default() };
    for (i, p) in scene.polygons.iter().enumerate() {
        if !instanced[i] {
            root.polygons.push(LocalPolygon { poly: p.poly, material: p.material });
            flat_to_input.push(i as u32);
        }
    }
    for (_, inst, map) in &root_instances {
        root.instances.push(*inst);
        flat_to_input.extend_from_slice(map);
    }
    prototypes[0] = root;
    let scene_out = InstancedScene {
        name: scene.name.clone(),
        path: std::path::PathBuf::new(),
        materials: scene.materials.clone(),
        prototypes,
        root: 0,
        grids: Vec::new(),
    };
    AutoResult { scene: scene_out, report, flat_to_input }
}

/// The polygons of `scene` in flattening order without two-sided pairs, for comparisons with the
/// input through [`AutoResult::flat_to_input`].
#[must_use]
pub fn flattened_polygons(scene: &InstancedScene) -> Vec<(Poly, u32)> {
    let mut out = Vec::new();
    if (scene.root as usize) < scene.prototypes.len() {
        let options = FlattenOptions { two_sided_pairs: false };
        for_each_polygon(scene, scene.root, &Transform::IDENTITY, &options, &mut |p, m, _| out.push((p, m)));
    }
    out
}

fn group_name(scene: &Scene, group: u32) -> String {
    scene.groups.get(group as usize).cloned().unwrap_or_else(|| format!("group{group}"))
}

/// `base`, or `base~k` for the first `k` that no prototype in `taken` is named.
fn unique_name(base: &str, taken: &[Prototype]) -> String {
    let base = if base.is_empty() { "scene" } else { base };
    let mut name = base.to_string();
    let mut k = 1;
    while taken.iter().any(|p| p.name == name) {
        name = format!("{base}~{k}");
        k += 1;
    }
    name
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::DVec3;
    use crate::scene::{Material, Polygon};

    fn scene_of(objects: &[Vec<Poly>]) -> Scene {
        Scene {
            name: "t".into(),
            polygons: objects
                .iter()
                .enumerate()
                .flat_map(|(g, ps)| ps.iter().map(move |&poly| Polygon { poly, material: 0, group: g as u32 }))
                .collect(),
            materials: vec![Material::diffuse("m", [0.5; 3])],
            groups: (0..objects.len()).map(|g| format!("o{g}")).collect(),
            camera: None,
            warnings: Default::default(),
            luminaires: Vec::new(),
            distant: Vec::new(),
            units: Default::default(),
        }
    }

    fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Poly {
        Poly::triangle(DVec3::from(a), DVec3::from(b), DVec3::from(c))
    }

    #[test]
    fn rotated_copy_matches_and_mirror_does_not() {
        // A scalene triangle pair (no symmetry), a copy turned about z, and its mirror image.
        let shape = vec![tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]), tri([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0])];
        let turn = |p: &Poly| {
            let m = DMat3::from_rotation_z(0.7);
            let v = p.vertices();
            Poly::triangle(m * v[1] + DVec3::X * 5.0, m * v[2] + DVec3::X * 5.0, m * v[0] + DVec3::X * 5.0)
        };
        let mirror = |p: &Poly| {
            let v = p.vertices();
            let f = |x: DVec3| DVec3::new(-x.x, x.y, x.z) + DVec3::Y * 5.0;
            Poly::triangle(f(v[2]), f(v[1]), f(v[0]))
        };
        let turned: Vec<Poly> = shape.iter().rev().map(turn).collect();
        let mirrored: Vec<Poly> = shape.iter().map(mirror).collect();
        let result = auto_instance(&scene_of(&[shape, turned, mirrored]), &AutoOptions::default());
        assert_eq!((result.report.prototypes, result.report.instances, result.report.polygons_instanced), (1, 2, 4));
        assert_eq!(result.scene.prototypes[0].polygons.len(), 2, "the mirror image stays plain");
        assert_eq!(result.flat_to_input, vec![4, 5, 0, 1, 3, 2]);
    }

    #[test]
    fn empty_and_non_finite_scenes_do_not_panic() {
        let empty = auto_instance(&scene_of(&[]), &AutoOptions::default());
        assert_eq!(empty.report, AutoReport::default());
        let bad = vec![tri([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])];
        let result = auto_instance(&scene_of(&[bad.clone(), bad]), &AutoOptions { min_copies: 0, rel_tol: -1.0 });
        assert_eq!(result.report.prototypes, 0);
        assert_eq!(result.scene.prototypes[0].polygons.len(), 2);
    }
}
