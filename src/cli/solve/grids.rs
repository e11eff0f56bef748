//! The grid files of a plain solve: `grid_<name>.csv` and `grid_<name>.svg`, with their figures.

use anyhow::Context;
use radiosity::output;

/// Writes `grid_<name>.csv` and `grid_<name>.svg` for each grid in the scene's `units` and returns
/// the figures by name; with `outside` (the daylight factor's reference, photopic), the daylight
/// factors too: their columns, figures and `grid_<name>_df.svg`.
pub(super) fn write_grids(
    out: &std::path::Path,
    grids: &[radiosity::points::Grid],
    results: &[Vec<radiosity::points::PointIrradiance>],
    units: radiosity::photometry::Units,
    outside: Option<f64>,
) -> anyhow::Result<std::collections::BTreeMap<String, radiosity::points::GridSummary>> {
    let mut figures = std::collections::BTreeMap::new();
    for (g, r) in grids.iter().zip(results) {
        let name = &g.spec.name;
        let values: Vec<f64> = r.iter().map(radiosity::points::PointIrradiance::photopic).collect();
        let errors: Vec<f64> = r.iter().map(radiosity::points::PointIrradiance::photopic_err).collect();
        let mut summary = radiosity::points::GridSummary::of(&values)
            .with_context(|| format!("grid `{name}`: no point, or a value that is not finite"))?
            .with_errors(&errors);
        if let Some(outside) = outside {
            summary = summary.with_daylight_factor(&values, &errors, outside);
        }
        let path = out.join(format!("grid_{name}.csv"));
        output::atomic::write_file(&path, |w| output::write_grid_csv(w, g, r, units, outside))
            .with_context(|| format!("{}: cannot write", path.display()))?;
        if let (Some(outside), Some(figures)) = (outside, &summary.daylight_factor) {
            let df: Vec<f64> = values.iter().map(|v| 100.0 * v / outside).collect();
            let svg = output::grid_df_svg(g, &df, figures).with_context(|| format!("grid `{name}`: cannot draw the daylight factors"))?;
            let path = out.join(format!("grid_{name}_df.svg"));
            output::atomic::write_bytes(&path, svg).with_context(|| format!("{}: cannot write", path.display()))?;
        }
        let svg = output::grid_svg(g, &values, &summary, units).with_context(|| format!("grid `{name}`: cannot draw the plot"))?;
        let path = out.join(format!("grid_{name}.svg"));
        output::atomic::write_bytes(&path, svg).with_context(|| format!("{}: cannot write", path.display()))?;
        let _ = figures.insert(name.clone(), summary);
    }
    Ok(figures)
}
