//! Daylight in the instanced solve: the scene's distant sources ([`crate::daylight`]: the sun and
//! the sky's cells, [`InstancedConfig::daylight`](super::InstancedConfig::daylight)) light every
//! own polygon with visibility through the whole two-level structure ([`InstanceCaster`]), and
//! the proxies at the top level as beams.
//!
//! - **Own polygons, at every level.** A polygon's mean irradiance from each source is
//!   `E·max(0, −n·toward)` times the share of its points from which a ray against the beam leaves
//!   the scene through the [`InstanceCaster`] (the top level's geometry and every instance's own:
//!   a leaf is shadowed by the actual leaves of other branches and other trees). A two-sided leaf's
//!   back gets the sources behind it from the same points. The points are a Halton set, rotated per
//!   polygon: the sun (and any sharp source) is traced from all of them, each sky cell from
//!   `⌈N / `[`SKY_RAYS_DIVISOR`]`⌉` of them (different cells from different points, so the whole
//!   sky is still seen from the whole polygon); a sky of more than [`SKY_MAX_CELLS`] cells facing
//!   the polygon gets as many rays as that many cells would, drawn over its cells in proportion
//!   to their light (every cell brighter than a ray's share traced, the dimmer ones in turn), the
//!   unoccluded sky scaled by the share of the drawn light that got through. Below the top N is
//!   [`InstancedConfig::direct_samples`](super::InstancedConfig::direct_samples); at the top a
//!   polygon larger than the median of its level (or than [`TOP_POINT_AREA_REL`] of the scene's
//!   diagonal squared, when that is smaller) gets more, in proportion to its area, up to
//!   [`TOP_MAX_POINTS`] (the ground under a forest is one polygon crossed by every tree's shadow;
//!   under a lone tree it is the median itself).
//!   Like the top level's emitters' traced direct light, it enters as emission `ρ·E` (plus `t·E` of
//!   the twin side for a transmitting leaf) and is added to the polygon's reported irradiance.
//! - **Proxies, at the top.** Each face of a closed instance's proxy gets the beams with the top
//!   level's own visibility (its polygons and the other proxies' boxes, a [`RayCaster`]), reflects
//!   `ρ̄·E` like the rest of the level, and hands the light on to its instance in the direction bin
//!   nearest to each source, tracked as direct light: below the top, every own polygon gets its
//!   share ray traced (above) in place of the beams, which carry only the interreflected light.
//!   With the traced direct light off (`direct_samples` 0) the daylight goes down with the beams.
//!
//! The points' mean is per polygon: the top level's polygons are not split along the instances'
//! shadow boundaries as the plain solve splits them along the sun's, so their means are exact but
//! their radiosity inside is uniform.

use super::level::Role;
use super::outside::{LevelLight, light_directions, nearest_direction};
use super::task::OwnPolygon;
use crate::daylight::DistantSource;
use crate::geom::{DVec3, Poly};
use crate::instancing::InstanceCaster;
use crate::instancing::model::InstancedScene;
use crate::scene::Scene;
use crate::visibility::{RayCaster, Rng};

/// A sky cell is traced from `⌈N / SKY_RAYS_DIVISOR⌉` of a polygon's N points, the sun from all of
/// them: with the default 16 points, one ray per cell and polygon (145 for the finer sky), 16 for
/// the sun. A cell's light is a small share of the sky's and its shadow is soft, and the cells
/// traced from different points average over the polygon.
pub const SKY_RAYS_DIVISOR: u32 = 16;

/// A sky of more cells than this (facing a polygon's sides) is not traced cell by cell but by
/// `SKY_MAX_CELLS·⌈N / `[`SKY_RAYS_DIVISOR`]`⌉` rays drawn over its cells in proportion to their
/// light (see the module docs): a 46-cell sky is traced cell by cell, a 145-cell one at the cost
/// of 48 cells. Exact when nothing blocks; within 5% of the cell-by-cell sum on a polygon that
/// sees half the sky (measured 2.4% at most, the unit test in `sky_sample.rs`).
pub const SKY_MAX_CELLS: u32 = 48;

/// Most points of a top-level polygon (see the module docs).
pub const TOP_MAX_POINTS: u32 = 1024;

/// Area, relative to the scene's diagonal squared, above which a top-level polygon gets more
/// points even when it is the median of its level (see the module docs). Without it a lone
/// tree's ground, the only polygon of its level, had 16 points for the tree's shadow, and the
/// instanced power balance (`tests/instanced_daylight.rs`) was 2.3% off.
pub const TOP_POINT_AREA_REL: f64 = 1.0 / 4096.0;

