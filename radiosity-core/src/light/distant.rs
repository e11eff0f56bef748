//! A distant source: a field of parallel beams (the sun, or one cell of a sky; see
//! [`crate::daylight`] for how they are made and how their light enters a solve).

use crate::geom::DVec3;

/// A field of parallel beams.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistantSource {
    /// Unit direction the light travels (toward the ground for the sun).
    pub toward: DVec3,
    /// Irradiance on a plane facing the beam, per channel (W/m²).
    pub irradiance: [f64; 3],
    /// Whether the source is small enough to cast sharp shadows (the sun): surfaces are split
    /// along its shadow boundaries before the solve, as for a luminaire.
    pub sharp: bool,
}

impl DistantSource {
    /// Irradiance on a surface with unit normal `n`, unoccluded.
    #[must_use]
    pub fn on(&self, n: DVec3) -> [f64; 3] {
        let cos = -n.dot(self.toward);
        if cos <= 0.0 { [0.0; 3] } else { self.irradiance.map(|e| e * cos) }
    }
}
