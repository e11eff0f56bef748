//! The refinement decision-graph model shared by the `oracle!` macro (compile time) and the DAG
//! runtime (run time): nodes, answers, decisions, the catalogue of built-in tools, validation and
//! DOT export. [`dsl`] holds the macro's parse → check → expand stages as plain functions.

pub mod catalogue;
pub mod dot;
pub mod dsl;
mod model;
pub mod validate;

pub use catalogue::{BUILTIN_TOOLS, Slot, ToolInfo, ToolKind};
pub use dot::to_dot;
pub use model::{Arg, Arm, DecisionKind, Graph, List, Node, NodeId, Param, ParamType, ParamValue, Str, Target, ToolRef, format_number};
pub use validate::{Checked, ErrorKind, GraphError, Resolved, Site, ToolLookup, validate};
