//! The furnace: a closed box, every face its own polygon with the same emission E and reflectance ρ,
//! has the exact solution B = E / (1 − ρ) everywhere (`reference/analytic_radiosity_cases.md`).
//! The light leaving every face is uniform, so BF has nothing to refine: the faces stay whole, the
//! 30 links carry exact polygon-to-polygon form factors, and the answer is exact at every eps,
//! however stiff the scene (the classic criterion refined such a box to its smallest elements).

use radiosity::geom::DVec3;
use radiosity::scene::shapes::furnace_box;

use crate::support::solve;

/// Refinement threshold: small enough that the classic criterion subdivided every face several
/// levels.
const EPS: f64 = 0.1;
/// Smallest element: 1e-3 of the box's area.
const MIN_AREA_REL: f64 = 1e-3;

fn furnace(rho: f64, tol: f64) {
    let e = 1.0;
    let scene = furnace_box(DVec3::new(1.0, 1.3, 0.8), rho, e);
    let solved = solve(&scene, EPS, MIN_AREA_REL);
    let exact = e / (1.0 - rho);
    let h = &solved.hierarchy;
    let leaves: Vec<u32> = h.leaves().collect();
    assert_eq!(leaves.len(), 6, "uniform sources need no subdivision");
    assert_eq!(solved.links.len(), 30, "every face to every other face");
    let mut worst: f64 = 0.0;
    for &leaf in &leaves {
        for c in 0..3 {
            let b = solved.solution.radiosity[leaf as usize][c];
            assert!(b.is_finite(), "leaf {leaf}: B = {b}");
            worst = worst.max((b / exact - 1.0).abs());
        }
    }
    println!(
        "furnace rho = {rho}: {} leaves, {} links, {} iterations (residual {:.1e}), worst leaf error {:.2e}",
        leaves.len(),
        solved.links.len(),
        solved.iterations,
        solved.solution.residual,
        worst
    );
    assert!(solved.solution.converged, "solver did not converge");
    assert!(worst <= tol, "rho = {rho}: worst leaf off by {worst:.3e} (tolerance {tol})");
    // Bounded iterations: far fewer than the 1/(1−ρ) sweeps of Jacobi.
    assert!(solved.iterations < 400, "{} iterations", solved.iterations);
}

/// Worst leaf error allowed: the contour integral's form factors are exact to ~1e-11, amplified by
/// 1/(1 − ρ).
const FURNACE_REL_TOL: f64 = 1e-6;

#[test]
fn furnace_rho_0_5() {
    furnace(0.5, FURNACE_REL_TOL);
}

#[test]
fn furnace_rho_0_99() {
    furnace(0.99, FURNACE_REL_TOL);
}

#[test]
fn furnace_rho_0_999() {
    furnace(0.999, FURNACE_REL_TOL);
}
