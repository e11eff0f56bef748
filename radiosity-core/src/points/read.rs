//! The calculation points file (`radiosity solve --points FILE`).
//!
//! Comma-separated text, one point a line; blank lines and lines starting with `#` are ignored,
//! spaces around a field too. Without a header, a row is `x,y,z,nx,ny,nz` (6 fields) or
//! `name,x,y,z,nx,ny,nz` (7 fields). A first line with a field named `x` is a header: it names the
//! columns, in any order, from `name,x,y,z,nx,ny,nz` (`name` optional) and every row then has as
//! many fields. A name may be quoted (`"A, left"`, `""` for a quote); an empty or absent name is
//! the point's 1-based row number among the points. The normal `(nx, ny, nz)` need not be unit
//! length but must not be zero. Every error names the file, the line and the reason.

use super::CalcPoint;
use crate::geom::DVec3;
use std::path::{Path, PathBuf};

/// A points file that cannot be read or holds a bad row.
#[derive(Debug, thiserror::Error)]
pub enum PointsError {
    /// The file could not be read.
    #[error("{}: cannot read file: {source}", path.display())]
    Io {
        /// File that failed.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// A bad header or row.
    #[error("{}:{line}: {msg}", path.display())]
    Parse {
        /// File.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// The file holds no point.
    #[error("{}: no points (expected rows `x,y,z,nx,ny,nz` or `name,x,y,z,nx,ny,nz`)", path.display())]
    Empty {
        /// File.
        path: PathBuf,
    },
}

/// The columns of a points file, in the order of a headerless 7-field row.
const COLUMNS: [&str; 7] = ["name", "x", "y", "z", "nx", "ny", "nz"];

/// Reads the points of `path` (format in the module documentation).
pub fn read_points(path: &Path) -> Result<Vec<CalcPoint>, PointsError> {
    let text = std::fs::read_to_string(path).map_err(|source| PointsError::Io { path: path.to_owned(), source })?;
    parse_points(path, &text)
}

/// Parses the text of a points file; `path` names it in errors.
pub fn parse_points(path: &Path, text: &str) -> Result<Vec<CalcPoint>, PointsError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Column index of each of COLUMNS in a row, from the header; None before the first row.
    let mut header: Option<[Option<usize>; 7]> = None;
    let mut n_header_fields = 0;
    let mut seen_first = false;
    let mut points = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let err = |msg: String| PointsError::Parse { path: path.to_owned(), line: line_no, msg };
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let fields = split_fields(trimmed).map_err(err)?;
        if !seen_first {
            seen_first = true;
            if fields.iter().any(|f| f.eq_ignore_ascii_case("x")) {
                header = Some(parse_header(&fields).map_err(err)?);
                n_header_fields = fields.len();
                continue;
            }
        }
        let cols: [Option<usize>; 7] = match header {
            Some(cols) if fields.len() == n_header_fields => cols,
            Some(_) => {
                return Err(err(format!("expected {n_header_fields} fields as the header names them, found {}", fields.len())));
            }
            None if fields.len() == 6 => [None, Some(0), Some(1), Some(2), Some(3), Some(4), Some(5)],
            None if fields.len() == 7 => [Some(0), Some(1), Some(2), Some(3), Some(4), Some(5), Some(6)],
            None => {
                return Err(err(format!("expected 6 fields `x,y,z,nx,ny,nz` or 7 fields `name,x,y,z,nx,ny,nz`, found {}", fields.len())));
            }
        };
        let mut v = [0.0; 6];
        for (k, value) in v.iter_mut().enumerate() {
            let name = COLUMNS[k + 1];
            let text = &fields[cols[k + 1].expect("x..nz are required columns")];
            *value = number(name, text).map_err(err)?;
        }
        let name = match cols[0].map(|c| fields[c].as_str()) {
            Some(name) if !name.is_empty() => name.to_owned(),
            _ => (points.len() + 1).to_string(),
        };
        let point = CalcPoint::new(name, DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]))
            .ok_or_else(|| err("zero normal: `nx,ny,nz` must not all be 0".to_string()))?;
        points.push(point);
    }
    if points.is_empty() {
        return Err(PointsError::Empty { path: path.to_owned() });
    }
    Ok(points)
}

/// The position of each of [`COLUMNS`] among the header's fields.
fn parse_header(fields: &[String]) -> Result<[Option<usize>; 7], String> {
    let mut cols = [None; 7];
    for (i, f) in fields.iter().enumerate() {
        let k = COLUMNS
            .iter()
            .position(|c| f.eq_ignore_ascii_case(c))
            .ok_or_else(|| format!("unknown column `{f}` in the header (expected {})", COLUMNS.join(",")))?;
        if cols[k].replace(i).is_some() {
            return Err(format!("column `{}` named twice in the header", COLUMNS[k]));
        }
    }
    if let Some(k) = (1..7).find(|&k| cols[k].is_none()) {
        return Err(format!("the header names no column `{}` (required: x,y,z,nx,ny,nz)", COLUMNS[k]));
    }
    Ok(cols)
}

