//! Validation, shared by the `oracle!` macro and the DAG runtime so the rules exist once. Each rule
//! is one function; all problems are collected (not just the first), each with the [`Site`] it is
//! about, which the front ends turn into a span (macro) or a file line (graph files).

use crate::catalogue::{self, ToolInfo};
use crate::model::{Arg, DecisionKind, Graph, NodeId, Target};
use std::collections::HashMap;
use std::fmt;

/// How the validator learns a tool's answers and arguments.
#[derive(Clone, Copy, Debug)]
pub enum ToolLookup {
    /// A tool whose answers and arguments are known: checked here.
    Known(&'static ToolInfo),
    /// A tool defined elsewhere (user code): the Rust compiler checks its answers.
    Foreign,
    /// Not a tool at all: an error.
    Unknown,
}

/// Lookup for the DAG runtime: only built-in tools exist.
#[must_use]
pub fn builtin_only(name: &str) -> ToolLookup {
    catalogue::builtin(name).map_or(ToolLookup::Unknown, ToolLookup::Known)
}

/// Lookup for the macro: built-in tools are checked here, anything else is left to rustc.
#[must_use]
pub fn builtin_or_foreign(name: &str) -> ToolLookup {
    catalogue::builtin(name).map_or(ToolLookup::Foreign, ToolLookup::Known)
}

/// The place in a graph a problem is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Site {
    /// The start arc.
    Start,
    /// A parameter, by index.
    Param(usize),
    /// A node's name.
    Node(NodeId),
    /// A node's tool.
    Tool(NodeId),
    /// A tool argument: node, argument index.
    Arg(NodeId, usize),
    /// An answer of an arm: node, arm index, answer index within the arm.
    Answer(NodeId, usize, usize),
    /// The target of an arm: node, arm index.
    ArmTarget(NodeId, usize),
}

/// Which rule a problem breaks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// Two parameters with one name.
    DuplicateParam,
    /// Two nodes with one name.
    DuplicateNode,
    /// A node named like a decision.
    ReservedNodeName,
    /// An arc to a node that does not exist.
    UnknownNode,
    /// A tool that does not exist.
    UnknownTool,
    /// A tool given the wrong number of arguments.
    ArgumentCount,
    /// An argument naming a parameter that does not exist.
    UnknownParam,
    /// An argument of the wrong type (an `f64` where a tool counts, a fraction as a count).
    ArgumentType,
    /// A node without arms.
    EmptyNode,
    /// An answer handled by two arms (or twice in one).
    DuplicateAnswer,
    /// An answer the tool never gives.
    UnknownAnswer,
    /// An answer of the tool no arm handles.
    UnhandledAnswer,
    /// A cycle.
    Cycle,
    /// A node the start never reaches.
    UnreachableNode,
}

/// One problem: the rule, where, and a message in the graph's own words.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GraphError {
    /// The rule broken.
    pub kind: ErrorKind,
    /// Where.
    pub site: Site,
    /// Lowercase message, names in backticks, no final period.
    pub message: String,
}

impl fmt::Display for GraphError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for GraphError {}

/// Where an arc leads once names are resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Resolved {
    /// A node.
    Node(NodeId),
    /// A decision.
    Decision(DecisionKind),
}

/// A graph that passed validation, with names resolved to ids.
#[derive(Clone, Debug)]
pub struct Checked {
    /// Where the start arc leads.
    pub start: Resolved,
    /// Per node, per arm: where the arm leads.
    pub arms: Vec<Vec<Resolved>>,
    /// Per node: number of arcs (arms or start) leading to it.
    pub in_degree: Vec<u32>,
    /// Per node: the tool, when it is known.
    pub tools: Vec<Option<&'static ToolInfo>>,
    /// Per node, for known tools: the arm handling each answer (indexed by answer index).
    pub answer_arm: Vec<Vec<usize>>,
}

struct Ctx<'g> {
    graph: &'g Graph,
    errors: Vec<GraphError>,
}

impl Ctx<'_> {
    fn error(&mut self, kind: ErrorKind, site: Site, message: String) {
        self.errors.push(GraphError { kind, site, message });
    }
}

