//! IES LM-63 files (1986, 1991, 1995, 2002): type C photometry.
//!
//! Everything before the `TILT=` line is header (the version line `IESNA:LM-63-1995`,
//! `IESNA:LM-63-2002` or `IESNA91`, and `[KEYWORD]` lines; free text in 1986 files) and is not
//! interpreted. `TILT=NONE` is the usual case; `TILT=INCLUDE` is read (lamp-to-luminaire geometry,
//! pair count, angles, factors) and its factors are not applied: the luminaire is taken in its
//! measured orientation. `TILT=<file>` is refused. The numbers after it are separated by
//! whitespace or commas, across lines: lamps, lumens per lamp (−1: absolute photometry), candela
//! multiplier, vertical and horizontal angle counts, photometric type (1 = C; B and A are
//! refused), units (1 feet, 2 metres), width, length, height of the luminous opening; ballast
//! factor, ballast-lamp photometric factor (1995 and earlier; "future use" in 2002, not applied),
//! input watts; the vertical angles, the horizontal angles, and the candela values, one horizontal
//! angle's vertical row after another. A negative width or length (a round opening in LM-63-2002)
//! is taken by its size. Horizontal angles must start at 0 (files whose horizontal angles run
//! 90–270 are refused).

use super::{MAX_ANGLES, MAX_VALUES, Photometry, PhotometryError, Tokens, check_angles, non_negative, read_text};
use std::path::Path;

/// Metres per foot (IES units type 1).
const METRES_PER_FOOT: f64 = 0.3048;

/// Most TILT pairs read.
const MAX_TILT_PAIRS: usize = 1000;

/// Reads an IES LM-63 file (format in the module documentation).
pub fn read_ies(path: &Path) -> Result<Photometry, PhotometryError> {
    let text = read_text(path)?;
    parse_ies(&text, &path.display().to_string())
}

