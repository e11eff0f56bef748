//! An independent reference solver for small closed scenes without occluders: constant elements on
//! a uniform mesh, every patch-to-patch form factor computed (Stokes' double contour integral for
//! near pairs, Gauss quadrature of Lambert's exact point-to-polygon formula for the others), the
//! dense system `B = E + ρ F B` iterated to convergence, and Richardson extrapolation over two mesh
//! sizes. No hierarchy, cluster, refinement, link or error criterion of the engine is involved:
//! only the two form-factor formulas, which `tests/core/formfactor.rs` checks against closed forms.
//!
//! It assumes every pair of patches sees the other unoccluded (a convex room): there is no
//! visibility.

use crate::formfactor::{point_polygon, polygon_polygon};
use crate::geom::{DVec3, Poly, PolyKind};
use crate::scene::Scene;
use rayon::prelude::*;

/// Pairs nearer than this (centre distance over the sum of the patches' radii) use the contour
/// integral; farther pairs the 4×4 Gauss rule on the receiver.
pub const CONTOUR_SEPARATION: f64 = 3.0;
/// The iteration stops when no radiosity changes by more than this, relative to the largest.
pub const ITERATION_REL_TOL: f64 = 1e-14;

/// One patch of the uniform mesh.
#[derive(Clone, Debug)]
struct Patch {
    poly: Poly,
    polygon: usize,
    area: f64,
    center: DVec3,
    normal: DVec3,
    radius: f64,
}

/// The meshed scene and its dense form-factor matrix (row `i`: `F(i ← j)` for every source `j`).
pub struct DenseSystem {
    patches: Vec<Patch>,
    ff: Vec<f64>,
    n_polygons: usize,
}

impl DenseSystem {
    /// Meshes every polygon of `scene` into patches no longer than `h` along their edges and
    /// computes the form factors (`O(patches²)` time and memory).
    #[must_use]
    pub fn new(scene: &Scene, h: f64) -> DenseSystem {
        let mut patches = Vec::new();
        for (i, p) in scene.polygons.iter().enumerate() {
            for poly in mesh(&p.poly, h) {
                let center = poly.centroid();
                let radius = poly.vertices().iter().map(|v| (*v - center).length()).fold(0.0, f64::max);
                patches.push(Patch { poly, polygon: i, area: poly.area(), center, normal: p.poly.normal(), radius });
            }
        }
        let n = patches.len();
        let ff: Vec<f64> = (0..n)
            .into_par_iter()
            .flat_map_iter(|i| {
                let patches = &patches;
                (0..n).map(move |j| if i == j { 0.0 } else { form_factor(&patches[i], &patches[j]) })
            })
            .collect();
        DenseSystem { patches, ff, n_polygons: scene.polygons.len() }
    }

    /// Number of patches.
    #[must_use]
    pub fn n_patches(&self) -> usize {
        self.patches.len()
    }

    /// Each patch's row sum `Σ_j F(i ← j)` (1 in a closed scene, up to the formulas' accuracy).
    #[must_use]
    pub fn row_sums(&self) -> Vec<f64> {
        let n = self.patches.len();
        (0..n).map(|i| self.ff[i * n..(i + 1) * n].iter().sum()).collect()
    }

    /// Solves `B = E + ρ F B` per channel for reflectance and emission given per input polygon, and
    /// returns each input polygon's area-weighted mean radiosity.
    #[must_use]
    pub fn polygon_means(&self, reflectance: &[[f64; 3]], emission: &[[f64; 3]]) -> Vec<[f64; 3]> {
        self.polygon_means_lit(reflectance, emission, |_, _| 0.0)
    }

    /// [`DenseSystem::polygon_means`] with a direct illuminance `direct(x, n)` (a luminaire's, in a
    /// convex room) on top of the emission: each patch emits `E + ρ·D̄`, `D̄` its mean of `direct`
    /// by the [`DIRECT_CELLS`]² midpoint rule.
    #[must_use]
    pub fn polygon_means_lit(
        &self,
        reflectance: &[[f64; 3]],
        emission: &[[f64; 3]],
        direct: impl Fn(DVec3, DVec3) -> f64 + Sync,
    ) -> Vec<[f64; 3]> {
        let n = self.patches.len();
        let cells = DIRECT_CELLS as f64;
        let d: Vec<f64> = self
            .patches
            .par_iter()
            .map(|p| {
                let mut sum = 0.0;
                let mut weight = 0.0;
                for i in 0..DIRECT_CELLS {
                    for j in 0..DIRECT_CELLS {
                        let (u, v) = ((i as f64 + 0.5) / cells, (j as f64 + 0.5) / cells);
                        // An area-preserving map of the unit square (the mesh's quads are
                        // parallelograms; triangles are folded).
                        sum += direct(p.poly.sample(u, v), p.normal);
                        weight += 1.0;
                    }
                }
                sum / weight
            })
            .collect();
        let mut means = vec![[0.0; 3]; self.n_polygons];
        for c in 0..3 {
            let rho: Vec<f64> = self.patches.iter().map(|p| reflectance[p.polygon][c]).collect();
            let e: Vec<f64> = self.patches.iter().zip(&d).map(|(p, d)| emission[p.polygon][c] + reflectance[p.polygon][c] * d).collect();
            let mut b = e.clone();
            loop {
                let next: Vec<f64> = (0..n)
                    .into_par_iter()
                    .map(|i| e[i] + rho[i] * self.ff[i * n..(i + 1) * n].iter().zip(&b).map(|(f, x)| f * x).sum::<f64>())
                    .collect();
                let change = next.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
                let top = next.iter().copied().fold(0.0, f64::max);
                b = next;
                if change <= ITERATION_REL_TOL * top {
                    break;
                }
            }
            let mut area = vec![0.0; self.n_polygons];
            for (p, x) in self.patches.iter().zip(&b) {
                means[p.polygon][c] += p.area * x;
                area[p.polygon] += p.area;
            }
            for (m, a) in means.iter_mut().zip(area) {
                m[c] /= a;
            }
        }
        means
    }
}

