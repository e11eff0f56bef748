//! The read-only services shared by every link of a refinement pass.

use super::Criterion;
use crate::hierarchy::Hierarchy;
use crate::visibility::{RayCaster, VisibilityConfig};

/// Read-only services shared by every link of a refinement pass.
pub struct Services<'a> {
    /// The element arena.
    pub hierarchy: &'a Hierarchy,
    /// Ray caster, `None` when the scene needs no visibility (nothing can occlude).
    pub caster: Option<&'a RayCaster>,
    /// Visibility sampling.
    pub visibility: VisibilityConfig,
    /// What is known of each element (radiosity, its variation, the irradiance reference), for
    /// energy criteria.
    pub data: &'a super::super::ElementData,
    /// Factor on every threshold of this pass ([`LinkCtx::threshold`](super::LinkCtx::threshold)): the pipeline refines
    /// coarse to fine, from a few times the oracle's eps down to it (or below, for a target error).
    pub threshold_scale: f64,
    /// Shaft culling for visibility, when enabled: links are classified by their shafts first and
    /// rays are cast against the shaft's candidate occluders only.
    pub shafts: Option<ShaftServices<'a>>,
    /// What the criteria bound the error of.
    pub criterion: Criterion,
    /// Under [`Criterion::Irradiance`], how many segments the visibility of a link of reflected
    /// light is sampled with when the oracle kept it without drawing any (see
    /// [`Criterion::kept_rays`]): `--rays`, or the kept count where calculation points read the
    /// solution (their error estimate does not count the links' sampling noise).
    pub reflected_rays: u32,
}

/// Shaft culling shared by a refinement pass.
#[derive(Clone, Copy)]
pub struct ShaftServices<'a> {
    /// The scene's objects and their bounding volumes.
    pub objects: &'a crate::visibility::shaft::ShaftObjects,
    /// Segments cast against candidate lists.
    pub rays: &'a std::sync::atomic::AtomicU64,
    /// Links classified invisible by a single occluder (no ray cast).
    pub invisible: &'a std::sync::atomic::AtomicU64,
    /// Links classified fully visible (no candidate, no ray cast).
    pub visible: &'a std::sync::atomic::AtomicU64,
}
