//! Computing the elements' direct light: every new element's ([`update_direct`]), and chosen
//! leaves' again with more samples ([`deepen_direct`]).

use super::ParallelShadows;
use super::point::DirectLight;
use super::rule::{LeafDirect, LeafSources, leaf_direct};
use crate::hierarchy::{ElementKind, Hierarchy};
use crate::light::Lights;
use crate::visibility::RayCaster;

/// Computes the direct irradiance of every surface element made since the last call (leaves by
/// quadrature with shadow rays: the luminaires' illuminance in every channel, the distant
/// sources' per channel), then every inner element's as the area mean of its children
/// ([`crate::solve::area_means`]), so that every level carries the same power.
///
/// A sharp distant source (the sun) lights each leaf by its exact lit share (module docs): no
/// error. Where a shadow boundary of a luminaire crosses a leaf (its rule's
/// points or corners disagree on the luminaire's visibility), or a luminaire lights it from nearer
/// than [`MAX_ANGULAR_SIZE`](super::MAX_ANGULAR_SIZE) allows, the leaf's value is the area mean of the same rule over its
/// four quarters (the children it would have), and the difference from its own rule's value is
/// its quadrature error ([`Hierarchy::direct_error`]): a step along a shadow edge defeats the
/// rule's polynomial accuracy, and halving the elements about halves what it misplaces (first
/// order; a near luminaire's error falls faster), so the finer value is in error by about that
/// difference.
pub fn update_direct(h: &mut Hierarchy, lights: &Lights, caster: Option<&RayCaster>) {
    use rayon::prelude::*;
    let (n, start) = (h.len(), h.direct.len());
    if lights.is_empty() || start == n {
        return;
    }
    let light = DirectLight::new(&lights.luminaires, caster, h.diagonal());
    let distant = crate::daylight::DistantLight::new(&lights.distant, caster, h.diagonal());
    let hh: &Hierarchy = h;
    let shadows = ParallelShadows::new(hh, &lights.distant, caster);
    let new: Vec<Option<LeafDirect>> = (start as u32..n as u32)
        .into_par_iter()
        .map(|id| {
            let e = hh.get(id);
            match e.kind {
                ElementKind::Surface { polygon, poly } if e.n_children == 0 => {
                    let inherited = hh.direct_soft.get(e.parent as usize).copied().flatten();
                    Some(leaf_direct(
                        &poly,
                        &LeafSources { normal: e.normal, polygon, light: &light, distant: &distant, shadows: shadows.as_ref() },
                        1,
                        inherited,
                    ))
                }
                _ => None,
            }
        })
        .collect();
    let mut direct = std::mem::take(&mut h.direct);
    direct.extend(new.iter().map(|v| v.as_ref().map_or([0.0; 3], |v| v.direct)));
    h.direct_error.resize(start, [0.0; 3]);
    h.direct_error.extend(new.iter().map(|v| v.as_ref().map_or([0.0; 3], |v| v.error)));
    h.direct_soft.resize(start, None);
    h.direct_soft.extend(new.iter().map(|v| v.as_ref().and_then(|v| v.soft)));
    h.direct_edge.resize(start, [0.0; 3]);
    h.direct_edge.extend(new.iter().map(|v| v.as_ref().map_or([0.0; 3], |v| v.edge)));
    crate::solve::area_means(h, &crate::solve::top_down(h), &mut direct);
    h.direct = direct;
}

/// Recomputes the direct light of surface leaves `leaves` with their quarters quartered
/// `depth` times ([`update_direct`] does it once), each leaf's error from the same one fewer
/// time, then every inner element's as the area mean of its children: more shadow rays where a
/// leaf cannot be split further (the smallest element size) and its shadow edges still leave its
/// polygon short of the target.
pub fn deepen_direct(h: &mut Hierarchy, lights: &Lights, caster: Option<&RayCaster>, leaves: &[(u32, u32)]) {
    use rayon::prelude::*;
    if lights.is_empty() || leaves.is_empty() || h.direct.len() != h.len() {
        return;
    }
    let light = DirectLight::new(&lights.luminaires, caster, h.diagonal());
    let distant = crate::daylight::DistantLight::new(&lights.distant, caster, h.diagonal());
    let hh: &Hierarchy = h;
    let shadows = ParallelShadows::new(hh, &lights.distant, caster);
    let new: Vec<(u32, [f64; 3], [f64; 3])> = leaves
        .par_iter()
        .filter_map(|&(id, depth)| {
            let e = hh.get(id);
            let ElementKind::Surface { polygon, poly } = e.kind else { return None };
            (e.n_children == 0).then(|| {
                let own = hh.direct_soft.get(id as usize).copied().flatten();
                let at = LeafSources { normal: e.normal, polygon, light: &light, distant: &distant, shadows: shadows.as_ref() };
                let d = leaf_direct(&poly, &at, depth.max(1), own);
                (id, d.direct, d.error)
            })
        })
        .collect();
    let mut direct = std::mem::take(&mut h.direct);
    h.direct_error.resize(h.len(), [0.0; 3]);
    for (id, d, err) in new {
        direct[id as usize] = d;
        h.direct_error[id as usize] = err;
    }
    crate::solve::area_means(h, &crate::solve::top_down(h), &mut direct);
    h.direct = direct;
}
