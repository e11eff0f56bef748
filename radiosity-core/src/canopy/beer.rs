//! What canopy physics expects of a random canopy: Beer's law for a beam, a uniform sky and a sky
//! of distant sources, and the exponential integral `E₃` they need.

use super::G_SPHERICAL;
use crate::daylight::DistantSource;
use crate::geom::DVec3;

/// `exp(−G·LAI/cos θ)`: the fraction of a parallel beam at zenith angle `zenith` (radians) that
/// a random canopy of spherical leaf-angle distribution transmits, in the continuum limit.
#[must_use]
pub fn beam_transmittance(lai: f64, zenith: f64) -> f64 {
    (-G_SPHERICAL * lai / zenith.cos()).exp()
}

/// `(1 − G·a/(A·cos θ))^N`: the expected fraction transmitted by `n` leaves of area `leaf_area`
/// placed at random over ground area `ground_area`, away from the canopy's edge.
#[must_use]
pub fn finite_beam_transmittance(n: usize, leaf_area: f64, ground_area: f64, zenith: f64) -> f64 {
    let p = G_SPHERICAL * leaf_area / (ground_area * zenith.cos());
    (1.0 - p).powf(n as f64)
}

/// `2·E₃(G·LAI)`: the fraction of a uniform sky's light (continuous) that the canopy transmits.
#[must_use]
pub fn diffuse_transmittance(lai: f64) -> f64 {
    2.0 * expint_e3(G_SPHERICAL * lai)
}

/// `Σ_i w_i·exp(−G·LAI/μ_i)`: the fraction of a sky of distant sources (see
/// [`crate::daylight::sky`]; z up) that the canopy transmits, `w_i` each source's share of the
/// horizontal irradiance, `μ_i` the cosine of its zenith angle.
#[must_use]
pub fn sky_transmittance(sources: &[DistantSource], lai: f64) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for s in sources {
        let w = s.on(DVec3::Z)[0];
        let mu = -s.toward.z;
        if w > 0.0 && mu > 0.0 {
            num += w * (-G_SPHERICAL * lai / mu).exp();
            den += w;
        }
    }
    if den > 0.0 { num / den } else { 0.0 }
}

/// The exponential integral `E₃(x) = ∫₁^∞ e^(−xt)/t³ dt` for `x ≥ 0`, from `E₁` (its series for
/// `x ≤ 1`, its continued fraction beyond, both to double precision) by the recurrence
/// `E_(n+1)(x) = (e^(−x) − x·E_n(x))/n`. `E₃(0) = 1/2`.
#[must_use]
pub fn expint_e3(x: f64) -> f64 {
    if x <= 0.0 {
        return 0.5;
    }
    let e1 = if x <= 1.0 {
        // E₁(x) = −γ − ln x − Σ_{k≥1} (−x)^k / (k·k!)
        let mut sum = 0.0;
        let mut term = 1.0;
        for k in 1..60 {
            term *= -x / f64::from(k);
            let add = term / f64::from(k);
            sum += add;
            if add.abs() < 1e-17 * sum.abs().max(1e-300) {
                break;
            }
        }
        -0.577_215_664_901_532_9 - x.ln() - sum
    } else {
        // Modified Lentz on E₁(x) = e^(−x) · 1/(x + 1 − 1²/(x + 3 − 2²/(x + 5 − ...)))
        let tiny = 1e-300;
        let mut b = x + 1.0;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..200 {
            let a = -f64::from(i) * f64::from(i);
            b += 2.0;
            d = 1.0 / (a * d + b);
            c = b + a / c;
            let del = c * d;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        h * (-x).exp()
    };
    let e2 = (-x).exp() - x * e1;
    ((-x).exp() - x * e2) / 2.0
}
