//! The visibility study: for the links of a BF solution whose areas projected along the link are
//! below a threshold, classify visibility with 4, 16 and 64 rays beside the reference classifier
//! ([`crate::oracle::tools::ReferenceVisibility`]) and count disagreements.

use crate::oracle::Tool;
use crate::oracle::tools::{RayVisibility, ReferenceClass, ReferenceVisibility, VisibilityClass};
use crate::pipeline::Solved;
use crate::refine::{LinkCtx, Services};
use crate::visibility::VisibilityConfig;
use rayon::prelude::*;

/// Ray counts of the classifiers compared with the reference.
pub const STUDY_RAYS: [u32; 3] = [4, 16, 64];

/// One threshold's results.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StudyRow {
    /// Projected-area threshold (scene units²).
    pub threshold: f64,
    /// Links below the threshold.
    pub links: u64,
    /// Fraction of those links each classifier ([`STUDY_RAYS`]) puts in another class than the
    /// reference (visible / invisible / partial; a `Probably*` answer counts as its class,
    /// `TooComplex` as partial).
    pub error_rate: [f64; 3],
}

fn class_of(c: VisibilityClass) -> ReferenceClass {
    match c {
        VisibilityClass::Visible | VisibilityClass::ProbablyVisible => ReferenceClass::Visible,
        VisibilityClass::Invisible | VisibilityClass::ProbablyInvisible => ReferenceClass::Invisible,
        VisibilityClass::Partial | VisibilityClass::ProbablyPartial | VisibilityClass::TooComplex => ReferenceClass::Partial,
    }
}

/// Runs the study on the links of `solved` (a solution computed with visibility) for each threshold.
#[must_use]
pub fn visibility_study(solved: &Solved, visibility: VisibilityConfig, thresholds: &[f64]) -> Vec<StudyRow> {
    let h = &solved.hierarchy;
    let data = crate::refine::ElementData::first_guess(h);
    let services = Services {
        hierarchy: h,
        caster: Some(&solved.caster),
        visibility,
        data: &data,
        threshold_scale: 1.0,
        shafts: None,
        criterion: crate::refine::Criterion::default(),
        reflected_rays: visibility.rays,
    };
    // Classify each link once; a fresh context per classifier so none reuses another's rays. Links
    // in parallel: each link's rays are seeded by the link, so the result does not depend on threads.
    let classified: Vec<(f64, ReferenceClass, [ReferenceClass; 3])> = solved
        .links
        .par_iter()
        .map(|l| {
            let mut ctx = LinkCtx::new(&services, l.source, l.receiver);
            let axis = ctx.axis();
            let reference = ReferenceVisibility.ask(&mut ctx);
            let answers = STUDY_RAYS.map(|n| class_of(RayVisibility(n).ask(&mut LinkCtx::new(&services, l.source, l.receiver))));
            (axis.projected_emitter.max(axis.projected_receiver), reference, answers)
        })
        .collect();
    thresholds
        .iter()
        .map(|&t| {
            let below: Vec<_> = classified
                .iter()
                // The test of the `ProjectedAreaBelow` tool.
                .filter(|(area, ..)| *area < t)
                .collect();
            let n = below.len() as u64;
            let error_rate = std::array::from_fn(|k| {
                let wrong = below.iter().filter(|(_, r, a)| a[k] != *r).count();
                if n == 0 { 0.0 } else { wrong as f64 / n as f64 }
            });
            StudyRow { threshold: t, links: n, error_rate }
        })
        .collect()
}
