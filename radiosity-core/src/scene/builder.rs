//! Shared by every loader: turns raw faces into validated triangles and quads.

use super::{Camera, Material, Polygon, Scene, SceneError, SceneWarnings};
use crate::geom::{DVec3, Poly};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Relative planarity tolerance: a quad whose fourth vertex lies farther than this times its
/// diagonal from the plane of the first three is triangulated.
pub const PLANARITY_REL_TOL: f64 = 1e-6;
/// Relative area under which a face is degenerate (area / longest edge² below this).
pub const DEGENERATE_REL_AREA: f64 = 1e-14;
/// How many warning messages are kept in words.
pub(super) const MAX_WARNING_MESSAGES: usize = 20;

/// Builds a [`Scene`] face by face, repairing what can be repaired and counting it.
pub struct SceneBuilder {
    path: PathBuf,
    scene: Scene,
    material_index: HashMap<String, u32>,
    group_index: HashMap<String, u32>,
}

impl SceneBuilder {
    /// A builder for the scene read from `path` (used in messages).
    #[must_use]
    pub fn new(path: &Path, name: &str) -> SceneBuilder {
        SceneBuilder {
            path: path.to_owned(),
            scene: Scene {
                name: name.to_owned(),
                polygons: Vec::new(),
                materials: Vec::new(),
                groups: Vec::new(),
                camera: None,
                warnings: SceneWarnings::default(),
                luminaires: Vec::new(),
                distant: Vec::new(),
                units: crate::photometry::Units::Radiometric,
            },
            material_index: HashMap::new(),
            group_index: HashMap::new(),
        }
    }

    /// Adds (or finds by name) a material after validating it; returns its index.
    pub fn material(&mut self, mut m: Material) -> Result<u32, SceneError> {
        if let Some(&i) = self.material_index.get(&m.name) {
            return Ok(i);
        }
        let bad = |msg: String| SceneError::Material { path: self.path.clone(), material: m.name.clone(), msg };
        for c in 0..3 {
            let r = m.reflectance[c];
            if !r.is_finite() || !(0.0..1.0).contains(&r) {
                return Err(bad(format!("diffuse reflectance {r} outside [0, 1)")));
            }
            let e = m.emission[c];
            if !e.is_finite() || e < 0.0 {
                return Err(bad(format!("emission {e} is negative or not finite")));
            }
            let t = m.transmittance[c];
            if !t.is_finite() || t < 0.0 || r + t >= 1.0 {
                return Err(bad(format!("transmittance {t} invalid (reflectance + transmittance must be < 1)")));
            }
        }
        if m.transmittance.iter().any(|&t| t > 0.0) {
            if m.one_sided {
                return Err(bad(
                    "declared one-sided (`two_sided = false`) but transmits: light would go through to a back it does not have".into(),
                ));
            }
            m.two_sided = true;
        }
        let i = self.scene.materials.len() as u32;
        self.material_index.insert(m.name.clone(), i);
        self.scene.materials.push(m);
        Ok(i)
    }

    /// Index of the group `name`, creating it.
    pub fn group(&mut self, name: &str) -> u32 {
        if let Some(&i) = self.group_index.get(name) {
            return i;
        }
        let i = self.scene.groups.len() as u32;
        self.group_index.insert(name.to_owned(), i);
        self.scene.groups.push(name.to_owned());
        i
    }

    /// Sets the camera.
    pub fn camera(&mut self, camera: Camera) {
        self.scene.camera = Some(camera);
    }

    /// Records a warning (counted by the caller's category).
    pub fn warn(&mut self, msg: String) {
        if self.scene.warnings.messages.len() < MAX_WARNING_MESSAGES {
            self.scene.warnings.messages.push(msg);
        }
    }

    /// Mutable access to the warning counters.
    pub fn warnings_mut(&mut self) -> &mut SceneWarnings {
        &mut self.scene.warnings
    }

    /// Adds a face given by its vertices (CCW about the front normal). `line` locates it in the file
    /// for messages. Non-finite coordinates are an error; zero-area faces are skipped with a warning;
    /// polygons with more than 4 vertices and non-planar or non-convex quads are triangulated.
    pub fn face(&mut self, vertices: &[DVec3], material: u32, group: u32, line: usize) -> Result<(), SceneError> {
        if vertices.iter().any(|v| !v.is_finite()) {
            return Err(SceneError::NonFinite { path: self.path.clone(), line, what: "face vertex".into() });
        }
        // Drop repeated consecutive vertices (common in exported meshes).
        let mut vs: Vec<DVec3> = Vec::with_capacity(vertices.len());
        for &v in vertices {
            if vs.last() != Some(&v) {
                vs.push(v);
            }
        }
        while vs.len() > 1 && vs.first() == vs.last() {
            vs.pop();
        }
        let location = format!("{}:{line}", self.path.display());
        if vs.len() < 3 || is_degenerate(&vs) {
            self.scene.warnings.degenerate_faces += 1;
            self.warn(format!("{location}: degenerate face (zero area) skipped"));
            return Ok(());
        }
        if vs.len() == 3 {
            self.push(Poly::triangle(vs[0], vs[1], vs[2]), material, group);
            return Ok(());
        }
        if vs.len() == 4 && is_planar_convex_quad(&vs) {
            self.push(Poly::quad(vs[0], vs[1], vs[2], vs[3]), material, group);
            return Ok(());
        }
        self.scene.warnings.triangulated_faces += 1;
        let tris = triangulate(&vs);
        if tris.is_empty() {
            self.scene.warnings.degenerate_faces += 1;
            self.warn(format!("{location}: face could not be triangulated (self-intersecting?); skipped"));
        }
        for [a, b, c] in tris {
            let t = [vs[a], vs[b], vs[c]];
            if !is_degenerate(&t) {
                self.push(Poly::triangle(t[0], t[1], t[2]), material, group);
            }
        }
        Ok(())
    }

