//! Calculation grids: regular lattices of calculation points over a parallelogram (a work plane or
//! a task area, as EN 12464-1 defines them), and the figures lighting standards read from them
//! (average, minimum, maximum, uniformity U0).
//!
//! A grid is `origin + s·u + t·v`, `s, t ∈ [0, 1]`, cut into `n_u × n_v` equal cells, `n_u =
//! ⌈|u| / spacing⌉` (and `n_v` alike), with one point at the centre of each cell: points every
//! `spacing` or a little closer, half a cell in from the edges, as EN 12464-1 places them. When
//! `|u|` is a multiple of the spacing, the points are exactly `spacing` apart and half a spacing
//! from the edges.

use super::CalcPoint;
use crate::geom::DVec3;
use crate::photometry::Units;
use crate::scene::Scene;

/// Most points a grid may have.
pub const MAX_GRID_POINTS: usize = 1_000_000;

/// A length that is this close (relative) to a multiple of the spacing counts as that multiple.
pub const SPACING_REL_TOL: f64 = 1e-9;

/// `|u × v|` below this times `|u|·|v|` is a degenerate (flat) parallelogram.
pub const DEGENERATE_SIN: f64 = 1e-9;

/// EN 12464-1's border zone: the work plane keeps this far (scene units, metres) from the walls.
pub const EN12464_BORDER_M: f64 = 0.5;

/// A polygon is part of the floor when its normal is within this cosine of the up axis (1°).
pub const FLOOR_MIN_COS: f64 = 0.999_847_695;

/// Up-facing polygons within this distance (relative to the scene's diagonal) of the lowest one are
/// the floor.
pub const FLOOR_HEIGHT_REL_TOL: f64 = 1e-6;

/// `[[grid]]` in a scene file, or `--grid` on the command line: a parallelogram of calculation
/// points (see the module documentation).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// Name: the output is `grid_<name>.csv` (letters, digits, `-`, `_`).
    pub name: String,
    /// A corner of the parallelogram (scene units).
    pub origin: [f64; 3],
    /// The first edge from `origin`.
    pub u: [f64; 3],
    /// The second edge from `origin`.
    pub v: [f64; 3],
    /// Largest distance between points (scene units).
    pub spacing: f64,
    /// The side the receivers face; need not be unit length (it is normalised). `None`: `u × v`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
}

/// A bad grid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridError {
    /// The grid is invalid.
    #[error("grid `{grid}`: {msg}")]
    Invalid {
        /// Its name.
        grid: String,
        /// What is wrong.
        msg: String,
    },
    /// `--grid` could not be read.
    #[error("--grid `{arg}`: {msg}")]
    Arg {
        /// The argument.
        arg: String,
        /// What is wrong.
        msg: String,
    },
    /// No work plane could be placed in the scene.
    #[error("--work-plane: {0}")]
    WorkPlane(String),
}

/// A grid's points: `n_u × n_v` points, `points[j·n_u + i]` at the centre of cell `(i, j)`,
/// `i` along `u` and `j` along `v`, named `<grid>_<i>_<j>`.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// The spec it was made from.
    pub spec: GridSpec,
    /// Points along `u`.
    pub n_u: usize,
    /// Points along `v`.
    pub n_v: usize,
    /// The unit normal of every point.
    pub normal: DVec3,
    /// The points, row by row along `u`.
    pub points: Vec<CalcPoint>,
}

/// The figures of a grid, on the photopic value of its points (lx in photometric scenes, W/m² in
/// radiometric ones), as `stats.json` holds them under `grids`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GridSummary {
    /// Points.
    pub points: usize,
    /// Average Ē.
    pub e_avg: f64,
    /// Minimum.
    pub e_min: f64,
    /// Maximum.
    pub e_max: f64,
    /// Uniformity U0 = e_min / e_avg (0 when e_avg is 0).
    pub u0: f64,
    /// e_min / e_max (0 when e_max is 0).
    pub min_over_max: f64,
    /// The largest estimated error of a point's value, same unit (`None`: not estimated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub e_err_max: Option<f64>,
    /// The grid's daylight factors, in a scene lit by a sky alone (see
    /// [`GridSummary::with_daylight_factor`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub daylight_factor: Option<DaylightFactorFigures>,
}

