//! Which polygons belong to closed meshes: edge connectivity by shared end points.

use super::{DVec3, Poly};
use std::collections::HashMap;

/// Whether each of `polys` belongs to an open mesh: its edge-connected component (polygons joined
/// through edges with the same two end points, compared exactly: shared vertices are the same
/// numbers) has an edge that only one polygon has. A box's faces are closed; a lone quad, a
/// ground plane or a leaf of two triangles are open. A mesh whose faces meet at T-junctions
/// counts as open.
#[must_use]
pub fn open_mesh_faces(polys: &[Poly]) -> Vec<bool> {
    let n = polys.len();
    let key = |v: DVec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
    let mut edges: HashMap<([u64; 3], [u64; 3]), Vec<u32>> = HashMap::new();
    for (p, poly) in polys.iter().enumerate() {
        let vs = poly.vertices();
        for k in 0..vs.len() {
            let (a, b) = (key(vs[k]), key(vs[(k + 1) % vs.len()]));
            edges.entry(if a <= b { (a, b) } else { (b, a) }).or_default().push(p as u32);
        }
    }
    // Union-find over polygons sharing an edge.
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for polys in edges.values() {
        for w in polys.windows(2) {
            let (a, b) = (root(&mut parent, w[0]), root(&mut parent, w[1]));
            parent[a.max(b) as usize] = a.min(b);
        }
    }
    let mut open = vec![false; n];
    for polys in edges.values() {
        if polys.len() < 2 {
            let r = root(&mut parent, polys[0]);
            open[r as usize] = true;
        }
    }
    (0..n as u32).map(|p| open[root(&mut parent, p) as usize]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_is_closed_and_a_lone_quad_or_a_split_one_is_open() {
        let c = DVec3::new;
        let quad = |a, b, cc, d| Poly::quad(a, b, cc, d);
        let cube = [
            quad(c(0., 0., 0.), c(0., 1., 0.), c(1., 1., 0.), c(1., 0., 0.)),
            quad(c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)),
            quad(c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)),
            quad(c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.)),
            quad(c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)),
            quad(c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)),
        ];
        let lone = quad(c(3., 0., 0.), c(4., 0., 0.), c(4., 1., 0.), c(3., 1., 0.));
        let halves =
            [Poly::triangle(c(5., 0., 0.), c(6., 0., 0.), c(6., 1., 0.)), Poly::triangle(c(5., 0., 0.), c(6., 1., 0.), c(5., 1., 0.))];
        let all: Vec<Poly> = cube.iter().copied().chain([lone]).chain(halves).collect();
        assert_eq!(open_mesh_faces(&all), [vec![false; 6], vec![true; 3]].concat());
        // The cube without its top is open.
        assert_eq!(open_mesh_faces(&cube[..5]), vec![true; 5]);
    }
}
