//! The content hash of a prototype and the cache key of its entry: stable across runs and
//! platforms, blind to names.

use super::settings::{PhaseMethod, PropertyConfig};
use crate::geom::DVec3;
use crate::instancing::model::InstancedScene;
use crate::scene::Material;

/// Version of the cached file layout and of the estimators; part of the cache key.
/// 2: entries hold the face transfer matrix ([`super::face_transfer`](crate::instancing::face_transfer)).
pub const CACHE_VERSION: u32 = 2;

/// Content hash of every prototype: its own polygons, their materials' radiometry, and its
/// instances' transforms and prototypes' hashes (recursively). Names do not enter.
#[must_use]
pub fn content_hashes(scene: &InstancedScene) -> Vec<u64> {
    let mut out = vec![0u64; scene.prototypes.len()];
    for id in scene.bottom_up() {
        let p = scene.prototype(id);
        let mut h = Fnv::new();
        h.u64(p.polygons.len() as u64);
        for q in &p.polygons {
            for v in q.poly.vertices() {
                h.vec(*v);
            }
            h.material(&scene.materials[q.material as usize]);
        }
        h.u64(p.instances.len() as u64);
        for i in &p.instances {
            h.u64(out[i.prototype as usize]);
            for x in i.transform.matrix.to_cols_array() {
                h.f64(x);
            }
        }
        out[id as usize] = h.0;
    }
    out
}

/// Key of a prototype's cache entry: its content hash combined with the configuration.
#[must_use]
pub fn cache_key(content_hash: u64, config: &PropertyConfig) -> String {
    let mut h = Fnv::new();
    h.u64(u64::from(CACHE_VERSION));
    h.u64(content_hash);
    h.u64(u64::from(config.n_directions));
    h.u64(u64::from(config.rays_per_direction));
    h.u64(config.seed);
    match config.method {
        PhaseMethod::RandomWalk => h.u64(1),
        PhaseMethod::Radiosity { eps } => {
            h.u64(2);
            h.f64(eps);
        }
    }
    format!("{:016x}", h.0)
}

/// FNV-1a, 64 bits: stable across runs and platforms (unlike `std`'s hasher).
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn u64(&mut self, x: u64) {
        for b in x.to_le_bytes() {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    fn f64(&mut self, x: f64) {
        self.u64(x.to_bits());
    }
    fn vec(&mut self, v: DVec3) {
        self.f64(v.x);
        self.f64(v.y);
        self.f64(v.z);
    }
    fn material(&mut self, m: &Material) {
        for c in 0..3 {
            self.f64(m.reflectance[c]);
            self.f64(m.transmittance[c]);
            self.f64(m.emission[c]);
        }
        self.u64(u64::from(m.two_sided));
    }
}
