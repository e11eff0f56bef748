//! Wavefront OBJ + MTL loading through `tobj`, with a line-numbered pre-scan so that errors and
//! warnings name the line. `Kd` is the diffuse reflectance, `Ke` the emitted radiosity in W/m²;
//! the optional non-standard `Kt r g b` key gives a diffuse transmittance (and makes the material two-sided).

use super::{Material, Scene, SceneBuilder, SceneError};
use crate::geom::DVec3;
use std::io::BufRead;
use std::path::{Path, PathBuf};

/// Reflectance of faces that use no material.
const DEFAULT_REFLECTANCE: [f64; 3] = [0.5; 3];

/// Loads an OBJ file from disk.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io { path: path.to_owned(), source })?;
    let dir = path.parent().map(Path::to_owned).unwrap_or_default();
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    load_str(&text, path, &name, |mtl: &Path| {
        let p = dir.join(mtl);
        std::fs::read_to_string(&p).map_err(|source| SceneError::Io { path: p, source })
    })
}

/// Loads an OBJ from memory; `read_mtl` returns the text of a material library named by `mtllib`.
pub fn load_str(text: &str, path: &Path, name: &str, read_mtl: impl Fn(&Path) -> Result<String, SceneError>) -> Result<Scene, SceneError> {
    let face_lines = prescan(text, path)?;
    let mtl_error: std::cell::RefCell<Option<SceneError>> = std::cell::RefCell::new(None);
    let options = tobj::LoadOptions { single_index: false, triangulate: false, ignore_points: true, ignore_lines: true };
    let (models, materials) = tobj::load_obj_buf(&mut text.as_bytes(), &options, |mtl_path| match read_mtl(mtl_path) {
        Ok(mtl_text) => tobj::load_mtl_buf(&mut mtl_text.as_bytes()),
        Err(e) => {
            *mtl_error.borrow_mut() = Some(e);
            Err(tobj::LoadError::OpenFileFailed)
        }
    })
    .map_err(|e| SceneError::Parse { path: path.to_owned(), line: 0, msg: format!("OBJ error: {e}") })?;
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let materials = materials.map_err(|e| SceneError::Parse { path: path.to_owned(), line: 0, msg: format!("material library: {e}") })?;

    let mut b = SceneBuilder::new(path, name);
    let mut mat_ids = Vec::with_capacity(materials.len());
    for m in &materials {
        mat_ids.push(b.material(convert_material(m, path)?)?);
    }
    let mut default_material = None;
    let mut face_k = 0usize;
    for model in &models {
        let mesh = &model.mesh;
        let group = b.group(&model.name);
        let material = match mesh.material_id {
            Some(i) if i < mat_ids.len() => mat_ids[i],
            _ => match default_material {
                Some(m) => m,
                None => {
                    let m = b.material(Material::diffuse("(default)", DEFAULT_REFLECTANCE))?;
                    default_material = Some(m);
                    m
                }
            },
        };
        let n_faces = if mesh.face_arities.is_empty() { mesh.indices.len() / 3 } else { mesh.face_arities.len() };
        let mut start = 0usize;
        let mut verts = Vec::with_capacity(8);
        for f in 0..n_faces {
            let arity = if mesh.face_arities.is_empty() { 3 } else { mesh.face_arities[f] as usize };
            verts.clear();
            for &vi in &mesh.indices[start..start + arity] {
                let k = 3 * vi as usize;
                verts.push(DVec3::new(mesh.positions[k], mesh.positions[k + 1], mesh.positions[k + 2]));
            }
            start += arity;
            let line = face_lines.get(face_k).copied().unwrap_or(0);
            face_k += 1;
            b.face(&verts, material, group, line)?;
        }
    }
    Ok(b.finish())
}

fn convert_material(m: &tobj::Material, path: &Path) -> Result<Material, SceneError> {
    let mut out = Material::diffuse(&m.name, m.diffuse.unwrap_or(DEFAULT_REFLECTANCE));
    out.emission = m.emissive.unwrap_or([0.0; 3]);
    if let Some(kt) = m.unknown_param.get("Kt") {
        let vals: Vec<f64> = kt.split_whitespace().filter_map(|w| w.parse().ok()).collect();
        out.transmittance = match vals.as_slice() {
            [t] => [*t; 3],
            [r, g, b] => [*r, *g, *b],
            _ => {
                return Err(SceneError::Material {
                    path: path.to_owned(),
                    material: m.name.clone(),
                    msg: format!("`Kt {kt}`: expected 1 or 3 numbers"),
                });
            }
        };
    }
    if m.unknown_param.get("two_sided").is_some_and(|v| v.trim() == "1") {
        out.two_sided = true;
    }
    Ok(out)
}

/// Checks vertex and face lines, returning the line number of each face in order.
fn prescan(text: &str, path: &Path) -> Result<Vec<usize>, SceneError> {
    let err = |line: usize, msg: String| SceneError::Parse { path: PathBuf::from(path), line, msg };
    let mut n_vertices = 0usize;
    let mut face_lines = Vec::new();
    for (i, raw) in text.as_bytes().lines().enumerate() {
        let line_no = i + 1;
        let raw = raw.map_err(|source| SceneError::Io { path: path.to_owned(), source })?;
        let line = raw.split('#').next().unwrap_or("");
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let coords: Vec<&str> = words.collect();
                if coords.len() < 3 {
                    return Err(err(line_no, format!("vertex needs 3 coordinates, found {}", coords.len())));
                }
                for w in &coords[..3] {
                    let x: f64 = w.parse().map_err(|_| err(line_no, format!("vertex coordinate `{w}` is not a number")))?;
                    if !x.is_finite() {
                        return Err(SceneError::NonFinite {
                            path: path.to_owned(),
                            line: line_no,
                            what: format!("vertex {}", n_vertices + 1),
                        });
                    }
                }
                n_vertices += 1;
            }
            Some("f") => {
                let refs: Vec<&str> = words.collect();
                if refs.len() < 3 {
                    return Err(err(line_no, format!("face needs at least 3 vertices, found {}", refs.len())));
                }
                for r in refs {
                    let idx = r.split('/').next().unwrap_or("");
                    let k: i64 = idx.parse().map_err(|_| err(line_no, format!("face vertex `{r}` is not an index")))?;
                    let resolved = if k < 0 { n_vertices as i64 + k } else { k - 1 };
                    if k == 0 || resolved < 0 || resolved >= n_vertices as i64 {
                        return Err(err(line_no, format!("face vertex index {k} out of range (1..={n_vertices} defined so far)")));
                    }
                }
                face_lines.push(line_no);
            }
            _ => {}
        }
    }
    Ok(face_lines)
}
