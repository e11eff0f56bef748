//! Named spectral bands and daylight in the scene file: `bands = [...]`, `[site]`, `[sun]`,
//! `[sky]` (see [`crate::daylight`]).
//!
//! The solver carries three channels per solve. A scene with named bands is solved in *packs* of
//! three bands ([`Bands::packs`]; `PAR` and `NIR` are one pack, 10 bins are four), each pack a
//! solve of its own with the materials and sources of its bands, so the cost grows with the
//! number of bands (by thirds). Without `bands` the three channels are red, green and blue.

use super::spec::ColorSpec;
use crate::daylight::{self, DistantSource, Site, SkyModel};
use crate::geom::DVec3;
use crate::instancing::InstancingError;
use crate::scene::Material;
use serde::Deserialize;
use std::path::Path;

/// Most bands a scene may declare.
pub const MAX_BANDS: usize = 64;

/// The channel names of an RGB scene.
pub const RGB_NAMES: [&str; 3] = ["r", "g", "b"];

/// `[site]`: which way is up and north.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SiteSpec {
    #[serde(default = "up_default")]
    up: [f64; 3],
    #[serde(default = "north_default")]
    north: [f64; 3],
}

fn up_default() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

fn north_default() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// `[sun]`: a direction, or a place and a time; the direct normal irradiance.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SunSpec {
    #[serde(default)]
    direction: Option<[f64; 3]>,
    #[serde(default)]
    latitude: Option<f64>,
    #[serde(default)]
    longitude: Option<f64>,
    #[serde(default)]
    time: Option<String>,
    direct_normal: ColorSpec,
}

/// `[sky] model`: the radiance distribution's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(super) enum SkyModelName {
    Uniform,
    CieOvercast,
    CieGeneral,
    Perez,
}

/// `[sky]`: a radiance model (a CIE general sky with its `type`, a Perez sky with its `clearness`
/// and `brightness`), the diffuse horizontal irradiance and the number of cells.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SkySpec {
    #[serde(default = "model_default")]
    model: SkyModelName,
    #[serde(default, rename = "type")]
    sky_type: Option<u8>,
    #[serde(default)]
    clearness: Option<f64>,
    #[serde(default)]
    brightness: Option<f64>,
    diffuse_horizontal: ColorSpec,
    #[serde(default = "directions_default")]
    directions: u32,
}

fn model_default() -> SkyModelName {
    SkyModelName::Uniform
}

fn directions_default() -> u32 {
    145
}

/// A material's values per band.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialBands {
    /// Reflectance per band.
    pub reflectance: Vec<f64>,
    /// Transmittance per band.
    pub transmittance: Vec<f64>,
    /// Emission per band (W/m²).
    pub emission: Vec<f64>,
}

pub use crate::daylight::SunReport;

/// The scene's bands and daylight, per band.
#[derive(Clone, Debug, Default)]
pub struct Bands {
    /// Band names (`r`, `g`, `b` without `bands`).
    pub names: Vec<String>,
    /// Whether the file declared `bands` (else RGB).
    pub declared: bool,
    /// Per material (in the scene's material order), its values per band.
    pub materials: Vec<MaterialBands>,
    /// The site.
    pub site: Site,
    /// The sun's unit direction of travel and direct normal irradiance per band (None without a
    /// sun, or with one below the horizon).
    pub sun: Option<(DVec3, Vec<f64>)>,
    /// What the scene file's sun resolved to.
    pub sun_report: Option<SunReport>,
    /// The sky: model, diffuse horizontal irradiance per band, cells.
    pub sky: Option<(SkyModel, Vec<f64>, u32)>,
}

impl Bands {
    /// Number of bands.
    #[must_use]
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// True without bands (never: RGB has three).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Solves needed: one per three bands.
    #[must_use]
    pub fn packs(&self) -> usize {
        self.names.len().div_ceil(3).max(1)
    }

    /// The bands of pack `k` (indices into [`Bands::names`]).
    #[must_use]
    pub fn pack_range(&self, k: usize) -> std::ops::Range<usize> {
        3 * k..(3 * k + 3).min(self.names.len())
    }

    /// Whether the scene has daylight.
    #[must_use]
    pub fn has_daylight(&self) -> bool {
        self.sun.is_some() || self.sky.is_some()
    }

