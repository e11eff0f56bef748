//! The classic BF oracle in its three releases: hand-written ([`crate::refine::BfHand`]), compiled
//! by `oracle!` ([`BfFlat`]) and interpreted by the DAG runtime ([`bf_dag`], from [`BF_TOML`]).
//! The three make the same decisions (the equivalence tests compare links and radiosity bit for
//! bit): facing pairs only; link when `B_S · F_max ≤ eps · B_ref`;
//! otherwise subdivide what can be: a cluster before a surface apart from it, else the larger
//! element first.

use super::runtime::{DagOracle, GraphFileError, parse_graph};
use std::path::Path;

oracle_macros::oracle! {
    crate = crate;

    /// The classic BF refiner (Hanrahan, Salzman & Aupperle 1991) compiled from its decision graph.
    pub oracle BfFlat {
        params { eps: f64 = 0.01 in 0.0..=1.0, min_area: f64 = 0.0 in 0.0..=1e300 }
        start => facing;
        facing: Facing { No => stop, Yes => energy }
        energy: BfAbove(eps) { No => link, Yes => size }
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
pub const BF_TOML: &str = r#"# The classic BF refiner as a decision graph.
name = "bf"
doc = "The classic BF refiner (Hanrahan, Salzman & Aupperle 1991), interpreted."
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
arms = [{ on = "No", to = "stop" }, { on = "Yes", to = "energy" }]

[[node]]
name = "energy"
tool = "BfAbove"
args = ["eps"]
arms = [{ on = "No", to = "link" }, { on = "Yes", to = "size" }]

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
