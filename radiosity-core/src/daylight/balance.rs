//! The power balance of a daylight solve: what the distant sources bring, what leaves the scene,
//! what is lost at open backs, and how far the balance is from closing.

use super::{DistantLight, DistantSource, FAR_REL, Site, any_perpendicular, escape_cells, open_backs};
use crate::geom::DVec3;
use crate::hierarchy::NONE;
use crate::visibility::RayCaster;

/// Power (per channel) that the distant sources deliver to the surfaces: `Σ A·E_direct` over the
/// leaves. Equal to what they bring in when nothing else lights the scene directly (no
/// luminaires: a scene file refuses both).
#[must_use]
pub fn power_incident(h: &crate::hierarchy::Hierarchy) -> [f64; 3] {
    let mut sum = [0.0; 3];
    if h.direct.is_empty() {
        return sum;
    }
    for leaf in h.leaves() {
        let e = h.get(leaf);
        if e.polygon().is_some() {
            for c in 0..3 {
                sum[c] += e.area * h.direct[leaf as usize][c];
            }
        }
    }
    sum
}

/// Where the light leaving the surfaces goes besides the links, per channel (W): out of the scene,
/// or onto an open back (see [`open_backs`]: blocked there, and lost), with that loss per polygon.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Leaving {
    /// Leaving the scene.
    pub escaped: [f64; 3],
    /// Landing on the back of a one-sided face.
    pub onto_backs: [f64; 3],
    /// [`Leaving::onto_backs`] per polygon whose back it lands on, summed over channels (empty
    /// when nothing lands on a back).
    pub onto_backs_by_polygon: Vec<f64>,
}

/// Where each leaf's escape cells go ([`power_leaving`]), kept from one call to the next: it is
/// geometry only (the leaf, and the scene the rays are cast into), so a leaf traced once is not
/// traced again while it stays a leaf. A level of a canopy's solve measures its power balance
/// with 145 rays from every leaf, most of them the level before's (the 3,200-leaf canopy of `bench
/// canopy` spent 4.7 of its 64 s there).
#[derive(Clone, Debug, Default)]
pub struct Escapes {
    /// Per element id (ids beyond it are traced and not kept).
    leaf: Vec<std::sync::OnceLock<LeafEscape>>,
}

/// One leaf's escape cells: the cosine-weighted share that hits nothing, and the shares landing
/// on each open back.
#[derive(Clone, Debug)]
struct LeafEscape {
    out: f64,
    backs: Box<[(u32, f64)]>,
}

impl Escapes {
    /// Room for the leaves of a hierarchy of `n` elements.
    pub fn cover(&mut self, n: usize) {
        if self.leaf.len() < n {
            self.leaf.resize_with(n, std::sync::OnceLock::new);
        }
    }

    /// How many leaves are traced and kept.
    #[cfg(test)]
    pub(super) fn traced(&self) -> usize {
        self.leaf.iter().filter(|c| c.get().is_some()).count()
    }
}

