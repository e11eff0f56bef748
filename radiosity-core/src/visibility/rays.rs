//! The ray caster and the stratified visibility estimate of a link.

use crate::geom::DVec3;
use crate::hierarchy::Hierarchy;
use crate::scene::Scene;
use glam::Vec3A;
use obvhs::{BvhBuildParams, cwbvh::CwBvh, cwbvh::builder::build_cwbvh_from_tris, ray::Ray, triangle::Triangle};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Fraction of the segment length left out at each end, so that the endpoints' neighbours that touch
/// them (a wall meeting the floor) do not occlude.
pub const SEGMENT_END_EPS: f32 = 1e-5;

/// Smallest magnitude given to a ray direction's component: the BVH traversal divides by the
/// components, and an exact zero can make it miss hits on faces aligned with the ray.
pub const MIN_DIRECTION_COMPONENT: f64 = 1e-9;

/// `dir` normalised for the traversal, with every component of magnitude below
/// [`MIN_DIRECTION_COMPONENT`] (an exact zero above all) given that magnitude and its sign.
fn ray_direction(dir: DVec3) -> Vec3A {
    let d = dir.normalize_or_zero();
    let nudge = |x: f64| (if x.abs() < MIN_DIRECTION_COMPONENT { MIN_DIRECTION_COMPONENT.copysign(x) } else { x }) as f32;
    Vec3A::new(nudge(d.x), nudge(d.y), nudge(d.z))
}

/// Regularisation of the kernel weights of visibility samples, relative to the squared sum of the
/// two elements' radii (keeps one near-contact sample from dominating).
pub const KERNEL_REGULARISATION: f64 = 1e-4;

/// Visibility sampling settings.
#[derive(Clone, Copy, Debug)]
pub struct VisibilityConfig {
    /// Rays per link.
    pub rays: u32,
    /// Seed of the per-link random sequences.
    pub seed: u64,
}

impl Default for VisibilityConfig {
    fn default() -> Self {
        VisibilityConfig { rays: 16, seed: 1 }
    }
}

