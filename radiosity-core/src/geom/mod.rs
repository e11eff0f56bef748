//! Geometry in `f64`: polygons (triangles and quads), boxes and quadrature rules.

mod aabb;
mod mesh;
mod polygon;
pub mod quadrature;
pub mod union_area;

pub use aabb::Aabb;
pub use glam::DVec3;
pub use mesh::open_mesh_faces;
pub use polygon::{BACK_TO_BACK_REL_TOL, Poly, PolyKind};

/// Relative tolerance under which a length is treated as zero, relative to the size of the object it belongs to.
pub const REL_EPS: f64 = 1e-12;
