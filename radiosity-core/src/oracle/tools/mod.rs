//! The built-in tools. Their names, answers and arguments are listed in
//! [`oracle_graph::catalogue`]; a test checks the two agree.

mod command;
mod energy;
mod geometry;
mod shaft;
mod visibility;

pub use command::{Done, Mark, PreciseFormFactor, PreciseVisibility};
pub use energy::{
    BfAbove, CLUSTER_ERROR_COEF, ClusterError, ErrorBound, FfGradient, FfSpread, Irradiance, IrradianceChange, PartialVisibility,
    SOURCE_VARIATION_WEIGHT, SourceVariation,
};
pub use geometry::{
    CanSubdivide, ClusterTooNear, Cone, Facing, Larger, NormalCone, PlanesIntersect, ProjectedAreaBelow, Side, SplitFirst, Subdividable,
    YesNo,
};
pub use shaft::{ShaftAnswer, ShaftClassify, ShaftFfError};
pub use visibility::{PROBABLE_BELOW_RAYS, REFERENCE_RAYS, RayVisibility, ReferenceClass, ReferenceVisibility, VisibilityClass};
