//! The gather at calculation points: every leaf's radiosity times Lambert's exact form factor from
//! the point, times the leaf's visibility from the point, found by rays and, where the leaf is seen
//! in part, by adaptive regular subdivision.
//!
//! The folder holds the gather one step per file, in the order a point takes them:
//! - `prepare.rs`: the leaves that give light, prepared once per solve (from a finished solve or
//!   from its parts between refinements), with what each point's error starts from;
//! - `point.rs`: one point's gather: the surfaces it lies on, every leaf's form factor and
//!   visibility, its error and the leaves it comes from, then the luminaires' and the sky's direct
//!   light;
//! - `clip.rs`: the half-spaces a point gathers from, a leaf clipped to them, and the exact form
//!   factor of what is left;
//! - `shadow.rs`: the visibility of a leaf seen in part, by rays to samples and adaptive regular
//!   subdivision.
//!
//! This file holds the contract ([`PointGather`]), its settings and constants, and the data the
//! steps share.

mod clip;
mod point;
mod prepare;
mod shadow;

pub use point::{
    LeafError, SKY_EDGE_PIECES, SKY_ERROR_FACTOR, SKY_PATCH_BUDGET, SKY_PATCH_ERROR_FACTOR, SKY_PATCH_MIN_PIECES, SKY_PATCH_PIECES,
    SKY_PATCH_PROBES, SKY_PROBE_SPREAD, SKY_PROBES,
};
pub use prepare::{AsSolveParts, SolveParts};

use super::{CalcPoint, PointIrradiance};
use crate::geom::{DVec3, Poly};
use crate::hierarchy::{ElementId, Hierarchy};
use crate::visibility::RayCaster;
use rayon::prelude::*;

/// Deepest regular subdivision (2×2 per level, as the hierarchy subdivides) of a leaf the point
/// sees in part: the finest pieces have 1/64 of the leaf's edges.
pub const SHADOW_DEPTH: u32 = 6;

/// Deepest subdivision [`PointsConfig::shadow_depth`] may ask for (deeper is taken as this).
pub const MAX_SHADOW_DEPTH: u32 = 14;

/// Error budget of the visibility of one leaf crossed by one straight shadow edge, relative to
/// the leaf's unoccluded form factor, when the kernel varies little over the leaf: the edge
/// crosses at most `3·2^D` of the finest pieces (`2·2^D − 1` for quads), each `4^−D` of the leaf
/// and each counted by the fraction of its clear samples; the samples' displacement
/// ([`SAMPLE_INSET`]) misjudges at most a band along the edge, and a strip along the leaf's
/// boundary, of that relative size. With [`SHADOW_DEPTH`] 6 that is 4.8%; measured, one leaf is
/// within 0.2% and the CIE 171 obstruction case within 0.2% at every point (see the README).
/// Leaves no shadow edge crosses are exact up to rounding.
pub const SHADOW_EDGE_REL_ERROR: f64 = 3.0 / (1u64 << SHADOW_DEPTH) as f64 + SAMPLE_INSET;

/// A piece whose samples agree (all clear or all blocked) is taken as wholly visible or hidden only
/// when its radius is at most this times its distance from the point (or at [`SHADOW_DEPTH`]);
/// larger pieces are subdivided, so that an occluder seen between the samples of a large, near
/// leaf is looked for.
pub const UNIFORM_MAX_SUBTENSE: f64 = 0.5;

/// Visibility samples of a piece are its corners and its centre, shared with the pieces around
/// it, each drawn toward the leaf's centre by this fraction of its distance, then moved by
/// [`SAMPLE_SHIFT`] times this fraction of the leaf's parameter range: off the leaf's edges, where
/// neighbouring polygons touch it, and off the symmetry planes of axis-aligned scenes, where a
/// centred point would send its rays exactly along an occluder's edge, or along the diagonal that
/// splits a quad into the ray caster's two triangles (whose triangle test is not watertight). A
/// piece cut by the point's tangent plane is sampled at the centre and corners of its visible
/// part, moved alike about its own centre.
pub const SAMPLE_INSET: f64 = 1e-3;

/// The shift of the samples along the leaf's two parameters, in units of [`SAMPLE_INSET`] times
/// the parameter range: unequal and of unequal signs, so that a sample leaves the diagonals too;
/// small enough (each below 1/3, their sum too) that the samples stay inside triangles and quads.
pub const SAMPLE_SHIFT: [f64; 2] = [0.2, -0.1];

/// A point lies on a polygon when it is within this distance, relative to the scene's diagonal, of
/// the polygon's plane and of its area; a leaf whose plane passes that close to the point gives it
/// no light (the point is on that surface or beside it in the same plane).
pub const ON_SURFACE_REL_TOL: f64 = 1e-6;

/// Rays start this far from the point, relative to the scene's diagonal, off the surfaces it lies
/// on (along its normal and those surfaces' normals on its side), so that those surfaces do not
/// block its rays.
pub const ORIGIN_OFFSET_REL: f64 = 1e-5;

/// Most half-spaces a point gathers from: its own, and those of up to three distinct surfaces it
/// lies on (a corner of a room); further surfaces through the point are not clipped against.
const MAX_SIDES: usize = 4;

/// Most vertices of a quad clipped by [`MAX_SIDES`] planes (each adds at most one).
const MAX_VERTICES: usize = 4 + MAX_SIDES;

/// Two side normals closer than this (1 − cosine) are one side.
const SAME_SIDE_EPS: f64 = 1e-12;

