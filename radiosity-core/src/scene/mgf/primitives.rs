//! Tessellation of MGF's curved primitives and prisms into faces, the way mgflib's `parser.c`
//! (used by RenderPark) expands them, with `nq` divisions per quarter circle:
//!
//! | entity | faces |
//! |---|---|
//! | `cone v1 r1 v2 r2` | 4·nq quads, or 4·nq triangles when a radius is 0 |
//! | `cyl v1 r v2` | a cone with equal radii: 4·nq quads (no end caps) |
//! | `sph v r` | 2·nq cones stacked along z: 2 × 4·nq triangles (caps) + (2·nq − 2) × 4·nq quads |
//! | `ring v r1 r2` | 4·nq triangles (r1 = 0) or quads, about the vertex normal |
//! | `torus v r1 r2` | 4·nq cones about the vertex normal: 16·nq² quads |
//! | `prism v1 .. vn len` | n side quads + two n-gons |
//!
//! Negative radii make inward-facing surfaces. Faces are CCW about their front normal. Every
//! coordinate here is in the entity's own (untransformed) frame.

use glam::DVec3;
use std::f64::consts::FRAC_PI_2;

/// Radii and lengths whose magnitude is at most this are zero (mgflib's `FTINY` / `round0`).
pub(super) const ZERO_LENGTH_TOL: f64 = 1e-6;
/// mgflib's `make_axes` picks the first coordinate axis whose component of w is below this.
const AXIS_PICK_LIMIT: f64 = 0.6;

/// Faces as vertex lists.
pub(super) type Faces = Vec<Vec<DVec3>>;

fn round0(x: f64) -> f64 {
    if x.abs() <= ZERO_LENGTH_TOL { 0.0 } else { x }
}

/// Unit vectors u, v with u × v = w (w unit), as mgflib's `make_axes`.
fn make_axes(w: DVec3) -> (DVec3, DVec3) {
    let axis = (0..3).find(|&i| w[i].abs() < AXIS_PICK_LIMIT).unwrap_or(2);
    let mut v = DVec3::ZERO;
    v[axis] = 1.0;
    let u = v.cross(w).normalize();
    (u, w.cross(u))
}

/// Points on a circle about the axis (u, v): `center + r (u cos θᵢ + v sin θᵢ)` for θᵢ = sgn·i·π/(2 nq).
struct Circle {
    u: DVec3,
    v: DVec3,
    /// (cos θᵢ, sin θᵢ), i = 0 ..= 4 nq.
    angles: Vec<(f64, f64)>,
}

impl Circle {
    fn new(u: DVec3, v: DVec3, sgn: f64, nq: u32) -> Circle {
        let step = FRAC_PI_2 / f64::from(nq);
        let angles = (0..=4 * nq).map(|i| (sgn * f64::from(i) * step).sin_cos()).map(|(s, c)| (c, s)).collect();
        Circle { u, v, angles }
    }

    fn n_segments(&self) -> usize {
        self.angles.len() - 1
    }

    fn point(&self, center: DVec3, r: f64, i: usize) -> DVec3 {
        let (c, s) = self.angles[i];
        center + r * (self.u * c + self.v * s)
    }
}

/// `cone p1 r1 p2 r2`: the truncated cone between circles of radius r1 about p1 and r2 about p2.
pub(super) fn cone(acc: &mut Faces, p1: DVec3, r1: f64, p2: DVec3, r2: f64, nq: u32) -> Result<(), String> {
    let (mut p1, mut r1, mut p2, mut r2) = (p1, round0(r1), p2, round0(r2));
    if r1 == 0.0 && r2 == 0.0 {
        return Err("cone with both radii zero".into());
    }
    if r1 != 0.0 && r2 != 0.0 && (r1 < 0.0) != (r2 < 0.0) {
        return Err("cone radii of opposite signs".into());
    }
    if r2 == 0.0 {
        // The apex goes first.
        std::mem::swap(&mut p1, &mut p2);
        std::mem::swap(&mut r1, &mut r2);
    }
    let sgn = if r2 < 0.0 { -1.0 } else { 1.0 };
    let w = (p1 - p2).try_normalize().ok_or("cone with coincident end points")?;
    let (u, v) = make_axes(w);
    let circle = Circle::new(u, v, sgn, nq);
    for i in 1..=circle.n_segments() {
        if r1 == 0.0 {
            acc.push(vec![p1, circle.point(p2, r2, i - 1), circle.point(p2, r2, i)]);
        } else {
            acc.push(vec![circle.point(p1, r1, i - 1), circle.point(p2, r2, i - 1), circle.point(p2, r2, i), circle.point(p1, r1, i)]);
        }
    }
    Ok(())
}

