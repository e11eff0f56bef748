//! A lower bound on radiosity from ray-traced direct light: an independent check of a solution.
//!
//! Light only adds up, so every polygon's radiosity is at least its emission plus the reflection
//! (and, for a transmitting leaf, the transmission from its other side) of the light it receives
//! straight from the emitters. That direct irradiance is estimated here by Monte Carlo over point
//! pairs on the polygon and on each emitter, each pair tested against every triangle of the scene:
//! no hierarchy, no links, no clusters, so a solution that falls below the bound by more than the
//! estimate's noise has lost light somewhere in its approximations.

use crate::geom::{DVec3, Poly};
use crate::hierarchy::NONE;
use crate::scene::Scene;
use crate::visibility::{RayCaster, Rng};
use rayon::prelude::*;

/// Direct irradiance `H_d` of each of `polygons` from every emitter of `scene`, from `samples`
/// point pairs per (polygon, emitter), seeded: `∑_e E_e · (A_e / N) ∑ cosθ cosθ' V / (π r²)`.
#[must_use]
pub fn direct_irradiance(scene: &Scene, caster: &RayCaster, polygons: &[u32], samples: u32, seed: u64) -> Vec<[f64; 3]> {
    let emitters: Vec<u32> = (0..scene.polygons.len() as u32).filter(|&i| scene.material_of(i as usize).is_emitter()).collect();
    let n = samples.max(1);
    polygons
        .par_iter()
        .map(|&i| {
            let p = &scene.polygons[i as usize].poly;
            let mut h = [0.0; 3];
            for &l in &emitters {
                if l == i {
                    continue;
                }
                let q = &scene.polygons[l as usize].poly;
                let e = scene.material_of(l as usize).emission;
                let mut rng = Rng::for_link(seed, i, l);
                let [f, _] = emitter_exchange(p, q, n, &mut rng, false, |x, y| caster.segment_clear(x, y, i, l));
                for c in 0..3 {
                    h[c] += f * e[c];
                }
            }
            h
        })
        .collect()
}

/// The form factor from a polygon `p` to an emitter `q` (the irradiance per unit emitted
/// radiosity), estimated from `n` point pairs: `(A_q / πn) ∑ cosθ cosθ' V / r²`, with `clear(x, y)`
/// the visibility of the pair. The points are stratified on both polygons (`q` on an `m × m` grid
/// when `n = m²`, else in one coordinate; `p` in one coordinate) and the strata paired by a random
/// permutation, which keeps the estimate unbiased. Returned for `p`'s front side and, when
/// `both_sides` (a transmitting leaf), for its back side from the same pairs (0 otherwise).
pub fn emitter_exchange(p: &Poly, q: &Poly, n: u32, rng: &mut Rng, both_sides: bool, clear: impl Fn(DVec3, DVec3) -> bool) -> [f64; 2] {
    let (normal, nq) = (p.normal(), q.normal());
    let n = n.max(1);
    let m = f64::from(n).sqrt().round() as u32;
    let grid = m * m == n;
    // A random pairing of the strata on `p` with those on `q` (Fisher–Yates).
    let mut order: Vec<u32> = (0..n).collect();
    for k in (1..n as usize).rev() {
        order.swap(k, (rng.next_u64() % (k as u64 + 1)) as usize);
    }
    let mut acc = [0.0; 2];
    for (k, &j) in order.iter().enumerate() {
        let k = k as u32;
        let x = p.sample((f64::from(j) + rng.next_f64()) / f64::from(n), rng.next_f64());
        let y = if grid {
            q.sample((f64::from(k % m) + rng.next_f64()) / f64::from(m), (f64::from(k / m) + rng.next_f64()) / f64::from(m))
        } else {
            q.sample(rng.next_f64(), (f64::from(k) + rng.next_f64()) / f64::from(n))
        };
        let d: DVec3 = y - x;
        let r2 = d.length_squared();
        let cos_q = (-nq.dot(d)).max(0.0);
        let cos_p = normal.dot(d);
        let side = usize::from(cos_p < 0.0);
        if side == 1 && !both_sides {
            continue;
        }
        let kernel = cos_p.abs() * cos_q / (r2 * r2);
        if kernel > 0.0 && kernel.is_finite() && clear(x, y) {
            acc[side] += kernel;
        }
    }
    acc.map(|a| a * q.area() / (std::f64::consts::PI * f64::from(n)))
}

/// The lower bound `E + ρ·H_d + t·H_d(other side)` on the radiosity of each of `polygons`
/// (`twin[i]`: the other side of a transmitting polygon, or [`NONE`], as
/// [`crate::hierarchy::twins`] gives it), from [`direct_irradiance`].
#[must_use]
pub fn direct_lower_bound(scene: &Scene, caster: &RayCaster, twin: &[u32], polygons: &[u32], samples: u32, seed: u64) -> Vec<[f64; 3]> {
    let mut asked: Vec<u32> = polygons.to_vec();
    asked.extend(polygons.iter().map(|&i| twin[i as usize]).filter(|&t| t != NONE));
    asked.sort_unstable();
    asked.dedup();
    let h = direct_irradiance(scene, caster, &asked, samples, seed);
    let of = |i: u32| asked.binary_search(&i).map(|k| h[k]).expect("every asked polygon has an estimate");
    polygons
        .iter()
        .map(|&i| {
            let m = scene.material_of(i as usize);
            let own = of(i);
            let other = if twin[i as usize] == NONE { [0.0; 3] } else { of(twin[i as usize]) };
            std::array::from_fn(|c| m.emission[c] + m.reflectance[c] * own[c] + m.transmittance[c] * other[c])
        })
        .collect()
}