/// Points of the top level's polygons when the traced direct light is off.
const TOP_MIN_POINTS: u32 = 16;

/// Seed of the points.
const DAYLIGHT_SEED: u64 = 0xDA71_1647;

/// The brightest radiosity the distant `sources` can give a surface of `materials`: the largest
/// unoccluded irradiance (over the planes facing each source) times the largest reflectance plus
/// transmittance, per channel, the largest channel. What local BF thresholds are relative to in a
/// scene lit by daylight (as the largest emission is in one lit by emitters).
#[must_use]
pub fn brightest(materials: &[crate::scene::Material], sources: &[DistantSource]) -> f64 {
    let mut e_max = [0.0f64; 3];
    for s in sources {
        let n = -s.toward;
        let mut e = [0.0; 3];
        for t in sources {
            let on = t.on(n);
            for c in 0..3 {
                e[c] += on[c];
            }
        }
        for c in 0..3 {
            e_max[c] = e_max[c].max(e[c]);
        }
    }
    materials.iter().flat_map(|m| (0..3).map(move |c| (m.reflectance[c] + m.transmittance[c]) * e_max[c])).fold(0.0, f64::max)
}

/// The `i`-th point of the base-`b` radical inverse.
fn radical_inverse(mut i: u32, b: u32) -> f64 {
    let (mut x, mut f) = (0.0, 1.0 / f64::from(b));
    while i > 0 {
        x += f * f64::from(i % b);
        i /= b;
        f /= f64::from(b);
    }
    x
}

/// Mean irradiance of both sides of polygon `p` (normal `n`; the back only when `two_sided`)
/// from `sources`, from `points` points (see the module docs), `clear` telling whether a segment
/// leaves the scene. `key` seeds the points' rotation.
#[allow(clippy::too_many_arguments)]
pub(super) fn polygon_irradiance(
    p: &Poly,
    two_sided: bool,
    points: u32,
    key: u64,
    sources: &[DistantSource],
    (offset, far): (f64, f64),
    clear: &dyn Fn(DVec3, DVec3) -> bool,
) -> ([f64; 3], [f64; 3]) {
    let n = p.normal();
    let points = points.max(1);
    let mut rng = Rng::for_link(DAYLIGHT_SEED ^ key.wrapping_mul(0x9E37_79B9_7F4A_7C15), 0, 0);
    let (du, dv) = (rng.next_f64(), rng.next_f64());
    let xs: Vec<DVec3> =
        (0..points).map(|i| p.sample((radical_inverse(i, 2) + du).fract(), (radical_inverse(i, 3) + dv).fract())).collect();
    let sky_points = points.div_ceil(SKY_RAYS_DIVISOR);
    // The sky cells that light either side: (source, back side, cosine).
    let sky: Vec<(usize, bool, f64)> = sources
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.sharp)
        .filter_map(|(k, s)| {
            let c = -n.dot(s.toward);
            if c > 0.0 {
                Some((k, false, c))
            } else if two_sided && c < 0.0 {
                Some((k, true, -c))
            } else {
                None
            }
        })
        .collect();
    let sampled = sky.len() > SKY_MAX_CELLS as usize;
    let (mut front, mut back) = ([0.0; 3], [0.0; 3]);
    if sampled {
        let rays = SKY_MAX_CELLS * sky_points;
        let sides = super::sky_sample::sampled_sky(&sky, sources, rays, rng.next_f64(), &mut |j, back, toward| {
            let side = if back { -n } else { n };
            let x = xs[(j % points) as usize] + side * offset;
            clear(x, x - toward * far)
        });
        (front, back) = (sides[0], sides[1]);
    }
    for (k, s) in sources.iter().enumerate() {
        if sampled && !s.sharp {
            continue;
        }
        let c = -n.dot(s.toward);
        let (side, cos, acc) = if c > 0.0 {
            (n, c, &mut front)
        } else if two_sided && c < 0.0 {
            (-n, -c, &mut back)
        } else {
            continue;
        };
        let (start, count) = if s.sharp { (0, points) } else { ((k as u32).wrapping_mul(sky_points) % points, sky_points) };
        let open = (0..count)
            .filter(|j| {
                let x = xs[((start + j) % points) as usize] + side * offset;
                clear(x, x - s.toward * far)
            })
            .count();
        let v = cos * open as f64 / f64::from(count);
        for ch in 0..3 {
            acc[ch] += s.irradiance[ch] * v;
        }
    }
    (front, back)
}

