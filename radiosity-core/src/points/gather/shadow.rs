//! The visibility of a leaf from a point: rays to samples of the leaf on a parameter grid shared by
//! its pieces, and where the samples disagree, adaptive regular subdivision down to the deepest
//! level, each piece with its own exact form factor.

use super::clip::{Clipped, Sides, form_factor};
use super::{SAMPLE_INSET, SAMPLE_SHIFT, UNIFORM_MAX_SUBTENSE};
use crate::geom::{DVec3, Poly};
use crate::hierarchy::NONE;
use crate::visibility::RayCaster;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A piece of a leaf, given by its corners in the leaf's parameters (see [`Poly::point`]) scaled
/// by `2^(depth + 1)`, `depth` the deepest subdivision: integers down to the centres of the finest
/// quads, so that corners shared by pieces are the same sample.
#[derive(Clone, Copy, Debug)]
struct Piece {
    corners: [[u32; 2]; 4],
    n: usize,
}

impl Piece {
    /// The whole leaf.
    fn leaf(poly: &Poly, scale: u32) -> Piece {
        match poly.n_vertices() {
            3 => Piece { corners: [[0, 0], [scale, 0], [0, scale], [0, 0]], n: 3 },
            _ => Piece { corners: [[0, 0], [scale, 0], [scale, scale], [0, scale]], n: 4 },
        }
    }

    /// The 4 children of regular subdivision (midpoints in the parameters, as [`Poly::subdivide`]).
    fn children(&self) -> [Piece; 4] {
        let mid = |a: [u32; 2], b: [u32; 2]| [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
        let [a, b, c, d] = self.corners;
        if self.n == 3 {
            let tri = |p, q, r| Piece { corners: [p, q, r, r], n: 3 };
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            [tri(a, ab, ca), tri(ab, b, bc), tri(ca, bc, c), tri(bc, ca, ab)]
        } else {
            let quad = |p, q, r, s| Piece { corners: [p, q, r, s], n: 4 };
            let (ab, bc, cd, da, m) = (mid(a, b), mid(b, c), mid(c, d), mid(d, a), mid(a, c));
            [quad(a, ab, m, da), quad(ab, b, bc, m), quad(m, bc, c, cd), quad(da, m, cd, d)]
        }
    }
}

/// The parameters (in [0, 1]) of the sample standing for the parameter-grid point `g` (scaled by
/// `scale`) of a leaf of `n_vertices`: drawn toward the leaf's centre by [`SAMPLE_INSET`] and
/// shifted by [`SAMPLE_SHIFT`].
fn sample_param(g: [f64; 2], scale: f64, n_vertices: usize) -> [f64; 2] {
    let centre = if n_vertices == 3 { 1.0 / 3.0 } else { 0.5 };
    let (u, v) = (g[0] / scale, g[1] / scale);
    [u + SAMPLE_INSET * (centre - u + SAMPLE_SHIFT[0]), v + SAMPLE_INSET * (centre - v + SAMPLE_SHIFT[1])]
}

/// The hasher of the sample cache's keys (packed grid coordinates): the SplitMix64 finaliser,
/// a few instructions where the standard SipHash took a seventh of a gather.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct GridHasher(u64);

impl Hasher for GridHasher {
    fn finish(&self) -> u64 {
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }

    fn write_u64(&mut self, n: u64) {
        self.0 = self.0.rotate_left(32) ^ n;
    }
}

/// The visibility search from one point, leaf after leaf.
pub(super) struct Shot<'c> {
    pub(super) caster: &'c RayCaster,
    pub(super) x: DVec3,
    pub(super) n: DVec3,
    pub(super) origin: DVec3,
    pub(super) sides: Sides,
    pub(super) max_depth: u32,
    pub(super) rays: u64,
    /// The leaf searched, its input polygon (whose own triangles do not block rays to it) and
    /// its parameters' scale (`2^(max_depth + 1)`).
    pub(super) leaf: Poly,
    pub(super) polygon: u32,
    pub(super) scale: u32,
    /// Whether the ray to each parameter-grid sample of the leaf is clear.
    pub(super) cache: HashMap<u64, bool, BuildHasherDefault<GridHasher>>,
}

