//! The outputs of an instanced solve (`solution.ply`, `solution.glb`, `patches.csv`, `image.png`),
//! each written atomically ([`crate::output::atomic`]), in memory
//! that does not grow with the scene: finished polygons are streamed, `patches.csv` row by row and
//! the leaf elements to a spool file beside the outputs; [`StreamedOutput::finish`] then reads the
//! spool back to write the PLY and the GLB (whose headers need the counts, and whose colours need the
//! tone map of the whole solution) and to draw the image with a z-buffer, and removes the spool.
//!
//! Differences from a plain solve's outputs: `patches.csv` rows come in solve order (the `index`
//! column is the flattened polygon's index), their `group` is the prototype that holds the polygon;
//! the PLY, the GLB and the image are flat-shaded per leaf (no smoothing across leaves, which would need the
//! neighbours in memory); the image is seen from the side (looking along +y, z up: the plant
//! generator's convention), as instanced scene files carry no camera.
//!
//! Like the plain solve's, `patches.csv` ends with `absorbed_<band>` (W: `A·(1 − ρ − t)·H` of the
//! polygon's side, the two sides of a leaf in two rows) and `groups.csv` sums the area and the
//! absorbed power per group, here per prototype (`group,area,absorbed_<band>...`). A scene that
//! names its bands (at most three solve instanced, see [`StreamedOutput::with_bands`]) gets their
//! names in the columns instead of `r`, `g`, `b`, and its first band in grey in the PLY, the GLB
//! and the image, as the plain solve shows it.

use super::InstancingError;
use super::model::InstancedScene;
use super::solver::{Leaf, PolygonInfo, RadiositySink, leaf_means};
use crate::geom::{Aabb, DVec3};
use crate::output::atomic::AtomicFile;
use crate::output::{GlbLayout, RenderConfig, ToneMap};
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// Bins per decade of the radiosity histogram that sets the tone map's white point.
const TONE_BINS_PER_DECADE: f64 = 16.0;
/// Smallest radiosity the histogram resolves (W/m²); smaller values fall in the first bin.
const TONE_MIN: f64 = 1e-12;
/// Number of histogram bins (24 decades).
const TONE_BINS: usize = 24 * 16;

/// Streams an instanced solve's outputs into a folder; see the module docs.
pub struct StreamedOutput {
    dir: PathBuf,
    spool_path: PathBuf,
    spool: BufWriter<std::fs::File>,
    csv_path: PathBuf,
    /// `patches.csv` under its temporary name until [`StreamedOutput::finish`] (`None` after).
    csv: Option<AtomicFile>,
    prototype_names: Vec<String>,
    material_names: Vec<String>,
    emitter: Vec<bool>,
    bounds: Aabb,
    leaves: u64,
    vertices: u64,
    histogram: Vec<u64>,
    max_b: f64,
    /// Column suffixes: `r`, `g`, `b` or the scene's band names (1 to 3).
    bands: Vec<String>,
    /// Whether the pictures show the first band in grey (named bands).
    grey: bool,
    /// `1 − ρ − t` per material and channel.
    absorptance: Vec<[f64; 3]>,
    /// Area and absorbed power per prototype.
    groups: Vec<(f64, [f64; 3])>,
}

/// What [`StreamedOutput::finish`] wrote.
#[derive(Clone, Debug, serde::Serialize)]
pub struct StreamedSummary {
    /// Leaf elements in `solution.ply`.
    pub leaves: u64,
    /// Radiosity shown as white in the PLY colours and the image (W/m²).
    pub white: f64,
    /// The bands, as `patches.csv` and `groups.csv` name them.
    pub bands: Vec<String>,
    /// Power absorbed by all the polygons, per band (W).
    pub absorbed: Vec<f64>,
}

fn io_err(path: &Path, e: std::io::Error) -> InstancingError {
    InstancingError::io(path, "cannot write file", e)
}

impl StreamedOutput {
    /// Creates `dir` and opens `patches.csv` and the spool in it (RGB columns).
    pub fn create(dir: &Path, scene: &InstancedScene) -> Result<StreamedOutput, InstancingError> {
        Self::with_bands(dir, scene, &["r", "g", "b"])
    }

