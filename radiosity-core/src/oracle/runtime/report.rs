//! Text and DOT renderings of what a [`crate::oracle::Recorder`] gathered.

use crate::oracle::tools::ShaftAnswer;
use crate::oracle::{Answer, NodeStats, TraceStep};
use oracle_graph::Graph;
use std::fmt::Write;

/// The execution track as lines: `node: Tool(args) -> answer (values, time)`.
#[must_use]
pub fn format_trace(graph: &Graph, trace: &[TraceStep]) -> String {
    let mut out = String::new();
    for step in trace {
        let Some(node) = graph.nodes.get(step.node) else { continue };
        let d = &step.data;
        let mut values = Vec::new();
        if let Some((f, q)) = d.form_factor {
            values.push(format!("F={f:.6e} ({q:?})"));
        }
        if let Some(f) = d.form_factor_max {
            values.push(format!("F_max={f:.6e}"));
        }
        if let Some((lo, hi)) = d.form_factor_range {
            values.push(format!("F_range=[{lo:.6e}, {hi:.6e}]"));
        }
        if let Some((v, n)) = d.visibility {
            values.push(format!("V={v:.4} ({n} rays)"));
        }
        if let Some(a) = d.axis {
            values.push(format!("dist={:.4e}, proj=({:.4e}, {:.4e})", a.distance, a.projected_emitter, a.projected_receiver));
        }
        if let Some(m) = d.mark {
            values.push(format!("mark={m}"));
        }
        if let Some((class, candidates)) = step.shaft {
            let class = ShaftAnswer::NAMES[ShaftAnswer::from(class).index()].to_lowercase();
            values.push(format!("shaft={class} ({candidates} candidates)"));
        }
        let next = node.arms.iter().find(|a| a.answers.iter().any(|x| x == step.answer)).map_or("?", |a| a.target.word());
        let _ = writeln!(
            out,
            "{}: {} -> {} => {} [{}] {:.1} µs",
            node.name,
            node.tool.name,
            step.answer,
            next,
            values.join(", "),
            step.nanos as f64 * 1e-3
        );
    }
    out
}

/// Statistics as a table: node, calls, time, answers histogram, never-taken arms.
#[must_use]
pub fn format_stats(stats: &[NodeStats]) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "{:<16} {:>12} {:>10}  answers", "node", "calls", "time (s)");
    for s in stats {
        let answers: Vec<String> = s.answers.iter().map(|(a, n)| format!("{a}={n}")).collect();
        let _ = writeln!(out, "{:<16} {:>12} {:>10.4}  {}", s.node, s.calls, s.seconds, answers.join(" "));
        for arm in &s.never_taken {
            let _ = writeln!(out, "{:<16} never taken: {arm}", "");
        }
    }
    out
}

/// DOT of `graph` with each node labelled by its call count and answer histogram.
#[must_use]
pub fn stats_dot(graph: &Graph, stats: &[NodeStats]) -> String {
    let labels: Vec<String> = stats
        .iter()
        .map(|s| {
            let answers: Vec<String> = s.answers.iter().map(|(a, n)| format!("{a}={n}")).collect();
            format!("{} calls; {}", s.calls, answers.join(" "))
        })
        .collect();
    oracle_graph::to_dot(graph, Some(&labels))
}
