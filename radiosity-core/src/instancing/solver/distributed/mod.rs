//! The instanced solve split over processes, without the transport: the top level in one process
//! ([`solve_top_level`]), each top-level instance's subtree in whichever process is free
//! ([`solve_subtrees`]), the finished polygons sent back as bytes and written in the order one
//! process writes them ([`replay`]).
//!
//! Below the top level the depth-first solve is embarrassingly parallel: a top-level instance's
//! subtree needs only the task that opens it (its prototype, transform, first flattened index,
//! the light field that reached its proxy, the direct part of that field and the occluders it
//! inherits) and the top level's emitters. Everything travels as little-endian bytes, so every
//! `f64` arrives with the same bits. With [`LevelReuse::Subtree`] the results of a subtree do not
//! depend on where or after which other subtree it is solved, so the bytes written are those of
//! one process solving with the same setting (see [`LevelReuse`]). The MPI transport is in the
//! `radiosity` binary (its `mpi` feature).
//!
//! # Layout
//! This file holds what the solve loop asks of its surroundings (`Driver`) and the one-process
//! driver; `top` the coordinator's part (the top level, its instances as [`Subtree`]s), `worker`
//! a worker's part (subtrees in, [`WorkerEvent`]s out), `wire` the bytes of tasks and finished
//! polygons, `figures` the bytes of the solve figures and how they add up; `tests` tests them
//! together.

mod figures;
mod top;
mod wire;
mod worker;

pub use figures::{decode_stats, encode_stats, merge_stats};
pub use top::{Subtree, TopLevel, solve_top_level};
pub use wire::{encode_polygon, replay};
pub use worker::{CHUNK_BYTES, WorkerEvent, solve_subtrees};

use super::config::LevelReuse;
use super::sink::RadiositySink;
// The solve loop the drivers below and in `top` and `worker` drive.
use super::solve_depth_first;
use super::task::Task;
use crate::geom::Poly;
use crate::instancing::InstancingError;

/// What the solve loop asks of its surroundings: where finished polygons go, and (for a
/// distributed solve) who takes the top level's instances and hands out the next one.
pub(super) trait Driver: Send {
    /// The sink finished polygons are streamed to.
    fn sink(&mut self) -> &mut dyn RadiositySink;
    /// The top level is solved and its closed instances are on `stack` (the last one is opened
    /// first): the driver may take them. `emitters` are the top level's emitters.
    fn top_level_done(&mut self, stack: &mut Vec<Task>, emitters: &[(Poly, [f64; 3])]) -> Result<(), InstancingError>;
    /// Whether the solve starts with the top level (a worker starts with an empty stack).
    fn starts_at_top(&self) -> bool {
        true
    }
    /// The stack is empty: the next subtree to solve, if any (`emitters` set for it).
    fn next(&mut self, emitters: &mut Vec<(Poly, [f64; 3])>) -> Result<Option<Task>, InstancingError>;
}

/// One process: the top level's instances stay on the stack, unless levels are reused per subtree,
/// when they are handed back one at a time so that the level cache is emptied between them.
pub(super) struct Alone<'a> {
    sink: &'a mut dyn RadiositySink,
    reuse: LevelReuse,
    queue: Vec<Task>,
}

impl<'a> Alone<'a> {
    pub(super) fn new(sink: &'a mut dyn RadiositySink, reuse: LevelReuse) -> Alone<'a> {
        Alone { sink, reuse, queue: Vec::new() }
    }
}

impl Driver for Alone<'_> {
    fn sink(&mut self) -> &mut dyn RadiositySink {
        self.sink
    }
    fn top_level_done(&mut self, stack: &mut Vec<Task>, _emitters: &[(Poly, [f64; 3])]) -> Result<(), InstancingError> {
        if self.reuse == LevelReuse::Subtree {
            self.queue = std::mem::take(stack);
        }
        Ok(())
    }
    fn next(&mut self, _emitters: &mut Vec<(Poly, [f64; 3])>) -> Result<Option<Task>, InstancingError> {
        Ok(self.queue.pop())
    }
}

#[cfg(test)]
mod tests;
