//! The power balance of an instanced solve under the sun and sky: `absorbed + escaped =
//! incident + emitted`, each side measured apart from the solver, so that the balance checks it.
//! Without distant sources [`DaylightBalance`] only passes polygons on.
//!
//! - **Incident**: what the distant sources deliver to the surfaces, from the sources alone. For
//!   each source, a stratified grid of [`INCIDENT_GRID`]² parallel rays, jittered, covers the
//!   scene's box as seen along the beam; each ray that meets a polygon (through the nested BVHs,
//!   [`InstanceCaster`]) carries `E` times its cell's area.
//! - **Escaped**: what leaves the surfaces for good, from the radiosity the solve streams out.
//!   For each finished polygon, [`ESCAPE_RAYS`] points over its leaves (by area; more on a polygon
//!   larger than [`ESCAPE_AREA_REL`] of the scene's diagonal squared, in proportion to its area,
//!   up to [`ESCAPE_MAX_RAYS`]) each send one cosine-distributed ray; those that meet nothing
//!   carry `B·A/N` of their leaf's radiosity out.
//!   Seeded by the polygon's flattened index: the same figure whatever order polygons arrive in.
//! - **Absorbed**: `A·(1 − ρ − t)·H` summed over the polygons (as `patches.csv` has it).
//! - **Lost at backs**: what lands on the back of a one-sided face (its material not two-sided),
//!   where the solve neither absorbs nor passes it on: the incident rays and the escape rays
//!   whose first hit is such a back carry it there (a black lamp housing one-sided under the sky,
//!   a ground seen from below). The balance counts it beside what is absorbed, and the solve
//!   names it.
//!
//! Both estimates are Monte Carlo: their noise, not the solve, sets how closely the balance can be
//! read (see `tests/instanced_daylight.rs` for what was measured).

use super::InstancingError;
use super::caster::InstanceCaster;
use super::model::InstancedScene;
use super::solver::{Leaf, PolygonInfo, RadiositySink};
use crate::daylight::DistantSource;
use crate::geom::{Aabb, Poly};
use rayon::prelude::*;

/// Rays per polygon for the escaped power.
pub const ESCAPE_RAYS: u32 = 16;
/// Area, relative to the scene's diagonal squared, above which a polygon gets more escape rays
/// (see the module docs). With 16 rays, a forest's ground (one polygon, most of the light that
/// leaves) had its escape fraction in steps of 1/16: the 9-tree forest's NIR balance read 0.979.
pub const ESCAPE_AREA_REL: f64 = 1.0 / 4096.0;
/// Most escape rays of one polygon.
pub const ESCAPE_MAX_RAYS: u32 = 4096;
/// Rays per side of each source's grid for the incident power.
pub const INCIDENT_GRID: u32 = 96;
/// Polygons gathered before their escape rays are traced in parallel.
const BATCH: usize = 4096;
/// Ray origins sit this far off the surface, relative to the scene's diagonal.
const OFFSET_REL: f64 = 1e-7;

/// Passes polygons on to `inner` and measures the balance's terms (see the module docs).
pub struct DaylightBalance<S> {
    inner: S,
    caster: Option<InstanceCaster>,
    sources: Vec<DistantSource>,
    bounds: Aabb,
    /// `1 − ρ − t` per material and channel.
    absorptance: Vec<[f64; 3]>,
    batch: Vec<Finished>,
    escaped: [f64; 3],
    absorbed: [f64; 3],
    emitted: [f64; 3],
    lost: [f64; 3],
    /// Emission per material.
    emission: Vec<[f64; 3]>,
}

/// A finished polygon awaiting its escape rays: its flattened index, its leaves with their
/// radiosity.
type Finished = (u64, Vec<(Poly, [f64; 3])>);

/// The terms of the balance, per channel (W).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct PowerBalance {
    /// Delivered to the surfaces by the sun and sky.
    pub incident: [f64; 3],
    /// Absorbed by the surfaces.
    pub absorbed: [f64; 3],
    /// Leaving the scene.
    pub escaped: [f64; 3],
    /// Emitted by the polygons.
    pub emitted: [f64; 3],
    /// Landing on the backs of one-sided faces, from the sources and from the surfaces, and lost
    /// there.
    pub lost_at_backs: [f64; 3],
}

