//! The embedded default scene: the Cornell box with its published geometry and camera.

use super::{Camera, Scene, obj};
use crate::geom::DVec3;
use std::path::Path;

const OBJ: &str = include_str!("../../data/cornell_box_measured.obj");
const MTL: &str = include_str!("../../data/cornell_box_measured.mtl");

/// The Cornell box as published by the Cornell Program of Computer Graphics (millimetres, +y up), with
/// the published camera at (278, 273, -800) mm looking +z (35 mm lens, 25 mm film).
#[must_use]
pub fn cornell_box() -> Scene {
    let path = Path::new("cornell-box (embedded)");
    let mut scene = obj::load_str(OBJ, path, "cornell-box", |_| Ok(MTL.to_owned())).expect("the embedded Cornell box is valid");
    scene.camera = Some(Camera {
        position: DVec3::new(278.0, 273.0, -800.0),
        direction: DVec3::Z,
        up: DVec3::Y,
        fov_y: 2.0 * (12.5f64 / 35.0).atan(),
    });
    scene
}
