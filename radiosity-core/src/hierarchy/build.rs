//! Top-down cluster construction over the input polygons (median split of centroids along the
//! longest axis of their bounds).

use super::{Element, ElementId, ElementKind, Hierarchy, NONE, surface_element};
use crate::geom::{Aabb, DVec3};
use crate::scene::Scene;

/// How the hierarchy is built.
#[derive(Clone, Copy, Debug)]
pub struct BuildConfig {
    /// Most polygons directly under one cluster.
    pub max_leaf_polygons: usize,
    /// Smallest surface element area, relative to the scene's total area.
    pub min_area_rel: f64,
    /// How many times every polygon may be quartered whatever `min_area_rel` says: a polygon
    /// smaller than `4^min_polygon_depth` times the smallest element may still be split into
    /// pieces of `4^-min_polygon_depth` of its own area. With it the smallest element is no
    /// longer relative to the scene's size alone, which grows with the number of leaves in a
    /// canopy while each leaf stays the same: 3,200 leaves of 10 cm over a 10 m ground (164 m²)
    /// could be quartered twice only, too coarse for the light that leaves crossing each other
    /// or 1 cm apart exchange, and the levels stalled at an estimate of 4.1% after 4 M links.
    pub min_polygon_depth: u8,
}

/// Default of [`BuildConfig::min_polygon_depth`]: pieces of 1/4096 of any polygon (1.6 mm on a
/// 10 cm leaf). The light two crossing leaves exchange converges slowly as the pieces along the
/// crossing line shrink (order 0.8 in the estimate's extrapolation): with 4 (6 mm) a 400-leaf
/// canopy with one crossing pair stalled at an estimate of 1.07%; with 6 it met 1% at the first
/// level.
pub const MIN_POLYGON_DEPTH: u8 = 6;

impl Default for BuildConfig {
    fn default() -> Self {
        BuildConfig { max_leaf_polygons: 4, min_area_rel: 2e-6, min_polygon_depth: MIN_POLYGON_DEPTH }
    }
}

/// Relative tolerance of [`twins`]: how far apart (relative to the polygon's size) the centroids of
/// the two sides may be.
pub const TWIN_REL_TOL: f64 = crate::geom::BACK_TO_BACK_REL_TOL;

/// The two sides of every transmitting surface: consecutive polygons with the same reflectance and
/// a positive transmittance (their materials may differ in emission), the second the first reversed
/// (same centroid and area, opposite normal), as the flattening of two-sided surfaces writes them.
#[must_use]
pub fn twins(scene: &Scene) -> Vec<u32> {
    let n = scene.polygons.len();
    let mut twin = vec![NONE; n];
    let mut k = 0;
    while k + 1 < n {
        let (a, b) = (&scene.polygons[k], &scene.polygons[k + 1]);
        let (m, mb) = (&scene.materials[a.material as usize], &scene.materials[b.material as usize]);
        if m.reflectance == mb.reflectance
            && m.transmittance == mb.transmittance
            && m.transmittance.iter().any(|&t| t > 0.0)
            && a.poly.is_back_of(&b.poly)
        {
            twin[k] = (k + 1) as u32;
            twin[k + 1] = k as u32;
            k += 2;
        } else {
            k += 1;
        }
    }
    twin
}

/// Builds the hierarchy of `scene`: one root surface element per polygon (ids `0..n`), then clusters.
#[must_use]
pub fn build(scene: &Scene, config: &BuildConfig) -> Hierarchy {
    let n = scene.polygons.len();
    let mut elements = Vec::with_capacity(2 * n + 1);
    for (i, p) in scene.polygons.iter().enumerate() {
        elements.push(surface_element(i as u32, p.poly, p.poly.normal(), NONE, 0));
    }
    let reflectance = scene.polygons.iter().map(|p| scene.materials[p.material as usize].reflectance).collect();
    let emission = scene.polygons.iter().map(|p| scene.materials[p.material as usize].emission).collect();
    let twin = twins(scene);
    let transmittance = scene
        .polygons
        .iter()
        .zip(&twin)
        .map(|(p, &t)| if t == NONE { [0.0; 3] } else { scene.materials[p.material as usize].transmittance })
        .collect();
    let total_area: f64 = elements.iter().map(|e| e.area).sum();
    let mut h = Hierarchy {
        elements,
        children: Vec::with_capacity(2 * n),
        cluster_polygons: (0..n as u32).collect(),
        cluster_area_prefix: Vec::new(),
        cluster_members: Vec::new(),
        root: NONE,
        n_polygons: n as u32,
        reflectance,
        emission,
        transmittance,
        twin,
        min_area: config.min_area_rel * total_area,
        min_piece_rel: 0.25f64.powi(i32::from(config.min_polygon_depth)),
        direct: Vec::new(),
        direct_error: Vec::new(),
        direct_soft: Vec::new(),
        direct_edge: Vec::new(),
    };
    let centroids: Vec<DVec3> = h.elements.iter().map(|e| e.center).collect();
    h.root = build_cluster(&mut h, &centroids, 0, n, 0, config.max_leaf_polygons.max(2));
    let mut prefix = Vec::with_capacity(n + 1);
    let mut acc = 0.0;
    prefix.push(0.0);
    for &p in &h.cluster_polygons {
        acc += h.elements[p as usize].area;
        prefix.push(acc);
    }
    h.cluster_area_prefix = prefix;
    h.cluster_members = h.cluster_polygons.iter().map(|&p| (h.elements[p as usize].normal, h.elements[p as usize].area)).collect();
    h
}

