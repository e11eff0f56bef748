//! Restarted GMRES (Saad & Schultz 1986) with Givens rotations, matrix-free. Written by hand: the
//! operator is a closure over the link hierarchy, and no maintained Rust crate offers a matrix-free
//! GMRES over plain slices.

use super::SolveConfig;

/// Outcome of [`gmres`].
#[derive(Clone, Debug)]
pub struct GmresResult {
    /// The solution.
    pub x: Vec<f64>,
    /// Operator applications.
    pub iterations: usize,
    /// Final relative residual (recomputed from the solution).
    pub residual: f64,
    /// Whether the tolerance was met.
    pub converged: bool,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Solves `A x = b` from `x0`, where `apply(x, y)` computes `y = A x`.
pub fn gmres(apply: &dyn Fn(&[f64], &mut [f64]), b: &[f64], x0: Vec<f64>, config: &SolveConfig) -> GmresResult {
    let n = b.len();
    let mut x = x0;
    x.resize(n, 0.0);
    let b_norm = norm(b);
    if n == 0 || b_norm == 0.0 {
        return GmresResult { x: vec![0.0; n], iterations: 0, residual: 0.0, converged: true };
    }
    let m = config.restart.max(1);
    let mut iterations = 0;
    let mut r = vec![0.0; n];
    let mut w = vec![0.0; n];
    loop {
        apply(&x, &mut r);
        iterations += 1;
        for i in 0..n {
            r[i] = b[i] - r[i];
        }
        let beta = norm(&r);
        let rel = beta / b_norm;
        if rel <= config.tolerance || iterations >= config.max_iterations || !rel.is_finite() {
            return GmresResult { x, iterations, residual: rel, converged: rel <= config.tolerance };
        }
        let mut v: Vec<Vec<f64>> = Vec::with_capacity(m + 1);
        v.push(r.iter().map(|ri| ri / beta).collect());
        let mut hess = vec![vec![0.0; m]; m + 1];
        let (mut cs, mut sn) = (vec![0.0; m], vec![0.0; m]);
        let mut g = vec![0.0; m + 1];
        g[0] = beta;
        let mut k_used = 0;
        for j in 0..m {
            apply(&v[j], &mut w);
            iterations += 1;
            // Modified Gram–Schmidt.
            for i in 0..=j {
                let hij = dot(&w, &v[i]);
                hess[i][j] = hij;
                for (wk, vk) in w.iter_mut().zip(&v[i]) {
                    *wk -= hij * vk;
                }
            }
            let h_next = norm(&w);
            hess[j + 1][j] = h_next;
            for i in 0..j {
                let t = cs[i] * hess[i][j] + sn[i] * hess[i + 1][j];
                hess[i + 1][j] = -sn[i] * hess[i][j] + cs[i] * hess[i + 1][j];
                hess[i][j] = t;
            }
            let denom = hess[j][j].hypot(hess[j + 1][j]);
            if denom == 0.0 {
                k_used = j;
                break;
            }
            cs[j] = hess[j][j] / denom;
            sn[j] = hess[j + 1][j] / denom;
            hess[j][j] = denom;
            hess[j + 1][j] = 0.0;
            g[j + 1] = -sn[j] * g[j];
            g[j] *= cs[j];
            k_used = j + 1;
            if h_next > 0.0 {
                v.push(w.iter().map(|wk| wk / h_next).collect());
            }
            if (g[j + 1].abs() / b_norm) <= 0.5 * config.tolerance || h_next == 0.0 || iterations >= config.max_iterations {
                break;
            }
        }
        // Back substitution for the Krylov coefficients.
        let mut yk = vec![0.0; k_used];
        for i in (0..k_used).rev() {
            let mut s = g[i];
            for l in i + 1..k_used {
                s -= hess[i][l] * yk[l];
            }
            yk[i] = s / hess[i][i];
        }
        for (i, yi) in yk.iter().enumerate() {
            for (xk, vk) in x.iter_mut().zip(&v[i]) {
                *xk += yi * vk;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_stiff_diagonal_plus_rank_one_system() {
        // A = I − ρ (1/n) 1 1ᵀ with ρ = 0.9999: x = b + ρ/(1−ρ) mean(b).
        let n = 50;
        let rho = 0.9999;
        let b: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
        let apply = |x: &[f64], y: &mut [f64]| {
            let mean = x.iter().sum::<f64>() / n as f64;
            for i in 0..n {
                y[i] = x[i] - rho * mean;
            }
        };
        let cfg = SolveConfig { tolerance: 1e-10, max_iterations: 100, restart: 20 };
        let res = gmres(&apply, &b, vec![0.0; n], &cfg);
        let mean_b = b.iter().sum::<f64>() / n as f64;
        for i in 0..n {
            let exact = b[i] + rho / (1.0 - rho) * mean_b;
            assert!((res.x[i] - exact).abs() < 1e-8 * exact, "{} vs {exact}", res.x[i]);
        }
        assert!(res.iterations < 10, "{} iterations", res.iterations);
    }
}