/// Power (per channel) that leaves the scene: every surface leaf's `B·A` times the cosine-weighted
/// share of the [`ESCAPE_CELLS`](super::ESCAPE_CELLS) cells of its hemisphere whose central ray hits nothing, the cells
/// shared out over the leaf's quadrature points in turn; and the power those cells' rays carry onto an open back (the closest
/// hit's back, when `open_back` of its polygon, as [`open_backs`] gives it). Independent of the links, so that
/// `absorbed + escaped + lost = incident + emitted` checks the solve. Each leaf's cells are traced
/// once for `escapes` (see [`Escapes`]).
#[must_use]
pub fn power_leaving(
    h: &crate::hierarchy::Hierarchy,
    radiosity: &[[f64; 3]],
    caster: &RayCaster,
    open_back: &[bool],
    escapes: &Escapes,
) -> Leaving {
    use rayon::prelude::*;
    let cells = escape_cells();
    let diag = h.diagonal();
    let offset = crate::visibility::SHADOW_ORIGIN_OFFSET_REL * diag;
    let far = FAR_REL * diag;
    let any_open_back = open_back.iter().any(|&o| o);
    let leaves: Vec<u32> = h.leaves().filter(|&l| h.get(l).polygon().is_some()).collect();
    type PerLeaf = ([f64; 3], [f64; 3], Vec<(u32, f64)>);
    let per_leaf: Vec<PerLeaf> = leaves
        .par_iter()
        .map(|&leaf| {
            let e = h.get(leaf);
            let b = radiosity[leaf as usize];
            if b.iter().all(|&v| v <= 0.0) {
                return ([0.0; 3], [0.0; 3], Vec::new());
            }
            let (Some(poly), Some(polygon)) = (e.poly(), e.polygon()) else { return ([0.0; 3], [0.0; 3], Vec::new()) };
            let trace = || {
                let points: Vec<DVec3> =
                    crate::geom::quadrature::weighted_points(poly, crate::geom::quadrature::element_rule(poly)).map(|(x, _)| x).collect();
                let frame = Site::new(e.normal, any_perpendicular(e.normal)).unwrap_or_default();
                let (mut out, mut backs) = (0.0, Vec::new());
                for (k, (d, w)) in cells.iter().enumerate() {
                    let origin = points[k % points.len()] + offset * e.normal;
                    let dir = frame.world(*d);
                    if caster.segment_clear(origin, origin + dir * far, polygon, NONE) {
                        out += w;
                    } else if any_open_back
                        && let Some((_, q)) = caster.closest_hit_where(origin, dir, |q| q != polygon)
                        && open_back[q as usize]
                        && h.get(q).normal.dot(dir) > 0.0
                    {
                        backs.push((q, *w));
                    }
                }
                LeafEscape { out, backs: backs.into_boxed_slice() }
            };
            let traced;
            let escape = match escapes.leaf.get(leaf as usize) {
                Some(cell) => cell.get_or_init(trace),
                None => {
                    traced = trace();
                    &traced
                }
            };
            let scale = b.map(|v| v * e.area);
            let onto: f64 = escape.backs.iter().map(|(_, w)| w).sum();
            let total: f64 = scale.iter().sum();
            (scale.map(|v| v * escape.out), scale.map(|v| v * onto), escape.backs.iter().map(|&(q, w)| (q, w * total)).collect())
        })
        .collect();
    // Summed in leaf order: the same figure on every run.
    let mut leaving = Leaving::default();
    for (esc, onto, by) in per_leaf {
        for c in 0..3 {
            leaving.escaped[c] += esc[c];
            leaving.onto_backs[c] += onto[c];
        }
        for (q, v) in by {
            if leaving.onto_backs_by_polygon.is_empty() {
                leaving.onto_backs_by_polygon = vec![0.0; h.n_polygons as usize];
            }
            leaving.onto_backs_by_polygon[q as usize] += v;
        }
    }
    leaving
}

/// Power (per channel) that the distant sources deliver to open backs ([`open_backs`]; `Σ A·E`
/// over their leaves, a shadow ray per quadrature point and source from the back), blocked there
/// and lost; and that power per polygon, summed over channels (empty when none).
#[must_use]
pub fn power_incident_on_backs(
    h: &crate::hierarchy::Hierarchy,
    distant: &[DistantSource],
    caster: &RayCaster,
    open_back: &[bool],
) -> ([f64; 3], Vec<f64>) {
    use rayon::prelude::*;
    if distant.is_empty() || !open_back.iter().any(|&o| o) {
        return ([0.0; 3], Vec::new());
    }
    let light = DistantLight::new(distant, Some(caster), h.diagonal());
    let leaves: Vec<u32> = h
        .leaves()
        .filter(|&l| {
            let e = h.get(l);
            e.polygon().is_some_and(|p| open_back[p as usize]) && distant.iter().any(|s| s.on(-e.normal).iter().any(|&v| v > 0.0))
        })
        .collect();
    let per_leaf: Vec<(u32, [f64; 3])> = leaves
        .par_iter()
        .map(|&leaf| {
            let e = h.get(leaf);
            let (Some(poly), Some(polygon)) = (e.poly(), e.polygon()) else { return (0, [0.0; 3]) };
            (polygon, crate::geom::quadrature::element_mean3(poly, |x| light.at(x, -e.normal, polygon)).map(|v| v * e.area))
        })
        .collect();
    let (mut total, mut by) = ([0.0; 3], Vec::new());
    for (p, v) in per_leaf {
        if v.iter().all(|&x| x <= 0.0) {
            continue;
        }
        if by.is_empty() {
            by = vec![0.0; h.n_polygons as usize];
        }
        by[p as usize] += v.iter().sum::<f64>();
        for c in 0..3 {
            total[c] += v[c];
        }
    }
    (total, by)
}

