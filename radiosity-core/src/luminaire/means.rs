//! Each polygon's mean direct light, and the luminous flux the surfaces receive.

use crate::hierarchy::Hierarchy;

/// Each polygon's mean direct irradiance ([`Hierarchy::direct`], area-weighted over its leaves);
/// empty without luminaires or distant sources.
#[must_use]
pub fn polygon_direct_means(h: &Hierarchy) -> Vec<[f64; 3]> {
    if h.direct.is_empty() {
        return Vec::new();
    }
    let mut sums = vec![([0.0; 3], 0.0); h.n_polygons as usize];
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let (Some(p), Some(d)) = (e.polygon(), h.direct.get(leaf as usize)) else { continue };
        let s = &mut sums[p as usize];
        s.1 += e.area;
        for c in 0..3 {
            s.0[c] += e.area * d[c];
        }
    }
    sums.into_iter().map(|(d, a)| if a > 0.0 { d.map(|v| v / a) } else { [0.0; 3] }).collect()
}

/// The luminous flux (lm) of all luminaires of `h` arriving on its surfaces (front sides), from the
/// leaves' direct illuminance: equal to the luminaires' flux in a closed scene.
#[must_use]
pub fn flux_received(h: &Hierarchy) -> f64 {
    if h.direct.is_empty() {
        return 0.0;
    }
    h.leaves().filter(|&l| !h.get(l).is_cluster()).map(|l| h.get(l).area * h.direct[l as usize][1]).sum()
}
