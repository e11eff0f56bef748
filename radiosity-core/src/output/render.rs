//! `image.png`: the solution seen from the scene camera (or a default view, or the user's), by ray casting into the leaf elements with
//! radiosity interpolated across leaves, and a simple tone map.

use super::smooth::CornerValues;
use super::view::{Candidate, View, ViewSpec, candidate_views, up_axis};
use crate::geom::{DVec3, PolyKind};
use crate::hierarchy::{ElementId, Hierarchy};
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

/// What an image shows and its size in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// The view.
    pub view: View,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// An outside default view is chosen when its preview is at least this fraction as bright as the
/// brightest candidate's (a cut-away shows the whole room; an inside view fills the frame).
pub const OUTSIDE_PREFERENCE: f64 = 0.35;
/// Side of the previews that score the candidate default views, pixels.
const PREVIEW_SIZE: u32 = 32;

/// The frame of an image of at most `config.width` × `config.height` pixels: the scene's camera
/// (or, for a scene without one, [`default_view`]), modified by `spec` when given; the image takes
/// the view's aspect ratio with square pixels (exactly the configured size unless `spec` sets the
/// angles).
#[must_use]
pub fn frame(
    scene: &Scene,
    h: &Hierarchy,
    caster: &RayCaster,
    corners: &CornerValues,
    tone: &ToneMap,
    config: &RenderConfig,
    spec: Option<&ViewSpec>,
) -> Frame {
    let aspect = f64::from(config.width.max(1)) / f64::from(config.height.max(1));
    let base = match &scene.camera {
        Some(cam) => View::from_camera(cam, aspect),
        None => default_view(scene, h, caster, corners, tone, aspect),
    };
    let view = spec.map_or(base, |s| s.apply(&base));
    let (width, height) = view.image_size(config.width, config.height);
    Frame { view, width, height }
}

/// The default view of a scene without a camera: of the [`candidate_views`], the brightest outside
/// one (a cut-away: the backs of one-sided surfaces let the view through) when its preview's mean
/// brightness is at least [`OUTSIDE_PREFERENCE`] of the brightest candidate's, else the brightest
/// (a view from inside, for scenes whose outside is dark, such as rooms with thick walls).
#[must_use]
pub fn default_view(scene: &Scene, h: &Hierarchy, caster: &RayCaster, corners: &CornerValues, tone: &ToneMap, aspect: f64) -> View {
    let candidates = candidate_views(&scene.bounds(), up_axis(scene), aspect);
    let scored: Vec<(f64, &Candidate)> = candidates
        .iter()
        .map(|c| {
            let (width, height) = c.view.image_size(PREVIEW_SIZE, PREVIEW_SIZE);
            let rgb = render_frame(scene, h, caster, corners, tone, &Frame { view: c.view, width, height }, 1);
            (mean_brightness(&rgb), c)
        })
        .collect();
    let best = |outside: bool| {
        scored.iter().filter(|(_, c)| c.outside || !outside).fold(None::<(f64, &Candidate)>, |b, &(s, c)| match b {
            Some((bs, _)) if bs >= s => b,
            _ => Some((s, c)),
        })
    };
    match (best(true), best(false)) {
        (Some((so, o)), Some((sa, _))) if so >= OUTSIDE_PREFERENCE * sa => o.view,
        (_, Some((_, a))) => a.view,
        _ => View::from_camera(&Camera::looking_at_box(&scene.bounds()), aspect),
    }
}

/// Mean of RGB bytes, 0–255 (0 for none).
#[must_use]
pub fn mean_brightness(rgb: &[u8]) -> f64 {
    if rgb.is_empty() { 0.0 } else { rgb.iter().map(|&b| f64::from(b)).sum::<f64>() / rgb.len() as f64 }
}

/// Renders the solution seen from the scene's camera or the default view ([`frame`] without a
/// view spec: exactly `config.width` × `config.height`): RGB bytes, row-major from the top.
#[must_use]
pub fn render(scene: &Scene, h: &Hierarchy, caster: &RayCaster, corners: &CornerValues, tone: &ToneMap, config: &RenderConfig) -> Vec<u8> {
    let f = frame(scene, h, caster, corners, tone, config, None);
    render_frame(scene, h, caster, corners, tone, &f, config.samples)
}

