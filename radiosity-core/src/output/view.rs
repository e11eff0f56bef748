//! Views of a scene: the pinhole [`View`] the images are drawn from, Radiance-style view options
//! ([`ViewSpec`]: `-vp -vd -vu -vh -vv -vtv`, inline or in a `.vf` file), and the candidate
//! default views of a scene without a camera ([`candidate_views`]).
//!
//! Radiance's conventions are kept: `-vh` and `-vv` are the full horizontal and vertical angles in
//! degrees, `-vd` need not be a unit vector, and options given override the view they modify (the
//! scene's own camera, or the default view).

use crate::geom::{Aabb, DVec3};
use crate::scene::{Camera, Scene};
use std::path::{Path, PathBuf};

/// Vertical field of view of the default views seen from outside the scene, degrees.
pub const OUTSIDE_FOV_DEG: f64 = 45.0;
/// Vertical field of view of the default views from inside the scene, degrees.
pub const INSIDE_FOV_DEG: f64 = 70.0;
/// Elevation of the default views from outside, above the scene's horizontal plane, degrees.
pub const OUTSIDE_ELEVATION_DEG: f64 = 30.0;
/// How far toward an upper corner of the bounding box the inside views stand, as a fraction of
/// the way from the centre to the corner.
pub const INSIDE_CORNER_FRACTION: f64 = 0.4;
/// Margin around the scene in the outside views: the distance that frames the bounding box is
/// multiplied by this.
pub const OUTSIDE_MARGIN: f64 = 1.05;
/// Largest full angle of a perspective view, degrees (exclusive).
pub const MAX_VIEW_ANGLE_DEG: f64 = 180.0;
/// Up vectors within this sine of the view direction are taken as parallel to it.
const PARALLEL_SINE: f64 = 1e-6;
/// The net emitting normal fixes the scene's up axis when it is at least this fraction of the
/// emitters' total area (otherwise the lights face every way, as in a furnace).
const NET_EMITTER_FRACTION: f64 = 0.5;
/// Extents within this relative difference count as equal when the thinnest axis is taken as up.
const EXTENT_TIE: f64 = 0.01;

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
    /// [`ViewSpec::parse`] reads it back.
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
fn horizontal_for(vertical: f64, aspect: f64) -> f64 {
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

/// The scene's up direction: opposite to the emitters' net normal when the lights mostly face one
/// way (ceiling lights face down), otherwise the axis along which the bounding box is thinnest
/// (`+z` on ties, then `+y`): rooms are lower than they are wide.
#[must_use]
pub fn up_axis(scene: &Scene) -> DVec3 {
    let (mut net, mut total) = (DVec3::ZERO, 0.0);
    for p in &scene.polygons {
        if scene.materials[p.material as usize].is_emitter() {
            net += p.poly.area_vector();
            total += p.poly.area();
        }
    }
    if total > 0.0 && net.length() >= NET_EMITTER_FRACTION * total {
        let d = -net;
        let a = d.abs();
        return if a.z >= a.x && a.z >= a.y {
            DVec3::Z * d.z.signum()
        } else if a.y >= a.x {
            DVec3::Y * d.y.signum()
        } else {
            DVec3::X * d.x.signum()
        };
    }
    let e = scene.bounds().extent();
    let thin = e.x.min(e.y).min(e.z);
    let tie = |x: f64| x <= thin * (1.0 + EXTENT_TIE);
    if tie(e.z) {
        DVec3::Z
    } else if tie(e.y) {
        DVec3::Y
    } else {
        DVec3::X
    }
}

/// A candidate default view, and whether it looks from outside the scene's bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// The view.
    pub view: View,
    /// True for the views from outside (a cut-away of a closed room: the backs of one-sided
    /// surfaces let the view through).
    pub outside: bool,
}

