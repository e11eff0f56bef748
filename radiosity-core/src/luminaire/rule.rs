//! One surface leaf's direct light by quadrature: its rule's points (and corners) with a shadow
//! ray per source, the sun's exact lit share, and where the rule may be wrong, its quarters.

use super::ParallelShadows;
use super::point::DirectLight;
use super::{CORNER_INSET, MAX_ANGULAR_SIZE};
use crate::geom::quadrature::element_rule;
use crate::geom::{DVec3, quadrature};

/// What lights one surface leaf, and how it faces: its polygon and normal, the luminaires, the
/// distant sources and, with visibility on, the sharp sources' exact shadows.
#[derive(Clone, Copy)]
pub(super) struct LeafSources<'a> {
    pub(super) normal: DVec3,
    pub(super) polygon: u32,
    pub(super) light: &'a DirectLight<'a>,
    pub(super) distant: &'a crate::daylight::DistantLight<'a>,
    pub(super) shadows: Option<&'a ParallelShadows<'a>>,
}

/// A surface leaf's direct irradiance and the error estimated in it: where its rule may be
/// inaccurate ([`rule_direct`]), the mean of the rule over its pieces quartered `depth` times
/// (at least once), the error its difference from the same quartered one fewer time; elsewhere
/// the rule's, with no error. The soft sources' light is `inherited` where given (its parent's,
/// seen the same all over it), and comes back where the leaf's pieces may take it
/// ([`Hierarchy::direct_soft`](crate::hierarchy::Hierarchy::direct_soft)).
pub(super) fn leaf_direct(poly: &crate::geom::Poly, at: &LeafSources<'_>, depth: u32, inherited: Option<[f64; 3]>) -> LeafDirect {
    let rule = rule_direct(poly, at, false, inherited);
    let (soft, edge) = (rule.soft_uniform.then_some(rule.soft), rule.edge);
    if !rule.crossed || depth == 0 {
        return LeafDirect { direct: rule.total(), error: [0.0; 3], soft, edge };
    }
    // The sky's cells cast soft shadows: the rule holds for them, and only the sharp sources are
    // sampled on the pieces.
    let coarse = if depth == 1 { rule.sharp } else { pieces_direct(poly, at, depth - 1) };
    let fine = pieces_direct(poly, at, depth);
    LeafDirect { direct: std::array::from_fn(|c| fine[c] + rule.soft[c]), error: std::array::from_fn(|c| fine[c] - coarse[c]), soft, edge }
}

/// The area mean of [`rule_direct`]'s sharp sources over the pieces of `poly` quartered `depth`
/// times.
fn pieces_direct(poly: &crate::geom::Poly, at: &LeafSources<'_>, depth: u32) -> [f64; 3] {
    if depth == 0 {
        return rule_direct(poly, at, true, None).sharp;
    }
    let (mut sum, mut area) = ([0.0; 3], 0.0);
    for piece in poly.subdivide() {
        let a = piece.area();
        let d = pieces_direct(&piece, at, depth - 1);
        for c in 0..3 {
            sum[c] += a * d[c];
        }
        area += a;
    }
    if area > 0.0 { sum.map(|v| v / area) } else { [0.0; 3] }
}

