//! Development probe: accuracy of receiver quadrature against the contour integral.
use radiosity::formfactor::{point_polygon, polygon_polygon};
use radiosity::geom::quadrature::{QUAD_4, QUAD_9, Rule};
use radiosity::geom::{DVec3, Poly};
fn avg(rp: &Poly, rn: DVec3, sv: &[DVec3], sn: DVec3, rule: &Rule) -> f64 {
    let mut f = 0.0;
    for (&(u, v), &w) in rule.points.iter().zip(rule.weights) {
        f += w * point_polygon(rp.point(u, v), rn, sv, sn);
    }
    f
}
fn main() {
    for &(name, tilt) in &[("parallel", false), ("perpendicular", true)] {
        for &d in &[0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0] {
            // Receiver: unit square at z=0 facing +z; source: unit square at height d facing -z (parallel),
            // or a vertical unit square at x = 1 + d/2 .. facing -x (perpendicular-ish, offset).
            let r = Poly::quad(DVec3::new(0., 0., 0.), DVec3::new(1., 0., 0.), DVec3::new(1., 1., 0.), DVec3::new(0., 1., 0.));
            let (sv, sn): (Vec<DVec3>, DVec3) = if !tilt {
                (vec![DVec3::new(0., 0., d), DVec3::new(0., 1., d), DVec3::new(1., 1., d), DVec3::new(1., 0., d)], -DVec3::Z)
            } else {
                let x = 0.5 + d;
                (vec![DVec3::new(x, 0., 0.0), DVec3::new(x, 0., 1.0), DVec3::new(x, 1., 1.0), DVec3::new(x, 1., 0.0)], -DVec3::X)
            };
            let exact = polygon_polygon(r.vertices(), &sv);
            let q4 = avg(&r, DVec3::Z, &sv, sn, &QUAD_4);
            let q9 = avg(&r, DVec3::Z, &sv, sn, &QUAD_9);
            let sep = d / (2.0 * 0.5f64.sqrt());
            println!("{name:13} d {d:5} sep {sep:5.2} F {exact:.6e} q4 {:+.2e} q9 {:+.2e}", q4 / exact - 1.0, q9 / exact - 1.0);
        }
    }
}
