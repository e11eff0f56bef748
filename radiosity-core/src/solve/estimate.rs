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

/// Factor on the estimate: the extrapolation was measured (`radiosity bench accuracy`, 2026-12-01)
/// to fall short of the true error by up to 2.5× on the validation scenes (a mesh coarsened by
/// merging its deepest pieces does not grow uniformly coarser, so the observed order is rough), and
/// the estimate must not be below it. The price: on most rows it is 2–9 times the true error.
pub const ESTIMATE_SAFETY: f64 = 2.6;
/// Smallest estimate reported: form factors are computed to about 1e-5, and so are polygon means
/// at best.
pub const ESTIMATE_FLOOR: f64 = 1e-5;

/// Factor on the last refinement level's change of the polygon means that the error estimate
/// under a target error is at least ([`LevelHistory`], `pipeline`'s levels), polygon by polygon
/// and for the largest. Finer links change what coarsening the mesh under the same links cannot
/// show: a link takes its source's radiosity as uniform and its visibility as one fraction over
/// its receiver. On interiors lit by many small lamps among furniture the mesh's estimate fell
/// below the true error (the generated classroom at a 10% target: 6.4% for 9.7%; RenderPark's
/// cube at 0.3%: 0.19% for 0.22–0.51% against two finer solves), while the last level's change
/// showed it. Measured at the default target (`radiosity bench accuracy`, `bench renderpark`,
/// 2026-12-06), the true error was 0.61 to 1.23 times the last change (Ward's room 0.89, the
/// corner rooms 0.61–1.23, the cube 1.05): 1.5 keeps a fifth above the largest.
pub const LEVEL_CHANGE_SAFETY: f64 = 1.5;

/// The polygon means of successive refinement levels, and how much each level changed them.
#[derive(Clone, Debug, Default)]
pub struct LevelHistory {
    /// Which polygons emit (left out of the measure).
    emitting: Vec<bool>,
    /// The last level's polygon means.
    last: Option<Vec<[f64; 3]>>,
    /// The changes between consecutive levels.
    changes: Vec<f64>,
    /// Each polygon's change over the last level (largest channel, absolute; empty before the
    /// second level).
    polygon_changes: Vec<f64>,
    /// Which polygons the level being refined now refines further (empty: all), see
    /// [`LevelHistory::refining`].
    refined: Vec<bool>,
    /// Each polygon's change the floor reads: its own over the last level it was refined at, or
    /// what its sources changed it by since, whichever is larger.
    floor_changes: Vec<f64>,
    /// The largest of `floor_changes` over the measured polygons, relative to the largest
    /// non-emitting mean.
    floor_change: Option<f64>,
}

impl LevelHistory {
    /// A history for a scene whose polygons emit where `emitting` says. When every polygon emits (a
    /// furnace), every polygon is measured.
    #[must_use]
    pub fn new(mut emitting: Vec<bool>) -> LevelHistory {
        if emitting.iter().all(|&e| e) {
            emitting.fill(false);
        }
        LevelHistory { emitting, ..LevelHistory::default() }
    }

    /// Says which polygons the next level refines further for their own error (local levels,
    /// `pipeline`'s `Config::local_levels`): any other keeps the largest change it showed since
    /// the last level that did as its floor ([`LevelHistory::floor_by_change`]), for a level that
    /// does not refine its links cannot show what they miss.
    pub fn refining(&mut self, refined: Vec<bool>) {
        self.refined = refined;
    }

    /// Records a level's polygon means; returns the change since the level before (relative to the
    /// largest non-emitting mean), `None` for the first.
    pub fn push(&mut self, means: Vec<[f64; 3]>) -> Option<f64> {
        let change = self.last.as_ref().map(|last| {
            self.polygon_changes = means.iter().zip(last).map(|(m, l)| (0..3).map(|c| (m[c] - l[c]).abs()).fold(0.0, f64::max)).collect();
            let held = std::mem::take(&mut self.floor_changes);
            let refined = std::mem::take(&mut self.refined);
            self.floor_changes = (self.polygon_changes.iter().enumerate())
                .map(|(p, &d)| if refined.get(p).is_none_or(|&r| r) { d } else { d.max(held.get(p).copied().unwrap_or(0.0)) })
                .collect();
            let lit = || (0..means.len()).filter(|&p| !self.emitting[p]);
            let top = lit().flat_map(|p| means[p]).fold(0.0, f64::max);
            let relative = |changes: &[f64]| if top > 0.0 { lit().map(|p| changes[p]).fold(0.0, f64::max) / top } else { 0.0 };
            self.floor_change = Some(relative(&self.floor_changes));
            relative(&self.polygon_changes)
        });
        if let Some(d) = change {
            self.changes.push(d);
        }
        self.last = Some(means);
        change
    }

