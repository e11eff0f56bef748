//! Flattening: every instance replaced by its transformed geometry, giving a plain [`Scene`] for the
//! reference ("full") solve. The instanced solver visits polygons in the same order, so that the
//! flattened index of a polygon is known without flattening.

use super::InstancingError;
use super::model::{InstancedScene, LocalPolygon, PrototypeId, Transform};
use crate::geom::Poly;
use crate::scene::{Material, Scene, SceneBuilder};

/// How polygons are emitted.
#[derive(Clone, Copy, Debug)]
pub struct FlattenOptions {
    /// Emit a two-sided polygon as two back-to-back one-sided polygons (front first), so that a
    /// solver that only knows one-sided surfaces lets both sides reflect. Transmittance is not
    /// represented this way (see the module docs of [`crate::instancing`]).
    pub two_sided_pairs: bool,
}

impl Default for FlattenOptions {
    fn default() -> Self {
        FlattenOptions { two_sided_pairs: true }
    }
}

/// Drops each polygon that is the back of the one before it (the same outline reversed, the same
/// two-sided material): flattening gives every two-sided polygon its back
/// ([`FlattenOptions::two_sided_pairs`]), so a leaf written as two back-to-back faces would
/// otherwise become two leaves in one place, four sides, each lit and counted. Returns how many
/// were dropped.
pub fn merge_backs(polygons: &mut Vec<LocalPolygon>, materials: &[Material]) -> usize {
    let before = polygons.len();
    let mut kept: Vec<LocalPolygon> = Vec::with_capacity(before);
    // Whether the last kept polygon already has its back merged (it is not a front for the next).
    let mut paired = false;
    for q in polygons.drain(..) {
        let back = !paired
            && kept
                .last()
                .is_some_and(|p| p.material == q.material && materials[q.material as usize].two_sided && q.poly.is_back_of(&p.poly));
        paired = back;
        if !back {
            kept.push(q);
        }
    }
    *polygons = kept;
    before - polygons.len()
}

/// Calls `f(poly, material, prototype)` for every polygon of prototype `id` placed by `transform`,
/// in flattening order: own polygons first (each two-sided one followed by its back twin when
/// `options.two_sided_pairs`), then each instance's polygons, recursively, depth-first.
pub fn for_each_polygon(
    scene: &InstancedScene,
    id: PrototypeId,
    transform: &Transform,
    options: &FlattenOptions,
    f: &mut dyn FnMut(Poly, u32, PrototypeId),
) {
    let mut stack: Vec<(PrototypeId, Transform)> = vec![(id, *transform)];
    while let Some((pid, t)) = stack.pop() {
        let p = scene.prototype(pid);
        for q in &p.polygons {
            let poly = t.poly(&q.poly);
            f(poly, q.material, pid);
            if options.two_sided_pairs && scene.materials[q.material as usize].two_sided {
                f(poly.reversed(), q.material, pid);
            }
        }
        // Reverse push so the first instance is visited first.
        for inst in p.instances.iter().rev() {
            stack.push((inst.prototype, t.then(&inst.transform)));
        }
    }
}

/// The whole scene as plain polygons (groups are prototype names), with what reading its files
/// repaired or skipped ([`super::model::Prototype::warnings`]).
pub fn flatten(scene: &InstancedScene, options: &FlattenOptions) -> Result<Scene, InstancingError> {
    let mut flat = flatten_prototype(scene, scene.root, &Transform::IDENTITY, options)?;
    for p in &scene.prototypes {
        flat.warnings.add(&p.warnings);
    }
    Ok(flat)
}

/// Prototype `id` placed by `transform`, as plain polygons.
pub fn flatten_prototype(
    scene: &InstancedScene,
    id: PrototypeId,
    transform: &Transform,
    options: &FlattenOptions,
) -> Result<Scene, InstancingError> {
    let mut b = SceneBuilder::new(&scene.path, &scene.name);
    for m in &scene.materials {
        let _ = b.material(m.clone())?;
    }
    let groups: Vec<u32> = scene.prototypes.iter().map(|p| b.group(&p.name)).collect();
    let mut result = Ok(());
    for_each_polygon(scene, id, transform, options, &mut |poly, material, pid| {
        if result.is_ok() {
            result = b.face(poly.vertices(), material, groups[pid as usize], 0);
        }
    });
    result?;
    Ok(b.finish())
}