    fn push(&mut self, poly: Poly, material: u32, group: u32) {
        self.scene.polygons.push(Polygon { poly, material, group });
    }

    /// Number of polygons so far.
    #[must_use]
    pub fn n_polygons(&self) -> usize {
        self.scene.polygons.len()
    }

    /// The finished scene (not yet checked for emitters: see [`Scene::check`]).
    #[must_use]
    pub fn finish(self) -> Scene {
        self.scene
    }
}

fn newell(vs: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for i in 0..vs.len() {
        n += vs[i].cross(vs[(i + 1) % vs.len()]);
    }
    0.5 * n
}

fn is_degenerate(vs: &[DVec3]) -> bool {
    let mut longest2: f64 = 0.0;
    for i in 0..vs.len() {
        longest2 = longest2.max((vs[(i + 1) % vs.len()] - vs[i]).length_squared());
    }
    let area = newell(vs).length();
    area.is_nan() || area <= DEGENERATE_REL_AREA * longest2 || longest2 == 0.0
}

fn is_planar_convex_quad(vs: &[DVec3]) -> bool {
    let n = newell(vs).normalize_or_zero();
    let diag = (vs[2] - vs[0]).length().max((vs[3] - vs[1]).length());
    let plane_tol = PLANARITY_REL_TOL * diag;
    let centroid = 0.25 * (vs[0] + vs[1] + vs[2] + vs[3]);
    if vs.iter().any(|&v| (v - centroid).dot(n).abs() > plane_tol) {
        return false;
    }
    // Convex: every corner turns the same way as the normal, strictly.
    (0..4).all(|i| {
        let a = vs[i];
        let b = vs[(i + 1) % 4];
        let c = vs[(i + 2) % 4];
        (b - a).cross(c - b).dot(n) > DEGENERATE_REL_AREA * diag * diag
    })
}

/// Ear-clipping triangulation of a simple polygon (projected on its dominant plane). Returns index
/// triples; empty when the polygon is not simple enough to clip.
fn triangulate(vs: &[DVec3]) -> Vec<[usize; 3]> {
    let n = newell(vs);
    let ax = n.abs();
    let (i, j) = if ax.x >= ax.y && ax.x >= ax.z {
        (1, 2)
    } else if ax.y >= ax.z {
        (2, 0)
    } else {
        (0, 1)
    };
    // Orientation of the projection relative to the normal.
    let sign = if n[3 - i - j] >= 0.0 { 1.0 } else { -1.0 };
    let p: Vec<[f64; 2]> = vs.iter().map(|v| [v[i], v[j]]).collect();
    let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| sign * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    let mut idx: Vec<usize> = (0..vs.len()).collect();
    let mut out = Vec::with_capacity(vs.len() - 2);
    let mut guard = 0;
    while idx.len() > 3 && guard < 4 * vs.len() * vs.len() {
        guard += 1;
        let m = idx.len();
        let mut clipped = false;
        for k in 0..m {
            let (a, b, c) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            if cross(p[a], p[b], p[c]) <= 0.0 {
                continue;
            }
            let inside = idx.iter().any(|&q| {
                q != a
                    && q != b
                    && q != c
                    && cross(p[a], p[b], p[q]) >= 0.0
                    && cross(p[b], p[c], p[q]) >= 0.0
                    && cross(p[c], p[a], p[q]) >= 0.0
            });
            if inside {
                continue;
            }
            out.push([a, b, c]);
            idx.remove(k);
            clipped = true;
            break;
        }
        if !clipped {
            // Fall back to a fan for nearly degenerate input.
            for k in 1..idx.len() - 1 {
                out.push([idx[0], idx[k], idx[k + 1]]);
            }
            return out;
        }
    }
    if idx.len() == 3 {
        out.push([idx[0], idx[1], idx[2]]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concave_pentagon_is_triangulated_with_its_area() {
        let vs = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 2.0, 0.0),
            DVec3::new(1.0, 0.5, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ];
        let tris = triangulate(&vs);
        assert_eq!(tris.len(), 3);
        let area: f64 = tris.iter().map(|t| newell(&[vs[t[0]], vs[t[1]], vs[t[2]]]).length()).sum();
        assert!((area - newell(&vs).length()).abs() < 1e-12, "{area}");
        for t in tris {
            assert!(newell(&[vs[t[0]], vs[t[1]], vs[t[2]]]).z > 0.0, "orientation kept");
        }
    }

    #[test]
    fn nonplanar_quad_is_split() {
        let mut b = SceneBuilder::new(Path::new("t.obj"), "t");
        let m = b.material(Material::diffuse("w", [0.5; 3])).unwrap();
        let g = b.group("g");
        b.face(&[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.01), DVec3::Y], m, g, 1).unwrap();
        assert_eq!(b.n_polygons(), 2);
        b.face(&[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y], m, g, 2).unwrap();
        assert_eq!(b.n_polygons(), 3);
        b.face(&[DVec3::ZERO, DVec3::X, DVec3::X * 2.0], m, g, 3).unwrap();
        assert_eq!(b.finish().warnings.degenerate_faces, 1);
    }
}
