//! `solution.ply`: the leaf elements as a mesh with per-vertex radiosity (float `radiosity_r/g/b`, W/m²)
//! and tone-mapped `red/green/blue` bytes. Binary little-endian PLY 1.0; each leaf has its own vertices.

use super::render::ToneMap;
use super::smooth::CornerValues;
use crate::hierarchy::Hierarchy;
use std::io::Write;

/// Writes the leaves of `h` with smoothed corner radiosity.
pub fn write_ply(w: &mut impl Write, h: &Hierarchy, corners: &CornerValues, tone: &ToneMap) -> std::io::Result<()> {
    let leaves: Vec<u32> = h.leaves().filter(|&e| h.get(e).poly().is_some()).collect();
    let n_vertices: usize = leaves.iter().map(|&e| h.get(e).poly().map_or(0, |p| p.n_vertices())).sum();
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment radiosity solution: leaf elements, radiosity in W/m2\n\
         element vertex {n_vertices}\nproperty float x\nproperty float y\nproperty float z\n\
         property float radiosity_r\nproperty float radiosity_g\nproperty float radiosity_b\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        leaves.len()
    )?;
    let mut buf = Vec::with_capacity(n_vertices * 27);
    for &e in &leaves {
        let poly = h.get(e).poly().expect("filtered");
        let c = corners.corners(e).copied().unwrap_or([[0.0; 3]; 4]);
        for (k, v) in poly.vertices().iter().enumerate() {
            for x in [v.x, v.y, v.z, c[k][0], c[k][1], c[k][2]] {
                buf.extend_from_slice(&(x as f32).to_le_bytes());
            }
            buf.extend_from_slice(&tone.map(c[k]));
        }
    }
    w.write_all(&buf)?;
    buf.clear();
    let mut next = 0i32;
    for &e in &leaves {
        let m = h.get(e).poly().expect("filtered").n_vertices();
        buf.push(m as u8);
        for k in 0..m as i32 {
            buf.extend_from_slice(&(next + k).to_le_bytes());
        }
        next += m as i32;
    }
    w.write_all(&buf)
}
