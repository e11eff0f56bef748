//! Refinement oracles as decision graphs (step 3, `refine`, seen from the oracle's side): the
//! [`Tool`] trait and the built-in [`tools`], parameters, instrumentation ([`Probe`]), the DAG
//! runtime ([`runtime`]), the BF oracle in its three releases ([`bf`]) and the scenes that benchmark
//! them, procedurally generated ([`scenes`]); the benchmark itself is `crate::lab::bench`.
//!
//! The per-link data manager is [`crate::refine::LinkData`]: each slot is filled by the first tool
//! that asks for it, at the precision it asks (form factor quality, ray count), and reused by
//! tools asking for less; a graph whose tools never ask for visibility never casts a ray.

pub mod bf;
mod probe;
pub mod registry;
pub mod runtime;
pub mod scenes;
pub mod shaft;
pub mod tools;

pub use oracle_graph as graph;
pub use probe::{NoProbe, NodeStats, Probe, Recorder, TraceStep};

use crate::refine::LinkCtx;

/// A question or command asked of a link. Tools are plain values (unit or tuple structs whose
/// fields are the arguments, in order), so the `oracle!` macro builds them in place for free.
pub trait Tool {
    /// The answer enum.
    type Answer: Answer;
    /// What the tool needs the pipeline to provide (shaft culling for the shaft tools).
    const NEEDS: crate::refine::Needs = crate::refine::Needs::NONE;
    /// Asks the tool about the link; may compute and memoise link data in `ctx`.
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Self::Answer;
}

/// An answer enum: a fieldless enum whose variants are numbered from 0 in declaration order.
pub trait Answer: Copy {
    /// Variant names in declaration order.
    const NAMES: &'static [&'static str];
    /// The variant's position in [`Answer::NAMES`].
    fn index(&self) -> usize;
}

/// Declares an answer enum and implements [`Answer`] for it (for custom tools).
///
/// ```
/// radiosity_core::answer_enum! {
///     /// Is it bright?
///     pub enum Bright {
///         /// Brighter than the threshold.
///         Yes,
///         /// Not brighter.
///         No,
///     }
/// }
/// ```
#[macro_export]
macro_rules! answer_enum {
    ($(#[$m:meta])* $vis:vis enum $name:ident { $($(#[$vm:meta])* $var:ident),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        $vis enum $name { $($(#[$vm])* $var),+ }
        impl $crate::oracle::Answer for $name {
            const NAMES: &'static [&'static str] = &[$(stringify!($var)),+];
            fn index(&self) -> usize {
                *self as usize
            }
        }
    };
}

/// A parameter that could not be set: unknown name or value out of range. The message lists the
/// valid parameters and their ranges.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct ParamError {
    /// One line, lowercase.
    pub message: String,
}

/// Checks `name = value` against the parameters of `graph`.
pub fn check_param(graph: &graph::Graph, name: &str, value: f64) -> Result<(), ParamError> {
    match graph.param(name) {
        Some(p) => p.check(value).map_err(|message| ParamError { message }),
        None => Err(ParamError {
            message: format!("unknown parameter `{name}` of oracle `{}` (parameters: {})", graph.name, param_list(graph)),
        }),
    }
}

/// The parameters of `graph` as `name: type = default in [min, max]`, comma-separated (`none` if
/// it has none).
#[must_use]
pub fn param_list(graph: &graph::Graph) -> String {
    if graph.params.is_empty() {
        return "none".to_owned();
    }
    let items: Vec<String> = graph
        .params
        .iter()
        .map(|p| match &p.value {
            graph::ParamValue::Fixed { default, .. } => {
                format!("{}: {} = {} in {}", p.name, p.ty.rust_name(), graph::format_number(*default), p.range_text())
            }
            graph::ParamValue::Computed { source } => format!("{}: {} = computed {source}", p.name, p.ty.rust_name()),
        })
        .collect();
    items.join(", ")
}

/// Parses `name=value` (the command line's `--param`) into the name and the value.
pub fn parse_param_assignment(text: &str) -> Result<(String, f64), ParamError> {
    let Some((name, value)) = text.split_once('=') else {
        return Err(ParamError { message: format!("expected `name=value`, found `{text}`") });
    };
    let value: f64 = value.trim().parse().map_err(|_| ParamError { message: format!("`{}` is not a number", value.trim()) })?;
    Ok((name.trim().to_owned(), value))
}
