//! Form factors against the closed forms of `reference/formfactors.md` (project references (a), (b)
//! and the perpendicular-squares case): Howell's catalogue values, recomputed independently there.

use radiosity::formfactor::{FormFactorQuality, link_form_factor, point_polygon};
use radiosity::geom::DVec3;
use radiosity::hierarchy::{self, BuildConfig};

use crate::support::Build;

/// Tolerance the issue sets on surface-to-surface form factors.
const FF_REL_TOL: f64 = 5e-3;
/// Tolerance on the analytic point-to-polygon formula.
const POINT_ABS_TOL: f64 = 1e-9;

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// Form factor F(receiver → source) between two quads, through the hierarchy's link machinery.
fn quad_pair(receiver: [DVec3; 4], source: [DVec3; 4]) -> f64 {
    let mut b = Build::new("ff-pair");
    let white = b.material("white", [0.5; 3], [0.0; 3]);
    let lamp = b.material("lamp", [0.5; 3], [1.0; 3]);
    b.quad("receiver", receiver, white);
    b.quad("source", source, lamp);
    let scene = b.finish();
    let h = hierarchy::build(&scene, &BuildConfig::default());
    // Elements 0 and 1 are the roots of polygons 0 and 1.
    link_form_factor(&h, 1, 0, FormFactorQuality::Precise)
}

#[test]
fn parallel_opposed_unit_squares_at_distance_one() {
    // Receiver at z = 0 facing +z, source at z = 1 facing −z.
    let receiver = [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)];
    let source = [v(0., 0., 1.), v(0., 1., 1.), v(1., 1., 1.), v(1., 0., 1.)];
    let f = quad_pair(receiver, source);
    let exact = 0.199_824_895_698_387;
    assert!((f / exact - 1.0).abs() < FF_REL_TOL, "F = {f}, exact {exact}");
}

#[test]
fn perpendicular_unit_squares_sharing_an_edge() {
    // Receiver in z = 0 facing +z; source in x = 0 facing +x; common edge along y at x = z = 0.
    let receiver = [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)];
    let source = [v(0., 0., 0.), v(0., 1., 0.), v(0., 1., 1.), v(0., 0., 1.)];
    let f = quad_pair(receiver, source);
    let exact = 0.200_043_776_075_403;
    assert!((f / exact - 1.0).abs() < FF_REL_TOL, "F = {f}, exact {exact}");
}

#[test]
fn point_to_rectangle_on_the_corner_normal() {
    // Handbook case: dA on the normal through a corner of an a×b rectangle at distance c.
    let closed = |a: f64, b: f64, c: f64| {
        let (x, y) = (a / c, b / c);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
    };
    for (a, b, c, tabulated) in
        [(1.0, 1.0, 1.0, 0.138_531_605_994_893), (2.0, 1.0, 1.0, 0.167_375_009_914_384), (1.0, 1.0, 0.25, 0.237_856_030_646_370)]
    {
        let rect = [v(0., 0., c), v(0., b, c), v(a, b, c), v(a, 0., c)]; // faces −z, toward the point
        let f = point_polygon(DVec3::ZERO, DVec3::Z, &rect, -DVec3::Z);
        assert!((f - closed(a, b, c)).abs() < POINT_ABS_TOL, "{a}×{b} at {c}: {f} vs closed form {}", closed(a, b, c));
        assert!((f - tabulated).abs() < POINT_ABS_TOL, "{a}×{b} at {c}: {f} vs tabulated {tabulated}");
    }
}

#[test]
fn point_to_polygon_clips_the_part_behind_the_point() {
    // A vertical square in the plane y = 1 (facing −y) spanning z ∈ [−1, 1], seen from the origin
    // with normal +z: only its upper half (z ≥ 0) is in front. The upper half alone lies entirely in
    // front, so the unclipped formula is exact for it; the clipped full square must equal it.
    let square = [v(0., 1., -1.), v(1., 1., -1.), v(1., 1., 1.), v(0., 1., 1.)];
    let upper = [v(0., 1., 0.), v(1., 1., 0.), v(1., 1., 1.), v(0., 1., 1.)];
    let f_full = point_polygon(DVec3::ZERO, DVec3::Z, &square, -DVec3::Y);
    let f_upper = point_polygon(DVec3::ZERO, DVec3::Z, &upper, -DVec3::Y);
    assert!(f_upper > 0.01, "upper half {f_upper}");
    assert!((f_full - f_upper).abs() < POINT_ABS_TOL, "clipped {f_full} vs upper half {f_upper}");
    // Entirely behind: nothing.
    let below = [v(0., 1., -1.), v(1., 1., -1.), v(1., 1., -0.5), v(0., 1., -0.5)];
    assert_eq!(point_polygon(DVec3::ZERO, DVec3::Z, &below, -DVec3::Y), 0.0);
}
