//! Form factor of a link (receiver ← source), by receiver quadrature of the analytic point-to-polygon
//! formula for surfaces, and by the isotropic cluster approximation where a cluster is involved.

use super::contour::{polygon_area, polygon_polygon};
use super::point_polygon::{MAX_CLIPPED, clip_to_halfspace, point_polygon};
use crate::geom::{DVec3, Poly, PolyKind, quadrature};
use crate::hierarchy::{Element, Hierarchy};
use std::f64::consts::PI;

/// Separation (centre distance over the sum of bounding radii) beyond which a surface link uses the
/// 4-point (quads) or 3-point (triangles) rule on the receiver; nearer pairs use 9 or 6 points. A
/// 1-point rule is biased (the kernel is convex in the distance), and so, less, is the 4-point one
/// (low by 2e-5 to 7e-5 at separation 4, by under 2.5e-5 from 8 on, against under 2e-5 for the
/// 9-point rule from separation 1.5 on; unit squares, `examples/ff_accuracy.rs`): the bias
/// accumulates in stiff scenes, where the solution amplifies a row-sum error δ by ρ/(1−ρ).
pub const FAR_SEPARATION: f64 = 8.0;
/// Separation under which a surface link uses the contour integral (of the clipped pair when one
/// crosses the other's plane) instead of receiver quadrature.
pub const NEAR_SEPARATION: f64 = 1.5;

/// How carefully a form factor is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum FormFactorQuality {
    /// One point at the receiver's centre.
    Estimate,
    /// The 4-point (quads) or 3-point (triangles) receiver rule where [`Precise`] would use more
    /// points (low by up to 1e-2 next to the contour integral's range): for sharing a link's
    /// transfer among the receiver's leaves, where only the ratios matter.
    ///
    /// [`Precise`]: FormFactorQuality::Precise
    Shape,
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
/// analytic value at the receiver's centre and near each of its corners. The BF criteria applied
/// to this value refine where a receiver touches its source (edges, corners), which the centre
/// value alone misses. Clusters use the conservative isotropic formula.
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
    // A receiver on or behind the source's plane, or a source on or behind the receiver's, gets
    // nothing. Coplanar back-to-back pairs (a face flush against a wall) would otherwise reach the
    // contour integral with every receiver point in the source's plane, where it is undefined
    // (it returned the clamp, 1): the leaf-resolution gather evaluates such pairs when a link to a
    // cluster holding the face was accepted for the cluster's other members.
    if behind_surface(s, rp.vertices().iter().copied()) || behind_surface(r, sv.iter().copied()) {
        return 0.0;
    }
    if quality == FormFactorQuality::Estimate {
        return point_polygon(r.center, r.normal, sv, s.normal);
    }
    let dist = (s.center - r.center).length();
    let separation = dist / (s.radius + r.radius).max(f64::MIN_POSITIVE);
    let far = separation >= FAR_SEPARATION || (quality == FormFactorQuality::Shape && separation >= NEAR_SEPARATION);
    let rule = match (rp.kind, far) {
        (PolyKind::Quad, true) => &quadrature::QUAD_4,
        (PolyKind::Quad, false) => &quadrature::QUAD_9,
        (PolyKind::Triangle, true) => &quadrature::TRI_3,
        (PolyKind::Triangle, false) => &quadrature::TRI_6,
    };
    if separation < NEAR_SEPARATION
        && wholly_in_front(rp.vertices(), sp.vertices(), s.normal, s.radius)
        && wholly_in_front(sv, rp.vertices(), r.normal, r.radius)
    {
        // Near pairs wholly in front of each other (touching walls included): Stokes' double
        // contour integral, exact up to 1e-11 and cheap where receiver quadrature struggles with
        // the log-singular derivatives at a shared edge.
        return polygon_polygon(rp.vertices(), sv);
    }
    if separation < NEAR_SEPARATION {
        // Other near pairs (one crosses the other's plane, or they interpenetrate, as leaves on a
        // twig do): only the part of each in front of the other's plane exchanges light, and those
        // parts are wholly in front of each other, so the contour integral of the clipped pair is
        // exact too. It replaces an adaptive receiver quadrature that cost up to 4⁴ rules per link.
        return clipped_contour(rp, r.normal, sv, s.normal);
    }
    rule_average(rp, r.normal, sv, s.normal, rule)
}