/// The default views of a scene without a camera, on an image of width / height `aspect`: from
/// outside, above each of the four horizontal diagonals, looking at the centre of the bounding box
/// and framing it; then from inside, 40% of the way from the centre to each upper corner of the
/// bounding box, looking at the centre. `up` is [`up_axis`].
#[must_use]
pub fn candidate_views(bounds: &Aabb, up: DVec3, aspect: f64) -> Vec<Candidate> {
    let c = bounds.center();
    let half = 0.5 * bounds.extent();
    // Two horizontal axes orthogonal to `up` (an axis or its opposite).
    let (a1, a2) = if up.z.abs() > 0.5 {
        (DVec3::X, DVec3::Y)
    } else if up.y.abs() > 0.5 {
        (DVec3::Z, DVec3::X)
    } else {
        (DVec3::Y, DVec3::Z)
    };
    let corners: Vec<DVec3> = (0..8)
        .map(|k| {
            c + DVec3::new(
                if k & 1 == 0 { -half.x } else { half.x },
                if k & 2 == 0 { -half.y } else { half.y },
                if k & 4 == 0 { -half.z } else { half.z },
            )
        })
        .collect();
    let mut out = Vec::with_capacity(8);
    let (elev, fov) = (OUTSIDE_ELEVATION_DEG.to_radians(), OUTSIDE_FOV_DEG.to_radians());
    for (s1, s2) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
        let horizontal_dir = (a1 * s1 + a2 * s2).normalize();
        let back = horizontal_dir * elev.cos() + up * elev.sin();
        let probe = View::new(c, -back, up, horizontal_for(fov, aspect), fov);
        let dist = framing_distance(&probe, c, &corners) * OUTSIDE_MARGIN;
        out.push(Candidate { view: View { position: c + back * dist, ..probe }, outside: true });
    }
    let fov = INSIDE_FOV_DEG.to_radians();
    for (s1, s2) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
        let toward = a1 * (s1 * half.dot(a1.abs())) + a2 * (s2 * half.dot(a2.abs())) + up * half.dot(up.abs());
        let eye = c + toward * INSIDE_CORNER_FRACTION;
        out.push(Candidate { view: View::new(eye, c - eye, up, horizontal_for(fov, aspect), fov), outside: false });
    }
    out
}

/// The distance back from `target` along the view direction at which every point of `points` is
/// inside the view's angles.
fn framing_distance(view: &View, target: DVec3, points: &[DVec3]) -> f64 {
    let right = view.direction.cross(view.up);
    let (th, tv) = ((0.5 * view.horizontal).tan(), (0.5 * view.vertical).tan());
    points
        .iter()
        .map(|&p| {
            let o = p - target;
            let (x, y, z) = (o.dot(right), o.dot(view.up), o.dot(view.direction));
            // The eye at `target − d·direction` sees `o` at depth `z + d`; it is inside when
            // |x| ≤ (z + d)·th and |y| ≤ (z + d)·tv.
            (x.abs() / th).max(y.abs() / tv) - z
        })
        .fold(f64::MIN_POSITIVE, f64::max)
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

    #[test]
    fn outside_views_frame_the_box() {
        let b = Aabb { min: DVec3::ZERO, max: DVec3::new(10.0, 6.0, 3.0) };
        for cand in candidate_views(&b, DVec3::Z, 1.0) {
            let v = cand.view;
            let right = v.direction.cross(v.up);
            for k in 0..8 {
                let p =
                    DVec3::new(if k & 1 == 0 { 0.0 } else { 10.0 }, if k & 2 == 0 { 0.0 } else { 6.0 }, if k & 4 == 0 { 0.0 } else { 3.0 });
                let o = p - v.position;
                let z = o.dot(v.direction);
                if cand.outside {
                    assert!(z > 0.0, "every corner in front of an outside view");
                    assert!(o.dot(right).abs() <= z * (0.5 * v.horizontal).tan() * (1.0 + 1e-9));
                    assert!(o.dot(v.up).abs() <= z * (0.5 * v.vertical).tan() * (1.0 + 1e-9));
                }
            }
            let inside = v.position.cmpge(b.min).all() && v.position.cmple(b.max).all();
            assert_eq!(inside, !cand.outside);
        }
    }
}
