//! The backs of one-sided faces: which get a back under the scene's distant sources, and which
//! stay open (light reaching them is lost).

use super::{Site, any_perpendicular, escape_cells};
use crate::visibility::RayCaster;

/// Gives a back (the reversed face, right after it, same material) to every one-sided face of an
/// open mesh whose back can receive light under the scene's distant sources: a source shines on
/// that side, or one of the [`ESCAPE_CELLS`](super::ESCAPE_CELLS) rays from its centre across that side meets a
/// surface. Leaves are two-sided the way Radiance and CARIBU treat surfaces: a canopy of single
/// faces would otherwise block the light reaching their backs and lose it (46% less absorbed by
/// opaque leaves written as one quad each). Faces of closed meshes, faces with a back, emitters,
/// materials declared either way (`two_sided`), and faces whose backs see nothing (a ground plane's
/// underside) stay as they are. Does nothing without distant sources. Returns how many backs
/// were added (also counted in [`crate::scene::SceneWarnings::two_sided_by_default`]).
pub fn two_sided_where_backs_see_light(scene: &mut crate::scene::Scene) -> usize {
    use rayon::prelude::*;
    if scene.distant.is_empty() || scene.polygons.is_empty() {
        return 0;
    }
    let polys: Vec<crate::geom::Poly> = scene.polygons.iter().map(|p| p.poly).collect();
    let n = polys.len();
    let open = crate::geom::open_mesh_faces(&polys);
    let has_back = |i: usize| (i > 0 && polys[i - 1].is_back_of(&polys[i])) || (i + 1 < n && polys[i + 1].is_back_of(&polys[i]));
    let candidates: Vec<usize> = (0..n)
        .filter(|&i| {
            let m = scene.material_of(i);
            open[i] && !m.two_sided && !m.one_sided && !m.is_emitter() && !has_back(i)
        })
        .collect();
    if candidates.is_empty() {
        return 0;
    }
    let caster = RayCaster::new(scene);
    let cells = escape_cells();
    let offset = crate::visibility::SHADOW_ORIGIN_OFFSET_REL * scene.bounds().diagonal();
    let lit: Vec<bool> = candidates
        .par_iter()
        .map(|&i| {
            let back = -polys[i].normal();
            if scene.distant.iter().any(|s| s.on(back).iter().any(|&v| v > 0.0)) {
                return true;
            }
            let frame = Site::new(back, any_perpendicular(back)).unwrap_or_default();
            let origin = polys[i].centroid() + offset * back;
            cells.iter().any(|(d, _)| {
                let dir = frame.world(*d);
                caster.closest_hit_where(origin, dir, |q| q != i as u32).is_some()
            })
        })
        .collect();
    let mut given = vec![false; n];
    for (&i, &l) in candidates.iter().zip(&lit) {
        given[i] = l;
    }
    let added = given.iter().filter(|&&g| g).count();
    if added > 0 {
        let old = std::mem::take(&mut scene.polygons);
        for (i, p) in old.into_iter().enumerate() {
            let back = given[i].then(|| crate::scene::Polygon { poly: p.poly.reversed(), ..p.clone() });
            scene.polygons.push(p);
            scene.polygons.extend(back);
        }
        scene.warnings.two_sided_by_default += added;
    }
    added
}

/// Whether each polygon of `h` has an open back: one-sided (no back next to it, see
/// [`crate::scene::Scene::pair_two_sided`]), so light reaching its back is blocked and lost, and
/// not part of a closed mesh (every edge of its edge-connected faces shared by two of them, as
/// a box's are), whose inside no light can reach. Light the solve puts on the backs of a closed
/// mesh (a coarse element of the ground, half under a box, sending its mean radiosity from under
/// it) is an error of the discretisation, left to show in the balance; light on an open back (a
/// one-sided leaf) is lost for real, and counted.
#[must_use]
pub fn open_backs(h: &crate::hierarchy::Hierarchy) -> Vec<bool> {
    let polys: Vec<crate::geom::Poly> = (0..h.n_polygons).filter_map(|p| h.get(p).poly().copied()).collect();
    if polys.len() != h.n_polygons as usize {
        return vec![false; h.n_polygons as usize];
    }
    let open = crate::geom::open_mesh_faces(&polys);
    (0..h.n_polygons).map(|p| open[p as usize] && crate::visibility::back_of(h, p).is_none()).collect()
}
