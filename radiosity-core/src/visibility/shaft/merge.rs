//! Merged occluders: coplanar convex polygons of one object that share edges exactly are merged
//! into one convex polygon, their exact union, so that a floor split into triangles or a wall
//! built from several quads blocks a shaft as a whole.
//!
//! Only exact unions are built: two polygons merge when they lie in one plane (to a relative
//! [`COPLANAR_REL_TOL`]), share an edge with bit-identical end vertices (traversed in opposite
//! directions), and their union is convex. The union then has no gap, so a segment crossing the
//! merged polygon crosses one of its input polygons (edges count as hits).

use crate::geom::{DVec3, Poly};

/// Relative tolerance of coplanarity and collinearity for merging, times the object's size.
pub const COPLANAR_REL_TOL: f64 = 1e-12;

/// A convex polygon that is the exact union of several coplanar input polygons.
#[derive(Clone, Debug, PartialEq)]
pub struct MergedPlate {
    /// Vertex loop, counter-clockwise about the common front normal.
    pub vertices: Vec<DVec3>,
    /// The input polygons it is made of (at least two).
    pub polygons: Vec<u32>,
}

/// The merged plates of an object's polygons `members`; `size` is the object's diagonal.
#[must_use]
pub fn merge_coplanar(polys: &[Poly], members: &[u32], size: f64) -> Vec<MergedPlate> {
    let tol = COPLANAR_REL_TOL * size.max(f64::MIN_POSITIVE);
    let mut plates: Vec<MergedPlate> =
        members.iter().map(|&m| MergedPlate { vertices: polys[m as usize].vertices().to_vec(), polygons: vec![m] }).collect();
    loop {
        let mut merged = None;
        'search: for i in 0..plates.len() {
            for j in i + 1..plates.len() {
                if let Some(u) = union(&plates[i], &plates[j], tol) {
                    merged = Some((i, j, u));
                    break 'search;
                }
            }
        }
        let Some((i, j, u)) = merged else { break };
        plates[i] = u;
        plates.remove(j);
    }
    plates.retain(|p| p.polygons.len() >= 2);
    plates
}

fn normal_of(vs: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for i in 0..vs.len() {
        n += vs[i].cross(vs[(i + 1) % vs.len()]);
    }
    n.normalize_or_zero()
}

/// The union of two plates when it is an exact convex polygon.
fn union(a: &MergedPlate, b: &MergedPlate, tol: f64) -> Option<MergedPlate> {
    let (va, vb) = (&a.vertices, &b.vertices);
    let (na, nb) = (normal_of(va), normal_of(vb));
    if na == DVec3::ZERO || na.dot(nb) < 1.0 - COPLANAR_REL_TOL || vb.iter().any(|&v| na.dot(v - va[0]).abs() > tol) {
        return None;
    }
    let (la, lb) = (va.len(), vb.len());
    for i in 0..la {
        let (p0, p1) = (va[i], va[(i + 1) % la]);
        for j in 0..lb {
            if vb[j] != p1 || vb[(j + 1) % lb] != p0 {
                continue;
            }
            // Walk a from p1 around to p0, then b from after p0 to before p1.
            let mut loop_: Vec<DVec3> = (0..la).map(|k| va[(i + 1 + k) % la]).collect();
            loop_.extend((2..lb).map(|k| vb[(j + k) % lb]));
            let vertices = convex_cleanup(loop_, na, tol)?;
            let mut polygons = a.polygons.clone();
            polygons.extend_from_slice(&b.polygons);
            return Some(MergedPlate { vertices, polygons });
        }
    }
    None
}

/// Drops collinear vertices; `None` when the loop turns clockwise anywhere (not convex).
fn convex_cleanup(mut vs: Vec<DVec3>, n: DVec3, tol: f64) -> Option<Vec<DVec3>> {
    loop {
        let m = vs.len();
        if m < 3 {
            return None;
        }
        let mut dropped = false;
        for k in 0..m {
            let (prev, cur, next) = (vs[(k + m - 1) % m], vs[k], vs[(k + 1) % m]);
            let (e1, e2) = (cur - prev, next - cur);
            let turn = e1.cross(e2).dot(n);
            let scale = e1.length().max(e2.length());
            if turn.abs() <= tol * scale {
                vs.remove(k);
                dropped = true;
                break;
            }
            if turn < 0.0 {
                return None;
            }
        }
        if !dropped {
            return Some(vs);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_triangles_make_their_quad_and_an_l_shape_does_not_merge() {
        let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y);
        let polys = [Poly::triangle(a, b, c), Poly::triangle(a, c, d)];
        let m = merge_coplanar(&polys, &[0, 1], 2.0);
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].vertices.len(), 4);
        assert_eq!(m[0].polygons, vec![0, 1]);
        // Three unit squares in an L: the first two merge into a 2 × 1 rectangle, the third cannot join.
        let sq = |x: f64, y: f64| {
            Poly::quad(DVec3::new(x, y, 0.0), DVec3::new(x + 1.0, y, 0.0), DVec3::new(x + 1.0, y + 1.0, 0.0), DVec3::new(x, y + 1.0, 0.0))
        };
        let polys = [sq(0.0, 0.0), sq(1.0, 0.0), sq(0.0, 1.0)];
        let m = merge_coplanar(&polys, &[0, 1, 2], 3.0);
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].polygons.len(), 2);
        // A 2 × 2 grid merges completely.
        let polys = [sq(0.0, 0.0), sq(1.0, 0.0), sq(0.0, 1.0), sq(1.0, 1.0)];
        let m = merge_coplanar(&polys, &[0, 1, 2, 3], 3.0);
        assert_eq!((m.len(), m[0].polygons.len(), m[0].vertices.len()), (1, 4, 4));
    }

    #[test]
    fn split_floor_blocks_only_when_merged() {
        use crate::visibility::shaft::{convex_polygon_occludes, plate_occludes};
        let quad_at =
            |z: f64, lo: f64, hi: f64| [DVec3::new(lo, lo, z), DVec3::new(hi, lo, z), DVec3::new(hi, hi, z), DVec3::new(lo, hi, z)];
        let (below, above) = (quad_at(-1.0, 0.2, 0.8), quad_at(1.0, 0.2, 0.8));
        let (a, b, c, d) = (DVec3::new(-1.0, -1.0, 0.0), DVec3::new(2.0, -1.0, 0.0), DVec3::new(2.0, 2.0, 0.0), DVec3::new(-1.0, 2.0, 0.0));
        let polys = [Poly::triangle(a, b, c), Poly::triangle(a, c, d)];
        assert!(polys.iter().all(|t| !plate_occludes(&below, &above, t)), "neither half blocks alone");
        let m = merge_coplanar(&polys, &[0, 1], 5.0);
        assert!(convex_polygon_occludes(&below, &above, &m[0].vertices), "the merged floor blocks");
    }

    #[test]
    fn gaps_and_bends_do_not_merge() {
        let t1 = Poly::triangle(DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0));
        let t2 = Poly::triangle(DVec3::ZERO, DVec3::new(1.0, 1.0 + 1e-9, 0.0), DVec3::Y);
        assert!(merge_coplanar(&[t1, t2], &[0, 1], 2.0).is_empty(), "edge end not bit-identical");
        let t3 = Poly::triangle(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, 1.0, 0.1));
        assert!(merge_coplanar(&[t1, t3], &[0, 1], 2.0).is_empty(), "not coplanar");
    }
}
