//! Whether one object is another moved rigidly: candidate rotations from anchor vertices, then
//! verification polygon by polygon.

use super::objects::{Object, Shape};
use super::{FILTER_TOL_FACTOR, MAX_FRAME_CANDIDATES};
use crate::geom::{DVec3, Poly};
use crate::scene::Scene;
use glam::DMat3;

pub(super) enum Match {
    /// The rotation (the translation follows from the centroids) and, for every polygon of the
    /// representative in its order, the matching input polygon.
    Found(DMat3, Vec<u32>),
    Different,
    GaveUp,
}

/// Whether `b` is `a` moved rigidly, within `rel_tol`.
pub(super) fn find_rigid_match(scene: &Scene, a: &Object, sa: &Shape, b: &Object, sb: &Shape, rel_tol: f64) -> Match {
    let r = sa.radius.max(sb.radius);
    let tol = rel_tol * r;
    let loose = FILTER_TOL_FACTOR * rel_tol;
    let close = |x: f64, y: f64, scale: f64| (x - y).abs() <= loose * scale;
    if sa.signature != sb.signature
        || !close(sa.radius, sb.radius, r)
        || !close(sa.area, sb.area, sa.area.max(sb.area))
        || !close(sa.cov_trace, sb.cov_trace, r * r)
        || !close(sa.cov_norm, sb.cov_norm, r * r)
    {
        return Match::Different;
    }
    // B's anchors: the farthest vertex, then the vertex farthest from the line through it.
    let (cb, ca) = (sb.centroid, sa.centroid);
    let Some(&p1) = sb.vertices.iter().max_by(|x, y| (**x - cb).length().total_cmp(&(**y - cb).length())) else {
        return Match::Different;
    };
    let axis = (p1 - cb).normalize_or_zero();
    let off_axis = |v: DVec3| (v - cb).reject_from_normalized(axis).length();
    let Some(&p2) = sb.vertices.iter().max_by(|x, y| off_axis(**x).total_cmp(&off_axis(**y))) else {
        return Match::Different;
    };
    if axis == DVec3::ZERO || off_axis(p2) <= tol {
        return Match::Different;
    }
    let Some(fb) = frame(cb, p1, p2) else { return Match::Different };
    let (d1, d2, d12) = ((p1 - cb).length(), (p2 - cb).length(), (p2 - p1).length());
    // Distances are compared with twice the tolerance: both objects carry vertex noise.
    let near = |x: f64, y: f64| (x - y).abs() <= 2.0 * tol;
    let b_lookup = PolygonLookup::new(scene, &b.polygons);
    let mut tried = 0usize;
    for &q1 in sa.vertices.iter().filter(|&&q| near((q - ca).length(), d1)) {
        for &q2 in sa.vertices.iter().filter(|&&q| near((q - ca).length(), d2) && near((q - q1).length(), d12)) {
            let Some(fa) = frame(ca, q1, q2) else { continue };
            if tried == MAX_FRAME_CANDIDATES {
                return Match::GaveUp;
            }
            tried += 1;
            let rot = fb * fa.transpose();
            if let Some(map) = verify(scene, a, ca, &rot, cb, &b_lookup, tol) {
                return Match::Found(rot, map);
            }
        }
    }
    Match::Different
}

/// Right-handed orthonormal frame (columns) from a centre and two non-collinear points.
fn frame(c: DVec3, p1: DVec3, p2: DVec3) -> Option<DMat3> {
    let u = (p1 - c).try_normalize()?;
    let v = (p2 - c).reject_from_normalized(u).try_normalize()?;
    Some(DMat3::from_cols(u, v, u.cross(v)))
}

/// B's polygons sorted by the x of their centroid, for window searches.
struct PolygonLookup {
    /// `(centroid, input polygon index)`, sorted by `centroid.x`.
    entries: Vec<(DVec3, u32)>,
}

impl PolygonLookup {
    fn new(scene: &Scene, polygons: &[u32]) -> PolygonLookup {
        let mut entries: Vec<(DVec3, u32)> = polygons.iter().map(|&i| (vertex_mean(&scene.polygons[i as usize].poly), i)).collect();
        entries.sort_by(|x, y| x.0.x.total_cmp(&y.0.x).then(x.1.cmp(&y.1)));
        PolygonLookup { entries }
    }
}

/// Mean of the vertices (moves with the vertices, unlike an area centroid it needs no area).
fn vertex_mean(p: &Poly) -> DVec3 {
    let v = p.vertices();
    v.iter().copied().sum::<DVec3>() / v.len() as f64
}

/// Maps every polygon of `a` by `x ↦ rot·(x − ca) + cb` and finds a distinct polygon of B with the
/// same material, vertex count and vertices (some cyclic rotation) within `tol`. Returns B's
/// polygon for each of A's, in A's order.
fn verify(scene: &Scene, a: &Object, ca: DVec3, rot: &DMat3, cb: DVec3, b: &PolygonLookup, tol: f64) -> Option<Vec<u32>> {
    let mut used = vec![false; b.entries.len()];
    let mut map = Vec::with_capacity(a.polygons.len());
    let mut mapped = [DVec3::ZERO; 4];
    for &ia in &a.polygons {
        let pa = &scene.polygons[ia as usize];
        let n = pa.poly.n_vertices();
        for (m, &v) in mapped.iter_mut().zip(pa.poly.vertices()) {
            *m = *rot * (v - ca) + cb;
        }
        let mean = mapped[..n].iter().copied().sum::<DVec3>() / n as f64;
        let start = b.entries.partition_point(|e| e.0.x < mean.x - tol);
        let mut found = None;
        for (k, &(cen, ib)) in b.entries.iter().enumerate().skip(start) {
            if cen.x > mean.x + tol {
                break;
            }
            if used[k] || (cen - mean).length() > tol {
                continue;
            }
            let pb = &scene.polygons[ib as usize];
            if pb.material != pa.material || pb.poly.n_vertices() != n {
                continue;
            }
            let vb = pb.poly.vertices();
            if (0..n).any(|shift| (0..n).all(|j| (mapped[j] - vb[(j + shift) % n]).length() <= tol)) {
                found = Some(k);
                break;
            }
        }
        let k = found?;
        used[k] = true;
        map.push(b.entries[k].1);
    }
    Some(map)
}
