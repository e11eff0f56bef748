//! `points.csv` (with `radiosity solve --points FILE`): one row per calculation point, in input
//! order: `name,x,y,z,nx,ny,nz,h_r,h_g,h_b,h_photopic`.

use super::csv_field;
use crate::points::{CalcPoint, PointIrradiance};
use std::io::Write;

/// Writes `points.csv`: each point's name, position, unit normal (as gathered: the input normal
/// normalised), irradiance per channel (W/m²) and its photopic value
/// ([`crate::points::PHOTOPIC_WEIGHTS`]).
pub fn write_points_csv(w: &mut impl Write, points: &[CalcPoint], results: &[PointIrradiance]) -> std::io::Result<()> {
    writeln!(w, "name,x,y,z,nx,ny,nz,h_r,h_g,h_b,h_photopic")?;
    for (p, r) in points.iter().zip(results) {
        let (x, n) = (p.position, p.normal);
        writeln!(
            w,
            "{},{},{},{},{},{},{},{:e},{:e},{:e},{:e}",
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