/// Renders the solution in `frame` with `samples` × `samples` rays a pixel: RGB bytes, row-major
/// from the top. Radiosity is interpolated across leaves; the backs of one-sided surfaces let the
/// view through, those of two-sided ones are black.
#[must_use]
pub fn render_frame(
    scene: &Scene,
    h: &Hierarchy,
    caster: &RayCaster,
    corners: &CornerValues,
    tone: &ToneMap,
    frame: &Frame,
    samples: u32,
) -> Vec<u8> {
    trace_pixels(frame, samples, |origin, dir| {
        // Averaging displayed values (tone-mapped) anti-aliases the edges of bright lights.
        let b = surface_hit(scene, h, caster, origin, dir).and_then(|hit| corners.interpolate(hit.leaf, hit.kind, hit.s, hit.t));
        tone.map(b.unwrap_or([0.0; 3]))
    })
}

/// Calls `pixel(origin, direction)` for `samples` × `samples` rays through each pixel of `frame`
/// and averages the colours: RGB bytes, row-major from the top.
pub(crate) fn trace_pixels(frame: &Frame, samples: u32, pixel: impl Fn(DVec3, DVec3) -> [u8; 3] + Sync) -> Vec<u8> {
    let n = samples.max(1);
    let (width, height) = (frame.width, frame.height);
    let rows: Vec<Vec<u8>> = (0..height)
        .into_par_iter()
        .map(|y| {
            let mut row = Vec::with_capacity(3 * width as usize);
            for x in 0..width {
                let mut acc = [0.0; 3];
                for sy in 0..n {
                    for sx in 0..n {
                        let u = (f64::from(x) + (f64::from(sx) + 0.5) / f64::from(n)) / f64::from(width) * 2.0 - 1.0;
                        let v = 1.0 - (f64::from(y) + (f64::from(sy) + 0.5) / f64::from(n)) / f64::from(height) * 2.0;
                        let px = pixel(frame.view.position, frame.view.ray(u, v));
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

/// Where a ray meets the surface it shows: a leaf and the parameters in it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SurfaceHit {
    /// The leaf element.
    pub leaf: ElementId,
    /// Its geometry's kind.
    pub kind: PolyKind,
    /// Parameters in the leaf.
    pub s: f64,
    /// Parameters in the leaf.
    pub t: f64,
}

/// The first surface along a ray that faces it (the backs of one-sided surfaces let it through);
/// `None` when the ray leaves the scene or meets the back of a two-sided surface.
pub(crate) fn surface_hit(scene: &Scene, h: &Hierarchy, caster: &RayCaster, origin: DVec3, dir: DVec3) -> Option<SurfaceHit> {
    let front_or_two_sided = |polygon: u32| {
        let two_sided = scene.polygons.get(polygon as usize).is_some_and(|p| scene.materials[p.material as usize].two_sided);
        two_sided || (polygon as usize) >= h.len() || h.get(polygon).normal.dot(dir) <= 0.0
    };
    let (t, polygon) = caster.closest_hit_where(origin, dir, front_or_two_sided)?;
    let root = h.get(polygon);
    let poly = root.poly()?;
    if root.normal.dot(dir) > 0.0 {
        // The back of a two-sided surface: its other side is not drawn.
        return None;
    }
    let p = origin + dir * t;
    let (s, tt) = poly.param_of_point(p);
    let (s, tt) = match poly.kind {
        PolyKind::Quad => (s.clamp(0.0, 1.0), tt.clamp(0.0, 1.0)),
        PolyKind::Triangle => {
            let (s, tt) = (s.max(0.0), tt.max(0.0));
            let sum = s + tt;
            if sum > 1.0 { (s / sum, tt / sum) } else { (s, tt) }
        }
    };
    let (leaf, ls, lt) = h.locate(polygon, s, tt);
    let kind = h.get(leaf).poly().map_or(poly.kind, |p| p.kind);
    Some(SurfaceHit { leaf, kind, s: ls, t: lt })
}

/// Encodes RGB bytes as PNG into `path`, atomically ([`super::atomic::write_file`]).
pub fn write_png(path: &std::path::Path, rgb: &[u8], width: u32, height: u32) -> Result<(), image::ImageError> {
    super::atomic::write_file(path, |w| {
        image::write_buffer_with_format(w, rgb, width, height, image::ExtendedColorType::Rgb8, image::ImageFormat::Png)
    })
}
