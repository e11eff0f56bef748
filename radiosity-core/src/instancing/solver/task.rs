//! Task traversal: the instances waiting to be opened, and the level each one gathers (its own
//! polygons, those of the instances opened in place, and the instances left closed).

use super::config::InstancedConfig;
use super::occluders::Occluders;
use super::proxy::padded;
use crate::geom::{Aabb, DVec3, Poly};
use crate::instancing::model::{InstancedScene, PrototypeId, Transform};

/// A polygon of a level's own: geometry (world), material, flattened index, prototype holding it.
pub(super) type OwnPolygon = (Poly, u32, u64, PrototypeId);

/// An instance waiting to be opened.
pub(super) struct Task {
    pub(super) prototype: PrototypeId,
    pub(super) transform: Transform,
    pub(super) flat_base: u64,
    /// Nesting depth of the instance (the scene is 0, its instances 1, theirs 2, ...).
    pub(super) depth: u32,
    /// The light that arrived at the instance: irradiance perpendicular to each direction of
    /// [`light_directions`](super::outside::light_directions) (a distant-light field); `None` at the top.
    pub(super) incoming: Option<Vec<[f64; 3]>>,
    /// The part of `incoming` that came straight from the top level's emitters, per direction
    /// bin (the few bins that hold any): below the top, each polygon's own share of it is ray
    /// traced instead (see [`InstancedConfig::direct_samples`](super::InstancedConfig::direct_samples)); proxy faces keep the beams.
    pub(super) direct: Vec<(u32, [f64; 3])>,
    /// Polygons of the levels above (scene frame) that cross the instance's box (a trunk through
    /// a branch's box): the beams from outside are tested against them too (see
    /// [`inherited_occluders`](super::occluders::inherited_occluders)).
    pub(super) occluders: Occluders,
}

/// A closed instance of a level: prototype, transform (scene frame), first flattened index, depth.
pub(super) type Closed = (PrototypeId, Transform, u64, u32);

/// The level gathered for a task.
pub(super) struct Gathered {
    /// Own polygons of the task and of the instances opened in place, by flattened index.
    pub(super) own: Vec<OwnPolygon>,
    /// The closed instances.
    pub(super) closed: Vec<Closed>,
    /// Which instances were opened in place (part of the key under which the level is cached).
    pub(super) inlined: Vec<bool>,
}

/// Gathers the level of `task`: own polygons of the task and of instances opened in place, and
/// the closed instances. An instance is opened in place when its depth is not instanced, it is too
/// large or empty, it lies near an emitter of the level, or it overlaps a sibling too much (see
/// [`InstancedConfig`]).
pub(super) fn gather_level(scene: &InstancedScene, config: &InstancedConfig, counts: &[u64], bounds: &[Aabb], task: &Task) -> Gathered {
    // Gather the level: own polygons of the task and of instances opened in place, and the
    // closed instances; `inlined` records which instances were opened in place (part of the
    // key under which the level is cached).
    let mut own: Vec<OwnPolygon> = Vec::new();
    let mut closed: Vec<Closed> = Vec::new();
    let mut emitters: Vec<Aabb> = Vec::new();
    let mut inlined: Vec<bool> = Vec::new();
    let mut pending = vec![(task.prototype, task.transform, task.flat_base, task.depth)];
    while let Some((pid, t, base, depth)) = pending.pop() {
        let p = scene.prototype(pid);
        let mut k = base;
        for q in &p.polygons {
            let poly = t.poly(&q.poly);
            if scene.materials[q.material as usize].is_emitter() {
                emitters.push(Aabb::from_points(poly.vertices()));
            }
            own.push((poly, q.material, k, pid));
            k += 1;
            if scene.materials[q.material as usize].two_sided {
                k += 1;
            }
        }
        let mut inline = Vec::new();
        let boxes: Vec<Aabb> = if config.open_overlap < 1.0 {
            p.instances.iter().map(|inst| t.then(&inst.transform).aabb(&padded(&bounds[inst.prototype as usize]))).collect()
        } else {
            Vec::new()
        };
        for (i, inst) in p.instances.iter().enumerate() {
            let c = inst.prototype;
            let child_t = t.then(&inst.transform);
            let open = !config.instance_levels.closes(depth + 1)
                || counts[c as usize] > config.max_closed_polygons
                || bounds[c as usize].is_empty()
                || near_an_emitter(&child_t.aabb(&bounds[c as usize]), &emitters, config.open_near_emitter)
                || (!boxes.is_empty()
                    && boxes.iter().enumerate().any(|(j, b)| j != i && overlap_fraction(&boxes[i], b) > config.open_overlap));
            inlined.push(open);
            if open {
                inline.push((c, child_t, k, depth + 1));
            } else {
                closed.push((c, child_t, k, depth + 1));
            }
            k += counts[c as usize];
        }
        for item in inline.into_iter().rev() {
            pending.push(item);
        }
    }
    own.sort_by_key(|o| o.2);
    Gathered { own, closed, inlined }
}

/// Volume of the intersection of `a` and `b` over the smaller one's volume (0 when disjoint).
fn overlap_fraction(a: &Aabb, b: &Aabb) -> f64 {
    let common = (a.max.min(b.max) - a.min.max(b.min)).max(DVec3::ZERO);
    let vol = |e: DVec3| e.x * e.y * e.z;
    let smaller = vol(a.extent()).min(vol(b.extent()));
    if smaller > 0.0 { vol(common) / smaller } else { 0.0 }
}

/// True when box `b` lies within `rel` times its diagonal of one of the `emitters` boxes.
fn near_an_emitter(b: &Aabb, emitters: &[Aabb], rel: f64) -> bool {
    let reach = rel * b.diagonal();
    emitters.iter().any(|e| {
        let gap = DVec3::ZERO.max(e.min - b.max).max(b.min - e.max);
        gap.length() < reach
    })
}