/// A grid's daylight factors, `DF = 100 · E ÷ E_outside` in %, `E_outside` the illuminance the sky
/// gives an unobstructed horizontal plane ([`crate::daylight::sky_alone_horizontal`]). EN 17037
/// asks for a target factor over half of a room's reference plane and a minimum one over 95% of
/// it: `median` and `over_95` are those figures of the grid.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DaylightFactorFigures {
    /// `E_outside` (the photopic value, in the grid's unit).
    pub outside: f64,
    /// The mean factor (%).
    pub mean: f64,
    /// The factor reached at half of the points or more (%).
    pub median: f64,
    /// The factor reached at 95% of the points or more (%).
    pub over_95: f64,
    /// The smallest (%).
    pub min: f64,
    /// The largest (%).
    pub max: f64,
    /// The largest estimated error of a point's factor (%; `None`: not estimated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub err_max: Option<f64>,
}

/// The largest value reached by at least `share` of `values` (sorted from the largest down).
fn reached_by(sorted_down: &[f64], share: f64) -> f64 {
    let k = ((share * sorted_down.len() as f64).ceil() as usize).clamp(1, sorted_down.len());
    sorted_down[k - 1]
}

/// The name of the photopic column of `grid_<name>.csv` (and of the figures): `e_lx` in
/// photometric scenes, `h_photopic` (as in `points.csv`) in radiometric ones.
#[must_use]
pub fn photopic_column(units: Units) -> &'static str {
    match units {
        Units::Photometric => "e_lx",
        Units::Radiometric => "h_photopic",
    }
}

/// The unit of the photopic value: `lx` or `W/m²`.
#[must_use]
pub fn photopic_unit(units: Units) -> &'static str {
    match units {
        Units::Photometric => "lx",
        Units::Radiometric => "W/m²",
    }
}

impl GridSummary {
    /// The figures of `values` (the photopic value of each point); `None` when there is none or
    /// one is not finite. Without errors: [`GridSummary::with_errors`] adds them.
    #[must_use]
    pub fn of(values: &[f64]) -> Option<GridSummary> {
        if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let e_avg = values.iter().sum::<f64>() / values.len() as f64;
        let e_min = values.iter().copied().fold(f64::INFINITY, f64::min);
        let e_max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
        Some(GridSummary {
            points: values.len(),
            e_avg,
            e_min,
            e_max,
            u0: ratio(e_min, e_avg),
            min_over_max: ratio(e_min, e_max),
            e_err_max: None,
            daylight_factor: None,
        })
    }

    /// The same figures with the largest of the points' estimated errors `errors` (same unit);
    /// none when one is not finite (the solve had no estimate).
    #[must_use]
    pub fn with_errors(mut self, errors: &[f64]) -> GridSummary {
        self.e_err_max = errors.iter().all(|e| e.is_finite()).then(|| errors.iter().copied().fold(0.0, f64::max));
        self
    }

    /// The same figures with the daylight factors of `values` (the points' photopic values, as
    /// given to [`GridSummary::of`]) relative to `outside` ([`DaylightFactorFigures`]), their
    /// largest error from `errors` (none when one is not finite); unchanged when `outside` is not
    /// positive or `values` is empty.
    #[must_use]
    pub fn with_daylight_factor(mut self, values: &[f64], errors: &[f64], outside: f64) -> GridSummary {
        if !(outside.is_finite() && outside > 0.0) || values.is_empty() {
            return self;
        }
        let df: Vec<f64> = values.iter().map(|v| 100.0 * v / outside).collect();
        let mut sorted = df.clone();
        sorted.sort_by(|a, b| b.total_cmp(a));
        self.daylight_factor = Some(DaylightFactorFigures {
            outside,
            mean: df.iter().sum::<f64>() / df.len() as f64,
            median: reached_by(&sorted, 0.5),
            over_95: reached_by(&sorted, 0.95),
            min: sorted[sorted.len() - 1],
            max: sorted[0],
            err_max: errors.iter().all(|e| e.is_finite()).then(|| 100.0 * errors.iter().copied().fold(0.0, f64::max) / outside),
        });
        self
    }
}

impl GridSpec {
    /// Checks the spec: a name of letters, digits, `-` and `_`; finite numbers; `spacing > 0`;
    /// `u` and `v` not parallel nor zero; a non-zero normal; at most [`MAX_GRID_POINTS`] points.
    pub fn validate(&self) -> Result<(), GridError> {
        self.grid().map(|_| ())
    }

