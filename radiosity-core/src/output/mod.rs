//! Step 5, `output`: the files `radiosity solve` writes — `image.png`, `solution.ply`, `patches.csv`,
//! `stats.json`, and `points.csv` with calculation points (names and columns are relied on by other
//! tools: see DESIGN.md).

mod csv;
mod ply;
mod points;
mod render;
mod smooth;
mod stats;
mod write;

pub use csv::{PolygonResult, csv_field, polygon_results, write_patches_csv};
pub use ply::write_ply;
pub use points::{write_points_csv, write_points_csv_in};
pub use render::{RenderConfig, ToneMap, render, write_png};
pub use smooth::CornerValues;
pub use stats::{Stats, StatsTimes, peak_rss_bytes, power_balance};
pub use write::{OutputConfig, OutputError, write_solution, write_stats};