    /// An error estimate under a target error raised to [`LEVEL_CHANGE_SAFETY`] times the last
    /// level's change: the whole (`estimate`, relative) by the largest change, each polygon's
    /// (`per_polygon`, W/m²) by its own. A polygon the last level did not refine
    /// ([`LevelHistory::refining`]) keeps the change of the last level that did as its floor.
    /// Unchanged before the second level.
    #[must_use]
    pub fn floor_by_change(&self, estimate: f64, per_polygon: Vec<f64>) -> (f64, Vec<f64>) {
        let Some(change) = self.floor_change else { return (estimate, per_polygon) };
        let per_polygon = per_polygon
            .into_iter()
            .enumerate()
            .map(|(p, e)| e.max(LEVEL_CHANGE_SAFETY * self.floor_changes.get(p).copied().unwrap_or(0.0)))
            .collect();
        (estimate.max(LEVEL_CHANGE_SAFETY * change), per_polygon)
    }

    /// Each polygon's change over the last level, largest channel, absolute (W/m²); empty until
    /// two levels are recorded.
    #[must_use]
    pub fn polygon_changes(&self) -> &[f64] {
        &self.polygon_changes
    }

    /// The changes between consecutive levels so far.
    #[must_use]
    pub fn changes(&self) -> &[f64] {
        &self.changes
    }
}

/// Smallest convergence order the Richardson estimate assumes.
pub const ORDER_MIN: f64 = 0.5;
/// Largest convergence order the Richardson estimate assumes.
pub const ORDER_MAX: f64 = 2.0;

/// The most the estimate takes of a polygon's change `|d₁|`, [`ESTIMATE_SAFETY`] included. Where
/// the order is low or not regular yet ([`ORDER_MIN`], `1/(2^0.5 − 1)` = 2.41) the safety factor
/// would make it 6.3: the lowest order and the margin for a misjudged one, both at once. On the
/// validation scenes at eps 0.64 to 0.000625 (`examples/estimate_orders.rs`, 2026-12-04) the
/// polygon with the largest true error had at most 3.05 times its change `|d₁|` (corner room, ρ
/// 0.95, eps 0.64; where the mesh's error dominates: on CIE 5.8 visibility sampling's does, which
/// [`visibility_noise`] covers); 3.5 keeps 15% above it, and the whole estimate stayed at 1.08 or
/// more times the true error on every row. It makes the coarse levels' estimate 3 to 8 times the
/// true error instead of 4 to 14 (Ward's room: 10.4% and 8.7% for 2.8% and 2.4%), so that a coarse
/// target stops at a coarse level.
pub const CHANGE_FACTOR_MAX: f64 = 3.5;

/// The error of `fine` (polygon means), from the same solve on meshes two (`coarse`) and four
/// (`coarser`) times coarser. For each non-emitting polygon and channel, the changes
/// `d₁ = fine − coarse` and `d₂ = coarse − coarser` give the order `p = log₂(d₂ / d₁)` (within
/// [`ORDER_MIN`, `ORDER_MAX`]; [`ORDER_MIN`] when the changes differ in sign, the convergence not
/// yet regular) and the error still in `fine`, `|d₁| / (2^p − 1)` (at most
/// [`CHANGE_FACTOR_MAX`] / [`ESTIMATE_SAFETY`] times `|d₁|`). The largest, relative to the largest
/// non-emitting mean.
#[must_use]
pub fn richardson_estimate(emitting: &[bool], fine: &[[f64; 3]], coarse: &[[f64; 3]], coarser: &[[f64; 3]]) -> f64 {
    let all = emitting.iter().all(|&e| e);
    let (mut top, mut worst) = (0.0f64, 0.0f64);
    for (i, &e) in emitting.iter().enumerate() {
        if e && !all {
            continue;
        }
        for c in 0..3 {
            top = top.max(fine[i][c]);
            worst = worst.max(richardson_error(fine[i][c], coarse[i][c], coarser[i][c]));
        }
    }
    if top > 0.0 { worst / top } else { 0.0 }
}