/// The finite number in field `text` of column `name`.
fn number(name: &str, text: &str) -> Result<f64, String> {
    if text.is_empty() {
        return Err(format!("`{name}` is missing"));
    }
    let v: f64 = text.parse().map_err(|_| format!("`{name}` is not a number: `{text}`"))?;
    if v.is_finite() { Ok(v) } else { Err(format!("`{name}` is not finite: `{text}`")) }
}

/// The comma-separated fields of `line`, trimmed; a field may be quoted, `""` standing for `"`.
fn split_fields(line: &str) -> Result<Vec<String>, String> {
    let mut fields = Vec::new();
    let mut cur = String::new();
    let mut in_quotes = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if in_quotes => {
                if chars.peek() == Some(&'"') {
                    cur.push('"');
                    let _ = chars.next();
                } else {
                    in_quotes = false;
                }
            }
            '"' if cur.trim().is_empty() => {
                cur.clear();
                in_quotes = true;
            }
            ',' if !in_quotes => fields.push(std::mem::take(&mut cur).trim().to_owned()),
            c => cur.push(c),
        }
    }
    if in_quotes {
        return Err("unterminated quoted field".to_string());
    }
    fields.push(cur.trim().to_owned());
    Ok(fields)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Vec<CalcPoint>, String> {
        parse_points(Path::new("p.csv"), text).map_err(|e| e.to_string())
    }

    #[test]
    fn headerless_rows_with_and_without_names() {
        let p = parse("# calculation points\n\n1,2,3,0,0,2\nA,0,0,0, 1,0,0\n").unwrap();
        assert_eq!(p.len(), 2);
        assert_eq!((p[0].name.as_str(), p[0].position, p[0].normal), ("1", DVec3::new(1.0, 2.0, 3.0), DVec3::Z));
        assert_eq!((p[1].name.as_str(), p[1].normal), ("A", DVec3::X));
    }

    #[test]
    fn header_in_any_order_with_quoted_names() {
        let p = parse("nz,ny,nx,z,y,x,name\n1,0,0,3,2,1,\"left, \"\"A\"\"\"\n1,0,0,0,0,0,\n").unwrap();
        assert_eq!(p[0].name, "left, \"A\"");
        assert_eq!((p[0].position, p[0].normal), (DVec3::new(1.0, 2.0, 3.0), DVec3::Z));
        assert_eq!(p[1].name, "2", "an empty name is the row number");
        let p = parse("X, Y, Z, NX, NY, NZ\r\n0,0,0,0,-3,0\r\n").unwrap();
        assert_eq!((p[0].name.as_str(), p[0].normal), ("1", -DVec3::Y));
    }

    #[test]
    fn errors_name_file_line_and_reason() {
        let cases = [
            ("x,y,z,nx,ny,nz\n0,0,0,0,0,1\n0,0,0,0,1\n", "p.csv:3: expected 6 fields as the header names them, found 5"),
            ("0,0,0,0,1\n", "p.csv:1: expected 6 fields `x,y,z,nx,ny,nz` or 7 fields `name,x,y,z,nx,ny,nz`, found 5"),
            ("\n0,0,zero,0,0,1\n", "p.csv:2: `z` is not a number: `zero`"),
            ("0,0,0,NaN,0,1\n", "p.csv:1: `nx` is not finite: `NaN`"),
            ("0,0,0,0,0,inf\n", "p.csv:1: `nz` is not finite: `inf`"),
            ("0,,0,0,0,1\n", "p.csv:1: `y` is missing"),
            ("a,0,0,0,0,0,0\n", "p.csv:1: zero normal: `nx,ny,nz` must not all be 0"),
            ("x,y,z,nx,ny,nz,colour\n", "p.csv:1: unknown column `colour` in the header (expected name,x,y,z,nx,ny,nz)"),
            ("x,y,z,nx,ny,x\n", "p.csv:1: column `x` named twice in the header"),
            ("name,x,y,z,nx,ny\n", "p.csv:1: the header names no column `nz` (required: x,y,z,nx,ny,nz)"),
            ("\"a,0,0,0,0,0,1\n", "p.csv:1: unterminated quoted field"),
            ("# nothing\nx,y,z,nx,ny,nz\n", "p.csv: no points (expected rows `x,y,z,nx,ny,nz` or `name,x,y,z,nx,ny,nz`)"),
        ];
        for (text, expected) in cases {
            assert_eq!(parse(text).unwrap_err(), expected, "for {text:?}");
        }
    }
}
