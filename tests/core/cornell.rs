//! The Cornell box: the embedded scene solves without NaN and with B ≥ E on every leaf; a mirror-
//! symmetric variant (red left, green right, gray elsewhere, white light in the middle of the ceiling)
//! has the symmetry B_red(x) = B_green(mirror(x)), which the solution must show.

use radiosity::geom::DVec3;
use radiosity::output::polygon_results;
use radiosity::scene::cornell_box;

use crate::support::{Build, rel_diff, solve};

/// Symmetry of per-polygon means: visibility is sampled with jitter, so mirror images differ by
/// sampling noise; the empty box has no occluder, so the noise is small.
const SYMMETRY_REL_TOL: f64 = 1e-2;

#[test]
fn embedded_cornell_box_has_no_nan_and_b_at_least_e() {
    let scene = cornell_box();
    let solved = solve(&scene, 0.01, 2e-6);
    let h = &solved.hierarchy;
    let mut n = 0;
    for leaf in h.leaves() {
        let p = h.get(leaf).polygon().expect("leaves are surfaces") as usize;
        let e = h.emission[p];
        let b = solved.solution.radiosity[leaf as usize];
        for c in 0..3 {
            assert!(b[c].is_finite() && solved.solution.irradiance[leaf as usize][c].is_finite(), "leaf {leaf}: B = {b:?}");
            assert!(b[c] >= e[c], "leaf {leaf} of polygon {p}: B = {b:?} below its emission {e:?}");
        }
        n += 1;
    }
    assert!(n > 100, "only {n} leaves: the oracle did not refine");
    // Something is lit besides the lamp.
    let lit = h
        .leaves()
        .filter(|&l| h.emission[h.get(l).polygon().unwrap() as usize][0] == 0.0 && solved.solution.radiosity[l as usize][0] > 0.0)
        .count();
    assert!(lit > n / 2, "{lit} of {n} leaves lit");
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

#[test]
fn symmetric_cornell_box_is_symmetric_with_colours_swapped() {
    let mut b = Build::new("symmetric-cornell");
    let white = b.material("white", [0.7; 3], [0.0; 3]);
    let red = b.material("red", [0.6, 0.1, 0.1], [0.0; 3]);
    let green = b.material("green", [0.1, 0.6, 0.1], [0.0; 3]);
    let lamp = b.material("lamp", [0.0; 3], [20.0; 3]);
    // Room [0,1]³ without a front wall (y = 0 open), z up; quads CCW about the inward normal.
    b.quad("floor", [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)], white);
    b.quad("back", [v(0., 1., 0.), v(1., 1., 0.), v(1., 1., 1.), v(0., 1., 1.)], white);
    b.quad("left", [v(0., 0., 0.), v(0., 1., 0.), v(0., 1., 1.), v(0., 0., 1.)], red);
    b.quad("right", [v(1., 0., 0.), v(1., 0., 1.), v(1., 1., 1.), v(1., 1., 0.)], green);
    // Ceiling as a frame around the lamp, all facing down.
    let (a, c) = (0.4, 0.6);
    let ceiling = |x0: f64, x1: f64, y0: f64, y1: f64| [v(x0, y0, 1.), v(x0, y1, 1.), v(x1, y1, 1.), v(x1, y0, 1.)];
    b.quad("lamp", ceiling(a, c, a, c), lamp);
    b.quad("ceiling", ceiling(0., 1., 0., a), white);
    b.quad("ceiling", ceiling(0., 1., c, 1.), white);
    b.quad("ceiling", ceiling(0., a, a, c), white);
    b.quad("ceiling", ceiling(c, 1., a, c), white);
    let scene = b.finish();
    let solved = solve(&scene, 0.001, 1e-4);
    let r = polygon_results(&solved.hierarchy, &solved.solution);
    let (floor, back, left, right, ceil_w, ceil_e) = (0, 1, 2, 3, 7, 8);
    let check = |what: &str, x: f64, y: f64| {
        let d = rel_diff(x, y);
        assert!(d < SYMMETRY_REL_TOL, "{what}: {x} vs {y} (relative difference {d:.2e})");
    };
    // Walls: red channel of the left wall ↔ green channel of the right wall, and so on.
    check("left R vs right G", r[left].b[0], r[right].b[1]);
    check("left G vs right R", r[left].b[1], r[right].b[0]);
    check("left B vs right B", r[left].b[2], r[right].b[2]);
    // Self-symmetric polygons: their red and green must agree.
    for (name, p) in [("floor", floor), ("back", back)] {
        check(&format!("{name} R vs G"), r[p].b[0], r[p].b[1]);
    }
    // Mirror pair of ceiling strips (x < 0.4 and x > 0.6).
    check("ceiling west R vs east G", r[ceil_w].b[0], r[ceil_e].b[1]);
    // The colour bleeding is there to be symmetric about: the floor is not gray-lit from one side.
    assert!(r[left].b[0] > 2.0 * r[left].b[1], "red wall is red: {:?}", r[left].b);
}
