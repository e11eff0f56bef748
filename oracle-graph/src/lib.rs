//! The refinement decision-graph model shared by the `oracle!` macro (compile time) and the DAG
//! runtime (run time): nodes, answers, decisions, validation and DOT export.