/// Cells per side of the midpoint rule of [`DenseSystem::polygon_means_lit`].
pub const DIRECT_CELLS: usize = 8;

/// The scene's reflectance and emission per polygon.
#[must_use]
pub fn materials(scene: &Scene) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    scene.polygons.iter().map(|p| (scene.materials[p.material as usize].reflectance, scene.materials[p.material as usize].emission)).unzip()
}

/// Richardson extrapolation of polygon means computed with mesh sizes `h` (`coarse`) and `h/2`
/// (`fine`) for a method of order 2: `fine + (fine − coarse)/3`.
#[must_use]
pub fn richardson(coarse: &[[f64; 3]], fine: &[[f64; 3]]) -> Vec<[f64; 3]> {
    coarse.iter().zip(fine).map(|(c, f)| std::array::from_fn(|k| f[k] + (f[k] - c[k]) / 3.0)).collect()
}

/// `poly` cut into a regular grid of pieces whose edges are at most `h` (quads) or by repeated 4-way
/// subdivision until they are (triangles).
fn mesh(poly: &Poly, h: f64) -> Vec<Poly> {
    let v = poly.v;
    match poly.kind {
        PolyKind::Quad => {
            let nu = (((v[1] - v[0]).length().max((v[2] - v[3]).length())) / h).ceil().max(1.0) as usize;
            let nv = (((v[3] - v[0]).length().max((v[2] - v[1]).length())) / h).ceil().max(1.0) as usize;
            let mut out = Vec::with_capacity(nu * nv);
            for j in 0..nv {
                for i in 0..nu {
                    let p = |a: usize, b: usize| poly.point(a as f64 / nu as f64, b as f64 / nv as f64);
                    out.push(Poly::quad(p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)));
                }
            }
            out
        }
        PolyKind::Triangle => {
            let longest = (0..3).map(|k| (v[(k + 1) % 3] - v[k]).length()).fold(0.0, f64::max);
            if longest <= h { vec![*poly] } else { poly.subdivide().iter().flat_map(|c| mesh(c, h)).collect() }
        }
    }
}

const GL4: [f64; 4] = [0.069_431_844_202_973_7, 0.330_009_478_207_571_9, 0.669_990_521_792_428_1, 0.930_568_155_797_026_3];
const GL4_W: [f64; 4] = [0.173_927_422_568_726_9, 0.326_072_577_431_273_1, 0.326_072_577_431_273_1, 0.173_927_422_568_726_9];

/// `F(r ← s)` of two patches without occlusion.
fn form_factor(r: &Patch, s: &Patch) -> f64 {
    let behind = |plane: &Patch, pts: &[DVec3]| {
        let tol = 1e-9 * plane.radius;
        pts.iter().all(|v| plane.normal.dot(*v - plane.center) <= tol)
    };
    if behind(r, s.poly.vertices()) || behind(s, r.poly.vertices()) {
        return 0.0;
    }
    let separation = (r.center - s.center).length() / (r.radius + s.radius);
    if separation < CONTOUR_SEPARATION {
        return polygon_polygon(r.poly.vertices(), s.poly.vertices());
    }
    let sv = s.poly.vertices();
    match r.poly.kind {
        PolyKind::Quad => {
            let (mut f, mut w) = (0.0, 0.0);
            for (a, wa) in GL4.iter().zip(GL4_W) {
                for (b, wb) in GL4.iter().zip(GL4_W) {
                    let v = r.poly.v;
                    let du = (1.0 - b) * (v[1] - v[0]) + b * (v[2] - v[3]);
                    let dv = (1.0 - a) * (v[3] - v[0]) + a * (v[2] - v[1]);
                    let jac = wa * wb * du.cross(dv).length();
                    f += jac * point_polygon(r.poly.point(*a, *b), r.normal, sv, s.normal);
                    w += jac;
                }
            }
            f / w
        }
        PolyKind::Triangle => {
            // The 6-point rule of degree 4 (Dunavant): points (a, a, 1 − 2a) and permutations.
            const RULE: [(f64, f64); 2] = [(0.445_948_490_915_965, 0.223_381_589_678_011), (0.091_576_213_509_771, 0.109_951_743_655_322)];
            let v = r.poly.v;
            let mut f = 0.0;
            for &(a, w) in &RULE {
                let o = 1.0 - 2.0 * a;
                for (l0, l1, l2) in [(a, a, o), (a, o, a), (o, a, a)] {
                    f += w * point_polygon(v[0] * l0 + v[1] * l1 + v[2] * l2, r.normal, sv, s.normal);
                }
            }
            f
        }
    }
}
