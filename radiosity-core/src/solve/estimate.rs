//! A-posteriori error estimate: at a deterministic sample of leaves, compare the irradiance the
//! leaf-resolution operator gathers (sources at the level of their links, radiosity averaged over
//! them) with a full-resolution gather (every leaf under each source, each with its own form
//! factor). The difference, times the leaf's reflectance, is the one-step residual of the solution
//! against the finer discretisation; the largest over the sample, relative to the largest leaf
//! radiosity, is reported. Visibility is the link's (the estimate measures discretisation, not
//! visibility sampling noise).

use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::{ElementId, Hierarchy, NONE};
use crate::refine::Link;
use rayon::prelude::*;

/// Most form factors the estimate may evaluate (it samples fewer leaves in larger scenes).
pub const ESTIMATE_BUDGET: usize = 2_000_000;
/// Most leaves sampled.
pub const ESTIMATE_MAX_SAMPLES: usize = 64;

/// The estimate for leaf radiosity/irradiance `radiosity`/`irradiance` (per element).
#[must_use]
pub fn error_estimate(h: &Hierarchy, links: &[Link], radiosity: &[[f64; 3]], irradiance: &[[f64; 3]]) -> f64 {
    let leaves: Vec<ElementId> = h.leaves().collect();
    if leaves.is_empty() {
        return 0.0;
    }
    let max_b = leaves.iter().flat_map(|&l| radiosity[l as usize]).fold(0.0f64, f64::max);
    if max_b <= 0.0 {
        return 0.0;
    }
    let samples = (ESTIMATE_BUDGET / leaves.len()).clamp(1, ESTIMATE_MAX_SAMPLES).min(leaves.len());
    let step = leaves.len() / samples;
    let by_receiver = super::leaf::LinksByReceiver::new(h, links);
    let picked: Vec<ElementId> = (0..samples).map(|k| leaves[k * step]).collect();
    picked
        .par_iter()
        .map(|&leaf| {
            let mut fine = [0.0; 3];
            let mut a = leaf;
            while a != NONE {
                for l in by_receiver.at(a) {
                    let mut stack = vec![l.source];
                    while let Some(e) = stack.pop() {
                        let kids = h.children_of(e);
                        if kids.is_empty() {
                            if e != leaf {
                                let f = formfactor::link_form_factor(h, e, leaf, FormFactorQuality::Precise) * l.vis;
                                let b = radiosity[e as usize];
                                for c in 0..3 {
                                    fine[c] += f * b[c];
                                }
                            }
                        } else {
                            stack.extend_from_slice(kids);
                        }
                    }
                }
                a = h.get(a).parent;
            }
            let rho = h.reflectance_of(leaf);
            let coarse = irradiance[leaf as usize];
            (0..3).map(|c| rho[c] * (fine[c] - coarse[c]).abs()).fold(0.0, f64::max)
        })
        .reduce(|| 0.0, f64::max)
        / max_b
}
