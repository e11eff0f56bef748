//! Faces with holes. MGF writes them either with `fh` (contours separated by `-`), which
//! [`merge_holes`] turns into one contour with seams, or directly as one `f` contour that visits a
//! vertex twice (`f v0 v1 v2 v3 v4 v5 v6 v7 v8 v4`). Such self-touching contours are triangulated
//! here by [`triangulate`], an ear clipper that lets coincident vertices touch; ordinary polygons
//! are left to the scene builder.

use crate::scene::builder::DEGENERATE_REL_AREA;
use glam::{DVec2, DVec3};

/// Joins the holes of a face (`fh`) to its outer contour by seams to the nearest vertex, as
/// RenderPark does: each hole, taken in order of closest approach, is spliced in as
/// `.. m, h_k, h_k+1, .., h_k-1, h_k, m ..`.
#[must_use]
pub(super) fn merge_holes(outer: Vec<DVec3>, mut holes: Vec<Vec<DVec3>>) -> Vec<DVec3> {
    let mut merged = outer;
    while !holes.is_empty() {
        let mut best = (f64::INFINITY, 0, 0, 0);
        for (h, hole) in holes.iter().enumerate() {
            for (k, &p) in hole.iter().enumerate() {
                for (m, &q) in merged.iter().enumerate() {
                    let d = p.distance_squared(q);
                    if d < best.0 {
                        best = (d, h, k, m);
                    }
                }
            }
        }
        let (_, h, k, m) = best;
        let hole = holes.remove(h);
        let splice: Vec<DVec3> = (0..=hole.len()).map(|i| hole[(k + i) % hole.len()]).chain([merged[m]]).collect();
        merged.splice(m + 1..m + 1, splice);
    }
    merged
}