/// Validates `graph`, resolving tools with `lookup`. Returns every problem found, in graph order.
pub fn validate(graph: &Graph, lookup: &dyn Fn(&str) -> ToolLookup) -> Result<Checked, Vec<GraphError>> {
    let mut cx = Ctx { graph, errors: Vec::new() };
    check_params(&mut cx);
    let ids = check_node_names(&mut cx);
    let start = resolve_targets_start(&mut cx, &ids);
    let arms = resolve_arm_targets(&mut cx, &ids);
    let tools = check_tools(&mut cx, lookup);
    let answer_arm = check_answers(&mut cx, &tools);
    let in_degree = in_degrees(graph, start, &arms);
    check_cycles(&mut cx, start, &arms);
    check_reachable(&mut cx, start, &arms);
    if !cx.errors.is_empty() {
        return Err(cx.errors);
    }
    let resolve_all = |v: Vec<Option<Resolved>>| v.into_iter().map(|r| r.expect("resolved when there is no error")).collect();
    Ok(Checked {
        start: start.expect("resolved when there is no error"),
        arms: arms.into_iter().map(resolve_all).collect(),
        in_degree,
        tools,
        answer_arm,
    })
}

/// Parameter names are unique.
fn check_params(cx: &mut Ctx<'_>) {
    let g = cx.graph;
    for (i, p) in g.params.iter().enumerate() {
        if g.params[..i].iter().any(|q| q.name == p.name) {
            cx.error(ErrorKind::DuplicateParam, Site::Param(i), format!("duplicate parameter `{}`", p.name));
        }
    }
}

/// Node names are unique and are not decision words. Returns the name → id map (first wins).
fn check_node_names(cx: &mut Ctx<'_>) -> HashMap<String, NodeId> {
    let g = cx.graph;
    let mut ids: HashMap<String, NodeId> = HashMap::new();
    for (i, n) in g.nodes.iter().enumerate() {
        let id = NodeId(i as u32);
        if DecisionKind::from_keyword(&n.name).is_some() {
            cx.error(ErrorKind::ReservedNodeName, Site::Node(id), format!("node name `{}` is a decision word", n.name));
        }
        if ids.contains_key(&*n.name) {
            cx.error(ErrorKind::DuplicateNode, Site::Node(id), format!("duplicate node `{}`", n.name));
        } else {
            ids.insert(n.name.to_string(), id);
        }
    }
    ids
}

fn resolve(ids: &HashMap<String, NodeId>, t: &Target) -> Option<Resolved> {
    match t {
        Target::Decision(d) => Some(Resolved::Decision(*d)),
        Target::Node(n) => ids.get(&**n).map(|&id| Resolved::Node(id)),
    }
}

/// The start arc leads to a node that exists.
fn resolve_targets_start(cx: &mut Ctx<'_>, ids: &HashMap<String, NodeId>) -> Option<Resolved> {
    let r = resolve(ids, &cx.graph.start);
    if r.is_none() {
        let word = cx.graph.start.word().to_owned();
        cx.error(ErrorKind::UnknownNode, Site::Start, format!("unknown node `{word}`"));
    }
    r
}

/// Every arm leads to a node that exists or to a decision.
fn resolve_arm_targets(cx: &mut Ctx<'_>, ids: &HashMap<String, NodeId>) -> Vec<Vec<Option<Resolved>>> {
    let g = cx.graph;
    let mut out = Vec::with_capacity(g.nodes.len());
    for (i, n) in g.nodes.iter().enumerate() {
        let mut row = Vec::with_capacity(n.arms.len());
        for (a, arm) in n.arms.iter().enumerate() {
            let r = resolve(ids, &arm.target);
            if r.is_none() {
                cx.error(ErrorKind::UnknownNode, Site::ArmTarget(NodeId(i as u32), a), format!("unknown node `{}`", arm.target.word()));
            }
            row.push(r);
        }
        out.push(row);
    }
    out
}

