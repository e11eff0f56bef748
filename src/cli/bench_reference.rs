//! The full solve of `bench instancing` kept on disk (`--reference FILE`): it takes minutes and
//! hundreds of MB on the age-30 tree, and does not change while the instanced solver does.

use radiosity::instancing::PolygonMeans;
use radiosity::instancing::bench::{BenchRow, load_means};
use std::path::{Path, PathBuf};

/// The figures file kept beside the means file `file`.
fn figures_path(file: &Path) -> PathBuf {
    let mut name = file.as_os_str().to_owned();
    name.push(".json");
    PathBuf::from(name)
}

/// The kept reference for `(age, seed, eps)` in `file`, if there is one; an error when `file`
/// holds a reference of another tree or threshold.
pub fn load(file: &Path, age: u32, seed: u64, eps: f64) -> anyhow::Result<Option<(BenchRow, PolygonMeans)>> {
    let figures = figures_path(file);
    if !file.exists() || !figures.exists() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&figures)?;
    let doc: serde_json::Value = serde_json::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", figures.display()))?;
    let (kept_age, kept_seed, kept_eps) = (doc["age"].as_u64(), doc["seed"].as_u64(), doc["eps"].as_f64());
    anyhow::ensure!(
        kept_age == Some(u64::from(age)) && kept_seed == Some(seed) && kept_eps == Some(eps),
        "{}: reference of tree age {kept_age:?} seed {kept_seed:?} at eps {kept_eps:?}, not of age {age} seed {seed} at eps {eps}",
        file.display()
    );
    let row: BenchRow = serde_json::from_value(doc["row"].clone()).map_err(|e| anyhow::anyhow!("{}: {e}", figures.display()))?;
    let means = load_means(file)?;
    anyhow::ensure!(means.radiosity.len() as u64 == row.polygons, "{}: truncated", file.display());
    Ok(Some((row, means)))
}

/// Keeps the full solve's per-polygon means (already written to `means_file`) in `file`, with its
/// figures beside it.
pub fn keep(means_file: &Path, file: &Path, row: &BenchRow, age: u32, seed: u64, eps: f64) -> anyhow::Result<()> {
    std::fs::copy(means_file, file).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", file.display()))?;
    let text = serde_json::to_string(&serde_json::json!({"age": age, "seed": seed, "eps": eps, "row": row}))?;
    radiosity::output::atomic::write_bytes(&figures_path(file), text)?;
    Ok(())
}
