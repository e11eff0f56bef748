//! EULUMDAT (`.ldt`) files: type C photometry.
//!
//! Lines 1–26 are the header, one field a line (text fields are not interpreted): the symmetry
//! indicator Isym (line 3: 0 none, 1 about the vertical axis, 2 about the C0–C180 plane, 3 about
//! the C90–C270 plane, 4 about both), the number of C planes Mc over the circle (line 4), the
//! number of γ angles Ng (line 6), the luminaire's and the luminous area's sizes in mm (lines
//! 13–21), the conversion factor of the intensities (line 24) and the number of lamp sets (line
//! 26), each set six lines whose third is its lamps' total flux (lm). Then ten direct ratios, the
//! Mc C angles (every plane of the circle, from 0), the Ng γ angles, and the intensities in cd per
//! 1000 lm, one C plane's γ row after another, for the planes the symmetry keeps: all of them
//! (Isym 0), one (1), C0–C180 (2), C90–C270 (3), C0–C90 (4). Values after the header may share
//! lines; a comma is read as a decimal point. Intensities are scaled to cd by the lamps' total flux
//! / 1000 and the conversion factor. Isym 3 is mirrored into a full table (I(C) = I(180° − C)).
//! The luminous opening is the luminous area: length (line 16) along C0, width (line 17; 0: round,
//! the length) along C90, and the largest of its heights (lines 18–21).

use super::{ANGLE_TOL_DEG, MAX_ANGLES, MAX_VALUES, Photometry, PhotometryError, Tokens, check_angles, non_negative, read_text};
use std::path::Path;

/// Lines of the fixed part of the header (up to the number of lamp sets).
const FIXED_HEADER_LINES: usize = 26;

/// Lines per lamp set.
const LINES_PER_LAMP_SET: usize = 6;

/// Direct ratio lines after the lamp sets.
const DIRECT_RATIO_LINES: usize = 10;

/// Most lamp sets read.
const MAX_LAMP_SETS: usize = 100;

/// Millimetres per metre.
const MM_PER_M: f64 = 1000.0;

/// Reads a EULUMDAT file (format in the module documentation).
pub fn read_ldt(path: &Path) -> Result<Photometry, PhotometryError> {
    let text = read_text(path)?;
    parse_ldt(&text, &path.display().to_string())
}

