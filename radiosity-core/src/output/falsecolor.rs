//! `falsecolor.png`: the solution in false colour, in the manner of Radiance's `falsecolor`: the
//! irradiance (what falls on each surface) or the radiosity (what leaves it), photopic-weighted
//! (see [`crate::points::photopic`]), on a linear or logarithmic scale, seen in the same frame as
//! `image.png`, with a legend on the left: a colour bar, its values and the unit.

use super::render::{Frame, surface_hit, trace_pixels, write_png};
use super::smooth::CornerValues;
use super::write::OutputError;
use crate::hierarchy::Hierarchy;
use crate::pipeline::Solved;
use crate::points::photopic;
use crate::scene::Scene;
use crate::solve::Solution;
use crate::visibility::RayCaster;
use font8x8::UnicodeFonts;
use std::path::{Path, PathBuf};

/// The colours of the scale, low to high, equally spaced (a spectrum from dark blue through cyan,
/// green and yellow to dark red); values between two stops mix them linearly.
pub const PALETTE: [[u8; 3]; 13] = [
    [48, 18, 59],
    [65, 69, 171],
    [70, 117, 237],
    [57, 162, 252],
    [27, 207, 212],
    [36, 236, 166],
    [97, 252, 108],
    [164, 252, 59],
    [209, 232, 52],
    [243, 198, 58],
    [254, 155, 45],
    [243, 99, 21],
    [122, 4, 3],
];
/// Where a ray leaves the scene (or meets the back of a two-sided surface).
pub const BACKGROUND: [u8; 3] = [0, 0, 0];
/// Width of the legend, pixels (Radiance's default).
pub const LEGEND_WIDTH: u32 = 100;
/// Smallest height of the picture, so the legend fits (pixels).
pub const LEGEND_MIN_HEIGHT: u32 = 200;
/// Decades a logarithmic scale spans below its maximum, by default.
pub const DEFAULT_LOG_DECADES: f64 = 3.0;
/// Labels of a linear scale: 0 and this many equal steps up to the maximum.
pub const LINEAR_STEPS: u32 = 5;
/// The unit of radiometric scenes' values.
pub const WATTS_PER_SQUARE_METRE: &str = "W/m²";
/// Colour of the legend's text and ticks.
const TEXT_COLOUR: [u8; 3] = [255, 255, 255];
/// Side of a glyph of the legend's font, pixels.
const GLYPH: u32 = 8;
/// The glyph of `²` (rows top to bottom, bit 0 the leftmost pixel). font8x8 0.3.1 files three
/// glyphs under U+00B2 (those of `²`, `³` and `´`) and its look-up finds the acute accent, so the
/// legend's unit draws this one, font8x8's own `LATIN_LEGACY[18]`.
const SUPERSCRIPT_TWO: [u8; 8] = [0x1C, 0x30, 0x18, 0x0C, 0x3C, 0x00, 0x00, 0x00];
/// Margin around the legend's parts, pixels.
const MARGIN: u32 = 6;
/// Width of the legend's colour bar, pixels.
const BAR_WIDTH: u32 = 16;
/// Legend labels closer than this (as a fraction of the bar) to an end label are left out.
const LABEL_GAP: f64 = 0.08;

/// What the false colours show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Irradiance: the light falling on a surface (front side), W/m².
    Irradiance,
    /// Radiosity: the light leaving a surface, W/m².
    Radiosity,
    /// The daylight factor: the irradiance as a share of the sky's on an open horizontal plane, %
    /// (the caller sets [`FalseColourConfig::factor`] to `100 ÷ E_outside` and the unit to `%`).
    DaylightFactor,
}

impl Quantity {
    /// The name shown in the legend.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Irradiance => "irradiance",
            Quantity::Radiosity => "radiosity",
            Quantity::DaylightFactor => "daylight factor",
        }
    }
}

/// How values map to the colour scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// From 0 to the maximum.
    Linear,
    /// Logarithmic, from the maximum down a number of decades.
    Log,
}

/// Settings of `falsecolor.png`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FalseColourConfig {
    /// What is shown.
    pub quantity: Quantity,
    /// Linear or logarithmic.
    pub scale: Scale,
    /// The top of the scale in displayed units (after `factor`); by default [`default_max`].
    pub max: Option<f64>,
    /// Decades below the maximum that a logarithmic scale spans.
    pub decades: f64,
    /// Multiplies the solution's values before they are shown (179 lm/W would turn a photometric
    /// scene's W/m² into lux).
    pub factor: f64,
    /// The unit written in the legend.
    pub unit: &'static str,
}

impl Default for FalseColourConfig {
    fn default() -> Self {
        FalseColourConfig {
            quantity: Quantity::Irradiance,
            scale: Scale::Linear,
            max: None,
            decades: DEFAULT_LOG_DECADES,
            factor: 1.0,
            unit: WATTS_PER_SQUARE_METRE,
        }
    }
}

