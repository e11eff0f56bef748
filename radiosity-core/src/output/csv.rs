//! `patches.csv`: one row per input polygon, in input order:
//! `index,group,material,area,b_r,b_g,b_b,h_r,h_g,h_b,units,absorbed_r,absorbed_g,absorbed_b`
//! (area-weighted means over the polygon's leaves; `units` is `W/m2`, or `lm/m2` in photometric
//! scenes: radiosity in lm/m², irradiance in lx; `absorbed_*` the power the polygon's side absorbs,
//! W or lm). `groups.csv`: per group (OBJ object or group, MGF object, prototype),
//! `group,area,absorbed_r,absorbed_g,absorbed_b`. A scene with named bands (`bands = ["PAR",
//! "NIR"]`) gets one column per band instead: `b_PAR,b_NIR,h_PAR,h_NIR,units,absorbed_PAR,...`.

use crate::scene::Scene;
use std::io::Write;

pub use crate::solve::{PolygonResult, polygon_results};

/// The channel names of an RGB solve, as the column suffixes of `patches.csv` and `groups.csv`.
pub const RGB: [&str; 3] = ["r", "g", "b"];

/// Writes `groups.csv`: one row per group of the scene (in the scene's order, groups without
/// polygons left out), `group,area,absorbed_r,absorbed_g,absorbed_b` summed over its polygons.
pub fn write_groups_csv(w: &mut impl Write, scene: &Scene, results: &[PolygonResult]) -> std::io::Result<()> {
    write_groups_csv_bands(w, scene, &RGB, &[results])
}

/// [`write_groups_csv`] for named bands: `packs[k]` holds the results of bands `3k .. 3k + 3`
/// (see [`crate::instancing::bands`]); one `absorbed_<band>` column per name.
pub fn write_groups_csv_bands(
    w: &mut impl Write,
    scene: &Scene,
    names: &[impl AsRef<str>],
    packs: &[&[PolygonResult]],
) -> std::io::Result<()> {
    let nb = names.len();
    let mut sums = vec![(0usize, 0.0, vec![0.0; nb]); scene.groups.len()];
    for (i, p) in scene.polygons.iter().enumerate() {
        let s = &mut sums[p.group as usize];
        s.0 += 1;
        s.1 += packs[0][i].area;
        for (b, v) in s.2.iter_mut().enumerate() {
            *v += packs[b / 3][i].absorbed[b % 3];
        }
    }
    write!(w, "group,area")?;
    for n in names {
        write!(w, ",absorbed_{}", n.as_ref())?;
    }
    writeln!(w)?;
    for (name, (n, area, a)) in scene.groups.iter().zip(sums) {
        if n > 0 {
            write!(w, "{},{:e}", csv_field(name), area)?;
            for v in a {
                write!(w, ",{v:e}")?;
            }
            writeln!(w)?;
        }
    }
    Ok(())
}

/// Writes `patches.csv`.
pub fn write_patches_csv(w: &mut impl Write, scene: &Scene, results: &[PolygonResult]) -> std::io::Result<()> {
    write_patches_csv_bands(w, scene, &RGB, &[results])
}

/// [`write_patches_csv`] for named bands: `b_<band>` for every band, then `h_<band>`, `units`,
/// `absorbed_<band>`; `packs[k]` holds the results of bands `3k .. 3k + 3`.
pub fn write_patches_csv_bands(
    w: &mut impl Write,
    scene: &Scene,
    names: &[impl AsRef<str>],
    packs: &[&[PolygonResult]],
) -> std::io::Result<()> {
    write!(w, "index,group,material,area")?;
    for prefix in ["b", "h"] {
        for n in names {
            write!(w, ",{prefix}_{}", n.as_ref())?;
        }
    }
    write!(w, ",units")?;
    for n in names {
        write!(w, ",absorbed_{}", n.as_ref())?;
    }
    writeln!(w)?;
    let units = scene.units.density_label();
    let nb = names.len();
    for (i, p) in scene.polygons.iter().enumerate() {
        let r = |b: usize| &packs[b / 3][i];
        write!(
            w,
            "{i},{},{},{:e}",
            csv_field(&scene.groups[p.group as usize]),
            csv_field(&scene.materials[p.material as usize].name),
            r(0).area
        )?;
        for b in 0..nb {
            write!(w, ",{:e}", r(b).b[b % 3])?;
        }
        for b in 0..nb {
            write!(w, ",{:e}", r(b).h[b % 3])?;
        }
        write!(w, ",{units}")?;
        for b in 0..nb {
            write!(w, ",{:e}", r(b).absorbed[b % 3])?;
        }
        writeln!(w)?;
    }
    Ok(())
}

/// `s` as one CSV field (quoted when it holds a comma, quote or line break).
#[must_use]
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_owned() }
}
