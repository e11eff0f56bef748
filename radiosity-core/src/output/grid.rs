//! `grid_<name>.csv` and `grid_<name>.svg` (with `radiosity solve --grid` or `--work-plane`): each
//! grid's points with their irradiance, and an isolux plot of them.

use crate::photometry::Units;
use crate::points::PointIrradiance;
use crate::points::grid::{Grid, GridSummary, photopic_column, photopic_unit};
use plotters::prelude::*;
use std::io::Write;

/// Contour levels aimed at per plot (the step is the 1-2-2.5-5 number nearest above range / this).
pub const TARGET_CONTOUR_LEVELS: f64 = 8.0;

/// Width of the isolux plot (pixels).
pub const SVG_WIDTH: u32 = 720;

/// Plot area heights are kept between these (pixels), whatever the grid's aspect.
const PLOT_HEIGHT_RANGE: (f64, f64) = (240.0, 900.0);

/// Points of a contour line this far (in cells) outside the hull of the grid's points are the
/// contouring's closure along the border, not a contour: they are left out.
const HULL_TOL_CELLS: f64 = 1e-9;

/// Writes `grid_<name>.csv`: the grid's points in its order, in the columns of `points.csv`
/// ([`super::write_points_csv_with`]: `name,x,y,z,nx,ny,nz,h_r,h_g,h_b,h_photopic[,e_lx],units,h_err[,e_err]`,
/// then `df_pct,df_err_pct` with `outside`, the daylight factor's reference).
pub fn write_grid_csv(
    w: &mut impl Write,
    grid: &Grid,
    results: &[PointIrradiance],
    units: Units,
    outside: Option<f64>,
) -> std::io::Result<()> {
    super::write_points_csv_with(w, &grid.points, results, units, outside)
}

/// Contour levels for values between `min` and `max`: the multiples of a 1-2-2.5-5 step strictly
/// between them, about [`TARGET_CONTOUR_LEVELS`] of them; none when `max <= min`.
#[must_use]
pub fn contour_levels(min: f64, max: f64) -> Vec<f64> {
    let step = level_step(min, max);
    if step <= 0.0 {
        return Vec::new();
    }
    let first = (min / step).floor() as i64 + 1;
    (first..).map(|k| k as f64 * step).take_while(|&l| l < max).filter(|&l| l > min).collect()
}

/// The step of [`contour_levels`] (0 when there is none).
fn level_step(min: f64, max: f64) -> f64 {
    if !(min.is_finite() && max.is_finite() && max > min) {
        return 0.0;
    }
    let raw = (max - min) / TARGET_CONTOUR_LEVELS;
    let mag = 10f64.powf(raw.log10().floor());
    let f = [1.0, 2.0, 2.5, 5.0, 10.0].into_iter().find(|&m| m * mag >= raw * (1.0 - 1e-12)).unwrap_or(10.0);
    f * mag
}

/// `value` with the decimals a level step of `step` needs (at most 6).
fn format_level(value: f64, step: f64) -> String {
    let mut decimals = 0;
    while decimals < 6 {
        let scaled = step * 10f64.powi(decimals);
        if (scaled.round() - scaled).abs() <= 1e-9 * scaled.abs().max(1.0) {
            break;
        }
        decimals += 1;
    }
    format!("{value:.*}", decimals as usize)
}

/// The isolux plot of a grid as SVG text: the points, contour lines at [`contour_levels`] with
/// their values, and the figures in a caption. Axes are `s` along `u` and `t` along `v` from the
/// grid's origin (scene units). `values` are the points' photopic values, in the grid's order.
pub fn grid_svg(grid: &Grid, values: &[f64], summary: &GridSummary, units: Units) -> std::io::Result<String> {
    let unit = photopic_unit(units);
    let caption = format!("grid {}: {} ({unit}), {} × {} points", grid.spec.name, photopic_column(units), grid.n_u, grid.n_v);
    contour_svg(grid, values, &caption, &|step| {
        format!(
            "Eavg {:.4} {unit};  Emin {:.4} {unit};  Emax {:.4} {unit};  U0 = Emin/Eavg {:.3};  Emin/Emax {:.3};  contours every {step} {unit}",
            summary.e_avg, summary.e_min, summary.e_max, summary.u0, summary.min_over_max,
        )
    })
}