/// The map from values to colours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourScale {
    /// Linear or logarithmic.
    pub scale: Scale,
    /// The value at the top of the scale (positive).
    pub max: f64,
    /// The value at the bottom of a logarithmic scale (positive; 0 for a linear one).
    pub min: f64,
}

impl ColourScale {
    /// A scale up to `max` (made positive), spanning `decades` below it when logarithmic.
    #[must_use]
    pub fn new(scale: Scale, max: f64, decades: f64) -> ColourScale {
        let max = if max.is_finite() && max > 0.0 { max } else { 1.0 };
        let decades = if decades.is_finite() && decades > 0.0 { decades } else { DEFAULT_LOG_DECADES };
        let min = match scale {
            Scale::Linear => 0.0,
            Scale::Log => max / 10f64.powf(decades),
        };
        ColourScale { scale, max, min }
    }

    /// Where `value` lies on the scale, 0 (bottom) to 1 (top), clamped.
    #[must_use]
    pub fn position(&self, value: f64) -> f64 {
        let t = match self.scale {
            Scale::Linear => value / self.max,
            Scale::Log if value > 0.0 => (value / self.min).log10() / (self.max / self.min).log10(),
            Scale::Log => 0.0,
        };
        if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }
    }

    /// The colour of `value`.
    #[must_use]
    pub fn colour(&self, value: f64) -> [u8; 3] {
        palette(self.position(value))
    }

    /// The legend's labels: `(position on the bar, value)`, bottom to top. Linear: 0 and
    /// [`LINEAR_STEPS`] equal steps; logarithmic: both ends and the powers of ten between them.
    #[must_use]
    pub fn labels(&self) -> Vec<(f64, f64)> {
        match self.scale {
            Scale::Linear => (0..=LINEAR_STEPS)
                .map(|k| {
                    let t = f64::from(k) / f64::from(LINEAR_STEPS);
                    (t, t * self.max)
                })
                .collect(),
            Scale::Log => {
                let mut out = vec![(0.0, self.min)];
                let (lo, hi) = (self.min.log10().ceil() as i32, self.max.log10().floor() as i32);
                for k in lo..=hi {
                    let v = 10f64.powi(k);
                    let t = self.position(v);
                    if (LABEL_GAP..=1.0 - LABEL_GAP).contains(&t) {
                        out.push((t, v));
                    }
                }
                out.push((1.0, self.max));
                out
            }
        }
    }
}

/// The colour at position `t` in [0, 1] of the scale: [`PALETTE`], mixed linearly between stops.
#[must_use]
pub fn palette(t: f64) -> [u8; 3] {
    let stops = &PALETTE;
    let x = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) } * (stops.len() - 1) as f64;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f64;
    std::array::from_fn(|c| (f64::from(stops[i][c]) * (1.0 - f) + f64::from(stops[i + 1][c]) * f).round() as u8)
}

/// The smallest of 1, 2, 2.5 and 5 times a power of ten that is at least `x` (1 for `x` not
/// positive and finite).
#[must_use]
pub fn nice_ceiling(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0].iter().map(|m| m * p).find(|&v| v >= x * (1.0 - 1e-12)).unwrap_or(10.0 * p)
}

/// A legend label: at most four significant digits, no trailing zeros; scientific notation
/// outside [1e-3, 1e5).
#[must_use]
pub fn format_label(v: f64) -> String {
    if v == 0.0 {
        return "0".to_owned();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.2e}");
    }
    let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_owned() } else { s }
}

/// The per-element values a quantity shows.
fn element_values(solution: &Solution, quantity: Quantity) -> &[[f64; 3]] {
    match quantity {
        Quantity::Irradiance | Quantity::DaylightFactor => &solution.irradiance,
        Quantity::Radiosity => &solution.radiosity,
    }
}

/// Share of the non-emitting surfaces' area (leaf by leaf) whose value is at most the default top
/// of the scale: the few brightest spots, next to the lights, go off the top rather than squeeze
/// the rest of the scene into its bottom colours.
pub const DEFAULT_MAX_AREA_SHARE: f64 = 0.98;

