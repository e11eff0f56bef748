//! The error estimate: how far each non-emitting polygon's mean radiosity still is from the exact
//! answer, relative to the largest non-emitting polygon mean (the quantity `stats.json` reports as
//! `error_estimate`, and the one the validation scenes measure exactly,
//! [`crate::validation::true_error`]).
//!
//! The solution is solved again, with the same links, on the mesh one and two levels coarser
//! ([`super::Cut::coarsened`]), and the three polygon means extrapolated (Richardson) with the order
//! their changes show ([`richardson_estimate`]). Visibility sampling adds noise that no mesh
//! change shows ([`visibility_noise`]); the larger of the two, times [`ESTIMATE_SAFETY`], plus
//! [`ESTIMATE_FLOOR`], is reported.
//!
//! The contract of this folder: every function here reads a solved hierarchy, its links and
//! polygon means, and returns an error, never changing the solution; the pipeline decides what to
//! solve again and when to stop. One kind of error per file:
//!
//! - `levels.rs`: how much each refinement level changed the polygon means ([`LevelHistory`]).
//! - `richardson.rs`: the mesh's error, extrapolated from the mesh one and two levels coarser.
//! - `noise.rs`: the noise visibility sampling leaves in the means.
//! - `closure.rs`: where the closure of a closed scene may have moved light.
//! - `unresolved.rs`: what polygons left whole put into the others' means.
//!
//! This file keeps the safety factor and floor, the polygons the estimate measures, the helpers
//! the kinds share, and [`mesh_and_direct_estimate`], which adds a polygon's own terms.

mod closure;
mod levels;
mod noise;
mod richardson;
mod unresolved;

pub use closure::closure_error;
pub use levels::{LEVEL_CHANGE_SAFETY, LevelHistory};
pub use noise::{NOISE_SIGMAS, noise_per_polygon, visibility_noise, worst_noise};
pub use richardson::{CHANGE_FACTOR_MAX, ORDER_MAX, ORDER_MIN, richardson_estimate, richardson_per_polygon};
pub use unresolved::unresolved_per_polygon;

use richardson::richardson_error;

/// Factor on the estimate: the extrapolation was measured (`radiosity bench accuracy`, 2026-12-01)
/// to fall short of the true error by up to 2.5× on the validation scenes (a mesh coarsened by
/// merging its deepest pieces does not grow uniformly coarser, so the observed order is rough), and
/// the estimate must not be below it. The price: on most rows it is 2–9 times the true error.
pub const ESTIMATE_SAFETY: f64 = 2.6;
/// Smallest estimate reported: form factors are computed to about 1e-5, and so are polygon means
/// at best.
pub const ESTIMATE_FLOOR: f64 = 1e-5;

/// Calls `add(polygon, share)` for every polygon a link's `receiver` covers: a surface's own with
/// its share of the polygon's area, every polygon of a cluster whole.
fn receiver_polygons(h: &crate::hierarchy::Hierarchy, receiver: crate::hierarchy::ElementId, mut add: impl FnMut(usize, f64)) {
    let r = h.get(receiver);
    match r.kind {
        crate::hierarchy::ElementKind::Surface { polygon, .. } => add(polygon as usize, r.area / h.get(polygon).area),
        crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } => {
            for &p in &h.cluster_polygons[poly_start as usize..poly_end as usize] {
                add(p as usize, 1.0);
            }
        }
    }
}

/// The largest `error(polygon, channel)` over the non-emitting polygons (every polygon in a
/// furnace, where all emit), relative to the largest non-emitting polygon mean of `radiosity`.
fn worst_relative(h: &crate::hierarchy::Hierarchy, radiosity: &[[f64; 3]], error: impl Fn(usize, usize) -> f64) -> f64 {
    let top = largest_non_emitting_mean(h, radiosity);
    let worst = measured_polygons(h).flat_map(|p| (0..3).map(move |c| (p, c))).map(|(p, c)| error(p, c)).fold(0.0, f64::max);
    if top > 0.0 { worst / top } else { 0.0 }
}

/// The polygons the estimate measures: the non-emitting ones (every polygon in a furnace, where
/// all emit).
pub(crate) fn measured_polygons(h: &crate::hierarchy::Hierarchy) -> impl Iterator<Item = usize> + '_ {
    let emits = |p: usize| h.emission[p].iter().any(|&x| x > 0.0);
    let all = (0..h.n_polygons as usize).all(emits);
    (0..h.n_polygons as usize).filter(move |&p| all || !emits(p))
}

/// The largest mean (every channel) of `radiosity` (per polygon, or per element with the polygons
/// first) over the polygons the estimate measures: what the error estimate is relative to.
#[must_use]
pub fn largest_non_emitting_mean(h: &crate::hierarchy::Hierarchy, radiosity: &[[f64; 3]]) -> f64 {
    measured_polygons(h).flat_map(|p| radiosity[p]).fold(0.0, f64::max)
}