/// The error still in one mean `fine` (see [`richardson_estimate`]).
fn richardson_error(fine: f64, coarse: f64, coarser: f64) -> f64 {
    let (d1, d2) = (fine - coarse, coarse - coarser);
    if d1 == 0.0 {
        return 0.0;
    }
    let order = if d2 / d1 > 1.0 { (d2 / d1).log2().clamp(ORDER_MIN, ORDER_MAX) } else { ORDER_MIN };
    d1.abs() * (1.0 / (order.exp2() - 1.0)).min(CHANGE_FACTOR_MAX / ESTIMATE_SAFETY)
}

/// Per polygon (largest channel, absolute), the error [`richardson_estimate`] finds in its mean,
/// and at least what the change between the two coarser meshes leaves at the fastest order
/// ([`ORDER_MAX`]): a polygon whose finest change vanishes by chance (a change of sign) still
/// counts the convergence its coarser change shows.
#[must_use]
pub fn richardson_per_polygon(fine: &[[f64; 3]], coarse: &[[f64; 3]], coarser: &[[f64; 3]]) -> Vec<f64> {
    let fastest = ORDER_MAX.exp2();
    (0..fine.len())
        .map(|i| {
            (0..3)
                .map(|c| {
                    let d2 = (coarse[i][c] - coarser[i][c]).abs();
                    richardson_error(fine[i][c], coarse[i][c], coarser[i][c]).max(d2 / (fastest * (fastest - 1.0)))
                })
                .fold(0.0, f64::max)
        })
        .collect()
}

/// How many standard deviations of visibility-sampling noise the estimate covers.
pub const NOISE_SIGMAS: f64 = 1.0;

/// The error that visibility sampling leaves in each polygon's mean radiosity, relative to the
/// largest non-emitting mean: a link whose segments ([`crate::refine::Link::rays`]) found it partly occluded has a
/// visibility of standard error `√(V (1 − V) / rays)`, which moves its receiver's irradiance by
/// `B_S F` times that; independent links add in quadrature over a polygon (each weighted by the
/// share of the polygon's area its receiver covers), and the reflectance turns irradiance into
/// radiosity. [`NOISE_SIGMAS`] standard deviations, largest over the non-emitting polygons.
/// With `irradiance` (the polygons' mean irradiance, under the irradiance criterion) the same
/// noise in each mean irradiance counts too (no reflectance turns it into radiosity: a black
/// receiver's is counted), relative to the largest non-emitting mean irradiance; the larger of
/// the two is returned.
#[must_use]
pub fn visibility_noise(
    h: &crate::hierarchy::Hierarchy,
    links: &[crate::refine::Link],
    radiosity: &[[f64; 3]],
    irradiance: Option<&[[f64; 3]]>,
) -> f64 {
    worst_noise(h, &noise_per_polygon(h, links, radiosity), radiosity, irradiance)
}

/// [`NOISE_SIGMAS`] standard deviations of each polygon's mean irradiance from visibility
/// sampling, per channel, in W/m² (what [`visibility_noise`] takes the largest of).
#[must_use]
pub fn noise_per_polygon(h: &crate::hierarchy::Hierarchy, links: &[crate::refine::Link], radiosity: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let n = h.n_polygons as usize;
    let mut var = vec![[0.0; 3]; n];
    for l in links {
        if l.vis <= 0.0 || l.vis >= 1.0 {
            continue;
        }
        let sd = (l.vis * (1.0 - l.vis) / f64::from(l.rays.max(1))).sqrt() * l.ff;
        let b = radiosity[l.source as usize];
        receiver_polygons(h, l.receiver, |p, share| {
            for c in 0..3 {
                var[p][c] += (share * sd * b[c]).powi(2);
            }
        });
    }
    var.into_iter().map(|v| v.map(|x| NOISE_SIGMAS * x.sqrt())).collect()
}

/// [`visibility_noise`] from the polygons' noise ([`noise_per_polygon`]).
#[must_use]
pub fn worst_noise(h: &crate::hierarchy::Hierarchy, noise: &[[f64; 3]], radiosity: &[[f64; 3]], irradiance: Option<&[[f64; 3]]>) -> f64 {
    let of_radiosity = worst_relative(h, radiosity, |p, c| h.reflectance[p][c] * noise[p][c]);
    let of_irradiance = irradiance.map_or(0.0, |means| worst_relative(h, means, |p, c| noise[p][c]));
    of_radiosity.max(of_irradiance)
}

