//! The graph file format (TOML) of the DAG runtime. Errors name the file and the line.
//!
//! ```toml
//! name = "bf"
//! doc = "What it does."
//! start = "facing"            # a node, or a decision word
//! uses = ["split.toml"]       # shared sub-graphs (files relative to this one), spliced in
//!
//! [[param]]
//! name = "eps"
//! type = "f64"                # or "u32"; default "f64"
//! default = 0.01
//! min = 0.0                   # inclusive range, optional
//! max = 1.0
//!
//! [[node]]
//! name = "energy"
//! tool = "BfAbove"
//! args = ["eps"]              # parameter names or numbers
//! arms = [{ on = "No", to = "link" }, { on = "Yes", to = "size" }]   # `on = "A | B"` for several
//! ```
//! A shared sub-graph file has nodes (and parameters) but no `start`.

use oracle_graph::{Arg, Arm, Graph, Node, Param, ParamType, ParamValue, Site, Target, ToolRef, validate};
use serde::Deserialize;
use std::borrow::Cow;
use std::fmt;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// How deep `uses` may nest (a file using itself is caught by this too).
pub const MAX_USE_DEPTH: usize = 8;

/// One problem in a graph file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Located {
    /// The file.
    pub path: PathBuf,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for Located {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{l}: {}", self.path.display(), self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

/// A rejected graph file: every problem found, one per line when displayed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GraphFileError {
    /// The problems, in file order.
    pub errors: Vec<Located>,
}

impl GraphFileError {
    /// An error about the whole file.
    #[must_use]
    pub fn whole(path: &Path, message: String) -> GraphFileError {
        GraphFileError { errors: vec![Located { path: path.to_owned(), line: None, message }] }
    }
}

impl fmt::Display for GraphFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let lines: Vec<String> = self.errors.iter().map(ToString::to_string).collect();
        f.write_str(&lines.join("\n"))
    }
}

