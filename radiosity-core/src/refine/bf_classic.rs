//! The classic BF criterion of Hanrahan, Salzman & Aupperle (1991), relative to one radiosity for
//! the whole scene: link when `B_S · F_max ≤ eps · B_ref`. The instanced solver's local problems
//! are tuned to it (their thresholds are rescaled to stay relative to the whole scene's brightest
//! emission, and its brightness classes, proxies and level cache follow from that), so it keeps it;
//! every other solve uses the BF oracle ([`super::BfHand`], [`crate::oracle::bf`]), whose
//! thresholds are relative to each receiver's own irradiance.

use super::{Decision, LinkCtx, Oracle};
use crate::scene::Scene;

/// The classic BF oracle: `B_S · F_max` against `eps · b_ref`.
#[derive(Clone, Copy, Debug)]
pub struct ClassicBf {
    /// Threshold, relative to `b_ref`.
    pub eps: f64,
    /// The radiosity thresholds are relative to: [`first_guess_max`] of the scene solved.
    pub b_ref: f64,
}

impl Oracle for ClassicBf {
    fn name(&self) -> &str {
        "bf-classic"
    }

    fn decide(&self, ctx: &mut LinkCtx<'_>) -> Decision {
        if !ctx.facing() {
            return Decision::Stop;
        }
        let f = ctx.form_factor_max();
        let b = ctx.emitter_radiosity();
        // The cluster estimate is conservative (distance shortened by the bounding radii, full
        // projected area), so a link it accepts carries at most eps·B_ref whatever the clusters'
        // distance.
        if b * f <= self.eps * self.b_ref {
            return Decision::Link;
        }
        super::bf_hand::split(ctx)
    }
}

/// The brightest first guess of a polygon's radiosity in `scene`: its emission plus its reflectance
/// times the closed-scene ambient irradiance `Φ / (A (1 − ρ̄))` (per channel, largest).
#[must_use]
pub fn first_guess_max(scene: &Scene) -> f64 {
    let mut power = [0.0; 3];
    let mut area = 0.0;
    let mut rho_area = [0.0; 3];
    for p in &scene.polygons {
        let m = &scene.materials[p.material as usize];
        let a = p.poly.area();
        area += a;
        for c in 0..3 {
            power[c] += a * m.emission[c];
            rho_area[c] += a * m.reflectance[c];
        }
    }
    let ambient: [f64; 3] = std::array::from_fn(|c| if area > 0.0 { power[c] / area / (1.0 - rho_area[c] / area).max(1e-3) } else { 0.0 });
    scene
        .polygons
        .iter()
        .flat_map(|p| {
            let m = &scene.materials[p.material as usize];
            (0..3).map(move |c| m.emission[c] + m.reflectance[c] * ambient[c])
        })
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE)
}