    /// The grid's points (see [`Grid`]), or why the spec is invalid ([`GridSpec::validate`]).
    pub fn grid(&self) -> Result<Grid, GridError> {
        let err = |msg: String| GridError::Invalid { grid: self.name.clone(), msg };
        if self.name.is_empty() || !self.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_') {
            return Err(err("name must be letters, digits, `-` or `_`".into()));
        }
        let vectors = [("origin", Some(self.origin)), ("u", Some(self.u)), ("v", Some(self.v)), ("normal", self.normal)];
        for (what, x) in vectors {
            if let Some(x) = x.filter(|x| x.iter().any(|c| !c.is_finite())) {
                return Err(err(format!("`{what}` = {x:?} is not finite")));
            }
        }
        if !(self.spacing.is_finite() && self.spacing > 0.0) {
            return Err(err(format!("`spacing` must be positive, found {}", self.spacing)));
        }
        let (origin, u, v) = (DVec3::from_array(self.origin), DVec3::from_array(self.u), DVec3::from_array(self.v));
        let cross = u.cross(v);
        // Finite here: u and v were checked.
        if cross.length() <= DEGENERATE_SIN * u.length() * v.length() {
            return Err(err("`u` and `v` must be non-zero and not parallel".into()));
        }
        let normal = match self.normal {
            Some(n) => DVec3::from_array(n).try_normalize().ok_or_else(|| err("`normal` must not be zero".into()))?,
            None => cross.normalize(),
        };
        let count = |len: f64| ((len / self.spacing) * (1.0 - SPACING_REL_TOL)).ceil().max(1.0);
        let (fu, fv) = (count(u.length()), count(v.length()));
        if fu * fv > MAX_GRID_POINTS as f64 {
            return Err(err(format!("{fu} × {fv} points is more than {MAX_GRID_POINTS}: use a larger `spacing`")));
        }
        let (n_u, n_v) = (fu as usize, fv as usize);
        let mut points = Vec::with_capacity(n_u * n_v);
        for j in 0..n_v {
            for i in 0..n_u {
                let (s, t) = ((i as f64 + 0.5) / n_u as f64, (j as f64 + 0.5) / n_v as f64);
                let position = origin + s * u + t * v;
                points.push(CalcPoint { name: format!("{}_{i}_{j}", self.name), position, normal });
            }
        }
        Ok(Grid { spec: self.clone(), n_u, n_v, normal, points })
    }

    /// Reads `--grid`: comma-separated `key=value` pairs, the keys of [`GridSpec`], vectors as
    /// three numbers separated by `;` (or spaces), `normal` optional:
    /// `name=work,origin=0.5;0.5;0.8,u=3;0;0,v=0;3;0,spacing=0.25,normal=0;0;1`. The spec is
    /// validated.
    pub fn parse_arg(arg: &str) -> Result<GridSpec, GridError> {
        let err = |msg: String| GridError::Arg { arg: arg.to_owned(), msg };
        let (mut name, mut origin, mut u, mut v, mut spacing, mut normal) = (None, None, None, None, None, None);
        for pair in arg.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let (key, value) = pair.split_once('=').ok_or_else(|| err(format!("expected `key=value`, found `{pair}`")))?;
            let (key, value) = (key.trim(), value.trim());
            let vector = || -> Result<[f64; 3], GridError> {
                let parts: Vec<&str> = value.split([';', ' ']).filter(|s| !s.is_empty()).collect();
                let numbers: Option<Vec<f64>> = parts.iter().map(|s| s.parse::<f64>().ok()).collect();
                match numbers {
                    Some(n) if n.len() == 3 => Ok([n[0], n[1], n[2]]),
                    _ => Err(err(format!("`{key}` needs three numbers separated by `;`, found `{value}`"))),
                }
            };
            let slot_taken = match key {
                "name" => name.replace(value.to_owned()).is_some(),
                "origin" => origin.replace(vector()?).is_some(),
                "u" => u.replace(vector()?).is_some(),
                "v" => v.replace(vector()?).is_some(),
                "normal" => normal.replace(vector()?).is_some(),
                "spacing" => {
                    let s = value.parse::<f64>().map_err(|_| err(format!("`spacing` needs a number, found `{value}`")))?;
                    spacing.replace(s).is_some()
                }
                _ => return Err(err(format!("unknown key `{key}` (expected name, origin, u, v, spacing, normal)"))),
            };
            if slot_taken {
                return Err(err(format!("`{key}` given twice")));
            }
        }
        let missing = |what: &str| err(format!("missing `{what}`"));
        let spec = GridSpec {
            name: name.ok_or_else(|| missing("name"))?,
            origin: origin.ok_or_else(|| missing("origin"))?,
            u: u.ok_or_else(|| missing("u"))?,
            v: v.ok_or_else(|| missing("v"))?,
            spacing: spacing.ok_or_else(|| missing("spacing"))?,
            normal,
        };
        spec.validate()?;
        Ok(spec)
    }
}