/// The default top of the scale: the displayed value below which [`DEFAULT_MAX_AREA_SHARE`] of
/// the non-emitting leaves' area lies (of all leaves when every surface emits), rounded up by
/// [`nice_ceiling`].
#[must_use]
pub fn default_max(scene: &Scene, h: &Hierarchy, solution: &Solution, config: &FalseColourConfig) -> f64 {
    let values = element_values(solution, config.quantity);
    let (mut lit, mut all) = (Vec::new(), Vec::new());
    for e in h.leaves() {
        let Some(polygon) = h.get(e).polygon() else { continue };
        let Some(v) = values.get(e as usize).map(|&v| config.factor * photopic(v)) else { continue };
        if !v.is_finite() {
            continue;
        }
        let area = h.get(e).area;
        all.push((v, area));
        if !scene.material_of(polygon as usize).is_emitter() {
            lit.push((v, area));
        }
    }
    let mut values = if lit.is_empty() { all } else { lit };
    values.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = values.iter().map(|v| v.1).sum();
    let mut seen = 0.0;
    let top = values
        .iter()
        .find(|(_, area)| {
            seen += area;
            seen >= DEFAULT_MAX_AREA_SHARE * total
        })
        .or(values.last())
        .map_or(0.0, |v| v.0);
    nice_ceiling(top)
}

/// The false-colour picture of `frame` with its legend on the left: RGB bytes, row-major from the
/// top, `frame.width + LEGEND_WIDTH` wide and `max(frame.height, LEGEND_MIN_HEIGHT)` high (the
/// image at the top right); returns the bytes, width and height.
#[must_use]
pub fn false_colour_image(
    scene: &Scene,
    h: &Hierarchy,
    caster: &RayCaster,
    solution: &Solution,
    frame: &Frame,
    samples: u32,
    config: &FalseColourConfig,
) -> (Vec<u8>, u32, u32) {
    let max = config.max.filter(|m| m.is_finite() && *m > 0.0).unwrap_or_else(|| default_max(scene, h, solution, config));
    let scale = ColourScale::new(config.scale, max, config.decades);
    let corners = CornerValues::from_values(h, element_values(solution, config.quantity));
    let picture = trace_pixels(frame, samples, |origin, dir| {
        surface_hit(scene, h, caster, origin, dir)
            .and_then(|hit| corners.interpolate(hit.leaf, hit.kind, hit.s, hit.t))
            .map_or(BACKGROUND, |v| scale.colour(config.factor * photopic(v)))
    });
    let (width, height) = (frame.width + LEGEND_WIDTH, frame.height.max(LEGEND_MIN_HEIGHT));
    let mut canvas = Canvas { rgb: vec![0; 3 * width as usize * height as usize], width, height };
    for y in 0..frame.height {
        let row = 3 * (y * frame.width) as usize;
        let at = 3 * (y * width + LEGEND_WIDTH) as usize;
        canvas.rgb[at..at + 3 * frame.width as usize].copy_from_slice(&picture[row..row + 3 * frame.width as usize]);
    }
    draw_legend(&mut canvas, &scale, config);
    (canvas.rgb, width, height)
}

/// Writes `falsecolor.png` into `dir`: [`false_colour_image`] of the solved scene in `frame`.
pub fn write_false_colour(
    dir: &Path,
    scene: &Scene,
    solved: &Solved,
    frame: &Frame,
    samples: u32,
    config: &FalseColourConfig,
) -> Result<PathBuf, OutputError> {
    let path = dir.join("falsecolor.png");
    let (rgb, width, height) = false_colour_image(scene, &solved.hierarchy, &solved.caster, &solved.solution, frame, samples, config);
    write_png(&path, &rgb, width, height).map_err(|e| OutputError { path: path.clone(), reason: e.to_string() })?;
    Ok(path)
}

/// An RGB picture being drawn on.
struct Canvas {
    rgb: Vec<u8>,
    width: u32,
    height: u32,
}

impl Canvas {
    fn set(&mut self, x: u32, y: u32, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y * self.width + x) as usize;
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    /// Draws `text` with its top-left corner at `(x, y)` in the 8 × 8 font; characters it lacks
    /// are drawn as `?`.
    fn text(&mut self, x: u32, y: u32, text: &str) {
        for (k, ch) in text.chars().enumerate() {
            let glyph = if ch == '²' {
                Some(SUPERSCRIPT_TWO)
            } else {
                font8x8::BASIC_FONTS.get(ch).or_else(|| font8x8::LATIN_FONTS.get(ch)).or_else(|| font8x8::BASIC_FONTS.get('?'))
            };
            let Some(glyph) = glyph else { continue };
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..GLYPH {
                    if bits & (1 << col) != 0 {
                        self.set(x + k as u32 * GLYPH + col, y + row as u32, TEXT_COLOUR);
                    }
                }
            }
        }
    }
}

