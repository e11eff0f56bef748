//! The escape albedo from a local hierarchical radiosity solve of the prototype
//! ([`PhaseMethod::Radiosity`](super::PhaseMethod::Radiosity)).

use super::measure::RAY_OFFSET_REL;
use crate::geom::{Aabb, DVec3};
use crate::pipeline;
use crate::refine::{ClassicBf, first_guess_max};
use crate::scene::{Material, Polygon, Scene};
use crate::visibility::RayCaster;

/// Shadow rays per polygon and direction of the radiosity method (a 3 × 3 stratified grid).
pub const DIRECT_SAMPLES_PER_SIDE: u32 = 3;

/// Escape albedo from a local hierarchical radiosity solve of the prototype (two-sided surfaces as
/// back-to-back pairs, transmittance dropped) under a unit directional irradiance along `w`. The
/// directional light is not an emitter of the solve: each polygon's direct irradiance `H₀` is
/// computed by shadow rays, the first reflection `ρ·H₀` is the solve's emission, and the solve adds
/// every further interreflection `H₁`; then albedo = 1 − Σ(1 − ρ)(H₀ + H₁)A / ΣH₀A.
pub(super) fn radiosity_albedo(flat: &Scene, bounds: &Aabb, w: DVec3, _a_eff: f64, eps: f64) -> [f64; 3] {
    let diag = bounds.diagonal().max(f64::MIN_POSITIVE);
    let mut scene = flat.clone();
    let n0 = scene.polygons.len();
    for i in 0..n0 {
        let p = scene.polygons[i].clone();
        if scene.materials[p.material as usize].two_sided {
            scene.polygons.push(Polygon { poly: p.poly.reversed(), ..p });
        }
    }
    let caster = RayCaster::new(&scene);
    let k = DIRECT_SAMPLES_PER_SIDE;
    let mut materials = Vec::with_capacity(scene.polygons.len());
    let mut direct = Vec::with_capacity(scene.polygons.len());
    for (i, p) in scene.polygons.iter().enumerate() {
        let n = p.poly.normal();
        let cos = n.dot(w);
        let mut h0 = 0.0;
        if cos > 0.0 {
            let mut clear = 0u32;
            for s in 0..k * k {
                let x = p.poly.sample((f64::from(s % k) + 0.5) / f64::from(k), (f64::from(s / k) + 0.5) / f64::from(k))
                    + n * (RAY_OFFSET_REL * diag);
                if caster.segment_clear(x, x + w * (2.0 * diag), i as u32, u32::MAX) {
                    clear += 1;
                }
            }
            h0 = cos * f64::from(clear) / f64::from(k * k);
        }
        let m = &scene.materials[p.material as usize];
        let mut mat = Material::diffuse(&format!("p{i}"), m.reflectance);
        mat.emission = m.reflectance.map(|r| r * h0);
        materials.push(mat);
        direct.push(h0);
    }
    for (i, p) in scene.polygons.iter_mut().enumerate() {
        p.material = i as u32;
    }
    scene.materials = materials;
    let intercepted: f64 = scene.polygons.iter().zip(&direct).map(|(p, h)| h * p.poly.area()).sum();
    if intercepted.is_nan() || intercepted <= 0.0 {
        return [0.0; 3];
    }
    let oracle = ClassicBf { eps, b_ref: first_guess_max(&scene) };
    let config = pipeline::Config {
        estimate_error: false,
        detect_closure: false,
        levels: 1,
        max_passes: 3,
        measure_variation: false,
        ..pipeline::Config::default()
    };
    let solved = pipeline::run(&scene, &oracle, &config, &|_| {});
    let h = &solved.hierarchy;
    let mut absorbed = [0.0; 3];
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let Some(p) = e.polygon() else { continue };
        let rho = h.reflectance[p as usize];
        let irr = solved.solution.irradiance[leaf as usize];
        for ch in 0..3 {
            absorbed[ch] += (1.0 - rho[ch]) * (irr[ch] + direct[p as usize]) * e.area;
        }
    }
    absorbed.map(|x| (1.0 - x / intercepted).clamp(0.0, 1.0))
}
