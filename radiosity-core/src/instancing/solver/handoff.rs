//! The light handed on: per closed instance of a solved level, the field of beams that reached
//! its proxy (and the part of it straight from the top level's emitters), pushed as a new task.

use super::direct::EmittedShare;
use super::level::{Level, Role, is_proxy};
use super::occluders::Occluders;
use super::outside::{LevelLight, nearest_direction};
use super::task::{Closed, Task};
use crate::geom::DVec3;
use crate::hierarchy::{ElementId, Hierarchy};
use crate::solve::Solution;

/// Calls `f(face, bin, F·V·B_source, source)` (RGB) for every link that arrived at a proxy face (at the
/// face or below, or at a cluster holding it), with the bin of the direction toward its source (for
/// a cluster receiver, weighted by the face's cosine toward it).
fn for_each_link_direction(
    h: &Hierarchy,
    links: &[crate::refine::Link],
    radiosity: &[[f64; 3]],
    roles: &[Role],
    dirs: &[DVec3],
    mut f: impl FnMut(usize, usize, [f64; 3], ElementId),
) {
    for l in links {
        let (r, src) = (h.get(l.receiver), h.get(l.source));
        let b_src = radiosity[l.source as usize];
        match r.kind {
            crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } => {
                for &p in &h.cluster_polygons[poly_start as usize..poly_end as usize] {
                    if !is_proxy(roles, p as usize) {
                        continue;
                    }
                    let face = h.get(p);
                    let u = (src.center - face.center).normalize_or_zero();
                    let cos = face.normal.dot(u);
                    if cos > 0.0 {
                        f(p as usize, nearest_direction(dirs, u), b_src.map(|x| l.ff * l.vis * x * cos), l.source);
                    }
                }
            }
            _ => {
                let Some(p) = r.polygon() else { continue };
                if is_proxy(roles, p as usize) {
                    let u = (src.center - r.center).normalize_or_zero();
                    f(p as usize, nearest_direction(dirs, u), b_src.map(|x| l.ff * l.vis * x), l.source);
                }
            }
        }
    }
}

/// Adds `x` to bin `b` of a sparse field.
fn add_to_bin(field: &mut Vec<(u32, [f64; 3])>, b: usize, x: [f64; 3]) {
    if x.iter().all(|&v| v == 0.0) {
        return;
    }
    match field.iter_mut().find(|(k, _)| *k as usize == b) {
        Some((_, e)) => {
            for c in 0..3 {
                e[c] += x[c];
            }
        }
        None => field.push((b as u32, x)),
    }
}

/// What a solved level hands on to its closed instances, per instance (slot): the flux per
/// direction bin over its proxy's faces, of that the part straight from the top level's emitters
/// (sparse), and the proxy's projected area per bin.
pub(super) struct Handoff {
    fields: Vec<Vec<[f64; 3]>>,
    direct_fields: Vec<Vec<(u32, [f64; 3])>>,
    projected: Vec<Vec<f64>>,
}

/// The flux that reached each of the `n_closed` proxies of a solved `level`, per direction bin:
/// its faces' irradiance (`face_irradiance`) split over the directions of the links that brought
/// it, plus their share of the beams from outside (`light`). With `top_direct` (the top level,
/// direct light traced), the part straight from the top level's emitters is tracked apart.
pub(super) fn child_fields(
    level: &Level,
    solution: &Solution,
    light: &LevelLight,
    face_irradiance: &[[f64; 3]],
    n_closed: usize,
    top_direct: bool,
) -> Handoff {
    let h = &level.h;
    // Per proxy face: how the links that brought its irradiance split over directions, plus
    // its share of the beams from outside, as a field per closed instance. Two passes over the
    // links (per-face totals, then shares), so that no per-face field is ever held.
    let mut face_total = vec![[0.0; 3]; level.polys.len()];
    for_each_link_direction(h, &level.links, &solution.radiosity, &level.roles, &light.dirs, |face, _, w, _| {
        for c in 0..3 {
            face_total[face][c] += w[c];
        }
    });
    let mut fields = vec![vec![[0.0; 3]; light.dirs.len()]; n_closed];
    // The part from the top level's emitters, sparse (a few bins per instance).
    let mut direct_fields: Vec<Vec<(u32, [f64; 3])>> = vec![Vec::new(); n_closed];
    let emitted = if top_direct { Some(EmittedShare::new(h, &level.base_emission)) } else { None };
    let mut projected = vec![vec![0.0; light.dirs.len()]; n_closed];
    for (i, role) in level.roles.iter().enumerate() {
        let Role::ProxyFace { slot, .. } = *role else { continue };
        let (area, n) = (level.polys[i].area(), level.polys[i].normal());
        let along_normal = nearest_direction(&light.dirs, n);
        let h_local = face_irradiance[i];
        for (b, u) in light.dirs.iter().enumerate() {
            projected[slot][b] += area * n.dot(*u).max(0.0);
            for c in 0..3 {
                let ext = light.bins.get(i).and_then(|v| v.get(b)).map_or(0.0, |x| x[c]);
                // No link to attribute (none arrived, or all from behind): along the normal.
                let unattributed = if face_total[i][c] <= 0.0 && b == along_normal { h_local[c] } else { 0.0 };
                fields[slot][b][c] += area * (ext + unattributed);
            }
            if let Some(d) = light.direct_bins.get(i).and_then(|v| v.get(b)) {
                add_to_bin(&mut direct_fields[slot], b, d.map(|x| area * x));
            }
        }
    }
    for_each_link_direction(h, &level.links, &solution.radiosity, &level.roles, &light.dirs, |face, b, w, source| {
        let Role::ProxyFace { slot } = level.roles[face] else { return };
        let area = level.polys[face].area();
        let share: [f64; 3] =
            std::array::from_fn(
                |c| {
                    if face_total[face][c] > 0.0 { area * face_irradiance[face][c] * w[c] / face_total[face][c] } else { 0.0 }
                },
            );
        for c in 0..3 {
            fields[slot][b][c] += share[c];
        }
        if let Some(emitted) = &emitted {
            let (e, b_src) = (emitted.of(h, source), solution.radiosity[source as usize]);
            add_to_bin(
                &mut direct_fields[slot],
                b,
                std::array::from_fn(|c| if b_src[c] > 0.0 { share[c] * (e[c] / b_src[c]).min(1.0) } else { 0.0 }),
            );
        }
    });
    Handoff { fields, direct_fields, projected }
}

/// Pushes a task for each of the `closed` instances (in reverse, so that they are opened in
/// order), its field the flux handed to it over its proxy's projected area, per direction bin.
pub(super) fn push_children(stack: &mut Vec<Task>, closed: &[Closed], handoff: Handoff, mut child_occluders: Vec<Occluders>) {
    let Handoff { mut fields, mut direct_fields, projected } = handoff;
    for (slot, &(c, t, base, depth)) in closed.iter().enumerate().rev() {
        let mut field = std::mem::take(&mut fields[slot]);
        for (flux, p) in field.iter_mut().zip(&projected[slot]) {
            *flux = flux.map(|f| if *p > 0.0 { f / p } else { 0.0 });
        }
        let occluders = std::mem::take(&mut child_occluders[slot]);
        let mut direct = std::mem::take(&mut direct_fields[slot]);
        for (b, flux) in &mut direct {
            let p = projected[slot][*b as usize];
            *flux = flux.map(|f| if p > 0.0 { f / p } else { 0.0 });
        }
        direct.retain(|(_, e)| e.iter().any(|&x| x > 0.0));
        stack.push(Task { prototype: c, transform: t, flat_base: base, depth, incoming: Some(field), direct, occluders });
    }
}
