//! The graph model: nodes that ask a tool, arms that map the tool's answers to the next node or to a
//! decision, parameters, and the start arc. Every list is a `Cow` so a graph can be a `const` (the
//! `oracle!` macro emits one) as well as built at run time (the builder API and graph files).

use std::borrow::Cow;

/// A string that is `'static` in a constant graph and owned in a built one.
pub type Str = Cow<'static, str>;
/// A list that is `'static` in a constant graph and owned in a built one.
pub type List<T> = Cow<'static, [T]>;

/// Index of a node in [`Graph::nodes`] (declaration order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(pub u32);

impl NodeId {
    /// The index as `usize`.
    #[must_use]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// What a graph finally says for a link; mirrors the refiner's `Decision`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum DecisionKind {
    /// Keep the link at this level.
    Link,
    /// Subdivide the emitter.
    SubdivideEmitter,
    /// Subdivide the receiver.
    SubdivideReceiver,
    /// Subdivide both.
    SubdivideBoth,
    /// Drop the link.
    Stop,
}

impl DecisionKind {
    /// Every decision, in declaration order.
    pub const ALL: [DecisionKind; 5] = [
        DecisionKind::Link,
        DecisionKind::SubdivideEmitter,
        DecisionKind::SubdivideReceiver,
        DecisionKind::SubdivideBoth,
        DecisionKind::Stop,
    ];

    /// The word that names the decision in a graph (`link`, `subdivide_emitter`, ...).
    #[must_use]
    pub fn keyword(self) -> &'static str {
        match self {
            DecisionKind::Link => "link",
            DecisionKind::SubdivideEmitter => "subdivide_emitter",
            DecisionKind::SubdivideReceiver => "subdivide_receiver",
            DecisionKind::SubdivideBoth => "subdivide_both",
            DecisionKind::Stop => "stop",
        }
    }

    /// The variant name of the refiner's `Decision` enum.
    #[must_use]
    pub fn variant(self) -> &'static str {
        match self {
            DecisionKind::Link => "Link",
            DecisionKind::SubdivideEmitter => "SubdivideEmitter",
            DecisionKind::SubdivideReceiver => "SubdivideReceiver",
            DecisionKind::SubdivideBoth => "SubdivideBoth",
            DecisionKind::Stop => "Stop",
        }
    }

    /// The decision a keyword names, if it names one.
    #[must_use]
    pub fn from_keyword(word: &str) -> Option<DecisionKind> {
        DecisionKind::ALL.into_iter().find(|d| d.keyword() == word)
    }
}

/// Where an arc goes: another node (by name) or a decision.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    /// The node of that name.
    Node(Str),
    /// A final decision.
    Decision(DecisionKind),
}

impl Target {
    /// Parses a target word: a decision keyword, otherwise a node name.
    #[must_use]
    pub fn parse(word: &str) -> Target {
        match DecisionKind::from_keyword(word) {
            Some(d) => Target::Decision(d),
            None => Target::Node(Cow::Owned(word.to_owned())),
        }
    }

    /// The word for this target, as written in a graph.
    #[must_use]
    pub fn word(&self) -> &str {
        match self {
            Target::Node(n) => n,
            Target::Decision(d) => d.keyword(),
        }
    }
}

/// One argument of a tool: a parameter of the graph, or a number written in place.
#[derive(Clone, Debug, PartialEq)]
pub enum Arg {
    /// The graph parameter of that name.
    Param(Str),
    /// A literal number.
    Number(f64),
}

/// A tool and its arguments, as a node asks it.
#[derive(Clone, Debug, PartialEq)]
pub struct ToolRef {
    /// The tool's name: a built-in name from [`crate::catalogue`], or a Rust path in macro graphs.
    pub name: Str,
    /// Arguments in the tool's order.
    pub args: List<Arg>,
}

/// One arm: the answers it matches and where they lead.
#[derive(Clone, Debug, PartialEq)]
pub struct Arm {
    /// Answer names (variants of the tool's answer enum), at least one.
    pub answers: List<Str>,
    /// Next node or decision.
    pub target: Target,
}

/// A node: asks one tool and branches on its answer.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Unique name within its graph.
    pub name: Str,
    /// The tool asked.
    pub tool: ToolRef,
    /// The arms, in the order written.
    pub arms: List<Arm>,
}

