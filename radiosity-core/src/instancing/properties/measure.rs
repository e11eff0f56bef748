//! Computing the properties: parallel rays through the prototype's box per direction give τ,
//! and the random walks from their first hits the escape albedo and the face transfer tally.

use super::entry::RadiativeProperties;
use super::key::{cache_key, content_hashes};
use super::radiosity::radiosity_albedo;
use super::sampling::{basis, box_projected_area, cosine_dir, hits_box, sphere_directions};
use super::settings::{PhaseMethod, PropertyConfig};
use crate::geom::{Aabb, DVec3};
use crate::instancing::InstancingError;
use crate::instancing::face_transfer::{FaceTally, entry_face, exit_face};
use crate::instancing::flatten::{FlattenOptions, flatten_prototype};
use crate::instancing::model::{InstancedScene, PrototypeId, Transform};
use crate::scene::{Polygon, Scene};
use crate::visibility::{RayCaster, Rng};
use std::f64::consts::PI;

/// Most bounces of one random walk (weights are negligible long before).
pub const MAX_BOUNCES: u32 = 256;
/// Offset of a bounced ray's origin off the surface, relative to the prototype's box diagonal.
pub const RAY_OFFSET_REL: f64 = 1e-5;

/// Computes the properties of prototype `id` (flattened in its local frame).
pub fn compute(scene: &InstancedScene, id: PrototypeId, config: &PropertyConfig) -> Result<RadiativeProperties, InstancingError> {
    let key = cache_key(content_hashes(scene)[id as usize], config);
    let flat = flatten_prototype(scene, id, &Transform::IDENTITY, &FlattenOptions { two_sided_pairs: false })?;
    Ok(compute_flat(&flat, &scene.prototype(id).name, key, config))
}

/// Properties of a plain scene seen as one object (see the module docs).
#[must_use]
pub fn compute_flat(flat: &Scene, name: &str, key: String, config: &PropertyConfig) -> RadiativeProperties {
    let bounds = flat.bounds();
    let dirs = sphere_directions(config.n_directions);
    let caster = RayCaster::new(flat);
    let surface_area = flat.total_area();
    let mut props = RadiativeProperties {
        key,
        prototype: name.to_owned(),
        bounds_min: bounds.min.to_array(),
        bounds_max: bounds.max.to_array(),
        directions: dirs.iter().map(|d| d.to_array()).collect(),
        transmittance: Vec::with_capacity(dirs.len()),
        box_area: Vec::with_capacity(dirs.len()),
        effective_area: Vec::with_capacity(dirs.len()),
        albedo: Vec::with_capacity(dirs.len()),
        phase: Vec::new(),
        surface_area,
        face_transfer: Vec::new(),
    };
    let mut tally = FaceTally::default();
    for (k, &w) in dirs.iter().enumerate() {
        let (tau, walk_albedo) = trace_direction(flat, &caster, &bounds, w, config, k as u32, &mut tally);
        let a_box = box_projected_area(&bounds, w);
        let a_eff = (1.0 - tau) * a_box;
        let albedo = match config.method {
            PhaseMethod::RandomWalk => walk_albedo,
            PhaseMethod::Radiosity { eps } => radiosity_albedo(flat, &bounds, w, a_eff, eps),
        };
        props.transmittance.push(tau);
        props.box_area.push(a_box);
        props.effective_area.push(a_eff);
        props.albedo.push(albedo);
    }
    // ∫ a(ω) dω over the sphere, by the equal-weight rule of the Fibonacci points.
    let integral = 4.0 * PI * props.mean_effective_area();
    props.phase = props
        .albedo
        .iter()
        .zip(&props.effective_area)
        .map(|(al, a)| al.map(|x| if integral > 0.0 { PI * x * a / integral } else { 0.0 }))
        .collect();
    props.face_transfer = tally.finish(props.mean_albedo()).0;
    props
}

