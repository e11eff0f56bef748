//! The level cache: levels kept for reuse by later instances of the same prototype that lie a
//! similarity away and whose light is of the same brightness class.

use super::direct::DirectSplit;
use super::level::Level;
use crate::geom::DVec3;
use crate::instancing::model::PrototypeId;
use glam::{DMat3, DMat4};
use std::collections::HashMap;

/// The brightest irradiance (per channel) that `field` brings to a surface facing any of `dirs`,
/// ignoring blockers.
fn irradiance_bound(dirs: &[DVec3], field: &[[f64; 3]]) -> [f64; 3] {
    let mut best = [0.0f64; 3];
    for n in dirs {
        let mut e = [0.0; 3];
        for (d, f) in dirs.iter().zip(field) {
            let cos = n.dot(*d);
            if cos > 0.0 {
                for c in 0..3 {
                    e[c] += f[c] * cos;
                }
            }
        }
        for c in 0..3 {
            best[c] = best[c].max(e[c]);
        }
    }
    best
}

/// The brightness class of a level's light: `⌈log₂ m⌉` of the largest channel `m` of its
/// [`irradiance_bound`], and the factor (in [1, 2)) that raises the light to the class's top. A level
/// is refined for its light raised to the top of its class, so that its refinement serves every
/// instance of the class (the BF criterion never asks for less refinement under brighter light),
/// and instances under much dimmer light get their own, coarser level.
fn brightness_class(bound: [f64; 3]) -> (i32, f64) {
    let m = bound.into_iter().fold(0.0, f64::max);
    if !(m > 0.0 && m.is_finite()) {
        return (i32::MIN, 1.0);
    }
    let class = m.log2().ceil() as i32;
    (class, 2f64.powi(class) / m)
}

/// The brightness class of a level's light `field` (in the directions `dirs`; `None` at the top),
/// with the factor that raises it to the class's top. The class bounds every polygon's light from
/// outside: the beams', and the traced direct light of a `split` (which a polygon may get
/// unattenuated where the beams are the instance's average).
pub(super) fn light_class(dirs: &[DVec3], field: Option<&[[f64; 3]]>, split: Option<&DirectSplit>) -> Option<(i32, f64)> {
    // The brightness class bounds every polygon's light from outside: the beams', and the
    // traced direct light (which a polygon may get unattenuated where the beams are the
    // instance's average).
    field.map(|field| {
        let mut bound = irradiance_bound(dirs, field);
        if let Some(split) = split {
            let rest = irradiance_bound(dirs, &split.rest);
            for c in 0..3 {
                let traced = split.traced.iter().map(|t| t[c]).fold(0.0, f64::max);
                bound[c] = bound[c].max(rest[c] + traced);
            }
        }
        brightness_class(bound)
    })
}

/// What a cached level is found by: its prototype, which of its instances were opened in place,
/// and the brightness class of its light.
pub(super) type LevelKey = (PrototypeId, Vec<bool>, i32);

/// Relative tolerance of `similarity`: how far from orthogonal the rotation part may be.
pub const SIMILARITY_TOLERANCE: f64 = 1e-6;

/// The motion from one instance's frame to another's, when it is a similarity.
#[derive(Clone, Copy, Debug)]
pub(super) struct Similarity {
    /// From the cached level's frame to the new instance's.
    pub(super) matrix: DMat4,
    /// Its rotation.
    pub(super) rotation: DMat3,
}

/// The similarity (rotation, uniform scale, translation; no mirror) that takes frame `from` to
/// frame `to`, if there is one: under it every form factor and visibility of a level is unchanged.
fn similarity(from: &DMat4, to: &DMat4) -> Option<Similarity> {
    let matrix = *to * from.inverse();
    let linear = DMat3::from_mat4(matrix);
    let det = linear.determinant();
    if !(det.is_finite() && det > 0.0) {
        return None;
    }
    let rotation = linear * det.cbrt().recip();
    let off = rotation.transpose() * rotation - DMat3::IDENTITY;
    let worst = off.to_cols_array().iter().fold(0.0f64, |a, x| a.max(x.abs()));
    (worst <= SIMILARITY_TOLERANCE).then_some(Similarity { matrix, rotation })
}

/// Levels kept for reuse, keyed by prototype and which of its instances were opened in place,
/// within a budget of bytes (least recently used evicted first).
pub(super) struct LevelCache {
    budget: usize,
    entries: HashMap<LevelKey, CachedLevel>,
    bytes: usize,
    pub(super) peak_bytes: usize,
    clock: u64,
}

struct CachedLevel {
    level: Level,
    /// World transform of the instance the level was built for.
    frame: DMat4,
    bytes: usize,
    last_used: u64,
}

impl LevelCache {
    pub(super) fn new(budget: usize) -> LevelCache {
        LevelCache { budget, entries: HashMap::new(), bytes: 0, peak_bytes: 0, clock: 0 }
    }

    /// A cached level usable for an instance at `frame`, as the
    /// motion from the cached instance to this one.
    pub(super) fn find(&mut self, key: &LevelKey, frame: &DMat4) -> Option<Similarity> {
        let entry = self.entries.get_mut(key)?;
        let s = similarity(&entry.frame, frame)?;
        self.clock += 1;
        entry.last_used = self.clock;
        Some(s)
    }

    pub(super) fn get(&mut self, key: &LevelKey) -> &mut Level {
        &mut self.entries.get_mut(key).expect("found before").level
    }

    /// Drops every cached level (the peak stays).
    pub(super) fn clear(&mut self) {
        self.entries.clear();
        self.bytes = 0;
    }

    /// Keeps `level` (replacing the entry of `key`) if it fits the budget, evicting the least
    /// recently used levels as needed.
    pub(super) fn insert(&mut self, key: LevelKey, level: Level, frame: DMat4) {
        if let Some(old) = self.entries.remove(&key) {
            self.bytes -= old.bytes;
        }
        let bytes = level.bytes();
        if bytes > self.budget {
            return;
        }
        while self.bytes + bytes > self.budget {
            let Some(oldest) = self.entries.iter().min_by_key(|(_, e)| e.last_used).map(|(k, _)| k.clone()) else { break };
            if let Some(e) = self.entries.remove(&oldest) {
                self.bytes -= e.bytes;
            }
        }
        self.clock += 1;
        let _ = self.entries.insert(key, CachedLevel { level, frame, bytes, last_used: self.clock });
        self.bytes += bytes;
        self.peak_bytes = self.peak_bytes.max(self.bytes);
    }
}