/// Parses the text of a EULUMDAT file; `source` names it in messages.
pub fn parse_ldt(text: &str, source: &str) -> Result<Photometry, PhotometryError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let lines: Vec<String> = text.lines().map(|l| l.replace(',', ".")).collect();
    let field = |line: usize, what: &str| -> Result<f64, PhotometryError> {
        let Some(t) = lines.get(line - 1) else {
            return Err(PhotometryError::at(source, lines.len().max(1), format!("file ends before line {line} ({what})")));
        };
        match t.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(PhotometryError::at(source, line, format!("{what}: `{}` is not a finite number", t.trim()))),
        }
    };
    let whole = |line: usize, what: &str, lo: usize, hi: usize| -> Result<usize, PhotometryError> {
        let v = field(line, what)?;
        if v.fract() != 0.0 || v < lo as f64 || v > hi as f64 {
            return Err(PhotometryError::at(source, line, format!("{what} must be a whole number from {lo} to {hi}, found {v}")));
        }
        Ok(v as usize)
    };
    let isym = whole(3, "symmetry indicator Isym", 0, 4)?;
    let mc = whole(4, "number of C planes Mc", 1, MAX_ANGLES)?;
    let ng = whole(6, "number of γ angles Ng", 1, MAX_ANGLES)?;
    let divisor = match isym {
        2 | 3 => 2,
        4 => 4,
        _ => 1,
    };
    if isym >= 2 && mc % divisor != 0 {
        return Err(PhotometryError::at(
            source,
            4,
            format!("Mc = {mc} C planes cannot be split by symmetry Isym = {isym} (needs a multiple of {divisor})"),
        ));
    }
    let n_stored = match isym {
        0 => mc,
        1 => 1,
        _ => mc / divisor + 1,
    };
    if n_stored * ng > MAX_VALUES {
        return Err(PhotometryError::at(source, 6, format!("{n_stored} × {ng} intensities is more than {MAX_VALUES}")));
    }
    let mm = |line: usize, what: &str| -> Result<f64, PhotometryError> {
        let v = field(line, what)?;
        if v < 0.0 {
            return Err(PhotometryError::at(source, line, format!("{what} must not be negative, found {v}")));
        }
        Ok(v / MM_PER_M)
    };
    let length = mm(16, "length of the luminous area")?;
    let width = mm(17, "width of the luminous area")?;
    let mut height: f64 = 0.0;
    for (line, plane) in [(18, "C0"), (19, "C90"), (20, "C180"), (21, "C270")] {
        height = height.max(mm(line, &format!("height of the luminous area at {plane}"))?);
    }
    let factor = field(24, "conversion factor")?;
    if factor <= 0.0 {
        return Err(PhotometryError::at(source, 24, format!("conversion factor must be positive, found {factor}")));
    }
    let n_sets = whole(26, "number of lamp sets", 1, MAX_LAMP_SETS)?;
    let mut lumens = 0.0;
    for k in 0..n_sets {
        let line = FIXED_HEADER_LINES + k * LINES_PER_LAMP_SET + 3;
        let flux = field(line, &format!("lamp set {}: total flux of the lamps", k + 1))?;
        if flux <= 0.0 {
            return Err(PhotometryError::at(
                source,
                line,
                format!("lamp set {}: total flux of the lamps must be positive, found {flux}", k + 1),
            ));
        }
        lumens += flux;
    }
    let first = FIXED_HEADER_LINES + n_sets * LINES_PER_LAMP_SET + DIRECT_RATIO_LINES + 1;
    if lines.len() < first - 1 {
        return Err(PhotometryError::at(
            source,
            lines.len().max(1),
            format!("file ends in its header (expected {} lines before the angles)", first - 1),
        ));
    }
    let mut tokens = Tokens::new(lines[first - 1..].iter().map(String::as_str), first, source);
    let all_c = tokens.numbers(mc, "C angle", |_| Ok(()))?;
    check_angles(&all_c, "C", 0.0, 360.0, source, tokens.line())?;
    let gamma = tokens.numbers(ng, "γ angle", |_| Ok(()))?;
    check_angles(&gamma, "γ", 0.0, 180.0, source, tokens.line())?;
    let stored_c: Vec<f64> = match isym {
        1 => vec![0.0],
        3 => {
            let start = all_c
                .iter()
                .position(|&c| (c - 90.0).abs() <= ANGLE_TOL_DEG)
                .ok_or_else(|| PhotometryError::at(source, tokens.line(), "symmetry Isym = 3 needs a C plane at 90° in the C angles"))?;
            all_c.get(start..start + n_stored).map(<[f64]>::to_vec).ok_or_else(|| {
                PhotometryError::at(source, tokens.line(), format!("symmetry Isym = 3 needs {n_stored} C planes from 90°"))
            })?
        }
        _ => all_c[..n_stored].to_vec(),
    };
    let scale = lumens / 1000.0 * factor;
    let mut stored = Vec::with_capacity(n_stored);
    for &c in &stored_c {
        let row = tokens.numbers(ng, &format!("intensity (C plane {c}) at γ angle"), non_negative)?;
        stored.push(row.into_iter().map(|v| v * scale).collect::<Vec<f64>>());
    }
    tokens.finish("the intensities")?;
    let (c, candela) = if isym == 3 {
        // Every plane of the circle, from the kept half by I(C) = I(180° − C).
        let mut rows = Vec::with_capacity(mc);
        for &c in &all_c {
            let mirrored = if (90.0..=270.0).contains(&c) { c } else { (180.0 - c).rem_euclid(360.0) };
            let k = stored_c.iter().position(|&s| (s - mirrored).abs() <= ANGLE_TOL_DEG).ok_or_else(|| {
                PhotometryError::at(
                    source,
                    tokens.line(),
                    format!("symmetry Isym = 3: C plane {c} has no mirror plane {mirrored} among C90–C270"),
                )
            })?;
            rows.push(stored[k].clone());
        }
        (all_c, rows)
    } else {
        (stored_c, stored)
    };
    let p = Photometry {
        gamma,
        c,
        candela,
        declared_lumens: Some(lumens),
        opening: [if width > 0.0 { width } else { length }, length, height],
        source: source.to_owned(),
    };
    p.validate().map_err(|msg| PhotometryError::at(source, tokens.line(), format!("{msg} (symmetry Isym = {isym})")))?;
    Ok(p)
}
