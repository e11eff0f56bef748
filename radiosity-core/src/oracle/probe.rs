//! Instrumentation of oracles: a [`Probe`] sees every node an oracle evaluates. Generated and
//! runtime oracles take the probe as a type parameter; with [`NoProbe`] (`ENABLED = false`) the
//! calls are removed at compile time, so the plain oracle costs nothing extra. [`Recorder`] keeps
//! per-node statistics and the execution track of one chosen emitter/receiver pair.

use crate::refine::{LinkCtx, LinkData};
use oracle_graph::Graph;
use std::sync::Mutex;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Receives one event per node evaluated.
pub trait Probe: Sync {
    /// False for probes that record nothing: callers skip the calls entirely.
    const ENABLED: bool;

    /// Called before a node's tool is asked; the value is handed back to [`Probe::record`].
    #[inline]
    fn start() -> Option<Instant> {
        None
    }

    /// Node `node` (index in the graph) answered `answer` (index in `names`, the answer enum's
    /// variant names); `t0` is what [`Probe::start`] returned.
    fn record(&self, ctx: &LinkCtx<'_>, node: usize, answer: usize, names: &'static [&'static str], t0: Option<Instant>);
}

/// The probe that records nothing (the plain oracle).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProbe;

impl Probe for NoProbe {
    const ENABLED: bool = false;

    #[inline(always)]
    fn record(&self, _: &LinkCtx<'_>, _: usize, _: usize, _: &'static [&'static str], _: Option<Instant>) {}
}

/// One step of an execution track.
#[derive(Clone, Debug)]
pub struct TraceStep {
    /// Node index in the graph.
    pub node: usize,
    /// The answer given (variant name).
    pub answer: &'static str,
    /// The link data after the tool ran: the values it used or computed.
    pub data: LinkData,
    /// The link's shaft classification and candidate count, once a tool classified it.
    pub shaft: Option<(crate::visibility::shaft::ShaftClass, usize)>,
    /// Time spent in the tool, nanoseconds.
    pub nanos: u64,
}

/// Statistics of one node.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct NodeStats {
    /// Node name.
    pub node: String,
    /// Times evaluated.
    pub calls: u64,
    /// Total time in its tool, seconds.
    pub seconds: f64,
    /// Count per answer (variant name), in enum order.
    pub answers: Vec<(String, u64)>,
    /// Arms never taken, as written (`A | B => target`).
    pub never_taken: Vec<String>,
}

#[derive(Default)]
struct Counters {
    calls: AtomicU64,
    nanos: AtomicU64,
    answers: [AtomicU64; MAX_ANSWERS],
    names: OnceLock<&'static [&'static str]>,
}

/// Most answers a tool may have for its counts to be kept.
pub const MAX_ANSWERS: usize = 16;

/// Records per-node statistics of every link, and the execution track of one pair.
pub struct Recorder {
    counters: Vec<Counters>,
    pair: Option<(u32, u32)>,
    trace: Mutex<Vec<TraceStep>>,
}

impl Recorder {
    /// A recorder for an oracle whose graph has `n_nodes` nodes, tracing no pair.
    #[must_use]
    pub fn new(n_nodes: usize) -> Recorder {
        Recorder { counters: (0..n_nodes).map(|_| Counters::default()).collect(), pair: None, trace: Mutex::new(Vec::new()) }
    }

    /// Also records the execution track of the link `emitter → receiver` (element ids).
    #[must_use]
    pub fn tracing(mut self, emitter: u32, receiver: u32) -> Recorder {
        self.pair = Some((emitter, receiver));
        self
    }

    /// The execution track of the traced pair, in evaluation order (empty if it was never asked).
    #[must_use]
    pub fn trace(&self) -> Vec<TraceStep> {
        self.trace.lock().map(|t| t.clone()).unwrap_or_default()
    }

    /// Statistics per node of `graph` (the graph the oracle was built from).
    #[must_use]
    pub fn stats(&self, graph: &Graph) -> Vec<NodeStats> {
        graph
            .nodes
            .iter()
            .zip(&self.counters)
            .map(|(node, c)| {
                let names: &[&str] = c.names.get().copied().unwrap_or(&[]);
                let count = |name: &str| {
                    names.iter().position(|n| *n == name).map_or(0, |i| c.answers[i.min(MAX_ANSWERS - 1)].load(Ordering::Relaxed))
                };
                let answers = names.iter().map(|n| ((*n).to_owned(), count(n))).collect();
                let never_taken = node
                    .arms
                    .iter()
                    .filter(|arm| arm.answers.iter().all(|a| count(a) == 0))
                    .map(|arm| {
                        let pats: Vec<&str> = arm.answers.iter().map(|a| &**a).collect();
                        format!("{} => {}", pats.join(" | "), arm.target.word())
                    })
                    .collect();
                NodeStats {
                    node: node.name.to_string(),
                    calls: c.calls.load(Ordering::Relaxed),
                    seconds: c.nanos.load(Ordering::Relaxed) as f64 * 1e-9,
                    answers,
                    never_taken,
                }
            })
            .collect()
    }
}

impl Probe for Recorder {
    const ENABLED: bool = true;

    #[inline]
    fn start() -> Option<Instant> {
        Some(Instant::now())
    }

    fn record(&self, ctx: &LinkCtx<'_>, node: usize, answer: usize, names: &'static [&'static str], t0: Option<Instant>) {
        let nanos = t0.map_or(0, |t| t.elapsed().as_nanos() as u64);
        let Some(c) = self.counters.get(node) else { return };
        let _ = c.names.set(names);
        c.calls.fetch_add(1, Ordering::Relaxed);
        c.nanos.fetch_add(nanos, Ordering::Relaxed);
        c.answers[answer.min(MAX_ANSWERS - 1)].fetch_add(1, Ordering::Relaxed);
        if self.pair == Some((ctx.emitter, ctx.receiver))
            && let Ok(mut t) = self.trace.lock()
        {
            let shaft = ctx.shaft.as_ref().map(|(class, candidates)| (*class, candidates.len()));
            t.push(TraceStep { node, answer: names.get(answer).copied().unwrap_or("?"), data: ctx.data, shaft, nanos });
        }
    }
}
