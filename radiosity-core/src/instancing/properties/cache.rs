//! The on-disk cache of the properties, one JSON file per prototype and key.

use super::entry::RadiativeProperties;
use super::key::cache_key;
use super::measure::compute_flat;
use super::settings::PropertyConfig;
use crate::instancing::InstancingError;
use crate::instancing::flatten::{FlattenOptions, flatten_prototype};
use crate::instancing::model::{InstancedScene, PrototypeId, Transform};
use std::path::{Path, PathBuf};

/// An on-disk cache of [`RadiativeProperties`], one JSON file per entry named
/// `<prototype>-<key>.json`; the key hashes the prototype's content and the configuration, so a
/// changed prototype misses the cache instead of reading stale properties.
#[derive(Clone, Debug)]
pub struct PropertyCache {
    /// Folder of the entries (created on first write).
    pub dir: PathBuf,
}

/// Whether [`PropertyCache::get_or_compute`] read the entry or computed it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CacheOutcome {
    /// Read from disk.
    Hit,
    /// Computed (and written).
    Computed,
}

impl PropertyCache {
    /// A cache in `dir`.
    #[must_use]
    pub fn new(dir: &Path) -> PropertyCache {
        PropertyCache { dir: dir.to_owned() }
    }

    /// Path of the entry for `name` and `key`.
    #[must_use]
    pub fn entry_path(&self, name: &str, key: &str) -> PathBuf {
        let safe: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
        self.dir.join(format!("{safe}-{key}.json"))
    }

    /// The properties of prototype `id`: read when an entry with the same key exists, computed and
    /// written otherwise. `hashes` are [`content_hashes`](super::content_hashes) of the scene.
    pub fn get_or_compute(
        &self,
        scene: &InstancedScene,
        hashes: &[u64],
        id: PrototypeId,
        config: &PropertyConfig,
    ) -> Result<(RadiativeProperties, CacheOutcome), InstancingError> {
        let name = &scene.prototype(id).name;
        let key = cache_key(hashes[id as usize], config);
        let path = self.entry_path(name, &key);
        if let Ok(text) = std::fs::read_to_string(&path) {
            let props: RadiativeProperties =
                serde_json::from_str(&text).map_err(|e| InstancingError::Cache { path: path.clone(), msg: e.to_string() })?;
            if props.key == key {
                return Ok((props, CacheOutcome::Hit));
            }
        }
        let flat = flatten_prototype(scene, id, &Transform::IDENTITY, &FlattenOptions { two_sided_pairs: false })?;
        let props = compute_flat(&flat, name, key, config);
        std::fs::create_dir_all(&self.dir).map_err(|e| InstancingError::io(&self.dir, "cannot create folder", e))?;
        let text = serde_json::to_string(&props).map_err(|e| InstancingError::Cache { path: path.clone(), msg: e.to_string() })?;
        crate::output::atomic::write_bytes(&path, text).map_err(|e| InstancingError::io(&path, "cannot write file", e))?;
        Ok((props, CacheOutcome::Computed))
    }
}