/// The error the closure of a closed scene may leave ([`super::LeafCoefficients::closure`]): it
/// scales each source's links so that they deliver its light whole, which corrects how much light
/// arrives in all but not where it lands (CIE 171 case 5.8 at eps 0.0025: links 5.5e-4 short,
/// 4.5e-5 off after the closure, in opposite signs on different walls). Each link's change,
/// `|factor − 1| F V B_S` at its receiver, is counted whole as a possible error of where it landed,
/// summed over each polygon (weighted by the share of its area the receiver covers); relative to
/// the largest non-emitting mean as [`visibility_noise`] is: the radiosity through the
/// reflectance and, with `irradiance`, the mean irradiance itself. 0 in an open scene (`changes`
/// empty); `changes` per link, as [`super::LeafCoefficients::closure_changes`] gives them.
#[must_use]
pub fn closure_error(
    h: &crate::hierarchy::Hierarchy,
    links: &[crate::refine::Link],
    changes: &[f32],
    radiosity: &[[f64; 3]],
    irradiance: Option<&[[f64; 3]]>,
) -> f64 {
    if changes.is_empty() {
        return 0.0;
    }
    let mut moved = vec![[0.0; 3]; h.n_polygons as usize];
    for (l, &change) in links.iter().zip(changes) {
        let m = f64::from(change).abs() * l.ff * l.vis;
        if m == 0.0 {
            continue;
        }
        let b = radiosity[l.source as usize];
        receiver_polygons(h, l.receiver, |p, share| {
            for c in 0..3 {
                moved[p][c] += share * m * b[c];
            }
        });
    }
    let of_radiosity = worst_relative(h, radiosity, |p, c| h.reflectance[p][c] * moved[p][c]);
    let of_irradiance = irradiance.map_or(0.0, |means| worst_relative(h, means, |p, c| moved[p][c]));
    of_radiosity.max(of_irradiance)
}

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

