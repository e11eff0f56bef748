//! Step 1, `scene`: load and validate a scene (OBJ + MTL, MGF, or the embedded Cornell box) into a
//! flat list of planar triangles and quads with materials.

mod builder;
mod cornell;
mod error;
pub mod generated;
mod guard;
pub mod mgf;
pub mod obj;
pub mod shapes;

pub use builder::SceneBuilder;
pub use cornell::cornell_box;
pub use error::SceneError;
pub use guard::contain;

use crate::geom::{Aabb, DVec3, Poly};
use std::path::Path;

/// A diffuse material. Radiometric quantities are per RGB channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name from the scene file.
    pub name: String,
    /// Diffuse reflectance ρ in [0, 1).
    pub reflectance: [f64; 3],
    /// Emitted radiosity (exitance) E in W/m².
    pub emission: [f64; 3],
    /// Diffuse transmittance (two-sided surfaces only).
    pub transmittance: [f64; 3],
    /// Whether both sides of the surface interact with light.
    pub two_sided: bool,
    /// Declared one-sided (`two_sided = false`): never given a back by default (see
    /// [`crate::daylight::two_sided_where_backs_see_light`]).
    pub one_sided: bool,
}

impl Material {
    /// A grey, non-emitting, one-sided material.
    #[must_use]
    pub fn diffuse(name: &str, reflectance: [f64; 3]) -> Material {
        Material { name: name.to_owned(), reflectance, emission: [0.0; 3], transmittance: [0.0; 3], two_sided: false, one_sided: false }
    }

    /// True when some channel emits.
    #[must_use]
    pub fn is_emitter(&self) -> bool {
        self.emission.iter().any(|&e| e > 0.0)
    }
}

/// One input polygon (after triangulation of polygons with more than 4 vertices).
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    /// Geometry, CCW about the front normal.
    pub poly: Poly,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Index into [`Scene::groups`].
    pub group: u32,
}

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: DVec3,
    /// Viewing direction (unit).
    pub direction: DVec3,
    /// Up vector (unit, roughly orthogonal to `direction`).
    pub up: DVec3,
    /// Vertical field of view in radians.
    pub fov_y: f64,
}

impl Camera {
    /// A camera that sees the whole box from its front (-z side... toward +z is away): placed on the
    /// +z side looking down -z, with a 40° field of view, y up.
    #[must_use]
    pub fn looking_at_box(bounds: &Aabb) -> Camera {
        let c = bounds.center();
        let e = bounds.extent();
        let fov_y = 40f64.to_radians();
        let half = 0.5 * e.x.max(e.y).max(1e-300);
        let dist = half / (0.5 * fov_y).tan() + 0.5 * e.z;
        Camera { position: c + DVec3::Z * dist * 1.05, direction: -DVec3::Z, up: DVec3::Y, fov_y }
    }
}

/// Counts of input problems that were repaired or skipped rather than rejected.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SceneWarnings {
    /// Faces skipped because their area is zero (or below the relative tolerance).
    pub degenerate_faces: usize,
    /// Faces with more than 4 vertices, or non-planar / non-convex quads, that were triangulated.
    pub triangulated_faces: usize,
    /// Materials whose reflectance was clamped below 1 (formats whose total reflectance may reach 1).
    pub clamped_materials: usize,
    /// Faces back to back with the two-sided face before them but of another material: kept as
    /// two surfaces, each with its own back ([`Scene::pair_two_sided`]).
    pub unpaired_backs: usize,
    /// One-sided faces of open meshes whose backs can receive light under the sun and sky, given
    /// a back of their material, as a leaf has ([`crate::daylight::two_sided_where_backs_see_light`]).
    pub two_sided_by_default: usize,
    /// The first few warnings in words (file:line: reason).
    pub messages: Vec<String>,
}

