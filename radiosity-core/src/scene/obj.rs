//! Wavefront OBJ + MTL loading through `tobj`, with a line-numbered pre-scan so that errors and
//! warnings name the line. `Kd` is the diffuse reflectance, `Ke` the emitted radiosity in W/m²;
//! the optional non-standard `Kt r g b` key gives a diffuse transmittance (and makes the material two-sided).
//!
//! `tobj` panics on some malformed lines (`Ke 1 2`: issue 17), so both files are pre-scanned with
//! `tobj`'s own rules and every `tobj` call is a [`contain`]ed backstop: a bad file is a one-line
//! error naming the OBJ or MTL file, the line and the reason, never a panic.

use super::guard::contain;
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
    let mtl_dir = path.parent().map(Path::to_owned).unwrap_or_default();
    // The material library read, named in material errors.
    let mtl_used: std::cell::RefCell<Option<PathBuf>> = std::cell::RefCell::new(None);
    let options = tobj::LoadOptions { single_index: false, triangulate: false, ignore_points: true, ignore_lines: true };
    let loaded = contain(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &options, |mtl_path| {
            let mtl_file = mtl_dir.join(mtl_path);
            *mtl_used.borrow_mut() = Some(mtl_file.clone());
            let parsed = read_mtl(mtl_path).and_then(|mtl_text| {
                prescan_mtl(&mtl_text, &mtl_file)?;
                contain(|| tobj::load_mtl_buf(&mut mtl_text.as_bytes()))
                    .map_err(|reason| SceneError::Parse { path: mtl_file.clone(), line: 0, msg: format!("MTL parser failed: {reason}") })?
                    .map_err(|e| SceneError::Parse { path: mtl_file.clone(), line: 0, msg: format!("MTL error: {e}") })
            });
            parsed.map_err(|e| {
                *mtl_error.borrow_mut() = Some(e);
                tobj::LoadError::MaterialParseError
            })
        })
    });
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let (models, materials) = loaded
        .map_err(|reason| SceneError::Parse { path: path.to_owned(), line: 0, msg: format!("OBJ parser failed: {reason}") })?
        .map_err(|e| SceneError::Parse { path: path.to_owned(), line: 0, msg: format!("OBJ error: {e}") })?;
    let materials = materials.map_err(|e| SceneError::Parse { path: path.to_owned(), line: 0, msg: format!("material library: {e}") })?;

    let mut b = SceneBuilder::new(path, name);
    let mtl_path = mtl_used.into_inner().unwrap_or_else(|| path.to_owned());
    let mut mat_ids = Vec::with_capacity(materials.len());
    for m in &materials {
        let id = b.material(convert_material(m, &mtl_path)?).map_err(|e| match e {
            SceneError::Material { material, msg, .. } => SceneError::Material { path: mtl_path.clone(), material, msg },
            other => other,
        })?;
        mat_ids.push(id);
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
    match m.unknown_param.get("two_sided").map(|v| v.trim()) {
        Some("1") => out.two_sided = true,
        Some("0") => out.one_sided = true,
        _ => {}
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

/// Checks an MTL file's lines with `tobj`'s rules (which it enforces by an error without a line, or
/// by a panic), so that every rejection names the line.
fn prescan_mtl(text: &str, path: &Path) -> Result<(), SceneError> {
    let err = |line: usize, msg: String| SceneError::Parse { path: PathBuf::from(path), line, msg };
    for (i, raw) in text.as_bytes().lines().enumerate() {
        let line_no = i + 1;
        let raw = raw.map_err(|source| SceneError::Io { path: path.to_owned(), source })?;
        let line = raw.trim();
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else { continue };
        let numbers = |n: usize, words: std::str::SplitWhitespace<'_>| -> Result<(), SceneError> {
            let found: Vec<&str> = words.take(n).collect();
            if found.len() < n {
                let what = if n == 1 { "a number".to_owned() } else { format!("{n} numbers") };
                return Err(err(line_no, format!("`{key}` needs {what}, found {}", found.len())));
            }
            for w in found {
                let _: f64 = w.parse().map_err(|_| err(line_no, format!("`{key}` value `{w}` is not a number")))?;
            }
            Ok(())
        };
        match key {
            "Ka" | "Kd" | "Ks" | "Ke" => numbers(3, words)?,
            "Ns" | "Ni" | "d" => numbers(1, words)?,
            "illum" => match words.next() {
                Some(w) if w.parse::<u8>().is_ok() => {}
                Some(w) => return Err(err(line_no, format!("`illum` value `{w}` is not an illumination model (0 to 255)"))),
                None => return Err(err(line_no, "`illum` needs an illumination model".to_owned())),
            },
            "newmtl" | "map_Ka" | "map_Kd" | "map_Ks" | "map_Bump" | "map_bump" | "map_Ns" | "map_ns" | "map_NS" | "bump" | "map_d"
                if words.next().is_none() =>
            {
                return Err(err(line_no, format!("`{key}` needs a name")));
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 17: `tobj` 4.0.5 panics on `Ke` with fewer than three numbers (`parse_float3` unwraps).
    /// The pre-scan rejects the line first; were it to miss one, `contain` turns the panic into
    /// the error's reason.
    #[test]
    fn short_ke_is_caught_before_tobj_and_contained_inside_it() {
        let mtl = "newmtl lamp\nKd 0.5 0.5 0.5\nKe 10 10\n";
        let contained = contain(|| tobj::load_mtl_buf(&mut mtl.as_bytes()).map(drop));
        let reason = contained.expect_err("tobj 4.0.5 panics on a short Ke");
        assert!(reason.contains("unwrap"), "{reason}");
        let e = prescan_mtl(mtl, Path::new("room.mtl")).expect_err("pre-scan");
        assert_eq!(e.to_string(), "room.mtl:3: `Ke` needs 3 numbers, found 2");
        assert!(prescan_mtl("newmtl a\nKd 1 1 1 # grey\nillum 2\nNs 10\nmap_Kd tex.png\n", Path::new("ok.mtl")).is_ok());
        for (line, reason) in [
            ("Kd 0.5 x 0.5", "`Kd` value `x` is not a number"),
            ("Ns", "`Ns` needs a number, found 0"),
            ("illum 300", "`illum` value `300` is not an illumination model (0 to 255)"),
            ("newmtl", "`newmtl` needs a name"),
        ] {
            let e = prescan_mtl(&format!("# bad\n{line}\n"), Path::new("bad.mtl")).expect_err(line);
            assert_eq!(e.to_string(), format!("bad.mtl:2: {reason}"));
        }
    }
}
