//! Graphviz DOT export: one box per node (its tool and arguments), one ellipse per decision used,
//! one edge per arm labelled with its answers. Output is in declaration order, so it is stable.

use crate::model::{Arg, DecisionKind, Graph, Target};
use std::fmt::Write;

/// The graph in DOT. `labels` may give an extra line per node (statistics), indexed like the nodes.
#[must_use]
pub fn to_dot(graph: &Graph, labels: Option<&[String]>) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "digraph \"{}\" {{", escape(&graph.name));
    out.push_str("    rankdir=TB;\n    node [fontname=\"Helvetica\"];\n");
    out.push_str("    start [shape=point];\n");
    for (i, n) in graph.nodes.iter().enumerate() {
        let args: Vec<String> = n
            .tool
            .args
            .iter()
            .map(|a| match a {
                Arg::Param(p) => p.to_string(),
                Arg::Number(x) => crate::model::format_number(*x),
            })
            .collect();
        let call = if args.is_empty() { n.tool.name.to_string() } else { format!("{}({})", n.tool.name, args.join(", ")) };
        let extra = labels.and_then(|l| l.get(i)).map(|s| format!("\\n{}", escape(s))).unwrap_or_default();
        let _ = writeln!(out, "    \"{}\" [shape=box, label=\"{}\\n{}{}\"];", escape(&n.name), escape(&n.name), escape(&call), extra);
    }
    let mut used: Vec<DecisionKind> = Vec::new();
    let mut note = |t: &Target| {
        if let Target::Decision(d) = t
            && !used.contains(d)
        {
            used.push(*d);
        }
    };
    note(&graph.start);
    for n in graph.nodes.iter() {
        for arm in n.arms.iter() {
            note(&arm.target);
        }
    }
    used.sort();
    for d in used {
        let _ = writeln!(out, "    \"{}\" [shape=ellipse, style=filled, fillcolor=\"#eeeeee\"];", d.keyword());
    }
    let _ = writeln!(out, "    start -> \"{}\";", escape(graph.start.word()));
    for n in graph.nodes.iter() {
        for arm in n.arms.iter() {
            let answers: Vec<&str> = arm.answers.iter().map(|a| &**a).collect();
            let _ = writeln!(
                out,
                "    \"{}\" -> \"{}\" [label=\"{}\"];",
                escape(&n.name),
                escape(arm.target.word()),
                escape(&answers.join(" | "))
            );
        }
    }
    out.push_str("}\n");
    out
}

fn escape(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"")
}
