//! The in-memory form of a scene with instances: materials, prototypes (local polygons plus
//! instances of other prototypes) and the root prototype that is the scene itself.
//!
//! Invariant: the prototype graph is acyclic (checked by the loader and by [`InstancedScene::validate`]),
//! every instance names an existing prototype, every transform is affine, finite and invertible.

use super::InstancingError;
use crate::geom::{Aabb, DVec3, Poly};
use crate::scene::Material;
use glam::{DMat3, DMat4};
use std::path::PathBuf;

/// Relative tolerance under which a transform is singular: `|det(L)|` below this times the product
/// of the column lengths of its linear part `L`.
pub const SINGULAR_REL_TOL: f64 = 1e-9;

/// Index of a prototype in [`InstancedScene::prototypes`].
pub type PrototypeId = u32;

/// An affine transform from a prototype's local frame to its parent's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// The 4×4 matrix (last row `0 0 0 1`), acting on column vectors.
    pub matrix: DMat4,
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Transform = Transform { matrix: DMat4::IDENTITY };

    /// Translation, then rotation, then scale composed as `T · R · S` (scale applied first).
    /// `rotate_deg` holds rotations about x, then y, then z, in degrees.
    #[must_use]
    pub fn from_trs(translate: DVec3, rotate_deg: DVec3, scale: DVec3) -> Transform {
        let r = DMat4::from_rotation_z(rotate_deg.z.to_radians())
            * DMat4::from_rotation_y(rotate_deg.y.to_radians())
            * DMat4::from_rotation_x(rotate_deg.x.to_radians());
        Transform { matrix: DMat4::from_translation(translate) * r * DMat4::from_scale(scale) }
    }

    /// From a row-major 3×4 affine matrix `[L | t]`.
    #[must_use]
    pub fn from_rows_3x4(m: &[f64; 12]) -> Transform {
        Transform {
            matrix: DMat4::from_cols_array(&[m[0], m[4], m[8], 0.0, m[1], m[5], m[9], 0.0, m[2], m[6], m[10], 0.0, m[3], m[7], m[11], 1.0]),
        }
    }

    /// The row-major 3×4 affine part.
    #[must_use]
    pub fn to_rows_3x4(&self) -> [f64; 12] {
        let c = self.matrix.to_cols_array();
        [c[0], c[4], c[8], c[12], c[1], c[5], c[9], c[13], c[2], c[6], c[10], c[14]]
    }

    /// Composition: `self` after `inner` (`self · inner`).
    #[must_use]
    pub fn then(&self, inner: &Transform) -> Transform {
        Transform { matrix: self.matrix * inner.matrix }
    }

    /// Maps a point.
    #[must_use]
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.matrix.transform_point3(p)
    }

    /// Determinant of the linear part (negative for mirrors).
    #[must_use]
    pub fn determinant(&self) -> f64 {
        DMat3::from_mat4(self.matrix).determinant()
    }

    /// Why the transform cannot place an instance, if it cannot: non-finite entries, a last row other
    /// than `0 0 0 1`, or a (nearly) singular linear part.
    #[must_use]
    pub fn defect(&self) -> Option<String> {
        let c = self.matrix.to_cols_array();
        if c.iter().any(|x| !x.is_finite()) {
            return Some("transform has a non-finite entry".into());
        }
        if c[3] != 0.0 || c[7] != 0.0 || c[11] != 0.0 || c[15] != 1.0 {
            return Some("transform is not affine (last row must be 0 0 0 1)".into());
        }
        let l = DMat3::from_mat4(self.matrix);
        let scale = l.x_axis.length() * l.y_axis.length() * l.z_axis.length();
        let det = l.determinant();
        if det.is_nan() || det.abs() <= SINGULAR_REL_TOL * scale || scale == 0.0 {
            return Some(format!("singular transform (determinant {det:e})"));
        }
        None
    }

    /// Maps a polygon, keeping its front side: a mirror reverses the vertex order.
    #[must_use]
    pub fn poly(&self, p: &Poly) -> Poly {
        let v = p.vertices();
        let mirror = self.determinant() < 0.0;
        let m = |i: usize| self.point(v[if mirror { v.len() - 1 - i } else { i }]);
        match v.len() {
            3 => Poly::triangle(m(0), m(1), m(2)),
            _ => Poly::quad(m(0), m(1), m(2), m(3)),
        }
    }

    /// The box containing the image of `b`.
    #[must_use]
    pub fn aabb(&self, b: &Aabb) -> Aabb {
        let mut out = Aabb::EMPTY;
        if b.is_empty() {
            return out;
        }
        for k in 0..8 {
            out.grow(self.point(corner(b, k)));
        }
        out
    }
}