/// The axis that points up in a scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UpAxis {
    /// +x.
    X,
    /// +y.
    Y,
    /// +z (the default).
    #[default]
    Z,
}

impl UpAxis {
    /// `(up, a, b)`: the axis indices of up and of the two horizontal axes, with `a × b = up`.
    #[must_use]
    fn axes(self) -> (usize, usize, usize) {
        match self {
            UpAxis::X => (0, 1, 2),
            UpAxis::Y => (1, 2, 0),
            UpAxis::Z => (2, 0, 1),
        }
    }
}

/// EN 12464-1's largest grid spacing for an area whose longer side is `d` metres:
/// `p = 0.2 · 5^log10(d)` (at most 10 m).
#[must_use]
pub fn en12464_spacing(d: f64) -> f64 {
    (0.2 * 5f64.powf(d.max(f64::MIN_POSITIVE).log10())).min(10.0)
}

/// A grid named `work`, facing up, `height` above the scene's floor, over the floor's extent less
/// a border zone `border` wide on every side (EN 12464-1: [`EN12464_BORDER_M`]), with points
/// `spacing` apart at most (`None`: [`en12464_spacing`] of the longer side).
///
/// The floor is the set of polygons facing up (normal within 1° of the up axis,
/// [`FLOOR_MIN_COS`]) at the lowest height among them ([`FLOOR_HEIGHT_REL_TOL`]); its extent is
/// the bounding rectangle of their vertices on the two horizontal axes. Errors when no polygon
/// faces up, or the border leaves nothing.
pub fn work_plane(scene: &Scene, height: f64, up: UpAxis, border: f64, spacing: Option<f64>) -> Result<GridSpec, GridError> {
    let err = |msg: String| GridError::WorkPlane(msg);
    if !height.is_finite() || !border.is_finite() || border < 0.0 {
        return Err(err(format!("height {height} and border {border} must be finite, the border not negative")));
    }
    let (k, a, b) = up.axes();
    let up_name = ["x", "y", "z"][k];
    let facing: Vec<&crate::scene::Polygon> = scene.polygons.iter().filter(|p| p.poly.normal()[k] >= FLOOR_MIN_COS).collect();
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in &scene.polygons {
        for x in p.poly.vertices() {
            (lo, hi) = (lo.min(*x), hi.max(*x));
        }
    }
    let tol = FLOOR_HEIGHT_REL_TOL * (hi - lo).length();
    let Some(floor) = facing.iter().map(|p| p.poly.vertices()[0][k]).reduce(f64::min) else {
        return Err(err(format!("no floor: no polygon faces up (+{up_name}); choose the up axis with --up")));
    };
    let (mut amin, mut amax, mut bmin, mut bmax) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for p in facing.iter().filter(|p| p.poly.vertices()[0][k] <= floor + tol) {
        for x in p.poly.vertices() {
            (amin, amax, bmin, bmax) = (amin.min(x[a]), amax.max(x[a]), bmin.min(x[b]), bmax.max(x[b]));
        }
    }
    let (la, lb) = (amax - amin - 2.0 * border, bmax - bmin - 2.0 * border);
    if !(la > 0.0 && lb > 0.0) {
        return Err(err(format!(
            "the floor is {} × {} (at {up_name} = {floor}): no room inside a border zone of {border}",
            amax - amin,
            bmax - bmin
        )));
    }
    let spacing = spacing.unwrap_or_else(|| en12464_spacing(la.max(lb)));
    let mut origin = [0.0; 3];
    (origin[k], origin[a], origin[b]) = (floor + height, amin + border, bmin + border);
    let (mut u, mut v, mut normal) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    (u[a], v[b], normal[k]) = (la, lb, 1.0);
    let spec = GridSpec { name: "work".into(), origin, u, v, spacing, normal: Some(normal) };
    spec.validate()?;
    Ok(spec)
}

#[cfg(test)]
mod tests;