    /// `materials` with the values of pack `k` (bands past the last are zero).
    #[must_use]
    pub fn pack_materials(&self, k: usize, materials: &[Material]) -> Vec<Material> {
        materials
            .iter()
            .zip(&self.materials)
            .map(|(m, b)| Material {
                reflectance: pick(&b.reflectance, k),
                transmittance: pick(&b.transmittance, k),
                emission: pick(&b.emission, k),
                ..m.clone()
            })
            .collect()
    }

    /// The distant sources of pack `k`.
    #[must_use]
    pub fn pack_distant(&self, k: usize) -> Vec<DistantSource> {
        let mut out = Vec::new();
        if let Some((toward, dni)) = &self.sun {
            out.push(DistantSource { toward: *toward, irradiance: pick(dni, k), sharp: true, patch: None });
        }
        if let Some((model, dhi, n)) = &self.sky {
            out.extend(daylight::sky(*model, pick(dhi, k), *n, &self.site).expect("checked when read"));
        }
        out
    }
}

/// Values `3k .. 3k + 3` of `v`, zero past its end.
fn pick(v: &[f64], k: usize) -> [f64; 3] {
    std::array::from_fn(|c| v.get(3 * k + c).copied().unwrap_or(0.0))
}

/// What the file said, before it is checked: `bands`, `[site]`, `[sun]`, `[sky]`, and the
/// materials' colour values with their lines.
pub(super) struct BandsInput<'a> {
    pub(super) bands: Option<&'a [String]>,
    pub(super) site: Option<&'a SiteSpec>,
    pub(super) sun: Option<(&'a SunSpec, usize)>,
    pub(super) sky: Option<(&'a SkySpec, usize)>,
    /// Per material: reflectance, transmittance, emission, line.
    pub(super) materials: Vec<(ColorSpec, Option<ColorSpec>, Option<ColorSpec>, usize)>,
}

/// Checks and resolves the file's bands and daylight. `line` is where `bands` is (1 when absent).
pub(super) fn resolve(input: &BandsInput<'_>, path: &Path, line: usize) -> Result<Bands, InstancingError> {
    let names: Vec<String> = match input.bands {
        Some(names) => {
            if names.is_empty() || names.len() > MAX_BANDS {
                return Err(InstancingError::at(path, line, format!("`bands` needs 1 to {MAX_BANDS} names")));
            }
            for (i, n) in names.iter().enumerate() {
                if n.is_empty() || !n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
                    return Err(InstancingError::at(path, line, format!("band name `{n}`: use letters, digits, `_` or `-`")));
                }
                if names[..i].contains(n) {
                    return Err(InstancingError::at(path, line, format!("duplicate band `{n}`")));
                }
            }
            names.to_vec()
        }
        None => RGB_NAMES.iter().map(|s| (*s).to_owned()).collect(),
    };
    let n = names.len();
    let values = |c: &ColorSpec, what: &str, line: usize| c.values(n).map_err(|e| InstancingError::at(path, line, format!("{what}: {e}")));
    let mut materials = Vec::with_capacity(input.materials.len());
    for (r, t, e, line) in &input.materials {
        let zero = ColorSpec::Grey(0.0);
        let m = MaterialBands {
            reflectance: values(r, "reflectance", *line)?,
            transmittance: values(t.as_ref().unwrap_or(&zero), "transmittance", *line)?,
            emission: values(e.as_ref().unwrap_or(&zero), "emission", *line)?,
        };
        for b in 0..n {
            let (rho, tau) = (m.reflectance[b], m.transmittance[b]);
            if !(0.0..1.0).contains(&rho) || !(0.0..1.0).contains(&tau) || rho + tau >= 1.0 {
                return Err(InstancingError::at(
                    path,
                    *line,
                    format!("band `{}`: reflectance {rho} and transmittance {tau} must be in [0, 1) with a sum below 1", names[b]),
                ));
            }
            if !(m.emission[b] >= 0.0 && m.emission[b].is_finite()) {
                return Err(InstancingError::at(
                    path,
                    *line,
                    format!("band `{}`: emission {} must be finite and non-negative", names[b], m.emission[b]),
                ));
            }
        }
        materials.push(m);
    }
    let site = match input.site {
        Some(s) => {
            Site::new(DVec3::from(s.up), DVec3::from(s.north)).map_err(|e| InstancingError::at(path, line, format!("[site]: {e}")))?
        }
        None => Site::default(),
    };
    let (mut sun, mut sun_report) = (None, None);
    if let Some((s, line)) = input.sun {
        let fail = |e: String| InstancingError::at(path, line, format!("[sun]: {e}"));
        let dni = values(&s.direct_normal, "[sun] direct_normal", line)?;
        let (toward, azimuth) = match (s.direction, s.latitude, s.longitude, &s.time) {
            (Some(d), None, None, None) => (DVec3::from(d), None),
            (None, Some(lat), Some(lon), Some(time)) => {
                let (z, a) = daylight::sun_position(lat, lon, time).map_err(|e| fail(e.to_string()))?;
                (-site.direction(z.to_radians(), a.to_radians()), Some(a))
            }
            _ => return Err(fail("give either `direction`, or `latitude`, `longitude` and `time`".into())),
        };
        let arr = pick(&dni, 0);
        let source = daylight::sun(toward, arr, &site).map_err(|e| fail(e.to_string()))?;
        if dni.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(fail(format!("direct_normal {dni:?} must be finite and non-negative")));
        }
        let t = toward.normalize();
        sun_report = Some(SunReport {
            toward: t.to_array(),
            zenith_deg: (-t).dot(site.up).clamp(-1.0, 1.0).acos().to_degrees(),
            azimuth_deg: azimuth,
            above_horizon: source.is_some(),
        });
        if source.is_some() {
            sun = Some((t, dni));
        }
    }
    let mut sky = None;
    if let Some((s, line)) = input.sky {
        let dhi = values(&s.diffuse_horizontal, "[sky] diffuse_horizontal", line)?;
        if dhi.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(InstancingError::at(path, line, format!("[sky]: diffuse_horizontal {dhi:?} must be finite and non-negative")));
        }
        daylight::sky_cells(s.directions).map_err(|e| InstancingError::at(path, line, format!("[sky]: {e}")))?;
        let model = sky_model(s, sun_report.as_ref(), &site).map_err(|e| InstancingError::at(path, line, format!("[sky]: {e}")))?;
        sky = Some((model, dhi, s.directions));
    }
    Ok(Bands { names, declared: input.bands.is_some(), materials, site, sun, sun_report, sky })
}

