//! `patches.csv`: one row per input polygon, in input order:
//! `index,group,material,area,b_r,b_g,b_b,h_r,h_g,h_b,units,absorbed_r,absorbed_g,absorbed_b`
//! (area-weighted means over the polygon's leaves; `units` is `W/m2`, or `lm/m2` in photometric
//! scenes: radiosity in lm/m², irradiance in lx; `absorbed_*` the power the polygon's side absorbs,
//! W or lm). `groups.csv`: per group (OBJ object or group, MGF object, prototype),
//! `group,area,absorbed_r,absorbed_g,absorbed_b`.

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
    /// Power absorbed by the polygon's side, `A·(1 − ρ − t)·H` (W; what is neither reflected nor
    /// transmitted), summed over its leaves.
    pub absorbed: [f64; 3],
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
    for (p, r) in out.iter_mut().enumerate() {
        let (rho, t) = (h.reflectance[p], h.transmittance[p]);
        r.absorbed = std::array::from_fn(|c| (1.0 - rho[c] - t[c]) * r.h[c]);
        if r.area > 0.0 {
            r.b = r.b.map(|v| v / r.area);
            r.h = r.h.map(|v| v / r.area);
        }
    }
    out
}

/// Writes `groups.csv`: one row per group of the scene (in the scene's order, groups without
/// polygons left out), `group,area,absorbed_r,absorbed_g,absorbed_b` summed over its polygons.
pub fn write_groups_csv(w: &mut impl Write, scene: &Scene, results: &[PolygonResult]) -> std::io::Result<()> {
    let mut sums = vec![(0usize, 0.0, [0.0; 3]); scene.groups.len()];
    for (p, r) in scene.polygons.iter().zip(results) {
        let s = &mut sums[p.group as usize];
        s.0 += 1;
        s.1 += r.area;
        for c in 0..3 {
            s.2[c] += r.absorbed[c];
        }
    }
    writeln!(w, "group,area,absorbed_r,absorbed_g,absorbed_b")?;
    for (name, (n, area, a)) in scene.groups.iter().zip(sums) {
        if n > 0 {
            writeln!(w, "{},{:e},{:e},{:e},{:e}", csv_field(name), area, a[0], a[1], a[2])?;
        }
    }
    Ok(())
}

/// Writes `patches.csv`.
pub fn write_patches_csv(w: &mut impl Write, scene: &Scene, results: &[PolygonResult]) -> std::io::Result<()> {
    writeln!(w, "index,group,material,area,b_r,b_g,b_b,h_r,h_g,h_b,units,absorbed_r,absorbed_g,absorbed_b")?;
    let units = scene.units.density_label();
    for (i, (p, r)) in scene.polygons.iter().zip(results).enumerate() {
        writeln!(
            w,
            "{i},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{units},{:e},{:e},{:e}",
            csv_field(&scene.groups[p.group as usize]),
            csv_field(&scene.materials[p.material as usize].name),
            r.area,
            r.b[0],
            r.b[1],
            r.b[2],
            r.h[0],
            r.h[1],
            r.h[2],
            r.absorbed[0],
            r.absorbed[1],
            r.absorbed[2]
        )?;
    }
    Ok(())
}

/// `s` as one CSV field (quoted when it holds a comma, quote or line break).
#[must_use]
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_owned() }
}
