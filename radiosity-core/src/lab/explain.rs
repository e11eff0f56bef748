//! `radiosity oracle explain`: the execution track of one link's decisions, recorded while a whole
//! scene is solved with a named oracle's graph in the DAG runtime.

use crate::oracle::registry::{RegistryError, graph};
use crate::oracle::runtime::DagOracle;
use crate::oracle::{Recorder, TraceStep};
use crate::pipeline::{self, Config};
use crate::scene::Scene;
use oracle_graph::Graph;

/// What `radiosity oracle explain` shows: the execution track of `emitter → receiver` (element ids)
/// when `scene` is solved with the graph of oracle `name`, interpreted by the DAG runtime with a
/// recorder (decisions are the same as the named release's). Empty when the pair is never asked.
pub fn explain(
    name: &str,
    params: &[(String, f64)],
    scene: &Scene,
    config: &Config,
    emitter: u32,
    receiver: u32,
) -> Result<(Graph, Vec<TraceStep>), RegistryError> {
    let g = graph(name)?;
    let probe = Recorder::new(g.nodes.len()).tracing(emitter, receiver);
    let dag = DagOracle::with_probe(g.clone(), params, Vec::new(), probe)?;
    let _ = pipeline::run(scene, &dag, config, &|_| {});
    Ok((g, dag.probe().trace()))
}
