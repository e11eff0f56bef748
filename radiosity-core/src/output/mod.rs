//! Step 5, `output`: the files `radiosity solve` writes — `image.png`, `solution.ply`,
//! `solution.glb`, `patches.csv`, `stats.json`, `points.csv` with calculation points, and
//! `grid_<name>.csv` / `.svg` with grids (names and columns are relied on by other
//! tools: see DESIGN.md).

pub mod atomic;
mod csv;
mod glb;
mod grid;
mod ply;
mod points;
mod render;
mod smooth;
mod stats;
mod write;

pub use csv::{PolygonResult, csv_field, polygon_results, write_patches_csv};
pub use glb::{GLB_RADIOSITY_ATTRIBUTE, GlbLayout, write_glb};
pub(crate) use glb::{push_f32s, push_fan};
pub use grid::{SVG_WIDTH, TARGET_CONTOUR_LEVELS, contour_levels, grid_svg, write_grid_csv};
pub use ply::write_ply;
pub use points::{write_points_csv, write_points_csv_in};
pub use render::{RenderConfig, ToneMap, render, write_png};
pub use smooth::CornerValues;
pub use stats::{Stats, StatsTimes, peak_rss_bytes, power_balance};
pub use write::{OutputConfig, OutputError, write_solution, write_stats};
