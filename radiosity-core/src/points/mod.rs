//! Step 6, `points`: irradiance at calculation points, gathered from a solved hierarchy, as
//! lighting programs are validated and read (CIE 171:2006).
//!
//! A calculation point is a position and a normal: a small receiver facing the normal. Its
//! irradiance is gathered from every leaf of the solution, `H(x) = Σ B_leaf · F(dx → leaf) ·
//! V(x, leaf)`, with Lambert's exact point-to-polygon form factor and visibility by rays; a leaf
//! the point sees in part is subdivided adaptively ([`SHADOW_DEPTH`]). See [`gather`] for the
//! contract, [`read_points`] for the file format and [`crate::output::write_points_csv`] for
//! `points.csv`.

mod gather;
pub mod grid;
mod read;

pub use gather::{
    AsSolveParts, LeafError, MAX_SHADOW_DEPTH, ON_SURFACE_REL_TOL, ORIGIN_OFFSET_REL, PointGather, PointsConfig, SAMPLE_INSET,
    SAMPLE_SHIFT, SHADOW_DEPTH, SHADOW_EDGE_REL_ERROR, SKY_EDGE_PIECES, SKY_ERROR_FACTOR, SKY_PATCH_BUDGET, SKY_PATCH_ERROR_FACTOR,
    SKY_PATCH_MIN_PIECES, SKY_PATCH_PIECES, SKY_PATCH_PROBES, SKY_PROBE_SPREAD, SKY_PROBES, SolveParts, UNIFORM_MAX_SUBTENSE, gather,
};
pub use grid::{Grid, GridError, GridSpec, GridSummary};
pub use read::{PointsError, parse_points, read_points};

use crate::geom::DVec3;

/// Rec. 709 (sRGB) luminance weights of the red, green and blue channels: the photopic value of a
/// colour is `0.2126·r + 0.7152·g + 0.0722·b`. They sum to 1, so a grey irradiance keeps its value.
pub const PHOTOPIC_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// The photopic (luminance-weighted) value of an RGB irradiance, with [`PHOTOPIC_WEIGHTS`]
/// (W/m² for radiometric scenes).
#[must_use]
pub fn photopic(h: [f64; 3]) -> f64 {
    PHOTOPIC_WEIGHTS[0] * h[0] + PHOTOPIC_WEIGHTS[1] * h[1] + PHOTOPIC_WEIGHTS[2] * h[2]
}

/// A calculation point: where a small receiver is, and which way it faces.
#[derive(Clone, Debug, PartialEq)]
pub struct CalcPoint {
    /// Its label in `points.csv`.
    pub name: String,
    /// Position, scene units.
    pub position: DVec3,
    /// Unit normal: the receiver gathers light arriving from this side.
    pub normal: DVec3,
}

impl CalcPoint {
    /// A point facing `normal`, which need not be unit length (it is normalised); `None` when the
    /// normal is zero or a coordinate is not finite.
    #[must_use]
    pub fn new(name: impl Into<String>, position: DVec3, normal: DVec3) -> Option<CalcPoint> {
        let normal = normal.try_normalize()?;
        position.is_finite().then(|| CalcPoint { name: name.into(), position, normal })
    }
}

/// The irradiance gathered at one calculation point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointIrradiance {
    /// Irradiance per channel on the receiver's side (W/m²).
    pub h: [f64; 3],
    /// The estimated error of `h` per channel, W/m² (see [`PointGather`]'s contract); NaN where
    /// the solve has no error estimate to start from.
    pub h_err: [f64; 3],
    /// The part of [`PointIrradiance::h_err`] that comes from the sky's discretisation into
    /// cells, each sampled ray by ray where the point sees part of it (W/m², per channel): what a
    /// finer sky (more `directions`) lowers, and refinement does not.
    pub sky_err: [f64; 3],
    /// Visibility rays cast for this point (0 where none were needed).
    pub rays: u64,
}

impl PointIrradiance {
    /// The photopic value of [`PointIrradiance::h`] (see [`photopic`]).
    #[must_use]
    pub fn photopic(&self) -> f64 {
        photopic(self.h)
    }

    /// The estimated error of [`PointIrradiance::photopic`] (the photopic value of the channels'
    /// errors: its weights are positive).
    #[must_use]
    pub fn photopic_err(&self) -> f64 {
        photopic(self.h_err)
    }

    /// The part of [`PointIrradiance::photopic_err`] that refinement can lower: all of it but
    /// the sky's discretisation ([`PointIrradiance::sky_err`]).
    #[must_use]
    pub fn refinable_err(&self) -> f64 {
        (photopic(self.h_err) - photopic(self.sky_err)).max(0.0)
    }
}

/// A point's error is relative to its own value, but never to less than this fraction of the
/// largest value of its set (a point in a deep shadow is held to the accuracy of one a hundred
/// times brighter, not without end).
pub const POINT_FLOOR_REL: f64 = 1e-2;

/// What each point's estimated error is relative to: its photopic value, at least
/// [`POINT_FLOOR_REL`] of the largest of `results`; `None` when there is no light or an error is
/// not known.
#[must_use]
pub fn error_scales(results: &[PointIrradiance]) -> Option<Vec<f64>> {
    let top = results.iter().map(PointIrradiance::photopic).fold(0.0, f64::max);
    if top <= 0.0 || results.iter().any(|r| !r.photopic_err().is_finite()) {
        return None;
    }
    Some(results.iter().map(|r| r.photopic().max(POINT_FLOOR_REL * top)).collect())
}

/// The largest estimated error of the photopic values of `results`, each relative to its value
/// (at least [`POINT_FLOOR_REL`] of the largest, see [`error_scales`]); `None` when there is no
/// light or an error is not known.
#[must_use]
pub fn worst_relative_error(results: &[PointIrradiance]) -> Option<f64> {
    let scales = error_scales(results)?;
    Some(results.iter().zip(scales).map(|(r, s)| r.photopic_err() / s).fold(0.0, f64::max))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(h: f64, err: f64) -> PointIrradiance {
        PointIrradiance { h: [h; 3], h_err: [err; 3], sky_err: [0.0; 3], rays: 0 }
    }

    /// The worst error relative to each point's value, or to the floor below it (grey channels:
    /// photopic = each channel).
    #[test]
    fn worst_relative_error_is_relative_to_each_value_down_to_the_floor() {
        let worst = worst_relative_error(&[point(100.0, 0.5), point(10.0, 2.0), point(50.0, 1.0)]).unwrap();
        assert!((worst - 0.2).abs() < 1e-12, "{worst}");
        // 0.01 is below the floor (1% of 100): its error counts against 1.
        let worst = worst_relative_error(&[point(100.0, 0.5), point(0.01, 0.03)]).unwrap();
        assert!((worst - 0.03).abs() < 1e-12, "{worst}");
        assert_eq!(worst_relative_error(&[point(100.0, 0.5), point(10.0, f64::NAN)]), None, "an unknown error");
        assert_eq!(worst_relative_error(&[point(0.0, 0.0)]), None, "no light");
    }
}
