//! Measurements for `bench instancing`: one solve (full or instanced) with its time, peak memory and
//! link count, and the per-polygon radiosity saved so that two solves run in separate processes
//! (peak RSS is per process) can be compared.

use super::InstancingError;
use super::model::InstancedScene;
use super::solver::{InstancedConfig, PolygonMeans, solve_full, solve_instanced};
use crate::output::peak_rss_bytes;
use std::io::Read;
use std::path::Path;

/// One measured solve.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct BenchRow {
    /// `full` or `instanced`.
    pub method: String,
    /// BF threshold used.
    pub eps: f64,
    /// Flattened polygons of the scene (two-sided as pairs).
    pub polygons: u64,
    /// Wall-clock seconds of the solve (loading excluded).
    pub seconds: f64,
    /// Peak resident set size of the process after the solve, bytes (0 when unknown).
    pub peak_rss_bytes: u64,
    /// Links (summed over local problems for the instanced solve).
    pub links: u64,
    /// Local problems solved (1 for the full solve).
    pub local_solves: u64,
}

/// Solves `scene` fully (flattened) and measures it; returns the row and the per-polygon means.
pub fn bench_full(scene: &InstancedScene, config: &InstancedConfig) -> Result<(BenchRow, PolygonMeans), InstancingError> {
    let t = std::time::Instant::now();
    let (means, links) = solve_full(scene, config)?;
    let row = BenchRow {
        method: "full".into(),
        eps: config.bf.eps,
        polygons: means.radiosity.len() as u64,
        seconds: t.elapsed().as_secs_f64(),
        peak_rss_bytes: peak_rss_bytes().unwrap_or(0),
        links,
        local_solves: 1,
    };
    Ok((row, means))
}

/// Solves `scene` with instances and measures it. With `keep_means` the per-polygon means are kept
/// for comparison (memory linear in the polygons, 32 bytes each); without, the solve streams to
/// nothing and only the figures are returned.
pub fn bench_instanced(
    scene: &InstancedScene,
    config: &InstancedConfig,
    keep_means: bool,
) -> Result<(BenchRow, Option<PolygonMeans>), InstancingError> {
    struct Discard;
    impl super::solver::RadiositySink for Discard {
        fn polygon(&mut self, _: &super::solver::PolygonInfo, _: &[super::solver::Leaf]) -> Result<(), InstancingError> {
            Ok(())
        }
    }
    let t = std::time::Instant::now();
    let mut means = PolygonMeans::default();
    let stats = if keep_means { solve_instanced(scene, config, &mut means)? } else { solve_instanced(scene, config, &mut Discard)? };
    let row = BenchRow {
        method: "instanced".into(),
        eps: config.bf.eps,
        polygons: stats.polygons_out,
        seconds: t.elapsed().as_secs_f64(),
        peak_rss_bytes: peak_rss_bytes().unwrap_or(0),
        links: stats.links,
        local_solves: stats.local_solves,
    };
    Ok((row, keep_means.then_some(means)))
}

/// Writes per-polygon means as little-endian `f64` (r, g, b, area) records.
pub fn save_means(path: &Path, means: &PolygonMeans) -> Result<(), InstancingError> {
    let mut out = Vec::with_capacity(32 * means.radiosity.len());
    for (b, a) in means.radiosity.iter().zip(&means.area) {
        for x in [b[0], b[1], b[2], *a] {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    crate::output::atomic::write_bytes(path, out).map_err(|e| InstancingError::io(path, "cannot write file", e))
}

/// Reads what [`save_means`] wrote.
pub fn load_means(path: &Path) -> Result<PolygonMeans, InstancingError> {
    let mut bytes = Vec::new();
    std::fs::File::open(path).and_then(|mut f| f.read_to_end(&mut bytes)).map_err(|e| InstancingError::io(path, "cannot read file", e))?;
    let mut means = PolygonMeans::default();
    for rec in bytes.chunks_exact(32) {
        let x: [f64; 4] = std::array::from_fn(|k| f64::from_le_bytes(rec[8 * k..8 * k + 8].try_into().expect("8 bytes")));
        means.radiosity.push([x[0], x[1], x[2]]);
        means.area.push(x[3]);
    }
    Ok(means)
}
