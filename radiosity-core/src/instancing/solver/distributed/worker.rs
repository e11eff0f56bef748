//! A worker's part: subtrees received as bytes, solved one after the other, their polygons sent
//! back in chunks.

use super::Driver;
use super::wire::{Reader, encode_polygon, get_emitters, get_task};
use crate::geom::Poly;
use crate::instancing::InstancingError;
use crate::instancing::model::InstancedScene;
use crate::instancing::solver::config::{InstancedConfig, InstancedStats};
use crate::instancing::solver::sink::{Leaf, PolygonInfo, RadiositySink};
use crate::instancing::solver::task::Task;
use std::sync::mpsc::{Receiver, Sender};

/// What a worker reports while it solves the subtrees it receives.
#[derive(Debug)]
pub enum WorkerEvent {
    /// Encoded finished polygons of the current subtree (see [`replay`](super::replay)), in order.
    Polygons(Vec<u8>),
    /// The current subtree is finished, after this many seconds.
    Finished(f64),
}

/// Bytes of encoded polygons gathered before they are sent as one [`WorkerEvent::Polygons`].
pub const CHUNK_BYTES: usize = 1 << 20;

/// The worker's driver and sink: receives subtrees, sends their polygons back in chunks.
struct Worker {
    work: Receiver<Vec<u8>>,
    events: Sender<WorkerEvent>,
    chunk: Vec<u8>,
    started: Option<std::time::Instant>,
}

impl Worker {
    fn send(&self, event: WorkerEvent) -> Result<(), InstancingError> {
        self.events.send(event).map_err(|_| InstancingError::Distributed("the process's message loop has stopped".into()))
    }
}

impl RadiositySink for Worker {
    fn polygon(&mut self, info: &PolygonInfo, leaves: &[Leaf]) -> Result<(), InstancingError> {
        encode_polygon(&mut self.chunk, info, leaves);
        if self.chunk.len() >= CHUNK_BYTES {
            let chunk = std::mem::take(&mut self.chunk);
            self.send(WorkerEvent::Polygons(chunk))?;
        }
        Ok(())
    }
}

impl Driver for Worker {
    fn sink(&mut self) -> &mut dyn RadiositySink {
        self
    }
    fn starts_at_top(&self) -> bool {
        false
    }
    fn top_level_done(&mut self, _stack: &mut Vec<Task>, _emitters: &[(Poly, [f64; 3])]) -> Result<(), InstancingError> {
        Err(InstancingError::Distributed("a worker was handed the top level".into()))
    }
    fn next(&mut self, emitters: &mut Vec<(Poly, [f64; 3])>) -> Result<Option<Task>, InstancingError> {
        if let Some(t) = self.started.take() {
            if !self.chunk.is_empty() {
                let chunk = std::mem::take(&mut self.chunk);
                self.send(WorkerEvent::Polygons(chunk))?;
            }
            self.send(WorkerEvent::Finished(t.elapsed().as_secs_f64()))?;
        }
        let Ok(bytes) = self.work.recv() else { return Ok(None) };
        self.started = Some(std::time::Instant::now());
        let mut r = Reader { bytes: &bytes, at: 0 };
        *emitters = get_emitters(&mut r)?;
        let task = get_task(&mut r)?;
        r.end()?;
        Ok(Some(task))
    }
}

/// Solves the subtrees received on `work` ([`Subtree::bytes`]) one after the other until the
/// channel closes, sending each one's polygons and its end on `events`; returns the figures of
/// all of them. Prototype properties and (with [`LevelReuse::Scene`]) levels are kept from one
/// subtree to the next, as in one process; with [`LevelReuse::Subtree`] the level cache is emptied
/// before each.
///
/// [`Subtree::bytes`]: super::Subtree::bytes
/// [`LevelReuse::Scene`]: crate::instancing::LevelReuse::Scene
/// [`LevelReuse::Subtree`]: crate::instancing::LevelReuse::Subtree
pub fn solve_subtrees(
    scene: &InstancedScene,
    config: &InstancedConfig,
    work: Receiver<Vec<u8>>,
    events: Sender<WorkerEvent>,
) -> Result<InstancedStats, InstancingError> {
    let mut worker = Worker { work, events, chunk: Vec::new(), started: None };
    rayon::scope(|_| super::solve_depth_first(scene, config, &mut worker))
}
