//! Photometric data (temporary: replaced by the readers' module at merge).

/// Units of a scene: radiometric (W, W/m²) or photometric (lm, cd, lx).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Units {
    /// W, W/m².
    #[default]
    Radiometric,
    /// lm, cd, lx.
    Photometric,
}

impl Units {
    /// The unit of radiosity and irradiance in files: `W/m2` or `lm/m2`.
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

/// A type C luminous intensity distribution.
#[derive(Clone, Debug)]
pub struct Photometry {
    /// Vertical angles γ in degrees.
    pub gamma: Vec<f64>,
    /// Horizontal angles C in degrees.
    pub c: Vec<f64>,
    /// Intensities in cd, `candela[i_c][i_gamma]`.
    pub candela: Vec<Vec<f64>>,
    /// Declared lamp flux.
    pub declared_lumens: Option<f64>,
    /// Luminous opening (m).
    pub opening: [f64; 3],
    /// Source.
    pub source: String,
}

impl Photometry {
    /// Intensity (axially symmetric stub).
    #[must_use]
    pub fn intensity(&self, _c_deg: f64, gamma_deg: f64) -> f64 {
        let g = &self.gamma;
        let row = &self.candela[0];
        if gamma_deg <= g[0] {
            return row[0];
        }
        for k in 1..g.len() {
            if gamma_deg <= g[k] {
                let t = (gamma_deg - g[k - 1]) / (g[k] - g[k - 1]);
                return row[k - 1] + t * (row[k] - row[k - 1]);
            }
        }
        0.0
    }

    /// Flux by fine numerical integration (stub).
    #[must_use]
    pub fn flux(&self) -> f64 {
        let n = 20_000;
        let mut f = 0.0;
        for k in 0..n {
            let g = (k as f64 + 0.5) / n as f64 * std::f64::consts::PI;
            f += self.intensity(0.0, g.to_degrees()) * g.sin() * std::f64::consts::PI / n as f64;
        }
        2.0 * std::f64::consts::PI * f
    }

    /// Scaled copy.
    #[must_use]
    pub fn scaled(&self, k: f64) -> Photometry {
        let mut p = self.clone();
        for row in &mut p.candela {
            for v in row {
                *v *= k;
            }
        }
        p
    }
}

/// A photometric file that cannot be read (stub).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct PhotometryError(String);

/// Reads by extension (stub).
pub fn read(path: &std::path::Path) -> Result<Photometry, PhotometryError> {
    Err(PhotometryError(format!("{}: photometric files are not read yet", path.display())))
}
