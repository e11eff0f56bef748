//! One prototype from its entries: its OBJ file, its inline boxes and polygons (validated and
//! triangulated by the scene builder) and its instances.

use super::spec::{BoxSpec, InstanceSpec, PolygonSpec, instance_transform};
use crate::geom::DVec3;
use crate::instancing::model::{Instance, LocalPolygon, Prototype, PrototypeId};
use crate::instancing::{InstancingError, obj_mesh};
use crate::scene::{Material, SceneBuilder, shapes::box_faces};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

pub(super) struct Ctx<'a> {
    pub(super) path: &'a Path,
    pub(super) dir: &'a Path,
    pub(super) text: &'a str,
    pub(super) materials: &'a [Material],
    pub(super) names: &'a HashMap<String, PrototypeId>,
}

impl Ctx<'_> {
    fn line(&self, offset: usize) -> usize {
        self.text[..offset.min(self.text.len())].bytes().filter(|&b| b == b'\n').count() + 1
    }

    fn material(&self, name: &str, line: usize) -> Result<u32, InstancingError> {
        self.materials
            .iter()
            .position(|m| m.name == name)
            .map(|i| i as u32)
            .ok_or_else(|| InstancingError::at(self.path, line, format!("unknown material `{name}`")))
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn prototype(
        &self,
        name: &str,
        obj: Option<&Spanned<String>>,
        renames: &HashMap<String, String>,
        boxes: &[Spanned<BoxSpec>],
        polygons: &[Spanned<PolygonSpec>],
        instances: &[Spanned<InstanceSpec>],
    ) -> Result<Prototype, InstancingError> {
        let mut out = Prototype { name: name.to_owned(), ..Prototype::default() };
        if let Some(obj) = obj {
            let line = self.line(obj.span().start);
            let file = self.dir.join(obj.get_ref());
            if !file.is_file() {
                return Err(InstancingError::at(
                    self.path,
                    line,
                    format!("prototype `{name}`: missing prototype file `{}`", file.display()),
                ));
            }
            let mesh = obj_mesh::read(&file).map_err(|source| InstancingError::Prototype {
                path: self.path.to_owned(),
                line,
                prototype: name.to_owned(),
                source: Box::new(source),
            })?;
            let target = |k: usize| renames.get(&mesh.materials[k].name).map_or(mesh.materials[k].name.as_str(), String::as_str).to_owned();
            let map: Vec<Option<u32>> = (0..mesh.materials.len()).map(|k| self.material(&target(k), line).ok()).collect();
            for p in &mesh.polygons {
                let k = p.material as usize;
                let material = map[k].ok_or_else(|| {
                    InstancingError::at(
                        self.path,
                        line,
                        format!(
                            "prototype `{name}`: material `{}` used in `{}` is not defined in the scene file",
                            target(k),
                            file.display()
                        ),
                    )
                })?;
                out.polygons.push(LocalPolygon { poly: p.poly, material });
            }
            out.source = Some(PathBuf::from(obj.get_ref()));
            out.warnings.add(&mesh.warnings);
        }
        // Inline geometry goes through the scene builder for validation and triangulation.
        let mut b = SceneBuilder::new(self.path, name);
        for m in self.materials {
            let _ = b.material(m.clone())?;
        }
        let g = b.group(name);
        for bs in boxes {
            let line = self.line(bs.span().start);
            let s = bs.get_ref();
            let m = self.material(&s.material, line)?;
            let (lo, hi) = (DVec3::from_array(s.min), DVec3::from_array(s.max));
            if !(lo.cmplt(hi).all()) {
                return Err(InstancingError::at(self.path, line, "box `min` must be below `max` on every axis"));
            }
            for (_, quad) in box_faces(lo, hi, s.inward) {
                b.face(&quad, m, g, line)?;
            }
        }
        for ps in polygons {
            let line = self.line(ps.span().start);
            let s = ps.get_ref();
            let m = self.material(&s.material, line)?;
            if s.vertices.len() < 3 {
                return Err(InstancingError::at(self.path, line, format!("polygon needs at least 3 vertices, found {}", s.vertices.len())));
            }
            let vs: Vec<DVec3> = s.vertices.iter().map(|v| DVec3::from_array(*v)).collect();
            b.face(&vs, m, g, line)?;
        }
        let inline = b.finish();
        out.warnings.add(&inline.warnings);
        out.polygons.extend(inline.polygons.iter().map(|p| LocalPolygon { poly: p.poly, material: p.material }));
        crate::instancing::flatten::merge_backs(&mut out.polygons, self.materials);
        for is in instances {
            let line = self.line(is.span().start);
            let s = is.get_ref();
            let prototype = *self
                .names
                .get(&s.of)
                .ok_or_else(|| InstancingError::at(self.path, line, format!("instance of unknown prototype `{}`", s.of)))?;
            let transform = instance_transform(s).map_err(|msg| InstancingError::at(self.path, line, msg))?;
            if let Some(d) = transform.defect() {
                return Err(InstancingError::at(self.path, line, format!("instance of `{}`: {d}", s.of)));
            }
            out.instances.push(Instance { prototype, transform, line });
        }
        Ok(out)
    }
}
