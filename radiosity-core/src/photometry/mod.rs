//! Photometric data: luminous intensity distributions of luminaires, read from IES LM-63
//! ([`read_ies`]) and EULUMDAT ([`read_ldt`]) files, type C only.
//!
//! A [`Photometry`] is a table of intensities (cd) over vertical angles γ (0 = nadir, the
//! luminaire's aim) and horizontal angles C (the C planes), with the file's symmetry kept:
//! one plane (axially symmetric), planes up to 90° (quadrant symmetric), up to 180° (bilateral
//! about the C0–C180 plane), or the full circle. [`Photometry::intensity`] interpolates it
//! bilinearly and [`Photometry::flux`] integrates that interpolation exactly over the sphere.

mod ies;
mod ldt;

pub use ies::{parse_ies, read_ies};
pub use ldt::{parse_ldt, read_ldt};

use std::path::Path;

/// Units of a scene: radiometric (W, W/m²) or photometric (lm, cd, lx).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Units {
    /// Watts, W/m² (the default).
    #[default]
    Radiometric,
    /// Lumens, candelas, lux.
    Photometric,
}

impl Units {
    /// The unit of radiosity and irradiance in files: `W/m2` or `lm/m2` (irradiance in lm/m² is
    /// lux).
    #[must_use]
    pub fn density_label(self) -> &'static str {
        match self {
            Units::Radiometric => "W/m2",
            Units::Photometric => "lm/m2",
        }
    }

    /// The unit of power: `W` or `lm`.
    #[must_use]
    pub fn power_label(self) -> &'static str {
        match self {
            Units::Radiometric => "W",
            Units::Photometric => "lm",
        }
    }
}

/// A photometric file that cannot be read, or holds bad data.
///
/// Display is one line: `FILE:LINE: reason`, or `FILE: reason` when no line is to blame.
#[derive(Debug, thiserror::Error)]
pub enum PhotometryError {
    /// The file could not be read.
    #[error("{source_name}: cannot read file: {error}")]
    Io {
        /// The file.
        source_name: String,
        /// The operating system's reason.
        error: std::io::Error,
    },
    /// Bad data on a line.
    #[error("{source_name}:{line}: {msg}")]
    Parse {
        /// The file.
        source_name: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// Bad data not tied to one line (a missing part, an unknown extension).
    #[error("{source_name}: {msg}")]
    File {
        /// The file.
        source_name: String,
        /// What is wrong.
        msg: String,
    },
}

impl PhotometryError {
    pub(crate) fn at(source: &str, line: usize, msg: impl Into<String>) -> PhotometryError {
        PhotometryError::Parse { source_name: source.to_owned(), line, msg: msg.into() }
    }

    pub(crate) fn file(source: &str, msg: impl Into<String>) -> PhotometryError {
        PhotometryError::File { source_name: source.to_owned(), msg: msg.into() }
    }
}

/// Most vertical or horizontal angles a file may list (files hold a few hundred at most).
pub const MAX_ANGLES: usize = 10_000;

/// Most intensity values a file may hold.
pub const MAX_VALUES: usize = 4_000_000;

/// Two angles closer than this (degrees) are the same angle: a last C plane at 360° − this or
/// above closes the circle, and symmetric planes are matched to this.
pub const ANGLE_TOL_DEG: f64 = 1e-6;

/// A type C luminous intensity distribution.
#[derive(Clone, Debug)]
pub struct Photometry {
    /// Vertical angles γ in degrees, ascending, within [0, 180] (0 = nadir, the luminaire's aim).
    pub gamma: Vec<f64>,
    /// Horizontal angles C in degrees, ascending, starting at 0, as the file gives them (one angle 0: axially symmetric; up to 90: quadrant symmetric; up to 180: bilateral symmetric about the C0–C180 plane; up to 360 or 355-ish: full).
    pub c: Vec<f64>,
    /// Intensities in cd, `candela[i_c][i_gamma]`, with every multiplier of the file applied (IES: candela multiplier and ballast factor; LDT: per-1000-lm values times the lamps' flux / 1000).
    pub candela: Vec<Vec<f64>>,
    /// Luminous flux of the lamps as the file declares it (lm), when it does (IES: lamps × lumens per lamp; -1 = absolute photometry → None).
    pub declared_lumens: Option<f64>,
    /// Luminous opening (m): width (along C90), length (along C0), height; zeros for a point.
    pub opening: [f64; 3],
    /// Where it came from (file name), for messages.
    pub source: String,
}

/// The symmetry of a table, from its last C plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symmetry {
    /// One plane: the same in every C plane.
    Axial,
    /// Planes 0–90°: symmetric about the C0–C180 and C90–C270 planes.
    Quadrant,
    /// Planes 0–180°: symmetric about the C0–C180 plane.
    Bilateral,
    /// Planes over the whole circle (the last one at or below 360°).
    Full,
}