/// Settings of the gather at calculation points.
#[derive(Clone, Copy, Debug)]
pub struct PointsConfig {
    /// Cast visibility rays (false: every leaf counts as wholly visible, as in a solve without
    /// visibility).
    pub use_visibility: bool,
    /// Deepest subdivision of a partly visible leaf ([`SHADOW_DEPTH`] by default).
    pub shadow_depth: u32,
}

impl Default for PointsConfig {
    fn default() -> Self {
        PointsConfig { use_visibility: true, shadow_depth: SHADOW_DEPTH }
    }
}

/// The irradiance at each of `points`, in order, gathered from `solved` (see [`PointGather`]);
/// points are gathered in parallel, each independently, so the result does not depend on the
/// thread count. Rays are cast unless `config.use_visibility` is off or the solve's analysis found
/// a convex enclosure ([`crate::analysis::SceneTraits::needs_visibility`]) and the point lies
/// inside it.
#[must_use]
pub fn gather<S: AsSolveParts + ?Sized>(solved: &S, points: &[CalcPoint], config: &PointsConfig) -> Vec<PointIrradiance> {
    let g = PointGather::for_solved(solved, config);
    points.par_iter().map(|p| g.irradiance(p)).collect()
}

/// A leaf that gives light: its geometry and radiosity.
#[derive(Clone, Copy, Debug)]
struct Source {
    poly: Poly,
    normal: DVec3,
    center: DVec3,
    radius: f64,
    polygon: u32,
    b: [f64; 3],
    /// How much its radiosity varies over it (largest channel of `max − min`, W/m²; 0 unknown).
    variation: f64,
    /// The estimated error of its mean (W/m²; NaN: the gather's `mean_error` for every leaf).
    mean_error: f64,
    /// How far its radiosity may be off for the sources of its links being coarse
    /// ([`crate::solve::leaf_value_errors`], W/m²; 0 unknown).
    value_error: f64,
    /// The leaf.
    id: ElementId,
}

/// The leaves of a solution that give light, prepared for gathering at many points.
///
/// Contract of [`PointGather::irradiance`]: `H(x) = Σ B_leaf · F(dx → leaf) · V(x, leaf)` over the
/// leaves with a positive radiosity, each leaf emitting from its front side only (a point in or
/// behind a leaf's plane gets nothing from it). `F` is Lambert's contour integral over the part of
/// the leaf in front of the receiver's tangent plane and on the point's side of every surface the
/// point lies on ([`ON_SURFACE_REL_TOL`]), so no light comes through the surface under the point,
/// whatever the receiver's normal. `V` is found by rays from the point (offset by
/// [`ORIGIN_OFFSET_REL`]) to samples of the leaf ([`SAMPLE_INSET`]); a leaf whose samples disagree is
/// subdivided 2×2, each piece with its own exact form factor, down to [`SHADOW_DEPTH`], where a
/// piece counts by its fraction of clear samples ([`SHADOW_EDGE_REL_ERROR`]). A wholly visible leaf
/// is exact up to rounding.
///
/// The estimated error `h_err` of each point adds, over the leaves it sees: half the range of the
/// leaf's radiosity (probed over it, [`crate::solve::element_data`]) times `F·V` times how much
/// the kernel varies over the leaf ([`crate::formfactor::kernel_variation`]: a far leaf's mean is
/// all a point sees of it, a near one's shape shows); how far the leaf's value may be off for the
/// sources of its links being coarse ([`crate::solve::leaf_value_errors`]) times `F·V`; the
/// estimated error of the leaf's polygon mean (its own, [`SolveParts::polygon_errors`], or the
/// solve's estimate times the largest mean) times `F·V`; and [`SHADOW_EDGE_REL_ERROR`] times `F·B`
/// for a leaf seen in part. Measured on the 1990 test room's 480 points (`tests/accuracy.rs`): at
/// the default target every point's true error is within its estimate plus the reference's 0.2%,
/// with importance rounds (the worst point's estimate 2.2 times its error) and without. The
/// luminaires' and the sun's direct light (one ray each) adds none: a luminaire's is exact for the
/// point-source model. The sky's cells add their discretisation ([`PointIrradiance::sky_err`]):
/// a cell with its patch of sky is probed at [`SKY_PATCH_PROBES`] and, seen in part, sampled on
/// [`SKY_PATCH_PIECES`]² pieces ([`SKY_PATCH_ERROR_FACTOR`]); one without (made by hand) is seen
/// along its middle ray, with [`SKY_PROBES`] more rays across it ([`SKY_ERROR_FACTOR`]).
pub struct PointGather<'a> {
    h: &'a Hierarchy,
    caster: Option<&'a RayCaster>,
    sources: Vec<Source>,
    /// The scene's diagonal.
    scale: f64,
    /// Rays are cast only for points outside the enclosure.
    convex_enclosure: bool,
    shadow_depth: u32,
    /// The luminaires and distant sources whose direct light the point gets besides the
    /// surfaces' (none unless set, as [`PointGather::for_solved`] does).
    lights: Option<&'a crate::light::Lights>,
    /// The error of a leaf's mean radiosity (W/m²): the solve's estimate times the largest
    /// non-emitting polygon mean it is relative to; NaN when unknown (until
    /// [`PointGather::for_solved`] sets it from an estimated solve).
    mean_error: f64,
    /// The input polygons' boxes, each grown by as much as the on-surface test may reach beyond
    /// the polygon ([`on_surface_reach`](point::on_surface_reach)): a point finds the surfaces it
    /// lies on among the few boxes holding it, not by testing every polygon (on a canopy of 320,000
    /// leaf sides that test was two thirds of the solve).
    on_surface: crate::visibility::shaft::ObjectBvh,
}
