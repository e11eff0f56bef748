//! Form factor of a link (receiver ← source), by receiver quadrature of the analytic point-to-polygon
//! formula for surfaces, and by the isotropic cluster approximation where a cluster is involved.

use super::point_polygon::point_polygon;
use crate::geom::{DVec3, Poly, PolyKind, quadrature};
use crate::hierarchy::{Element, Hierarchy};
use std::f64::consts::PI;

/// Separation (centre distance over the sum of bounding radii) beyond which a surface link uses the
/// 4-point (quads) or 3-point (triangles) rule on the receiver; nearer pairs use 9 or 6 points. A
/// 1-point rule is biased (the kernel is convex in the distance), and its bias accumulates in stiff
/// scenes, where the solution amplifies a row-sum error δ by ρ/(1−ρ).
pub const FAR_SEPARATION: f64 = 4.0;
/// Separation under which a surface link integrates adaptively over the receiver.
pub const NEAR_SEPARATION: f64 = 1.5;

/// How carefully a form factor is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum FormFactorQuality {
    /// One point at the receiver's centre.
    Estimate,
    /// Receiver quadrature chosen by separation.
    Precise,
}

/// Cheap estimate of the link coefficient: the analytic point-to-polygon value at the receiver's centre
/// for surfaces, the isotropic cluster formula (with the distance shortened by the bounding radii,
/// so it over-estimates near pairs) otherwise.
#[must_use]
pub fn estimate(h: &Hierarchy, source: u32, receiver: u32) -> f64 {
    let (s, r) = (h.get(source), h.get(receiver));
    match (s.poly(), r.poly()) {
        (Some(sp), Some(_)) => point_polygon(r.center, r.normal, sp.vertices(), s.normal),
        _ => cluster_ff(h, s, r, true),
    }
}

/// Where [`estimate_max`] samples the receiver: its centre and its corners pulled this fraction of
/// the way toward the centre (a corner exactly on the source's plane would read 0).
pub const MAX_PROBE_PULL: f64 = 0.1;

/// Estimate of the largest point-to-source form factor over the receiver: the maximum of the
/// analytic value at the receiver's centre and near each of its corners. The classic BF criterion
/// applied to this value refines where a receiver touches its source (edges, corners), which the
/// centre value alone misses. Clusters use the conservative isotropic formula.
#[must_use]
pub fn estimate_max(h: &Hierarchy, source: u32, receiver: u32) -> f64 {
    let (s, r) = (h.get(source), h.get(receiver));
    match (s.poly(), r.poly()) {
        (Some(sp), Some(rp)) => {
            let sv = sp.vertices();
            let mut f = point_polygon(r.center, r.normal, sv, s.normal);
            for &v in rp.vertices() {
                let x = v + MAX_PROBE_PULL * (r.center - v);
                f = f.max(point_polygon(x, r.normal, sv, s.normal));
            }
            f
        }
        _ => cluster_ff(h, s, r, true),
    }
}

/// The link coefficient `F` (see the module docs of [`crate::formfactor`]) without visibility.
#[must_use]
pub fn link_form_factor(h: &Hierarchy, source: u32, receiver: u32, quality: FormFactorQuality) -> f64 {
    let (s, r) = (h.get(source), h.get(receiver));
    let (Some(sp), Some(rp)) = (s.poly(), r.poly()) else {
        return cluster_ff(h, s, r, false);
    };
    let sv = sp.vertices();
    if quality == FormFactorQuality::Estimate {
        return point_polygon(r.center, r.normal, sv, s.normal);
    }
    let dist = (s.center - r.center).length();
    let separation = dist / (s.radius + r.radius).max(f64::MIN_POSITIVE);
    let rule = match (rp.kind, separation) {
        (PolyKind::Quad, x) if x >= FAR_SEPARATION => &quadrature::QUAD_4,
        (PolyKind::Quad, _) => &quadrature::QUAD_9,
        (PolyKind::Triangle, x) if x >= FAR_SEPARATION => &quadrature::TRI_3,
        (PolyKind::Triangle, _) => &quadrature::TRI_6,
    };
    if separation < NEAR_SEPARATION
        && wholly_in_front(rp.vertices(), sp.vertices(), s.normal, s.radius)
        && wholly_in_front(sv, rp.vertices(), r.normal, r.radius)
    {
        // Near pairs wholly in front of each other (touching walls included): Stokes' double
        // contour integral, exact up to 1e-11 and cheap where receiver quadrature struggles with
        // the log-singular derivatives at a shared edge.
        return super::contour::polygon_polygon(rp.vertices(), sv);
    }
    if separation < NEAR_SEPARATION {
        // Other near pairs (one crosses the other's plane): the integrand is singular in its
        // derivatives at the contact, so integrate adaptively until the 4-children refinement agrees.
        let whole = rule_average(rp, r.normal, sv, s.normal, rule);
        return adaptive_average(rp, r.normal, sv, s.normal, whole, ADAPTIVE_MAX_DEPTH);
    }
    rule_average(rp, r.normal, sv, s.normal, rule)
}

/// Tolerance (relative to the element's radius) of "in front of a plane" for choosing the contour
/// integral; a vertex on the plane (a shared edge) counts as in front.
pub const FRONT_REL_TOL: f64 = 1e-9;

/// True when every vertex of `poly` lies on or in front of the plane through `plane_pts` with
/// normal `n`, and not all of them on it (coplanar pairs exchange nothing).
fn wholly_in_front(poly: &[DVec3], plane_pts: &[DVec3], n: DVec3, radius: f64) -> bool {
    let o = plane_pts[0];
    let tol = FRONT_REL_TOL * radius.max(f64::MIN_POSITIVE);
    let mut some_in_front = false;
    for v in poly {
        let d = n.dot(*v - o);
        if d < -tol {
            return false;
        }
        some_in_front |= d > tol;
    }
    some_in_front
}