/// The error that polygons left whole put into the others' means, relative to the largest
/// non-emitting mean. A polygon that is a single element is the same on the coarser meshes of
/// [`richardson_estimate`], which then show nothing of it (Ward's room at `--eps 0.64`, every
/// polygon whole: a 7.6% error estimated at 0.001%), yet its radiosity is not uniform where its
/// irradiance is not. Its irradiance is taken from its chain of links at the centre and halfway
/// to each vertex ([`crate::formfactor::point_to_element`] times each link's visibility); half
/// its range, times the reflectance, is how far its radiosity departs from its mean, and each link
/// it sends passes that on to its receiver's mean with the link's form factor (the receiver's
/// share of its polygon's area; every polygon of a receiving cluster whole), times the
/// receiver's reflectance, and times half the spread `κ` of the kernel over the source seen
/// from the receiver ([`crate::refine::source_kernel_spread`]; whole for a link partly occluded,
/// whose kernel steps where the occluder's shadow ends): what departs from the mean reaches the
/// receiver only as far as the receiver weights the source unevenly (the covariance of radiosity
/// and kernel, each within its range, is at most the product of their half ranges), so that a
/// leaf's uneven light reaches the far ones of a canopy as a tenth of it. Per polygon and channel,
/// in W/m² of radiosity. A uniform field (a furnace) gives 0.
#[must_use]
pub fn unresolved_per_polygon(h: &crate::hierarchy::Hierarchy, links: &[crate::refine::Link], radiosity: &[[f64; 3]]) -> Vec<[f64; 3]> {
    use rayon::prelude::*;
    let n = h.n_polygons as usize;
    let by_receiver = super::by_receiver::LinksByReceiver::new(h, links);
    // Half the range of each whole polygon's radiosity, per channel (zero for subdivided ones).
    let spread: Vec<[f64; 3]> = (0..n)
        .into_par_iter()
        .map(|p| {
            let e = h.get(p as u32);
            let Some(poly) = e.poly().filter(|_| h.children_of(p as u32).is_empty()) else {
                return [0.0; 3];
            };
            let points = std::iter::once(e.center).chain(poly.vertices().iter().map(|&v| 0.5 * (v + e.center)));
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [0.0f64; 3]);
            for x in points {
                let mut irr = [0.0; 3];
                let mut a = p as u32;
                while a != crate::hierarchy::NONE {
                    for l in by_receiver.at(a) {
                        let f = crate::formfactor::point_to_element(h, x, e.normal, l.source).max(0.0) * l.vis;
                        let b = radiosity[l.source as usize];
                        for c in 0..3 {
                            irr[c] += f * b[c];
                        }
                    }
                    a = h.get(a).parent;
                }
                for c in 0..3 {
                    lo[c] = lo[c].min(irr[c]);
                    hi[c] = hi[c].max(irr[c]);
                }
            }
            std::array::from_fn(|c| 0.5 * h.reflectance[p][c] * (hi[c] - lo[c]).max(0.0))
        })
        .collect();
    // Each link from a whole polygon with its share of the spread (κ / 2, at most 1).
    let weights: Vec<f64> = links
        .par_iter()
        .map(|l| {
            let whole = h.get(l.source).polygon().is_some_and(|p| l.source == p && spread[p as usize] != [0.0; 3]);
            if !whole {
                0.0
            } else if l.vis < 1.0 {
                1.0
            } else {
                0.5 * crate::refine::source_kernel_spread(h, l.source, l.receiver)
            }
        })
        .collect();
    let mut err = vec![[0.0; 3]; n];
    for (l, &w) in links.iter().zip(&weights) {
        if w == 0.0 {
            continue;
        }
        let s = spread[l.source as usize];
        receiver_polygons(h, l.receiver, |q, share| {
            for c in 0..3 {
                err[q][c] += h.reflectance[q][c] * share * l.ff * l.vis * w * s[c];
            }
        });
    }
    err
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

    /// The change of each level, relative to the largest non-emitting mean, and each polygon's
    /// own over the last level (emitters' too: the estimate's per-polygon floor).
    #[test]
    fn level_history_changes_overall_and_per_polygon() {
        let mut history = LevelHistory::new(vec![false, true, false]);
        assert_eq!(history.push(vec![[1.0; 3], [100.0; 3], [4.0; 3]]), None);
        assert!(history.polygon_changes().is_empty());
        let change = history.push(vec![[1.5, 1.0, 1.0], [90.0; 3], [3.8, 4.0, 4.0]]).expect("a change");
        assert!((change - 0.5 / 4.0).abs() < 1e-12, "{change}");
        let per_polygon = history.polygon_changes();
        assert_eq!(per_polygon.len(), 3);
        for (got, want) in per_polygon.iter().zip([0.5, 10.0, 0.2]) {
            assert!((got - want).abs() < 1e-12, "{per_polygon:?}");
        }
        assert_eq!(history.changes().len(), 1);
    }

    /// A polygon a level leaves as it was keeps the change of the last level that refined it as
    /// its floor, unless what it changes by now is larger; a refined one takes its new change.
    #[test]
    fn level_history_holds_the_change_of_polygons_left_as_they_were() {
        let mut history = LevelHistory::new(vec![false, false, false]);
        history.push(vec![[10.0; 3], [4.0; 3], [2.0; 3]]);
        history.push(vec![[10.0; 3], [4.4; 3], [2.2; 3]]);
        history.refining(vec![true, false, false]);
        let change = history.push(vec![[10.1; 3], [4.41; 3], [2.5; 3]]).expect("a change");
        assert!((change - 0.3 / 10.1).abs() < 1e-9, "{change}");
        let (estimate, per_polygon) = history.floor_by_change(0.0, vec![0.0; 3]);
        for (got, want) in per_polygon.iter().zip([0.1, 0.4, 0.3]) {
            assert!((got - LEVEL_CHANGE_SAFETY * want).abs() < 1e-9, "{per_polygon:?}");
        }
        assert!((estimate - LEVEL_CHANGE_SAFETY * 0.4 / 10.1).abs() < 1e-9, "{estimate}");
        // The mask is for one level: the next refines every polygon again.
        history.push(vec![[10.1; 3], [4.42; 3], [2.5; 3]]);
        let (_, per_polygon) = history.floor_by_change(0.0, vec![0.0; 3]);
        assert!((per_polygon[1] - LEVEL_CHANGE_SAFETY * 0.01).abs() < 1e-9, "{per_polygon:?}");
    }

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
