//! The MGF interpreter: named contexts (vertices, colours, materials), the object and transform
//! stacks, includes, and the handling of each entity. Faces go to the [`SceneBuilder`] in world
//! coordinates.

use super::MgfOptions;
use super::color::{self, Chroma};
use super::contexts::Contexts;
use super::holes;
use super::lines::{self, Entity, parse_f64, parse_int};
use super::material::{Location, MaterialCtx};
use super::primitives::{self, Faces, ZERO_LENGTH_TOL};
use super::xform::{self, XfSpec};
use crate::geom::DVec3;
use crate::scene::{Material, Scene, SceneBuilder, SceneError};
use glam::DAffine3;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Component, Path, PathBuf};
use std::rc::Rc;

/// Group of the faces outside every object.
const ROOT_GROUP: &str = "(root)";
/// Separator of nested object names in group names.
const GROUP_SEPARATOR: &str = "/";
/// Name of the material used before any `m name` (mgflib's unnamed material).
const UNNAMED_MATERIAL: &str = "unnamed";

/// Reads one MGF file and everything it includes into a [`Scene`].
pub(super) struct Reader {
    options: MgfOptions,
    builder: SceneBuilder,
    /// The file given to [`Reader::new`], as displayed in the builder's messages.
    root_display: String,
    /// Parsed files by canonical path (included files are parsed once however often included).
    sources: HashMap<PathBuf, Rc<Source>>,
    /// Files being read, innermost last.
    files: Vec<Rc<Source>>,
    /// Counter giving each reading of a file its own id.
    n_runs: usize,
    vertices: Contexts<VertexCtx>,
    colors: Contexts<ColorValue>,
    materials: Contexts<MaterialCtx>,
    /// Scene material of the current material context, while it is unchanged.
    material_id: Option<u32>,
    /// Scene materials made from each MGF material name (a redefined material gets a new one).
    emitted: HashMap<Box<str>, Vec<(Material, u32)>>,
    /// Names given to scene materials.
    used_material_names: HashSet<String>,
    /// Object names, outermost first.
    objects: Vec<Box<str>>,
    /// Scene group of the current object path, while it is unchanged.
    group_id: Option<u32>,
    /// Transforms, innermost last.
    xf: Vec<XfFrame>,
    /// Skipped entity kinds.
    skipped: BTreeMap<Box<str>, Skipped>,
    /// Reused face buffer for primitives.
    scratch: Faces,
}

/// A parsed file.
struct Source {
    /// Path as opened, for messages.
    path: Rc<Path>,
    /// Canonical path, for the cache and cycle detection.
    key: PathBuf,
    entities: Vec<Entity>,
}

/// A colour, or why it cannot be used (a `cspec` whose spectrum has no valid chromaticity is
/// accepted, as mgflib does, but is an error where a material or `cmix` uses it).
type ColorValue = Result<Chroma, Rc<str>>;

/// An MGF vertex: point and (unit or zero) normal, in the coordinates of the entity using it.
#[derive(Clone, Copy, Debug, Default)]
struct VertexCtx {
    p: DVec3,
    n: DVec3,
}

/// One `xf` (or the transform of an `i file xf-args`) in force.
struct XfFrame {
    spec: XfSpec,
    /// Current array instance (one index per `-a`).
    idx: Vec<usize>,
    /// Transform of the enclosing frame.
    parent: DAffine3,
    /// Local → world.
    to_world: DAffine3,
    /// The transform mirrors: vertex order is reversed to keep faces CCW.
    reversed: bool,
    /// Reading of the file that opened it.
    run: usize,
    /// Entity index where the next array instance starts.
    resume: usize,
    /// Opened by `i`: closed at the end of the included file.
    include: bool,
    /// Line of the `xf` or `i`.
    line: usize,
    /// Length of the object stack before the array instance name (arrays only).
    objects_base: Option<usize>,
}

/// Count of a skipped entity kind, and which warning message reports it.
struct Skipped {
    count: usize,
    message_idx: Option<usize>,
}