impl PowerBalance {
    /// `(absorbed + escaped + lost at backs) / (incident + emitted)` of channel `c` (`None`
    /// when nothing comes in).
    #[must_use]
    pub fn ratio(&self, c: usize) -> Option<f64> {
        let inp = self.incident[c] + self.emitted[c];
        (inp > 0.0).then(|| (self.absorbed[c] + self.escaped[c] + self.lost_at_backs[c]) / inp)
    }
}

impl<S: RadiositySink> DaylightBalance<S> {
    /// Measures the balance of `scene` under `sources` while passing polygons on to `inner`.
    pub fn new(inner: S, scene: &InstancedScene, sources: &[DistantSource]) -> DaylightBalance<S> {
        // The nested BVHs only when there is something to trace.
        let caster = (!sources.is_empty()).then(|| InstanceCaster::new(scene));
        let bounds = scene.local_bounds().get(scene.root as usize).copied().unwrap_or(Aabb::EMPTY);
        DaylightBalance {
            inner,
            caster,
            sources: sources.to_vec(),
            bounds,
            absorptance: scene.materials.iter().map(|m| std::array::from_fn(|c| 1.0 - m.reflectance[c] - m.transmittance[c])).collect(),
            batch: Vec::new(),
            escaped: [0.0; 3],
            absorbed: [0.0; 3],
            emitted: [0.0; 3],
            lost: [0.0; 3],
            emission: scene.materials.iter().map(|m| m.emission).collect(),
        }
    }

    fn diagonal(&self) -> f64 {
        if self.bounds.is_empty() { 0.0 } else { (self.bounds.max - self.bounds.min).length() }
    }

    /// Traces the gathered polygons' escape rays; sums in arrival order.
    fn flush(&mut self) {
        let diag = self.diagonal();
        let (Some(caster), batch) = (&self.caster, &self.batch) else { return };
        let out: Vec<([f64; 3], [f64; 3])> = batch.par_iter().map(|(index, leaves)| escaped(caster, *index, leaves, diag)).collect();
        for (e, l) in out {
            for c in 0..3 {
                self.escaped[c] += e[c];
                self.lost[c] += l[c];
            }
        }
        self.batch.clear();
    }

    /// Finishes the escape rays, traces the incident power, and gives back the sink with the
    /// balance (`None` without distant sources).
    pub fn finish(mut self) -> (S, Option<PowerBalance>) {
        self.flush();
        let Some(caster) = &self.caster else { return (self.inner, None) };
        let (incident, lost) = incident(caster, &self.sources, &self.bounds);
        let lost_at_backs = std::array::from_fn(|c| self.lost[c] + lost[c]);
        (self.inner, Some(PowerBalance { incident, absorbed: self.absorbed, escaped: self.escaped, emitted: self.emitted, lost_at_backs }))
    }
}

/// The power leaving polygon `index` (leaves with their radiosity) for good, and what of it
/// lands on the backs of one-sided faces.
fn escaped(caster: &InstanceCaster, index: u64, leaves: &[(Poly, [f64; 3])], diag: f64) -> ([f64; 3], [f64; 3]) {
    let areas: Vec<f64> = leaves.iter().map(|(p, _)| p.area()).collect();
    let total: f64 = areas.iter().sum();
    if total.is_nan() || total <= 0.0 || leaves.iter().all(|(_, b)| b.iter().all(|&v| v <= 0.0)) {
        return ([0.0; 3], [0.0; 3]);
    }
    let mut rng = crate::visibility::Rng::for_link(0x0e5c_a9ed, (index >> 32) as u32, index as u32);
    let (offset, far) = (OFFSET_REL * diag.max(f64::MIN_POSITIVE), crate::daylight::FAR_REL * diag);
    let (mut out, mut lost) = ([0.0; 3], [0.0; 3]);
    let reference = ESCAPE_AREA_REL * diag * diag;
    let rays = if reference > 0.0 {
        (f64::from(ESCAPE_RAYS) * total / reference).ceil().clamp(f64::from(ESCAPE_RAYS), f64::from(ESCAPE_MAX_RAYS)) as u32
    } else {
        ESCAPE_RAYS
    };
    let step = total / f64::from(rays);
    let (mut k, mut cum) = (0usize, areas[0]);
    for j in 0..rays {
        // Stratified over the leaves by area.
        let target = (f64::from(j) + rng.next_f64()) * step;
        while target > cum && k + 1 < leaves.len() {
            k += 1;
            cum += areas[k];
        }
        let (poly, b) = &leaves[k];
        let n = poly.normal();
        let x = poly.sample(rng.next_f64(), rng.next_f64()) + n * offset;
        let (u1, u2) = (rng.next_f64(), rng.next_f64());
        let d = super::properties::cosine_dir_from(n, u1, u2);
        let to = match caster.first_hit(x, x + d * far) {
            None => &mut out,
            Some(true) => &mut lost,
            Some(false) => continue,
        };
        for c in 0..3 {
            to[c] += b[c] * step;
        }
    }
    (out, lost)
}