/// The daylight-factor plot of a grid as SVG text, like [`grid_svg`]: `df` are the points'
/// daylight factors (%), `figures` theirs ([`GridSummary::with_daylight_factor`]).
pub fn grid_df_svg(grid: &Grid, df: &[f64], figures: &crate::points::grid::DaylightFactorFigures) -> std::io::Result<String> {
    let caption = format!("grid {}: daylight factor (%), {} × {} points", grid.spec.name, grid.n_u, grid.n_v);
    contour_svg(grid, df, &caption, &|step| {
        format!(
            "DF mean {:.3}%;  reached by half the points {:.3}%, by 95% {:.3}%;  min {:.3}%;  max {:.3}%;  contours every {step}%",
            figures.mean, figures.median, figures.over_95, figures.min, figures.max,
        )
    })
}

/// A grid's contour plot of `values`: `caption` above, `footer(contour step)` below.
fn contour_svg(grid: &Grid, values: &[f64], caption: &str, footer_text: &dyn Fn(String) -> String) -> std::io::Result<String> {
    let (lu, lv) = (glam::DVec3::from_array(grid.spec.u).length(), glam::DVec3::from_array(grid.spec.v).length());
    let (du, dv) = (lu / grid.n_u as f64, lv / grid.n_v as f64);
    let plot_w = f64::from(SVG_WIDTH) - 90.0;
    let plot_h = (plot_w * lv / lu).clamp(PLOT_HEIGHT_RANGE.0, PLOT_HEIGHT_RANGE.1);
    let height = (plot_h + 130.0) as u32;
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let levels = contour_levels(min, max);
    let step = level_step(min, max);
    let lines = if grid.n_u >= 2 && grid.n_v >= 2 && !levels.is_empty() && values.len() == grid.n_u * grid.n_v {
        contour::ContourBuilder::new(grid.n_u, grid.n_v, true)
            .x_step(du)
            .y_step(dv)
            .lines(values, &levels)
            .map_err(std::io::Error::other)?
    } else {
        Vec::new()
    };
    let inside = |x: f64, y: f64| {
        let (tu, tv) = (HULL_TOL_CELLS * du, HULL_TOL_CELLS * dv);
        x >= 0.5 * du - tu && x <= lu - 0.5 * du + tu && y >= 0.5 * dv - tv && y <= lv - 0.5 * dv + tv
    };
    let mut out = String::new();
    {
        let e = |e: plotters::drawing::DrawingAreaErrorKind<_>| std::io::Error::other(e.to_string());
        let root = SVGBackend::with_string(&mut out, (SVG_WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let (plot, footer) = root.split_vertically(height - 50);
        let mut chart = ChartBuilder::on(&plot)
            .caption(caption, ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(48)
            .build_cartesian_2d(0.0..lu, 0.0..lv)
            .map_err(e)?;
        chart.configure_mesh().disable_mesh().x_desc("s along u").y_desc("t along v").draw().map_err(e)?;
        let pts =
            grid.points.iter().enumerate().map(|(k, _)| ((k % grid.n_u) as f64 * du + 0.5 * du, (k / grid.n_u) as f64 * dv + 0.5 * dv));
        chart.draw_series(pts.map(|p| Circle::new(p, 2, BLACK.mix(0.6).filled()))).map_err(e)?;
        let line_style = RGBColor(0, 90, 180).stroke_width(1);
        let font = ("sans-serif", 11).into_font().color(&RGBColor(0, 60, 140));
        for line in &lines {
            let label = format_level(line.threshold(), step);
            for ls in line.geometry() {
                // Runs of the line inside the points' hull.
                let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
                for c in &ls.0 {
                    if inside(c.x, c.y) {
                        runs.last_mut().expect("one run at least").push((c.x, c.y));
                    } else if !runs.last().expect("one run at least").is_empty() {
                        runs.push(Vec::new());
                    }
                }
                for run in runs.into_iter().filter(|r| r.len() >= 2) {
                    let mid = run[run.len() / 2];
                    chart.draw_series(LineSeries::new(run, line_style)).map_err(e)?;
                    chart.draw_series(std::iter::once(Text::new(label.clone(), mid, font.clone()))).map_err(e)?;
                }
            }
        }
        let figures = footer_text(if step > 0.0 { format_level(step, step) } else { "-".into() });
        footer.draw(&Text::new(figures, (12, 18), ("sans-serif", 13).into_font())).map_err(e)?;
        root.present().map_err(e)?;
    }
    Ok(out)
}
