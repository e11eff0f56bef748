//! The solve figures between processes: encoded, decoded, and added up over processes.

use super::wire::Reader;
use crate::instancing::InstancingError;
use crate::instancing::solver::config::InstancedStats;

/// Encodes solve figures (and the sender's peak RSS) for [`decode_stats`].
#[must_use]
pub fn encode_stats(s: &InstancedStats, peak_rss_bytes: u64) -> Vec<u8> {
    let words = [
        s.local_solves,
        s.polygons_out,
        s.leaves_out,
        s.links,
        s.max_local_polygons as u64,
        s.max_local_links,
        s.cache_hits,
        s.cache_computed,
        s.levels_reused,
        s.levels_cached_peak_bytes,
        s.seconds.to_bits(),
        peak_rss_bytes,
    ];
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// Decodes [`encode_stats`]: the figures and the sender's peak RSS.
pub fn decode_stats(bytes: &[u8]) -> Result<(InstancedStats, u64), InstancingError> {
    let mut r = Reader { bytes, at: 0 };
    let mut w = [0u64; 12];
    for x in &mut w {
        *x = r.u64()?;
    }
    r.end()?;
    let s = InstancedStats {
        local_solves: w[0],
        polygons_out: w[1],
        leaves_out: w[2],
        links: w[3],
        max_local_polygons: w[4] as usize,
        max_local_links: w[5],
        cache_hits: w[6],
        cache_computed: w[7],
        levels_reused: w[8],
        levels_cached_peak_bytes: w[9],
        seconds: f64::from_bits(w[10]),
    };
    Ok((s, w[11]))
}

/// Adds the figures of `other` (another process's part of the solve) to `total`: counts add up,
/// largest figures take the larger; the wall-clock time stays `total`'s.
pub fn merge_stats(total: &mut InstancedStats, other: &InstancedStats) {
    total.local_solves += other.local_solves;
    total.polygons_out += other.polygons_out;
    total.leaves_out += other.leaves_out;
    total.links += other.links;
    total.max_local_polygons = total.max_local_polygons.max(other.max_local_polygons);
    total.max_local_links = total.max_local_links.max(other.max_local_links);
    total.cache_hits += other.cache_hits;
    total.cache_computed += other.cache_computed;
    total.levels_reused += other.levels_reused;
    total.levels_cached_peak_bytes = total.levels_cached_peak_bytes.max(other.levels_cached_peak_bytes);
}