/// The power the sources deliver to the surfaces (see the module docs), and what of it lands on
/// the backs of one-sided faces.
fn incident(caster: &InstanceCaster, sources: &[DistantSource], bounds: &Aabb) -> ([f64; 3], [f64; 3]) {
    if bounds.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    let diag = (bounds.max - bounds.min).length();
    let centre = (bounds.min + bounds.max) * 0.5;
    let per_source: Vec<([f64; 3], [f64; 3])> = sources
        .par_iter()
        .enumerate()
        .map(|(k, s)| {
            let d = -s.toward.normalize();
            let (e1, e2) = super::properties::basis(d);
            let (mut u0, mut u1, mut v0, mut v1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
            for i in 0..8 {
                let c = super::model::corner(bounds, i) - centre;
                (u0, u1) = (u0.min(c.dot(e1)), u1.max(c.dot(e1)));
                (v0, v1) = (v0.min(c.dot(e2)), v1.max(c.dot(e2)));
            }
            let g = INCIDENT_GRID;
            let (du, dv) = ((u1 - u0) / f64::from(g), (v1 - v0) / f64::from(g));
            let mut rng = crate::visibility::Rng::for_link(0x01c1_de47, k as u32, g);
            let (mut hits, mut backs) = (0u64, 0u64);
            for i in 0..g {
                for j in 0..g {
                    let u = u0 + (f64::from(i) + rng.next_f64()) * du;
                    let v = v0 + (f64::from(j) + rng.next_f64()) * dv;
                    let p = centre + e1 * u + e2 * v;
                    if let Some(back) = caster.first_hit(p + d * diag, p - d * diag) {
                        hits += 1;
                        backs += u64::from(back);
                    }
                }
            }
            let cell = du * dv;
            (s.irradiance.map(|e| e * hits as f64 * cell), s.irradiance.map(|e| e * backs as f64 * cell))
        })
        .collect();
    per_source
        .iter()
        .fold(([0.0; 3], [0.0; 3]), |(a, l), (b, m)| (std::array::from_fn(|c| a[c] + b[c]), std::array::from_fn(|c| l[c] + m[c])))
}

impl<S: RadiositySink> RadiositySink for DaylightBalance<S> {
    fn polygon(&mut self, info: &PolygonInfo, leaves: &[Leaf]) -> Result<(), InstancingError> {
        if !self.sources.is_empty() {
            let alpha = self.absorptance.get(info.material as usize).copied().unwrap_or([0.0; 3]);
            let emission = self.emission.get(info.material as usize).copied().unwrap_or([0.0; 3]);
            for leaf in leaves {
                let a = leaf.poly.area();
                for c in 0..3 {
                    self.absorbed[c] += a * alpha[c] * leaf.h[c];
                    self.emitted[c] += a * emission[c];
                }
            }
            self.batch.push((info.flat_index, leaves.iter().map(|l| (l.poly, l.b)).collect()));
            if self.batch.len() >= BATCH {
                self.flush();
            }
        }
        self.inner.polygon(info, leaves)
    }
}