/// `F(receiver ← source)` of a near pair, one crossing the other's plane: the contour integral of
/// the receiver's part in front of the source's plane to the source's part in front of the
/// receiver's plane, scaled by the receiver's fraction in front.
fn clipped_contour(rp: &Poly, rn: DVec3, sv: &[DVec3], sn: DVec3) -> f64 {
    // A vertex on the clipping plane comes out twice up to rounding; the contour integral drops
    // the vanishing edge between the copies ([`super::contour::MIN_EDGE`]).
    let rv = rp.vertices();
    let mut rbuf = [DVec3::ZERO; MAX_CLIPPED];
    let mut sbuf = [DVec3::ZERO; MAX_CLIPPED];
    let nr = clip_to_halfspace(rv, sv[0], sn, &mut rbuf);
    let ns = clip_to_halfspace(sv, rv[0], rn, &mut sbuf);
    let area = rp.area();
    if nr < 3 || ns < 3 || area <= 0.0 {
        return 0.0;
    }
    let front_area = polygon_area(&rbuf[..nr]);
    polygon_polygon(&rbuf[..nr], &sbuf[..ns]) * (front_area / area)
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

/// Average over the receiver `rp` of the point-to-source form factor with a fixed rule
/// ([`quadrature::weighted_points`]).
fn rule_average(rp: &Poly, rn: DVec3, sv: &[DVec3], sn: DVec3, rule: &quadrature::Rule) -> f64 {
    let (mut f, mut wsum) = (0.0, 0.0);
    for (x, w) in quadrature::weighted_points(rp, rule) {
        f += w * point_polygon(x, rn, sv, sn);
        wsum += w;
    }
    if wsum > 0.0 { f / wsum } else { 0.0 }
}

/// Relative tolerance (times the plane element's radius) within which a point counts as on a
/// surface's plane in [`behind_surface`].
pub const ON_PLANE_REL_TOL: f64 = 1e-9;

/// Whether every one of `points` lies on or behind the plane of the surface element `plane`
/// (false for a cluster, unless all its polygons lie in one plane facing one way): the facing test of refinement
/// ([`crate::refine::LinkCtx::facing`]) and of [`link_form_factor`].
#[must_use]
pub fn behind_surface(plane: &Element, points: impl IntoIterator<Item = DVec3>) -> bool {
    let Some((origin, tol)) = plane_of(plane) else { return false };
    points.into_iter().all(|v| plane.normal.dot(v - origin) <= tol)
}

/// A point of element `plane`'s plane and how far off it a point may lie and still count as on
/// it; `None` for a cluster whose polygons do not share one plane facing one way.
fn plane_of(plane: &Element) -> Option<(DVec3, f64)> {
    let (origin, flatness) = match plane.poly() {
        // A quad is planar only up to the loaders' tolerance (its vertices as written, rounded
        // to a few decimals): a point counts as on its plane as long as it is no farther from it
        // than the quad's own vertices are, or a face's own back (the same vertices) would be
        // taken for a surface in front of it, at distance 0, and the two would exchange all their
        // light (a form factor clamped to 1 each way: light out of nothing).
        Some(p) => (p.v[0], p.vertices().iter().map(|&v| plane.normal.dot(v - p.v[0]).abs()).fold(0.0, f64::max)),
        // A flat cluster (all its polygons in one plane, one way) has its centre in that plane.
        None if plane.normal != DVec3::ZERO => (plane.center, 0.0),
        None => return None,
    };
    Some((origin, (ON_PLANE_REL_TOL * plane.radius).max(flatness)))
}

/// Whether surface elements `a` and `b` cross each other, as two leaves through each other do:
/// each reaches through the other's plane (vertices strictly on both sides of it, beyond the
/// tolerance of [`behind_surface`]) and an edge of one passes through the other. (For convex
/// polygons that straddle each other's planes, both cuts lie on the planes' common line, and they
/// overlap exactly when an edge of one meets the other.) False when either is a cluster.
#[must_use]
pub fn surfaces_cross(a: &Element, b: &Element) -> bool {
    let (Some(pa), Some(pb)) = (a.poly(), b.poly()) else { return false };
    // Whether `other`'s vertices lie strictly on both sides of `plane`'s plane.
    let straddles = |plane: &Element, other: &Poly| -> bool {
        let Some((o, tol)) = plane_of(plane) else { return false };
        let d = |v: &DVec3| plane.normal.dot(*v - o);
        other.vertices().iter().any(|v| d(v) > tol) && other.vertices().iter().any(|v| d(v) < -tol)
    };
    if !straddles(a, pb) || !straddles(b, pa) {
        return false;
    }
    // Whether an edge of `p` passes through the convex polygon `q` (normal `n`).
    let edge_through = |p: &Poly, q: &Poly, n: DVec3| -> bool {
        let (pv, qv) = (p.vertices(), q.vertices());
        let o = qv[0];
        (0..pv.len()).any(|i| {
            let (x0, x1) = (pv[i], pv[(i + 1) % pv.len()]);
            let (d0, d1) = (n.dot(x0 - o), n.dot(x1 - o));
            if (d0 > 0.0) == (d1 > 0.0) || d0 == d1 {
                return false;
            }
            let x = x0 + (x1 - x0) * (d0 / (d0 - d1));
            (0..qv.len()).all(|k| n.dot((qv[(k + 1) % qv.len()] - qv[k]).cross(x - qv[k])) >= 0.0)
        })
    };
    edge_through(pa, pb, b.normal) || edge_through(pb, pa, a.normal)
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
            let members = &h.cluster_members[poly_start as usize..poly_end as usize];
            if members.len() > CLUSTER_EXACT_MAX_POLYGONS {
                return 0.25 * e.area;
            }
            members.iter().map(|&(normal, area)| area * normal.dot(dir).max(0.0)).sum()
        }
    }
}