fn build_cluster(h: &mut Hierarchy, centroids: &[DVec3], start: usize, end: usize, depth: u16, max_leaf: usize) -> ElementId {
    let id = h.elements.len() as ElementId;
    // Reserve the slot; children are filled in below.
    h.elements.push(Element {
        kind: ElementKind::Cluster { poly_start: start as u32, poly_end: end as u32 },
        parent: NONE,
        child_start: 0,
        n_children: 0,
        area: 0.0,
        center: DVec3::ZERO,
        normal: DVec3::ZERO,
        bounds: Aabb::EMPTY,
        radius: 0.0,
        depth,
    });
    let kids: Vec<ElementId> = if end - start <= max_leaf {
        h.cluster_polygons[start..end].to_vec()
    } else {
        let mut cb = Aabb::EMPTY;
        for &p in &h.cluster_polygons[start..end] {
            cb.grow(centroids[p as usize]);
        }
        let axis = cb.longest_axis();
        let mid = (start + end) / 2;
        h.cluster_polygons[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis]).then(a.cmp(&b))
        });
        vec![build_cluster(h, centroids, start, mid, depth + 1, max_leaf), build_cluster(h, centroids, mid, end, depth + 1, max_leaf)]
    };
    let child_start = h.children.len() as u32;
    let mut bounds = Aabb::EMPTY;
    let mut area = 0.0;
    let mut weighted = DVec3::ZERO;
    for &k in &kids {
        let e = &mut h.elements[k as usize];
        e.parent = id;
        bounds.merge(&e.bounds);
        area += e.area;
        weighted += e.area * e.center;
        h.children.push(k);
    }
    let center = if area > 0.0 { weighted / area } else { bounds.center() };
    // Bounding sphere about the area centroid: farthest box corner.
    let radius = (0..8)
        .map(|c| {
            let corner = DVec3::new(
                if c & 1 == 0 { bounds.min.x } else { bounds.max.x },
                if c & 2 == 0 { bounds.min.y } else { bounds.max.y },
                if c & 4 == 0 { bounds.min.z } else { bounds.max.z },
            );
            (corner - center).length()
        })
        .fold(0.0, f64::max);
    let normal = flat_normal(h, start, end, center, radius);
    let e = &mut h.elements[id as usize];
    e.child_start = child_start;
    e.n_children = kids.len() as u32;
    e.bounds = bounds;
    e.area = area;
    e.center = center;
    e.radius = radius;
    e.normal = normal;
    id
}

/// Tolerance of [`flat_normal`]: how far a member's normal may turn (`1 − n·n₀`) and a vertex lie
/// off the plane (relative to the cluster's radius).
pub const FLAT_REL_TOL: f64 = 1e-9;

/// The common front normal of the polygons `cluster_polygons[start..end]` when they all lie in one
/// plane facing the same way (a wall cut into pieces), else zero: such a cluster has a plane, and
/// nothing behind it exchanges light with it (see [`crate::formfactor::behind_surface`]).
fn flat_normal(h: &Hierarchy, start: usize, end: usize, center: DVec3, radius: f64) -> DVec3 {
    let members = &h.cluster_polygons[start..end];
    let Some(&first) = members.first() else { return DVec3::ZERO };
    let n0 = h.elements[first as usize].normal;
    let tol = FLAT_REL_TOL * radius.max(f64::MIN_POSITIVE);
    for &p in members {
        let e = &h.elements[p as usize];
        if 1.0 - e.normal.dot(n0) > FLAT_REL_TOL {
            return DVec3::ZERO;
        }
        let Some(poly) = e.poly() else { return DVec3::ZERO };
        if poly.vertices().iter().any(|v| n0.dot(*v - center).abs() > tol) {
            return DVec3::ZERO;
        }
    }
    n0
}
