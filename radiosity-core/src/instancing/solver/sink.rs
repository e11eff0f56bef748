//! Output: the finished polygons of a level streamed to a [`RadiositySink`], leaf by leaf.

use super::cache::Similarity;
use super::config::InstancedStats;
use super::level::{Level, Role};
use crate::geom::Poly;
use crate::hierarchy::{ElementId, Hierarchy};
use crate::instancing::InstancingError;
use crate::instancing::model::{PrototypeId, Transform};
use crate::solve::Solution;

/// A finished leaf element of a streamed polygon.
#[derive(Clone, Copy, Debug)]
pub struct Leaf {
    /// The element's polygon (world coordinates).
    pub poly: Poly,
    /// Radiosity B (W/m², RGB).
    pub b: [f64; 3],
    /// Front-side irradiance H (W/m², RGB), light from outside an opened instance included.
    pub h: [f64; 3],
}

/// Which flattened polygon a streamed polygon is.
#[derive(Clone, Copy, Debug)]
pub struct PolygonInfo {
    /// Index in [`flatten()`](crate::instancing::flatten()) order with two-sided pairs.
    pub flat_index: u64,
    /// Scene material.
    pub material: u32,
    /// Prototype that holds the polygon.
    pub prototype: PrototypeId,
}

/// Receives finished polygons, in flattening order of each local problem (not globally sorted).
pub trait RadiositySink: Send {
    /// Polygon `info` finished, with its leaf elements.
    fn polygon(&mut self, info: &PolygonInfo, leaves: &[Leaf]) -> Result<(), InstancingError>;
}

/// Keeps the area-weighted mean radiosity of every flattened polygon (memory linear in the
/// polygons: for comparisons with the full solve, not for large scenes).
#[derive(Clone, Debug, Default)]
pub struct PolygonMeans {
    /// Mean radiosity by flattened index (zero until received).
    pub radiosity: Vec<[f64; 3]>,
    /// Area by flattened index.
    pub area: Vec<f64>,
}

impl RadiositySink for PolygonMeans {
    fn polygon(&mut self, info: &PolygonInfo, leaves: &[Leaf]) -> Result<(), InstancingError> {
        let i = info.flat_index as usize;
        if self.radiosity.len() <= i {
            self.radiosity.resize(i + 1, [0.0; 3]);
            self.area.resize(i + 1, 0.0);
        }
        let (area, b, _) = leaf_means(leaves);
        self.radiosity[i] = b;
        self.area[i] = area;
        Ok(())
    }
}

/// Total area and area-weighted mean radiosity and irradiance of a polygon's leaves.
#[must_use]
pub fn leaf_means(leaves: &[Leaf]) -> (f64, [f64; 3], [f64; 3]) {
    let (mut area, mut b, mut h) = (0.0, [0.0; 3], [0.0; 3]);
    for leaf in leaves {
        let a = leaf.poly.area();
        area += a;
        for c in 0..3 {
            b[c] += a * leaf.b[c];
            h[c] += a * leaf.h[c];
        }
    }
    let mean = |x: f64| if area > 0.0 { x / area } else { 0.0 };
    (area, b.map(mean), h.map(mean))
}

/// Calls `f` on every leaf below `e`.
pub(super) fn collect_leaves(h: &Hierarchy, e: ElementId, f: &mut dyn FnMut(ElementId)) {
    let mut stack = vec![e];
    while let Some(x) = stack.pop() {
        let kids = h.children_of(x);
        if kids.is_empty() {
            f(x);
        } else {
            stack.extend_from_slice(kids);
        }
    }
}

/// Streams the own polygons of a solved level to `sink` (in world coordinates, by flattened index
/// from `flat_base`), their irradiance including the light from outside (`external`), and returns
/// each proxy face's mean irradiance (zero for the own polygons).
pub(super) fn stream_own(
    level: &Level,
    solution: &Solution,
    external: &[[f64; 3]],
    similarity: Option<&Similarity>,
    flat_base: u64,
    sink: &mut dyn RadiositySink,
    stats: &mut InstancedStats,
) -> Result<Vec<[f64; 3]>, InstancingError> {
    // Stream the own polygons, keep only the proxies' irradiance.
    let to_world = similarity.map(|s| Transform { matrix: s.matrix });
    let h = &level.h;
    let mut leaves = Vec::new();
    let mut face_irradiance = vec![[0.0; 3]; level.polys.len()];
    for (i, role) in level.roles.iter().enumerate() {
        match *role {
            Role::Own(info) => {
                leaves.clear();
                let ext = external.get(i).copied().unwrap_or([0.0; 3]);
                collect_leaves(h, i as ElementId, &mut |e| {
                    if let Some(p) = h.get(e).poly() {
                        let irr = solution.irradiance[e as usize];
                        leaves.push(Leaf {
                            poly: to_world.as_ref().map_or(*p, |t| t.poly(p)),
                            b: solution.radiosity[e as usize],
                            h: std::array::from_fn(|c| irr[c] + ext[c]),
                        });
                    }
                });
                stats.leaves_out += leaves.len() as u64;
                stats.polygons_out += 1;
                sink.polygon(&PolygonInfo { flat_index: flat_base + info.flat_index, ..info }, &leaves)?;
            }
            Role::ProxyFace { .. } => {
                let (mut acc, mut area) = ([0.0; 3], 0.0);
                collect_leaves(h, i as ElementId, &mut |e| {
                    let a = h.get(e).area;
                    let irr = solution.irradiance[e as usize];
                    for c in 0..3 {
                        acc[c] += a * irr[c];
                    }
                    area += a;
                });
                face_irradiance[i] = acc.map(|v| if area > 0.0 { v / area } else { 0.0 });
            }
        }
    }
    Ok(face_irradiance)
}
