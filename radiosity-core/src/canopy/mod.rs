//! Random canopies: a horizontal slab of small black leaves with a spherical leaf-angle
//! distribution, for validation against canopy physics (Beer's law).
//!
//! [`random_leaves`] places `N` square leaves of side `s` independently and uniformly at random:
//! their centres in the slab `x, y ∈ [−L/2, L/2]`, `z ∈ [base, base + height]`, their normals
//! uniform over the sphere, each turned about its normal by a uniform angle. `N` is the leaf area
//! index `LAI` times the canopy's ground area `L²` over the leaf area `s²`, rounded.
//!
//! A ray crossing the whole slab misses one such leaf with probability `1 − G·a/(A·cos θ)` (`a`
//! the leaf area, `A = L²`, `θ` the ray's zenith angle, `G` = [`G_SPHERICAL`] the mean projected
//! area of a unit leaf of random orientation), independently of the other leaves, so the canopy
//! transmits on average `(1 − G·a/(A·cos θ))^N` of a parallel beam ([`finite_beam_transmittance`]),
//! which is `exp(−G·LAI/cos θ)` ([`beam_transmittance`]) up to a relative `τ²/(2N)`
//! (`τ = G·LAI/cos θ`). Under a uniform sky it transmits `τ_d = 2·∫₀¹ μ·exp(−G·LAI/μ) dμ =
//! 2·E₃(G·LAI)` ([`diffuse_transmittance`]); a sky of distant sources gives
//! `Σ_i w_i·exp(−G·LAI/μ_i)` ([`sky_transmittance`]). Both hold below the canopy where the rays
//! stay inside it: farther than [`Canopy::margin`] from its edge.
//!
//! Leaves are one-sided polygons; the ray caster does not cull back faces, so both sides block.
//! [`write_scene_file`] writes a canopy as a scene file (TOML with the leaves in an OBJ file, a
//! ground, a `[sun]`, a `[sky]` and a calculation grid below the canopy's centre).

mod beer;
mod scene_file;

pub use beer::{beam_transmittance, diffuse_transmittance, expint_e3, finite_beam_transmittance, sky_transmittance};
pub use scene_file::{SceneFileOptions, write_scene_file};

use crate::daylight::DistantSource;
use crate::geom::DVec3;
use crate::scene::{Material, Scene, SceneBuilder};
use crate::visibility::Rng;
use std::path::Path;

/// The G-function of the spherical leaf-angle distribution: the mean area of a unit leaf's shadow
/// on a plane across the beam, whatever the beam's direction.
pub const G_SPHERICAL: f64 = 0.5;

/// Most leaves [`random_leaves`] makes (about 100 bytes each, and a scene polygon each).
pub const MAX_LEAVES: usize = 20_000_000;

/// A canopy's parameters (lengths in scene units, z up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CanopyParams {
    /// Leaf area index: one-sided leaf area per unit ground area (> 0).
    pub lai: f64,
    /// Side of the square leaves (> 0).
    pub leaf_size: f64,
    /// Side of the square of ground the leaf centres are spread over, centred on the origin
    /// (> `leaf_size`).
    pub extent: f64,
    /// Height of the lowest leaf centres above the ground (z = 0): at least the leaf's
    /// half-diagonal, so that no leaf reaches the ground.
    pub base: f64,
    /// Thickness of the slab of leaf centres (≥ 0).
    pub height: f64,
    /// Seed of the placement.
    pub seed: u64,
}

impl Default for CanopyParams {
    fn default() -> Self {
        CanopyParams { lai: 1.0, leaf_size: 0.1, extent: 10.0, base: 0.5, height: 2.0, seed: 1 }
    }
}

/// Parameters [`random_leaves`] cannot use.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("canopy: {0}")]
pub struct CanopyError(pub String);

impl CanopyParams {
    /// Checks the parameters (see the fields) and the leaf count ([`MAX_LEAVES`]).
    pub fn validate(&self) -> Result<(), CanopyError> {
        let bad = |msg: String| Err(CanopyError(msg));
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 { Ok(()) } else { bad(format!("{name} must be positive and finite, got {v}")) }
        };
        positive("leaf area index", self.lai)?;
        positive("leaf size", self.leaf_size)?;
        positive("extent", self.extent)?;
        if self.extent <= self.leaf_size {
            return bad(format!("extent {} must exceed the leaf size {}", self.extent, self.leaf_size));
        }
        if !self.height.is_finite() || self.height < 0.0 {
            return bad(format!("height must be finite and non-negative, got {}", self.height));
        }
        let half_diagonal = self.half_diagonal();
        if !self.base.is_finite() || self.base < half_diagonal {
            return bad(format!(
                "base {} must be at least the leaf's half-diagonal {half_diagonal:.6} so that no leaf reaches the ground",
                self.base
            ));
        }
        let n = self.lai * (self.extent / self.leaf_size).powi(2);
        if !(n.round() >= 1.0) {
            return bad(format!("leaf area index {} over extent {} makes no leaf of size {}", self.lai, self.extent, self.leaf_size));
        }
        if n.round() > MAX_LEAVES as f64 {
            return bad(format!("{n:.0} leaves is more than {MAX_LEAVES}: use larger leaves, a smaller extent or a lower leaf area index"));
        }
        Ok(())
    }

    /// Number of leaves: `LAI·L²/s²`, rounded.
    #[must_use]
    pub fn leaf_count(&self) -> usize {
        (self.lai * (self.extent / self.leaf_size).powi(2)).round() as usize
    }

    /// How far from the canopy's edge a ground point must be for every ray toward zenith angle
    /// `zenith` (radians, any azimuth) to cross the whole slab inside the canopy, past any leaf
    /// whose centre is in the slab: `(base + height + d)·tan θ + d`, `d` the leaf's half-diagonal.
    /// Infinite at and beyond the horizon.
    #[must_use]
    pub fn margin(&self, zenith: f64) -> f64 {
        let d = self.half_diagonal();
        if zenith.cos() <= 0.0 { f64::INFINITY } else { (self.base + self.height + d) * zenith.tan() + d }
    }

    /// Half the diagonal of a leaf: its farthest reach from its centre.
    #[must_use]
    pub fn half_diagonal(&self) -> f64 {
        self.leaf_size * std::f64::consts::FRAC_1_SQRT_2
    }
}