    /// [`StreamedOutput::create`] for a scene whose materials hold the bands `names` (1 to 3; the
    /// channels past them are not written).
    pub fn with_bands(dir: &Path, scene: &InstancedScene, names: &[impl AsRef<str>]) -> Result<StreamedOutput, InstancingError> {
        if names.is_empty() || names.len() > 3 {
            return Err(InstancingError::io(
                dir,
                "cannot write an instanced solve's outputs",
                std::io::Error::other(format!("{} bands (the instanced solve takes 1 to 3)", names.len())),
            ));
        }
        let bands: Vec<String> = names.iter().map(|n| n.as_ref().to_owned()).collect();
        std::fs::create_dir_all(dir).map_err(|e| io_err(dir, e))?;
        let spool_path = dir.join("solution.spool");
        let spool = BufWriter::new(std::fs::File::create(&spool_path).map_err(|e| io_err(&spool_path, e))?);
        let csv_path = dir.join("patches.csv");
        let mut csv = AtomicFile::create(&csv_path).map_err(|e| io_err(&csv_path, e))?;
        let column = |prefix: &str| bands.iter().map(|n| format!(",{prefix}_{n}")).collect::<String>();
        writeln!(csv, "index,group,material,area{}{},units{}", column("b"), column("h"), column("absorbed"))
            .map_err(|e| io_err(&csv_path, e))?;
        Ok(StreamedOutput {
            dir: dir.to_owned(),
            spool_path,
            spool,
            csv_path,
            csv: Some(csv),
            prototype_names: scene.prototypes.iter().map(|p| p.name.clone()).collect(),
            material_names: scene.materials.iter().map(|m| m.name.clone()).collect(),
            emitter: scene.materials.iter().map(crate::scene::Material::is_emitter).collect(),
            bounds: Aabb::EMPTY,
            leaves: 0,
            vertices: 0,
            histogram: vec![0; TONE_BINS],
            max_b: 0.0,
            grey: bands.iter().map(String::as_str).ne(["r", "g", "b"]),
            bands,
            absorptance: scene.materials.iter().map(|m| std::array::from_fn(|c| 1.0 - m.reflectance[c] - m.transmittance[c])).collect(),
            groups: vec![(0.0, [0.0; 3]); scene.prototypes.len()],
        })
    }

    /// The tone map of the streamed solution: [`ToneMap::from_levels`], with the percentile read
    /// from a logarithmic histogram (bins 1/16 of a decade wide).
    fn tone(&self) -> ToneMap {
        let total: u64 = self.histogram.iter().sum();
        if total == 0 {
            return ToneMap { white: 1.0 };
        }
        let rank = (total as f64 * 0.95) as u64;
        let (mut seen, mut bin) = (0, 0);
        for (i, &n) in self.histogram.iter().enumerate() {
            seen += n;
            bin = i;
            if seen > rank {
                break;
            }
        }
        let p95 = (TONE_MIN * 10f64.powf((bin as f64 + 1.0) / TONE_BINS_PER_DECADE)).min(self.max_b);
        ToneMap::from_levels(p95, self.max_b)
    }

    /// Renames `patches.csv` to its final name, writes `solution.ply`, `solution.glb` and, with
    /// `render`, `image.png` from the spool, then removes it (the spool is removed on failure too).
    pub fn finish(mut self, render: Option<&RenderConfig>) -> Result<StreamedSummary, InstancingError> {
        if let Some(csv) = self.csv.take() {
            csv.commit().map_err(|e| io_err(&self.csv_path, e))?;
        }
        self.write_groups()?;
        self.spool.flush().map_err(|e| io_err(&self.spool_path, e))?;
        let tone = self.tone();
        self.write_ply(&tone)?;
        self.write_glb(&tone)?;
        if let Some(render) = render {
            let rgb = self.render(&tone, render)?;
            let png = self.dir.join("image.png");
            crate::output::write_png(&png, &rgb, render.width, render.height)
                .map_err(|e| InstancingError::io(&png, "cannot write image", std::io::Error::other(e)))?;
        }
        let nb = self.bands.len();
        let absorbed = (0..nb).map(|c| self.groups.iter().map(|g| g.1[c]).sum()).collect();
        Ok(StreamedSummary { leaves: self.leaves, white: tone.white, bands: self.bands.clone(), absorbed })
    }

    /// `groups.csv`: area and absorbed power per prototype holding polygons, in the scene's order.
    fn write_groups(&self) -> Result<(), InstancingError> {
        let path = self.dir.join("groups.csv");
        let mut w = AtomicFile::create(&path).map_err(|e| io_err(&path, e))?;
        let header = self.bands.iter().map(|n| format!(",absorbed_{n}")).collect::<String>();
        let mut result = writeln!(w, "group,area{header}");
        for (name, (area, absorbed)) in self.prototype_names.iter().zip(&self.groups) {
            if *area > 0.0 && result.is_ok() {
                let values = absorbed[..self.bands.len()].iter().map(|v| format!(",{v:e}")).collect::<String>();
                result = writeln!(w, "{},{area:e}{values}", crate::output::csv_field(name));
            }
        }
        result.and_then(|()| w.commit()).map_err(|e| io_err(&path, e))
    }