/// The sky model `[sky]` names; a CIE general or a Perez sky takes the sun's position from `[sun]`.
fn sky_model(s: &SkySpec, sun: Option<&SunReport>, site: &Site) -> Result<SkyModel, String> {
    let perez = (s.clearness, s.brightness);
    if s.model != SkyModelName::Perez && (perez.0.is_some() || perez.1.is_some()) {
        return Err("`clearness` and `brightness` apply to model = \"perez\" only".into());
    }
    if s.model != SkyModelName::CieGeneral && s.sky_type.is_some() {
        return Err("`type` applies to model = \"cie-general\" only".into());
    }
    // The sun's zenith angle and azimuth (clockwise from north) in the site's frame.
    let sun_position = |model: &str| -> Result<(f64, f64), String> {
        let Some(sun) = sun else {
            return Err(format!("model \"{model}\" needs the sun's position: give [sun] (`direct_normal = 0` leaves its beam out)"));
        };
        let to_sun = -DVec3::from(sun.toward);
        let zenith = to_sun.dot(site.up).clamp(-1.0, 1.0).acos();
        Ok((zenith, to_sun.dot(site.east()).atan2(to_sun.dot(site.north))))
    };
    match s.model {
        SkyModelName::Uniform => Ok(SkyModel::Uniform),
        SkyModelName::CieOvercast => Ok(SkyModel::CieOvercast),
        SkyModelName::CieGeneral => {
            let Some(t) = s.sky_type else { return Err("model \"cie-general\" needs `type` (1 to 15)".into()) };
            let (zenith, azimuth) = sun_position("cie-general")?;
            Ok(SkyModel::CieGeneral(daylight::CieSky::new(t, zenith, azimuth).map_err(|e| e.to_string())?))
        }
        SkyModelName::Perez => {
            let (Some(clearness), Some(brightness)) = perez else {
                return Err("model \"perez\" needs `clearness` and `brightness` (the sky's ε and Δ)".into());
            };
            let (zenith, azimuth) = sun_position("perez")?;
            Ok(SkyModel::Perez(daylight::PerezSky::new(clearness, brightness, zenith, azimuth).map_err(|e| e.to_string())?))
        }
    }
}