/// Tools exist; known tools get the right number and types of arguments; arguments name declared
/// parameters.
fn check_tools(cx: &mut Ctx<'_>, lookup: &dyn Fn(&str) -> ToolLookup) -> Vec<Option<&'static ToolInfo>> {
    let g = cx.graph;
    let mut out = Vec::with_capacity(g.nodes.len());
    for (i, n) in g.nodes.iter().enumerate() {
        let id = NodeId(i as u32);
        let info = match lookup(&n.tool.name) {
            ToolLookup::Known(info) => {
                if info.args.len() != n.tool.args.len() {
                    let names: Vec<&str> = info.args.iter().map(|a| a.name).collect();
                    cx.error(
                        ErrorKind::ArgumentCount,
                        Site::Tool(id),
                        format!(
                            "tool `{}` takes {} argument(s) ({}), found {}",
                            info.name,
                            info.args.len(),
                            names.join(", "),
                            n.tool.args.len()
                        ),
                    );
                }
                Some(info)
            }
            ToolLookup::Foreign => None,
            ToolLookup::Unknown => {
                let known: Vec<&str> = catalogue::BUILTIN_TOOLS.iter().map(|t| t.name).collect();
                cx.error(ErrorKind::UnknownTool, Site::Tool(id), format!("unknown tool `{}` (tools: {})", n.tool.name, known.join(", ")));
                None
            }
        };
        for (k, arg) in n.tool.args.iter().enumerate() {
            let spec = info.and_then(|t| t.args.get(k));
            match arg {
                Arg::Param(p) => match (g.param(p), spec) {
                    (None, _) => cx.error(ErrorKind::UnknownParam, Site::Arg(id, k), format!("unknown parameter `{p}`")),
                    (Some(param), Some(spec)) if param.ty != spec.ty => cx.error(
                        ErrorKind::ArgumentType,
                        Site::Arg(id, k),
                        format!(
                            "argument `{}` of `{}` is `{}`, parameter `{p}` is `{}`",
                            spec.name,
                            n.tool.name,
                            spec.ty.rust_name(),
                            param.ty.rust_name()
                        ),
                    ),
                    _ => {}
                },
                Arg::Number(x) => {
                    if let Some(spec) = spec
                        && spec.ty == crate::model::ParamType::U32
                        && !(x.fract() == 0.0 && *x >= 0.0 && *x <= f64::from(u32::MAX))
                    {
                        cx.error(
                            ErrorKind::ArgumentType,
                            Site::Arg(id, k),
                            format!(
                                "argument `{}` of `{}` is a count (`u32`), found {}",
                                spec.name,
                                n.tool.name,
                                crate::model::format_number(*x)
                            ),
                        );
                    }
                }
            }
        }
        out.push(info);
    }
    out
}

/// Every node has an arm; no answer is handled twice; for known tools, every answer is handled
/// exactly once and no arm names an answer the tool never gives.
fn check_answers(cx: &mut Ctx<'_>, tools: &[Option<&'static ToolInfo>]) -> Vec<Vec<usize>> {
    let g = cx.graph;
    let mut out = Vec::with_capacity(g.nodes.len());
    for (i, n) in g.nodes.iter().enumerate() {
        let id = NodeId(i as u32);
        if n.arms.is_empty() {
            cx.error(ErrorKind::EmptyNode, Site::Node(id), format!("node `{}` has no arms", n.name));
        }
        let mut seen: Vec<&str> = Vec::new();
        for (a, arm) in n.arms.iter().enumerate() {
            for (k, ans) in arm.answers.iter().enumerate() {
                if seen.contains(&&**ans) {
                    cx.error(
                        ErrorKind::DuplicateAnswer,
                        Site::Answer(id, a, k),
                        format!("answer `{ans}` is handled twice in node `{}`", n.name),
                    );
                } else {
                    seen.push(ans);
                }
                if let Some(info) = tools[i]
                    && info.answer_index(ans).is_none()
                {
                    cx.error(
                        ErrorKind::UnknownAnswer,
                        Site::Answer(id, a, k),
                        format!("`{ans}` is not an answer of `{}` (answers: {})", info.name, info.answers.join(", ")),
                    );
                }
            }
        }
        let mut map = Vec::new();
        if let Some(info) = tools[i] {
            let missing: Vec<&str> = info.answers.iter().copied().filter(|a| !seen.contains(a)).collect();
            if !missing.is_empty() && !n.arms.is_empty() {
                cx.error(
                    ErrorKind::UnhandledAnswer,
                    Site::Node(id),
                    format!("node `{}` does not handle answer(s) `{}` of `{}`", n.name, missing.join("`, `"), info.name),
                );
            }
            map = info
                .answers
                .iter()
                .map(|ans| n.arms.iter().position(|arm| arm.answers.iter().any(|x| x == ans)).unwrap_or(usize::MAX))
                .collect();
        }
        out.push(map);
    }
    out
}