/// Relative tolerance of the adaptive receiver quadrature for near pairs.
pub const ADAPTIVE_REL_TOL: f64 = 1e-4;
/// Absolute tolerance of the adaptive receiver quadrature for near pairs.
pub const ADAPTIVE_ABS_TOL: f64 = 1e-9;
/// Deepest subdivision of the receiver in the adaptive quadrature.
pub const ADAPTIVE_MAX_DEPTH: u32 = 4;

/// Average over the receiver `rp` of the point-to-source form factor with a fixed rule.
fn rule_average(rp: &Poly, rn: DVec3, sv: &[DVec3], sn: DVec3, rule: &quadrature::Rule) -> f64 {
    let mut f = 0.0;
    match rp.kind {
        PolyKind::Quad => {
            // Bilinear map: weight by the local Jacobian so non-parallelograms integrate correctly.
            let mut wsum = 0.0;
            for (&(u, v), &w) in rule.points.iter().zip(rule.weights) {
                let du = (1.0 - v) * (rp.v[1] - rp.v[0]) + v * (rp.v[2] - rp.v[3]);
                let dv = (1.0 - u) * (rp.v[3] - rp.v[0]) + u * (rp.v[2] - rp.v[1]);
                let jac = du.cross(dv).length();
                f += w * jac * point_polygon(rp.point(u, v), rn, sv, sn);
                wsum += w * jac;
            }
            if wsum > 0.0 {
                f /= wsum;
            }
        }
        PolyKind::Triangle => {
            for (&(u, v), &w) in rule.points.iter().zip(rule.weights) {
                f += w * point_polygon(rp.point(u, v), rn, sv, sn);
            }
        }
    }
    f
}

fn adaptive_average(rp: &Poly, rn: DVec3, sv: &[DVec3], sn: DVec3, whole: f64, depth: u32) -> f64 {
    let rule = match rp.kind {
        PolyKind::Quad => &quadrature::QUAD_4,
        PolyKind::Triangle => &quadrature::TRI_3,
    };
    let kids = rp.subdivide();
    let areas = kids.map(|k| k.area());
    let total: f64 = areas.iter().sum();
    if total <= 0.0 {
        return whole;
    }
    let vals = kids.map(|k| rule_average(&k, rn, sv, sn, rule));
    let fine: f64 = vals.iter().zip(&areas).map(|(v, a)| v * a).sum::<f64>() / total;
    if depth == 0 || (fine - whole).abs() <= ADAPTIVE_ABS_TOL + ADAPTIVE_REL_TOL * fine.abs() {
        return fine;
    }
    let mut acc = 0.0;
    for k in 0..4 {
        acc += areas[k] * adaptive_average(&kids[k], rn, sv, sn, vals[k], depth - 1);
    }
    acc / total
}

/// Clusters with at most this many polygons use their members' exact projected area in the link
/// direction; larger ones the isotropic `A/4`.
pub const CLUSTER_EXACT_MAX_POLYGONS: usize = 1024;

/// Projected area of element `e` seen from direction `dir` (unit, pointing away from the element
/// toward the viewer): `A·max(0, n·dir)` for a surface; for a cluster the sum of its polygons'
/// (self-occlusion inside the cluster ignored), or the isotropic `A/4` for large clusters.
#[must_use]
pub fn projected_area(h: &Hierarchy, e: &Element, dir: DVec3) -> f64 {
    match e.kind {
        crate::hierarchy::ElementKind::Surface { .. } => e.area * e.normal.dot(dir).max(0.0),
        crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } => {
            let members = &h.cluster_polygons[poly_start as usize..poly_end as usize];
            if members.len() > CLUSTER_EXACT_MAX_POLYGONS {
                return 0.25 * e.area;
            }
            members
                .iter()
                .map(|&p| {
                    let el = h.get(p);
                    el.area * el.normal.dot(dir).max(0.0)
                })
                .sum()
        }
    }
}

/// Cluster link coefficient (Sillion 1995, with oriented projected areas): the source radiates
/// `B·A_proj,S(dir)/π` per steradian toward the receiver, which collects it over `A_proj,R(−dir)`,
/// averaged over its area. `conservative` shortens the distance by the bounding radii and replaces
/// projected areas by their upper bounds (used for refinement estimates).
fn cluster_ff(h: &Hierarchy, s: &Element, r: &Element, conservative: bool) -> f64 {
    let d = r.center - s.center;
    let mut dist2 = d.length_squared();
    if conservative {
        let gap = (dist2.sqrt() - s.radius - r.radius).max(0.0);
        // Never let the estimate blow up: at contact use the radii as the distance scale.
        dist2 = gap.max(0.25 * (s.radius + r.radius)).powi(2);
    }
    if dist2 <= 0.0 {
        return 0.0;
    }
    let dir = d.normalize_or_zero(); // from source to receiver
    // Source factor: intensity per unit radiosity.
    let source = if conservative { s.area / PI } else { projected_area(h, s, dir) / PI };
    // Receiver factor: mean irradiance over the receiver per unit normal irradiance.
    let receiver = if conservative {
        1.0
    } else if r.is_cluster() {
        projected_area(h, r, -dir) / r.area.max(f64::MIN_POSITIVE)
    } else {
        (-r.normal.dot(dir)).max(0.0)
    };
    let f = source * receiver / dist2;
    if conservative { f } else { f.min(1.0) }
}
