//! Writing a scene with instances: one TOML file plus one OBJ file per prototype that has polygons
//! of its own. Reading the result back with [`super::load`] gives the same scene (up to the
//! round trip of `f64` through decimal text, which is exact for Rust's shortest representation).

use super::InstancingError;
use super::format::{ColorSpec, InstanceSpec, MaterialSpec, TOP_LEVEL_NAME};
use super::model::InstancedScene;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(Serialize)]
struct OutFile {
    name: String,
    root: String,
    material: Vec<MaterialSpec>,
    prototype: Vec<OutPrototype>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    grid: Vec<crate::points::GridSpec>,
}

#[derive(Serialize)]
struct OutPrototype {
    name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    obj: Option<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    instance: Vec<InstanceSpec>,
}

/// Writes `scene` as `<dir>/<stem>.toml` plus `<dir>/<stem>_<prototype>.obj` for each prototype with
/// own polygons; returns the TOML path. Creates `dir` if needed.
pub fn write_scene(scene: &InstancedScene, dir: &Path, stem: &str) -> Result<PathBuf, InstancingError> {
    std::fs::create_dir_all(dir).map_err(|e| InstancingError::io(dir, "cannot create folder", e))?;
    let names: Vec<String> =
        scene.prototypes.iter().map(|p| if p.name == TOP_LEVEL_NAME { unique_name(scene, "scene") } else { p.name.clone() }).collect();
    let material = scene
        .materials
        .iter()
        .map(|m| MaterialSpec {
            name: m.name.clone(),
            reflectance: ColorSpec::Rgb(m.reflectance),
            transmittance: m.transmittance.iter().any(|&t| t > 0.0).then_some(ColorSpec::Rgb(m.transmittance)),
            emission: m.emission.iter().any(|&e| e > 0.0).then_some(ColorSpec::Rgb(m.emission)),
            two_sided: if m.two_sided {
                Some(true)
            } else if m.one_sided {
                Some(false)
            } else {
                None
            },
        })
        .collect();
    let mut prototype = Vec::with_capacity(scene.prototypes.len());
    for (p, name) in scene.prototypes.iter().zip(&names) {
        let obj = if p.polygons.is_empty() {
            None
        } else {
            let file = format!("{stem}_{}.obj", sanitize(name));
            let path = dir.join(&file);
            crate::output::atomic::write_bytes(&path, obj_text(scene, p))
                .map_err(|e| InstancingError::io(&path, "cannot write file", e))?;
            Some(file)
        };
        let instance = p
            .instances
            .iter()
            .map(|i| InstanceSpec {
                of: names[i.prototype as usize].clone(),
                matrix: Some(i.transform.to_rows_3x4().to_vec()),
                ..InstanceSpec::default()
            })
            .collect();
        prototype.push(OutPrototype { name: name.clone(), obj, instance });
    }
    let out =
        OutFile { name: scene.name.clone(), root: names[scene.root as usize].clone(), material, prototype, grid: scene.grids.clone() };
    let text = toml::to_string(&out)
        .map_err(|e| InstancingError::at(&dir.join(format!("{stem}.toml")), 0, format!("cannot encode scene: {e}")))?;
    let path = dir.join(format!("{stem}.toml"));
    let header = "# Scene with instances (radiosity instancing format): materials, prototypes (OBJ + instances), root.\n";
    crate::output::atomic::write_bytes(&path, format!("{header}{text}")).map_err(|e| InstancingError::io(&path, "cannot write file", e))?;
    Ok(path)
}

fn unique_name(scene: &InstancedScene, base: &str) -> String {
    let mut name = base.to_owned();
    let mut k = 1;
    while scene.find(&name).is_some() {
        name = format!("{base}_{k}");
        k += 1;
    }
    name
}

fn sanitize(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect()
}

/// OBJ text of a prototype's own polygons, in its local frame, with `usemtl` names.
fn obj_text(scene: &InstancedScene, p: &super::model::Prototype) -> String {
    let mut s = String::with_capacity(64 * p.polygons.len());
    let _ = writeln!(s, "# prototype `{}`: {} polygons, local frame", p.name, p.polygons.len());
    for q in &p.polygons {
        for v in q.poly.vertices() {
            let _ = writeln!(s, "v {} {} {}", v.x, v.y, v.z);
        }
    }
    let mut current = u32::MAX;
    let mut base = 1usize;
    for q in &p.polygons {
        if q.material != current {
            current = q.material;
            let _ = writeln!(s, "usemtl {}", scene.materials[current as usize].name);
        }
        let n = q.poly.n_vertices();
        s.push('f');
        for k in 0..n {
            let _ = write!(s, " {}", base + k);
        }
        s.push('\n');
        base += n;
    }
    s
}