/// τ and the random-walk escape albedo for light arriving from `w` (rays travel along −w); each
/// intercepted ray's power, entry face and exit face go to `tally`.
fn trace_direction(
    flat: &Scene,
    caster: &RayCaster,
    bounds: &Aabb,
    w: DVec3,
    config: &PropertyConfig,
    k: u32,
    tally: &mut FaceTally,
) -> (f64, [f64; 3]) {
    let d = -w;
    let (u, v) = basis(d);
    let c = bounds.center();
    let diag = bounds.diagonal().max(f64::MIN_POSITIVE);
    let (mut umin, mut umax, mut vmin, mut vmax) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for q in 0..8 {
        let p = crate::instancing::model::corner(bounds, q) - c;
        umin = umin.min(p.dot(u));
        umax = umax.max(p.dot(u));
        vmin = vmin.min(p.dot(v));
        vmax = vmax.max(p.dot(v));
    }
    let strata = (f64::from(config.rays_per_direction.max(1))).sqrt().ceil() as u32;
    // Power per ray under unit irradiance: the shadow rectangle's area over the rays.
    let ray_power = (umax - umin) * (vmax - vmin) / f64::from(strata * strata);
    let mut rng = Rng::for_link(config.seed, 0x7A0, k);
    let (mut n_box, mut n_pass, mut n_hit) = (0u64, 0u64, 0u64);
    let mut escaped = [0.0; 3];
    for i in 0..strata * strata {
        let su = umin + (umax - umin) * (f64::from(i % strata) + rng.next_f64()) / f64::from(strata);
        let sv = vmin + (vmax - vmin) * (f64::from(i / strata) + rng.next_f64()) / f64::from(strata);
        let origin = c + u * su + v * sv - d * diag;
        if !hits_box(bounds, origin, d) {
            continue;
        }
        n_box += 1;
        match caster.closest_hit(origin, d) {
            None => n_pass += 1,
            Some((t, p)) => {
                n_hit += 1;
                let out = walk(flat, caster, origin + d * t, d, p, diag, &mut rng);
                if let Some((e, _, _)) = out {
                    for ch in 0..3 {
                        escaped[ch] += e[ch];
                    }
                }
                if let Some(entry) = entry_face(bounds, origin, d) {
                    let exit = out.and_then(|(e, x, dir)| exit_face(bounds, x.clamp(bounds.min, bounds.max), dir).map(|f| (f, e)));
                    tally.add(entry, ray_power, exit);
                }
            }
        }
    }
    let tau = if n_box > 0 { n_pass as f64 / n_box as f64 } else { 1.0 };
    let albedo = escaped.map(|e| if n_hit > 0 { (e / n_hit as f64).clamp(0.0, 1.0) } else { 0.0 });
    (tau, albedo)
}

/// Follows one path from a first hit; returns its escaping weight per channel and the ray it
/// escapes along (`None` when absorbed).
fn walk(
    flat: &Scene,
    caster: &RayCaster,
    mut x: DVec3,
    mut d: DVec3,
    mut poly: u32,
    diag: f64,
    rng: &mut Rng,
) -> Option<([f64; 3], DVec3, DVec3)> {
    let mut weight = [1.0f64; 3];
    for _ in 0..MAX_BOUNCES {
        let Polygon { poly: geom, material, .. } = &flat.polygons[poly as usize];
        let m = &flat.materials[*material as usize];
        let n = geom.normal();
        let front = d.dot(n) < 0.0;
        if !front && !m.two_sided {
            return None;
        }
        let side = if front { n } else { -n };
        let pr = (m.reflectance.iter().sum::<f64>() / 3.0).max(0.0);
        let pt = if m.two_sided { (m.transmittance.iter().sum::<f64>() / 3.0).max(0.0) } else { 0.0 };
        let xi = rng.next_f64();
        let out_normal = if xi < pr {
            for c in 0..3 {
                weight[c] *= m.reflectance[c] / pr;
            }
            side
        } else if xi < pr + pt {
            for c in 0..3 {
                weight[c] *= m.transmittance[c] / pt;
            }
            -side
        } else {
            return None;
        };
        d = cosine_dir(out_normal, rng);
        x += out_normal * (RAY_OFFSET_REL * diag);
        match caster.closest_hit(x, d) {
            None => return Some((weight, x, d)),
            Some((t, p)) => {
                x += d * t;
                poly = p;
            }
        }
    }
    None
}