impl SceneWarnings {
    /// Adds `other`'s counts and as many of its messages as there is room for.
    pub fn add(&mut self, other: &SceneWarnings) {
        self.degenerate_faces += other.degenerate_faces;
        self.triangulated_faces += other.triangulated_faces;
        self.clamped_materials += other.clamped_materials;
        self.unpaired_backs += other.unpaired_backs;
        self.two_sided_by_default += other.two_sided_by_default;
        let room = builder::MAX_WARNING_MESSAGES.saturating_sub(self.messages.len());
        self.messages.extend(other.messages.iter().take(room).cloned());
    }

    /// What was repaired or skipped, in words, the counts that are zero left out
    /// (`2 degenerate faces skipped, 1 face triangulated`); `None` when nothing was.
    #[must_use]
    pub fn summary(&self) -> Option<String> {
        let parts: Vec<String> = [
            (self.degenerate_faces, "degenerate face", "skipped"),
            (self.triangulated_faces, "face", "triangulated"),
            (self.clamped_materials, "material", "clamped"),
            (self.unpaired_backs, "back-to-back face of another material", "kept as its own surface"),
            (
                self.two_sided_by_default,
                "lone face",
                "given a back like its front, as light can reach it there (`two_sided = false` keeps a material one-sided)",
            ),
        ]
        .into_iter()
        .filter(|&(n, ..)| n > 0)
        .map(|(n, noun, done)| format!("{n} {noun}{} {done}", if n == 1 { "" } else { "s" }))
        .collect();
        (!parts.is_empty()).then(|| parts.join(", "))
    }
}

/// A validated scene: planar, non-degenerate triangles and quads with finite coordinates.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Display name (file name or `cornell-box`).
    pub name: String,
    /// Input polygons in input order.
    pub polygons: Vec<Polygon>,
    /// Materials.
    pub materials: Vec<Material>,
    /// Object / group names.
    pub groups: Vec<String>,
    /// The scene's camera, when it has one.
    pub camera: Option<Camera>,
    /// What was repaired or skipped.
    pub warnings: SceneWarnings,
    /// Photometric luminaires (see [`crate::luminaire`]); only in photometric scenes.
    pub luminaires: Vec<crate::light::Luminaire>,
    /// Distant sources: the sun and the sky's cells (see [`crate::daylight`]).
    pub distant: Vec<crate::light::DistantSource>,
    /// Radiometric (W, W/m²) or photometric (lm, lx: every channel a luminous quantity).
    pub units: crate::photometry::Units,
}

/// Options of [`load`].
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions {
    /// Accept a scene with no emitter.
    pub allow_dark: bool,
}

/// Loads an OBJ (+ MTL) or MGF file, chosen by extension, and validates it.
pub fn load(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let scene = match ext.as_deref() {
        Some("obj") => obj::load(path)?,
        Some("mgf") => mgf::load(path)?,
        _ => {
            if !path.exists() {
                return Err(SceneError::Io {
                    path: path.to_owned(),
                    source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
                });
            }
            return Err(SceneError::UnknownFormat { path: path.to_owned() });
        }
    };
    let mut scene = scene;
    scene.pair_two_sided();
    scene.check(path, options)?;
    Ok(scene)
}

impl Scene {
    /// The scene's light sources besides its emitting polygons (copies).
    #[must_use]
    pub fn lights(&self) -> crate::light::Lights {
        crate::light::Lights { luminaires: self.luminaires.clone(), distant: self.distant.clone() }
    }

    /// Validation common to every format: non-empty, at least one emitter unless `allow_dark`.
    pub fn check(&self, path: &Path, options: &LoadOptions) -> Result<(), SceneError> {
        if self.polygons.is_empty() {
            return Err(SceneError::Empty { path: path.to_owned() });
        }
        if !options.allow_dark && !self.polygons.iter().any(|p| self.materials[p.material as usize].is_emitter()) {
            return Err(SceneError::NoEmitter { path: path.to_owned() });
        }
        Ok(())
    }

