//! Shaft visibility culling (Haines & Wallace): shafts between element boxes, candidate occluders,
//! conservative occlusion tests.
//!
//! Part of step `visibility`. A link's interaction volume is a [`Shaft`] between its two elements'
//! boxes; only objects whose bounding volume meets it ([`ShaftObjects::candidates`]) can occlude the
//! link, and a subdivided link's children test only their parent's candidates. [`classify`] says
//! whether a link is certainly invisible (one candidate blocks it all), certainly visible (nothing
//! reaches into the shaft) or partial; [`visibility_among`] estimates the visibility fraction by
//! ray casting against the candidates only.
//!
//! Architecture invariant: every "invisible" answer is conservative (never claimed when some
//! segment between the elements is unblocked) and every candidate list is complete (no object
//! whose geometry meets the shaft is missing). Both are checked by property tests
//! (`tests/shaft_props.rs`).

mod arena;
mod build;
mod bvh;
mod classify;
mod cull;
mod merge;
mod obb;
mod objects;
mod occlusion;
mod plane;
mod rays;

pub use arena::{CandidateLists, CandidateRange};
pub use build::{MAX_SIDE_PLANES, SHAFT_REL_TOL, Shaft, ShaftKind};
pub use bvh::ObjectBvh;
pub use classify::{GRAZE_REL_TOL, ShaftClass, ShaftVerdict, classify, classify_with, element_vertices, occludes, shaft_of};
pub use cull::{may_intersect_aabb, may_intersect_obb};
pub use merge::{COPLANAR_REL_TOL, MergedPlate};
pub use obb::{AXIS_ALIGNED_TOL, Obb};
pub use objects::{BoundingVolume, ConvexSolid, ObjectConfig, SOLID_REL_TOL, ShaftObject, ShaftObjects};
pub use occlusion::{OCCLUSION_REL_TOL, convex_polygon_occludes, plate_occludes, solid_occludes};
pub use plane::{Plane, aabb_corners};
pub use rays::{MAX_CULL_PARENT_OBJECTS, MAX_LOOP_POLYGONS, SEGMENT_END_EPS, n_polygons_among, segment_clear_among, visibility_among};
