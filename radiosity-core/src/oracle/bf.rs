//! The classic BF oracle in its three releases: hand-written ([`crate::refine::BfHand`]), compiled
//! by `oracle!` ([`BfFlat`]) and interpreted by the DAG runtime ([`bf_dag`], from [`BF_TOML`]).
//! The three make the same decisions (the equivalence tests compare links and radiosity bit for
//! bit); every threshold is `eps` times the receiver's own irradiance ([`crate::refine::LinkCtx::threshold`]):
//! 1. pairs that cannot see each other's front are dropped;
//! 2. a link with a cluster at one end whose elements are too near for the cluster approximation,
//!    or between two surfaces that cross each other ([`crate::refine::LinkCtx::too_near`]), is
//!    subdivided;
//! 3. a link whose whole transfer `B_S · F_max` is within the threshold is kept;
//! 4. otherwise it is subdivided while the cluster approximation's error
//!    ([`super::tools::ClusterError`]) exceeds the threshold, then, splitting the source, while the
//!    error of gathering the source's mean radiosity ([`super::tools::SourceVariation`]) does, then
//!    while partial visibility's ([`super::tools::PartialVisibility`]) does;
//! 5. what is subdivided: a cluster before a surface apart from it, else the larger element.

use super::runtime::{DagOracle, GraphFileError, parse_graph};
use std::path::Path;

oracle_macros::oracle! {
    crate = crate;

    /// The BF refiner compiled from its decision graph: facing pairs only; no cluster link where
    /// the clusters are too near for it; link when the whole transfer is within eps of the
    /// receiver's irradiance; otherwise subdivide while the cluster approximation, the source's
    /// radiosity variation (the source is split) or partial visibility could err by more.
    pub oracle BfFlat {
        params { eps: f64 = 0.01 in 0.0..=1.0, min_area: f64 = 0.0 in 0.0..=1e300 }
        start => facing;
        facing: Facing { No => stop, Yes => near }
        near: ClusterTooNear { Yes => size, No => transfer }
        transfer: BfAbove(eps) { No => link, Yes => cluster }
        cluster: ClusterError(eps) { Above => size, Below => variation }
        variation: SourceVariation(eps) { Above => source, Below => shadow }
        source: CanSubdivide(min_area) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => shadow,
            Both => subdivide_emitter,
        }
        shadow: PartialVisibility(eps) { Above => size, Below => link }
        size: CanSubdivide(min_area) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => subdivide_receiver,
            Both => first,
        }
        first: SplitFirst { Emitter => subdivide_emitter, Receiver => subdivide_receiver }
    }
}

/// The BF graph in the graph-file format of the DAG runtime (the same graph as [`BfFlat`]).
pub const BF_TOML: &str = r#"# The BF refiner as a decision graph.
name = "bf"
doc = "The BF refiner, relative to each receiver's irradiance, interpreted."
start = "facing"

[[param]]
name = "eps"
default = 0.01
min = 0.0
max = 1.0

[[param]]
name = "min_area"
default = 0.0
min = 0.0
max = 1e300

[[node]]
name = "facing"
tool = "Facing"
arms = [{ on = "No", to = "stop" }, { on = "Yes", to = "near" }]

[[node]]
name = "near"
tool = "ClusterTooNear"
arms = [{ on = "Yes", to = "size" }, { on = "No", to = "transfer" }]

[[node]]
name = "transfer"
tool = "BfAbove"
args = ["eps"]
arms = [{ on = "No", to = "link" }, { on = "Yes", to = "cluster" }]

[[node]]
name = "cluster"
tool = "ClusterError"
args = ["eps"]
arms = [{ on = "Above", to = "size" }, { on = "Below", to = "variation" }]

[[node]]
name = "variation"
tool = "SourceVariation"
args = ["eps"]
arms = [{ on = "Above", to = "source" }, { on = "Below", to = "shadow" }]

[[node]]
name = "source"
tool = "CanSubdivide"
args = ["min_area"]
arms = [
    { on = "Neither", to = "link" },
    { on = "Emitter", to = "subdivide_emitter" },
    { on = "Receiver", to = "shadow" },
    { on = "Both", to = "subdivide_emitter" },
]

[[node]]
name = "shadow"
tool = "PartialVisibility"
args = ["eps"]
arms = [{ on = "Above", to = "size" }, { on = "Below", to = "link" }]

[[node]]
name = "size"
tool = "CanSubdivide"
args = ["min_area"]
arms = [
    { on = "Neither", to = "link" },
    { on = "Emitter", to = "subdivide_emitter" },
    { on = "Receiver", to = "subdivide_receiver" },
    { on = "Both", to = "first" },
]

[[node]]
name = "first"
tool = "SplitFirst"
arms = [{ on = "Emitter", to = "subdivide_emitter" }, { on = "Receiver", to = "subdivide_receiver" }]
"#;

/// The BF oracle of the DAG runtime, with `eps` (the other parameters at their defaults).
pub fn bf_dag(eps: f64) -> Result<DagOracle, GraphFileError> {
    let graph = parse_graph(BF_TOML, Path::new("<bf>"))?;
    DagOracle::new(graph, &[("eps".to_owned(), eps)]).map_err(|e| GraphFileError::whole(Path::new("<bf>"), e.to_string()))
}
