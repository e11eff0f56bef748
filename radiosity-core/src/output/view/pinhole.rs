//! The pinhole view the images are drawn from, and how it is written as Radiance view options.

use crate::geom::DVec3;
use crate::scene::Camera;

/// Up vectors within this sine of the view direction are taken as parallel to it.
pub(super) const PARALLEL_SINE: f64 = 1e-6;

/// A pinhole view: where the eye is, where it looks, and the angles the image covers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Eye position.
    pub position: DVec3,
    /// Viewing direction (unit).
    pub direction: DVec3,
    /// Up vector (unit, orthogonal to `direction`).
    pub up: DVec3,
    /// Full horizontal angle, radians (in (0, π)).
    pub horizontal: f64,
    /// Full vertical angle, radians (in (0, π)).
    pub vertical: f64,
}

impl View {
    /// The view of a scene camera on an image of width / height `aspect`: its vertical angle is
    /// the camera's, its horizontal angle the one that gives square pixels.
    #[must_use]
    pub fn from_camera(cam: &Camera, aspect: f64) -> View {
        View::new(cam.position, cam.direction, cam.up, horizontal_for(cam.fov_y, aspect), cam.fov_y)
    }

    /// A view from `eye` toward `target` (`up` made orthogonal to the direction; another axis is
    /// taken when they are parallel). Angles in radians.
    #[must_use]
    pub fn new(eye: DVec3, direction: DVec3, up: DVec3, horizontal: f64, vertical: f64) -> View {
        let direction = direction.try_normalize().unwrap_or(DVec3::NEG_Z);
        let up = orthogonal_up(direction, up);
        View { position: eye, direction, up, horizontal, vertical }
    }

    /// Image size in pixels fitting in `max_width` × `max_height` with square pixels, as large as
    /// the view's aspect allows (Radiance's `rpict -x -y` with `-pa 1`); at least 1 × 1.
    #[must_use]
    pub fn image_size(&self, max_width: u32, max_height: u32) -> (u32, u32) {
        let aspect = (0.5 * self.horizontal).tan() / (0.5 * self.vertical).tan();
        let (w, h) = (f64::from(max_width.max(1)), f64::from(max_height.max(1)));
        let (w, h) = if aspect >= w / h { (w, w / aspect) } else { (h * aspect, h) };
        ((w.round() as u32).max(1), (h.round() as u32).max(1))
    }

    /// Direction of the ray through image coordinates `(u, v)`, both in [-1, 1] (u to the right,
    /// v up), unit length.
    #[must_use]
    pub fn ray(&self, u: f64, v: f64) -> DVec3 {
        let right = self.direction.cross(self.up);
        let d = self.direction + right * (u * (0.5 * self.horizontal).tan()) + self.up * (v * (0.5 * self.vertical).tan());
        d.normalize()
    }
}

impl std::fmt::Display for View {
    /// The view as Radiance options on one line, as `rvu` saves it (`rvu -vtv -vp ... -vv 45`):
    /// [`ViewSpec::parse`](super::ViewSpec::parse) reads it back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (p, d, u) = (self.position, self.direction, self.up);
        write!(
            f,
            "rvu -vtv -vp {} {} {} -vd {} {} {} -vu {} {} {} -vh {} -vv {}",
            p.x,
            p.y,
            p.z,
            d.x,
            d.y,
            d.z,
            u.x,
            u.y,
            u.z,
            self.horizontal.to_degrees(),
            self.vertical.to_degrees()
        )
    }
}

/// The horizontal angle that gives square pixels to a vertical angle `vertical` on an image of
/// width / height `aspect`.
pub(super) fn horizontal_for(vertical: f64, aspect: f64) -> f64 {
    2.0 * ((0.5 * vertical).tan() * aspect).atan()
}

/// `up` made unit and orthogonal to the unit `direction`; when they are parallel (or `up` is zero),
/// the world axis least aligned with `direction` is used instead.
fn orthogonal_up(direction: DVec3, up: DVec3) -> DVec3 {
    let ortho = |u: DVec3| (u - direction * direction.dot(u)).try_normalize();
    if let Some(u) = up.try_normalize().filter(|u| u.cross(direction).length() > PARALLEL_SINE).and_then(ortho) {
        return u;
    }
    let a = direction.abs();
    let axis = if a.z <= a.x && a.z <= a.y {
        DVec3::Z
    } else if a.y <= a.x {
        DVec3::Y
    } else {
        DVec3::X
    };
    ortho(axis).unwrap_or(DVec3::Y)
}