    /// Calls `f` on every spooled leaf: its vertices and radiosity.
    fn read_spool(&self, f: &mut dyn FnMut(&[DVec3], [f64; 3])) -> Result<(), InstancingError> {
        let path = &self.spool_path;
        let file = std::fs::File::open(path).map_err(|e| InstancingError::io(path, "cannot read file", e))?;
        let mut r = BufReader::new(file);
        let mut rec = [0u8; 1 + 4 * 3 * 4 + 4 * 3];
        let mut vs = [DVec3::ZERO; 4];
        for _ in 0..self.leaves {
            r.read_exact(&mut rec[..1]).map_err(|e| InstancingError::io(path, "cannot read file", e))?;
            let n = usize::from(rec[0]).min(4);
            let len = 1 + 12 * n + 12;
            r.read_exact(&mut rec[1..len]).map_err(|e| InstancingError::io(path, "cannot read file", e))?;
            let float = |k: usize| f64::from(f32::from_le_bytes(rec[1 + 4 * k..5 + 4 * k].try_into().expect("4 bytes")));
            for (i, v) in vs.iter_mut().enumerate().take(n) {
                *v = DVec3::new(float(3 * i), float(3 * i + 1), float(3 * i + 2));
            }
            f(&vs[..n], [float(3 * n), float(3 * n + 1), float(3 * n + 2)]);
        }
        Ok(())
    }

    /// Binary PLY with the properties of the plain solve's `solution.ply` (flat per leaf).
    fn write_ply(&self, tone: &ToneMap) -> Result<(), InstancingError> {
        let path = self.dir.join("solution.ply");
        let mut w = AtomicFile::create(&path).map_err(|e| io_err(&path, e))?;
        write!(
            w,
            "ply\nformat binary_little_endian 1.0\ncomment radiosity solution (instanced, flat per leaf), radiosity in W/m2\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float radiosity_r\nproperty float radiosity_g\nproperty float radiosity_b\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            self.vertices, self.leaves
        )
        .map_err(|e| io_err(&path, e))?;
        let mut result = Ok(());
        self.read_spool(&mut |vs, b| {
            let px = tone.map(b);
            for v in vs {
                let mut rec = [0u8; 27];
                for (k, x) in [v.x, v.y, v.z, b[0], b[1], b[2]].into_iter().enumerate() {
                    rec[4 * k..4 * k + 4].copy_from_slice(&(x as f32).to_le_bytes());
                }
                rec[24..27].copy_from_slice(&px);
                if result.is_ok() {
                    result = w.write_all(&rec);
                }
            }
        })?;
        std::mem::replace(&mut result, Ok(())).map_err(|e| io_err(&path, e))?;
        let mut next = 0i32;
        self.read_spool(&mut |vs, _| {
            let mut rec = [0u8; 17];
            rec[0] = vs.len() as u8;
            for k in 0..vs.len() {
                rec[1 + 4 * k..5 + 4 * k].copy_from_slice(&(next + k as i32).to_le_bytes());
            }
            next += vs.len() as i32;
            if result.is_ok() {
                result = w.write_all(&rec[..1 + 4 * vs.len()]);
            }
        })?;
        result.and_then(|()| w.commit()).map_err(|e| io_err(&path, e))
    }

