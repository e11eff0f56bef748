//! `points.csv` (with `radiosity solve --points FILE`): one row per calculation point, in input
//! order: `name,x,y,z,nx,ny,nz,h_r,h_g,h_b,h_photopic[,e_lx],units,h_err[,e_err]` (`e_lx` in
//! photometric scenes; `units` is `W/m2` or `lm/m2`; `h_err` the estimated error of `h_photopic`
//! in its units and `e_err` of `e_lx`, see [`crate::points::PointGather`]; `NaN` when the solve
//! has no error estimate), in a scene lit by a sky alone followed by `df_pct,df_err_pct`.

use super::csv_field;
use crate::photometry::Units;
use crate::points::{CalcPoint, PointIrradiance};
use std::io::Write;

/// Writes `points.csv`: each point's name, position, unit normal (as gathered: the input normal
/// normalised), irradiance per channel (W/m²) and its photopic value
/// ([`crate::points::PHOTOPIC_WEIGHTS`]), then the photopic value's estimated error.
pub fn write_points_csv(w: &mut impl Write, points: &[CalcPoint], results: &[PointIrradiance]) -> std::io::Result<()> {
    write_points_csv_in(w, points, results, Units::Radiometric)
}

/// [`write_points_csv`] in the scene's `units`: photometric scenes get the illuminance `e_lx`
/// (the photopic value, lx) too.
pub fn write_points_csv_in(w: &mut impl Write, points: &[CalcPoint], results: &[PointIrradiance], units: Units) -> std::io::Result<()> {
    write_points_csv_with(w, points, results, units, None)
}

/// [`write_points_csv_in`], and with `outside` (the sky's light on an open horizontal plane,
/// photopic: [`crate::daylight::sky_alone_horizontal`]) two more columns, the daylight factor
/// `df_pct` = 100 · photopic ÷ outside and its estimated error `df_err_pct` (%).
pub fn write_points_csv_with(
    w: &mut impl Write,
    points: &[CalcPoint],
    results: &[PointIrradiance],
    units: Units,
    outside: Option<f64>,
) -> std::io::Result<()> {
    let photometric = units == Units::Photometric;
    let (lux, lux_err) = if photometric { (",e_lx", ",e_err") } else { ("", "") };
    let df_header = if outside.is_some() { ",df_pct,df_err_pct" } else { "" };
    writeln!(w, "name,x,y,z,nx,ny,nz,h_r,h_g,h_b,h_photopic{lux},units,h_err{lux_err}{df_header}")?;
    let label = units.density_label();
    for (p, r) in points.iter().zip(results) {
        let (x, n) = (p.position, p.normal);
        let lux = if photometric { format!(",{:e}", r.photopic()) } else { String::new() };
        let err = r.photopic_err();
        let lux_err = if photometric { format!(",{err:e}") } else { String::new() };
        let df = outside.map_or(String::new(), |o| format!(",{:e},{:e}", 100.0 * r.photopic() / o, 100.0 * err / o));
        writeln!(
            w,
            "{},{},{},{},{},{},{},{:e},{:e},{:e},{:e}{lux},{label},{err:e}{lux_err}{df}",
            csv_field(&p.name),
            x.x,
            x.y,
            x.z,
            n.x,
            n.y,
            n.z,
            r.h[0],
            r.h[1],
            r.h[2],
            r.photopic()
        )?;
    }
    Ok(())
}
