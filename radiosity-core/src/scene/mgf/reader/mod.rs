//! The MGF interpreter: named contexts (vertices, colours, materials), the object and transform
//! stacks, includes, and the handling of each entity. Faces go to the [`SceneBuilder`] in world
//! coordinates.
//!
//! This folder holds one [`Reader`], its state and the entity loop here, and its handling of each
//! kind of entity in a file per step: `geometry.rs` (faces and primitives to the builder),
//! `materials.rs` (colours and materials), `objects.rs` (objects, transforms, includes, skipped
//! entities). Only [`Reader::new`] and [`Reader::read`] are used outside it.

mod geometry;
mod materials;
mod objects;

use super::MgfOptions;
use super::color::Chroma;
use super::contexts::Contexts;
use super::lines::{self, Entity, parse_f64};
use super::material::{Location, MaterialCtx};
use super::primitives::{Faces, ZERO_LENGTH_TOL};
use super::xform::XfSpec;
use crate::geom::DVec3;
use crate::scene::{Material, Scene, SceneBuilder, SceneError};
use glam::DAffine3;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
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
}
