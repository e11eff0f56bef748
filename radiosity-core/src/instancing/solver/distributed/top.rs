//! The coordinator's part: the top level solved alone, its closed instances encoded as subtrees
//! for other processes.

use super::Driver;
use super::wire::{put_emitters, put_task};
use crate::geom::Poly;
use crate::instancing::InstancingError;
use crate::instancing::model::{InstancedScene, PrototypeId};
use crate::instancing::solver::config::{InstancedConfig, InstancedStats};
use crate::instancing::solver::sink::RadiositySink;
use crate::instancing::solver::task::Task;

/// A top-level instance's subtree, ready to be sent to another process.
#[derive(Clone, Debug)]
pub struct Subtree {
    /// The encoded task (with the top level's emitters), the message a worker receives.
    pub bytes: Vec<u8>,
    /// The instance's prototype.
    pub prototype: PrototypeId,
    /// Its first flattened polygon index.
    pub flat_base: u64,
    /// Its flattened polygon count (two-sided polygons counted twice): an estimate of its cost.
    pub polygons: u64,
}

/// The top level solved by the coordinating process.
#[derive(Debug)]
pub struct TopLevel {
    /// The top level's closed instances, in the order one process solves them and writes their
    /// polygons.
    pub subtrees: Vec<Subtree>,
    /// Figures of the top-level solve alone.
    pub stats: InstancedStats,
}

/// The coordinator's driver: takes the top level's instances instead of solving them.
struct Top<'a> {
    sink: &'a mut dyn RadiositySink,
    counts: Vec<u64>,
    subtrees: Vec<Subtree>,
}

impl Driver for Top<'_> {
    fn sink(&mut self) -> &mut dyn RadiositySink {
        self.sink
    }
    fn top_level_done(&mut self, stack: &mut Vec<Task>, emitters: &[(Poly, [f64; 3])]) -> Result<(), InstancingError> {
        for task in std::mem::take(stack).into_iter().rev() {
            let mut bytes = Vec::new();
            put_emitters(&mut bytes, emitters);
            put_task(&mut bytes, &task);
            let polygons = self.counts.get(task.prototype as usize).copied().unwrap_or(0);
            self.subtrees.push(Subtree { bytes, prototype: task.prototype, flat_base: task.flat_base, polygons });
        }
        Ok(())
    }
    fn next(&mut self, _emitters: &mut Vec<(Poly, [f64; 3])>) -> Result<Option<Task>, InstancingError> {
        Ok(None)
    }
}

/// Solves the top level of `scene` alone, streaming its own polygons to `sink`, and returns its
/// closed instances' subtrees for other processes ([`solve_subtrees`](super::solve_subtrees)).
pub fn solve_top_level(
    scene: &InstancedScene,
    config: &InstancedConfig,
    sink: &mut dyn RadiositySink,
) -> Result<TopLevel, InstancingError> {
    let mut top = Top { sink, counts: scene.flattened_counts(true), subtrees: Vec::new() };
    let stats = rayon::scope(|_| super::solve_depth_first(scene, config, &mut top))?;
    Ok(TopLevel { subtrees: top.subtrees, stats })
}