/// The mesh's and the direct light's error in the polygons' means, each polygon's own terms added
/// before the largest is taken (a polygon's error is at most the sum of its own, and the largest
/// of each term may lie on a different polygon): per measured polygon and channel, the Richardson
/// error of its mean radiosity ([`richardson_estimate`], from `means`: fine, coarse, coarser),
/// plus what polygons left whole put into it (`unresolved`, [`unresolved_per_polygon`]), plus its
/// reflectance times its direct light's quadrature error (`direct`, per polygon and channel, or
/// empty), relative to the largest measured mean; and with `irradiance_means` (the same three for
/// the mean irradiance, direct light included) the Richardson error of the mean irradiance plus
/// the direct light's error, relative to the largest mean irradiance. The larger of the two.
#[must_use]
pub fn mesh_and_direct_estimate(
    h: &crate::hierarchy::Hierarchy,
    means: [&[[f64; 3]]; 3],
    irradiance_means: Option<[&[[f64; 3]]; 3]>,
    unresolved: &[[f64; 3]],
    direct: &[[f64; 3]],
) -> f64 {
    let direct_at = |p: usize, c: usize| direct.get(p).map_or(0.0, |d| d[c]);
    let relative = |m: [&[[f64; 3]]; 3], own: &dyn Fn(usize, usize) -> f64| {
        let (mut top, mut worst) = (0.0f64, 0.0f64);
        for p in measured_polygons(h) {
            for c in 0..3 {
                top = top.max(m[0][p][c]);
                worst = worst.max(richardson_error(m[0][p][c], m[1][p][c], m[2][p][c]) + own(p, c));
            }
        }
        if top > 0.0 { worst / top } else { 0.0 }
    };
    let of_radiosity = relative(means, &|p, c| unresolved.get(p).map_or(0.0, |u| u[c]) + h.reflectance[p][c] * direct_at(p, c));
    let of_irradiance = irradiance_means.map_or(0.0, |m| relative(m, &|p, c| direct_at(p, c)));
    of_radiosity.max(of_irradiance)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{DVec3, Poly};
    use crate::refine::Link;
    use crate::scene::{Material, Polygon, Scene};

    fn square(x0: f64, y0: f64, z: f64, side: f64, up: bool) -> Poly {
        let (a, b, c, d) =
            (DVec3::new(x0, y0, z), DVec3::new(x0 + side, y0, z), DVec3::new(x0 + side, y0 + side, z), DVec3::new(x0, y0 + side, z));
        if up { Poly::quad(a, b, c, d) } else { Poly::quad(a, d, c, b) }
    }

    fn hierarchy(polys: &[(Poly, u32)], materials: Vec<Material>) -> crate::hierarchy::Hierarchy {
        let scene = Scene {
            name: "t".into(),
            polygons: polys.iter().map(|&(poly, material)| Polygon { poly, material, group: 0 }).collect(),
            materials,
            groups: vec!["g".into()],
            camera: None,
            warnings: Default::default(),
            luminaires: Vec::new(),
            distant: Vec::new(),
            units: Default::default(),
        };
        crate::hierarchy::build(&scene, &crate::hierarchy::BuildConfig::default())
    }

    /// A polygon's error is at most the sum of its own terms: the largest Richardson error on one
    /// polygon and the largest direct-light error on another are not added.
    #[test]
    fn each_polygons_own_terms_are_added_before_the_largest_is_taken() {
        let grey = Material::diffuse("grey", [0.5; 3]);
        let h = hierarchy(&[(square(0.0, 0.0, 0.0, 1.0, true), 0), (square(2.0, 0.0, 0.0, 1.0, true), 0)], vec![grey]);
        // Polygon 0: changes 0.3 then 1.2 (order 2): 0.1 still in its mean of 10. Polygon 1: no
        // change, a direct-light error of 0.4 reflected at 0.5.
        let fine = [[10.0; 3], [8.0; 3]];
        let coarse = [[9.7; 3], [8.0; 3]];
        let coarser = [[8.5; 3], [8.0; 3]];
        let direct = [[0.0; 3], [0.4; 3]];
        let none = [[0.0; 3]; 2];
        let e = mesh_and_direct_estimate(&h, [&fine, &coarse, &coarser], None, &none, &direct);
        assert!((e - 0.02).abs() < 1e-12, "largest own sum 0.2 of the top mean 10: {e}");
        // With the irradiance means too: polygon 1's direct error of 0.4 against a top of 20.
        let h_fine = [[20.0; 3], [5.0; 3]];
        let e = mesh_and_direct_estimate(&h, [&fine, &coarse, &coarser], Some([&h_fine, &h_fine, &h_fine]), &none, &direct);
        assert!((e - 0.02).abs() < 1e-12, "the radiosity side's 0.02 is the larger: {e}");
    }

    /// What a whole polygon's uneven radiosity puts into a receiver's mean: the bound covers the
    /// exact covariance (quadrature over both polygons) for a receiver near it and one far away,
    /// and the far one's bound is a small part of the first-order bound `ρ F ΔB / 2`.
    #[test]
    fn a_whole_polygons_uneven_light_reaches_far_receivers_as_the_kernel_varies() {
        let lamp = Material { emission: [100.0; 3], ..Material::diffuse("lamp", [0.0; 3]) };
        let grey = Material::diffuse("grey", [0.5; 3]);
        // A small lamp over one corner of a unit floor; ceilings near and far above it.
        let polys = [
            (square(0.05, 0.05, 0.3, 0.1, false), 0),
            (square(0.0, 0.0, 0.0, 1.0, true), 1),
            (square(0.0, 0.0, 0.5, 1.0, false), 1),
            (square(-2.0, -2.0, 10.0, 5.0, false), 1),
        ];
        let h = hierarchy(&polys, vec![lamp, grey]);
        assert!(h.get(0).normal.z < 0.0 && h.get(1).normal.z > 0.0 && h.get(2).normal.z < 0.0);
        let (lamp_b, rho) = (100.0, 0.5);
        // The floor's radiosity at a point: the lamp's light there, reflected.
        let floor_b = |x: DVec3| rho * lamp_b * crate::formfactor::point_to_element(&h, x, DVec3::Z, 0);
        let n = 40;
        let grid = |p: &Poly| -> Vec<DVec3> {
            (0..n * n).map(|k| p.sample((f64::from(k % n) + 0.5) / f64::from(n), (f64::from(k / n) + 0.5) / f64::from(n))).collect()
        };
        let floor_points = grid(&polys[1].0);
        let floor_mean = floor_points.iter().map(|&y| floor_b(y)).sum::<f64>() / floor_points.len() as f64;
        // Links: lamp to floor; floor to each ceiling, with its form factor by quadrature.
        let kernel = |x: DVec3, nx: DVec3, y: DVec3, ny: DVec3| {
            let d = y - x;
            let r2 = d.length_squared();
            (nx.dot(d).max(0.0) * (-ny.dot(d)).max(0.0)) / (std::f64::consts::PI * r2 * r2)
        };
        let mut links = vec![Link { source: 0, receiver: 1, ff: 0.0, vis: 1.0, rays: 0 }];
        let mut exact = Vec::new();
        for r in [2u32, 3] {
            let (rp, rn) = (polys[r as usize].0, h.get(r).normal);
            let (mut ff, mut err) = (0.0, 0.0);
            let receiver_points = grid(&rp);
            let floor_area = 1.0 / floor_points.len() as f64;
            for &x in &receiver_points {
                for &y in &floor_points {
                    let k = kernel(x, rn, y, DVec3::Z) * floor_area;
                    ff += k;
                    err += k * (floor_b(y) - floor_mean);
                }
            }
            let m = receiver_points.len() as f64;
            links.push(Link { source: 1, receiver: r, ff: ff / m, vis: 1.0, rays: 0 });
            exact.push(rho * (err / m).abs());
        }
        let mut radiosity = vec![[0.0; 3]; h.len()];
        radiosity[0] = [lamp_b; 3];
        radiosity[1] = [floor_mean; 3];
        let bound = unresolved_per_polygon(&h, &links, &radiosity);
        // The first-order bound: ρ_R F times half the floor's range as the estimate samples it.
        let spread = {
            let e = h.get(1);
            let pts: Vec<DVec3> = std::iter::once(e.center).chain(polys[1].0.vertices().iter().map(|&v| 0.5 * (v + e.center))).collect();
            let vals: Vec<f64> = pts.iter().map(|&x| floor_b(x)).collect();
            0.5 * (vals.iter().copied().fold(f64::MIN, f64::max) - vals.iter().copied().fold(f64::MAX, f64::min))
        };
        for (k, r) in [2usize, 3].into_iter().enumerate() {
            let b = bound[r][0];
            assert!(b >= exact[k], "receiver {r}: bound {b:.4e} below the exact {:.4e}", exact[k]);
            let first_order = rho * links[k + 1].ff * spread;
            assert!(b <= first_order * (1.0 + 1e-12), "receiver {r}: {b:.4e} over the first-order {first_order:.4e}");
            if r == 3 {
                assert!(b < 0.25 * first_order, "the far receiver's bound {b:.4e} is a small part of {first_order:.4e}");
            }
        }
    }
}
