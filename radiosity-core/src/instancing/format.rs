//! The scene file with instances (TOML). Reading: [`load`] / [`parse`]; the layout is documented in
//! the module [`crate::instancing`].

use super::model::{Instance, InstancedScene, LocalPolygon, Prototype, PrototypeId, Transform};
use super::{InstancingError, obj_mesh};
use crate::geom::DVec3;
use crate::scene::{Material, SceneBuilder, shapes::box_faces};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Name of the implicit root prototype made of the file's top-level content.
pub const TOP_LEVEL_NAME: &str = "(scene)";

/// A colour given as one number (grey), three (RGB), or one per named band.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum ColorSpec {
    /// The same value in every channel.
    Grey(f64),
    /// Red, green, blue.
    Rgb([f64; 3]),
    /// One value per band of the scene's `bands`.
    Bands(Vec<f64>),
}

impl ColorSpec {
    /// The three channels (the first three bands, zero past the last).
    #[must_use]
    pub fn rgb(&self) -> [f64; 3] {
        match self {
            ColorSpec::Grey(x) => [*x; 3],
            ColorSpec::Rgb(c) => *c,
            ColorSpec::Bands(v) => std::array::from_fn(|c| v.get(c).copied().unwrap_or(0.0)),
        }
    }

    /// The values of `n` bands: one number for all, or exactly `n`.
    pub fn values(&self, n: usize) -> Result<Vec<f64>, String> {
        let v = match self {
            ColorSpec::Grey(x) => return Ok(vec![*x; n]),
            ColorSpec::Rgb(c) => c.to_vec(),
            ColorSpec::Bands(v) => v.clone(),
        };
        if v.len() == n {
            Ok(v)
        } else {
            Err(format!("{} values given, the scene has {n} bands (give one number or one per band)", v.len()))
        }
    }
}

/// `[[material]]`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Name used by `usemtl` in prototype OBJ files and by `material = ...` entries.
    pub name: String,
    /// Diffuse reflectance ρ, in [0, 1).
    pub reflectance: ColorSpec,
    /// Diffuse transmittance t (makes the material two-sided; ρ + t < 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmittance: Option<ColorSpec>,
    /// Emitted radiosity, W/m².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<ColorSpec>,
    /// Both sides reflect (a side's radiosity is ρ·H(same side) + t·H(other side)); `false`
    /// declares the material one-sided, which a face under the sun and sky otherwise is only
    /// where no light can reach its back ([`crate::daylight::two_sided_where_backs_see_light`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_sided: Option<bool>,
}

/// A uniform or per-axis scale.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum ScaleSpec {
    /// Uniform.
    Uniform(f64),
    /// Per axis.
    Axes([f64; 3]),
}

/// `[[instance]]` or `[[prototype.instance]]`: a placement of the prototype `of`. Either `matrix`
/// (12 numbers: a row-major 3×4 `[L | t]`, or 16: a row-major 4×4) or any of `translate`, `rotate`
/// (degrees about x, then y, then z) and `scale`, composed as translate · rotate · scale.
#[derive(Clone, Debug, Deserialize, Serialize, Default)]
#[serde(deny_unknown_fields)]
pub struct InstanceSpec {
    /// Name of the placed prototype.
    pub of: String,
    /// Row-major matrix, 12 or 16 numbers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<Vec<f64>>,
    /// Translation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translate: Option<[f64; 3]>,
    /// Rotations about x, y, z in degrees (applied in that order).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate: Option<[f64; 3]>,
    /// Scale.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<ScaleSpec>,
}

/// `[[box]]`: an axis-aligned box of 6 quads.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// Smallest corner.
    pub min: [f64; 3],
    /// Largest corner.
    pub max: [f64; 3],
    /// Material name.
    pub material: String,
    /// Faces point inward (a room) instead of outward (a solid).
    #[serde(default)]
    pub inward: bool,
}

/// `[[polygon]]`: one planar polygon, CCW about its front normal.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PolygonSpec {
    /// Material name.
    pub material: String,
    /// At least 3 vertices.
    pub vertices: Vec<[f64; 3]>,
}

