//! Step 5, `output`: the files `radiosity solve` writes — `image.png`, `falsecolor.png`,
//! `solution.ply`, `solution.glb`, `patches.csv`, `groups.csv`, `stats.json`, `points.csv` with calculation points,
//! and `grid_<name>.csv` / `.svg` with grids (names and columns are relied on by other
//! tools: see DESIGN.md).

pub mod atomic;
mod csv;
mod falsecolor;
mod glb;
mod grid;
mod ply;
mod points;
mod render;
mod smooth;
mod stats;
mod view;
mod write;

pub use csv::{
    PolygonResult, csv_field, polygon_results, write_groups_csv, write_groups_csv_bands, write_patches_csv, write_patches_csv_bands,
};
pub use falsecolor::{
    BACKGROUND, ColourScale, DEFAULT_LOG_DECADES, DEFAULT_MAX_AREA_SHARE, FalseColourConfig, LEGEND_MIN_HEIGHT, LEGEND_WIDTH, LINEAR_STEPS,
    PALETTE, Quantity, Scale, WATTS_PER_SQUARE_METRE, default_max, false_colour_image, format_label, nice_ceiling, palette,
    write_false_colour,
};
pub use glb::{GLB_RADIOSITY_ATTRIBUTE, GlbLayout, write_glb};
pub(crate) use glb::{push_f32s, push_fan};
pub use grid::{SVG_WIDTH, TARGET_CONTOUR_LEVELS, contour_levels, grid_df_svg, grid_svg, write_grid_csv};
pub use ply::write_ply;
pub use points::{write_points_csv, write_points_csv_in, write_points_csv_with};
pub use render::{Frame, OUTSIDE_PREFERENCE, RenderConfig, ToneMap, default_view, frame, mean_brightness, render, render_frame, write_png};
pub use smooth::CornerValues;
pub use stats::{BandPower, LOST_AT_BACKS_WARN_REL, Stats, StatsTimes, channel_powers, peak_rss_bytes, power_balance};
pub use view::{
    Candidate, INSIDE_CORNER_FRACTION, INSIDE_FOV_DEG, MAX_VIEW_ANGLE_DEG, OUTSIDE_ELEVATION_DEG, OUTSIDE_FOV_DEG, OUTSIDE_MARGIN, View,
    ViewError, ViewSpec, candidate_views, up_axis,
};
pub use write::{OutputConfig, OutputError, write_solution, write_stats};
