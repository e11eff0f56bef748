//! `solution.glb`: the leaf elements as one binary glTF 2.0 mesh, for Blender and web viewers.
//!
//! The vertices are those of `solution.ply`, in the same order (each leaf has its own vertices);
//! each leaf is a fan of triangles. Attributes, all `FLOAT` `VEC3`, one tightly packed buffer view
//! each:
//! - `POSITION`, with `min`/`max`;
//! - `COLOR_0`, the tone map's linear display value ([`ToneMap::linear`]): glTF colours are linear,
//!   and a viewer's sRGB encoding of them gives exactly `solution.ply`'s `red/green/blue` bytes;
//! - `_RADIOSITY`, the radiosity in W/m² (linear, not tone-mapped; glTF custom attributes start
//!   with `_`).
//!
//! One material, white, unlit (`KHR_materials_unlit`, not required: a viewer without it shows a
//! rough dielectric), so the baked colours show as they are. The binary buffer holds the positions,
//! the colours, the radiosity, then the `u32` triangle indices.

use super::render::ToneMap;
use super::smooth::CornerValues;
use crate::hierarchy::Hierarchy;
use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use std::io::Write;

/// Name of the radiosity attribute (W/m², `FLOAT` `VEC3`).
pub const GLB_RADIOSITY_ATTRIBUTE: &str = "_RADIOSITY";

/// Sizes and bounds of a GLB mesh, known before its data is written (so that the data can be
/// streamed).
#[derive(Clone, Copy, Debug)]
pub struct GlbLayout {
    /// Vertices.
    pub n_vertices: u64,
    /// Triangles.
    pub n_triangles: u64,
    /// Smallest position coordinates (as written, `f32`).
    pub min: [f32; 3],
    /// Largest position coordinates (as written, `f32`).
    pub max: [f32; 3],
}

impl GlbLayout {
    /// Bytes of one `FLOAT` `VEC3` vertex attribute.
    fn attribute_bytes(&self) -> u64 {
        12 * self.n_vertices
    }

    /// Bytes of the binary chunk's data: three attributes and the indices (all multiples of 4).
    fn bin_bytes(&self) -> u64 {
        3 * self.attribute_bytes() + 12 * self.n_triangles
    }

    /// The GLB header, the JSON chunk and the binary chunk's header; the caller then writes the
    /// binary data in order: positions, colours, radiosity (`f32` × 3 per vertex), indices (`u32`
    /// × 3 per triangle). Fails when the file would pass GLB's 4 GiB limit.
    pub fn header(&self) -> std::io::Result<Vec<u8>> {
        let mut json_text = json::serialize::to_string(&self.document()).map_err(std::io::Error::other)?.into_bytes();
        while json_text.len() % 4 != 0 {
            json_text.push(b' ');
        }
        let bin = self.bin_bytes();
        let total = 12 + 8 + json_text.len() as u64 + 8 + bin;
        let too_big = || std::io::Error::other(format!("{total} bytes is over glTF binary's 4 GiB limit"));
        let total32 = u32::try_from(total).map_err(|_| too_big())?;
        let mut out = Vec::with_capacity(json_text.len() + 28);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&total32.to_le_bytes());
        out.extend_from_slice(&(json_text.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json_text);
        out.extend_from_slice(&(bin as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        Ok(out)
    }

    /// The glTF document describing the binary chunk.
    fn document(&self) -> json::Root {
        let mut root =
            json::Root { asset: json::Asset { generator: Some("radiosity".into()), ..json::Asset::default() }, ..Default::default() };
        let buffer = root.push(json::Buffer {
            byte_length: USize64(self.bin_bytes()),
            extensions: None,
            extras: Default::default(),
            name: None,
            uri: None,
        });
        let mut offset = 0u64;
        let mut view = |root: &mut json::Root, bytes: u64, target: json::buffer::Target| {
            let v = root.push(json::buffer::View {
                buffer,
                byte_length: USize64(bytes),
                byte_offset: Some(USize64(offset)),
                byte_stride: None,
                extensions: None,
                extras: Default::default(),
                name: None,
                target: Some(Valid(target)),
            });
            offset += bytes;
            v
        };
        let mut accessor = |root: &mut json::Root, bytes: u64, count: u64, ty: json::accessor::Type, target, name: &str| {
            let buffer_view = view(root, bytes, target);
            let component_type = if target == json::buffer::Target::ElementArrayBuffer {
                json::accessor::ComponentType::U32
            } else {
                json::accessor::ComponentType::F32
            };
            root.push(json::Accessor {
                buffer_view: Some(buffer_view),
                byte_offset: None,
                count: USize64(count),
                component_type: Valid(json::accessor::GenericComponentType(component_type)),
                extensions: None,
                extras: Default::default(),
                type_: Valid(ty),
                min: None,
                max: None,
                name: Some(name.into()),
                normalized: false,
                sparse: None,
            })
        };
        let vec3 = json::accessor::Type::Vec3;
        let array = json::buffer::Target::ArrayBuffer;
        let n = self.n_vertices;
        let positions = accessor(&mut root, self.attribute_bytes(), n, vec3, array, "position");
        let colors = accessor(&mut root, self.attribute_bytes(), n, vec3, array, "tone-mapped colour (linear)");
        let radiosity = accessor(&mut root, self.attribute_bytes(), n, vec3, array, "radiosity (W/m2)");
        let indices = accessor(
            &mut root,
            12 * self.n_triangles,
            3 * self.n_triangles,
            json::accessor::Type::Scalar,
            json::buffer::Target::ElementArrayBuffer,
            "triangles",
        );
        let p = &mut root.accessors[positions.value()];
        p.min = Some(json::Value::from(self.min.to_vec()));
        p.max = Some(json::Value::from(self.max.to_vec()));

        let material = root.push(json::Material {
            name: Some("radiosity (unlit vertex colours)".into()),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor([1.0; 4]),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(1.0),
                ..Default::default()
            },
            extensions: Some(json::extensions::material::Material { unlit: Some(json::extensions::material::Unlit {}) }),
            ..Default::default()
        });
        root.extensions_used.push("KHR_materials_unlit".into());
        let mut attributes = std::collections::BTreeMap::new();
        let _ = attributes.insert(Valid(json::mesh::Semantic::Positions), positions);
        let _ = attributes.insert(Valid(json::mesh::Semantic::Colors(0)), colors);
        let _ = attributes.insert(Valid(json::mesh::Semantic::Extras(GLB_RADIOSITY_ATTRIBUTE.trim_start_matches('_').into())), radiosity);
        let primitive = json::mesh::Primitive {
            attributes,
            extensions: None,
            extras: Default::default(),
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        };
        let mesh = root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some("leaf elements".into()),
            primitives: vec![primitive],
            weights: None,
        });
        let node = root.push(json::Node { mesh: Some(mesh), name: Some("radiosity solution".into()), ..Default::default() });
        let scene = root.push(json::Scene { extensions: None, extras: Default::default(), name: None, nodes: vec![node] });
        root.scene = Some(scene);
        root
    }
}