/// Corner `k` (bits: x, y, z) of a box.
#[must_use]
pub fn corner(b: &Aabb, k: usize) -> DVec3 {
    DVec3::new(
        if k & 1 == 0 { b.min.x } else { b.max.x },
        if k & 2 == 0 { b.min.y } else { b.max.y },
        if k & 4 == 0 { b.min.z } else { b.max.z },
    )
}

/// A polygon in a prototype's local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalPolygon {
    /// Geometry (CCW about the front normal).
    pub poly: Poly,
    /// Index into [`InstancedScene::materials`].
    pub material: u32,
}

/// One placement of a prototype inside another.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// The placed prototype.
    pub prototype: PrototypeId,
    /// Local frame of the placed prototype → frame of the prototype holding the instance.
    pub transform: Transform,
    /// Line of the instance in its scene file (0 when generated), for messages.
    pub line: usize,
}

/// Geometry that is placed by instances: its own polygons and instances of other prototypes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Prototype {
    /// Unique name.
    pub name: String,
    /// Own polygons in the local frame.
    pub polygons: Vec<LocalPolygon>,
    /// Sub-instances.
    pub instances: Vec<Instance>,
    /// Where it came from (the OBJ file, or `None` when generated), for the writer and messages.
    pub source: Option<PathBuf>,
    /// What reading it repaired or skipped (degenerate faces, triangulations), counted once per
    /// face of the file, not per instance.
    pub warnings: crate::scene::SceneWarnings,
}

/// A scene with instances. The scene itself is the prototype [`InstancedScene::root`].
#[derive(Clone, Debug, Default)]
pub struct InstancedScene {
    /// Display name.
    pub name: String,
    /// File it was read from (used in messages; empty when generated).
    pub path: PathBuf,
    /// Materials shared by all prototypes. Two-sided materials reflect on both sides; a diffuse
    /// transmittance makes a material two-sided.
    pub materials: Vec<Material>,
    /// All prototypes, including the root.
    pub prototypes: Vec<Prototype>,
    /// The prototype that is the scene.
    pub root: PrototypeId,
    /// Calculation grids of the scene file (`[[grid]]`), validated, names unique.
    pub grids: Vec<crate::points::GridSpec>,
}

impl InstancedScene {
    /// The prototype `id`.
    #[must_use]
    pub fn prototype(&self, id: PrototypeId) -> &Prototype {
        &self.prototypes[id as usize]
    }

    /// Index of the prototype named `name`.
    #[must_use]
    pub fn find(&self, name: &str) -> Option<PrototypeId> {
        self.prototypes.iter().position(|p| p.name == name).map(|i| i as PrototypeId)
    }

    /// Index of the material named `name`.
    #[must_use]
    pub fn find_material(&self, name: &str) -> Option<u32> {
        self.materials.iter().position(|m| m.name == name).map(|i| i as u32)
    }

    /// Checks the invariant of the module: ids in range, transforms invertible, no cycle. The error
    /// names the instance's line (0 for generated scenes).
    pub fn validate(&self) -> Result<(), InstancingError> {
        let n = self.prototypes.len();
        if self.root as usize >= n {
            return Err(InstancingError::at(&self.path, 0, "root prototype out of range"));
        }
        for p in &self.prototypes {
            for poly in &p.polygons {
                if poly.material as usize >= self.materials.len() {
                    return Err(InstancingError::at(&self.path, 0, format!("prototype `{}`: material index out of range", p.name)));
                }
            }
            for inst in &p.instances {
                if inst.prototype as usize >= n {
                    return Err(InstancingError::at(
                        &self.path,
                        inst.line,
                        format!("prototype `{}`: instance of an unknown prototype", p.name),
                    ));
                }
                if let Some(d) = inst.transform.defect() {
                    return Err(InstancingError::at(
                        &self.path,
                        inst.line,
                        format!("instance of `{}` in `{}`: {d}", self.prototypes[inst.prototype as usize].name, p.name),
                    ));
                }
            }
        }
        if let Some((line, cycle)) = find_cycle(self) {
            return Err(InstancingError::at(&self.path, line, format!("instance cycle: {cycle}")));
        }
        Ok(())
    }

    /// Prototypes in an order where every prototype comes after all those it instances.
    /// Requires an acyclic graph (see [`InstancedScene::validate`]).
    #[must_use]
    pub fn bottom_up(&self) -> Vec<PrototypeId> {
        let n = self.prototypes.len();
        let mut state = vec![0u8; n];
        let mut out = Vec::with_capacity(n);
        for start in 0..n {
            if state[start] != 0 {
                continue;
            }
            // Iterative post-order.
            let mut stack = vec![(start, 0usize)];
            state[start] = 1;
            while let Some(&mut (p, ref mut k)) = stack.last_mut() {
                let insts = &self.prototypes[p].instances;
                if *k < insts.len() {
                    let c = insts[*k].prototype as usize;
                    *k += 1;
                    if state[c] == 0 {
                        state[c] = 1;
                        stack.push((c, 0));
                    }
                } else {
                    state[p] = 2;
                    out.push(p as PrototypeId);
                    stack.pop();
                }
            }
        }
        out
    }