/// A generated canopy.
#[derive(Clone, Debug)]
pub struct Canopy {
    /// What it was made from.
    pub params: CanopyParams,
    /// The leaves, each a square CCW about its front normal.
    pub leaves: Vec<[DVec3; 4]>,
}

/// `N` random leaves (see the module docs), the same for the same parameters and seed.
pub fn random_leaves(params: &CanopyParams) -> Result<Canopy, CanopyError> {
    params.validate()?;
    let n = params.leaf_count();
    let mut rng = Rng::for_link(params.seed, 0x6361_6e6f, 0x7079);
    let half = 0.5 * params.leaf_size;
    let leaves = (0..n)
        .map(|_| {
            let mut u = || rng.next_f64();
            let c = DVec3::new((u() - 0.5) * params.extent, (u() - 0.5) * params.extent, params.base + u() * params.height);
            // Uniform on the sphere: z uniform in [−1, 1], azimuth uniform.
            let z = 2.0 * u() - 1.0;
            let phi = std::f64::consts::TAU * u();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let n = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let e1 = if n.x.abs() < 0.9 { DVec3::X.cross(n) } else { DVec3::Y.cross(n) }.normalize();
            let e2 = n.cross(e1);
            let psi = std::f64::consts::TAU * u();
            let t1 = e1 * psi.cos() + e2 * psi.sin();
            let t2 = n.cross(t1);
            let (a, b) = (t1 * half, t2 * half);
            [c - a - b, c + a - b, c + a + b, c - a + b]
        })
        .collect();
    Ok(Canopy { params: *params, leaves })
}

/// A ground under the canopy: the square of the canopy's extent at z = 0, facing up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ground {
    /// Its diffuse reflectance.
    pub reflectance: f64,
    /// Tiles per side (≥ 1): the ground is `tiles²` square polygons, row by row from −x, −y.
    pub tiles: u32,
}

impl Canopy {
    /// The leaf area index of the leaves made: `N·s²/L²` (the asked one up to the rounding of `N`).
    #[must_use]
    pub fn lai(&self) -> f64 {
        self.leaves.len() as f64 * self.params.leaf_size.powi(2) / self.params.extent.powi(2)
    }

    /// [`CanopyParams::margin`] of its parameters.
    #[must_use]
    pub fn margin(&self, zenith: f64) -> f64 {
        self.params.margin(zenith)
    }

    /// The canopy as a scene named `name`: the leaves (material `leaf`, black, one group) and an
    /// optional ground (material `ground`, group `ground`), lit by `distant`. Leaves come first,
    /// so polygon `leaves.len() + k` is ground tile `k`.
    pub fn scene(&self, name: &str, ground: Option<Ground>, distant: Vec<DistantSource>) -> Result<Scene, CanopyError> {
        let mut b = SceneBuilder::new(Path::new(&format!("{name} (generated)")), name);
        let leaf = b.material(Material::diffuse("leaf", [0.0; 3])).map_err(|e| CanopyError(e.to_string()))?;
        let g = b.group("leaves");
        for q in &self.leaves {
            b.face(q, leaf, g, 0).map_err(|e| CanopyError(e.to_string()))?;
        }
        if let Some(ground) = ground {
            if ground.tiles == 0 {
                return Err(CanopyError("the ground needs at least one tile per side".into()));
            }
            let m = b.material(Material::diffuse("ground", [ground.reflectance; 3])).map_err(|e| CanopyError(e.to_string()))?;
            let g = b.group("ground");
            for (x0, y0, x1, y1) in self.ground_tiles(ground.tiles) {
                let q = [DVec3::new(x0, y0, 0.0), DVec3::new(x1, y0, 0.0), DVec3::new(x1, y1, 0.0), DVec3::new(x0, y1, 0.0)];
                b.face(&q, m, g, 0).map_err(|e| CanopyError(e.to_string()))?;
            }
        }
        if b.n_polygons() != self.leaves.len() + ground.map_or(0, |g| (g.tiles as usize).pow(2)) {
            return Err(CanopyError("a leaf or ground tile was degenerate".into()));
        }
        let mut scene = b.finish();
        scene.distant = distant;
        Ok(scene)
    }