/// Parses the text of an IES LM-63 file; `source` names it in messages.
pub fn parse_ies(text: &str, source: &str) -> Result<Photometry, PhotometryError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let lines: Vec<&str> = text.lines().collect();
    let Some(tilt_idx) = lines.iter().position(|l| l.trim_start().to_ascii_uppercase().starts_with("TILT")) else {
        return Err(PhotometryError::file(source, "missing `TILT=` line (not an IES LM-63 file?)"));
    };
    let tilt_line = tilt_idx + 1;
    let compact: String = lines[tilt_idx].chars().filter(|c| !c.is_whitespace()).collect();
    let Some(tilt) = compact.get(4..).and_then(|s| s.strip_prefix('=')) else {
        return Err(PhotometryError::at(source, tilt_line, "expected `TILT=NONE`, `TILT=INCLUDE` or `TILT=<file>`"));
    };
    let mut tokens = Tokens::new(lines[tilt_idx + 1..].iter().copied(), tilt_line + 1, source);
    match tilt.to_ascii_uppercase().as_str() {
        "NONE" => {}
        "INCLUDE" => {
            let (geometry, line) = tokens.number("the TILT lamp-to-luminaire geometry")?;
            if ![1.0, 2.0, 3.0].contains(&geometry) {
                return Err(PhotometryError::at(
                    source,
                    line,
                    format!("TILT lamp-to-luminaire geometry must be 1, 2 or 3, found {geometry}"),
                ));
            }
            let n = tokens.count("the number of TILT angles", MAX_TILT_PAIRS)?;
            let angles = tokens.numbers(n, "TILT angle", |_| Ok(()))?;
            check_angles(&angles, "TILT", 0.0, 180.0, source, tokens.line())?;
            let _ = tokens.numbers(n, "TILT factor", |v| if v < 0.0 { Err(format!("negative factor {v}")) } else { Ok(()) })?;
        }
        _ => {
            return Err(PhotometryError::at(
                source,
                tilt_line,
                format!("`TILT={tilt}`: tilt data in another file is not supported (use TILT=NONE or TILT=INCLUDE)"),
            ));
        }
    }
    let (lamps, lamps_line) = tokens.number("the number of lamps")?;
    if lamps <= 0.0 {
        return Err(PhotometryError::at(source, lamps_line, format!("number of lamps must be positive, found {lamps}")));
    }
    let (lumens_per_lamp, line) = tokens.number("the lumens per lamp")?;
    if lumens_per_lamp <= 0.0 && lumens_per_lamp != -1.0 {
        return Err(PhotometryError::at(
            source,
            line,
            format!("lumens per lamp must be positive or -1 (absolute photometry), found {lumens_per_lamp}"),
        ));
    }
    let (multiplier, line) = tokens.number("the candela multiplier")?;
    if multiplier <= 0.0 {
        return Err(PhotometryError::at(source, line, format!("candela multiplier must be positive, found {multiplier}")));
    }
    let n_gamma = tokens.count("the number of vertical angles", MAX_ANGLES)?;
    let n_c = tokens.count("the number of horizontal angles", MAX_ANGLES)?;
    if n_gamma * n_c > MAX_VALUES {
        return Err(PhotometryError::at(source, tokens.line(), format!("{n_gamma} × {n_c} intensities is more than {MAX_VALUES}")));
    }
    let (kind, line) = tokens.number("the photometric type")?;
    match kind {
        1.0 => {}
        2.0 | 3.0 => {
            let name = if kind == 2.0 { "B" } else { "A" };
            return Err(PhotometryError::at(
                source,
                line,
                format!("type {name} photometry is not supported (only type C, photometric type 1)"),
            ));
        }
        _ => return Err(PhotometryError::at(source, line, format!("photometric type must be 1 (C), 2 (B) or 3 (A), found {kind}"))),
    }
    let (units, line) = tokens.number("the units type")?;
    let metres = match units {
        1.0 => METRES_PER_FOOT,
        2.0 => 1.0,
        _ => return Err(PhotometryError::at(source, line, format!("units type must be 1 (feet) or 2 (metres), found {units}"))),
    };
    let (width, _) = tokens.number("the width")?;
    let (length, _) = tokens.number("the length")?;
    let (height, _) = tokens.number("the height")?;
    let (ballast, line) = tokens.number("the ballast factor")?;
    if ballast <= 0.0 {
        return Err(PhotometryError::at(source, line, format!("ballast factor must be positive, found {ballast}")));
    }
    let (ballast_lamp, line) = tokens.number("the ballast-lamp photometric factor")?;
    if ballast_lamp <= 0.0 {
        return Err(PhotometryError::at(source, line, format!("ballast-lamp photometric factor must be positive, found {ballast_lamp}")));
    }
    let _input_watts = tokens.number("the input watts")?;
    let gamma = tokens.numbers(n_gamma, "vertical angle", |_| Ok(()))?;
    check_angles(&gamma, "vertical", 0.0, 180.0, source, tokens.line())?;
    let c = tokens.numbers(n_c, "horizontal angle", |_| Ok(()))?;
    check_angles(&c, "horizontal", 0.0, 360.0, source, tokens.line())?;
    if c[0] != 0.0 {
        return Err(PhotometryError::at(
            source,
            tokens.line(),
            format!("horizontal angles must start at 0, found {} (tables of 90–270° are not supported)", c[0]),
        ));
    }
    let scale = multiplier * ballast;
    let mut candela = Vec::with_capacity(n_c);
    for &angle in &c {
        let row = tokens.numbers(n_gamma, &format!("candela value (horizontal angle {angle}) at vertical angle"), non_negative)?;
        candela.push(row.into_iter().map(|v| v * scale).collect::<Vec<f64>>());
    }
    tokens.finish("the candela values")?;
    let p = Photometry {
        gamma,
        c,
        candela,
        declared_lumens: (lumens_per_lamp > 0.0).then_some(lamps * lumens_per_lamp),
        opening: [width.abs() * metres, length.abs() * metres, height.abs() * metres],
        source: source.to_owned(),
    };
    p.validate().map_err(|msg| PhotometryError::at(source, tokens.line(), msg))?;
    Ok(p)
}
