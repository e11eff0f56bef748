//! The entries of a scene file as read (`[[material]]`, `[[instance]]`, `[[box]]`, `[[polygon]]`,
//! `[[luminaire]]`), and the transform an instance entry describes.

use crate::geom::DVec3;
use crate::instancing::model::Transform;
use serde::{Deserialize, Serialize};

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
