//! Experiments on oracles that run whole solves: the benchmark of the BF oracle's three releases
//! ([`mod@bench`]), the visibility study ([`study`]) and the execution track of one link
//! ([`explain`]). They sit above the flow (`pipeline`), which they call; the oracles themselves
//! (`oracle`) only decide and must not solve.

pub mod bench;
mod explain;
pub mod study;

pub use explain::explain;
