//! The instanced solve over MPI ranks (feature `mpi`; see docs/mpi.md).
//!
//! `mpirun -n K radiosity solve scene.toml ...` with K ≥ 2: rank 0 solves the top level and keeps
//! its closed instances' subtrees in a queue, in the order one process solves them; every other
//! rank asks for a subtree when it is idle (handed out in order, at most [`WINDOW_PER_WORKER`] per
//! worker ahead of the next one to write), solves it (keeping prototype properties, and levels
//! within the subtree, as one process does) and streams its finished polygons back in chunks;
//! rank 0 writes them in the queue's order, so its output files are those of one process run with
//! `--level-reuse subtree` (which a distributed run always uses). A process started without
//! `mpirun` (no MPI launcher in the environment) never initialises MPI: it is one process.
//!
//! Faults: a rank whose solve fails sends its error, and rank 0 ends the job naming the rank and the
//! subtree it held. A rank that dies is noticed by `mpirun`, which ends the job; rank 0 then says
//! which subtree each rank held (a SIGTERM watchdog). `RADIOSITY_MPI_FAIL=RANK:N` (a test hook)
//! makes rank RANK exit abruptly on receiving its N-th subtree. `RADIOSITY_MPI_LOG=FILE` makes rank
//! 0 write one CSV row per subtree (rank, polygons, bytes, seconds): the figures docs/mpi.md
//! projects from.

use anyhow::Context;
use mpi::point_to_point::{Destination, Source};
use mpi::topology::{Communicator, SimpleCommunicator};
use radiosity::instancing::distributed::{self, Subtree, WorkerEvent};
use radiosity::instancing::{InstancedConfig, InstancedScene, InstancedStats, RadiositySink};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::time::Instant;

/// A worker is idle (no payload).
const TAG_READY: i32 = 1;
/// Rank 0 hands out a subtree ([`Subtree::bytes`]).
const TAG_WORK: i32 = 2;
/// Rank 0 has no more subtrees: the worker sends its figures and ends.
const TAG_STOP: i32 = 3;
/// A chunk of finished polygons of the worker's current subtree.
const TAG_POLYGONS: i32 = 4;
/// The worker's current subtree is finished (its seconds, f64 little-endian).
const TAG_DONE: i32 = 5;
/// The worker's figures ([`distributed::encode_stats`]).
const TAG_STATS: i32 = 6;
/// The worker failed (a UTF-8 message).
const TAG_ERROR: i32 = 7;

/// Subtrees handed out at most this many times the workers ahead of the next one to write: bounds
/// what rank 0 holds of subtrees that finished ahead of an earlier one (when rank 0's writing is
/// the bottleneck, workers then wait instead of rank 0's memory growing).
const WINDOW_PER_WORKER: usize = 4;

/// Set once MPI is initialised with more than one rank.
static DISTRIBUTED: AtomicBool = AtomicBool::new(false);

/// Initialises MPI when the process was started by an MPI launcher (`mpirun`, `srun` with PMI),
/// and returns the universe, which finalises MPI when dropped. Without a launcher, nothing.
pub fn init() -> Option<mpi::environment::Universe> {
    let launched = ["OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"].iter().any(|v| std::env::var_os(v).is_some());
    if !launched {
        return None;
    }
    // Only the main thread calls MPI (the solve runs on other threads and talks through channels).
    let (universe, _) = mpi::initialize_with_threading(mpi::Threading::Funneled)?;
    if universe.world().size() > 1 {
        DISTRIBUTED.store(true, Ordering::SeqCst);
    }
    Some(universe)
}

/// Is this a run over two or more ranks?
pub fn distributed() -> bool {
    DISTRIBUTED.load(Ordering::SeqCst)
}

/// This process's rank (0 when not distributed).
pub fn rank() -> i32 {
    if distributed() { SimpleCommunicator::world().rank() } else { 0 }
}

/// Ends the whole job after an error was printed (a rank that only returned would leave the
/// others waiting for it).
pub fn abort_if_distributed() {
    if distributed() {
        SimpleCommunicator::world().abort(1);
    }
}

/// Refuses what a distributed run cannot do: everything but the instanced solve.
pub fn refuse_plain() -> anyhow::Result<()> {
    anyhow::ensure!(
        !distributed(),
        "under mpirun with {} ranks only the instanced solve (`radiosity solve SCENE.toml`, a scene with instances and no luminaires or grids) is distributed; run this without mpirun",
        SimpleCommunicator::world().size()
    );
    Ok(())
}

