//! `image.png`: the solution seen from the scene camera, by ray casting into the leaf elements with
//! radiosity interpolated across leaves, and a simple tone map.

use super::smooth::CornerValues;
use crate::geom::DVec3;
use crate::hierarchy::Hierarchy;
use crate::scene::{Camera, Scene};
use crate::visibility::RayCaster;
use rayon::prelude::*;

/// Image settings.
#[derive(Clone, Copy, Debug)]
pub struct RenderConfig {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel along each axis (n × n).
    pub samples: u32,
}

impl Default for RenderConfig {
    fn default() -> Self {
        RenderConfig { width: 512, height: 512, samples: 2 }
    }
}

/// Maps radiosity (W/m²) to display bytes: linear scale so that `white` maps to 1, then clamp and
/// sRGB gamma.
#[derive(Clone, Copy, Debug)]
pub struct ToneMap {
    /// Radiosity shown as full white.
    pub white: f64,
}

impl ToneMap {
    /// A tone map whose white point is a high percentile of the non-emitting polygons' radiosity.
    #[must_use]
    pub fn from_scene(scene: &Scene, per_polygon_b: &[[f64; 3]]) -> ToneMap {
        let mut lum: Vec<f64> = scene
            .polygons
            .iter()
            .zip(per_polygon_b)
            .filter(|(p, _)| !scene.materials[p.material as usize].is_emitter())
            .map(|(_, b)| b[0].max(b[1]).max(b[2]))
            .filter(|v| v.is_finite() && *v > 0.0)
            .collect();
        lum.sort_by(f64::total_cmp);
        if lum.is_empty() {
            let white = per_polygon_b.iter().map(|b| b[0].max(b[1]).max(b[2])).fold(0.0, f64::max);
            return ToneMap { white: if white > 0.0 { white } else { 1.0 } };
        }
        ToneMap::from_levels(lum[(lum.len() as f64 * 0.95) as usize], lum[lum.len() - 1])
    }

    /// The white point from the 95th percentile and the largest of the non-emitting polygons'
    /// radiosity (largest channel): 1.3 × the larger of the percentile and 0.3 × the largest.
    #[must_use]
    pub fn from_levels(p95: f64, max: f64) -> ToneMap {
        let white = p95.max(0.3 * max) * 1.3;
        ToneMap { white: if white > 0.0 { white } else { 1.0 } }
    }

    /// Linear display value of a radiosity, before the sRGB encoding: `b / white` clamped to
    /// [0, 1] (NaN gives 0).
    #[must_use]
    pub fn linear(&self, b: [f64; 3]) -> [f64; 3] {
        b.map(|v| {
            let x = (v / self.white).clamp(0.0, 1.0);
            if x.is_nan() { 0.0 } else { x }
        })
    }

    /// Display bytes of a radiosity: the sRGB encoding of [`ToneMap::linear`].
    #[must_use]
    pub fn map(&self, b: [f64; 3]) -> [u8; 3] {
        self.linear(b).map(|x| {
            let srgb = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
            (srgb * 255.0 + 0.5) as u8
        })
    }
}

/// Renders the solution: RGB bytes, row-major from the top.
#[must_use]
pub fn render(scene: &Scene, h: &Hierarchy, caster: &RayCaster, corners: &CornerValues, tone: &ToneMap, config: &RenderConfig) -> Vec<u8> {
    let cam: Camera = scene.camera_or_default();
    let fwd = cam.direction.normalize_or_zero();
    let right = fwd.cross(cam.up).normalize_or_zero();
    let up = right.cross(fwd);
    let aspect = f64::from(config.width) / f64::from(config.height.max(1));
    let half_h = (0.5 * cam.fov_y).tan();
    let half_w = half_h * aspect;
    let n = config.samples.max(1);
    let rows: Vec<Vec<u8>> = (0..config.height)
        .into_par_iter()
        .map(|y| {
            let mut row = Vec::with_capacity(3 * config.width as usize);
            for x in 0..config.width {
                let mut acc = [0.0; 3];
                for sy in 0..n {
                    for sx in 0..n {
                        let u = (f64::from(x) + (f64::from(sx) + 0.5) / f64::from(n)) / f64::from(config.width) * 2.0 - 1.0;
                        let v = 1.0 - (f64::from(y) + (f64::from(sy) + 0.5) / f64::from(n)) / f64::from(config.height) * 2.0;
                        let dir = (fwd + right * (u * half_w) + up * (v * half_h)).normalize();
                        let b = shade(h, caster, corners, cam.position, dir);
                        // Average displayed values (tone-mapped), which anti-aliases edges of bright lights.
                        let px = tone.map(b);
                        for c in 0..3 {
                            acc[c] += f64::from(px[c]);
                        }
                    }
                }
                for c in acc {
                    row.push((c / f64::from(n * n)).round() as u8);
                }
            }
            row
        })
        .collect();
    rows.concat()
}

fn shade(h: &Hierarchy, caster: &RayCaster, corners: &CornerValues, origin: DVec3, dir: DVec3) -> [f64; 3] {
    let Some((t, polygon)) = caster.closest_hit(origin, dir) else { return [0.0; 3] };
    let root = h.get(polygon);
    let Some(poly) = root.poly() else { return [0.0; 3] };
    if root.normal.dot(dir) > 0.0 {
        // The back of a one-sided surface reflects nothing.
        return [0.0; 3];
    }
    let p = origin + dir * t;
    let (s, tt) = poly.param_of_point(p);
    let (s, tt) = match poly.kind {
        crate::geom::PolyKind::Quad => (s.clamp(0.0, 1.0), tt.clamp(0.0, 1.0)),
        crate::geom::PolyKind::Triangle => {
            let (s, tt) = (s.max(0.0), tt.max(0.0));
            let sum = s + tt;
            if sum > 1.0 { (s / sum, tt / sum) } else { (s, tt) }
        }
    };
    let (leaf, ls, lt) = h.locate(polygon, s, tt);
    let kind = h.get(leaf).poly().map_or(poly.kind, |p| p.kind);
    corners.interpolate(leaf, kind, ls, lt).unwrap_or([0.0; 3])
}

/// Encodes RGB bytes as PNG into `path`, atomically ([`super::atomic::write_file`]).
pub fn write_png(path: &std::path::Path, rgb: &[u8], width: u32, height: u32) -> Result<(), image::ImageError> {
    super::atomic::write_file(path, |w| {
        image::write_buffer_with_format(w, rgb, width, height, image::ExtendedColorType::Rgb8, image::ImageFormat::Png)
    })
}