    /// The ground's tiles `(x0, y0, x1, y1)`, row by row from −x, −y.
    #[must_use]
    pub fn ground_tiles(&self, tiles: u32) -> Vec<(f64, f64, f64, f64)> {
        let half = 0.5 * self.params.extent;
        let step = self.params.extent / f64::from(tiles.max(1));
        let at = |i: u32| if i == tiles { half } else { -half + step * f64::from(i) };
        (0..tiles).flat_map(|j| (0..tiles).map(move |i| (at(i), at(j), at(i + 1), at(j + 1)))).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaves_are_squares_of_the_asked_size_deterministic_for_a_seed() {
        let p = CanopyParams { lai: 1.0, leaf_size: 0.2, extent: 4.0, base: 0.5, height: 1.0, seed: 7 };
        let c = random_leaves(&p).unwrap();
        assert_eq!(c.leaves.len(), 400);
        assert!((c.lai() - 1.0).abs() < 1e-12);
        for q in &c.leaves {
            for k in 0..4 {
                assert!(((q[(k + 1) % 4] - q[k]).length() - 0.2).abs() < 1e-12);
            }
            assert!(q.iter().all(|v| v.z >= 0.5 - p.half_diagonal() - 1e-12 && v.z <= 1.5 + p.half_diagonal() + 1e-12));
        }
        assert_eq!(random_leaves(&p).unwrap().leaves, c.leaves);
        assert_ne!(random_leaves(&CanopyParams { seed: 8, ..p }).unwrap().leaves, c.leaves);
        // Normals uniform over the sphere: mean |n_z| is 1/2, mean n_z is 0.
        let normals: Vec<DVec3> = c.leaves.iter().map(|q| (q[1] - q[0]).cross(q[2] - q[1]).normalize()).collect();
        let mean_abs = normals.iter().map(|n| n.z.abs()).sum::<f64>() / 400.0;
        let mean = normals.iter().map(|n| n.z).sum::<f64>() / 400.0;
        // Standard deviations over 400 leaves: 0.289/20 and 0.577/20; four of them allowed.
        assert!((mean_abs - 0.5).abs() < 4.0 * 0.289 / 20.0, "{mean_abs}");
        assert!(mean.abs() < 4.0 * 0.577 / 20.0, "{mean}");
    }

    #[test]
    fn bad_parameters_are_refused_in_words() {
        let ok = CanopyParams::default();
        for (p, words) in [
            (CanopyParams { lai: 0.0, ..ok }, "leaf area index"),
            (CanopyParams { lai: f64::NAN, ..ok }, "leaf area index"),
            (CanopyParams { leaf_size: -1.0, ..ok }, "leaf size"),
            (CanopyParams { extent: 0.05, ..ok }, "must exceed the leaf size"),
            (CanopyParams { height: -1.0, ..ok }, "height"),
            (CanopyParams { base: 0.01, ..ok }, "half-diagonal"),
            (CanopyParams { lai: 1e-6, ..ok }, "makes no leaf"),
            (CanopyParams { leaf_size: 1e-4, ..ok }, "more than"),
        ] {
            let e = random_leaves(&p).unwrap_err().to_string();
            assert!(e.contains(words), "{p:?}: {e}");
        }
    }

    #[test]
    fn scene_has_the_leaves_then_the_ground_tiles() {
        let c = random_leaves(&CanopyParams { lai: 0.5, leaf_size: 0.5, extent: 5.0, ..CanopyParams::default() }).unwrap();
        let s = c.scene("c", Some(Ground { reflectance: 0.2, tiles: 3 }), Vec::new()).unwrap();
        assert_eq!(s.polygons.len(), c.leaves.len() + 9);
        let ground: f64 = s.polygons[c.leaves.len()..].iter().map(|p| p.poly.area()).sum();
        assert!((ground - 25.0).abs() < 1e-9);
        assert!(c.scene("c", Some(Ground { reflectance: 0.2, tiles: 0 }), Vec::new()).is_err());
    }

    #[test]
    fn e3_against_tabulated_values() {
        // From E₁ tabulated to 8 digits (Abramowitz & Stegun 5.1: E₁(0.1) = 1.82292395,
        // E₁(0.5) = 0.55977359, E₁(1) = 0.21938393, E₁(2) = 0.04890051) by the recurrence, by hand.
        assert_eq!(expint_e3(0.0), 0.5);
        for (x, v) in [(0.1, 0.416_291_5), (0.5, 0.221_604_37), (1.0, 0.109_691_97), (2.0, 0.030_133_38)] {
            assert!((expint_e3(x) - v).abs() < 1e-7, "E3({x}) = {} vs {v}", expint_e3(x));
        }
    }
}