/// A leaf's vertices and its corner values.
type LeafCorners = (Vec<[f32; 3]>, [[f64; 3]; 4]);

/// Writes one value per vertex into the buffer of a section: its position and its corner value.
type VertexWriter<'a> = dyn FnMut(&mut Vec<u8>, &[f32; 3], [f64; 3]) + 'a;

/// Writes the leaves of `h` as `solution.glb` (see the module docs): the vertices and corner
/// values of [`super::write_ply`], colours from `tone`.
pub fn write_glb(w: &mut impl Write, h: &Hierarchy, corners: &CornerValues, tone: &ToneMap) -> std::io::Result<()> {
    let leaves: Vec<LeafCorners> = h
        .leaves()
        .filter_map(|e| {
            let poly = h.get(e).poly()?;
            let vs = poly.vertices().iter().map(|v| [v.x as f32, v.y as f32, v.z as f32]).collect();
            Some((vs, corners.corners(e).copied().unwrap_or([[0.0; 3]; 4])))
        })
        .collect();
    let n_vertices: usize = leaves.iter().map(|(vs, _)| vs.len()).sum();
    let n_triangles: usize = leaves.iter().map(|(vs, _)| vs.len().saturating_sub(2)).sum();
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for v in leaves.iter().flat_map(|(vs, _)| vs) {
        for k in 0..3 {
            min[k] = min[k].min(v[k]);
            max[k] = max[k].max(v[k]);
        }
    }
    if n_vertices == 0 {
        (min, max) = ([0.0; 3], [0.0; 3]);
    }
    let layout = GlbLayout { n_vertices: n_vertices as u64, n_triangles: n_triangles as u64, min, max };
    w.write_all(&layout.header()?)?;
    let mut buf = Vec::with_capacity(12 * n_vertices);
    let mut section = |w: &mut dyn Write, f: &mut VertexWriter<'_>| {
        buf.clear();
        for (vs, c) in &leaves {
            for (k, v) in vs.iter().enumerate() {
                f(&mut buf, v, c[k]);
            }
        }
        w.write_all(&buf)
    };
    section(w, &mut |buf, v, _| push_f32s(buf, *v))?;
    section(w, &mut |buf, _, b| push_f32s(buf, tone.linear(b).map(|x| x as f32)))?;
    section(w, &mut |buf, _, b| push_f32s(buf, b.map(|x| x as f32)))?;
    let mut indices = Vec::with_capacity(12 * n_triangles);
    let mut base = 0u32;
    for (vs, _) in &leaves {
        push_fan(&mut indices, base, vs.len());
        base += vs.len() as u32;
    }
    w.write_all(&indices)
}

/// Appends three `f32` little-endian.
pub(crate) fn push_f32s(buf: &mut Vec<u8>, x: [f32; 3]) {
    for v in x {
        buf.extend_from_slice(&v.to_le_bytes());
    }
}

/// Appends the `u32` indices of the triangle fan of a polygon with `n` vertices from `base`.
pub(crate) fn push_fan(buf: &mut Vec<u8>, base: u32, n: usize) {
    for k in 1..n.saturating_sub(1) as u32 {
        for i in [base, base + k, base + k + 1] {
            buf.extend_from_slice(&i.to_le_bytes());
        }
    }
}
