//! Refinement oracles as decision graphs: tools, the per-link data manager, the DAG runtime.