/// `[[luminaire]]`: a photometric file placed in the scene (see [`crate::luminaire::Luminaire::new`]).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LuminaireSpec {
    /// An IES LM-63 file, relative to the scene file's folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ies: Option<String>,
    /// A EULUMDAT file, relative to the scene file's folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ldt: Option<String>,
    /// Name in messages (default: the file's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Photometric centre.
    pub position: [f64; 3],
    /// Direction of the photometric nadir (γ = 0); default straight down, −z.
    #[serde(default = "default_aim")]
    pub aim: [f64; 3],
    /// Degrees about the aim, turning the C = 0 plane.
    #[serde(default)]
    pub rotate: f64,
    /// Scales every intensity.
    #[serde(default = "default_multiplier")]
    pub multiplier: f64,
}

fn default_aim() -> [f64; 3] {
    [0.0, 0.0, -1.0]
}

fn default_multiplier() -> f64 {
    1.0
}

/// What a scene file says about light and units beyond its geometry: `units`, `[[luminaire]]`,
/// `bands`, `[site]`, `[sun]` and `[sky]`.
#[derive(Clone, Debug, Default)]
pub struct Lighting {
    /// `units = "radiometric"` (default) or `"photometric"`.
    pub units: crate::photometry::Units,
    /// The luminaires, placed.
    pub luminaires: Vec<crate::luminaire::Luminaire>,
    /// Bands (RGB unless declared) with the materials' values per band, and the daylight.
    pub bands: super::bands::Bands,
}

impl Lighting {
    /// Whether the file asks for anything the instanced solver does not do (luminaires, photometric
    /// units, more than three bands): such a scene is flattened and solved as a plain scene. The
    /// sun and the sky it does ([`InstancedConfig::daylight`](super::InstancedConfig::daylight)).
    #[must_use]
    pub fn needs_plain_solve(&self) -> bool {
        !self.luminaires.is_empty() || self.units != crate::photometry::Units::Radiometric || self.bands.packs() > 1
    }
}

/// `[[prototype]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PrototypeSpec {
    name: Spanned<String>,
    #[serde(default)]
    obj: Option<Spanned<String>>,
    #[serde(default)]
    materials: HashMap<String, String>,
    #[serde(default, rename = "box")]
    boxes: Vec<Spanned<BoxSpec>>,
    #[serde(default)]
    polygon: Vec<Spanned<PolygonSpec>>,
    #[serde(default)]
    instance: Vec<Spanned<InstanceSpec>>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    root: Option<Spanned<String>>,
    #[serde(default)]
    material: Vec<Spanned<MaterialSpec>>,
    #[serde(default)]
    prototype: Vec<Spanned<PrototypeSpec>>,
    #[serde(default)]
    obj: Option<Spanned<String>>,
    #[serde(default)]
    materials: HashMap<String, String>,
    #[serde(default, rename = "box")]
    boxes: Vec<Spanned<BoxSpec>>,
    #[serde(default)]
    polygon: Vec<Spanned<PolygonSpec>>,
    #[serde(default)]
    instance: Vec<Spanned<InstanceSpec>>,
    #[serde(default)]
    units: Option<crate::photometry::Units>,
    #[serde(default)]
    luminaire: Vec<Spanned<LuminaireSpec>>,
    /// `[[grid]]`: calculation grids.
    #[serde(default)]
    grid: Vec<Spanned<crate::points::GridSpec>>,
    #[serde(default)]
    bands: Option<Spanned<Vec<String>>>,
    #[serde(default)]
    site: Option<super::bands::SiteSpec>,
    #[serde(default)]
    sun: Option<Spanned<super::bands::SunSpec>>,
    #[serde(default)]
    sky: Option<Spanned<super::bands::SkySpec>>,
}

/// Reads a scene file with instances. Prototype OBJ paths are relative to the file's folder.
pub fn load(path: &Path) -> Result<InstancedScene, InstancingError> {
    load_with_lighting(path).map(|(scene, _)| scene)
}

/// Reads a scene file with its [`Lighting`] (units and luminaires; photometric files are relative
/// to the scene file's folder).
pub fn load_with_lighting(path: &Path) -> Result<(InstancedScene, Lighting), InstancingError> {
    let text = std::fs::read_to_string(path).map_err(|e| InstancingError::io(path, "cannot read file", e))?;
    let dir = path.parent().map(Path::to_owned).unwrap_or_default();
    parse_with_lighting(&text, path, &dir)
}

