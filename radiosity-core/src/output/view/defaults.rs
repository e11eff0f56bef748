//! The scene's up axis, and the candidate default views of a scene without a camera: from
//! outside above each horizontal diagonal, and from inside toward each upper corner.

use super::View;
use super::pinhole::horizontal_for;
use crate::geom::{Aabb, DVec3};
use crate::scene::Scene;

/// Vertical field of view of the default views seen from outside the scene, degrees.
pub const OUTSIDE_FOV_DEG: f64 = 45.0;
/// Vertical field of view of the default views from inside the scene, degrees.
pub const INSIDE_FOV_DEG: f64 = 70.0;
/// Elevation of the default views from outside, above the scene's horizontal plane, degrees.
pub const OUTSIDE_ELEVATION_DEG: f64 = 30.0;
/// How far toward an upper corner of the bounding box the inside views stand, as a fraction of
/// the way from the centre to the corner.
pub const INSIDE_CORNER_FRACTION: f64 = 0.4;
/// Margin around the scene in the outside views: the distance that frames the bounding box is
/// multiplied by this.
pub const OUTSIDE_MARGIN: f64 = 1.05;
/// The net emitting normal fixes the scene's up axis when it is at least this fraction of the
/// emitters' total area (otherwise the lights face every way, as in a furnace).
const NET_EMITTER_FRACTION: f64 = 0.5;
/// Extents within this relative difference count as equal when the thinnest axis is taken as up.
const EXTENT_TIE: f64 = 0.01;

/// The scene's up direction: opposite to the emitters' net normal when the lights mostly face one
/// way (ceiling lights face down), otherwise the axis along which the bounding box is thinnest
/// (`+z` on ties, then `+y`): rooms are lower than they are wide.
#[must_use]
pub fn up_axis(scene: &Scene) -> DVec3 {
    let (mut net, mut total) = (DVec3::ZERO, 0.0);
    for p in &scene.polygons {
        if scene.materials[p.material as usize].is_emitter() {
            net += p.poly.area_vector();
            total += p.poly.area();
        }
    }
    if total > 0.0 && net.length() >= NET_EMITTER_FRACTION * total {
        let d = -net;
        let a = d.abs();
        return if a.z >= a.x && a.z >= a.y {
            DVec3::Z * d.z.signum()
        } else if a.y >= a.x {
            DVec3::Y * d.y.signum()
        } else {
            DVec3::X * d.x.signum()
        };
    }
    let e = scene.bounds().extent();
    let thin = e.x.min(e.y).min(e.z);
    let tie = |x: f64| x <= thin * (1.0 + EXTENT_TIE);
    if tie(e.z) {
        DVec3::Z
    } else if tie(e.y) {
        DVec3::Y
    } else {
        DVec3::X
    }
}

/// A candidate default view, and whether it looks from outside the scene's bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// The view.
    pub view: View,
    /// True for the views from outside (a cut-away of a closed room: the backs of one-sided
    /// surfaces let the view through).
    pub outside: bool,
}

/// The default views of a scene without a camera, on an image of width / height `aspect`: from
/// outside, above each of the four horizontal diagonals, looking at the centre of the bounding box
/// and framing it; then from inside, 40% of the way from the centre to each upper corner of the
/// bounding box, looking at the centre. `up` is [`up_axis`].
#[must_use]
pub fn candidate_views(bounds: &Aabb, up: DVec3, aspect: f64) -> Vec<Candidate> {
    let c = bounds.center();
    let half = 0.5 * bounds.extent();
    // Two horizontal axes orthogonal to `up` (an axis or its opposite).
    let (a1, a2) = if up.z.abs() > 0.5 {
        (DVec3::X, DVec3::Y)
    } else if up.y.abs() > 0.5 {
        (DVec3::Z, DVec3::X)
    } else {
        (DVec3::Y, DVec3::Z)
    };
    let corners: Vec<DVec3> = (0..8)
        .map(|k| {
            c + DVec3::new(
                if k & 1 == 0 { -half.x } else { half.x },
                if k & 2 == 0 { -half.y } else { half.y },
                if k & 4 == 0 { -half.z } else { half.z },
            )
        })
        .collect();
    let mut out = Vec::with_capacity(8);
    let (elev, fov) = (OUTSIDE_ELEVATION_DEG.to_radians(), OUTSIDE_FOV_DEG.to_radians());
    for (s1, s2) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
        let horizontal_dir = (a1 * s1 + a2 * s2).normalize();
        let back = horizontal_dir * elev.cos() + up * elev.sin();
        let probe = View::new(c, -back, up, horizontal_for(fov, aspect), fov);
        let dist = framing_distance(&probe, c, &corners) * OUTSIDE_MARGIN;
        out.push(Candidate { view: View { position: c + back * dist, ..probe }, outside: true });
    }
    let fov = INSIDE_FOV_DEG.to_radians();
    for (s1, s2) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
        let toward = a1 * (s1 * half.dot(a1.abs())) + a2 * (s2 * half.dot(a2.abs())) + up * half.dot(up.abs());
        let eye = c + toward * INSIDE_CORNER_FRACTION;
        out.push(Candidate { view: View::new(eye, c - eye, up, horizontal_for(fov, aspect), fov), outside: false });
    }
    out
}

/// The distance back from `target` along the view direction at which every point of `points` is
/// inside the view's angles.
fn framing_distance(view: &View, target: DVec3, points: &[DVec3]) -> f64 {
    let right = view.direction.cross(view.up);
    let (th, tv) = ((0.5 * view.horizontal).tan(), (0.5 * view.vertical).tan());
    points
        .iter()
        .map(|&p| {
            let o = p - target;
            let (x, y, z) = (o.dot(right), o.dot(view.up), o.dot(view.direction));
            // The eye at `target − d·direction` sees `o` at depth `z + d`; it is inside when
            // |x| ≤ (z + d)·th and |y| ≤ (z + d)·tv.
            (x.abs() / th).max(y.abs() / tv) - z
        })
        .fold(f64::MIN_POSITIVE, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outside_views_frame_the_box() {
        let b = Aabb { min: DVec3::ZERO, max: DVec3::new(10.0, 6.0, 3.0) };
        for cand in candidate_views(&b, DVec3::Z, 1.0) {
            let v = cand.view;
            let right = v.direction.cross(v.up);
            for k in 0..8 {
                let p =
                    DVec3::new(if k & 1 == 0 { 0.0 } else { 10.0 }, if k & 2 == 0 { 0.0 } else { 6.0 }, if k & 4 == 0 { 0.0 } else { 3.0 });
                let o = p - v.position;
                let z = o.dot(v.direction);
                if cand.outside {
                    assert!(z > 0.0, "every corner in front of an outside view");
                    assert!(o.dot(right).abs() <= z * (0.5 * v.horizontal).tan() * (1.0 + 1e-9));
                    assert!(o.dot(v.up).abs() <= z * (0.5 * v.vertical).tan() * (1.0 + 1e-9));
                }
            }
            let inside = v.position.cmpge(b.min).all() && v.position.cmple(b.max).all();
            assert_eq!(inside, !cand.outside);
        }
    }
}