impl std::error::Error for GraphFileError {}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileGraph {
    name: Option<String>,
    doc: Option<String>,
    start: Option<Spanned<String>>,
    #[serde(default)]
    uses: Vec<Spanned<String>>,
    #[serde(default)]
    param: Vec<Spanned<FileParam>>,
    #[serde(default)]
    node: Vec<FileNode>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileParam {
    name: String,
    #[serde(rename = "type")]
    ty: Option<String>,
    default: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
    computed: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileNode {
    name: Spanned<String>,
    tool: Spanned<String>,
    #[serde(default)]
    args: Vec<Spanned<FileArg>>,
    #[serde(default)]
    arms: Vec<FileArm>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum FileArg {
    Param(String),
    Number(f64),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileArm {
    on: Spanned<String>,
    to: Spanned<String>,
}

/// Lines of one node's parts, for messages.
#[derive(Clone, Debug)]
struct NodeLines {
    path: PathBuf,
    name: usize,
    tool: usize,
    args: Vec<usize>,
    on: Vec<usize>,
    to: Vec<usize>,
}

struct Parsed {
    graph: Graph,
    start_line: Option<usize>,
    param_lines: Vec<(PathBuf, usize)>,
    nodes: Vec<NodeLines>,
}

fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// Reads, parses and validates the graph file at `path` (and the files it `uses`).
pub fn load_graph(path: &Path) -> Result<Graph, GraphFileError> {
    let text = std::fs::read_to_string(path).map_err(|e| GraphFileError::whole(path, format!("cannot read: {e}")))?;
    parse_graph(&text, path)
}

/// Parses and validates graph-file `text`; `path` names it in messages and locates its `uses`.
pub fn parse_graph(text: &str, path: &Path) -> Result<Graph, GraphFileError> {
    let parsed = parse_file(text, path, 0)?;
    let loc = |file: &Path, line: usize, message: String| Located { path: file.to_owned(), line: Some(line), message };
    match validate(&parsed.graph, &oracle_graph::validate::builtin_only) {
        Ok(_) => Ok(parsed.graph),
        Err(errors) => Err(GraphFileError {
            errors: errors
                .into_iter()
                .map(|e| {
                    let node = |id: oracle_graph::NodeId| &parsed.nodes[id.index()];
                    match e.site {
                        Site::Start => Located { path: path.to_owned(), line: parsed.start_line, message: e.message },
                        Site::Param(i) => loc(&parsed.param_lines[i].0, parsed.param_lines[i].1, e.message),
                        Site::Node(id) => loc(&node(id).path, node(id).name, e.message),
                        Site::Tool(id) => loc(&node(id).path, node(id).tool, e.message),
                        Site::Arg(id, k) => loc(&node(id).path, node(id).args[k], e.message),
                        Site::Answer(id, a, _) => loc(&node(id).path, node(id).on[a], e.message),
                        Site::ArmTarget(id, a) => loc(&node(id).path, node(id).to[a], e.message),
                    }
                })
                .collect(),
        }),
    }
}

/// A TOML error's message on one line (`toml` may give several lines, or none at the end of a file).
fn toml_reason(e: &toml::de::Error) -> String {
    let msg = e.message().trim();
    if msg.is_empty() { "invalid TOML".to_owned() } else { msg.replace('\n', "; ") }
}

fn parse_file(text: &str, path: &Path, depth: usize) -> Result<Parsed, GraphFileError> {
    let file: FileGraph = toml::from_str(text).map_err(|e| GraphFileError {
        errors: vec![Located { path: path.to_owned(), line: e.span().map(|s| line_of(text, s.start)), message: toml_reason(&e) }],
    })?;
    let mut errors = Vec::new();
    let at = |span: std::ops::Range<usize>| line_of(text, span.start);
    let mut params = Vec::new();
    let mut param_lines = Vec::new();
    for p in &file.param {
        let line = at(p.span());
        let fp = p.get_ref();
        let ty = match fp.ty.as_deref().unwrap_or("f64") {
            "f64" => ParamType::F64,
            "u32" => ParamType::U32,
            other => {
                errors.push(Located {
                    path: path.to_owned(),
                    line: Some(line),
                    message: format!("unsupported parameter type `{other}` (expected `f64` or `u32`)"),
                });
                continue;
            }
        };
        let value = match (&fp.computed, fp.default) {
            (Some(c), None) => ParamValue::Computed { source: Cow::Owned(c.clone()) },
            (None, Some(default)) => {
                let (lo, hi) = match ty {
                    ParamType::F64 => (f64::NEG_INFINITY, f64::INFINITY),
                    ParamType::U32 => (0.0, f64::from(u32::MAX)),
                };
                ParamValue::Fixed { default, min: fp.min.unwrap_or(lo), max: fp.max.unwrap_or(hi) }
            }
            _ => {
                errors.push(Located {
                    path: path.to_owned(),
                    line: Some(line),
                    message: format!("parameter `{}` needs exactly one of `default`, `computed`", fp.name),
                });
                continue;
            }
        };
        let param = Param { name: Cow::Owned(fp.name.clone()), ty, value };
        if let ParamValue::Fixed { default, .. } = param.value
            && let Err(m) = param.check(default)
        {
            errors.push(Located { path: path.to_owned(), line: Some(line), message: format!("default of {m}") });
            continue;
        }
        params.push(param);
        param_lines.push((path.to_owned(), line));
    }
    let mut nodes = Vec::new();
    let mut node_lines = Vec::new();
    for n in &file.node {
        let mut arms = Vec::new();
        let (mut on, mut to) = (Vec::new(), Vec::new());
        for arm in &n.arms {
            let answers: Vec<Cow<'static, str>> = arm.on.get_ref().split('|').map(|a| Cow::Owned(a.trim().to_owned())).collect();
            if answers.iter().any(|a| a.is_empty()) {
                errors.push(Located {
                    path: path.to_owned(),
                    line: Some(at(arm.on.span())),
                    message: format!("empty answer in `{}`", arm.on.get_ref()),
                });
            }
            arms.push(Arm { answers: Cow::Owned(answers), target: Target::parse(arm.to.get_ref().trim()) });
            on.push(at(arm.on.span()));
            to.push(at(arm.to.span()));
        }
        let args = n
            .args
            .iter()
            .map(|a| match a.get_ref() {
                FileArg::Param(p) => Arg::Param(Cow::Owned(p.clone())),
                FileArg::Number(x) => Arg::Number(*x),
            })
            .collect::<Vec<_>>();
        nodes.push(Node {
            name: Cow::Owned(n.name.get_ref().clone()),
            tool: ToolRef { name: Cow::Owned(n.tool.get_ref().clone()), args: Cow::Owned(args) },
            arms: Cow::Owned(arms),
        });
        node_lines.push(NodeLines {
            path: path.to_owned(),
            name: at(n.name.span()),
            tool: at(n.tool.span()),
            args: n.args.iter().map(|a| at(a.span())).collect(),
            on,
            to,
        });
    }
    let mut parsed = Parsed {
        graph: Graph {
            name: Cow::Owned(
                file.name.clone().unwrap_or_else(|| path.file_stem().map_or("graph".to_owned(), |s| s.to_string_lossy().into_owned())),
            ),
            doc: Cow::Owned(file.doc.clone().unwrap_or_default()),
            params: Cow::Owned(params),
            start: file.start.as_ref().map_or(Target::parse("stop"), |s| Target::parse(s.get_ref().trim())),
            nodes: Cow::Owned(nodes),
        },
        start_line: file.start.as_ref().map(|s| at(s.span())),
        param_lines,
        nodes: node_lines,
    };
    for u in &file.uses {
        let line = at(u.span());
        let err = |message: String| Located { path: path.to_owned(), line: Some(line), message };
        if depth >= MAX_USE_DEPTH {
            errors.push(err(format!("`uses` nested deeper than {MAX_USE_DEPTH} files (a file using itself?)")));
            continue;
        }
        let sub_path = path.parent().unwrap_or(Path::new(".")).join(u.get_ref());
        let sub_text = match std::fs::read_to_string(&sub_path) {
            Ok(t) => t,
            Err(e) => {
                errors.push(err(format!("cannot read shared sub-graph `{}`: {e}", sub_path.display())));
                continue;
            }
        };
        match parse_file(&sub_text, &sub_path, depth + 1) {
            Ok(sub) => {
                for (p, l) in sub.graph.params.iter().zip(sub.param_lines) {
                    if parsed.graph.param(&p.name).is_none() {
                        parsed.graph.params.to_mut().push(p.clone());
                        parsed.param_lines.push(l);
                    }
                }
                parsed.graph.nodes.to_mut().extend(sub.graph.nodes.iter().cloned());
                parsed.nodes.extend(sub.nodes);
            }
            Err(e) => errors.extend(e.errors),
        }
    }
    if file.start.is_none() && depth == 0 {
        errors.push(Located { path: path.to_owned(), line: Some(1), message: "missing `start`".to_owned() });
    }
    if errors.is_empty() { Ok(parsed) } else { Err(GraphFileError { errors }) }
}
