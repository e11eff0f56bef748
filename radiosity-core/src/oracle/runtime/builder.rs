//! Building a graph in code.

use oracle_graph::{Arg, Arm, Graph, Node, Param, ParamType, ParamValue, Target, ToolRef};
use std::borrow::Cow;

/// Builds a [`Graph`] step by step: parameters, the start, then nodes each followed by its arms.
///
/// ```
/// use radiosity_core::oracle::runtime::GraphBuilder;
/// let g = GraphBuilder::new("tiny")
///     .start("facing")
///     .node("facing", "Facing", &[])
///     .arm(&["Yes"], "link")
///     .arm(&["No"], "stop")
///     .build();
/// assert_eq!(g.nodes.len(), 1);
/// ```
#[derive(Clone, Debug)]
pub struct GraphBuilder {
    graph: Graph,
}

/// An argument given to [`GraphBuilder::node`]: a parameter name or a number.
#[derive(Clone, Debug)]
pub enum BuildArg {
    /// A parameter.
    Param(&'static str),
    /// A number.
    Number(f64),
}

impl From<&'static str> for BuildArg {
    fn from(p: &'static str) -> BuildArg {
        BuildArg::Param(p)
    }
}

impl From<f64> for BuildArg {
    fn from(x: f64) -> BuildArg {
        BuildArg::Number(x)
    }
}

impl GraphBuilder {
    /// An empty graph called `name` starting at `stop`.
    #[must_use]
    pub fn new(name: &str) -> GraphBuilder {
        GraphBuilder {
            graph: Graph {
                name: Cow::Owned(name.to_owned()),
                doc: Cow::Borrowed(""),
                params: Cow::Owned(Vec::new()),
                start: Target::parse("stop"),
                nodes: Cow::Owned(Vec::new()),
            },
        }
    }

    /// Sets the documentation.
    #[must_use]
    pub fn doc(mut self, doc: &str) -> GraphBuilder {
        self.graph.doc = Cow::Owned(doc.to_owned());
        self
    }

    /// Declares a fixed parameter with its default and inclusive range.
    #[must_use]
    pub fn param(mut self, name: &str, ty: ParamType, default: f64, min: f64, max: f64) -> GraphBuilder {
        self.graph.params.to_mut().push(Param { name: Cow::Owned(name.to_owned()), ty, value: ParamValue::Fixed { default, min, max } });
        self
    }

    /// Declares a parameter computed per link (its function is given to the oracle).
    #[must_use]
    pub fn computed_param(mut self, name: &str, ty: ParamType, description: &str) -> GraphBuilder {
        let value = ParamValue::Computed { source: Cow::Owned(description.to_owned()) };
        self.graph.params.to_mut().push(Param { name: Cow::Owned(name.to_owned()), ty, value });
        self
    }

    /// Sets where the graph starts (a node name or a decision word).
    #[must_use]
    pub fn start(mut self, target: &str) -> GraphBuilder {
        self.graph.start = Target::parse(target);
        self
    }

    /// Adds a node asking `tool` with `args`; its arms follow with [`GraphBuilder::arm`].
    #[must_use]
    pub fn node(mut self, name: &str, tool: &str, args: &[BuildArg]) -> GraphBuilder {
        let args: Vec<Arg> = args
            .iter()
            .map(|a| match a {
                BuildArg::Param(p) => Arg::Param(Cow::Borrowed(p)),
                BuildArg::Number(x) => Arg::Number(*x),
            })
            .collect();
        let node = Node {
            name: Cow::Owned(name.to_owned()),
            tool: ToolRef { name: Cow::Owned(tool.to_owned()), args: Cow::Owned(args) },
            arms: Cow::Owned(Vec::new()),
        };
        self.graph.nodes.to_mut().push(node);
        self
    }

    /// Adds an arm to the last node: these answers lead to `target` (a node or a decision word).
    /// Without a node, the arm is ignored.
    #[must_use]
    pub fn arm(mut self, answers: &[&str], target: &str) -> GraphBuilder {
        if let Some(node) = self.graph.nodes.to_mut().last_mut() {
            let answers = answers.iter().map(|a| Cow::Owned((*a).to_owned())).collect::<Vec<_>>();
            node.arms.to_mut().push(Arm { answers: Cow::Owned(answers), target: Target::parse(target) });
        }
        self
    }

    /// Splices in the nodes (and missing parameters) of a shared sub-graph.
    #[must_use]
    pub fn use_shared(mut self, shared: &Graph) -> GraphBuilder {
        self.graph.splice(shared);
        self
    }

    /// The graph (not validated: [`super::DagOracle::new`] validates).
    #[must_use]
    pub fn build(self) -> Graph {
        self.graph
    }
}
