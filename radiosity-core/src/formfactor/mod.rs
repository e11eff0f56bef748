//! Form factors in `f64`: Lambert's contour integral from a point to a polygon, its average over a
//! receiver by quadrature, and the isotropic cluster approximation.
//!
//! Convention: for a link from source (emitter) `S` to receiver `R`, the stored coefficient `F` is such
//! that the receiver's area-averaged irradiance is `H_R = F · V · B_S` (`V` the visibility fraction,
//! `B_S` the source's area-averaged radiosity). For surfaces, `F` is the classic form factor `F(R→S)`.

mod contour;
mod link;
mod point_polygon;

pub use contour::polygon_polygon;
pub use link::{
    FAR_SEPARATION, FormFactorQuality, MAX_PROBE_PULL, NEAR_SEPARATION, ON_PLANE_REL_TOL, behind_surface, estimate, estimate_max,
    link_form_factor, point_to_element, projected_area, surfaces_cross,
};
pub use point_polygon::{clip_to_halfspace, kernel_variation, point_polygon, point_polygon_unclipped};