/// Ray offset and length for a scene of diagonal `diag`: rays start this far off the surface and
/// run past the scene's box.
fn ray_span(diag: f64) -> (f64, f64) {
    let diag = diag.max(f64::MIN_POSITIVE);
    let offset = crate::visibility::SHADOW_ORIGIN_OFFSET_REL * diag;
    (offset, 1.01 * diag + offset)
}

/// Daylight irradiance of the `own` polygons of a level (scene frame), by flattened index relative
/// to `flat_base` (a transmitting leaf's back side at the index after its front), ray traced
/// through `caster` (see the module docs). `samples` points per polygon; at the `top`, more for
/// polygons larger than the median. `diag` is the scene's diagonal.
pub(super) fn traced_daylight(
    scene: &InstancedScene,
    own: &[OwnPolygon],
    flat_base: u64,
    sources: &[DistantSource],
    caster: &InstanceCaster,
    (samples, top): (u32, bool),
    diag: f64,
) -> Vec<[f64; 3]> {
    use rayon::prelude::*;
    let len = own.iter().map(|o| (o.2 - flat_base) as usize + 2).max().unwrap_or(0);
    let mut out = vec![[0.0; 3]; len];
    if sources.is_empty() {
        return out;
    }
    let samples = if top { samples.max(TOP_MIN_POINTS) } else { samples.max(1) };
    let median = if top {
        let mut areas: Vec<f64> = own.iter().map(|o| o.0.area()).collect();
        areas.sort_by(f64::total_cmp);
        areas.get(areas.len() / 2).copied().unwrap_or(0.0).min(TOP_POINT_AREA_REL * diag * diag)
    } else {
        0.0
    };
    let span = ray_span(diag);
    let clear = |a: DVec3, b: DVec3| caster.segment_clear(a, b);
    let sides: Vec<(usize, [f64; 3], Option<[f64; 3]>)> = own
        .par_iter()
        .map(|(p, material, flat, _)| {
            let two_sided = scene.materials[*material as usize].two_sided;
            let points = if top && median > 0.0 {
                let scaled = (f64::from(samples) * p.area() / median).ceil().min(f64::from(TOP_MAX_POINTS));
                (scaled as u32).clamp(samples, TOP_MAX_POINTS.max(samples))
            } else {
                samples
            };
            let (front, back) = polygon_irradiance(p, two_sided, points, *flat, sources, span, &clear);
            ((flat - flat_base) as usize, front, two_sided.then_some(back))
        })
        .collect();
    for (k, front, back) in sides {
        out[k] = front;
        if let Some(back) = back {
            out[k + 1] = back;
        }
    }
    out
}

/// Adds `more` into `into` (by index, growing it as needed).
pub(super) fn add_into(into: &mut Vec<[f64; 3]>, more: &[[f64; 3]]) {
    if into.len() < more.len() {
        into.resize(more.len(), [0.0; 3]);
    }
    for (a, b) in into.iter_mut().zip(more) {
        for c in 0..3 {
            a[c] += b[c];
        }
    }
}

/// The daylight of the top level: its own polygons' traced irradiance, and what the proxy faces
/// need to be lit.
pub(super) struct TopDaylight<'a> {
    /// Own polygons' irradiance by flattened index (see [`traced_daylight`]).
    pub(super) traced: Vec<[f64; 3]>,
    pub(super) sources: &'a [DistantSource],
    /// Points per proxy face (at least 16).
    pub(super) samples: u32,
    /// Whether the proxies' daylight is handed on as direct light (traced below the top).
    pub(super) tracked: bool,
}

