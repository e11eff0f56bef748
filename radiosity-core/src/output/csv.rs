//! `patches.csv`: one row per input polygon, in input order:
//! `index,group,material,area,b_r,b_g,b_b,h_r,h_g,h_b,units` (area-weighted means over the polygon's
//! leaves; `units` is `W/m2`, or `lm/m2` in photometric scenes: radiosity in lm/m², irradiance in lx).

use crate::hierarchy::Hierarchy;
use crate::scene::Scene;
use crate::solve::Solution;
use std::io::Write;

/// Area-weighted radiosity and irradiance of one input polygon.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PolygonResult {
    /// Area (scene units²).
    pub area: f64,
    /// Mean radiosity B (W/m²).
    pub b: [f64; 3],
    /// Mean front-side irradiance H (W/m²).
    pub h: [f64; 3],
}

/// Means over each polygon's leaves, in input order.
#[must_use]
pub fn polygon_results(h: &Hierarchy, solution: &Solution) -> Vec<PolygonResult> {
    let mut out = vec![PolygonResult::default(); h.n_polygons as usize];
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let Some(p) = e.polygon() else { continue };
        let r = &mut out[p as usize];
        r.area += e.area;
        for c in 0..3 {
            r.b[c] += e.area * solution.radiosity[leaf as usize][c];
            r.h[c] += e.area * solution.irradiance[leaf as usize][c];
        }
    }
    for r in &mut out {
        if r.area > 0.0 {
            r.b = r.b.map(|v| v / r.area);
            r.h = r.h.map(|v| v / r.area);
        }
    }
    out
}

/// Writes `patches.csv`.
pub fn write_patches_csv(w: &mut impl Write, scene: &Scene, results: &[PolygonResult]) -> std::io::Result<()> {
    writeln!(w, "index,group,material,area,b_r,b_g,b_b,h_r,h_g,h_b,units")?;
    let units = scene.units.density_label();
    for (i, (p, r)) in scene.polygons.iter().zip(results).enumerate() {
        writeln!(
            w,
            "{i},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{units}",
            csv_field(&scene.groups[p.group as usize]),
            csv_field(&scene.materials[p.material as usize].name),
            r.area,
            r.b[0],
            r.b[1],
            r.b[2],
            r.h[0],
            r.h[1],
            r.h[2]
        )?;
    }
    Ok(())
}

/// `s` as one CSV field (quoted when it holds a comma, quote or line break).
#[must_use]
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_owned() }
}