/// The point form factor `F(dx → source)` from a small receiver at `x` with unit normal `n` to the
/// element `source`: Lambert's formula for a surface (its front side only, clipped to `x`'s front
/// half-space); for a cluster, its members seen as a point source at its centre, radiating
/// `A_proj(dir) / π` per unit radiosity toward `x` (see [`projected_area`]).
#[must_use]
pub fn point_to_element(h: &Hierarchy, x: DVec3, n: DVec3, source: u32) -> f64 {
    let s = h.get(source);
    match s.poly() {
        Some(sp) => point_polygon(x, n, sp.vertices(), s.normal),
        None => {
            let d = x - s.center;
            let dist2 = d.length_squared();
            if dist2 <= 0.0 {
                return 0.0;
            }
            let dir = d / dist2.sqrt();
            (projected_area(h, s, dir) / PI * (-n.dot(dir)).max(0.0) / dist2).min(1.0)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Midpoint rule over an n×n grid of the receiver square `[x0,x1]×[0,1]` at z = 0 (normal +z)
    /// of the point-to-polygon formula (which clips the source per point): an independent route.
    fn brute(x0: f64, x1: f64, sv: &[DVec3], sn: DVec3) -> f64 {
        let n = 600;
        let mut acc = 0.0;
        for i in 0..n {
            for j in 0..n {
                let x = DVec3::new(x0 + (x1 - x0) * (i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64, 0.0);
                acc += point_polygon(x, DVec3::Z, sv, sn);
            }
        }
        acc / (n * n) as f64
    }

    #[test]
    fn crossing_and_interpenetrating_pairs_match_receiver_quadrature() {
        let r = Poly::quad(DVec3::new(0., 0., 0.), DVec3::new(1., 0., 0.), DVec3::new(1., 1., 0.), DVec3::new(0., 1., 0.));
        // A vertical square through the receiver at x = 0.5, facing −x, reaching below the floor:
        // only x < 0.5 of the receiver and z > 0 of the source exchange light.
        let s = [DVec3::new(0.5, 0., -0.5), DVec3::new(0.5, 0., 0.5), DVec3::new(0.5, 1., 0.5), DVec3::new(0.5, 1., -0.5)];
        let sn = -DVec3::X;
        let f = clipped_contour(&r, DVec3::Z, &s, sn);
        let g = brute(0.0, 0.5, &s, sn) * 0.5;
        assert!((f - g).abs() < 2e-4 * g, "clipped contour {f} vs quadrature {g}");
        // A tilted triangle crossing the receiver's plane, facing down and sideways.
        let tri = [DVec3::new(0.2, 0.1, 0.6), DVec3::new(0.9, 0.8, -0.3), DVec3::new(0.1, 0.9, 0.4)];
        let tn = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
        let f = clipped_contour(&r, DVec3::Z, &tri, tn);
        let g = brute(0.0, 1.0, &tri, tn);
        assert!(g > 1e-3, "the configuration exchanges light: {g}");
        assert!((f - g).abs() < 2e-3 * g, "clipped contour {f} vs quadrature {g}");
    }

    /// A face flush against a wall, back to back (same plane, opposite normals), exchanges nothing
    /// with it, and neither does a face behind another; a facing pair does. Before the facing test
    /// the contour integral returned its clamp, 1, for the back-to-back pair.
    #[test]
    fn back_to_back_and_behind_pairs_get_nothing() {
        use crate::scene::{Material, SceneBuilder};
        let mut b = SceneBuilder::new(std::path::Path::new("test"), "test");
        let m = b.material(Material::diffuse("grey", [0.5; 3])).unwrap();
        let g = b.group("g");
        let wall = [DVec3::new(0., 0., 0.), DVec3::new(2., 0., 0.), DVec3::new(2., 0., 2.), DVec3::new(0., 0., 2.)];
        // The wall faces +y; the flush face (wound the other way) faces −y, as do the others.
        let flush: Vec<DVec3> =
            [DVec3::new(0.5, 0., 0.5), DVec3::new(0.5, 0., 1.5), DVec3::new(1.5, 0., 1.5), DVec3::new(1.5, 0., 0.5)].to_vec();
        let facing: Vec<DVec3> =
            [DVec3::new(0.5, 1., 0.5), DVec3::new(0.5, 1., 1.5), DVec3::new(1.5, 1., 1.5), DVec3::new(1.5, 1., 0.5)].to_vec();
        let behind: Vec<DVec3> = facing.iter().map(|v| DVec3::new(v.x, -1.0, v.z)).collect();
        for poly in [&wall[..], &flush, &facing, &behind] {
            let reversed: Vec<DVec3> = poly.iter().rev().copied().collect();
            b.face(&reversed, m, g, 0).unwrap();
        }
        let scene = b.finish();
        let h = crate::hierarchy::build(&scene, &crate::hierarchy::BuildConfig::default());
        let n = |i: u32| h.get(i).normal;
        assert!(n(0).y > 0.99 && n(1).y < -0.99 && n(2).y < -0.99, "normals {} {} {}", n(0), n(1), n(2));
        for q in [FormFactorQuality::Estimate, FormFactorQuality::Precise] {
            assert_eq!(link_form_factor(&h, 0, 1, q), 0.0, "wall -> flush face");
            assert_eq!(link_form_factor(&h, 1, 0, q), 0.0, "flush face -> wall");
            assert_eq!(link_form_factor(&h, 0, 3, q), 0.0, "wall -> face behind it");
            assert!(link_form_factor(&h, 0, 2, q) > 0.05, "wall -> face in front of it");
        }
    }
}
