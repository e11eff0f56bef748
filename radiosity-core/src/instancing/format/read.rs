//! Reading a whole scene file: bands, materials, prototypes, the root, grids and luminaires.

use super::prototype::Ctx;
use super::spec::{BoxSpec, ColorSpec, InstanceSpec, LuminaireSpec, MaterialSpec, PolygonSpec};
use crate::geom::DVec3;
use crate::instancing::InstancingError;
use crate::instancing::model::{InstancedScene, PrototypeId};
use crate::scene::{Material, SceneBuilder};
use serde::Deserialize;
use std::collections::HashMap;
use std::path::Path;
use toml::Spanned;

/// Name of the implicit root prototype made of the file's top-level content.
pub const TOP_LEVEL_NAME: &str = "(scene)";

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
    /// sun and the sky it does ([`InstancedConfig::daylight`](crate::instancing::InstancedConfig::daylight)).
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
    if units == crate::photometry::Units::Photometric && bands.declared {
        return Err(InstancingError::at(path, 1, "`bands` are radiometric: leave out `units = \"photometric\"`"));
    }
    Ok((scene, Lighting { units, luminaires, bands }))
}
