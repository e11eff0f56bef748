//! Photometric luminaires: a measured intensity distribution ([`crate::photometry::Photometry`],
//! from an IES or EULUMDAT file) placed in a scene with a position, an aim and a rotation.
//!
//! A luminaire is a **point** at its photometric centre: the illuminance it gives a receiver point
//! `x` with normal `n` is `E = I(C, γ) · cos θ / d² · V`, with `I` the file's intensity toward `x`,
//! `θ` the angle of incidence, `d` the distance and `V` one shadow ray. This is the far-field
//! model of every photometric file: against a luminous square on its axis it is 1.3% high at five
//! times the square's side (the "five-times rule"), 0.3% at ten, and 33% at one (tested in
//! `tests/luminaires.rs`): place calculation points at least five opening sizes away.
//!
//! Its light enters the hierarchy as the *direct illuminance* of each element
//! ([`crate::hierarchy::Hierarchy::direct`]), averaged over the element by quadrature with a shadow
//! ray per point, so that every surface's first reflection `ρ · E_direct` is an emission of the
//! radiosity system ([`crate::hierarchy::Hierarchy::emission_of`]): the interreflections then run
//! through the links like any other light. Before refinement, surfaces are subdivided until each
//! element subtends a small angle from every luminaire that lights it ([`MAX_ANGULAR_SIZE`]) and no
//! shadow boundary crosses an element ([`MAX_SHADOW_DEPTH`]), so the quadrature is accurate
//! (under a target error, the sun's boundaries are left to the levels' error control: [`prepare`]).
//! A sharp distant source (the sun) is not sampled at points at all: its light on an element is
//! its unoccluded irradiance times the share of the element that the other polygons' shadows
//! leave lit, found exactly by projecting them onto the element's plane and taking their union's
//! area ([`crate::geom::union_area`]).
//!
//! Where it may not be (a shadow edge of a luminaire or of the sun crossing a leaf, a luminaire
//! nearer than the angular size allows), the leaf is sampled on its quarters as well and the
//! difference is its quadrature error ([`update_direct`], [`Hierarchy::direct_error`](crate::hierarchy::Hierarchy::direct_error)); each
//! polygon's share ([`direct_polygon_errors`]) is in the solve's error estimate, and under a target
//! error the levels sample those leaves finer (then split them) until
//! every polygon's mean direct light is within a share of the target of its own value
//! ([`direct_splits`], [`deepen_direct`]).
//!
//! One file per step: [`DirectLight`] sees the luminaires from a point (`point.rs`); `split.rs`
//! subdivides the surfaces before refinement ([`prepare`]); `shadows.rs` finds where the polygons'
//! shadows fall along a distant source's direction; `update.rs` computes the elements' direct
//! light ([`update_direct`], [`deepen_direct`]) with `rule.rs`'s quadrature of one leaf; `errors.rs`
//! holds each polygon's quadrature error and the splits it asks for ([`direct_polygon_errors`],
//! [`direct_splits`]); `means.rs` the polygons' means and the flux received; `shares.rs` what each
//! source brings to the surfaces ([`source_shares`]).

mod errors;
mod means;
mod point;
mod rule;
mod shadows;
mod shares;
mod split;
mod update;

pub use crate::light::luminaire::{Luminaire, LuminaireError};
pub use crate::visibility::SHADOW_ORIGIN_OFFSET_REL;
pub use errors::{DIRECT_FLOOR_REL, direct_polygon_errors, direct_splits};
pub use means::{flux_received, polygon_direct_means};
pub use point::DirectLight;
pub(crate) use shadows::ParallelShadows;
pub use shares::{SourceKind, SourceShare, luminaires_onto_surfaces, source_shares};
pub use split::prepare;
pub use update::{deepen_direct, update_direct};

/// Subdivide (before refinement) a surface element lit by a luminaire while its bounding radius
/// exceeds this fraction of its distance to the luminaire: the quadrature of `I cos θ / d²` over
/// it is then accurate to about 1e-4 (9-point rule, smooth intensities).
pub const MAX_ANGULAR_SIZE: f64 = 0.25;
/// Most subdivision levels below an input polygon for the luminaires' angular size.
pub const MAX_ANGULAR_DEPTH: u16 = 7;
/// Most subdivision levels below an input polygon for a shadow boundary of a luminaire crossing an
/// element (its quadrature points disagree on visibility).
pub const MAX_SHADOW_DEPTH: u16 = 6;

/// How far inside its corners (a share of the way to its centre) an element's visibility is
/// tested, besides at its rule's points, to find shadow boundaries crossing it
/// ([`update_direct`]).
pub const CORNER_INSET: f64 = 1e-3;