impl Photometry {
    /// The symmetry the C planes imply (see [`Photometry::c`]); `None` for a table
    /// [`Photometry::validate`] refuses.
    #[must_use]
    pub fn symmetry(&self) -> Option<Symmetry> {
        let last = *self.c.last()?;
        match self.c.len() {
            1 if last.abs() <= ANGLE_TOL_DEG => Some(Symmetry::Axial),
            _ if (last - 90.0).abs() <= ANGLE_TOL_DEG => Some(Symmetry::Quadrant),
            _ if (last - 180.0).abs() <= ANGLE_TOL_DEG => Some(Symmetry::Bilateral),
            _ if last > 180.0 && last <= 360.0 + ANGLE_TOL_DEG => Some(Symmetry::Full),
            _ => None,
        }
    }

    /// Checks the table: angles finite and strictly ascending, γ within [0, 180], C starting at 0
    /// and ending at 0 (one plane), 90, 180 or above 180 up to 360, one row of finite, non-negative
    /// intensities per C plane with one value per γ. The message says what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        if self.gamma.is_empty() || self.c.is_empty() {
            return Err("no angles".into());
        }
        ascending(&self.gamma, "vertical")?;
        ascending(&self.c, "horizontal")?;
        if self.gamma[0] < 0.0 || self.gamma[self.gamma.len() - 1] > 180.0 {
            return Err(format!(
                "vertical angles must lie within [0, 180], found {} to {}",
                self.gamma[0],
                self.gamma[self.gamma.len() - 1]
            ));
        }
        if self.c[0].abs() > ANGLE_TOL_DEG {
            return Err(format!("the first horizontal angle must be 0, found {}", self.c[0]));
        }
        if self.symmetry().is_none() {
            return Err(format!(
                "the last horizontal angle must be 0 (one plane), 90, 180, or above 180 up to 360, found {}",
                self.c[self.c.len() - 1]
            ));
        }
        if self.candela.len() != self.c.len() || self.candela.iter().any(|row| row.len() != self.gamma.len()) {
            return Err(format!("expected {} × {} intensities", self.c.len(), self.gamma.len()));
        }
        if let Some(v) = self.candela.iter().flatten().find(|v| !v.is_finite() || **v < 0.0) {
            return Err(format!("intensity {v} is not a finite non-negative number"));
        }
        Ok(())
    }

    /// Intensity (cd) at (C, γ) degrees, any values (wrapped/reflected by the symmetry), bilinear in the table; 0 beyond the last γ if it is below 180.
    ///
    /// γ is reflected into [0, 180] (γ and −γ, and γ and 360 − γ, are the same direction), and so is
    /// 0 before the first γ if that is above 0. C is taken modulo 360, then reflected into the
    /// planes the symmetry keeps; a full table wraps from its last plane to the first at 360°.
    /// Non-finite angles give 0.
    #[must_use]
    pub fn intensity(&self, c_deg: f64, gamma_deg: f64) -> f64 {
        if !(c_deg.is_finite() && gamma_deg.is_finite()) || self.candela.is_empty() {
            return 0.0;
        }
        let mut g = gamma_deg.rem_euclid(360.0);
        if g > 180.0 {
            g = 360.0 - g;
        }
        let Some((ig, tg)) = bracket(&self.gamma, g) else { return 0.0 };
        let row = |i: usize| {
            let r = &self.candela[i];
            if tg == 0.0 { r[ig] } else { r[ig] * (1.0 - tg) + r[ig + 1] * tg }
        };
        let (i0, i1, tc) = self.c_bracket(c_deg);
        let a = row(i0);
        if tc == 0.0 { a } else { a * (1.0 - tc) + row(i1) * tc }
    }

    /// The C planes around `c_deg` (any value) and the weight of the second: `(i0, i1, t)`.
    fn c_bracket(&self, c_deg: f64) -> (usize, usize, f64) {
        let mut c = c_deg.rem_euclid(360.0);
        match self.symmetry() {
            Some(Symmetry::Axial) | None => return (0, 0, 0.0),
            Some(Symmetry::Quadrant) => {
                if c > 180.0 {
                    c = 360.0 - c;
                }
                if c > 90.0 {
                    c = 180.0 - c;
                }
            }
            Some(Symmetry::Bilateral) => {
                if c > 180.0 {
                    c = 360.0 - c;
                }
            }
            Some(Symmetry::Full) => {
                let n = self.c.len();
                let last = self.c[n - 1];
                if c > last {
                    // Between the last plane and the first one at 360°.
                    let span = 360.0 - last;
                    let t = if span > ANGLE_TOL_DEG { (c - last) / span } else { 0.0 };
                    return (n - 1, 0, t);
                }
            }
        }
        match bracket(&self.c, c) {
            Some((i, t)) => (i, (i + 1).min(self.c.len() - 1), t),
            None => (self.c.len() - 1, self.c.len() - 1, 0.0),
        }
    }

    /// Luminous flux (lm) from integrating the table over the sphere, consistent with `intensity` (e.g. zonal: sum of I·dΩ per zone with the table's interpolation; must reproduce Φ = π·I0 for I = I0 cos γ, γ ∈ [0, 90], to 1e-3 relative even on a 5° table).
    ///
    /// The integral of the bilinear interpolation is exact: over a cell, the C direction averages
    /// the two planes, and `∫ (linear in γ) sin γ dγ` has a closed form.
    #[must_use]
    pub fn flux(&self) -> f64 {
        let profile = |i: usize| self.profile_integral(i);
        let c = &self.c;
        let between = |i: usize, j: usize, dc_deg: f64| dc_deg.to_radians() * 0.5 * (profile(i) + profile(j));
        match self.symmetry() {
            None => 0.0,
            Some(Symmetry::Axial) => std::f64::consts::TAU * profile(0),
            Some(s) => {
                let mut sum: f64 = (0..c.len() - 1).map(|i| between(i, i + 1, c[i + 1] - c[i])).sum();
                match s {
                    Symmetry::Quadrant => sum *= 4.0,
                    Symmetry::Bilateral => sum *= 2.0,
                    _ => sum += between(c.len() - 1, 0, 360.0 - c[c.len() - 1]),
                }
                sum
            }
        }
    }

    /// `∫ I(γ) sin γ dγ` over the table's γ for C plane `i`, γ interpolated linearly.
    fn profile_integral(&self, i: usize) -> f64 {
        let row = &self.candela[i];
        self.gamma
            .windows(2)
            .zip(row.windows(2))
            .map(|(g, v)| {
                let (a, b) = (g[0].to_radians(), g[1].to_radians());
                let d = b - a;
                let s0 = a.cos() - b.cos();
                // ∫ (γ − a)/d · sin γ dγ over [a, b].
                let s1 = ((a.cos() - b.cos()) * (-a) + (-b * b.cos() + b.sin() + a * a.cos() - a.sin())) / d;
                v[0] * (s0 - s1) + v[1] * s1
            })
            .sum()
    }

    /// Scales every intensity (a luminaire's multiplier).
    #[must_use]
    pub fn scaled(&self, k: f64) -> Photometry {
        Photometry {
            candela: self.candela.iter().map(|row| row.iter().map(|v| v * k).collect()).collect(),
            declared_lumens: self.declared_lumens.map(|l| l * k),
            ..self.clone()
        }
    }

    /// The largest intensity of the table (cd).
    #[must_use]
    pub fn max_intensity(&self) -> f64 {
        self.candela.iter().flatten().fold(0.0, |m, &v| m.max(v))
    }
}

