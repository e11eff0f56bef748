//! The distributed machinery's tests: encodings round trip bit for bit, and subtrees solved on
//! threads in any order give the bits of one process.

use super::*;
use crate::geom::{DVec3, PolyKind};
use crate::instancing::solver::config::{InstancedConfig, InstancedStats};
use crate::instancing::solver::sink::{Leaf, PolygonInfo};

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