    /// `solution.glb` with the layout of the plain solve's ([`crate::output::write_glb`]), flat per
    /// leaf: four passes over the spool (positions, colours, radiosity, indices).
    fn write_glb(&self, tone: &ToneMap) -> Result<(), InstancingError> {
        let path = self.dir.join("solution.glb");
        let mut w = AtomicFile::create(&path).map_err(|e| io_err(&path, e))?;
        let (min, max) = if self.bounds.is_empty() {
            ([0.0; 3], [0.0; 3])
        } else {
            // Rounding to f32 is monotonic, so the rounded bounds bound the rounded vertices.
            let (a, b) = (self.bounds.min, self.bounds.max);
            ([a.x as f32, a.y as f32, a.z as f32], [b.x as f32, b.y as f32, b.z as f32])
        };
        let layout = GlbLayout { n_vertices: self.vertices, n_triangles: self.vertices.saturating_sub(2 * self.leaves), min, max };
        let header = layout.header().map_err(|e| io_err(&path, e))?;
        w.write_all(&header).map_err(|e| io_err(&path, e))?;
        let mut result = Ok(());
        let mut buf = Vec::with_capacity(64);
        let mut next = 0u32;
        for pass in 0..4 {
            self.read_spool(&mut |vs, b| {
                buf.clear();
                match pass {
                    0 => vs.iter().for_each(|v| crate::output::push_f32s(&mut buf, [v.x as f32, v.y as f32, v.z as f32])),
                    1 => vs.iter().for_each(|_| crate::output::push_f32s(&mut buf, tone.linear(b).map(|x| x as f32))),
                    2 => vs.iter().for_each(|_| crate::output::push_f32s(&mut buf, b.map(|x| x as f32))),
                    _ => {
                        crate::output::push_fan(&mut buf, next, vs.len());
                        next += vs.len() as u32;
                    }
                }
                if result.is_ok() {
                    result = w.write_all(&buf);
                }
            })?;
        }
        result.and_then(|()| w.commit()).map_err(|e| io_err(&path, e))
    }

    /// Draws the spooled leaves with a z-buffer at `samples`² supersampling; RGB bytes, rows from
    /// the top.
    fn render(&self, tone: &ToneMap, config: &RenderConfig) -> Result<Vec<u8>, InstancingError> {
        let ss = config.samples.max(1) as usize;
        let (w, h) = (config.width as usize * ss, config.height as usize * ss);
        let mut depth = vec![0f32; w * h];
        let mut color = vec![[0u8; 3]; w * h];
        let b = if self.bounds.is_empty() { Aabb { min: DVec3::ZERO, max: DVec3::ONE } } else { self.bounds };
        let cam = SideCamera::new(&b, config.width as f64 / config.height.max(1) as f64);
        self.read_spool(&mut |vs, rad| {
            let n = (vs[1] - vs[0]).cross(vs[vs.len() - 1] - vs[0]);
            if n.dot(cam.eye - vs[0]) <= 0.0 {
                return; // back side: the other side of a two-sided surface is its own polygon
            }
            let mut p = [[0.0f64; 3]; 4];
            for (k, v) in vs.iter().enumerate() {
                let Some(s) = cam.project(*v, w, h) else { return };
                p[k] = s;
            }
            let px = tone.map(rad);
            for k in 1..vs.len() - 1 {
                fill_triangle([p[0], p[k], p[k + 1]], w, h, &mut |i, inv_z| {
                    if inv_z > depth[i] {
                        depth[i] = inv_z;
                        color[i] = px;
                    }
                });
            }
        })?;
        let mut out = Vec::with_capacity(3 * config.width as usize * config.height as usize);
        for y in 0..config.height as usize {
            for x in 0..config.width as usize {
                let mut acc = [0u32; 3];
                for sy in 0..ss {
                    for sx in 0..ss {
                        let c = color[(y * ss + sy) * w + x * ss + sx];
                        for k in 0..3 {
                            acc[k] += u32::from(c[k]);
                        }
                    }
                }
                for a in acc {
                    out.push(((a as f64) / (ss * ss) as f64).round() as u8);
                }
            }
        }
        Ok(out)
    }
}

impl Drop for StreamedOutput {
    /// Removes the spool, whether the solve finished or not; an unfinished `patches.csv` is removed
    /// by its [`AtomicFile`].
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.spool_path);
    }
}

