//! The DAG runtime ("DAG release"): a decision graph built at run time (the [`GraphBuilder`] API or
//! a graph file, see [`parse_graph`]), validated by the same rules as the macro, and executed by an
//! interpreter. Instrument it with a [`Recorder`](crate::oracle::Recorder) for statistics and an
//! execution track; export it with [`oracle_graph::to_dot`].

mod builder;
mod file;
mod report;
mod tool;

pub use builder::GraphBuilder;
pub use file::{GraphFileError, Located, load_graph, parse_graph};
pub use report::{format_stats, format_trace, stats_dot};
pub use tool::DynTool;

use crate::oracle::{NoProbe, ParamError, Probe, check_param};
use crate::refine::{Decision, LinkCtx, Oracle};
use oracle_graph::{Arg, DecisionKind, Graph, ParamValue, Resolved, validate};

/// A function computing a parameter for each link.
pub type ComputedParam = Box<dyn Fn(&LinkCtx<'_>) -> f64 + Send + Sync>;

#[derive(Clone, Copy, Debug)]
enum Next {
    Node(u32),
    Decision(Decision),
}

struct CompiledNode {
    tool: DynTool,
    /// Per answer index: where it leads.
    next: Vec<Next>,
    /// Arguments computed per link: (argument position, computed-parameter index). Empty for most.
    computed_args: Vec<(usize, usize)>,
    /// Argument values bound at build time (computed positions hold 0).
    args: Vec<f64>,
}

/// Why a graph could not be turned into an oracle.
#[derive(Debug, thiserror::Error)]
pub enum RuntimeError {
    /// The graph breaks validation rules (every problem listed).
    #[error("{}", .0.iter().map(ToString::to_string).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<oracle_graph::GraphError>),
    /// A parameter could not be set.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A computed parameter has no function.
    #[error("computed parameter `{0}` has no function (register it with `DagOracle::with_computed`)")]
    MissingComputed(String),
}

/// A decision graph executed by the interpreter. `P` selects instrumentation, as for the oracles
/// `oracle!` generates.
pub struct DagOracle<P = NoProbe> {
    graph: Graph,
    values: Vec<f64>,
    computed: Vec<(String, ComputedParam)>,
    nodes: Vec<CompiledNode>,
    start: Next,
    probe: P,
}

fn decision(d: DecisionKind) -> Decision {
    match d {
        DecisionKind::Link => Decision::Link,
        DecisionKind::SubdivideEmitter => Decision::SubdivideEmitter,
        DecisionKind::SubdivideReceiver => Decision::SubdivideReceiver,
        DecisionKind::SubdivideBoth => Decision::SubdivideBoth,
        DecisionKind::Stop => Decision::Stop,
    }
}

impl DagOracle<NoProbe> {
    /// Validates `graph` (built-in tools only), sets the parameters in `params` (name, value), and
    /// compiles it for the interpreter.
    pub fn new(graph: Graph, params: &[(String, f64)]) -> Result<DagOracle<NoProbe>, RuntimeError> {
        DagOracle::with_probe(graph, params, Vec::new(), NoProbe)
    }
}

impl<P: Probe> DagOracle<P> {
    /// As [`DagOracle::new`], with functions for the computed parameters and a probe.
    pub fn with_probe(
        graph: Graph,
        params: &[(String, f64)],
        computed: Vec<(String, ComputedParam)>,
        probe: P,
    ) -> Result<DagOracle<P>, RuntimeError> {
        let checked = validate(&graph, &oracle_graph::validate::builtin_only).map_err(RuntimeError::Invalid)?;
        let mut values: Vec<f64> = graph
            .params
            .iter()
            .map(|p| match p.value {
                ParamValue::Fixed { default, .. } => default,
                ParamValue::Computed { .. } => 0.0,
            })
            .collect();
        for (name, value) in params {
            check_param(&graph, name, *value)?;
            if let Some(i) = graph.params.iter().position(|p| p.name == **name) {
                values[i] = *value;
            }
        }
        for p in graph.params.iter() {
            if matches!(p.value, ParamValue::Computed { .. }) && !computed.iter().any(|(n, _)| *n == *p.name) {
                return Err(RuntimeError::MissingComputed(p.name.to_string()));
            }
        }
        let to_next = |r: Resolved| match r {
            Resolved::Node(id) => Next::Node(id.0),
            Resolved::Decision(d) => Next::Decision(decision(d)),
        };
        let mut nodes = Vec::with_capacity(graph.nodes.len());
        for (i, node) in graph.nodes.iter().enumerate() {
            let mut args = Vec::with_capacity(node.tool.args.len());
            let mut computed_args = Vec::new();
            for (k, a) in node.tool.args.iter().enumerate() {
                match a {
                    Arg::Number(x) => args.push(*x),
                    Arg::Param(p) => {
                        let idx = graph.params.iter().position(|q| q.name == *p).unwrap_or(0);
                        match graph.params[idx].value {
                            ParamValue::Fixed { .. } => args.push(values[idx]),
                            ParamValue::Computed { .. } => {
                                let f = computed.iter().position(|(n, _)| *n == **p).unwrap_or(0);
                                computed_args.push((k, f));
                                args.push(0.0);
                            }
                        }
                    }
                }
            }
            let tool = DynTool::build(&node.tool.name, &args).expect("validated: built-in tool");
            let next = checked.answer_arm[i].iter().map(|&arm| to_next(checked.arms[i][arm])).collect();
            nodes.push(CompiledNode { tool, next, computed_args, args });
        }
        let start = to_next(checked.start);
        Ok(DagOracle { graph, values, computed, nodes, start, probe })
    }

    /// The graph.
    #[must_use]
    pub fn graph(&self) -> &Graph {
        &self.graph
    }

    /// The probe.
    #[must_use]
    pub fn probe(&self) -> &P {
        &self.probe
    }

    /// Value of each fixed parameter, in declaration order (computed ones read 0).
    #[must_use]
    pub fn param_values(&self) -> &[f64] {
        &self.values
    }
}

impl<P: Probe> Oracle for DagOracle<P> {
    fn name(&self) -> &str {
        &self.graph.name
    }

    fn needs(&self) -> crate::refine::Needs {
        self.nodes.iter().fold(crate::refine::Needs::NONE, |n, node| n.union(node.tool.needs()))
    }

    fn decide(&self, ctx: &mut LinkCtx<'_>) -> Decision {
        let mut next = self.start;
        loop {
            match next {
                Next::Decision(d) => return d,
                Next::Node(i) => {
                    let node = &self.nodes[i as usize];
                    let t0 = P::start();
                    let (answer, names) = if node.computed_args.is_empty() {
                        node.tool.ask(ctx)
                    } else {
                        let mut args = node.args.clone();
                        for &(k, f) in &node.computed_args {
                            args[k] = (self.computed[f].1)(ctx);
                        }
                        let name = &self.graph.nodes[i as usize].tool.name;
                        DynTool::build(name, &args).unwrap_or(node.tool).ask(ctx)
                    };
                    if P::ENABLED {
                        self.probe.record(ctx, i as usize, answer, names, t0);
                    }
                    next = node.next[answer];
                }
            }
        }
    }
}