/// Parses scene text; `path` names it in messages and `dir` is where relative OBJ paths start.
pub fn parse(text: &str, path: &Path, dir: &Path) -> Result<InstancedScene, InstancingError> {
    parse_with_lighting(text, path, dir).map(|(scene, _)| scene)
}

/// [`parse`] with the file's [`Lighting`].
pub fn parse_with_lighting(text: &str, path: &Path, dir: &Path) -> Result<(InstancedScene, Lighting), InstancingError> {
    let line_of = |offset: usize| text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1;
    let spec: FileSpec = toml::from_str(text).map_err(|e| {
        let line = e.span().map_or(0, |s| line_of(s.start));
        let msg = e.message().trim();
        InstancingError::at(path, line, if msg.is_empty() { "invalid TOML".to_owned() } else { msg.replace('\n', "; ") })
    })?;

    // Bands and daylight first: the materials' values are per band.
    let band_input = super::bands::BandsInput {
        bands: spec.bands.as_ref().map(|b| b.get_ref().as_slice()),
        site: spec.site.as_ref(),
        sun: spec.sun.as_ref().map(|s| (s.get_ref(), line_of(s.span().start))),
        sky: spec.sky.as_ref().map(|s| (s.get_ref(), line_of(s.span().start))),
        materials: spec
            .material
            .iter()
            .map(|m| {
                let ms = m.get_ref();
                (ms.reflectance.clone(), ms.transmittance.clone(), ms.emission.clone(), line_of(m.span().start))
            })
            .collect(),
    };
    let bands = super::bands::resolve(&band_input, path, spec.bands.as_ref().map_or(1, |b| line_of(b.span().start)))?;

    // Materials, validated by the scene builder (same rules as OBJ / MGF materials); with bands,
    // the first pack's values.
    let mut validator = SceneBuilder::new(path, "");
    let mut seen: Vec<&str> = Vec::with_capacity(spec.material.len());
    for m in &spec.material {
        let line = line_of(m.span().start);
        let ms = m.get_ref();
        if seen.contains(&ms.name.as_str()) {
            return Err(InstancingError::at(path, line, format!("duplicate material `{}`", ms.name)));
        }
        let mat = Material {
            name: ms.name.clone(),
            reflectance: ms.reflectance.rgb(),
            emission: ms.emission.as_ref().map_or([0.0; 3], ColorSpec::rgb),
            transmittance: ms.transmittance.as_ref().map_or([0.0; 3], ColorSpec::rgb),
            two_sided: ms.two_sided == Some(true),
            one_sided: ms.two_sided == Some(false),
        };
        seen.push(&ms.name);
        let _ = validator.material(mat).map_err(|e| InstancingError::at(path, line, e.to_string()))?;
    }
    let materials = validator.finish().materials;

    // Prototype names first, so instances may refer forward.
    let mut names: HashMap<String, PrototypeId> = HashMap::new();
    for (i, p) in spec.prototype.iter().enumerate() {
        let name = p.get_ref().name.get_ref();
        if name == TOP_LEVEL_NAME || names.insert(name.clone(), i as PrototypeId).is_some() {
            return Err(InstancingError::at(path, line_of(p.get_ref().name.span().start), format!("duplicate prototype `{name}`")));
        }
    }
    let has_top = spec.obj.is_some() || !spec.boxes.is_empty() || !spec.polygon.is_empty() || !spec.instance.is_empty();
    let ctx = Ctx { path, dir, text, materials: &materials, names: &names };
    let mut prototypes = Vec::with_capacity(spec.prototype.len() + 1);
    for p in &spec.prototype {
        let p = p.get_ref();
        prototypes.push(ctx.prototype(p.name.get_ref(), p.obj.as_ref(), &p.materials, &p.boxes, &p.polygon, &p.instance)?);
    }
    let root = match &spec.root {
        Some(r) => {
            if has_top {
                return Err(InstancingError::at(
                    path,
                    line_of(r.span().start),
                    "`root` and top-level geometry or instances cannot be combined",
                ));
            }
            *names
                .get(r.get_ref())
                .ok_or_else(|| InstancingError::at(path, line_of(r.span().start), format!("unknown prototype `{}`", r.get_ref())))?
        }
        None => {
            prototypes.push(ctx.prototype(
                TOP_LEVEL_NAME,
                spec.obj.as_ref(),
                &spec.materials,
                &spec.boxes,
                &spec.polygon,
                &spec.instance,
            )?);
            (prototypes.len() - 1) as PrototypeId
        }
    };
    let mut grids: Vec<crate::points::GridSpec> = Vec::with_capacity(spec.grid.len());
    for g in &spec.grid {
        let line = line_of(g.span().start);
        let gs = g.get_ref();
        gs.validate().map_err(|e| InstancingError::at(path, line, e.to_string()))?;
        if grids.iter().any(|other| other.name == gs.name) {
            return Err(InstancingError::at(path, line, format!("duplicate grid `{}`", gs.name)));
        }
        grids.push(gs.clone());
    }
    let name = spec.name.unwrap_or_else(|| path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
    let scene = InstancedScene { name, path: path.to_owned(), materials, prototypes, root, grids };
    scene.validate()?;
    let units = spec.units.unwrap_or_default();
    let mut luminaires = Vec::with_capacity(spec.luminaire.len());
    for l in &spec.luminaire {
        let line = line_of(l.span().start);
        let ls = l.get_ref();
        let file = match (&ls.ies, &ls.ldt) {
            (Some(f), None) | (None, Some(f)) => f,
            _ => return Err(InstancingError::at(path, line, "a luminaire needs one of `ies` or `ldt`")),
        };
        if units != crate::photometry::Units::Photometric {
            return Err(InstancingError::at(path, line, "luminaires need `units = \"photometric\"` (their intensities are in cd)"));
        }
        let photometry = crate::photometry::read(&dir.join(file)).map_err(|e| InstancingError::at(path, line, e.to_string()))?;
        let name = ls
            .name
            .clone()
            .unwrap_or_else(|| Path::new(file).file_name().map_or_else(|| file.clone(), |n| n.to_string_lossy().into_owned()));
        let lum = crate::luminaire::Luminaire::new(
            &name,
            std::sync::Arc::new(photometry),
            DVec3::from(ls.position),
            DVec3::from(ls.aim),
            ls.rotate,
            ls.multiplier,
        )
        .map_err(|e| InstancingError::at(path, line, e.to_string()))?;
        luminaires.push(lum);
    }
    if !luminaires.is_empty() && bands.has_daylight() {
        let span = spec.sun.as_ref().map(Spanned::span).or_else(|| spec.sky.as_ref().map(Spanned::span));
        let line = span.map_or(1, |s| line_of(s.start));
        return Err(InstancingError::at(path, line, "luminaires and daylight in one scene are not supported"));
    }
    if units == crate::photometry::Units::Photometric && bands.declared {
        return Err(InstancingError::at(path, 1, "`bands` are radiometric: leave out `units = \"photometric\"`"));
    }
    Ok((scene, Lighting { units, luminaires, bands }))
}

struct Ctx<'a> {
    path: &'a Path,
    dir: &'a Path,
    text: &'a str,
    materials: &'a [Material],
    names: &'a HashMap<String, PrototypeId>,
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
    fn prototype(
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
        super::flatten::merge_backs(&mut out.polygons, self.materials);
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

/// The transform an instance entry describes.
pub fn instance_transform(s: &InstanceSpec) -> Result<Transform, String> {
    if let Some(m) = &s.matrix {
        if s.translate.is_some() || s.rotate.is_some() || s.scale.is_some() {
            return Err("`matrix` cannot be combined with `translate`, `rotate` or `scale`".into());
        }
        return match m.len() {
            12 => Ok(Transform::from_rows_3x4(m.as_slice().try_into().expect("length checked"))),
            16 => {
                let rows: [f64; 16] = m.as_slice().try_into().expect("length checked");
                Ok(Transform { matrix: glam::DMat4::from_cols_array(&rows).transpose() })
            }
            n => Err(format!("`matrix` needs 12 (3×4) or 16 (4×4) numbers, found {n}")),
        };
    }
    let scale = match s.scale {
        None => DVec3::ONE,
        Some(ScaleSpec::Uniform(k)) => DVec3::splat(k),
        Some(ScaleSpec::Axes(a)) => DVec3::from_array(a),
    };
    Ok(Transform::from_trs(DVec3::from_array(s.translate.unwrap_or([0.0; 3])), DVec3::from_array(s.rotate.unwrap_or([0.0; 3])), scale))
}