/// `sph c r`: 2·nq cones between parallels from the +z pole to the −z pole.
pub(super) fn sphere(acc: &mut Faces, c: DVec3, r: f64, nq: u32) -> Result<(), String> {
    if round0(r) == 0.0 {
        return Err("sphere radius is zero".into());
    }
    let n = 2 * nq;
    let mut prev = (c + DVec3::Z * r, 0.0);
    for i in 1..=n {
        let (s, co) = (f64::from(i) * FRAC_PI_2 / f64::from(nq)).sin_cos();
        // The last parallel is the pole itself (mgflib gets r·sin π ≈ 1e-16 and rounds it to 0).
        let next = if i == n { (c - DVec3::Z * r, 0.0) } else { (c + DVec3::Z * (r * co), r * s) };
        cone(acc, prev.0, prev.1, next.0, next.1, nq)?;
        prev = next;
    }
    Ok(())
}

/// `torus c r_min r_max` about the unit normal `n`: 2·nq cones for the outer half of the tube
/// and 2·nq (with negated radii) for the inner half.
pub(super) fn torus(acc: &mut Faces, c: DVec3, n: DVec3, r_min: f64, r_max: f64, nq: u32) -> Result<(), String> {
    let r_min = round0(r_min);
    let sgn = [r_min, r_max].into_iter().find(|&r| r != 0.0).map(f64::signum).ok_or("torus with both radii zero")?;
    if sgn * (r_max - r_min) <= 0.0 {
        return Err("torus outer radius must exceed the inner one".into());
    }
    let half_tube = 0.5 * (r_max - r_min);
    let mean = 0.5 * (r_min + r_max);
    let step = FRAC_PI_2 / f64::from(nq);
    let mut prev = (c + n * (sgn * half_tube), mean);
    for i in 1..=4 * nq {
        let (s, co) = (f64::from(i) * step).sin_cos();
        if i == 2 * nq + 1 {
            prev.1 = -mean;
        }
        let radius = if i <= 2 * nq { mean + half_tube * s } else { -mean - half_tube * s };
        let next = (c + n * (sgn * half_tube * co), radius);
        cone(acc, prev.0, prev.1, next.0, next.1, nq)?;
        prev = next;
    }
    Ok(())
}

/// `ring c r_min r_max`: a disc (r_min = 0) or annulus facing the unit normal `n`.
pub(super) fn ring(acc: &mut Faces, c: DVec3, n: DVec3, r_min: f64, r_max: f64, nq: u32) -> Result<(), String> {
    let r_min = round0(r_min);
    if r_min < 0.0 || r_max <= r_min {
        return Err("ring radii must satisfy 0 <= inner < outer".into());
    }
    let (u, v) = make_axes(n);
    let circle = Circle::new(u, v, 1.0, nq);
    for i in 1..=circle.n_segments() {
        let (outer0, outer1) = (circle.point(c, r_max, i - 1), circle.point(c, r_max, i));
        if r_min == 0.0 {
            acc.push(vec![c, outer0, outer1]);
        } else {
            acc.push(vec![circle.point(c, r_min, i - 1), outer0, outer1, circle.point(c, r_min, i)]);
        }
    }
    Ok(())
}

