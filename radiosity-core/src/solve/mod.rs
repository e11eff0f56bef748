//! Step 4, `solve`: radiosity on the link hierarchy. One application of the hierarchical operator is
//! pull (area-weighted radiosity up the tree), gather (along links, in parallel over receivers) and
//! push (irradiance down to the leaves); the linear system `(I − ρ·K) B = E` on the leaves is solved
//! matrix-free by restarted GMRES, which handles stiff scenes (ρ near 1) in a few dozen products
//! instead of the O(1/(1−ρ)) sweeps of Jacobi iteration.

mod by_receiver;
mod cut;
mod direct;
mod estimate;
mod final_gather;
mod gmres;
mod leaf;
mod operator;
mod polygon;
mod ranges;

pub use cut::Cut;
pub use direct::{direct_irradiance, direct_lower_bound, emitter_exchange};
pub(crate) use estimate::measured_polygons;
pub use estimate::{
    CHANGE_FACTOR_MAX, ESTIMATE_FLOOR, ESTIMATE_SAFETY, LEVEL_CHANGE_SAFETY, LevelHistory, NOISE_SIGMAS, ORDER_MAX, ORDER_MIN,
    closure_error, largest_non_emitting_mean, mesh_and_direct_estimate, noise_per_polygon, richardson_estimate, richardson_per_polygon,
    unresolved_per_polygon, visibility_noise, worst_noise,
};
pub use final_gather::{area_means, final_gather, top_down};
pub use gmres::{GmresResult, gmres};
pub use leaf::{
    ChainReuse, HALF_MIN_TARGET, HALF_ROUNDING, LEAF_OPERATOR_MAX_BYTES, LeafCoefficients, LeafOperator, Precision, leaf_operator_entries,
};
pub use operator::Operator;
pub use polygon::{PolygonResult, polygon_results};
pub use ranges::{VALUE_SERIES_FACTOR, element_data, leaf_value_errors};

use crate::hierarchy::Hierarchy;
use crate::refine::Link;

/// Solver settings.
#[derive(Clone, Copy, Debug)]
pub struct SolveConfig {
    /// Stop when the residual norm falls below `tolerance` times the norm of the emission.
    pub tolerance: f64,
    /// Most operator applications.
    pub max_iterations: usize,
    /// GMRES restart length.
    pub restart: usize,
}

impl Default for SolveConfig {
    fn default() -> Self {
        SolveConfig { tolerance: 1e-9, max_iterations: 2000, restart: 40 }
    }
}

/// A solved system.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Radiosity per element (W/m²): leaves solved, inner elements area-weighted.
    pub radiosity: Vec<[f64; 3]>,
    /// Irradiance per element (W/m²) from all links at the element and its ancestors (front side).
    pub irradiance: Vec<[f64; 3]>,
    /// Operator applications used.
    pub iterations: usize,
    /// Final relative residual `‖E − (I − M)B‖ / ‖E‖`.
    pub residual: f64,
    /// Whether the tolerance was reached.
    pub converged: bool,
}

/// Solves for the radiosity, starting from `initial` (per element; leaves are read).
#[must_use]
pub fn solve(h: &Hierarchy, links: &[Link], initial: &[[f64; 3]], config: &SolveConfig) -> Solution {
    let op = Operator::new(h, links);
    let rhs = op.emission();
    let x0 = op.leaves_from_elements(initial);
    let result = gmres(&|x: &[f64], y: &mut [f64]| op.apply_system(x, y), &rhs, x0, config);
    let (radiosity, irradiance) = op.expand(&result.x);
    Solution { radiosity, irradiance, iterations: result.iterations, residual: result.residual, converged: result.converged }
}

/// Solves the leaf-resolution system of `op` ([`LeafOperator`]) starting from `initial` (per
/// element, usually the hierarchical solution).
#[must_use]
pub fn solve_leaf_operator(op: &LeafOperator<'_>, initial: &[[f64; 3]], config: &SolveConfig) -> Solution {
    let rhs = op.cut().emission();
    let x0 = op.cut().from_elements(initial);
    let result = gmres(&|x: &[f64], y: &mut [f64]| op.apply_system(x, y), &rhs, x0, config);
    let (radiosity, irradiance) = op.expand(&result.x);
    Solution { radiosity, irradiance, iterations: result.iterations, residual: result.residual, converged: result.converged }
}