/// What rank 0 reports of a distributed run (stats.json's `mpi`).
pub struct Report {
    ranks: i32,
    subtrees: usize,
    top_level_seconds: f64,
    bytes_to_workers: u64,
    bytes_from_workers: u64,
    subtree_seconds_sum: f64,
    subtree_seconds_max: f64,
    largest_message_bytes: u64,
    write_seconds: f64,
    polygons_written: u64,
    peak_rss_bytes_per_rank: Vec<u64>,
}

impl Report {
    /// The report as stats.json's `mpi` object.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "ranks": self.ranks,
            "subtrees": self.subtrees,
            "top_level_seconds": self.top_level_seconds,
            "bytes_to_workers": self.bytes_to_workers,
            "bytes_from_workers": self.bytes_from_workers,
            "subtree_seconds_sum": self.subtree_seconds_sum,
            "subtree_seconds_max": self.subtree_seconds_max,
            "largest_message_bytes": self.largest_message_bytes,
            "write_seconds": self.write_seconds,
            "polygons_written": self.polygons_written,
            "peak_rss_bytes_per_rank": self.peak_rss_bytes_per_rank,
        })
    }
}

/// The instanced solve: in one process, or (distributed) rank 0's part. Rank 0 returns the merged
/// figures of all ranks and its report.
pub fn solve(
    scene: &InstancedScene,
    config: &InstancedConfig,
    sink: &mut dyn RadiositySink,
) -> anyhow::Result<(InstancedStats, Option<Report>)> {
    if !distributed() {
        return Ok((radiosity::instancing::solve_instanced(scene, config, sink)?, None));
    }
    coordinate(scene, config, sink).map(|(s, r)| (s, Some(r)))
}

/// Which subtree each rank holds, for the watchdog's message.
static IN_FLIGHT: Mutex<String> = Mutex::new(String::new());
/// Write end of the watchdog's pipe (-1 until installed).
static WATCHDOG_FD: AtomicI32 = AtomicI32::new(-1);

extern "C" fn on_term(_: libc::c_int) {
    let fd = WATCHDOG_FD.load(Ordering::SeqCst);
    if fd >= 0 {
        // SAFETY: write(2) is async-signal-safe; one byte from a static buffer.
        let _ = unsafe { libc::write(fd, b"t".as_ptr().cast(), 1) };
    }
}

/// On SIGTERM (mpirun ending the job because a rank died) prints which subtree each rank held
/// and exits, instead of dying silently.
fn install_watchdog() {
    let mut fds = [0 as libc::c_int; 2];
    // SAFETY: pipe(2) fills the two descriptors.
    if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
        return;
    }
    WATCHDOG_FD.store(fds[1], Ordering::SeqCst);
    let read_fd = fds[0];
    let _ = std::thread::Builder::new().name("mpi-watchdog".into()).spawn(move || {
        let mut b = [0u8; 1];
        // SAFETY: reads one byte into a local buffer.
        if unsafe { libc::read(read_fd, b.as_mut_ptr().cast(), 1) } == 1 {
            let held = IN_FLIGHT.lock().map(|s| s.clone()).unwrap_or_default();
            eprintln!("error: rank 0: the job was ended from outside (mpirun ends it when a rank dies; its message names the rank); subtrees in flight: {held}");
            // SAFETY: ends the process at once, as the signal would have.
            unsafe { libc::_exit(1) };
        }
    });
    // SAFETY: installs a handler that only writes to a pipe.
    unsafe {
        let _ = libc::signal(libc::SIGTERM, on_term as *const () as libc::sighandler_t);
    }
}

/// Receives the next message from `source`, sleeping between probes: MPI's blocking receive spins,
/// which takes a core from the solving ranks when ranks share cores (and rank 0 mostly waits).
fn receive<S: Source>(source: &S) -> (Vec<u8>, mpi::point_to_point::Status) {
    while source.immediate_probe().is_none() {
        std::thread::sleep(std::time::Duration::from_micros(500));
    }
    source.receive_vec::<u8>()
}

/// Writes encoded polygons to `sink`, timing it (rank 0's output stream, the part of a distributed
/// run that does not shrink with more ranks).
fn write(bytes: &[u8], sink: &mut dyn RadiositySink, report: &mut Report) -> anyhow::Result<()> {
    let t = Instant::now();
    report.polygons_written += distributed::replay(bytes, sink)?;
    report.write_seconds += t.elapsed().as_secs_f64();
    Ok(())
}

/// Describes subtree `i` of `n`.
fn describe(scene: &InstancedScene, i: usize, n: usize, s: &Subtree) -> String {
    format!(
        "subtree {} of {n} (instance of `{}`, flattened polygons {}..{})",
        i + 1,
        scene.prototype(s.prototype).name,
        s.flat_base,
        s.flat_base + s.polygons
    )
}