impl Shot<'_> {
    /// The visible part of the form factor `f` of the leaf `poly` (`clipped`: clipped to the
    /// point's sides).
    pub(super) fn leaf(&mut self, poly: &Poly, polygon: u32, clipped: &Clipped, f: f64) -> f64 {
        self.leaf = *poly;
        self.polygon = polygon;
        self.cache.clear();
        self.visible(&Piece::leaf(poly, self.scale), clipped, f, 0)
    }

    fn clear(&mut self, target: DVec3) -> bool {
        self.rays += 1;
        self.caster.segment_clear(self.origin, target, NONE, self.polygon)
    }

    /// Whether the ray to the sample at the leaf's parameters `g` (scaled) is clear: the point
    /// drawn toward the leaf's centre and shifted a little (see [`SAMPLE_INSET`]); cached for grid
    /// points (`key`).
    fn clear_param(&mut self, g: [f64; 2], key: Option<u64>) -> bool {
        if let Some(clear) = key.and_then(|k| self.cache.get(&k).copied()) {
            return clear;
        }
        let [u, v] = sample_param(g, f64::from(self.scale), self.leaf.n_vertices());
        let clear = self.clear(self.leaf.point(u, v));
        if let Some(k) = key {
            let _ = self.cache.insert(k, clear);
        }
        clear
    }

    /// The visible part of the form factor `f` of `piece` (`clipped`: the piece clipped to the
    /// point's sides), at subdivision `depth`.
    fn visible(&mut self, piece: &Piece, clipped: &Clipped, f: f64, depth: u32) -> f64 {
        let vs = clipped.vertices();
        let center = vs.iter().copied().sum::<DVec3>() / vs.len() as f64;
        let whole = clipped.unclipped;
        let (n_clear, n_samples) = if whole {
            // The piece's corners and centre on the leaf's parameter grid, shared with its
            // neighbours, parent and children.
            let key = |g: [u32; 2]| u64::from(g[0]) << 32 | u64::from(g[1]);
            let mut n_clear = 0;
            for &g in &piece.corners[..piece.n] {
                n_clear += usize::from(self.clear_param([f64::from(g[0]), f64::from(g[1])], Some(key(g))));
            }
            let [a, _, c, _] = piece.corners;
            n_clear += usize::from(if piece.n == 3 {
                let sum = |k: usize| piece.corners[..3].iter().map(|g| f64::from(g[k])).sum::<f64>() / 3.0;
                self.clear_param([sum(0), sum(1)], None)
            } else {
                let m = [(a[0] + c[0]) / 2, (a[1] + c[1]) / 2];
                self.clear_param([f64::from(m[0]), f64::from(m[1])], Some(key(m)))
            });
            (n_clear, piece.n + 1)
        } else {
            // Cut by the point's planes: the clipped polygon's centre and corners, drawn toward its
            // centre and moved a little along the next edge.
            let mut n_clear = usize::from(self.clear(center + 0.25 * SAMPLE_INSET * (vs[1] - vs[0])));
            for (i, &v) in vs.iter().enumerate() {
                let next = vs[(i + 1) % vs.len()];
                n_clear += usize::from(self.clear(v + SAMPLE_INSET * (center - v) + 0.25 * SAMPLE_INSET * (next - v)));
            }
            (n_clear, vs.len() + 1)
        };
        if n_clear == 0 || n_clear == n_samples {
            let radius = vs.iter().map(|&v| (v - center).length()).fold(0.0, f64::max);
            if depth >= self.max_depth || radius <= UNIFORM_MAX_SUBTENSE * (center - self.x).length() {
                return if n_clear == 0 { 0.0 } else { f };
            }
        } else if depth >= self.max_depth {
            return f * n_clear as f64 / n_samples as f64;
        }
        let scale = f64::from(self.scale);
        let mut sum = 0.0;
        for child in piece.children() {
            let corners = child.corners.map(|g| self.leaf.point(f64::from(g[0]) / scale, f64::from(g[1]) / scale));
            let c = self.sides.clip(&corners[..child.n]);
            let fc = form_factor(self.x, self.n, &c);
            if fc > 0.0 {
                sum += self.visible(&child, &c, fc, depth + 1);
            }
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::SHADOW_DEPTH;

    fn quad() -> Poly {
        Poly::quad(DVec3::new(0.0, 0.0, 0.0), DVec3::new(2.0, 0.1, 0.0), DVec3::new(2.5, 1.7, 0.0), DVec3::new(-0.3, 1.2, 0.0))
    }

    fn triangle() -> Poly {
        Poly::triangle(DVec3::new(0.0, 0.0, 1.0), DVec3::new(2.0, 0.3, 1.0), DVec3::new(0.4, 1.5, 1.0))
    }

    /// The pieces in parameters are the hierarchy's regular subdivision (`Poly::subdivide`), two
    /// levels down, so each piece's form factor is that of the element the hierarchy would make.
    #[test]
    fn pieces_are_the_regular_subdivision() {
        let scale = 2 << SHADOW_DEPTH;
        for poly in [quad(), triangle()] {
            let at = |g: [u32; 2]| poly.point(f64::from(g[0]) / f64::from(scale), f64::from(g[1]) / f64::from(scale));
            let leaf = Piece::leaf(&poly, scale);
            for (piece, child) in leaf.children().iter().zip(poly.subdivide()) {
                for (grand, grand_child) in piece.children().iter().zip(child.subdivide()) {
                    for (k, v) in grand_child.vertices().iter().enumerate() {
                        let d = (at(grand.corners[k]) - *v).length();
                        assert!(d <= 1e-12, "{:?} corner {k}: {d}", poly.kind);
                    }
                }
            }
        }
    }

    /// Every sample of the finest grid lies strictly inside its leaf, off its edges, and within
    /// the inset of its grid point.
    #[test]
    fn samples_stay_inside_the_leaf() {
        let n = 1u32 << (SHADOW_DEPTH + 1);
        let scale = f64::from(n);
        for n_vertices in [3, 4] {
            for i in 0..=n {
                for j in (0..=n).filter(|&j| n_vertices == 4 || i + j <= n) {
                    let (gu, gv) = (f64::from(i) / scale, f64::from(j) / scale);
                    let [u, v] = sample_param([f64::from(i), f64::from(j)], scale, n_vertices);
                    let margin = if n_vertices == 3 { u.min(v).min(1.0 - u - v) } else { u.min(v).min(1.0 - u).min(1.0 - v) };
                    assert!(margin > 1e-3 * SAMPLE_INSET, "{n_vertices} vertices, grid ({i}, {j}): ({u}, {v})");
                    assert!((u - gu).abs().max((v - gv).abs()) <= SAMPLE_INSET, "moved at most the inset");
                }
            }
        }
    }
}