/// The legend in the left [`LEGEND_WIDTH`] pixels: the quantity and the unit (with `, log` for a
/// logarithmic scale) at the top, then the colour bar, bottom to top, with ticks and labels.
fn draw_legend(canvas: &mut Canvas, scale: &ColourScale, config: &FalseColourConfig) {
    canvas.text(MARGIN, MARGIN, config.quantity.name());
    let unit = match scale.scale {
        Scale::Linear => config.unit.to_owned(),
        Scale::Log => format!("{}, log", config.unit),
    };
    canvas.text(MARGIN, MARGIN + GLYPH + 2, &unit);
    let top = 2 * MARGIN + 2 * GLYPH + 2 + GLYPH / 2;
    let bottom = canvas.height.saturating_sub(MARGIN + GLYPH / 2).max(top + 1);
    let span = f64::from(bottom - top);
    for y in top..=bottom {
        let c = palette(f64::from(bottom - y) / span);
        for x in MARGIN..MARGIN + BAR_WIDTH {
            canvas.set(x, y, c);
        }
    }
    for (t, v) in scale.labels() {
        let y = bottom - (t * span).round() as u32;
        for x in MARGIN + BAR_WIDTH..MARGIN + BAR_WIDTH + 3 {
            canvas.set(x, y, TEXT_COLOUR);
        }
        canvas.text(MARGIN + BAR_WIDTH + 5, y.saturating_sub(GLYPH / 2), &format_label(v));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values_map_to_known_colours() {
        let s = ColourScale::new(Scale::Linear, 120.0, DEFAULT_LOG_DECADES);
        let n = (PALETTE.len() - 1) as f64;
        assert_eq!(s.colour(0.0), PALETTE[0]);
        assert_eq!(s.colour(-5.0), PALETTE[0]);
        assert_eq!(s.colour(120.0), PALETTE[12]);
        assert_eq!(s.colour(1e9), PALETTE[12]);
        // The stops are equally spaced: value 120·k/12 is stop k.
        assert_eq!(s.colour(120.0 * 3.0 / n), PALETTE[3]);
        assert_eq!(s.colour(120.0 * 9.0 / n), PALETTE[9]);
        // Half-way between stops 0 and 1 mixes them: (48+65)/2 = 56.5 → 57 (rounded), ...
        assert_eq!(s.colour(120.0 * 0.5 / n), [57, 44, 115]);
        let log = ColourScale::new(Scale::Log, 1000.0, 3.0);
        assert_eq!(log.min, 1.0);
        assert!((log.position(10.0) - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(log.colour(0.0), PALETTE[0]);
        assert_eq!(log.colour(10f64.powf(3.0 * 6.0 / n)), PALETTE[6]);
    }

    #[test]
    fn legend_labels() {
        let lin = ColourScale::new(Scale::Linear, 250.0, 3.0);
        let labels: Vec<String> = lin.labels().iter().map(|&(_, v)| format_label(v)).collect();
        assert_eq!(labels, ["0", "50", "100", "150", "200", "250"]);
        let log = ColourScale::new(Scale::Log, 250.0, 3.0);
        let labels: Vec<(String, String)> = log.labels().iter().map(|&(t, v)| (format!("{t:.3}"), format_label(v))).collect();
        assert_eq!(
            labels,
            [("0.000", "0.25"), ("0.201", "1"), ("0.534", "10"), ("0.867", "100"), ("1.000", "250")]
                .map(|(a, b)| (a.to_owned(), b.to_owned()))
        );
    }

    #[test]
    fn nice_ceilings_and_labels() {
        assert_eq!(nice_ceiling(0.7), 1.0);
        assert_eq!(nice_ceiling(1.0), 1.0);
        assert_eq!(nice_ceiling(2.2), 2.5);
        assert_eq!(nice_ceiling(31.4), 50.0);
        assert_eq!(nice_ceiling(6000.0), 10000.0);
        assert_eq!(nice_ceiling(f64::NAN), 1.0);
        assert_eq!(format_label(0.125), "0.125");
        assert_eq!(format_label(31.416), "31.42");
        assert_eq!(format_label(1234.4), "1234");
        assert_eq!(format_label(2.5e6), "2.50e6");
        assert_eq!(format_label(0.0002), "2.00e-4");
    }

    #[test]
    fn legend_text_is_drawn_with_the_unit() {
        let mut c = Canvas { rgb: vec![0; 3 * 100 * 20], width: 100, height: 20 };
        c.text(0, 0, "W/m²");
        // Every glyph leaves white pixels in its own 8-pixel cell, the superscript two included.
        for k in 0..4u32 {
            let lit = (0..8).flat_map(|y| (0..8).map(move |x| (x, y))).any(|(x, y)| c.rgb[3 * (y * 100 + 8 * k + x) as usize] == 255);
            assert!(lit, "glyph {k} drawn");
        }
        // The fifth row of `²` is its foot, pixels 2 to 5 (the acute accent has none there).
        let foot: Vec<bool> = (0..8).map(|x| c.rgb[3 * (4 * 100 + 24 + x) as usize] == 255).collect();
        assert_eq!(foot, [false, false, true, true, true, true, false, false]);
    }
}