/// The light of a daylight solve measured apart from the links, per channel (W): what the sun and
/// sky bring to either side of the surfaces, what leaves the scene, what lands on open backs
/// ([`open_backs`]: from the sources and from the surfaces), and that loss per polygon (summed
/// over channels; empty when none).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutsideLinks {
    /// Onto the surfaces from the distant sources, fronts and open backs.
    pub incident: [f64; 3],
    /// Out of the scene.
    pub escaped: [f64; 3],
    /// Onto open backs, blocked and lost.
    pub lost_at_backs: [f64; 3],
    /// [`OutsideLinks::lost_at_backs`] per polygon.
    pub lost_by_polygon: Vec<f64>,
}

/// [`OutsideLinks`] of a solution: [`power_incident`], [`power_incident_on_backs`] and
/// [`power_leaving`] together (its leaves traced once for `escapes`).
#[must_use]
pub fn outside_links(
    h: &crate::hierarchy::Hierarchy,
    distant: &[DistantSource],
    radiosity: &[[f64; 3]],
    caster: &RayCaster,
    escapes: &Escapes,
) -> OutsideLinks {
    let open_back = open_backs(h);
    let front = power_incident(h);
    let (on_backs, on_backs_by) = power_incident_on_backs(h, distant, caster, &open_back);
    let leaving = power_leaving(h, radiosity, caster, &open_back, escapes);
    let lost_by_polygon = match (on_backs_by.is_empty(), leaving.onto_backs_by_polygon.is_empty()) {
        (true, _) => leaving.onto_backs_by_polygon,
        (false, true) => on_backs_by,
        (false, false) => on_backs_by.iter().zip(&leaving.onto_backs_by_polygon).map(|(a, b)| a + b).collect(),
    };
    OutsideLinks {
        incident: std::array::from_fn(|c| front[c] + on_backs[c]),
        escaped: leaving.escaped,
        lost_at_backs: std::array::from_fn(|c| leaving.onto_backs[c] + on_backs[c]),
        lost_by_polygon,
    }
}

/// How far the power balance of a solve is from closing (see
/// [`crate::pipeline::LevelReport::balance_gap`]): `solution.irradiance` is what the links bring,
/// without the direct light. Light landing on the back of a one-sided face (from the sources or
/// the surfaces) counts as incident and lost, as in `stats.json`. The leaves are traced once for
/// `escapes` (see [`Escapes`]).
#[must_use]
pub fn balance_gap(
    h: &crate::hierarchy::Hierarchy,
    distant: &[DistantSource],
    solution: &crate::solve::Solution,
    caster: &RayCaster,
    escapes: &Escapes,
) -> f64 {
    let outside = outside_links(h, distant, &solution.radiosity, caster, escapes);
    let incident = outside.incident;
    let escaped: [f64; 3] = std::array::from_fn(|c| outside.escaped[c] + outside.lost_at_backs[c]);
    let (mut absorbed, mut emitted) = ([0.0; 3], [0.0; 3]);
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let Some(p) = e.polygon() else { continue };
        let p = p as usize;
        let direct = h.direct.get(leaf as usize).copied().unwrap_or_default();
        for c in 0..3 {
            absorbed[c] +=
                e.area * (1.0 - h.reflectance[p][c] - h.transmittance[p][c]) * (solution.irradiance[leaf as usize][c] + direct[c]);
            emitted[c] += e.area * h.emission[p][c];
        }
    }
    (0..3)
        .filter(|&c| incident[c] + emitted[c] > 0.0)
        .map(|c| ((absorbed[c] + escaped[c]) - (incident[c] + emitted[c])).abs() / (incident[c] + emitted[c]))
        .fold(0.0, f64::max)
}