impl RadiositySink for StreamedOutput {
    fn polygon(&mut self, info: &PolygonInfo, leaves: &[Leaf]) -> Result<(), InstancingError> {
        let (area, b, h) = leaf_means(leaves);
        let mut rec = Vec::with_capacity(64);
        for leaf in leaves {
            let vs = leaf.poly.vertices();
            rec.clear();
            rec.push(vs.len() as u8);
            for v in vs {
                self.bounds.grow(*v);
                for x in [v.x, v.y, v.z] {
                    rec.extend_from_slice(&(x as f32).to_le_bytes());
                }
            }
            let b = if self.grey { [leaf.b[0]; 3] } else { leaf.b };
            for x in b {
                rec.extend_from_slice(&(x as f32).to_le_bytes());
            }
            self.spool.write_all(&rec).map_err(|e| io_err(&self.spool_path, e))?;
            self.leaves += 1;
            self.vertices += vs.len() as u64;
        }
        let emitter = self.emitter.get(info.material as usize).copied().unwrap_or(false);
        let lum = if self.grey { b[0] } else { b[0].max(b[1]).max(b[2]) };
        if !emitter && lum.is_finite() && lum > 0.0 {
            let bin = ((lum / TONE_MIN).log10() * TONE_BINS_PER_DECADE).floor().clamp(0.0, (TONE_BINS - 1) as f64) as usize;
            self.histogram[bin] += 1;
            self.max_b = self.max_b.max(lum);
        }
        let group = self.prototype_names.get(info.prototype as usize).map_or("", String::as_str);
        let material = self.material_names.get(info.material as usize).map_or("", String::as_str);
        let alpha = self.absorptance.get(info.material as usize).copied().unwrap_or([0.0; 3]);
        let absorbed: [f64; 3] = std::array::from_fn(|c| area * alpha[c] * h[c]);
        if let Some(g) = self.groups.get_mut(info.prototype as usize) {
            g.0 += area;
            for (sum, v) in g.1.iter_mut().zip(absorbed) {
                *sum += v;
            }
        }
        let nb = self.bands.len();
        let Some(csv) = self.csv.as_mut() else { return Err(io_err(&self.csv_path, std::io::Error::other("already finished"))) };
        let mut row = format!("{},{},{},{area:e}", info.flat_index, crate::output::csv_field(group), crate::output::csv_field(material));
        for v in b[..nb].iter().chain(&h[..nb]) {
            row.push_str(&format!(",{v:e}"));
        }
        row.push_str(",W/m2");
        for v in &absorbed[..nb] {
            row.push_str(&format!(",{v:e}"));
        }
        writeln!(csv, "{row}").map_err(|e| io_err(&self.csv_path, e))
    }
}

/// A pinhole camera on the −y side of a box looking along +y, z up, 40° vertical field of view,
/// far enough to see the whole box.
struct SideCamera {
    eye: DVec3,
    half_w: f64,
    half_h: f64,
    near: f64,
}

impl SideCamera {
    fn new(b: &Aabb, aspect: f64) -> SideCamera {
        let (c, e) = (b.center(), b.extent());
        let half_h = (20f64).to_radians().tan();
        let half_w = half_h * aspect.max(1e-9);
        let dist = (0.5 * e.z / half_h).max(0.5 * e.x / half_w).max(1e-300) + 0.5 * e.y;
        SideCamera { eye: c - DVec3::Y * dist * 1.05, half_w, half_h, near: 1e-9 * dist }
    }

    /// Pixel coordinates (x right, y down) and `1/depth` of `v`, or `None` behind the camera.
    fn project(&self, v: DVec3, w: usize, h: usize) -> Option<[f64; 3]> {
        let d = v - self.eye;
        let (x, y, z) = (d.x, d.z, d.y);
        if z <= self.near {
            return None;
        }
        Some([(x / (z * self.half_w) + 1.0) * 0.5 * w as f64, (1.0 - y / (z * self.half_h)) * 0.5 * h as f64, 1.0 / z])
    }
}

/// Calls `f(pixel index, 1/depth)` for every pixel centre inside the screen-space triangle `p`
/// (either winding), with `1/depth` interpolated linearly in screen space (perspective-correct).
fn fill_triangle(p: [[f64; 3]; 3], w: usize, h: usize, f: &mut dyn FnMut(usize, f32)) {
    let area = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    if area.abs() < 1e-12 || !area.is_finite() {
        return;
    }
    let x0 = p.iter().map(|q| q[0]).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
    let x1 = (p.iter().map(|q| q[0]).fold(f64::NEG_INFINITY, f64::max).ceil().min(w as f64)).max(0.0) as usize;
    let y0 = p.iter().map(|q| q[1]).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
    let y1 = (p.iter().map(|q| q[1]).fold(f64::NEG_INFINITY, f64::max).ceil().min(h as f64)).max(0.0) as usize;
    let edge = |a: [f64; 3], b: [f64; 3], x: f64, y: f64| (b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1]);
    for y in y0..y1 {
        for x in x0..x1 {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let w0 = edge(p[1], p[2], cx, cy) / area;
            let w1 = edge(p[2], p[0], cx, cy) / area;
            let w2 = 1.0 - w0 - w1;
            if w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0 {
                f(y * w + x, (w0 * p[0][2] + w1 * p[1][2] + w2 * p[2][2]) as f32);
            }
        }
    }
}
