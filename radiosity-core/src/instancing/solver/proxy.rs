//! Closed instances: each prototype's proxy box, from its radiative properties (cached on disk).

use super::config::InstancedStats;
use super::task::Closed;
use crate::geom::{Aabb, DVec3};
use crate::instancing::InstancingError;
use crate::instancing::face_transfer::BOX_FACES;
use crate::instancing::model::{InstancedScene, PrototypeId};
use crate::instancing::properties::{CacheOutcome, PropertyCache, PropertyConfig, RadiativeProperties};
use std::collections::HashMap;

/// Largest reflectance given to a proxy (the builder requires ρ < 1).
pub const MAX_PROXY_REFLECTANCE: f64 = 0.99;

/// Smallest extent of a proxy box on any axis, relative to its diagonal (flat prototypes such as a
/// single leaf still get a box with six faces of positive area).
pub const MIN_PROXY_EXTENT_REL: f64 = 1e-3;

/// A closed instance's stand-in, per prototype.
#[derive(Clone, Copy, Debug)]
pub(super) struct Proxy {
    /// Shrunk local box.
    pub(super) shrunk: Aabb,
    /// Mean escape albedo.
    pub(super) albedo: [f64; 3],
    /// Face transfer matrix of the prototype's box, row-major (see
    /// [`face_transfer`](crate::instancing::face_transfer)).
    pub(super) transfer: [[f64; 3]; BOX_FACES * BOX_FACES],
}

/// Centre and half-extents of `b` with every extent at least [`MIN_PROXY_EXTENT_REL`] of its
/// diagonal: the box a proxy is shrunk from.
pub(super) fn padded_half(b: &Aabb) -> (DVec3, DVec3) {
    let min_extent = MIN_PROXY_EXTENT_REL * b.diagonal().max(f64::MIN_POSITIVE);
    (b.center(), (0.5 * b.extent()).max(DVec3::splat(0.5 * min_extent)))
}

/// `b` padded as a proxy's box is (see [`padded_half`]).
pub(super) fn padded(b: &Aabb) -> Aabb {
    if b.is_empty() {
        return *b;
    }
    let (c, half) = padded_half(b);
    Aabb { min: c - half, max: c + half }
}

/// The proxy of a prototype with local box `local` and properties `props`.
pub(super) fn proxy_of(local: &Aabb, props: &RadiativeProperties) -> Proxy {
    let (c, half) = padded_half(local);
    let s = (1.0 - props.mean_transmittance()).clamp(0.0, 1.0).sqrt().max(MIN_PROXY_EXTENT_REL);
    let t = props.face_transfer();
    let transfer = std::array::from_fn(|k| t.get(k / BOX_FACES, k % BOX_FACES));
    Proxy { shrunk: Aabb { min: c - half * s, max: c + half * s }, albedo: props.mean_albedo(), transfer }
}

/// Gets the proxy of every prototype of the `closed` instances that has none yet, from its
/// properties: read from `cache` (or computed and stored there), or computed in memory.
#[allow(clippy::too_many_arguments)]
pub(super) fn ensure_proxies(
    scene: &InstancedScene,
    bounds: &[Aabb],
    hashes: &[u64],
    cache: Option<&PropertyCache>,
    closed: &[Closed],
    proxies: &mut HashMap<PrototypeId, Proxy>,
    stats: &mut InstancedStats,
    config: &PropertyConfig,
) -> Result<(), InstancingError> {
    for &(c, _, _, _) in closed {
        if proxies.contains_key(&c) {
            continue;
        }
        let props = match cache {
            Some(cache) => {
                let (props, outcome) = cache.get_or_compute(scene, hashes, c, config)?;
                match outcome {
                    CacheOutcome::Hit => stats.cache_hits += 1,
                    CacheOutcome::Computed => stats.cache_computed += 1,
                }
                props
            }
            None => {
                stats.cache_computed += 1;
                crate::instancing::properties::compute(scene, c, config)?
            }
        };
        let _ = proxies.insert(c, proxy_of(&bounds[c as usize], &props));
    }
    Ok(())
}
