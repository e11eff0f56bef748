//! Views of a scene: the pinhole [`View`] the images are drawn from, Radiance-style view options
//! ([`ViewSpec`]: `-vp -vd -vu -vh -vv -vtv`, inline or in a `.vf` file), and the candidate
//! default views of a scene without a camera ([`candidate_views`]).
//!
//! Radiance's conventions are kept: `-vh` and `-vv` are the full horizontal and vertical angles in
//! degrees, `-vd` need not be a unit vector, and options given override the view they modify (the
//! scene's own camera, or the default view).
//!
//! The contract of this folder: a view is data (an eye, a direction, an up vector and two angles);
//! nothing here draws. The renderer (`render.rs` beside this folder) draws from a [`View`], which
//! comes from the scene's camera, from view options applied to it, or from a candidate default
//! view.
//!
//! - `pinhole.rs`: the pinhole [`View`], and how it is written as view options.
//! - `spec.rs`: Radiance's view options ([`ViewSpec`]), read from a line or a `.vf` file, and
//!   their errors ([`ViewError`]).
//! - `defaults.rs`: the scene's up axis ([`up_axis`]) and the candidate default views of a scene
//!   without a camera ([`candidate_views`]).

mod defaults;
mod pinhole;
mod spec;

pub use defaults::{
    Candidate, INSIDE_CORNER_FRACTION, INSIDE_FOV_DEG, OUTSIDE_ELEVATION_DEG, OUTSIDE_FOV_DEG, OUTSIDE_MARGIN, candidate_views, up_axis,
};
pub use pinhole::View;
pub use spec::{MAX_VIEW_ANGLE_DEG, ViewError, ViewSpec};