/// `prism v1 .. vn length`: the polygon v1..vn (facing its CCW normal) extruded by `length` against
/// that normal; side quads, the moved copy reversed, and the polygon itself.
pub(super) fn prism(acc: &mut Faces, pts: &[DVec3], length: f64) -> Result<(), String> {
    if pts.len() < 3 {
        return Err("prism needs at least 3 vertices".into());
    }
    if length.abs() <= ZERO_LENGTH_TOL {
        return Err("prism length is zero".into());
    }
    let mut normal = DVec3::ZERO;
    let mut prev = DVec3::ZERO;
    for &p in &pts[1..] {
        let d = p - pts[0];
        normal += prev.cross(d);
        prev = d;
    }
    let normal = normal.try_normalize().ok_or("prism base polygon has no area")?;
    let moved: Vec<DVec3> = pts.iter().map(|&p| p - length * normal).collect();
    let n = pts.len();
    for i in 0..n {
        let j = (i + n - 1) % n;
        acc.push(vec![moved[i], pts[i], pts[j], moved[j]]);
    }
    acc.push(moved.iter().rev().copied().collect());
    acc.push(pts.to_vec());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_vector(f: &[DVec3]) -> DVec3 {
        (0..f.len()).map(|i| f[i].cross(f[(i + 1) % f.len()])).sum::<DVec3>() * 0.5
    }

    fn centroid(f: &[DVec3]) -> DVec3 {
        f.iter().sum::<DVec3>() / f.len() as f64
    }

    /// Every face points away from (`outward`) or toward the centre `c`.
    fn all_face(faces: &Faces, c: DVec3, outward: bool) -> bool {
        faces.iter().all(|f| (area_vector(f).dot(centroid(f) - c) > 0.0) == outward)
    }

    fn counts(faces: &Faces) -> (usize, usize) {
        (faces.iter().filter(|f| f.len() == 3).count(), faces.iter().filter(|f| f.len() == 4).count())
    }

    #[test]
    fn sphere_has_two_triangle_caps_and_faces_outward() {
        let mut faces = Faces::new();
        sphere(&mut faces, DVec3::new(1.0, 2.0, 3.0), 2.0, 4).unwrap();
        assert_eq!(counts(&faces), (32, 96));
        assert!(all_face(&faces, DVec3::new(1.0, 2.0, 3.0), true));
        let area: f64 = faces.iter().map(|f| area_vector(f).length()).sum();
        let exact = 4.0 * std::f64::consts::PI * 4.0;
        assert!(area < exact && area > 0.95 * exact, "{area} vs {exact}");
        let mut inward = Faces::new();
        sphere(&mut inward, DVec3::ZERO, -1.0, 4).unwrap();
        assert_eq!(counts(&inward), (32, 96));
        assert!(all_face(&inward, DVec3::ZERO, false));
    }

    #[test]
    fn cylinder_cone_ring_torus_prism_counts() {
        let mut f = Faces::new();
        cone(&mut f, DVec3::ZERO, 1.0, DVec3::Z, 1.0, 4).unwrap();
        assert_eq!(counts(&f), (0, 16));
        assert!(all_face(&f, DVec3::Z * 0.5, true));
        let mut f = Faces::new();
        cone(&mut f, DVec3::ZERO, 1.0, DVec3::Z, 0.0, 4).unwrap();
        assert_eq!(counts(&f), (16, 0));
        assert!(all_face(&f, DVec3::Z * 0.3, true));
        let mut f = Faces::new();
        ring(&mut f, DVec3::ZERO, DVec3::Z, 0.0, 1.0, 4).unwrap();
        assert_eq!(counts(&f), (16, 0));
        assert!(f.iter().all(|f| area_vector(f).z > 0.0));
        let mut f = Faces::new();
        ring(&mut f, DVec3::ZERO, -DVec3::Y, 0.5, 1.0, 4).unwrap();
        assert_eq!(counts(&f), (0, 16));
        assert!(f.iter().all(|f| area_vector(f).y < 0.0));
        let mut f = Faces::new();
        torus(&mut f, DVec3::ZERO, DVec3::Z, 1.0, 2.0, 4).unwrap();
        assert_eq!(counts(&f), (0, 256));
        let mut f = Faces::new();
        let pentagon: Vec<DVec3> = (0..5).map(|i| DVec3::new((i as f64 * 1.2566).cos(), (i as f64 * 1.2566).sin(), 0.0)).collect();
        prism(&mut f, &pentagon, 1.0).unwrap();
        assert_eq!(f.len(), 7);
        assert!(all_face(&f, DVec3::new(0.0, 0.0, -0.5), true));
    }

    #[test]
    fn illegal_shapes_are_errors() {
        let mut f = Faces::new();
        assert!(cone(&mut f, DVec3::ZERO, 0.0, DVec3::Z, 0.0, 4).is_err());
        assert!(cone(&mut f, DVec3::ZERO, 1.0, DVec3::Z, -1.0, 4).is_err());
        assert!(cone(&mut f, DVec3::ZERO, 1.0, DVec3::ZERO, 1.0, 4).is_err());
        assert!(ring(&mut f, DVec3::ZERO, DVec3::Z, 1.0, 0.5, 4).is_err());
        assert!(sphere(&mut f, DVec3::ZERO, 0.0, 4).is_err());
        assert!(prism(&mut f, &[DVec3::ZERO, DVec3::X, DVec3::X * 2.0], 1.0).is_err());
        assert!(f.is_empty());
    }
}