impl TopDaylight<'_> {
    /// The light of the top level's local problem `local` (polygons with `roles`): every polygon's
    /// daylight irradiance, and each proxy face's per direction bin (and as direct light when
    /// `tracked`), as [`LevelLight`] carries them; the polygons' materials in `local` take the
    /// reflected and transmitted daylight as emission.
    pub(super) fn light(&self, local: &mut Scene, roles: &[Role]) -> LevelLight {
        use rayon::prelude::*;
        let dirs = light_directions();
        let bins_of: Vec<usize> = self.sources.iter().map(|s| nearest_direction(&dirs, -s.toward)).collect();
        let has_proxies = roles.iter().any(|r| matches!(r, Role::ProxyFace { .. }));
        let caster = has_proxies.then(|| RayCaster::new(local));
        let diag = local.bounds().diagonal();
        let (offset, far) = ray_span(diag);
        let rows: Vec<([f64; 3], Vec<[f64; 3]>)> = local
            .polygons
            .par_iter()
            .enumerate()
            .map(|(i, poly)| match (roles.get(i), &caster) {
                (Some(Role::Own(info)), _) => (self.traced.get(info.flat_index as usize).copied().unwrap_or([0.0; 3]), Vec::new()),
                (Some(Role::ProxyFace { .. }), Some(caster)) => {
                    let clear = |a: DVec3, b: DVec3| caster.segment_clear(a, b, i as u32, crate::hierarchy::NONE);
                    let mut bins = vec![[0.0; 3]; dirs.len()];
                    let mut total = [0.0; 3];
                    for (k, s) in self.sources.iter().enumerate() {
                        let one = std::slice::from_ref(s);
                        let (e, _) = polygon_irradiance(
                            &poly.poly,
                            false,
                            self.samples.max(TOP_MIN_POINTS),
                            i as u64 ^ ((k as u64) << 32),
                            one,
                            (offset, far),
                            &clear,
                        );
                        for c in 0..3 {
                            bins[bins_of[k]][c] += e[c];
                            total[c] += e[c];
                        }
                    }
                    (total, bins)
                }
                _ => ([0.0; 3], Vec::new()),
            })
            .collect();
        let mut external = Vec::with_capacity(rows.len());
        let mut bins = Vec::with_capacity(rows.len());
        for (e, b) in rows {
            external.push(e);
            bins.push(b);
        }
        lit_materials(local, &external);
        let direct_bins = if self.tracked { bins.clone() } else { Vec::new() };
        LevelLight { dirs, external, bins, direct_bins }
    }
}

/// Gives every polygon of `local` a material of its own whose emission adds the reflection of its
/// `external` irradiance and the transmission of its twin side's (as a level lit from outside
/// does).
fn lit_materials(local: &mut Scene, external: &[[f64; 3]]) {
    let twin = crate::hierarchy::twins(local);
    let mut materials = Vec::with_capacity(local.polygons.len());
    for (i, p) in local.polygons.iter_mut().enumerate() {
        let mut m = local.materials[p.material as usize].clone();
        m.name = format!("p{i}");
        let e = external.get(i).copied().unwrap_or([0.0; 3]);
        let other = if twin[i] == crate::hierarchy::NONE { [0.0; 3] } else { external.get(twin[i] as usize).copied().unwrap_or([0.0; 3]) };
        m.emission = std::array::from_fn(|c| m.emission[c] + m.reflectance[c] * e[c] + m.transmittance[c] * other[c]);
        materials.push(m);
        p.material = i as u32;
    }
    local.materials = materials;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Radical inverses fill [0, 1) as the Halton sequence does.
    #[test]
    fn radical_inverse_values() {
        assert_eq!(radical_inverse(0, 2), 0.0);
        assert_eq!(radical_inverse(1, 2), 0.5);
        assert_eq!(radical_inverse(3, 2), 0.75);
        assert!((radical_inverse(1, 3) - 1.0 / 3.0).abs() < 1e-15);
        assert!((radical_inverse(5, 3) - (2.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-15);
    }

    /// An unoccluded polygon gets `E·cos` exactly from every source, its back side (two-sided)
    /// the sources behind it.
    #[test]
    fn unoccluded_polygon_gets_e_cos() {
        let p = Poly::quad(DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y);
        let sun = DistantSource { toward: DVec3::new(0.6, 0.0, -0.8), irradiance: [100.0, 50.0, 10.0], sharp: true, patch: None };
        let below = DistantSource { toward: DVec3::Z, irradiance: [7.0; 3], sharp: false, patch: None };
        let (front, back) = polygon_irradiance(&p, true, 16, 3, &[sun, below], (1e-6, 10.0), &|_, _| true);
        for c in 0..3 {
            assert!((front[c] - sun.irradiance[c] * 0.8).abs() < 1e-12, "{front:?}");
            assert!((back[c] - 7.0).abs() < 1e-12, "{back:?}");
        }
        let (front, back) = polygon_irradiance(&p, false, 16, 3, &[sun, below], (1e-6, 10.0), &|_, _| false);
        assert_eq!((front, back), ([0.0; 3], [0.0; 3]));
    }
}