/// Reads by extension (.ies / .ldt, case-insensitive).
pub fn read(path: &Path) -> Result<Photometry, PhotometryError> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("ies") => read_ies(path),
        Some("ldt") => read_ldt(path),
        _ => Err(PhotometryError::file(&path.display().to_string(), "unknown photometric file type (expected .ies or .ldt)")),
    }
}

/// The text of `path`, or the error naming it.
pub(crate) fn read_text(path: &Path) -> Result<String, PhotometryError> {
    let bytes = std::fs::read(path).map_err(|error| PhotometryError::Io { source_name: path.display().to_string(), error })?;
    // Photometric files are ASCII in practice, Latin-1 in some old ones: keep any byte.
    Ok(match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.into_bytes().iter().map(|&b| b as char).collect(),
    })
}

/// `Err` unless `v` is strictly ascending and finite.
fn ascending(v: &[f64], what: &str) -> Result<(), String> {
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(format!("{what} angle {x} is not a finite number"));
    }
    match v.windows(2).find(|w| w[1] <= w[0]) {
        Some(w) => Err(format!("{what} angles must be strictly ascending, found {} then {}", w[0], w[1])),
        None => Ok(()),
    }
}

/// The interval of ascending `v` holding `x`: `(i, t)` with `x = v[i] + t·(v[i+1] − v[i])`, or
/// `(i, 0)` at a single point; `None` when `x` lies outside.
fn bracket(v: &[f64], x: f64) -> Option<(usize, f64)> {
    let n = v.len();
    if n == 0 || x < v[0] - ANGLE_TOL_DEG || x > v[n - 1] + ANGLE_TOL_DEG {
        return None;
    }
    if n == 1 {
        return Some((0, 0.0));
    }
    let i = v.partition_point(|&a| a <= x).clamp(1, n - 1) - 1;
    let t = ((x - v[i]) / (v[i + 1] - v[i])).clamp(0.0, 1.0);
    Some((i, t))
}

