//! Radiance-style view options (`-vp -vd -vu -vh -vv -vtv`, inline or in a `.vf` file): each one
//! given overrides the view it is applied to.

use super::View;
use super::pinhole::PARALLEL_SINE;
use crate::geom::DVec3;
use std::path::{Path, PathBuf};

/// Largest full angle of a perspective view, degrees (exclusive).
pub const MAX_VIEW_ANGLE_DEG: f64 = 180.0;

/// A view given with Radiance's options: each field set overrides the view it is applied to.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewSpec {
    /// `-vp x y z`: eye position.
    pub position: Option<DVec3>,
    /// `-vd dx dy dz`: view direction (non-zero; its length does not matter).
    pub direction: Option<DVec3>,
    /// `-vu ux uy uz`: view up vector (non-zero).
    pub up: Option<DVec3>,
    /// `-vh degrees`: full horizontal angle.
    pub horizontal_deg: Option<f64>,
    /// `-vv degrees`: full vertical angle.
    pub vertical_deg: Option<f64>,
}

/// A view that cannot be read: the reason, with the file and line when it came from a file.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// Inline options that are malformed.
    #[error("{0}")]
    Options(String),
    /// A view file line that is malformed.
    #[error("{}:{line}: {reason}", path.display())]
    Line {
        /// The view file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// A view file that cannot be read (the reason is the source).
    #[error("{}: cannot read view file", path.display())]
    Io {
        /// The view file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A view file with no view options.
    #[error("{}: no view options in the file", path.display())]
    Empty {
        /// The view file.
        path: PathBuf,
    },
}

/// Program names that may start a line of a view file (as `rvu`'s `view` command writes it).
const PROGRAM_NAMES: &[&str] = &["rview", "rvu", "rpict", "rtrace", "rholo", "pinterp"];
/// Options Radiance writes in every saved view that this renderer accepts only at their default, 0:
/// fore and aft clipping, view shift and lift.
const ZERO_ONLY: &[&str] = &["-vo", "-va", "-vs", "-vl"];

impl ViewSpec {
    /// Parses Radiance view options (`-vtv -vp 0 0 1.5 -vd 1 0 0 -vu 0 0 1 -vh 60 -vv 45`),
    /// optionally after a program name (`rvu`, `rview`, `rpict`, ...) or `VIEW=`. Lines are read in
    /// order, later options overriding earlier ones; blank lines and `#` comments are skipped.
    pub fn parse(text: &str) -> Result<ViewSpec, ViewError> {
        let mut spec = ViewSpec::default();
        for line in text.lines() {
            spec.parse_line(line).map_err(ViewError::Options)?;
        }
        Ok(spec)
    }

    /// Reads a Radiance view file (`.vf`): lines of options as [`ViewSpec::parse`] reads them.
    pub fn read(path: &Path) -> Result<ViewSpec, ViewError> {
        let text = std::fs::read_to_string(path).map_err(|source| ViewError::Io { path: path.to_owned(), source })?;
        let mut spec = ViewSpec::default();
        let mut any = false;
        for (i, line) in text.lines().enumerate() {
            any |= spec.parse_line(line).map_err(|reason| ViewError::Line { path: path.to_owned(), line: i + 1, reason })?;
        }
        if any { Ok(spec) } else { Err(ViewError::Empty { path: path.to_owned() }) }
    }

    /// Parses one line into `self`; true when it held options.
    fn parse_line(&mut self, line: &str) -> Result<bool, String> {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            return Ok(false);
        }
        let line = line.strip_prefix("VIEW=").unwrap_or(line);
        let mut tokens = line.split_whitespace().peekable();
        if tokens.peek().is_some_and(|t| PROGRAM_NAMES.contains(t)) {
            let _ = tokens.next();
        }
        let mut any = false;
        while let Some(opt) = tokens.next() {
            any = true;
            let mut numbers = |n: usize| -> Result<Vec<f64>, String> {
                let mut out = Vec::with_capacity(n);
                for _ in 0..n {
                    let tok =
                        tokens.next().ok_or_else(|| format!("view option {opt} needs {n} number{}", if n == 1 { "" } else { "s" }))?;
                    let x: f64 = tok.parse().map_err(|_| format!("view option {opt}: `{tok}` is not a number"))?;
                    if !x.is_finite() {
                        return Err(format!("view option {opt}: `{tok}` is not a finite number"));
                    }
                    out.push(x);
                }
                Ok(out)
            };
            match opt {
                "-vtv" => {}
                "-vp" => self.position = Some(vec3(&numbers(3)?)),
                "-vd" | "-vu" => {
                    let v = vec3(&numbers(3)?);
                    if v.length_squared() == 0.0 {
                        return Err(format!("view option {opt} must not be the zero vector"));
                    }
                    if opt == "-vd" {
                        self.direction = Some(v);
                    } else {
                        self.up = Some(v);
                    }
                }
                "-vh" | "-vv" => {
                    let a = numbers(1)?[0];
                    if !(a > 0.0 && a < MAX_VIEW_ANGLE_DEG) {
                        return Err(format!("view option {opt} must be between 0 and {MAX_VIEW_ANGLE_DEG} degrees (perspective), got {a}"));
                    }
                    if opt == "-vh" {
                        self.horizontal_deg = Some(a);
                    } else {
                        self.vertical_deg = Some(a);
                    }
                }
                o if ZERO_ONLY.contains(&o) => {
                    let x = numbers(1)?[0];
                    if x != 0.0 {
                        return Err(format!("view option {opt} {x} is not supported (only {opt} 0)"));
                    }
                }
                o if o.starts_with("-vt") => {
                    return Err(format!("view type {o} is not supported (only -vtv, perspective)"));
                }
                "-vf" => return Err("view option -vf (a view file inside a view) is not supported".to_owned()),
                o if o.starts_with('-') => return Err(format!("unsupported view option {o}")),
                o => return Err(format!("unexpected `{o}` in a view (options start with -v)")),
            }
        }
        if let (Some(d), Some(u)) = (self.direction, self.up)
            && d.normalize().cross(u.normalize()).length() <= PARALLEL_SINE
        {
            return Err("view up vector (-vu) is parallel to the view direction (-vd)".to_owned());
        }
        Ok(any)
    }

    /// `base` with the options given here overriding its fields. An up vector that the direction
    /// makes parallel is replaced by a world axis (see [`View::new`]).
    #[must_use]
    pub fn apply(&self, base: &View) -> View {
        let deg = |a: Option<f64>, default: f64| a.map_or(default, f64::to_radians);
        View::new(
            self.position.unwrap_or(base.position),
            self.direction.unwrap_or(base.direction),
            self.up.unwrap_or(base.up),
            deg(self.horizontal_deg, base.horizontal),
            deg(self.vertical_deg, base.vertical),
        )
    }
}