/// A small, fast, seedable generator (SplitMix64). Written here because a link needs a generator
/// derived from `(seed, source, receiver)` without any shared state, which is three lines.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed and two ids.
    #[must_use]
    pub fn for_link(seed: u64, a: u32, b: u32) -> Rng {
        let mut r = Rng(seed ^ ((a as u64) << 32 | b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        r.next_u64();
        r
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// Ray caster over the input triangles of a scene.
pub struct RayCaster {
    bvh: CwBvh,
    triangles: Vec<Triangle>,
    /// Input polygon of each triangle, in BVH primitive order.
    tri_polygon: Vec<u32>,
    frame: BvhFrame,
    rays_cast: RayCount,
}

/// The normalised frame an `f32` BVH is built in: centred on the bounds, diagonal 1, so that
/// `f32` keeps its precision (and obvhs's fixed node epsilon its meaning) at any scene scale.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BvhFrame {
    center: DVec3,
    /// 1 / the bounds' diagonal (1 for empty or point bounds): frame lengths over this are
    /// scene lengths.
    pub(crate) inv_scale: f64,
}

impl BvhFrame {
    pub(crate) fn of(bounds: &crate::geom::Aabb) -> BvhFrame {
        let diag = bounds.diagonal();
        BvhFrame { center: bounds.center(), inv_scale: if diag > 0.0 { 1.0 / diag } else { 1.0 } }
    }

    /// `p` (scene coordinates) in the frame, in `f32`.
    pub(crate) fn point(&self, p: DVec3) -> Vec3A {
        let q = (p - self.center) * self.inv_scale;
        Vec3A::new(q.x as f32, q.y as f32, q.z as f32)
    }
}

/// A count of rays cast from many threads: one cache-line-sized slot per worker thread, so that
/// counting every ray does not bounce one cache line between cores (a shared counter cost 15% of
/// an instanced tree solve on two threads).
struct RayCount {
    slots: Box<[Slot]>,
}

#[repr(align(128))]
#[derive(Default)]
struct Slot(AtomicU64);

/// Slots of a [`RayCount`]: threads beyond it share slots (still correct, only slower).
const RAY_COUNT_SLOTS: usize = 64;

impl RayCount {
    fn new() -> RayCount {
        RayCount { slots: (0..RAY_COUNT_SLOTS).map(|_| Slot::default()).collect() }
    }

    #[inline]
    fn add(&self, n: u64) {
        let slot = rayon::current_thread_index().map_or(0, |i| i + 1) % RAY_COUNT_SLOTS;
        let _ = self.slots[slot].0.fetch_add(n, Ordering::Relaxed);
    }

    fn total(&self) -> u64 {
        self.slots.iter().map(|s| s.0.load(Ordering::Relaxed)).sum()
    }
}

impl RayCaster {
    /// Builds the BVH over every polygon of `scene` (quads as two triangles).
    #[must_use]
    pub fn new(scene: &Scene) -> RayCaster {
        let bounds = scene.bounds();
        let frame = BvhFrame::of(&bounds);
        let to_f32 = |p: DVec3| frame.point(p);
        let mut tris = Vec::with_capacity(scene.polygons.len() * 2);
        let mut owner = Vec::with_capacity(scene.polygons.len() * 2);
        for (i, p) in scene.polygons.iter().enumerate() {
            let v = p.poly.vertices();
            for k in 1..v.len() - 1 {
                tris.push(Triangle { v0: to_f32(v[0]), v1: to_f32(v[k]), v2: to_f32(v[k + 1]) });
                owner.push(i as u32);
            }
        }
        let mut core_time = std::time::Duration::ZERO;
        let bvh =
            if tris.is_empty() { CwBvh::default() } else { build_cwbvh_from_tris(&tris, BvhBuildParams::medium_build(), &mut core_time) };
        // Reorder triangles into BVH primitive order so the callback indexes them directly.
        let (triangles, tri_polygon) = bvh.primitive_indices.iter().map(|&i| (tris[i as usize], owner[i as usize])).unzip();
        RayCaster { bvh, triangles, tri_polygon, frame, rays_cast: RayCount::new() }
    }

    /// Number of rays cast so far.
    #[must_use]
    pub fn rays_cast(&self) -> u64 {
        self.rays_cast.total()
    }

    fn to_local(&self, p: DVec3) -> Vec3A {
        self.frame.point(p)
    }

    /// True when the open segment `a`–`b` meets no triangle other than those of polygons `skip_a`, `skip_b`.
    #[must_use]
    pub fn segment_clear(&self, a: DVec3, b: DVec3, skip_a: u32, skip_b: u32) -> bool {
        self.rays_cast.add(1);
        self.segment_clear_uncounted(a, b, skip_a, skip_b)
    }

    /// [`RayCaster::segment_clear`] without counting the segment in [`RayCaster::rays_cast`].
    #[must_use]
    pub fn segment_clear_uncounted(&self, a: DVec3, b: DVec3, skip_a: u32, skip_b: u32) -> bool {
        self.segment_clear_skipping(a, b, &[skip_a, skip_b])
    }

    /// True when the open segment `a`–`b` meets no triangle of a polygon outside `skip` (not
    /// counted in [`RayCaster::rays_cast`]).
    #[must_use]
    pub fn segment_clear_skipping(&self, a: DVec3, b: DVec3, skip: &[u32]) -> bool {
        if self.triangles.is_empty() {
            return true;
        }
        let (la, lb) = (self.to_local(a), self.to_local(b));
        let d = lb - la;
        let len = d.length();
        if len.is_nan() || len <= 0.0 {
            return true;
        }
        let dir = d / len;
        let ray = Ray::new(la, dir, len * SEGMENT_END_EPS, len * (1.0 - SEGMENT_END_EPS));
        self.bvh.ray_traverse_miss(ray, |ray, id| {
            if skip.contains(&self.tri_polygon[id]) { f32::INFINITY } else { self.triangles[id].intersect(ray) }
        })
    }

    /// Closest hit along a ray in scene coordinates: `(distance, input polygon)`. Direction
    /// components that are exactly zero are nudged (see `ray_direction`).
    #[must_use]
    pub fn closest_hit(&self, origin: DVec3, dir: DVec3) -> Option<(f64, u32)> {
        if self.triangles.is_empty() {
            return None;
        }
        let ray = Ray::new(self.to_local(origin), ray_direction(dir), 0.0, f32::INFINITY);
        let mut hit = obvhs::ray::RayHit::none();
        if self.bvh.ray_traverse(ray, &mut hit, |ray, id| self.triangles[id].intersect(ray)) {
            Some((hit.t as f64 / self.frame.inv_scale, self.tri_polygon[hit.primitive_id as usize]))
        } else {
            None
        }
    }

    /// [`RayCaster::closest_hit`] among the input polygons that `accept` takes: the others let the
    /// ray through (the renderer sees through the backs of one-sided surfaces this way).
    #[must_use]
    pub fn closest_hit_where(&self, origin: DVec3, dir: DVec3, accept: impl Fn(u32) -> bool) -> Option<(f64, u32)> {
        if self.triangles.is_empty() {
            return None;
        }
        let ray = Ray::new(self.to_local(origin), ray_direction(dir), 0.0, f32::INFINITY);
        let mut hit = obvhs::ray::RayHit::none();
        let found = self.bvh.ray_traverse(ray, &mut hit, |ray, id| {
            if accept(self.tri_polygon[id]) { self.triangles[id].intersect(ray) } else { f32::INFINITY }
        });
        found.then(|| (hit.t as f64 / self.frame.inv_scale, self.tri_polygon[hit.primitive_id as usize]))
    }

    /// True when the ray from `origin` along `dir` (scene coordinates) meets no triangle: an
    /// occlusion query, cheaper than [`RayCaster::closest_hit`]. Direction components that are
    /// exactly zero are nudged (see `ray_direction`).
    #[must_use]
    pub fn ray_clear(&self, origin: DVec3, dir: DVec3) -> bool {
        self.rays_cast.add(1);
        self.ray_clear_uncounted(origin, dir)
    }

    /// True when the ray from `origin` along `dir` meets no triangle of a polygon other than
    /// `skip`, however near `origin` (counted in [`RayCaster::rays_cast`]): a shadow ray toward a
    /// distant source. A segment to a far point ends its search a fixed share of its length
    /// short of both ends ([`SEGMENT_END_EPS`]), 0.6 mm on a canopy of 14 m, so that a leaf
    /// crossing another was lit along the crossing line where the other shades it.
    #[must_use]
    pub fn ray_clear_skipping(&self, origin: DVec3, dir: DVec3, skip: u32) -> bool {
        self.rays_cast.add(1);
        self.ray_clear_skipping_uncounted(origin, dir, skip)
    }

    /// [`RayCaster::ray_clear`] without counting the ray in [`RayCaster::rays_cast`] (rays that
    /// analyse the scene rather than compute visibility).
    #[must_use]
    pub fn ray_clear_uncounted(&self, origin: DVec3, dir: DVec3) -> bool {
        self.ray_clear_skipping_uncounted(origin, dir, crate::hierarchy::NONE)
    }

    /// [`RayCaster::ray_clear_skipping`] without counting the ray.
    fn ray_clear_skipping_uncounted(&self, origin: DVec3, dir: DVec3, skip: u32) -> bool {
        if self.triangles.is_empty() {
            return true;
        }
        let ray = Ray::new(self.to_local(origin), ray_direction(dir), 0.0, f32::INFINITY);
        self.bvh
            .ray_traverse_miss(ray, |ray, id| if self.tri_polygon[id] == skip { f32::INFINITY } else { self.triangles[id].intersect(ray) })
    }

    /// Kernel-weighted visibility between `source` and `receiver` against every triangle of the
    /// scene (see [`sampled_visibility`]).
    #[must_use]
    pub fn visibility(&self, h: &Hierarchy, source: u32, receiver: u32, config: &VisibilityConfig) -> f64 {
        // A segment ends on a surface, where the other side of a two-sided one lies in the same
        // plane: in the BVH's f32 frame the end of a short segment can land on it, and light
        // between leaves crossing each other (the shortest segments, and the heaviest in the
        // kernel's weights) was taken for blocked. The other sides are left out with the sides.
        let twin = |p: u32| h.twin.get(p as usize).copied().unwrap_or(crate::hierarchy::NONE);
        sampled_visibility(h, source, receiver, config, |pa, pb, poly_a, poly_b| {
            self.rays_cast.add(1);
            self.segment_clear_skipping(pa, pb, &[poly_a, twin(poly_a), poly_b, twin(poly_b)])
        })
    }
}

/// Rays [`escape_fraction`] casts.
pub const ESCAPE_SAMPLES: u32 = 4096;
/// How far from its surface (relative to the scene's diagonal) an escape ray starts, and how far a
/// touching surface may be for the point to count as in contact.
pub const ESCAPE_OFFSET_REL: f64 = 2e-4;

/// The fraction of light leaving the scene's surfaces that escapes it: rays from points spread
/// over every polygon's front side in proportion to its area, in cosine-distributed directions,
/// that meet nothing ([`ESCAPE_SAMPLES`] rays, stratified, seeded). A point where another surface
/// touches the polygon's front (a box standing on the floor) sends nothing. 0 for a closed scene
/// (up to rays slipping through shared edges, a few in a million).
#[must_use]
pub fn escape_fraction(h: &Hierarchy, caster: &RayCaster, seed: u64) -> f64 {
    let n = ESCAPE_SAMPLES;
    // obvhs ignores hits nearer than 1e-4 of the frame (the scene's diagonal): the offset is twice
    // that.
    let offset = ESCAPE_OFFSET_REL * h.get(h.root).bounds.diagonal().max(f64::MIN_POSITIVE);
    let escaped = (0..n)
        .into_par_iter()
        .filter(|&i| {
            let mut rng = Rng::for_link(seed, i, u32::MAX);
            let w = (f64::from(i) + rng.next_f64()) / f64::from(n);
            let (p, poly) = h.sample_point(h.root, rng.next_f64(), rng.next_f64(), w);
            let normal = h.get(poly).normal;
            // Cosine-distributed direction about the normal.
            let (u1, u2) = (rng.next_f64(), rng.next_f64());
            let (r, phi) = (u1.sqrt(), 2.0 * std::f64::consts::PI * u2);
            let t = if normal.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
            let a = normal.cross(t).normalize();
            let b = normal.cross(a);
            let dir = a * (r * phi.cos()) + b * (r * phi.sin()) + normal * (1.0 - u1).max(0.0).sqrt();
            // A face in contact with another (a table leg's foot on the floor) sends nothing out:
            // the ray would start beyond the surface it touches. A face's own back (a leaf's other
            // side, the polygon next to it) is not such a contact.
            let back = back_of(h, poly).unwrap_or(poly);
            let in_contact = !caster.segment_clear_uncounted(p - normal * offset, p + normal * offset, poly, back);
            !in_contact && caster.ray_clear_uncounted(p + normal * offset, dir)
        })
        .count();
    f64::from(escaped as u32) / f64::from(n)
}

/// The polygon next to `poly` (before or after it) that is its back ([`crate::geom::Poly::is_back_of`]):
/// the other side of a two-sided surface, which [`crate::scene::Scene::pair_two_sided`] and
/// flattening put next to each other.
#[must_use]
pub fn back_of(h: &Hierarchy, poly: u32) -> Option<u32> {
    let front = h.get(poly).poly()?;
    [poly.checked_sub(1), poly.checked_add(1).filter(|&q| q < h.n_polygons)]
        .into_iter()
        .flatten()
        .find(|&q| h.get(q).poly().is_some_and(|b| b.is_back_of(front)))
}

/// Visibility between the surfaces of `source` and `receiver` from `config.rays` stratified
/// segments, `clear(a, b, polygon_a, polygon_b)` deciding whether one is unoccluded. Jittered strata
/// on both ends, the receiver's strata in a shuffled order (Fisher–Yates). Each segment is weighted
/// by the transfer kernel cosθ_s·cosθ_r / r² between its endpoints (regularised by
/// [`KERNEL_REGULARISATION`]), so the result estimates ∫∫K·V / ∫∫K (what multiplies the unoccluded
/// form factor) rather than the plain fraction of clear segments, which is biased where the kernel
/// and the occlusion vary together (contact shadows); the plain fraction is returned when no segment
/// carries weight. Deterministic for a given seed, independent of thread scheduling; every caster
/// (the global BVH, shaft candidate lists) samples the same segments through this function.
pub fn sampled_visibility(
    h: &Hierarchy,
    source: u32,
    receiver: u32,
    config: &VisibilityConfig,
    mut clear: impl FnMut(DVec3, DVec3, u32, u32) -> bool,
) -> f64 {
    let n = config.rays.max(1) as usize;
    let mut rng = Rng::for_link(config.seed, source, receiver);
    let k = (n as f64).sqrt().ceil() as usize;
    let mut order: Vec<u32> = (0..(k * k) as u32).collect();
    for i in (1..order.len()).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    let reg = KERNEL_REGULARISATION * (h.get(source).radius + h.get(receiver).radius).powi(2);
    let (mut n_clear, mut w_clear, mut w_all) = (0usize, 0.0f64, 0.0f64);
    for i in 0..n {
        let cell_s = i % (k * k);
        let cell_r = order[i % (k * k)] as usize;
        let su = ((cell_s % k) as f64 + rng.next_f64()) / k as f64;
        let sv = ((cell_s / k) as f64 + rng.next_f64()) / k as f64;
        let ru = ((cell_r % k) as f64 + rng.next_f64()) / k as f64;
        let rv = ((cell_r / k) as f64 + rng.next_f64()) / k as f64;
        let (pa, poly_a) = h.sample_point(source, su, sv, rng.next_f64());
        let (pb, poly_b) = h.sample_point(receiver, ru, rv, rng.next_f64());
        let d = pb - pa;
        let r2 = d.length_squared();
        let (na, nb) = (h.get(poly_a).normal, h.get(poly_b).normal);
        let w = (na.dot(d).max(0.0) * (-nb.dot(d)).max(0.0)) / (r2 * (r2 + reg));
        if clear(pa, pb, poly_a, poly_b) {
            n_clear += 1;
            w_clear += w;
        }
        w_all += w;
    }
    if w_all > 0.0 && w_all.is_finite() { w_clear / w_all } else { n_clear as f64 / n as f64 }
}
