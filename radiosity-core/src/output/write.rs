//! Writes the output files of a solve into a directory, each atomically ([`super::atomic`]).

use super::atomic::AtomicFile;
use super::{
    CornerValues, FalseColourConfig, RenderConfig, Stats, ToneMap, ViewSpec, frame, polygon_results, render_frame, write_false_colour,
    write_glb, write_patches_csv, write_ply, write_png,
};
use crate::pipeline::Solved;
use crate::scene::Scene;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A file that could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot write: {reason}", path.display())]
pub struct OutputError {
    /// The file.
    pub path: PathBuf,
    /// Why.
    pub reason: String,
}

/// Which files to write (all by default).
#[derive(Clone, Copy, Debug)]
pub struct OutputConfig {
    /// Render `image.png`.
    pub image: bool,
    /// Image settings.
    pub render: RenderConfig,
    /// Radiance view options applied to the scene's camera or default view.
    pub view: Option<ViewSpec>,
    /// Write `falsecolor.png` beside `image.png` with these settings.
    pub false_colour: Option<FalseColourConfig>,
}

impl Default for OutputConfig {
    fn default() -> Self {
        OutputConfig { image: true, render: RenderConfig::default(), view: None, false_colour: Some(FalseColourConfig::default()) }
    }
}

/// Writes `path` atomically with `write` ([`super::atomic::write_file`]); errors name the file.
fn write_atomic(path: &Path, write: impl FnOnce(&mut AtomicFile) -> std::io::Result<()>) -> Result<(), OutputError> {
    super::atomic::write_file(path, write).map_err(|e| OutputError { path: path.to_path_buf(), reason: e.to_string() })
}

/// Writes `patches.csv`, `groups.csv`, `solution.ply`, `solution.glb`, `image.png` with its view `view.vf`
/// (Radiance options that `--view` reads back) and `falsecolor.png` (unless disabled) into `dir` (created if
/// needed); `stats.json` is written by [`write_stats`] once the output time is known.
pub fn write_solution(dir: &Path, scene: &Scene, solved: &Solved, config: &OutputConfig) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(|e| OutputError { path: dir.to_path_buf(), reason: e.to_string() })?;
    let results = polygon_results(&solved.hierarchy, &solved.solution);
    let path = dir.join("patches.csv");
    write_atomic(&path, |w| write_patches_csv(w, scene, &results))?;
    let path = dir.join("groups.csv");
    write_atomic(&path, |w| super::write_groups_csv(w, scene, &results))?;

    let per_polygon: Vec<[f64; 3]> = results.iter().map(|r| r.b).collect();
    let tone = ToneMap::from_scene(scene, &per_polygon);
    let corners = CornerValues::new(&solved.hierarchy, &solved.solution);
    let path = dir.join("solution.ply");
    write_atomic(&path, |w| write_ply(w, &solved.hierarchy, &corners, &tone))?;
    let path = dir.join("solution.glb");
    write_atomic(&path, |w| write_glb(w, &solved.hierarchy, &corners, &tone))?;

    if config.image {
        let path = dir.join("image.png");
        let frame = frame(scene, &solved.hierarchy, &solved.caster, &corners, &tone, &config.render, config.view.as_ref());
        let rgb = render_frame(scene, &solved.hierarchy, &solved.caster, &corners, &tone, &frame, config.render.samples);
        write_png(&path, &rgb, frame.width, frame.height).map_err(|e| OutputError { path: path.clone(), reason: e.to_string() })?;
        let path = dir.join("view.vf");
        write_atomic(&path, |w| writeln!(w, "{}", frame.view))?;
        if let Some(fc) = &config.false_colour {
            write_false_colour(dir, scene, solved, &frame, config.render.samples, fc)?;
        }
    }

    Ok(())
}

/// Writes `stats.json` into `dir`.
pub fn write_stats(dir: &Path, stats: &Stats) -> Result<(), OutputError> {
    let path = dir.join("stats.json");
    write_atomic(&path, |w| {
        serde_json::to_writer_pretty(&mut *w, stats)?;
        std::io::Write::write_all(w, b"\n")
    })
}
