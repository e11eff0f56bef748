//! The objects of a plain scene (one per OBJ object / group) and what comparisons need of each:
//! its signature and its rotation invariants.

use crate::geom::DVec3;
use crate::scene::Scene;
use std::collections::BTreeMap;

/// One OBJ object / group: its polygons in input order and, when comparable, its shape.
pub(super) struct Object {
    pub(super) group: u32,
    pub(super) first: u32,
    pub(super) polygons: Vec<u32>,
    pub(super) shape: Option<Shape>,
}

/// What comparisons need of an object.
pub(super) struct Shape {
    pub(super) signature: Vec<(u32, u8)>,
    pub(super) centroid: DVec3,
    /// Largest vertex distance from the centroid.
    pub(super) radius: f64,
    pub(super) area: f64,
    /// Trace and Frobenius norm of the area-weighted vertex covariance, per unit weight.
    pub(super) cov_trace: f64,
    pub(super) cov_norm: f64,
    /// Distinct vertices.
    pub(super) vertices: Vec<DVec3>,
}

pub(super) fn collect_objects(scene: &Scene) -> Vec<Object> {
    let mut by_group: BTreeMap<u32, usize> = BTreeMap::new();
    let mut objects: Vec<Object> = Vec::new();
    for (i, p) in scene.polygons.iter().enumerate() {
        let idx = *by_group.entry(p.group).or_insert_with(|| {
            objects.push(Object { group: p.group, first: i as u32, polygons: Vec::new(), shape: None });
            objects.len() - 1
        });
        objects[idx].polygons.push(i as u32);
    }
    for o in &mut objects {
        o.shape = shape_of(scene, &o.polygons);
    }
    objects
}

fn shape_of(scene: &Scene, polygons: &[u32]) -> Option<Shape> {
    let mut signature = Vec::with_capacity(polygons.len());
    let (mut wsum, mut csum, mut area) = (0.0, DVec3::ZERO, 0.0);
    for &i in polygons {
        let p = &scene.polygons[i as usize];
        if p.material as usize >= scene.materials.len() || p.poly.vertices().iter().any(|v| !v.is_finite()) {
            return None;
        }
        signature.push((p.material, p.poly.n_vertices() as u8));
        let a = p.poly.area();
        area += a;
        for &v in p.poly.vertices() {
            let w = a / p.poly.n_vertices() as f64;
            wsum += w;
            csum += w * v;
        }
    }
    signature.sort_unstable();
    if !wsum.is_finite() || wsum <= 0.0 || !area.is_finite() {
        return None;
    }
    let centroid = csum / wsum;
    let mut cov = [[0.0f64; 3]; 3];
    let mut radius = 0.0f64;
    let mut vertices = Vec::new();
    for &i in polygons {
        let p = &scene.polygons[i as usize];
        let w = p.poly.area() / p.poly.n_vertices() as f64 / wsum;
        for &v in p.poly.vertices() {
            let d = (v - centroid).to_array();
            for (r, row) in cov.iter_mut().enumerate() {
                for (c, x) in row.iter_mut().enumerate() {
                    *x += w * d[r] * d[c];
                }
            }
            radius = radius.max((v - centroid).length());
            vertices.push(v);
        }
    }
    vertices.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)).then(a.z.total_cmp(&b.z)));
    vertices.dedup();
    let cov_trace = cov[0][0] + cov[1][1] + cov[2][2];
    let cov_norm = cov.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    if !radius.is_finite() || radius <= 0.0 {
        return None;
    }
    Some(Shape { signature, centroid, radius, area, cov_trace, cov_norm, vertices })
}
