//! Prototype geometry from Wavefront OBJ: vertices, faces and `usemtl` names (materials are defined
//! in the scene file, not in MTL libraries). Faces go through [`SceneBuilder`], so they are validated,
//! triangulated and counted exactly like the plain OBJ loader's.

use crate::geom::DVec3;
use crate::scene::{Material, Scene, SceneBuilder, SceneError};
use std::path::Path;

/// Material name of faces that follow no `usemtl`.
pub const DEFAULT_MATERIAL: &str = "default";

/// Reads an OBJ file into a scene whose material names are the file's `usemtl` names (their
/// reflectances are placeholders; the caller maps names to the scene's materials).
pub fn read(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io { path: path.to_owned(), source })?;
    parse(&text, path)
}

/// Parses OBJ text (see [`read`]); `path` is used in messages.
pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let err = |line: usize, msg: String| SceneError::Parse { path: path.to_owned(), line, msg };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut b = SceneBuilder::new(path, &name);
    let mut vertices: Vec<DVec3> = Vec::new();
    let mut material = b.material(Material::diffuse(DEFAULT_MATERIAL, [0.5; 3]))?;
    let mut group = b.group("default");
    let mut face = Vec::with_capacity(8);
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = raw.split('#').next().unwrap_or("");
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let mut c = [0.0; 3];
                for (k, slot) in c.iter_mut().enumerate() {
                    let w = words.next().ok_or_else(|| err(line_no, format!("vertex needs 3 coordinates, found {k}")))?;
                    *slot = w.parse().map_err(|_| err(line_no, format!("vertex coordinate `{w}` is not a number")))?;
                }
                let v = DVec3::from_array(c);
                if !v.is_finite() {
                    return Err(SceneError::NonFinite {
                        path: path.to_owned(),
                        line: line_no,
                        what: format!("vertex {}", vertices.len() + 1),
                    });
                }
                vertices.push(v);
            }
            Some("f") => {
                face.clear();
                for r in words {
                    let idx = r.split('/').next().unwrap_or("");
                    let k: i64 = idx.parse().map_err(|_| err(line_no, format!("face vertex `{r}` is not an index")))?;
                    let n = vertices.len() as i64;
                    let resolved = if k < 0 { n + k } else { k - 1 };
                    if k == 0 || resolved < 0 || resolved >= n {
                        return Err(err(line_no, format!("face vertex index {k} out of range (1..={n} defined so far)")));
                    }
                    face.push(vertices[resolved as usize]);
                }
                if face.len() < 3 {
                    return Err(err(line_no, format!("face needs at least 3 vertices, found {}", face.len())));
                }
                b.face(&face, material, group, line_no)?;
            }
            Some("usemtl") => {
                let m = words.next().ok_or_else(|| err(line_no, "`usemtl` needs a material name".into()))?;
                material = b.material(Material::diffuse(m, [0.5; 3]))?;
            }
            Some("g" | "o") => {
                group = b.group(words.next().unwrap_or("default"));
            }
            _ => {}
        }
    }
    Ok(b.finish())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn usemtl_names_are_kept_and_bad_index_names_its_line() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl leaf\nf 1 2 3\nusemtl bark\nf 2 4 3\n";
        let s = parse(text, Path::new("t.obj")).unwrap();
        let names: Vec<&str> = s.polygons.iter().map(|p| s.materials[p.material as usize].name.as_str()).collect();
        assert_eq!(names, ["leaf", "bark"]);
        let e = parse("v 0 0 0\nf 1 2 3\n", Path::new("t.obj")).unwrap_err().to_string();
        assert_eq!(e, "t.obj:2: face vertex index 2 out of range (1..=1 defined so far)");
    }
}
