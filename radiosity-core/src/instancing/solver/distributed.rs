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

use super::config::{InstancedConfig, InstancedStats, LevelReuse};
use super::occluders::Occluders;
use super::sink::{Leaf, PolygonInfo, RadiositySink};
use super::task::Task;
use crate::geom::{DVec3, Poly, PolyKind};
use crate::instancing::InstancingError;
use crate::instancing::model::{InstancedScene, PrototypeId, Transform};
use glam::DMat4;
use std::sync::mpsc::{Receiver, Sender};

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
/// closed instances' subtrees for other processes ([`solve_subtrees`]).
pub fn solve_top_level(
    scene: &InstancedScene,
    config: &InstancedConfig,
    sink: &mut dyn RadiositySink,
) -> Result<TopLevel, InstancingError> {
    let mut top = Top { sink, counts: scene.flattened_counts(true), subtrees: Vec::new() };
    let stats = rayon::scope(|_| super::solve_depth_first(scene, config, &mut top))?;
    Ok(TopLevel { subtrees: top.subtrees, stats })
}

/// What a worker reports while it solves the subtrees it receives.
#[derive(Debug)]
pub enum WorkerEvent {
    /// Encoded finished polygons of the current subtree (see [`replay`]), in order.
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
pub fn solve_subtrees(
    scene: &InstancedScene,
    config: &InstancedConfig,
    work: Receiver<Vec<u8>>,
    events: Sender<WorkerEvent>,
) -> Result<InstancedStats, InstancingError> {
    let mut worker = Worker { work, events, chunk: Vec::new(), started: None };
    rayon::scope(|_| super::solve_depth_first(scene, config, &mut worker))
}

/// Decodes the polygons of `bytes` (one or more [`WorkerEvent::Polygons`] chunks, whole) into
/// `sink`, in order; returns how many.
pub fn replay(bytes: &[u8], sink: &mut dyn RadiositySink) -> Result<u64, InstancingError> {
    let mut r = Reader { bytes, at: 0 };
    let mut n = 0;
    let mut leaves = Vec::new();
    while !r.done() {
        let info = PolygonInfo { flat_index: r.u64()?, material: r.u32()?, prototype: r.u32()? };
        let count = r.u32()? as usize;
        leaves.clear();
        for _ in 0..count {
            leaves.push(Leaf { poly: r.poly()?, b: r.rgb()?, h: r.rgb()? });
        }
        sink.polygon(&info, &leaves)?;
        n += 1;
    }
    Ok(n)
}

/// Encodes a finished polygon as [`replay`] reads it.
pub fn encode_polygon(out: &mut Vec<u8>, info: &PolygonInfo, leaves: &[Leaf]) {
    out.extend_from_slice(&info.flat_index.to_le_bytes());
    out.extend_from_slice(&info.material.to_le_bytes());
    out.extend_from_slice(&info.prototype.to_le_bytes());
    out.extend_from_slice(&(leaves.len() as u32).to_le_bytes());
    for leaf in leaves {
        put_poly(out, &leaf.poly);
        put_f64s(out, &leaf.b);
        put_f64s(out, &leaf.h);
    }
}

/// Encodes solve figures (and the sender's peak RSS) for [`decode_stats`].
#[must_use]
pub fn encode_stats(s: &InstancedStats, peak_rss_bytes: u64) -> Vec<u8> {
    let words = [
        s.local_solves,
        s.polygons_out,
        s.leaves_out,
        s.links,
        s.max_local_polygons as u64,
        s.max_local_links,
        s.cache_hits,
        s.cache_computed,
        s.levels_reused,
        s.levels_cached_peak_bytes,
        s.seconds.to_bits(),
        peak_rss_bytes,
    ];
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// Decodes [`encode_stats`]: the figures and the sender's peak RSS.
pub fn decode_stats(bytes: &[u8]) -> Result<(InstancedStats, u64), InstancingError> {
    let mut r = Reader { bytes, at: 0 };
    let mut w = [0u64; 12];
    for x in &mut w {
        *x = r.u64()?;
    }
    r.end()?;
    let s = InstancedStats {
        local_solves: w[0],
        polygons_out: w[1],
        leaves_out: w[2],
        links: w[3],
        max_local_polygons: w[4] as usize,
        max_local_links: w[5],
        cache_hits: w[6],
        cache_computed: w[7],
        levels_reused: w[8],
        levels_cached_peak_bytes: w[9],
        seconds: f64::from_bits(w[10]),
    };
    Ok((s, w[11]))
}

/// Adds the figures of `other` (another process's part of the solve) to `total`: counts add up,
/// largest figures take the larger; the wall-clock time stays `total`'s.
pub fn merge_stats(total: &mut InstancedStats, other: &InstancedStats) {
    total.local_solves += other.local_solves;
    total.polygons_out += other.polygons_out;
    total.leaves_out += other.leaves_out;
    total.links += other.links;
    total.max_local_polygons = total.max_local_polygons.max(other.max_local_polygons);
    total.max_local_links = total.max_local_links.max(other.max_local_links);
    total.cache_hits += other.cache_hits;
    total.cache_computed += other.cache_computed;
    total.levels_reused += other.levels_reused;
    total.levels_cached_peak_bytes = total.levels_cached_peak_bytes.max(other.levels_cached_peak_bytes);
}

fn put_f64s(out: &mut Vec<u8>, xs: &[f64]) {
    for x in xs {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

fn put_poly(out: &mut Vec<u8>, p: &Poly) {
    out.push(match p.kind {
        PolyKind::Triangle => 3,
        PolyKind::Quad => 4,
    });
    for v in &p.v {
        put_f64s(out, &v.to_array());
    }
}

fn put_emitters(out: &mut Vec<u8>, emitters: &[(Poly, [f64; 3])]) {
    out.extend_from_slice(&(emitters.len() as u64).to_le_bytes());
    for (p, e) in emitters {
        put_poly(out, p);
        put_f64s(out, e);
    }
}

fn put_task(out: &mut Vec<u8>, t: &Task) {
    out.extend_from_slice(&t.prototype.to_le_bytes());
    put_f64s(out, &t.transform.matrix.to_cols_array());
    out.extend_from_slice(&t.flat_base.to_le_bytes());
    out.extend_from_slice(&t.depth.to_le_bytes());
    match &t.incoming {
        None => out.push(0),
        Some(field) => {
            out.push(1);
            out.extend_from_slice(&(field.len() as u64).to_le_bytes());
            for f in field {
                put_f64s(out, f);
            }
        }
    }
    out.extend_from_slice(&(t.direct.len() as u64).to_le_bytes());
    for (b, e) in &t.direct {
        out.extend_from_slice(&b.to_le_bytes());
        put_f64s(out, e);
    }
    let occluders: Vec<&Poly> = t.occluders.iter().collect();
    out.extend_from_slice(&(occluders.len() as u64).to_le_bytes());
    for p in occluders {
        put_poly(out, p);
    }
}

/// Reads the little-endian encoding; every shortfall is an error, never a panic.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], InstancingError> {
        let end = self.at.checked_add(N).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(InstancingError::Distributed(format!("message cut short at byte {} of {}", self.at, self.bytes.len())));
        };
        let mut a = [0u8; N];
        a.copy_from_slice(&self.bytes[self.at..end]);
        self.at = end;
        Ok(a)
    }
    fn u8(&mut self) -> Result<u8, InstancingError> {
        Ok(self.take::<1>()?[0])
    }
    fn u32(&mut self) -> Result<u32, InstancingError> {
        Ok(u32::from_le_bytes(self.take()?))
    }
    fn u64(&mut self) -> Result<u64, InstancingError> {
        Ok(u64::from_le_bytes(self.take()?))
    }
    fn f64(&mut self) -> Result<f64, InstancingError> {
        Ok(f64::from_le_bytes(self.take()?))
    }
    fn rgb(&mut self) -> Result<[f64; 3], InstancingError> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }
    /// A count of items of at least `min_bytes` each, checked against the bytes left.
    fn count(&mut self, min_bytes: usize) -> Result<usize, InstancingError> {
        let n = self.u64()?;
        let left = (self.bytes.len() - self.at) as u64;
        if n.saturating_mul(min_bytes as u64) > left {
            return Err(InstancingError::Distributed(format!("message claims {n} items in {left} bytes")));
        }
        Ok(n as usize)
    }
    fn poly(&mut self) -> Result<Poly, InstancingError> {
        let kind = match self.u8()? {
            3 => PolyKind::Triangle,
            4 => PolyKind::Quad,
            k => return Err(InstancingError::Distributed(format!("bad polygon kind {k}"))),
        };
        let mut v = [DVec3::ZERO; 4];
        for x in &mut v {
            *x = DVec3::new(self.f64()?, self.f64()?, self.f64()?);
        }
        Ok(Poly { v, kind })
    }
    fn done(&self) -> bool {
        self.at >= self.bytes.len()
    }
    fn end(&self) -> Result<(), InstancingError> {
        if self.done() {
            Ok(())
        } else {
            Err(InstancingError::Distributed(format!("{} bytes left over in a message", self.bytes.len() - self.at)))
        }
    }
}