fn vec3(v: &[f64]) -> DVec3 {
    DVec3::new(v[0], v[1], v[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn parses_a_saved_rvu_view() {
        let spec = ViewSpec::parse("rvu -vtv -vp 1 2 3 -vd 0 2 0 -vu 0 0 1 -vh 60 -vv 45 -vo 0 -va 0 -vs 0 -vl 0").unwrap();
        assert_eq!(spec.position, Some(DVec3::new(1.0, 2.0, 3.0)));
        assert_eq!(spec.direction, Some(DVec3::new(0.0, 2.0, 0.0)));
        assert_eq!(spec.horizontal_deg, Some(60.0));
        assert_eq!(spec.vertical_deg, Some(45.0));
        let base = View::new(DVec3::ZERO, DVec3::X, DVec3::Z, 1.0, 1.0);
        let v = spec.apply(&base);
        assert!(close(v.direction, DVec3::Y) && close(v.up, DVec3::Z));
        assert!((v.horizontal - 60f64.to_radians()).abs() < 1e-12);
        // tan(30°) / tan(22.5°) = 1.3938: a 512 box gives 512 × 367.
        assert_eq!(v.image_size(512, 512), (512, 367));
    }

    #[test]
    fn a_view_written_as_options_reads_back() {
        let v = View::new(DVec3::new(1.5, -2.0, 0.25), DVec3::new(1.0, 2.0, -0.5), DVec3::Z, 1.1, 0.7);
        let text = v.to_string();
        assert!(text.starts_with("rvu -vtv -vp 1.5 -2 0.25 -vd "), "{text}");
        let back = ViewSpec::parse(&text).unwrap().apply(&View::new(DVec3::ZERO, DVec3::X, DVec3::Y, 0.1, 0.1));
        assert!(close(back.position, v.position) && close(back.direction, v.direction) && close(back.up, v.up));
        assert!((back.horizontal - v.horizontal).abs() < 1e-12 && (back.vertical - v.vertical).abs() < 1e-12);
    }

    #[test]
    fn options_override_only_what_they_give() {
        let base = View::new(DVec3::ONE, DVec3::X, DVec3::Z, 1.0, 0.5);
        let v = ViewSpec::parse("-vp 0 0 1").unwrap().apply(&base);
        assert_eq!(v, View { position: DVec3::Z, ..base });
    }

    #[test]
    fn malformed_views_are_one_line_errors() {
        for (text, expected) in [
            ("-vtl -vp 0 0 0", "view type -vtl is not supported (only -vtv, perspective)"),
            ("-vp 1 2", "view option -vp needs 3 numbers"),
            ("-vp 1 x 2", "view option -vp: `x` is not a number"),
            ("-vd 0 0 0", "view option -vd must not be the zero vector"),
            ("-vh 200", "view option -vh must be between 0 and 180 degrees (perspective), got 200"),
            ("-vs 0.5", "view option -vs 0.5 is not supported (only -vs 0)"),
            ("-vx 1", "unsupported view option -vx"),
            ("-vd 0 0 1 -vu 0 0 -2", "view up vector (-vu) is parallel to the view direction (-vd)"),
            ("hello", "unexpected `hello` in a view (options start with -v)"),
        ] {
            let e = ViewSpec::parse(text).unwrap_err().to_string();
            assert_eq!(e, expected, "{text}");
        }
    }

    #[test]
    fn view_file_errors_name_the_file_and_line() {
        let dir = std::env::temp_dir().join(format!("radiosity-view-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.vf");
        std::fs::write(&path, "# a view\nrview -vtv -vp 0 0 1\n-vta\n").unwrap();
        let e = ViewSpec::read(&path).unwrap_err().to_string();
        assert_eq!(e, format!("{}:3: view type -vta is not supported (only -vtv, perspective)", path.display()));
        std::fs::write(&path, "# nothing\n").unwrap();
        assert!(ViewSpec::read(&path).unwrap_err().to_string().ends_with("no view options in the file"));
        std::fs::write(&path, "VIEW= -vtv -vp 0 0 1 -vd 1 0 0\n").unwrap();
        assert_eq!(ViewSpec::read(&path).unwrap().direction, Some(DVec3::X));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_parallel_base_up_is_replaced_by_an_axis() {
        let base = View::new(DVec3::ZERO, DVec3::X, DVec3::Z, 1.0, 1.0);
        let v = ViewSpec::parse("-vd 0 0 -1").unwrap().apply(&base);
        assert!(close(v.direction, DVec3::NEG_Z));
        assert!(v.up.dot(v.direction).abs() < 1e-12 && (v.up.length() - 1.0).abs() < 1e-12);
    }
}