impl XfFrame {
    fn update(&mut self) {
        self.to_world = self.parent * self.spec.matrix(&self.idx);
        self.reversed = self.to_world.matrix3.determinant() < 0.0;
    }
}

impl Reader {
    /// A reader for the scene file `path`.
    pub fn new(path: &Path, options: MgfOptions) -> Reader {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let here = Location { path: Rc::from(path), line: 0 };
        Reader {
            options,
            builder: SceneBuilder::new(path, &name),
            root_display: path.display().to_string(),
            sources: HashMap::new(),
            files: Vec::new(),
            n_runs: 0,
            vertices: Contexts::new(VertexCtx::default()),
            colors: Contexts::new(Ok(Chroma::NEUTRAL)),
            materials: Contexts::new(MaterialCtx::new(here)),
            material_id: None,
            emitted: HashMap::new(),
            used_material_names: HashSet::new(),
            objects: Vec::new(),
            group_id: None,
            xf: Vec::new(),
            skipped: BTreeMap::new(),
            scratch: Faces::new(),
        }
    }

    /// Reads the scene: from `text` when given (includes are still read from disk, relative to
    /// `path`), else from the file `path`.
    pub fn read(mut self, path: &Path, text: Option<&str>) -> Result<Scene, SceneError> {
        let src = self.open(path, text)?;
        self.run(src, None)?;
        let n_skipped: Vec<(usize, usize)> = self.skipped.values().filter_map(|s| Some((s.message_idx?, s.count))).collect();
        let messages = &mut self.builder.warnings_mut().messages;
        for (idx, count) in n_skipped {
            if let Some(msg) = messages.get_mut(idx).filter(|_| count > 1) {
                msg.push_str(&format!(" ({count} times in all)"));
            }
        }
        Ok(self.builder.finish())
    }