/// The contour without repeated consecutive points (cyclically).
#[must_use]
pub(super) fn without_consecutive_repeats(pts: &[DVec3]) -> Vec<DVec3> {
    let mut out: Vec<DVec3> = Vec::with_capacity(pts.len());
    for &p in pts {
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

/// True when some point occurs twice in `pts` (a contour touching itself).
#[must_use]
pub(super) fn touches_itself(pts: &[DVec3]) -> bool {
    (1..pts.len()).any(|i| pts[..i].contains(&pts[i]))
}

/// Triangles (index triples, CCW about the contour's normal) covering a contour that may touch
/// itself at coincident vertices. Slivers (collinear corners, spikes) are clipped without a
/// triangle. `None` when no ear can be found (the contour crosses itself).
#[must_use]
pub(super) fn triangulate(pts: &[DVec3]) -> Option<Vec<[usize; 3]>> {
    let normal: DVec3 = (0..pts.len()).map(|i| pts[i].cross(pts[(i + 1) % pts.len()])).sum();
    let n = normal.abs();
    let (i, j) = if n.x >= n.y && n.x >= n.z {
        (1, 2)
    } else if n.y >= n.z {
        (2, 0)
    } else {
        (0, 1)
    };
    // Projected so that the contour runs counter-clockwise.
    let flip = if normal[3 - i - j] < 0.0 { -1.0 } else { 1.0 };
    let p: Vec<DVec2> = pts.iter().map(|v| DVec2::new(v[i], flip * v[j])).collect();
    let (lo, hi) = p.iter().fold((p[0], p[0]), |(lo, hi), &q| (lo.min(q), hi.max(q)));
    let sliver = DEGENERATE_REL_AREA * (hi - lo).length_squared();
    let orient = |a: usize, b: usize, c: usize| (p[b] - p[a]).perp_dot(p[c] - p[a]);
    let same = |a: usize, b: usize| pts[a] == pts[b];

    let mut ring: Vec<usize> = (0..pts.len()).collect();
    let mut out = Vec::with_capacity(pts.len().saturating_sub(2));
    while ring.len() > 3 {
        let m = ring.len();
        let corner = |k: usize| (ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]);
        // Slivers first: removing them does not change the covered region.
        if let Some(k) = (0..m).find(|&k| {
            let (a, b, c) = corner(k);
            orient(a, b, c).abs() <= sliver
        }) {
            ring.remove(k);
            continue;
        }
        let is_ear = |k: usize| {
            let (a, b, c) = corner(k);
            if orient(a, b, c) <= sliver {
                return false;
            }
            let touches_corner = |q: usize| same(q, a) || same(q, b) || same(q, c);
            let inside = ring
                .iter()
                .any(|&q| !touches_corner(q) && orient(a, b, q) >= -sliver && orient(b, c, q) >= -sliver && orient(c, a, q) >= -sliver);
            let crossing = (0..m).any(|e| {
                let (s, t) = (ring[e], ring[(e + 1) % m]);
                let touches_diagonal = same(s, a) || same(s, c) || same(t, a) || same(t, c);
                !touches_diagonal && orient(c, a, s) * orient(c, a, t) < 0.0 && orient(s, t, c) * orient(s, t, a) < 0.0
            });
            !inside && !crossing
        };
        let k = (0..m).find(|&k| is_ear(k))?;
        let (a, b, c) = corner(k);
        out.push([a, b, c]);
        ring.remove(k);
    }
    if let [a, b, c] = ring[..]
        && orient(a, b, c) > sliver
    {
        out.push([a, b, c]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(pts: &[DVec3], tris: &[[usize; 3]]) -> f64 {
        tris.iter().map(|t| 0.5 * (pts[t[1]] - pts[t[0]]).cross(pts[t[2]] - pts[t[0]]).z).sum()
    }

    fn square(s: f64, ccw: bool) -> Vec<DVec3> {
        let mut v = vec![DVec3::new(-s, -s, 0.0), DVec3::new(s, -s, 0.0), DVec3::new(s, s, 0.0), DVec3::new(-s, s, 0.0)];
        if !ccw {
            v.reverse();
        }
        v
    }

    #[test]
    fn hole_by_seam_is_triangulated_with_the_right_area() {
        let merged = merge_holes(square(2.0, true), vec![square(1.0, false)]);
        assert_eq!(merged.len(), 10);
        assert!(touches_itself(&merged));
        let tris = triangulate(&merged).unwrap();
        assert_eq!(tris.len(), 8);
        assert!((area(&merged, &tris) - 12.0).abs() < 1e-12);
        assert!(tris.iter().all(|t| area(&merged, &[*t]) > 0.0), "all CCW");
    }

    #[test]
    fn contour_touching_itself_at_one_vertex() {
        // The pentagon (0,0) (1,1) (4,0) (4,4) (0,4) (area 14) with a square hole hanging from (1,1).
        let v = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let pts = vec![v(0.0, 0.0), v(1.0, 1.0), v(1.0, 2.0), v(2.0, 2.0), v(2.0, 1.0), v(1.0, 1.0), v(4.0, 0.0), v(4.0, 4.0), v(0.0, 4.0)];
        let tris = triangulate(&pts).unwrap();
        assert!((area(&pts, &tris) - 13.0).abs() < 1e-12, "{}", area(&pts, &tris));
        // Clockwise input gives clockwise triangles (same orientation as the contour).
        let rev: Vec<DVec3> = pts.iter().rev().copied().collect();
        let tris = triangulate(&rev).unwrap();
        assert!((area(&rev, &tris) + 13.0).abs() < 1e-12);
    }

    #[test]
    fn collinear_corners_make_no_slivers() {
        let v = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let pts = vec![v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.0), v(2.0, 2.0), v(0.0, 2.0)];
        let tris = triangulate(&pts).unwrap();
        assert!((area(&pts, &tris) - 4.0).abs() < 1e-12);
        assert!(tris.iter().all(|t| area(&pts, &[*t]) > 1e-9));
        assert_eq!(without_consecutive_repeats(&[v(0.0, 0.0), v(0.0, 0.0), v(1.0, 0.0), v(0.0, 0.0)]), vec![v(0.0, 0.0), v(1.0, 0.0)]);
    }
}
