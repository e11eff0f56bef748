//! The traced direct light: below the top, the light straight from the top level's emitters is
//! split off an instance's field and ray traced to every own polygon through the nested
//! per-prototype BVHs ([`InstanceCaster`]).

use super::task::{OwnPolygon, Task};
use crate::geom::Poly;
use crate::hierarchy::{ElementId, Hierarchy};
use crate::instancing::InstanceCaster;
use crate::instancing::model::InstancedScene;

/// The emitted part of an element's radiosity at the top level (its area-weighted mean
/// emission): which share of a link's light came straight from an emitter.
pub(super) struct EmittedShare<'a> {
    /// Emitting polygons: their place in the hierarchy's cluster order and their `A·E`.
    emitters: Vec<(usize, [f64; 3])>,
    emission: &'a [[f64; 3]],
}

impl<'a> EmittedShare<'a> {
    pub(super) fn new(h: &Hierarchy, emission: &'a [[f64; 3]]) -> EmittedShare<'a> {
        let emitters = h
            .cluster_polygons
            .iter()
            .enumerate()
            .filter_map(|(pos, &p)| {
                let e = emission[p as usize];
                e.iter().any(|&x| x > 0.0).then(|| (pos, e.map(|x| x * h.get(p).area)))
            })
            .collect();
        EmittedShare { emitters, emission }
    }

    pub(super) fn of(&self, h: &Hierarchy, e: ElementId) -> [f64; 3] {
        let el = h.get(e);
        match el.kind {
            crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } => {
                let mut sum = [0.0; 3];
                for (pos, ae) in &self.emitters {
                    if (poly_start as usize..poly_end as usize).contains(pos) {
                        for c in 0..3 {
                            sum[c] += ae[c];
                        }
                    }
                }
                sum.map(|x| if el.area > 0.0 { x / el.area } else { 0.0 })
            }
            _ => el.polygon().map_or([0.0; 3], |p| self.emission[p as usize]),
        }
    }
}

/// A field split into the light straight from the top level's emitters and the rest, with the
/// direct light ray traced to the level's own polygons.
pub(super) struct DirectSplit {
    /// The field less its direct part.
    pub(super) rest: Vec<[f64; 3]>,
    /// The direct part, per direction bin (what proxy faces receive and pass on).
    pub(super) direct: Vec<[f64; 3]>,
    /// Traced direct irradiance per own polygon, by flattened index relative to the instance's
    /// first (a transmitting leaf's back side at the index after its front).
    pub(super) traced: Vec<[f64; 3]>,
}

/// Direct irradiance of the `own` polygons of a level (scene frame) from `emitters`, ray traced
/// through `caster` from [`InstancedConfig::direct_samples`](super::InstancedConfig::direct_samples) point pairs per polygon and emitter,
/// by flattened index relative to `flat_base` (see [`DirectSplit::traced`]). A transmitting leaf's
/// two sides are estimated from one set of pairs. Seeded by flattened index.
fn traced_direct(
    scene: &InstancedScene,
    own: &[OwnPolygon],
    flat_base: u64,
    emitters: &[(Poly, [f64; 3])],
    caster: &InstanceCaster,
    samples: u32,
) -> Vec<[f64; 3]> {
    use rayon::prelude::*;
    let sides: Vec<(usize, [f64; 3], Option<[f64; 3]>)> = own
        .par_iter()
        .map(|(p, material, flat, _)| {
            let two_sided = scene.materials[*material as usize].two_sided;
            let (mut front, mut back) = ([0.0; 3], [0.0; 3]);
            for (k, (q, e)) in emitters.iter().enumerate() {
                let mut rng = crate::visibility::Rng::for_link(DIRECT_SEED ^ flat.wrapping_mul(0x9E37_79B9_7F4A_7C15), k as u32, 0);
                let [f, g] = crate::solve::emitter_exchange(p, q, samples, &mut rng, two_sided, |x, y| caster.segment_clear(x, y));
                for c in 0..3 {
                    front[c] += f * e[c];
                    back[c] += g * e[c];
                }
            }
            ((flat - flat_base) as usize, front, two_sided.then_some(back))
        })
        .collect();
    let len = sides.iter().map(|s| s.0 + 2).max().unwrap_or(0);
    let mut out = vec![[0.0; 3]; len];
    for (k, front, back) in sides {
        out[k] = front;
        if let Some(back) = back {
            out[k + 1] = back;
        }
    }
    out
}

/// Seed of the point pairs of [`traced_direct`].
const DIRECT_SEED: u64 = 0xD1EC7;

/// The emitting polygons of the top level's `own` (scene frame), with their emission.
pub(super) fn top_emitters(scene: &InstancedScene, own: &[OwnPolygon]) -> Vec<(Poly, [f64; 3])> {
    own.iter().filter(|o| scene.materials[o.1 as usize].is_emitter()).map(|o| (o.0, scene.materials[o.1 as usize].emission)).collect()
}

/// The caster of the direct light: one BVH per prototype, built once the top level is freed.
pub(super) fn build_caster(scene: &InstancedScene, trace: bool) -> InstanceCaster {
    let c = InstanceCaster::new(scene);
    if trace {
        eprintln!("direct light: nested BVHs of {} prototypes, {:.1} MB", scene.prototypes.len(), c.bytes() as f64 / 1e6);
    }
    c
}

/// Below the top (once a `caster` is built), the field of `task` split into its direct part and
/// the rest, with the direct light traced to the level's `own` polygons from `emitters`.
pub(super) fn direct_split(
    scene: &InstancedScene,
    task: &Task,
    own: &[OwnPolygon],
    emitters: &[(Poly, [f64; 3])],
    caster: Option<&InstanceCaster>,
    samples: u32,
) -> Option<DirectSplit> {
    match (&task.incoming, caster) {
        (Some(field), Some(caster)) => {
            let mut direct = vec![[0.0; 3]; field.len()];
            for &(b, e) in &task.direct {
                direct[b as usize] = e;
            }
            let rest = field.iter().zip(&direct).map(|(f, d)| std::array::from_fn(|c| (f[c] - d[c]).max(0.0))).collect();
            let traced = traced_direct(scene, own, task.flat_base, emitters, caster, samples);
            Some(DirectSplit { rest, direct, traced })
        }
        _ => None,
    }
}