fn get_emitters(r: &mut Reader<'_>) -> Result<Vec<(Poly, [f64; 3])>, InstancingError> {
    let n = r.count(97 + 24)?;
    (0..n).map(|_| Ok((r.poly()?, r.rgb()?))).collect()
}

fn get_task(r: &mut Reader<'_>) -> Result<Task, InstancingError> {
    let prototype = r.u32()?;
    let mut m = [0.0; 16];
    for x in &mut m {
        *x = r.f64()?;
    }
    let transform = Transform { matrix: DMat4::from_cols_array(&m) };
    let flat_base = r.u64()?;
    let depth = r.u32()?;
    let incoming = match r.u8()? {
        0 => None,
        1 => {
            let n = r.count(24)?;
            Some((0..n).map(|_| r.rgb()).collect::<Result<Vec<_>, _>>()?)
        }
        k => return Err(InstancingError::Distributed(format!("bad field flag {k}"))),
    };
    let n = r.count(28)?;
    let direct = (0..n).map(|_| Ok((r.u32()?, r.rgb()?))).collect::<Result<Vec<_>, InstancingError>>()?;
    let n = r.count(97)?;
    let occluders = Occluders::from_polys((0..n).map(|_| r.poly()).collect::<Result<Vec<_>, _>>()?);
    Ok(Task { prototype, transform, flat_base, depth, incoming, direct, occluders })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Collects what a sink receives, bit for bit.
    #[derive(Default)]
    struct Bits(Vec<u64>);

    impl RadiositySink for Bits {
        fn polygon(&mut self, info: &PolygonInfo, leaves: &[Leaf]) -> Result<(), InstancingError> {
            self.0.extend([info.flat_index, u64::from(info.material), u64::from(info.prototype)]);
            for l in leaves {
                self.0.extend(l.poly.v.iter().flat_map(|v| v.to_array()).chain(l.b).chain(l.h).map(f64::to_bits));
                self.0.push(u64::from(l.poly.kind == PolyKind::Quad));
            }
            Ok(())
        }
    }

    #[test]
    fn polygons_round_trip_bit_for_bit_and_truncation_is_an_error() {
        let tri = Poly::triangle(DVec3::new(0.1, 1.0 / 3.0, -0.0), DVec3::new(f64::MIN_POSITIVE, 2.0, 3.0), DVec3::new(1e300, -7.5, 0.3));
        let leaves = [Leaf { poly: tri, b: [0.1, 0.2, 1.0 / 7.0], h: [5e-324, 1.0, 2.0] }];
        let info = PolygonInfo { flat_index: 123_456_789_012, material: 3, prototype: 7 };
        let mut bytes = Vec::new();
        encode_polygon(&mut bytes, &info, &leaves);
        encode_polygon(&mut bytes, &PolygonInfo { flat_index: 1, ..info }, &[]);
        let (mut direct, mut replayed) = (Bits::default(), Bits::default());
        direct.polygon(&info, &leaves).unwrap();
        direct.polygon(&PolygonInfo { flat_index: 1, ..info }, &[]).unwrap();
        assert_eq!(replay(&bytes, &mut replayed).unwrap(), 2);
        assert_eq!(direct.0, replayed.0);
        assert!(replay(&bytes[..bytes.len() - 1], &mut Bits::default()).is_err());
        assert!(replay(&bytes[..30], &mut Bits::default()).is_err());
    }

    #[test]
    fn stats_round_trip_and_merge() {
        let s = InstancedStats { local_solves: 3, max_local_polygons: 9, seconds: 0.1, levels_cached_peak_bytes: 5, ..Default::default() };
        let (back, rss) = decode_stats(&encode_stats(&s, 77)).unwrap();
        assert_eq!((back.local_solves, back.max_local_polygons, back.seconds.to_bits(), rss), (3, 9, 0.1f64.to_bits(), 77));
        let mut total = InstancedStats { local_solves: 1, max_local_polygons: 20, levels_cached_peak_bytes: 2, ..Default::default() };
        merge_stats(&mut total, &back);
        assert_eq!((total.local_solves, total.max_local_polygons, total.levels_cached_peak_bytes), (4, 20, 5));
        assert!(decode_stats(&[0; 95]).is_err());
    }

    /// The distributed machinery without MPI: the top level, then its subtrees on two worker
    /// threads in other orders than one process takes them (one worker takes the even ones
    /// backwards, the other the odd ones), the polygons replayed in order: the bits of one process
    /// solving with [`LevelReuse::Subtree`], and the same figures.
    #[test]
    fn subtrees_solved_on_threads_in_any_order_give_the_bits_of_one_process() {
        use crate::instancing::{ForestParams, generate_forest, solve_instanced};
        use std::sync::mpsc::channel;
        let scene = generate_forest(&ForestParams { trees: 2, min_age: 3, max_age: 4, ..ForestParams::default() });
        let config = InstancedConfig { level_reuse: LevelReuse::Subtree, ..InstancedConfig::default() };
        let mut one = Bits::default();
        let one_stats = solve_instanced(&scene, &config, &mut one).unwrap();

        let mut many = Bits::default();
        let top = solve_top_level(&scene, &config, &mut many).unwrap();
        let n = top.subtrees.len();
        assert!(n > 2, "{n} subtrees");
        let orders: [Vec<usize>; 2] = [(0..n).step_by(2).rev().collect(), (1..n).step_by(2).collect()];
        let mut results: Vec<Vec<u8>> = vec![Vec::new(); n];
        let mut stats = top.stats;
        std::thread::scope(|s| {
            let workers: Vec<_> = orders
                .iter()
                .map(|order| {
                    let (work, work_rx) = channel();
                    let (events_tx, events) = channel();
                    for &i in order {
                        work.send(top.subtrees[i].bytes.clone()).unwrap();
                    }
                    drop(work);
                    let (scene, config) = (&scene, &config);
                    (order, events, s.spawn(move || solve_subtrees(scene, config, work_rx, events_tx)))
                })
                .collect();
            for (order, events, handle) in workers {
                merge_stats(&mut stats, &handle.join().unwrap().unwrap());
                let mut next = order.iter();
                let mut current = *next.next().unwrap();
                for event in events.try_iter() {
                    match event {
                        WorkerEvent::Polygons(bytes) => results[current].extend_from_slice(&bytes),
                        WorkerEvent::Finished(_) => current = next.next().copied().unwrap_or(usize::MAX),
                    }
                }
                assert_eq!(current, usize::MAX, "every subtree finished");
            }
        });
        for bytes in &results {
            let _ = replay(bytes, &mut many).unwrap();
        }
        assert_eq!(one.0.len(), many.0.len());
        assert!(one.0 == many.0, "the distributed solve's bits differ from one process's");
        let counts = |s: &InstancedStats| (s.local_solves, s.levels_reused, s.links, s.polygons_out, s.leaves_out, s.max_local_links);
        assert_eq!(counts(&stats), counts(&one_stats));
        assert!(one_stats.levels_reused > 0, "levels are reused within subtrees");
    }
}