/// Numbers of a text with the line each starts on, split at whitespace and commas.
pub(crate) struct Tokens<'a> {
    items: Vec<(&'a str, usize)>,
    pos: usize,
    /// Last line of the text, for errors at its end.
    end_line: usize,
    source: &'a str,
}

impl<'a> Tokens<'a> {
    /// The tokens of `lines`, the first of which is line `first_line` (1-based).
    pub(crate) fn new(lines: impl Iterator<Item = &'a str>, first_line: usize, source: &'a str) -> Tokens<'a> {
        let mut items = Vec::new();
        let mut end_line = first_line.saturating_sub(1);
        for (k, line) in lines.enumerate() {
            end_line = first_line + k;
            items.extend(line.split(|ch: char| ch.is_whitespace() || ch == ',').filter(|t| !t.is_empty()).map(|t| (t, end_line)));
        }
        Tokens { items, pos: 0, end_line: end_line.max(1), source }
    }

    /// The next number, `what` naming it in errors; NaN and infinities are refused.
    pub(crate) fn number(&mut self, what: &str) -> Result<(f64, usize), PhotometryError> {
        let Some(&(t, line)) = self.items.get(self.pos) else {
            return Err(PhotometryError::at(self.source, self.end_line, format!("file ends before {what}")));
        };
        self.pos += 1;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok((v, line)),
            _ => Err(PhotometryError::at(self.source, line, format!("{what}: `{t}` is not a finite number"))),
        }
    }

    /// The next number as a count within `1..=max`.
    pub(crate) fn count(&mut self, what: &str, max: usize) -> Result<usize, PhotometryError> {
        let (v, line) = self.number(what)?;
        if v.fract() != 0.0 || v < 1.0 || v > max as f64 {
            return Err(PhotometryError::at(self.source, line, format!("{what} must be a whole number from 1 to {max}, found {v}")));
        }
        Ok(v as usize)
    }

    /// `n` numbers, each checked by `check` (its message names the reason).
    pub(crate) fn numbers(&mut self, n: usize, what: &str, check: impl Fn(f64) -> Result<(), String>) -> Result<Vec<f64>, PhotometryError> {
        let mut out = Vec::with_capacity(n);
        for k in 0..n {
            let (v, line) = self.number(&format!("{what} {} of {n}", k + 1))?;
            check(v).map_err(|msg| PhotometryError::at(self.source, line, format!("{what} {} of {n}: {msg}", k + 1)))?;
            out.push(v);
        }
        Ok(out)
    }

    /// Line of the last token read (or of the end).
    pub(crate) fn line(&self) -> usize {
        self.pos.checked_sub(1).and_then(|p| self.items.get(p)).map_or(self.end_line, |t| t.1)
    }

    /// `Err` if tokens are left.
    pub(crate) fn finish(&self, after: &str) -> Result<(), PhotometryError> {
        match self.items.get(self.pos) {
            Some(&(t, line)) => Err(PhotometryError::at(
                self.source,
                line,
                format!("unexpected `{t}` after {after} ({} values too many)", self.items.len() - self.pos),
            )),
            None => Ok(()),
        }
    }
}

/// `Err` for a negative intensity.
pub(crate) fn non_negative(v: f64) -> Result<(), String> {
    if v < 0.0 { Err(format!("negative intensity {v}")) } else { Ok(()) }
}

/// `Err` unless the angles are strictly ascending and within `[lo, hi]`; `line` is where they end.
pub(crate) fn check_angles(v: &[f64], what: &str, lo: f64, hi: f64, source: &str, line: usize) -> Result<(), PhotometryError> {
    ascending(v, what).map_err(|msg| PhotometryError::at(source, line, msg))?;
    if let Some(x) = v.iter().find(|&&x| x < lo || x > hi) {
        return Err(PhotometryError::at(source, line, format!("{what} angle {x} lies outside [{lo}, {hi}]")));
    }
    Ok(())
}

#[cfg(test)]
mod tests;