    /// Parses a file (once: later calls return the cached entities).
    fn open(&mut self, path: &Path, text: Option<&str>) -> Result<Rc<Source>, SceneError> {
        let io = |source| SceneError::Io { path: path.to_owned(), source };
        let key = match text {
            Some(_) => std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned()),
            None => std::fs::canonicalize(path).map_err(io)?,
        };
        if let Some(src) = self.sources.get(&key) {
            return Ok(src.clone());
        }
        let entities = match text {
            Some(text) => lines::split(text),
            None => lines::split(&String::from_utf8_lossy(&std::fs::read(path).map_err(io)?)),
        };
        let src = Rc::new(Source { path: Rc::from(path), key: key.clone(), entities });
        self.sources.insert(key, src.clone());
        Ok(src)
    }

    /// Reads the entities of `src`; with `include_xf`, once per array instance of that transform.
    fn run(&mut self, src: Rc<Source>, include_xf: Option<(XfSpec, usize)>) -> Result<(), SceneError> {
        let run = self.n_runs;
        self.n_runs += 1;
        let has_include_frame = include_xf.is_some();
        if let Some((spec, line)) = include_xf {
            // Before the file is pushed: an error names the including file's `i` line.
            self.push_xf(spec, run, 0, true, line)?;
        }
        self.files.push(src.clone());
        let own_base = self.xf.len();
        let objects_base = self.objects.len();
        loop {
            let mut next = 0;
            while let Some(e) = src.entities.get(next) {
                next += 1;
                if let Some(jump) = self.entity(e, run, next)? {
                    next = jump;
                }
            }
            while self.xf.len() > own_base {
                let line = self.xf.last().map_or(0, |f| f.line);
                self.warn_at(line, "`xf` not closed before the end of the file; closed there".into());
                self.pop_xf();
            }
            if self.objects.len() > objects_base {
                let names = self.objects[objects_base..].join(GROUP_SEPARATOR);
                self.warn_at(
                    src.entities.last().map_or(0, |e| e.line),
                    format!("object `{names}` not closed before the end of the file; closed there"),
                );
                self.objects.truncate(objects_base);
                self.group_id = None;
            }
            if has_include_frame {
                if self.next_instance() {
                    continue;
                }
                self.pop_xf();
            }
            break;
        }
        self.files.pop();
        Ok(())
    }

    fn current_path(&self) -> Rc<Path> {
        self.files.last().map_or_else(|| Rc::from(Path::new(&self.root_display)), |f| f.path.clone())
    }

    fn parse_err(&self, line: usize, msg: impl Into<String>) -> SceneError {
        SceneError::Parse { path: self.current_path().to_path_buf(), line, msg: msg.into() }
    }

    fn warn_at(&mut self, line: usize, msg: String) {
        let path = self.current_path();
        self.builder.warn(format!("{}:{line}: {msg}", path.display()));
    }

    fn location(&self, line: usize) -> Location {
        Location { path: self.current_path(), line }
    }

    /// Handles one entity; returns where to continue when it jumps back (next array instance).
    fn entity(&mut self, e: &Entity, run: usize, next: usize) -> Result<Option<usize>, SceneError> {
        let line = e.line;
        match &*e.words[0] {
            "v" => self.vertices.select(&e.words, VertexCtx::default(), "vertex").map_err(|m| self.parse_err(line, m))?,
            "p" => self.vertices.current_mut().p = DVec3::from_array(self.floats::<3>(e)?),
            "n" => self.vertices.current_mut().n = DVec3::from_array(self.floats::<3>(e)?).normalize_or_zero(),
            "f" => self.face(e)?,
            "fh" => self.face_with_holes(e)?,
            "sph" | "cyl" | "cone" | "ring" | "torus" | "prism" => self.primitive(e)?,
            "c" => self.colors.select(&e.words, Ok(Chroma::NEUTRAL), "colour").map_err(|m| self.parse_err(line, m))?,
            "cxy" | "cspec" | "cct" | "cmix" => *self.colors.current_mut() = self.color(e)?,
            "m" => {
                let at = self.location(line);
                self.materials.select(&e.words, MaterialCtx::new(at.clone()), "material").map_err(|m| self.parse_err(line, m))?;
                if e.words.len() > 2 {
                    self.materials.current_mut().at = at;
                }
                self.material_id = None;
            }
            "rd" | "td" | "ed" | "sides" => self.material_property(e)?,
            "rs" | "ts" => {
                let [value, roughness] = self.floats::<2>(e)?;
                if !(0.0..=1.0).contains(&value) || roughness < 0.0 {
                    return Err(self.parse_err(line, format!("`{}` needs a value in [0, 1] and a roughness >= 0", e.words[0])));
                }
            }
            "ir" => {
                let [real, _imaginary] = self.floats::<2>(e)?;
                if real <= ZERO_LENGTH_TOL {
                    return Err(self.parse_err(line, "`ir` needs a positive index of refraction"));
                }
            }
            "o" => self.object(e)?,
            "xf" => return self.xf(e, run, next),
            "i" => self.include(e)?,
            "ies" => self.skip(e, "unsupported entity"),
            _ => self.skip(e, "unknown entity"),
        }
        Ok(None)
    }

    /// Exactly `N` numbers after the entity name.
    fn floats<const N: usize>(&self, e: &Entity) -> Result<[f64; N], SceneError> {
        if e.words.len() != N + 1 {
            let s = if N == 1 { "" } else { "s" };
            return Err(self.parse_err(e.line, format!("`{}` takes {N} number{s}, found {} argument(s)", e.words[0], e.words.len() - 1)));
        }
        let mut out = [0.0; N];
        for (o, w) in out.iter_mut().zip(&e.words[1..]) {
            *o = self.float(w, e.line)?;
        }
        Ok(out)
    }

    fn float(&self, word: &str, line: usize) -> Result<f64, SceneError> {
        parse_f64(word).ok_or_else(|| self.parse_err(line, format!("`{word}` is not a number")))
    }

    fn n_args(&self, e: &Entity, n: usize) -> Result<(), SceneError> {
        if e.words.len() == n + 1 {
            Ok(())
        } else {
            Err(self.parse_err(e.line, format!("`{}` takes {n} arguments, found {}", e.words[0], e.words.len() - 1)))
        }
    }

    fn vertex(&self, name: &str, line: usize) -> Result<VertexCtx, SceneError> {
        self.vertices.named.get(name).copied().ok_or_else(|| self.parse_err(line, format!("undefined vertex `{name}`")))
    }

    fn points(&self, names: &[Box<str>], line: usize) -> Result<Vec<DVec3>, SceneError> {
        names.iter().map(|n| self.vertex(n, line).map(|v| v.p)).collect()
    }

    fn face(&mut self, e: &Entity) -> Result<(), SceneError> {
        if e.words.len() < 4 {
            return Err(self.parse_err(e.line, "a face needs at least 3 vertices"));
        }
        let pts = self.points(&e.words[1..], e.line)?;
        self.emit(pts, e.line)
    }

    /// `fh v.. - h.. - h..`: holes are joined to the outer contour by seams.
    fn face_with_holes(&mut self, e: &Entity) -> Result<(), SceneError> {
        let mut contours = Vec::new();
        for names in e.words[1..].split(|w| &**w == "-") {
            if names.len() < 3 {
                return Err(self.parse_err(e.line, "each contour of `fh` needs at least 3 vertices"));
            }
            contours.push(self.points(names, e.line)?);
        }
        let holes = contours.split_off(1);
        let outer = contours.pop().unwrap_or_default();
        self.emit(holes::merge_holes(outer, holes), e.line)
    }

    fn primitive(&mut self, e: &Entity) -> Result<(), SceneError> {
        let mut faces = std::mem::take(&mut self.scratch);
        faces.clear();
        self.primitive_faces(&mut faces, e)?;
        for f in faces.drain(..) {
            self.emit(f, e.line)?;
        }
        self.scratch = faces;
        Ok(())
    }

    /// The faces of a `sph`, `cyl`, `cone`, `ring`, `torus` or `prism`, in local coordinates.
    fn primitive_faces(&self, acc: &mut Faces, e: &Entity) -> Result<(), SceneError> {
        let (w, line) = (&e.words, e.line);
        let nq = self.options.quarter_circle_divisions.max(1);
        let result = match &*w[0] {
            "sph" => {
                self.n_args(e, 2)?;
                primitives::sphere(acc, self.vertex(&w[1], line)?.p, self.float(&w[2], line)?, nq)
            }
            "cyl" => {
                self.n_args(e, 3)?;
                let r = self.float(&w[2], line)?;
                primitives::cone(acc, self.vertex(&w[1], line)?.p, r, self.vertex(&w[3], line)?.p, r, nq)
            }
            "cone" => {
                self.n_args(e, 4)?;
                let (r1, r2) = (self.float(&w[2], line)?, self.float(&w[4], line)?);
                primitives::cone(acc, self.vertex(&w[1], line)?.p, r1, self.vertex(&w[3], line)?.p, r2, nq)
            }
            "ring" | "torus" => {
                self.n_args(e, 3)?;
                let v = self.vertex(&w[1], line)?;
                if v.n == DVec3::ZERO {
                    return Err(self.parse_err(line, format!("`{}` centre vertex `{}` has no normal (`n`)", w[0], w[1])));
                }
                let (r1, r2) = (self.float(&w[2], line)?, self.float(&w[3], line)?);
                if &*w[0] == "ring" { primitives::ring(acc, v.p, v.n, r1, r2, nq) } else { primitives::torus(acc, v.p, v.n, r1, r2, nq) }
            }
            _ => {
                // `prism v1 .. vn length`
                if w.len() < 5 {
                    return Err(self.parse_err(line, "`prism` needs at least 3 vertices and a length"));
                }
                let pts = self.points(&w[1..w.len() - 1], line)?;
                primitives::prism(acc, &pts, self.float(&w[w.len() - 1], line)?)
            }
        };
        result.map_err(|m| self.parse_err(line, format!("`{}`: {m}", w[0])))
    }

    /// Transforms a face to world coordinates and hands it to the builder.
    fn emit(&mut self, mut pts: Vec<DVec3>, line: usize) -> Result<(), SceneError> {
        if let Some(f) = self.xf.last() {
            for p in &mut pts {
                *p = f.to_world.transform_point3(*p);
            }
            if f.reversed {
                pts.reverse();
            }
        }
        if pts.iter().any(|p| !p.is_finite()) {
            return Err(SceneError::NonFinite { path: self.current_path().to_path_buf(), line, what: "transformed face vertex".into() });
        }
        let material = self.material_id()?;
        let group = self.group_id();
        let n_messages = self.builder.warnings_mut().messages.len();
        let contour = holes::without_consecutive_repeats(&pts);
        match holes::touches_itself(&contour).then(|| holes::triangulate(&contour)).flatten() {
            Some(triangles) => {
                self.builder.warnings_mut().triangulated_faces += 1;
                for [a, b, c] in triangles {
                    self.builder.face(&[contour[a], contour[b], contour[c]], material, group, line)?;
                }
            }
            None => self.builder.face(&pts, material, group, line)?,
        }
        self.relocate_messages(n_messages);
        Ok(())
    }

    /// The builder names the root file in its messages; faces from included files name theirs.
    fn relocate_messages(&mut self, from: usize) {
        let path = self.current_path();
        let here = path.display().to_string();
        if here == self.root_display {
            return;
        }
        for msg in self.builder.warnings_mut().messages.iter_mut().skip(from) {
            if let Some(rest) = msg.strip_prefix(self.root_display.as_str()).filter(|r| r.starts_with(':')) {
                *msg = format!("{here}{rest}");
            }
        }
    }

    /// `cxy`, `cspec`, `cct` or `cmix`: the new value of the current colour.
    fn color(&self, e: &Entity) -> Result<ColorValue, SceneError> {
        let (w, line) = (&e.words, e.line);
        match &*w[0] {
            "cxy" => {
                let [x, y] = self.floats::<2>(e)?;
                Chroma::new(x, y)
                    .map(Ok)
                    .ok_or_else(|| self.parse_err(line, format!("chromaticity ({x}, {y}) outside x, y >= 0, x + y <= 1")))
            }
            "cspec" => {
                if w.len() < 5 {
                    return Err(self.parse_err(line, "`cspec` needs a wavelength range and at least 2 values"));
                }
                let values = w[1..].iter().map(|v| self.float(v, line)).collect::<Result<Vec<f64>, _>>()?;
                Ok(color::from_spectrum(values[0], values[1], &values[2..]).ok_or_else(|| {
                    let path = self.current_path();
                    Rc::from(format!(
                        "the colour set by `cspec` at {}:{line} has no valid chromaticity (its spectrum gives negative or zero tristimulus values)",
                        path.display()
                    ))
                }))
            }
            "cct" => {
                let [kelvin] = self.floats::<1>(e)?;
                color::from_temperature(kelvin).map(Ok).ok_or_else(|| {
                    self.parse_err(line, format!("colour temperature {kelvin} K is below {} K", color::MIN_COLOR_TEMPERATURE))
                })
            }
            _ => {
                // `cmix w1 c1 w2 c2 ...`
                if w.len() < 5 || w.len() % 2 == 0 {
                    return Err(self.parse_err(line, "`cmix` needs pairs of weight and colour name, at least 2"));
                }
                let mut parts = Vec::with_capacity(w.len() / 2);
                for pair in w[1..].chunks(2) {
                    let weight = self.float(&pair[0], line)?;
                    let c =
                        self.colors.named.get(&pair[1]).ok_or_else(|| self.parse_err(line, format!("undefined colour `{}`", pair[1])))?;
                    parts.push((weight, c.clone().map_err(|why| self.parse_err(line, format!("colour `{}`: {why}", pair[1])))?));
                }
                color::mix(&parts)
                    .map(Ok)
                    .ok_or_else(|| self.parse_err(line, "`cmix` weights must sum to a positive value (and colours need y > 0)"))
            }
        }
    }

    /// `rd`, `td`, `ed` (with the current colour) or `sides` of the current material.
    fn material_property(&mut self, e: &Entity) -> Result<(), SceneError> {
        let at = self.location(e.line);
        if &*e.words[0] == "sides" {
            self.n_args(e, 1)?;
            let one_sided = match parse_int(&e.words[1]) {
                Some(1) => true,
                Some(2) => false,
                _ => return Err(self.parse_err(e.line, format!("`sides` must be 1 or 2, found `{}`", e.words[1]))),
            };
            self.materials.current_mut().one_sided = one_sided;
        } else {
            let [value] = self.floats::<1>(e)?;
            if value < 0.0 {
                return Err(self.parse_err(e.line, format!("`{}` must not be negative", e.words[0])));
            }
            let color = self.colors.current().clone().map_err(|why| self.parse_err(e.line, why.to_string()))?;
            let value = (value, color);
            let m = self.materials.current_mut();
            match &*e.words[0] {
                "rd" => m.rd = value,
                "td" => m.td = value,
                _ => m.ed = value,
            }
        }
        self.materials.current_mut().at = at;
        self.material_id = None;
        Ok(())
    }

    /// Scene material of the current material context (made on first use after each change).
    fn material_id(&mut self) -> Result<u32, SceneError> {
        if let Some(id) = self.material_id {
            return Ok(id);
        }
        let name: Box<str> = self.materials.current.clone().unwrap_or_else(|| UNNAMED_MATERIAL.into());
        let ctx = self.materials.current();
        let (mut material, clamped) = ctx.to_material(&name, self.options.force_one_sided);
        let at = ctx.at.clone();
        let versions = self.emitted.entry(name.clone()).or_default();
        let same = |m: &Material| {
            m.reflectance == material.reflectance
                && m.emission == material.emission
                && m.transmittance == material.transmittance
                && m.two_sided == material.two_sided
        };
        let id = match versions.iter().find(|(m, _)| same(m)) {
            Some(&(_, id)) => id,
            None => {
                let mut k = 1;
                while self.used_material_names.contains(&material.name) {
                    k += 1;
                    material.name = format!("{name}#{k}");
                }
                self.used_material_names.insert(material.name.clone());
                if let Some(why) = clamped {
                    self.builder.warnings_mut().clamped_materials += 1;
                    self.builder.warn(format!("{}:{}: material `{}`: {why}", at.path.display(), at.line, material.name));
                }
                let id = self.builder.material(material.clone())?;
                versions.push((material, id));
                id
            }
        };
        self.material_id = Some(id);
        Ok(id)
    }

    /// Scene group of the current object path.
    fn group_id(&mut self) -> u32 {
        if let Some(id) = self.group_id {
            return id;
        }
        let id =
            if self.objects.is_empty() { self.builder.group(ROOT_GROUP) } else { self.builder.group(&self.objects.join(GROUP_SEPARATOR)) };
        self.group_id = Some(id);
        id
    }

    fn object(&mut self, e: &Entity) -> Result<(), SceneError> {
        match &e.words[..] {
            [_] => {
                if self.objects.pop().is_none() {
                    self.warn_at(e.line, "`o` closes no object; ignored".into());
                }
            }
            [_, name] => self.objects.push(name.clone()),
            _ => return Err(self.parse_err(e.line, "`o` takes at most one name")),
        }
        self.group_id = None;
        Ok(())
    }

    /// `xf args` opens a transform; `xf` closes it or starts its next array instance.
    fn xf(&mut self, e: &Entity, run: usize, next: usize) -> Result<Option<usize>, SceneError> {
        if e.words.len() > 1 {
            let spec = XfSpec::parse(&e.words[1..]).map_err(|m| self.parse_err(e.line, m))?;
            self.push_xf(spec, run, next, false, e.line)?;
            return Ok(None);
        }
        match self.xf.last() {
            Some(f) if f.run == run && !f.include => {}
            Some(_) => return Err(self.parse_err(e.line, "`xf` closes a transform opened in another file")),
            None => return Err(self.parse_err(e.line, "`xf` closes no transform")),
        }
        if self.next_instance() {
            return Ok(self.xf.last().map(|f| f.resume));
        }
        self.pop_xf();
        Ok(None)
    }

    fn push_xf(&mut self, spec: XfSpec, run: usize, resume: usize, include: bool, line: usize) -> Result<(), SceneError> {
        let mut sizes = self.xf.iter().flat_map(|f| &f.spec.array_sizes).chain(&spec.array_sizes);
        if sizes.try_fold(1usize, |acc, &n| acc.checked_mul(n)).is_none_or(|n| n > xform::MAX_INSTANCES) {
            return Err(
                self.parse_err(line, format!("array transform makes over {} instances (counting enclosing arrays)", xform::MAX_INSTANCES))
            );
        }
        let parent = self.xf.last().map_or(DAffine3::IDENTITY, |f| f.to_world);
        let idx = vec![0; spec.array_sizes.len()];
        let objects_base = (!idx.is_empty()).then_some(self.objects.len());
        let mut frame = XfFrame { spec, idx, parent, to_world: parent, reversed: false, run, resume, include, line, objects_base };
        frame.update();
        self.xf.push(frame);
        self.push_instance_name();
        Ok(())
    }

    /// Moves the innermost transform to its next array instance; false when it has none left.
    fn next_instance(&mut self) -> bool {
        let Some(f) = self.xf.last_mut() else { return false };
        let Some(base) = f.objects_base else { return false };
        if !xform::next_instance(&mut f.idx, &f.spec.array_sizes) {
            return false;
        }
        f.update();
        self.objects.truncate(base);
        self.push_instance_name();
        true
    }

    /// Array instances are objects named `a<i>` (`a<i>.<j>` ... for several `-a`), as in mgflib.
    fn push_instance_name(&mut self) {
        if let Some(f) = self.xf.last().filter(|f| f.objects_base.is_some()) {
            let idx: Vec<String> = f.idx.iter().map(usize::to_string).collect();
            self.objects.push(format!("a{}", idx.join(".")).into());
            self.group_id = None;
        }
    }

    fn pop_xf(&mut self) {
        if let Some(base) = self.xf.pop().and_then(|f| f.objects_base) {
            self.objects.truncate(base);
            self.group_id = None;
        }
    }

    /// `i file [xf args]`: reads `file` (relative to the including file) under the transform.
    fn include(&mut self, e: &Entity) -> Result<(), SceneError> {
        let Some(name) = e.words.get(1) else {
            return Err(self.parse_err(e.line, "`i` needs a file name"));
        };
        let spec = match e.words.len() > 2 {
            true => Some((XfSpec::parse(&e.words[2..]).map_err(|m| self.parse_err(e.line, m))?, e.line)),
            false => None,
        };
        let here = self.current_path();
        // Relative to the including file; `./` components dropped so that messages read cleanly.
        let path: PathBuf = here.parent().unwrap_or(Path::new("")).join(&**name).components().filter(|c| *c != Component::CurDir).collect();
        let line = e.line;
        let src = self.open(&path, None).map_err(|err| match err {
            // Named at the `i` line, with the reason, so the message says where the include is.
            SceneError::Io { path, source } => self.parse_err(line, format!("cannot read included file `{}`: {source}", path.display())),
            other => other,
        })?;
        if let Some(pos) = self.files.iter().position(|f| f.key == src.key) {
            let chain: Vec<String> = self.files[pos..].iter().chain([&src]).map(|f| f.path.display().to_string()).collect();
            return Err(self.parse_err(e.line, format!("include cycle: {}", chain.join(" -> "))));
        }
        self.run(src, spec)
    }

    /// Skips an entity with one warning per entity kind (counted).
    fn skip(&mut self, e: &Entity, what: &str) {
        let path = self.current_path();
        let n_messages = self.builder.warnings_mut().messages.len();
        let entry = self.skipped.entry(e.words[0].clone()).or_insert(Skipped { count: 0, message_idx: None });
        if entry.count == 0 {
            self.builder.warn(format!("{}:{}: {what} `{}` skipped", path.display(), e.line, e.words[0]));
            if self.builder.warnings_mut().messages.len() > n_messages {
                entry.message_idx = Some(n_messages);
            }
        }
        entry.count += 1;
    }
}