/// Rank 0: solves the top level, hands out the subtrees in order to whichever rank asks, writes
/// the polygons in order (buffering subtrees that finish ahead of an earlier one).
fn coordinate(scene: &InstancedScene, config: &InstancedConfig, sink: &mut dyn RadiositySink) -> anyhow::Result<(InstancedStats, Report)> {
    let world = SimpleCommunicator::world();
    let size = world.size();
    install_watchdog();
    let t0 = Instant::now();
    let top = distributed::solve_top_level(scene, config, sink)?;
    let top_level_seconds = t0.elapsed().as_secs_f64();
    let subtrees = top.subtrees;
    let mut stats = top.stats;
    let n = subtrees.len();
    let mut held: Vec<Option<usize>> = vec![None; size as usize];
    let mut done = vec![false; n];
    let mut pending: Vec<Vec<u8>> = vec![Vec::new(); n];
    let mut seconds = vec![0.0; n];
    let mut result_bytes = vec![0u64; n];
    let mut ranks = vec![0i32; n];
    let (mut next_hand, mut next_write, mut stopped) = (0usize, 0usize, 0);
    let mut idle: Vec<i32> = Vec::new();
    let window = WINDOW_PER_WORKER * (size as usize - 1);
    let mut report = Report {
        ranks: size,
        subtrees: n,
        top_level_seconds,
        bytes_to_workers: 0,
        bytes_from_workers: 0,
        subtree_seconds_sum: 0.0,
        subtree_seconds_max: 0.0,
        largest_message_bytes: 0,
        write_seconds: 0.0,
        polygons_written: 0,
        peak_rss_bytes_per_rank: vec![0; size as usize],
    };
    let update_in_flight = |held: &[Option<usize>]| {
        let text: Vec<String> = held
            .iter()
            .enumerate()
            .skip(1)
            .map(|(r, h)| match h {
                Some(i) => format!("rank {r} held {}", describe(scene, *i, n, &subtrees[*i])),
                None => format!("rank {r} idle"),
            })
            .collect();
        if let Ok(mut s) = IN_FLIGHT.lock() {
            *s = text.join("; ");
        }
    };
    while stopped < size - 1 {
        let (msg, status) = receive(&world.any_process());
        let r = status.source_rank();
        report.bytes_from_workers += msg.len() as u64;
        report.largest_message_bytes = report.largest_message_bytes.max(msg.len() as u64);
        let holding = held[r as usize];
        match status.tag() {
            TAG_READY | TAG_DONE => {
                if let Some(i) = holding {
                    let s = msg.get(..8).and_then(|b| b.try_into().ok()).map_or(0.0, f64::from_le_bytes);
                    (seconds[i], done[i]) = (s, true);
                    report.subtree_seconds_sum += s;
                    report.subtree_seconds_max = report.subtree_seconds_max.max(s);
                    // Write every finished subtree that is next in order, then what the next one
                    // (still being solved) has sent so far; its further chunks are written as they come.
                    while next_write < n && done[next_write] {
                        write(&std::mem::take(&mut pending[next_write]), sink, &mut report)?;
                        next_write += 1;
                    }
                    if next_write < n && !pending[next_write].is_empty() {
                        write(&std::mem::take(&mut pending[next_write]), sink, &mut report)?;
                    }
                }
                held[r as usize] = None;
                idle.push(r);
                // Hand out subtrees in order to the idle ranks, at most `window` ahead of the
                // next one to write: what finishes ahead of it waits in memory here.
                while let Some(&r) = idle.last() {
                    if next_hand < n && next_hand < next_write + window {
                        let s = &subtrees[next_hand];
                        world.process_at_rank(r).send_with_tag(&s.bytes[..], TAG_WORK);
                        report.bytes_to_workers += s.bytes.len() as u64;
                        report.largest_message_bytes = report.largest_message_bytes.max(s.bytes.len() as u64);
                        held[r as usize] = Some(next_hand);
                        ranks[next_hand] = r;
                        next_hand += 1;
                    } else if next_hand >= n {
                        world.process_at_rank(r).send_with_tag(&[0u8; 0][..], TAG_STOP);
                    } else {
                        break;
                    }
                    let _ = idle.pop();
                }
                update_in_flight(&held);
            }
            TAG_POLYGONS => {
                let Some(i) = holding else { anyhow::bail!("rank {r} sent polygons while holding no subtree") };
                result_bytes[i] += msg.len() as u64;
                if i == next_write {
                    write(&msg, sink, &mut report).with_context(|| format!("from rank {r}"))?;
                } else {
                    pending[i].extend_from_slice(&msg);
                }
            }
            TAG_STATS => {
                let (s, rss) = distributed::decode_stats(&msg).with_context(|| format!("figures of rank {r}"))?;
                distributed::merge_stats(&mut stats, &s);
                report.peak_rss_bytes_per_rank[r as usize] = rss;
                stopped += 1;
            }
            TAG_ERROR => {
                let what = holding.map_or("holding no subtree".to_string(), |i| format!("on {}", describe(scene, i, n, &subtrees[i])));
                anyhow::bail!("rank {r} failed {what}: {}", String::from_utf8_lossy(&msg));
            }
            t => anyhow::bail!("rank {r} sent a message of unknown tag {t}"),
        }
    }
    anyhow::ensure!(next_write == n, "only {next_write} of {n} subtrees were written");
    report.peak_rss_bytes_per_rank[0] = radiosity::output::peak_rss_bytes().unwrap_or(0);
    stats.seconds = t0.elapsed().as_secs_f64();
    if let Some(path) = std::env::var_os("RADIOSITY_MPI_LOG") {
        let mut csv = String::from("subtree,prototype,polygons,task_bytes,result_bytes,rank,seconds\n");
        for (i, s) in subtrees.iter().enumerate() {
            csv.push_str(&format!(
                "{i},{},{},{},{},{},{:.6}\n",
                scene.prototype(s.prototype).name,
                s.polygons,
                s.bytes.len(),
                result_bytes[i],
                ranks[i],
                seconds[i]
            ));
        }
        std::fs::write(&path, csv).with_context(|| format!("{}: cannot write", std::path::Path::new(&path).display()))?;
    }
    Ok((stats, report))
}

