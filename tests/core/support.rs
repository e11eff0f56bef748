//! Helpers shared by the core tests.

use radiosity::geom::DVec3;
use radiosity::pipeline::{self, Config, Solved};
use radiosity::refine::{BfHand, BfParams};
use radiosity::scene::{Material, Scene, SceneBuilder};
use std::path::Path;

/// Solves `scene` with the hand-written BF oracle at `eps`, smallest element `min_area_rel` of the
/// scene's area.
pub fn solve(scene: &Scene, eps: f64, min_area_rel: f64) -> Solved {
    let mut config = Config::default();
    config.build.min_area_rel = min_area_rel;
    pipeline::run(scene, &BfHand { params: BfParams { eps } }, &config, &|_| {})
}

/// A scene builder for generated test scenes.
pub struct Build {
    b: SceneBuilder,
}

impl Build {
    pub fn new(name: &str) -> Build {
        Build { b: SceneBuilder::new(Path::new(name), name) }
    }

    /// Adds a material; returns its index.
    pub fn material(&mut self, name: &str, rho: [f64; 3], emission: [f64; 3]) -> u32 {
        let mut m = Material::diffuse(name, rho);
        m.emission = emission;
        self.b.material(m).expect("valid test material")
    }

    /// Adds a material with a diffuse transmittance (two-sided); returns its index.
    pub fn transmitting(&mut self, name: &str, rho: [f64; 3], t: [f64; 3]) -> u32 {
        let mut m = Material::diffuse(name, rho);
        m.transmittance = t;
        self.b.material(m).expect("valid test material")
    }

    /// Adds a quad in group `group`.
    pub fn quad(&mut self, group: &str, v: [DVec3; 4], material: u32) {
        let g = self.b.group(group);
        self.b.face(&v, material, g, 0).expect("valid test quad");
    }

    pub fn finish(self) -> Scene {
        self.b.finish()
    }
}

/// Relative difference `|a − b| / max(|a|, |b|)` (0 when both are 0).
pub fn rel_diff(a: f64, b: f64) -> f64 {
    let m = a.abs().max(b.abs());
    if m == 0.0 { 0.0 } else { (a - b).abs() / m }
}