/// The value type of a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamType {
    /// A real number.
    F64,
    /// A count (rays, samples).
    U32,
}

impl ParamType {
    /// The Rust spelling of the type.
    #[must_use]
    pub fn rust_name(self) -> &'static str {
        match self {
            ParamType::F64 => "f64",
            ParamType::U32 => "u32",
        }
    }

    /// The type named by a Rust type word (`f64`, `u32`).
    #[must_use]
    pub fn from_rust_name(word: &str) -> Option<ParamType> {
        match word {
            "f64" => Some(ParamType::F64),
            "u32" => Some(ParamType::U32),
            _ => None,
        }
    }
}

/// How a parameter gets its value.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    /// A value set once per run, with its default and the inclusive range it may be set in.
    Fixed {
        /// Default value.
        default: f64,
        /// Smallest allowed value.
        min: f64,
        /// Largest allowed value.
        max: f64,
    },
    /// Computed for each link by a function of the link context (its source is shown in docs).
    Computed {
        /// The function's source text, for listings.
        source: Str,
    },
}

/// A number as a person writes it: plain for ordinary magnitudes, in exponent form for very large
/// or very small ones (`1e300`, not three hundred digits).
#[must_use]
pub fn format_number(x: f64) -> String {
    let a = x.abs();
    if a != 0.0 && a.is_finite() && !(1e-4..1e6).contains(&a) { format!("{x:e}") } else { format!("{x}") }
}

/// A named parameter of a graph.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// Name, used by arguments and on the command line (`--param name=value`).
    pub name: Str,
    /// Value type.
    pub ty: ParamType,
    /// Fixed or computed.
    pub value: ParamValue,
}

impl Param {
    /// Checks a value set for this parameter: finite, of its type, within its range.
    pub fn check(&self, value: f64) -> Result<(), String> {
        match &self.value {
            ParamValue::Computed { .. } => Err(format!("parameter `{}` is computed per link and cannot be set", self.name)),
            ParamValue::Fixed { min, max, .. } => {
                if !value.is_finite() || value < *min || value > *max {
                    return Err(format!("parameter `{}` = {} is outside {}", self.name, format_number(value), self.range_text()));
                }
                if self.ty == ParamType::U32 && value.fract() != 0.0 {
                    return Err(format!("parameter `{}` = {} is not a whole number", self.name, format_number(value)));
                }
                Ok(())
            }
        }
    }

    /// The range as text, e.g. `[0, 1]`, or `computed` for computed parameters.
    #[must_use]
    pub fn range_text(&self) -> String {
        match &self.value {
            ParamValue::Fixed { min, max, .. } => format!("[{}, {}]", format_number(*min), format_number(*max)),
            ParamValue::Computed { .. } => "computed".to_owned(),
        }
    }
}

/// A refinement decision graph.
#[derive(Clone, Debug, PartialEq)]
pub struct Graph {
    /// Name of the oracle (or of the shared sub-graph).
    pub name: Str,
    /// Documentation, one paragraph.
    pub doc: Str,
    /// Parameters, in declaration order.
    pub params: List<Param>,
    /// The first node (or an immediate decision).
    pub start: Target,
    /// Nodes, in declaration order; [`NodeId`]s index this list.
    pub nodes: List<Node>,
}

impl Graph {
    /// The id of the node called `name` (the first one, if duplicated).
    #[must_use]
    pub fn node_id(&self, name: &str) -> Option<NodeId> {
        self.nodes.iter().position(|n| n.name == name).map(|i| NodeId(i as u32))
    }

    /// The node `id`.
    #[must_use]
    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id.index()]
    }

    /// The parameter called `name`.
    #[must_use]
    pub fn param(&self, name: &str) -> Option<&Param> {
        self.params.iter().find(|p| p.name == name)
    }

    /// Appends the nodes of a shared sub-graph (its parameters too, unless already declared), so
    /// several graphs can reuse one branch. Name clashes are left for [`crate::validate()`] to report.
    pub fn splice(&mut self, shared: &Graph) {
        self.nodes.to_mut().extend(shared.nodes.iter().cloned());
        for p in shared.params.iter() {
            if self.param(&p.name).is_none() {
                self.params.to_mut().push(p.clone());
            }
        }
    }
}