/// A rank other than 0: asks for subtrees, solves them on a solver thread, streams their polygons
/// to rank 0, and sends its figures at the end. Writes no output file.
pub fn work(scene: &InstancedScene, config: &InstancedConfig) -> anyhow::Result<()> {
    let world = SimpleCommunicator::world();
    let me = world.rank();
    let root = world.process_at_rank(0);
    let fail_at = std::env::var("RADIOSITY_MPI_FAIL").ok().and_then(|v| {
        let (r, n) = v.split_once(':')?;
        (r.parse::<i32>().ok()? == me).then_some(n.parse::<u64>().ok()?)
    });
    let (work_tx, work_rx) = std::sync::mpsc::channel::<Vec<u8>>();
    let (event_tx, event_rx) = std::sync::mpsc::channel::<WorkerEvent>();
    let outcome = std::thread::scope(|s| {
        let solver = s.spawn(move || distributed::solve_subtrees(scene, config, work_rx, event_tx));
        root.send_with_tag(&[0u8; 0][..], TAG_READY);
        let mut received = 0u64;
        let mut work_tx = Some(work_tx);
        let looped: Result<(), String> = 'outer: loop {
            let (msg, status) = receive(&root);
            match status.tag() {
                TAG_WORK => {
                    received += 1;
                    if fail_at == Some(received) {
                        eprintln!("rank {me}: RADIOSITY_MPI_FAIL: exiting abruptly on receiving subtree number {received}");
                        std::process::exit(3);
                    }
                    if work_tx.as_ref().is_none_or(|tx| tx.send(msg).is_err()) {
                        break Err("the solver thread stopped".into());
                    }
                    loop {
                        match event_rx.recv() {
                            Ok(WorkerEvent::Polygons(chunk)) => root.send_with_tag(&chunk[..], TAG_POLYGONS),
                            Ok(WorkerEvent::Finished(seconds)) => {
                                root.send_with_tag(&seconds.to_le_bytes()[..], TAG_DONE);
                                break;
                            }
                            Err(_) => break 'outer Err("the solver thread stopped".into()),
                        }
                    }
                }
                TAG_STOP => break Ok(()),
                t => break Err(format!("rank 0 sent a message of unknown tag {t}")),
            }
        };
        drop(work_tx.take());
        let solved = match solver.join() {
            Ok(Ok(stats)) => Ok(stats),
            Ok(Err(e)) => Err(e.to_string()),
            Err(panic) => Err(format!(
                "panicked: {}",
                panic
                    .downcast_ref::<&str>()
                    .map(ToString::to_string)
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_default()
            )),
        };
        match (looped, solved) {
            (Ok(()), Ok(stats)) => Ok(stats),
            (_, Err(e)) | (Err(e), Ok(_)) => Err(e),
        }
    });
    match outcome {
        Ok(stats) => {
            let rss = radiosity::output::peak_rss_bytes().unwrap_or(0);
            root.send_with_tag(&distributed::encode_stats(&stats, rss)[..], TAG_STATS);
            Ok(())
        }
        Err(e) => {
            // Rank 0 names the subtree and ends the job; wait for that.
            root.send_with_tag(e.as_bytes(), TAG_ERROR);
            let _ = receive(&root);
            anyhow::bail!("rank {me}: {e}")
        }
    }
}