    /// Gives every two-sided polygon (a material that transmits, or is declared two-sided) its back,
    /// right after it: the reversed polygon, unless the input already has it there (a leaf written
    /// as two back-to-back faces). The solvers know one-sided surfaces; a pair with a transmittance
    /// becomes one surface that transmits between its sides ([`crate::hierarchy::twins`]), and
    /// without one, a face both of whose sides reflect. A lone face whose material transmits
    /// would otherwise transmit nothing. Returns how many backs were added.
    pub fn pair_two_sided(&mut self) -> usize {
        let old = std::mem::take(&mut self.polygons);
        let mut added = 0;
        let mut i = 0;
        while i < old.len() {
            let p = old[i].clone();
            self.polygons.push(p.clone());
            i += 1;
            if !self.materials[p.material as usize].two_sided {
                continue;
            }
            match old.get(i) {
                Some(q) if q.material == p.material && q.poly.is_back_of(&p.poly) => {
                    self.polygons.push(q.clone());
                    i += 1;
                }
                next => {
                    if let Some(q) = next.filter(|q| q.poly.is_back_of(&p.poly)) {
                        self.warnings.unpaired_backs += 1;
                        if self.warnings.messages.len() < builder::MAX_WARNING_MESSAGES {
                            self.warnings.messages.push(format!(
                                "{}: polygon {} (0-based, in input order) is back to back with polygon {} but of material `{}`, not `{}`: kept as two surfaces",
                                self.name,
                                i,
                                i - 1,
                                self.materials[q.material as usize].name,
                                self.materials[p.material as usize].name
                            ));
                        }
                    }
                    self.polygons.push(Polygon { poly: p.poly.reversed(), ..p });
                    added += 1;
                }
            }
        }
        added
    }

    /// Bounding box of all polygons.
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in &self.polygons {
            for &v in p.poly.vertices() {
                b.grow(v);
            }
        }
        b
    }

    /// Total area of all polygons.
    #[must_use]
    pub fn total_area(&self) -> f64 {
        self.polygons.iter().map(|p| p.poly.area()).sum()
    }

    /// Material of polygon `i`.
    #[must_use]
    pub fn material_of(&self, i: usize) -> &Material {
        &self.materials[self.polygons[i].material as usize]
    }

    /// The camera, or one framing the scene's bounding box.
    #[must_use]
    pub fn camera_or_default(&self) -> Camera {
        self.camera.unwrap_or_else(|| Camera::looking_at_box(&self.bounds()))
    }

    /// Applies `f` to every vertex (used to build scaled / translated test scenes).
    pub fn transform(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.polygons {
            for v in &mut p.poly.v {
                *v = f(*v);
            }
        }
        if let Some(c) = &mut self.camera {
            let pos = f(c.position);
            let ahead = f(c.position + c.direction);
            let d = (ahead - pos).normalize_or_zero();
            if d != DVec3::ZERO {
                c.direction = d;
            }
            c.position = pos;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::SceneWarnings;

    fn summary(degenerate_faces: usize, triangulated_faces: usize, clamped_materials: usize) -> Option<String> {
        SceneWarnings {
            degenerate_faces,
            triangulated_faces,
            clamped_materials,
            unpaired_backs: 0,
            two_sided_by_default: 0,
            messages: Vec::new(),
        }
        .summary()
    }

    #[test]
    fn warning_summary_says_only_what_happened_in_singular_or_plural() {
        assert_eq!(summary(0, 0, 0), None);
        assert_eq!(summary(0, 1, 0).as_deref(), Some("1 face triangulated"));
        assert_eq!(summary(2, 0, 0).as_deref(), Some("2 degenerate faces skipped"));
        assert_eq!(summary(1, 3, 1).as_deref(), Some("1 degenerate face skipped, 3 faces triangulated, 1 material clamped"));
        assert_eq!(summary(0, 0, 2).as_deref(), Some("2 materials clamped"));
    }
}