    /// Number of polygons of each prototype when flattened (own polygons plus its instances',
    /// recursively), counting a two-sided polygon twice when `two_sided_pairs`.
    #[must_use]
    pub fn flattened_counts(&self, two_sided_pairs: bool) -> Vec<u64> {
        let mut counts = vec![0u64; self.prototypes.len()];
        for id in self.bottom_up() {
            let p = &self.prototypes[id as usize];
            let own: u64 =
                p.polygons.iter().map(|q| if two_sided_pairs && self.materials[q.material as usize].two_sided { 2 } else { 1 }).sum();
            let sub: u64 = p.instances.iter().map(|i| counts[i.prototype as usize]).sum();
            counts[id as usize] = own.saturating_add(sub);
        }
        counts
    }

    /// Flattened surface area of every prototype (two-sided surfaces counted twice with
    /// `two_sided_pairs`, as the solver sees them). An instance's area scales by `|det|^(2/3)` of
    /// its transform's linear part: exact for similarities (rotation, uniform scale, translation),
    /// which is what generated and automatically found instances use; an approximation under shear
    /// or non-uniform scale.
    #[must_use]
    pub fn flattened_areas(&self, two_sided_pairs: bool) -> Vec<f64> {
        let mut areas = vec![0.0f64; self.prototypes.len()];
        for id in self.bottom_up() {
            let p = &self.prototypes[id as usize];
            let own: f64 = p
                .polygons
                .iter()
                .map(|q| q.poly.area() * if two_sided_pairs && self.materials[q.material as usize].two_sided { 2.0 } else { 1.0 })
                .sum();
            let sub: f64 = p
                .instances
                .iter()
                .map(|i| areas[i.prototype as usize] * glam::DMat3::from_mat4(i.transform.matrix).determinant().abs().powf(2.0 / 3.0))
                .sum();
            areas[id as usize] = own + sub;
        }
        areas
    }

    /// Local bounding box of every prototype (its own polygons and its instances' boxes).
    #[must_use]
    pub fn local_bounds(&self) -> Vec<Aabb> {
        let mut bounds = vec![Aabb::EMPTY; self.prototypes.len()];
        for id in self.bottom_up() {
            let p = &self.prototypes[id as usize];
            let mut b = Aabb::EMPTY;
            for q in &p.polygons {
                for &v in q.poly.vertices() {
                    b.grow(v);
                }
            }
            for i in &p.instances {
                b.merge(&i.transform.aabb(&bounds[i.prototype as usize]));
            }
            bounds[id as usize] = b;
        }
        bounds
    }
}

/// The first cycle found: the line of the instance that closes it and the path in words
/// (`` `a` -> `b` -> `a` ``).
fn find_cycle(scene: &InstancedScene) -> Option<(usize, String)> {
    let n = scene.prototypes.len();
    let mut state = vec![0u8; n];
    for start in 0..n {
        if state[start] != 0 {
            continue;
        }
        let mut stack: Vec<(usize, usize)> = vec![(start, 0)];
        state[start] = 1;
        while let Some(&mut (p, ref mut k)) = stack.last_mut() {
            let insts = &scene.prototypes[p].instances;
            if *k < insts.len() {
                let inst = insts[*k];
                *k += 1;
                let c = inst.prototype as usize;
                match state[c] {
                    0 => {
                        state[c] = 1;
                        stack.push((c, 0));
                    }
                    1 => {
                        let from = stack.iter().position(|&(q, _)| q == c).unwrap_or(0);
                        let mut names: Vec<String> =
                            stack[from..].iter().map(|&(q, _)| format!("`{}`", scene.prototypes[q].name)).collect();
                        names.push(format!("`{}`", scene.prototypes[c].name));
                        return Some((inst.line, names.join(" -> ")));
                    }
                    _ => {}
                }
            } else {
                state[p] = 2;
                stack.pop();
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_round_trip_and_mirror_keeps_front() {
        let m = [0.0, -2.0, 0.0, 1.0, 2.0, 0.0, 0.0, 2.0, 0.0, 0.0, 2.0, 3.0];
        let t = Transform::from_rows_3x4(&m);
        assert_eq!(t.to_rows_3x4(), m);
        assert_eq!(t.point(DVec3::X), DVec3::new(1.0, 4.0, 3.0));
        let tri = Poly::triangle(DVec3::ZERO, DVec3::X, DVec3::Y);
        let mirror = Transform::from_trs(DVec3::ZERO, DVec3::ZERO, DVec3::new(-1.0, 1.0, 1.0));
        assert!(mirror.poly(&tri).normal().z > 0.0, "a mirrored polygon keeps its front side");
        assert!(Transform::from_trs(DVec3::ZERO, DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0)).defect().is_some());
    }
}