fn in_degrees(g: &Graph, start: Option<Resolved>, arms: &[Vec<Option<Resolved>>]) -> Vec<u32> {
    let mut deg = vec![0u32; g.nodes.len()];
    let targets = std::iter::once(start).chain(arms.iter().flatten().copied());
    for t in targets {
        if let Some(Resolved::Node(id)) = t {
            deg[id.index()] += 1;
        }
    }
    deg
}

/// The graph is acyclic. Each cycle is reported once, at the arc that closes it, with its path.
fn check_cycles(cx: &mut Ctx<'_>, start: Option<Resolved>, arms: &[Vec<Option<Resolved>>]) {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        OnStack,
        Done,
    }
    let n = arms.len();
    let mut mark = vec![Mark::New; n];
    // Roots: the start first, then every node in order (cycles among unreachable nodes count too).
    let mut roots: Vec<usize> = Vec::new();
    if let Some(Resolved::Node(id)) = start {
        roots.push(id.index());
    }
    roots.extend(0..n);
    for root in roots {
        if mark[root] != Mark::New {
            continue;
        }
        // Iterative DFS: (node, next arm index).
        let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
        mark[root] = Mark::OnStack;
        while let Some(&mut (node, ref mut arm)) = stack.last_mut() {
            if *arm == arms[node].len() {
                mark[node] = Mark::Done;
                stack.pop();
                continue;
            }
            let a = *arm;
            *arm += 1;
            let Some(Resolved::Node(next)) = arms[node][a] else { continue };
            match mark[next.index()] {
                Mark::New => {
                    mark[next.index()] = Mark::OnStack;
                    stack.push((next.index(), 0));
                }
                Mark::OnStack => {
                    let from = stack.iter().position(|&(s, _)| s == next.index()).unwrap_or(0);
                    let mut path: Vec<String> = stack[from..].iter().map(|&(s, _)| format!("`{}`", cx.graph.nodes[s].name)).collect();
                    path.push(format!("`{}`", cx.graph.nodes[next.index()].name));
                    cx.error(ErrorKind::Cycle, Site::ArmTarget(NodeId(node as u32), a), format!("cycle: {}", path.join(" -> ")));
                }
                Mark::Done => {}
            }
        }
    }
}

/// Every node is reachable from the start (duplicates, reported already, excepted).
fn check_reachable(cx: &mut Ctx<'_>, start: Option<Resolved>, arms: &[Vec<Option<Resolved>>]) {
    let n = arms.len();
    let mut seen = vec![false; n];
    let mut todo: Vec<usize> = Vec::new();
    if let Some(Resolved::Node(id)) = start {
        seen[id.index()] = true;
        todo.push(id.index());
    } else if start.is_none() {
        // The start is broken and already reported: do not flood with unreachable nodes.
        return;
    }
    while let Some(i) = todo.pop() {
        for t in arms[i].iter().flatten() {
            if let Resolved::Node(id) = t
                && !seen[id.index()]
            {
                seen[id.index()] = true;
                todo.push(id.index());
            }
        }
    }
    for (i, s) in seen.iter().enumerate() {
        // A duplicate is already reported; its copy is never reached by name.
        let duplicate = cx.graph.nodes[..i].iter().any(|n| n.name == cx.graph.nodes[i].name);
        if !s && !duplicate {
            let name = cx.graph.nodes[i].name.to_string();
            cx.error(ErrorKind::UnreachableNode, Site::Node(NodeId(i as u32)), format!("node `{name}` is unreachable from `start`"));
        }
    }
}