/// The direct irradiance of a surface element (polygon `polygon`, normal `normal`) by its
/// [`element_rule`] with a shadow ray per point and source, the sharp distant sources' (the sun's)
/// by their exact lit share where `shadows` are given ([`ParallelShadows`], with visibility on);
/// and whether the rule may be inaccurate: a shadow boundary of a luminaire crosses the element
/// (its points or corners disagree on the luminaire's visibility), or a luminaire that lights it
/// is nearer than [`MAX_ANGULAR_SIZE`] allows.
fn rule_direct(poly: &crate::geom::Poly, at: &LeafSources<'_>, sharp_only: bool, inherited_soft: Option<[f64; 3]>) -> RuleDirect {
    let LeafSources { normal, polygon, light, distant, shadows } = *at;
    let sources = distant.sources();
    // The sharp distant sources' light comes from their exact lit share where the shadows are
    // known ([`ParallelShadows`]), not from the points.
    let exact = |k: usize| shadows.is_some() && sources[k].sharp;
    let mut seen_luminaire = vec![[false; 2]; light.luminaires.len()];
    let mut brightest = vec![0.0f64; light.luminaires.len()];
    let sharp_on: Vec<bool> = sources.iter().map(|s| s.sharp && s.on(normal).iter().any(|&v| v > 0.0)).collect();
    // The soft sources traced here: none when only the sharp ones are asked for or the element
    // takes its parent's.
    let soft_traced = !sharp_only && inherited_soft.is_none();
    let soft_on: Vec<bool> = sources.iter().map(|s| soft_traced && !s.sharp && s.on(normal).iter().any(|&v| v > 0.0)).collect();
    let mut seen_distant = vec![[false; 2]; sources.len()];
    let (mut sharp, mut soft, mut wsum) = ([0.0; 3], [0.0; 3], 0.0);
    for (x, w) in quadrature::weighted_points(poly, element_rule(poly)) {
        wsum += w;
        for (k, seen) in seen_luminaire.iter_mut().enumerate() {
            let (v, occluded) = light.from_one(k, x, normal, polygon);
            if v > 0.0 || occluded {
                seen[usize::from(occluded)] = true;
            }
            brightest[k] = brightest[k].max(v);
            for s in &mut sharp {
                *s += w * v;
            }
        }
        for (k, seen) in seen_distant.iter_mut().enumerate() {
            if (!sources[k].sharp && !soft_traced) || exact(k) {
                continue;
            }
            let (v, occluded) = distant.from_one(k, x, normal, polygon);
            if sharp_on[k] || soft_on[k] {
                seen[usize::from(occluded)] = true;
            }
            let sum = if sources[k].sharp { &mut sharp } else { &mut soft };
            for c in 0..3 {
                sum[c] += w * v[c];
            }
        }
    }
    if wsum > 0.0 {
        sharp = sharp.map(|v| v / wsum);
        soft = soft.map(|v| v / wsum);
    }
    if let Some(shadows) = shadows {
        for (k, s) in sources.iter().enumerate().filter(|&(k, _)| sharp_on[k]) {
            let lit = shadows.lit_share(poly, normal, polygon, s.toward);
            let on = s.on(normal);
            for c in 0..3 {
                sharp[c] += on[c] * lit;
            }
            seen_distant[k] = [lit > 0.0, lit < 1.0];
        }
    }
    if let Some(inherited) = inherited_soft {
        soft = inherited;
    }
    // The corners too (a hair inside): an edge that passes between the rule's outermost points
    // and the element's side leaves every point on one side of it.
    let centre = poly.centroid();
    for &v in poly.vertices() {
        let x = centre + (v - centre) * (1.0 - CORNER_INSET);
        for (k, seen) in seen_luminaire.iter_mut().enumerate().filter(|(_, s)| !(s[0] && s[1])) {
            let (v, occluded) = light.from_one(k, x, normal, polygon);
            if v > 0.0 || occluded {
                seen[usize::from(occluded)] = true;
            }
        }
        for (k, seen) in seen_distant.iter_mut().enumerate().filter(|(k, s)| sharp_on[*k] && !exact(*k) && !(s[0] && s[1])) {
            seen[usize::from(distant.from_one(k, x, normal, polygon).1)] = true;
        }
    }
    // Whether the soft sources' visibility is the same all over the element (every point and
    // corner sees each of them, or none does): its pieces then get the same soft light, and take
    // it from it instead of tracing it again. The corners are traced for that only while the
    // points agree.
    let mut soft_uniform =
        inherited_soft.is_some() || (soft_traced && !seen_distant.iter().zip(sources).any(|(s, src)| !src.sharp && s[0] && s[1]));
    if soft_traced && soft_uniform {
        'corners: for &v in poly.vertices() {
            let x = centre + (v - centre) * (1.0 - CORNER_INSET);
            for (k, seen) in seen_distant.iter_mut().enumerate().filter(|(k, _)| soft_on[*k]) {
                seen[usize::from(distant.from_one(k, x, normal, polygon).1)] = true;
                if seen[0] && seen[1] {
                    soft_uniform = false;
                    break 'corners;
                }
            }
        }
    }
    // A luminaire nearer than the element's size allows (where the subdivision before refinement
    // stopped at its depth): the rule's accuracy is not assured either.
    let radius = poly.vertices().iter().map(|&v| (v - centre).length()).fold(0.0, f64::max);
    let near = light
        .luminaires
        .iter()
        .zip(&seen_luminaire)
        .any(|(lum, seen)| seen[0] && radius > MAX_ANGULAR_SIZE * (centre - lum.position).length());
    let crossed = near || seen_luminaire.iter().any(|s| s[0] && s[1]);
    let step = seen_luminaire.iter().zip(&brightest).filter(|(s, _)| s[0] && s[1]).map(|(_, v)| v).sum::<f64>();
    let mut edge = [step; 3];
    // A sharp distant source's shadow edge across the element steps its light; its lit share is
    // exact, and no quadrature misplaces the edge.
    for (k, s) in sources.iter().enumerate() {
        if sharp_on[k] && seen_distant[k][0] && seen_distant[k][1] {
            let on = s.on(normal);
            for c in 0..3 {
                edge[c] += on[c];
            }
        }
    }
    RuleDirect { sharp, soft, crossed, soft_uniform, edge }
}

/// What [`rule_direct`] finds on one element: the mean direct irradiance from the sources whose
/// shadows are sharp (luminaires, the sun) and from the others (the sky's cells), and whether the
/// rule may be inaccurate for the sharp ones.
struct RuleDirect {
    sharp: [f64; 3],
    soft: [f64; 3],
    crossed: bool,
    soft_uniform: bool,
    /// The step in direct irradiance across the shadow boundaries that cross the element: each
    /// crossing sharp distant source's unoccluded irradiance, each crossing luminaire's largest
    /// seen at a lit point.
    edge: [f64; 3],
}

/// A surface leaf's direct light ([`leaf_direct`]).
pub(super) struct LeafDirect {
    pub(super) direct: [f64; 3],
    pub(super) error: [f64; 3],
    pub(super) soft: Option<[f64; 3]>,
    pub(super) edge: [f64; 3],
}

impl RuleDirect {
    fn total(&self) -> [f64; 3] {
        std::array::from_fn(|c| self.sharp[c] + self.soft[c])
    }
}
