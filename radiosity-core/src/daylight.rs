//! Daylight: the sun and the sky as distant sources.
//!
//! A distant source is a field of parallel beams: a direction of travel and the irradiance it gives
//! a plane facing it, per channel ([`DistantSource`]). The **sun** is one such source, its
//! direction given or computed from a place and a time by the `spa` crate (the PSA algorithm,
//! 0.5 arc minute), its irradiance the direct normal irradiance. The **sky** is a set of them: the
//! upper hemisphere split into cells of equal solid angle ([`sky_cells`]: 46 or 145 cells, like
//! the "turtle" skies canopy models use, or any count from 1 up), each cell one source: its light
//! vector `∫ L ω dω` under the chosen radiance distribution ([`SkyModel`]: uniform, or the CIE
//! standard overcast sky `L(θ) ∝ (1 + 2 cos θ) / 3`), scaled so that the sky delivers the given
//! diffuse horizontal irradiance. A plane that sees a whole cell gets exactly that cell's light, so
//! the discretised sky gives an unobstructed horizontal plane the diffuse horizontal irradiance
//! exactly, whatever the cell count, and a vertical one within 1% (145 cells: 0.5% uniform, 0.6% overcast).
//!
//! Directions are in the scene's frame through a [`Site`]: which way is up and which is north
//! (default z up, y north, x east).
//!
//! Light enters the solve like the luminaires' (see [`crate::luminaire`]): each element's direct
//! irradiance, a shadow ray per quadrature point and source, becomes the emission `ρ·E` of the
//! radiosity system. Light that leaves the scene is measured after the solve ([`power_leaving`]):
//! the power balance of an open scene is `incident = absorbed + escaped`.

use crate::geom::DVec3;
use crate::hierarchy::NONE;
use crate::visibility::RayCaster;

pub use crate::light::DistantSource;

/// Where the sun is, as the scene file gave it or as computed.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SunReport {
    /// Unit direction the light travels.
    pub toward: [f64; 3],
    /// Zenith angle (degrees).
    pub zenith_deg: f64,
    /// Azimuth (degrees clockwise from north), when computed from place and time.
    pub azimuth_deg: Option<f64>,
    /// Whether it is above the horizon (below, it gives no light).
    pub above_horizon: bool,
}

/// Which way is up and which is north in the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Site {
    /// Unit zenith direction.
    pub up: DVec3,
    /// Unit direction of north, perpendicular to `up`.
    pub north: DVec3,
}

impl Default for Site {
    fn default() -> Site {
        Site { up: DVec3::Z, north: DVec3::Y }
    }
}

impl Site {
    /// A site from any non-parallel `up` and `north` (north is made perpendicular to up).
    pub fn new(up: DVec3, north: DVec3) -> Result<Site, DaylightError> {
        let up_len = up.length();
        if !up_len.is_finite() || up_len <= 0.0 {
            return Err(DaylightError(format!("`up` {up} is not a direction")));
        }
        let up = up / up_len;
        let north = north - up * up.dot(north);
        let n_len = north.length();
        if !n_len.is_finite() || n_len <= 1e-9 {
            return Err(DaylightError(format!("`north` {north} is not a direction across `up`")));
        }
        Ok(Site { up, north: north / n_len })
    }

    /// East: north × up.
    #[must_use]
    pub fn east(&self) -> DVec3 {
        self.north.cross(self.up)
    }

    /// A direction given in the site's frame (x east, y north, z up) in the scene's frame.
    #[must_use]
    pub fn world(&self, d: DVec3) -> DVec3 {
        self.east() * d.x + self.north * d.y + self.up * d.z
    }

    /// The unit direction toward a point of the sky at zenith angle `zenith` and azimuth
    /// `azimuth` (radians, clockwise from north seen from above: east is π/2).
    #[must_use]
    pub fn direction(&self, zenith: f64, azimuth: f64) -> DVec3 {
        let (sz, cz) = zenith.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        (self.east() * (sz * sa) + self.north * (sz * ca) + self.up * cz).normalize()
    }
}

/// A daylight input that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct DaylightError(pub String);

/// Where the sun is seen from a place at a time: `(zenith, azimuth)` in degrees (azimuth clockwise
/// from north), by the `spa` crate. `time` is RFC 3339 (`2026-06-21T12:00:00+02:00`).
pub fn sun_position(latitude: f64, longitude: f64, time: &str) -> Result<(f64, f64), DaylightError> {
    let t = chrono::DateTime::parse_from_rfc3339(time)
        .map_err(|e| DaylightError(format!("time `{time}` is not RFC 3339 ({e}), e.g. 2026-06-21T12:00:00+02:00")))?;
    if !(-90.0..=90.0).contains(&latitude) || !(-180.0..=180.0).contains(&longitude) {
        return Err(DaylightError(format!("latitude {latitude} / longitude {longitude} out of range (-90..90, -180..180 degrees)")));
    }
    let pos = spa::solar_position::<spa::StdFloatOps>(t.with_timezone(&chrono::Utc), latitude, longitude)
        .map_err(|e| DaylightError(format!("solar position: {e:?}")))?;
    Ok((pos.zenith_angle, pos.azimuth))
}

/// The sun as a distant source: light traveling along `toward`, `direct_normal` on a plane facing
/// it. A sun at or below the horizon (`toward` not downward) gives no source.
pub fn sun(toward: DVec3, direct_normal: [f64; 3], site: &Site) -> Result<Option<DistantSource>, DaylightError> {
    let len = toward.length();
    if !len.is_finite() || len <= 0.0 {
        return Err(DaylightError(format!("sun direction {toward} is not a direction")));
    }
    check_levels("direct_normal", &direct_normal)?;
    let toward = toward / len;
    Ok((toward.dot(site.up) < 0.0).then_some(DistantSource { toward, irradiance: direct_normal, sharp: true }))
}

/// Radiance distribution of the sky over its hemisphere.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SkyModel {
    /// The same radiance everywhere.
    Uniform,
    /// CIE standard overcast sky: `L(θ) = L_z (1 + 2 cos θ) / 3`.
    CieOvercast,
}

impl SkyModel {
    /// `∫ L(μ) μ dμ` (k = 1) or `∫ L(μ) √(1 − μ²) dμ` (k = 2) from 0 to `mu` (μ = cos θ, L
    /// relative to the zenith's): the vertical and horizontal parts of a ring's light vector.
    fn moment(self, mu: f64, k: u32) -> f64 {
        let root = (1.0 - mu * mu).max(0.0).sqrt();
        let half_disc = 0.5 * (mu * root + mu.clamp(-1.0, 1.0).asin());
        match (self, k) {
            (SkyModel::Uniform, 1) => mu * mu / 2.0,
            (SkyModel::Uniform, _) => half_disc,
            (SkyModel::CieOvercast, 1) => (mu * mu / 2.0 + 2.0 * mu.powi(3) / 3.0) / 3.0,
            (SkyModel::CieOvercast, _) => (half_disc + 2.0 * (1.0 - root.powi(3)) / 3.0) / 3.0,
        }
    }
}

/// One cell of the sky's hemisphere: cos θ from `mu_low` to `mu_high`, azimuth from `phi_start`
/// over `phi_width` (radians, clockwise from north).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyCell {
    /// cos θ at the cell's lower (horizon-side) edge.
    pub mu_low: f64,
    /// cos θ at its upper edge (1 for the zenith cap).
    pub mu_high: f64,
    /// Azimuth where the cell starts.
    pub phi_start: f64,
    /// Azimuth width (2π for the zenith cap).
    pub phi_width: f64,
}

/// Rings of the 46-cell sky, zenith first (cells per ring).
pub const RINGS_46: [u32; 5] = [1, 5, 10, 15, 15];
/// Rings of the 145-cell sky, zenith first.
pub const RINGS_145: [u32; 7] = [1, 8, 16, 24, 32, 32, 32];

/// The upper hemisphere split into `n` cells of equal solid angle (2π/n each), in rings about the
/// zenith: 46 and 145 use [`RINGS_46`] and [`RINGS_145`] (cells near square); other counts use
/// rings of 1, 8, 16, 24, ... cells, the last ring taking what is left.
pub fn sky_cells(n: u32) -> Result<Vec<SkyCell>, DaylightError> {
    if n == 0 || n > 100_000 {
        return Err(DaylightError(format!("sky directions {n}: give 1 to 100000 (46 or 145 are the usual)")));
    }
    let rings: Vec<u32> = match n {
        46 => RINGS_46.to_vec(),
        145 => RINGS_145.to_vec(),
        _ => {
            let mut rings = vec![1];
            let mut total = 1;
            let mut k = 1;
            while total < n {
                let c = (8 * k).min(n - total);
                rings.push(c);
                total += c;
                k += 1;
            }
            rings
        }
    };
    let mut cells = Vec::with_capacity(n as usize);
    let mut done = 0u32;
    for (r, &count) in rings.iter().enumerate() {
        let mu_high = 1.0 - f64::from(done) / f64::from(n);
        done += count;
        let mu_low = if done == n { 0.0 } else { 1.0 - f64::from(done) / f64::from(n) };
        let width = std::f64::consts::TAU / f64::from(count);
        // Alternate rings are staggered by half a cell.
        let offset = if r % 2 == 0 { 0.0 } else { 0.5 * width };
        for i in 0..count {
            cells.push(SkyCell { mu_low, mu_high, phi_start: offset + width * f64::from(i), phi_width: width });
        }
    }
    Ok(cells)
}

/// The sky as `n` distant sources (see [`sky_cells`]) under `model`, delivering
/// `diffuse_horizontal` (W/m² per channel) to an unobstructed horizontal plane.
pub fn sky(model: SkyModel, diffuse_horizontal: [f64; 3], n: u32, site: &Site) -> Result<Vec<DistantSource>, DaylightError> {
    check_levels("diffuse_horizontal", &diffuse_horizontal)?;
    let cells = sky_cells(n)?;
    let weights: Vec<f64> = cells.iter().map(|c| c.phi_width * (model.moment(c.mu_high, 1) - model.moment(c.mu_low, 1))).collect();
    let total: f64 = weights.iter().sum();
    Ok(cells
        .iter()
        .zip(&weights)
        .map(|(c, &w)| {
            // The cell's light vector ∫ L ω dω: its vertical part is `w`, its horizontal part
            // points to the cell's middle azimuth. A plane that sees the whole cell receives
            // exactly the vector's projection on its normal.
            let horizontal = 2.0 * (0.5 * c.phi_width).sin() * (model.moment(c.mu_high, 2) - model.moment(c.mu_low, 2));
            let magnitude = w.hypot(horizontal);
            let zenith = horizontal.atan2(w);
            let azimuth = c.phi_start + 0.5 * c.phi_width;
            let toward = -site.direction(zenith, azimuth);
            let scale = magnitude / total;
            DistantSource { toward, irradiance: diffuse_horizontal.map(|e| e * scale), sharp: false }
        })
        .collect())
}

fn check_levels(what: &str, v: &[f64; 3]) -> Result<(), DaylightError> {
    if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
        return Err(DaylightError(format!("`{what}` {v:?} must be finite and non-negative")));
    }
    Ok(())
}

/// Shadow rays toward distant sources run this far (relative to the scene's diagonal) from the
/// receiver: past every surface of the scene.
pub const FAR_REL: f64 = 4.0;

/// Sees the distant sources from points: irradiance with one shadow ray per source.
pub struct DistantLight<'a> {
    sources: &'a [DistantSource],
    caster: Option<&'a RayCaster>,
    offset: f64,
}

impl<'a> DistantLight<'a> {
    /// The sources seen.
    #[must_use]
    pub fn sources(&self) -> &'a [DistantSource] {
        self.sources
    }

    /// `caster` `None`: no occlusion.
    #[must_use]
    pub fn new(sources: &'a [DistantSource], caster: Option<&'a RayCaster>, scene_diagonal: f64) -> DistantLight<'a> {
        DistantLight { sources, caster, offset: crate::visibility::SHADOW_ORIGIN_OFFSET_REL * scene_diagonal }
    }

    /// Whether a ray from `x` (normal `n`, on polygon `skip`) against the light of source `k`
    /// leaves the scene, and the unoccluded irradiance it would bring.
    #[must_use]
    pub fn from_one(&self, k: usize, x: DVec3, n: DVec3, skip: u32) -> ([f64; 3], bool) {
        let s = &self.sources[k];
        let e = s.on(n);
        if e.iter().all(|&v| v <= 0.0) {
            return ([0.0; 3], false);
        }
        match self.caster {
            Some(caster) if !caster.ray_clear_skipping(x + self.offset * n, -s.toward, skip) => ([0.0; 3], true),
            _ => (e, false),
        }
    }

    /// Irradiance at `x` (normal `n`) from every source.
    #[must_use]
    pub fn at(&self, x: DVec3, n: DVec3, skip: u32) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for k in 0..self.sources.len() {
            let (e, _) = self.from_one(k, x, n, skip);
            for c in 0..3 {
                sum[c] += e[c];
            }
        }
        sum
    }
}

/// Cells of the hemisphere about a surface's normal through which [`power_leaving`] looks.
pub const ESCAPE_CELLS: u32 = 145;

/// The [`ESCAPE_CELLS`] directions of a hemisphere about +z with their cosine weights (summing to
/// 1), for [`power_leaving`].
#[must_use]
pub fn escape_cells() -> Vec<(DVec3, f64)> {
    let site = Site::default();
    let sources = sky(SkyModel::Uniform, [1.0; 3], ESCAPE_CELLS, &site).expect("a valid cell count");
    sources.iter().map(|s| (-s.toward, s.irradiance[0] * (-s.toward.z))).map(|(d, w)| (DVec3::new(d.x, d.y, d.z), w)).collect()
}

/// Power (per channel) that the distant sources deliver to the surfaces: `Σ A·E_direct` over the
/// leaves. Equal to what they bring in when nothing else lights the scene directly (no
/// luminaires: a scene file refuses both).
#[must_use]
pub fn power_incident(h: &crate::hierarchy::Hierarchy) -> [f64; 3] {
    let mut sum = [0.0; 3];
    if h.direct.is_empty() {
        return sum;
    }
    for leaf in h.leaves() {
        let e = h.get(leaf);
        if e.polygon().is_some() {
            for c in 0..3 {
                sum[c] += e.area * h.direct[leaf as usize][c];
            }
        }
    }
    sum
}

/// Gives a back (the reversed face, right after it, same material) to every one-sided face of an
/// open mesh whose back can receive light under the scene's distant sources: a source shines on
/// that side, or one of the [`ESCAPE_CELLS`] rays from its centre across that side meets a
/// surface. Leaves are two-sided the way Radiance and CARIBU treat surfaces: a canopy of single
/// faces would otherwise block the light reaching their backs and lose it (46% less absorbed by
/// opaque leaves written as one quad each). Faces of closed meshes, faces with a back, emitters,
/// materials declared either way (`two_sided`), and faces whose backs see nothing (a ground plane's
/// underside) stay as they are. Does nothing without distant sources. Returns how many backs
/// were added (also counted in [`crate::scene::SceneWarnings::two_sided_by_default`]).
pub fn two_sided_where_backs_see_light(scene: &mut crate::scene::Scene) -> usize {
    use rayon::prelude::*;
    if scene.distant.is_empty() || scene.polygons.is_empty() {
        return 0;
    }
    let polys: Vec<crate::geom::Poly> = scene.polygons.iter().map(|p| p.poly).collect();
    let n = polys.len();
    let open = crate::geom::open_mesh_faces(&polys);
    let has_back = |i: usize| (i > 0 && polys[i - 1].is_back_of(&polys[i])) || (i + 1 < n && polys[i + 1].is_back_of(&polys[i]));
    let candidates: Vec<usize> = (0..n)
        .filter(|&i| {
            let m = scene.material_of(i);
            open[i] && !m.two_sided && !m.one_sided && !m.is_emitter() && !has_back(i)
        })
        .collect();
    if candidates.is_empty() {
        return 0;
    }
    let caster = RayCaster::new(scene);
    let cells = escape_cells();
    let offset = crate::visibility::SHADOW_ORIGIN_OFFSET_REL * scene.bounds().diagonal();
    let lit: Vec<bool> = candidates
        .par_iter()
        .map(|&i| {
            let back = -polys[i].normal();
            if scene.distant.iter().any(|s| s.on(back).iter().any(|&v| v > 0.0)) {
                return true;
            }
            let frame = Site::new(back, any_perpendicular(back)).unwrap_or_default();
            let origin = polys[i].centroid() + offset * back;
            cells.iter().any(|(d, _)| {
                let dir = frame.world(*d);
                caster.closest_hit_where(origin, dir, |q| q != i as u32).is_some()
            })
        })
        .collect();
    let mut given = vec![false; n];
    for (&i, &l) in candidates.iter().zip(&lit) {
        given[i] = l;
    }
    let added = given.iter().filter(|&&g| g).count();
    if added > 0 {
        let old = std::mem::take(&mut scene.polygons);
        for (i, p) in old.into_iter().enumerate() {
            let back = given[i].then(|| crate::scene::Polygon { poly: p.poly.reversed(), ..p.clone() });
            scene.polygons.push(p);
            scene.polygons.extend(back);
        }
        scene.warnings.two_sided_by_default += added;
    }
    added
}

/// Whether each polygon of `h` has an open back: one-sided (no back next to it, see
/// [`crate::scene::Scene::pair_two_sided`]), so light reaching its back is blocked and lost, and
/// not part of a closed mesh (every edge of its edge-connected faces shared by two of them, as
/// a box's are), whose inside no light can reach. Light the solve puts on the backs of a closed
/// mesh (a coarse element of the ground, half under a box, sending its mean radiosity from under
/// it) is an error of the discretisation, left to show in the balance; light on an open back (a
/// one-sided leaf) is lost for real, and counted.
#[must_use]
pub fn open_backs(h: &crate::hierarchy::Hierarchy) -> Vec<bool> {
    let polys: Vec<crate::geom::Poly> = (0..h.n_polygons).filter_map(|p| h.get(p).poly().copied()).collect();
    if polys.len() != h.n_polygons as usize {
        return vec![false; h.n_polygons as usize];
    }
    let open = crate::geom::open_mesh_faces(&polys);
    (0..h.n_polygons).map(|p| open[p as usize] && crate::visibility::back_of(h, p).is_none()).collect()
}

/// Where the light leaving the surfaces goes besides the links, per channel (W): out of the scene,
/// or onto an open back (see [`open_backs`]: blocked there, and lost), with that loss per polygon.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Leaving {
    /// Leaving the scene.
    pub escaped: [f64; 3],
    /// Landing on the back of a one-sided face.
    pub onto_backs: [f64; 3],
    /// [`Leaving::onto_backs`] per polygon whose back it lands on, summed over channels (empty
    /// when nothing lands on a back).
    pub onto_backs_by_polygon: Vec<f64>,
}

/// Power (per channel) that leaves the scene: every surface leaf's `B·A` times the cosine-weighted
/// share of the [`ESCAPE_CELLS`] cells of its hemisphere whose central ray hits nothing, the cells
/// shared out over the leaf's quadrature points in turn; and the power those cells' rays carry onto an open back (the closest
/// hit's back, when `open_back` of its polygon, as [`open_backs`] gives it). Independent of the links, so that
/// `absorbed + escaped + lost = incident + emitted` checks the solve.
#[must_use]
pub fn power_leaving(h: &crate::hierarchy::Hierarchy, radiosity: &[[f64; 3]], caster: &RayCaster, open_back: &[bool]) -> Leaving {
    use rayon::prelude::*;
    let cells = escape_cells();
    let diag = h.diagonal();
    let offset = crate::visibility::SHADOW_ORIGIN_OFFSET_REL * diag;
    let far = FAR_REL * diag;
    let any_open_back = open_back.iter().any(|&o| o);
    let leaves: Vec<u32> = h.leaves().filter(|&l| h.get(l).polygon().is_some()).collect();
    type PerLeaf = ([f64; 3], [f64; 3], Vec<(u32, f64)>);
    let per_leaf: Vec<PerLeaf> = leaves
        .par_iter()
        .map(|&leaf| {
            let e = h.get(leaf);
            let b = radiosity[leaf as usize];
            if b.iter().all(|&v| v <= 0.0) {
                return ([0.0; 3], [0.0; 3], Vec::new());
            }
            let (Some(poly), Some(polygon)) = (e.poly(), e.polygon()) else { return ([0.0; 3], [0.0; 3], Vec::new()) };
            let points: Vec<DVec3> =
                crate::geom::quadrature::weighted_points(poly, crate::geom::quadrature::element_rule(poly)).map(|(x, _)| x).collect();
            let frame = Site::new(e.normal, any_perpendicular(e.normal)).unwrap_or_default();
            let (mut out, mut backs) = (0.0, Vec::new());
            for (k, (d, w)) in cells.iter().enumerate() {
                let origin = points[k % points.len()] + offset * e.normal;
                let dir = frame.world(*d);
                if caster.segment_clear(origin, origin + dir * far, polygon, NONE) {
                    out += w;
                } else if any_open_back
                    && let Some((_, q)) = caster.closest_hit_where(origin, dir, |q| q != polygon)
                    && open_back[q as usize]
                    && h.get(q).normal.dot(dir) > 0.0
                {
                    backs.push((q, *w));
                }
            }
            let scale = b.map(|v| v * e.area);
            let onto: f64 = backs.iter().map(|(_, w)| w).sum();
            let total: f64 = scale.iter().sum();
            (scale.map(|v| v * out), scale.map(|v| v * onto), backs.into_iter().map(|(q, w)| (q, w * total)).collect())
        })
        .collect();
    // Summed in leaf order: the same figure on every run.
    let mut leaving = Leaving::default();
    for (esc, onto, by) in per_leaf {
        for c in 0..3 {
            leaving.escaped[c] += esc[c];
            leaving.onto_backs[c] += onto[c];
        }
        for (q, v) in by {
            if leaving.onto_backs_by_polygon.is_empty() {
                leaving.onto_backs_by_polygon = vec![0.0; h.n_polygons as usize];
            }
            leaving.onto_backs_by_polygon[q as usize] += v;
        }
    }
    leaving
}

/// Power (per channel) that the distant sources deliver to open backs ([`open_backs`]; `Σ A·E`
/// over their leaves, a shadow ray per quadrature point and source from the back), blocked there
/// and lost; and that power per polygon, summed over channels (empty when none).
#[must_use]
pub fn power_incident_on_backs(
    h: &crate::hierarchy::Hierarchy,
    distant: &[DistantSource],
    caster: &RayCaster,
    open_back: &[bool],
) -> ([f64; 3], Vec<f64>) {
    use rayon::prelude::*;
    if distant.is_empty() || !open_back.iter().any(|&o| o) {
        return ([0.0; 3], Vec::new());
    }
    let light = DistantLight::new(distant, Some(caster), h.diagonal());
    let leaves: Vec<u32> = h
        .leaves()
        .filter(|&l| {
            let e = h.get(l);
            e.polygon().is_some_and(|p| open_back[p as usize]) && distant.iter().any(|s| s.on(-e.normal).iter().any(|&v| v > 0.0))
        })
        .collect();
    let per_leaf: Vec<(u32, [f64; 3])> = leaves
        .par_iter()
        .map(|&leaf| {
            let e = h.get(leaf);
            let (Some(poly), Some(polygon)) = (e.poly(), e.polygon()) else { return (0, [0.0; 3]) };
            (polygon, crate::geom::quadrature::element_mean3(poly, |x| light.at(x, -e.normal, polygon)).map(|v| v * e.area))
        })
        .collect();
    let (mut total, mut by) = ([0.0; 3], Vec::new());
    for (p, v) in per_leaf {
        if v.iter().all(|&x| x <= 0.0) {
            continue;
        }
        if by.is_empty() {
            by = vec![0.0; h.n_polygons as usize];
        }
        by[p as usize] += v.iter().sum::<f64>();
        for c in 0..3 {
            total[c] += v[c];
        }
    }
    (total, by)
}

/// The light of a daylight solve measured apart from the links, per channel (W): what the sun and
/// sky bring to either side of the surfaces, what leaves the scene, what lands on open backs
/// ([`open_backs`]: from the sources and from the surfaces), and that loss per polygon (summed
/// over channels; empty when none).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutsideLinks {
    /// Onto the surfaces from the distant sources, fronts and open backs.
    pub incident: [f64; 3],
    /// Out of the scene.
    pub escaped: [f64; 3],
    /// Onto open backs, blocked and lost.
    pub lost_at_backs: [f64; 3],
    /// [`OutsideLinks::lost_at_backs`] per polygon.
    pub lost_by_polygon: Vec<f64>,
}

/// [`OutsideLinks`] of a solution: [`power_incident`], [`power_incident_on_backs`] and
/// [`power_leaving`] together.
#[must_use]
pub fn outside_links(
    h: &crate::hierarchy::Hierarchy,
    distant: &[DistantSource],
    radiosity: &[[f64; 3]],
    caster: &RayCaster,
) -> OutsideLinks {
    let open_back = open_backs(h);
    let front = power_incident(h);
    let (on_backs, on_backs_by) = power_incident_on_backs(h, distant, caster, &open_back);
    let leaving = power_leaving(h, radiosity, caster, &open_back);
    let lost_by_polygon = match (on_backs_by.is_empty(), leaving.onto_backs_by_polygon.is_empty()) {
        (true, _) => leaving.onto_backs_by_polygon,
        (false, true) => on_backs_by,
        (false, false) => on_backs_by.iter().zip(&leaving.onto_backs_by_polygon).map(|(a, b)| a + b).collect(),
    };
    OutsideLinks {
        incident: std::array::from_fn(|c| front[c] + on_backs[c]),
        escaped: leaving.escaped,
        lost_at_backs: std::array::from_fn(|c| leaving.onto_backs[c] + on_backs[c]),
        lost_by_polygon,
    }
}

/// How far the power balance of a solve is from closing (see
/// [`crate::pipeline::LevelReport::balance_gap`]): `solution.irradiance` is what the links bring,
/// without the direct light. Light landing on the back of a one-sided face (from the sources or
/// the surfaces) counts as incident and lost, as in `stats.json`.
#[must_use]
pub fn balance_gap(
    h: &crate::hierarchy::Hierarchy,
    distant: &[DistantSource],
    solution: &crate::solve::Solution,
    caster: &RayCaster,
) -> f64 {
    let outside = outside_links(h, distant, &solution.radiosity, caster);
    let incident = outside.incident;
    let escaped: [f64; 3] = std::array::from_fn(|c| outside.escaped[c] + outside.lost_at_backs[c]);
    let (mut absorbed, mut emitted) = ([0.0; 3], [0.0; 3]);
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let Some(p) = e.polygon() else { continue };
        let p = p as usize;
        let direct = h.direct.get(leaf as usize).copied().unwrap_or_default();
        for c in 0..3 {
            absorbed[c] +=
                e.area * (1.0 - h.reflectance[p][c] - h.transmittance[p][c]) * (solution.irradiance[leaf as usize][c] + direct[c]);
            emitted[c] += e.area * h.emission[p][c];
        }
    }
    (0..3)
        .filter(|&c| incident[c] + emitted[c] > 0.0)
        .map(|c| ((absorbed[c] + escaped[c]) - (incident[c] + emitted[c])).abs() / (incident[c] + emitted[c]))
        .fold(0.0, f64::max)
}

fn any_perpendicular(n: DVec3) -> DVec3 {
    if n.x.abs() < 0.9 { DVec3::X.cross(n) } else { DVec3::Y.cross(n) }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOL: f64 = 1e-12;

    /// A closed box's faces have no open back (nothing reaches their insides); a lone face has;
    /// a face with its back written after it has none (the back reflects).
    #[test]
    fn open_backs_are_one_sided_faces_of_open_meshes() {
        use crate::scene::{Material, SceneBuilder};
        let mut b = SceneBuilder::new(std::path::Path::new("test"), "test");
        let m = b.material(Material::diffuse("grey", [0.5; 3])).unwrap();
        let mut two = Material::diffuse("leaf", [0.4; 3]);
        two.two_sided = true;
        let leaf = b.material(two).unwrap();
        let g = b.group("g");
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        // A unit cube, faces outward.
        let cube = [
            [c(0., 0., 0.), c(0., 1., 0.), c(1., 1., 0.), c(1., 0., 0.)],
            [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
            [c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.)],
            [c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)],
            [c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
        ];
        for f in &cube {
            b.face(f, m, g, 0).unwrap();
        }
        let lone = [c(3., 0., 1.), c(4., 0., 1.), c(4., 1., 1.), c(3., 1., 1.)];
        b.face(&lone, m, g, 0).unwrap();
        b.face(&lone.map(|v| v + DVec3::Z), leaf, g, 0).unwrap();
        let mut scene = b.finish();
        scene.pair_two_sided();
        let h = crate::hierarchy::build(&scene, &crate::hierarchy::BuildConfig::default());
        let open = open_backs(&h);
        assert_eq!(open, [vec![false; 6], vec![true], vec![false, false]].concat());
    }

    #[test]
    fn cells_have_equal_solid_angle_and_cover_the_hemisphere() {
        for n in [1, 7, 46, 145, 500] {
            let cells = sky_cells(n).unwrap();
            assert_eq!(cells.len(), n as usize);
            let total: f64 = cells.iter().map(|c| c.phi_width * (c.mu_high - c.mu_low)).sum();
            assert!((total - std::f64::consts::TAU).abs() < 1e-9, "{n}: {total}");
            for c in &cells {
                let omega = c.phi_width * (c.mu_high - c.mu_low);
                assert!((omega - std::f64::consts::TAU / f64::from(n)).abs() < 1e-9, "{n}: {omega}");
            }
        }
        assert!(sky_cells(0).is_err());
    }

    #[test]
    fn sky_delivers_the_diffuse_horizontal_irradiance_to_a_horizontal_plane() {
        let site = Site::default();
        for model in [SkyModel::Uniform, SkyModel::CieOvercast] {
            for n in [46, 145] {
                let s = sky(model, [100.0, 50.0, 0.0], n, &site).unwrap();
                let h: f64 = s.iter().map(|b| b.on(DVec3::Z)[0]).sum();
                assert!((h - 100.0).abs() < 1e-9, "{model:?} {n}: {h}");
                // Nothing reaches a plane facing down.
                assert!(s.iter().all(|b| b.on(-DVec3::Z) == [0.0; 3]));
            }
        }
    }

    #[test]
    fn vertical_plane_gets_half_the_uniform_sky_and_less_of_the_overcast() {
        // Uniform sky: a vertical plane sees half the sky's hemisphere: E_v = E_h / 2 exactly in
        // the continuum; the 145-cell sky within 0.5%. CIE overcast: E_v / E_h = 0.396 (the
        // integral of (1 + 2 cos θ)/3 against the vertical plane's cosine, over the
        // horizontal's, by a fine midpoint rule below).
        let site = Site::default();
        let uni = sky(SkyModel::Uniform, [1.0; 3], 145, &site).unwrap();
        let v: f64 = uni.iter().map(|b| b.on(DVec3::X)[0]).sum();
        assert!((v - 0.5).abs() < 0.0025, "uniform vertical {v}");
        let ov = sky(SkyModel::CieOvercast, [1.0; 3], 145, &site).unwrap();
        let v: f64 = ov.iter().map(|b| b.on(DVec3::X)[0]).sum();
        let exact = vertical_over_horizontal_overcast();
        assert!((v - exact).abs() < 0.01 * exact, "overcast vertical {v} vs {exact}");
    }

    /// E_v / E_h of the CIE overcast sky by a fine midpoint rule.
    fn vertical_over_horizontal_overcast() -> f64 {
        let (nt, np) = (2000, 2000);
        let (mut ev, mut eh) = (0.0, 0.0);
        for i in 0..nt {
            let th = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
            let l = (1.0 + 2.0 * th.cos()) / 3.0;
            let dth = std::f64::consts::FRAC_PI_2 / nt as f64;
            eh += l * th.cos() * th.sin() * dth * std::f64::consts::TAU;
            for j in 0..np {
                let ph = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
                let c = th.sin() * ph.cos();
                if c > 0.0 {
                    ev += l * c * th.sin() * dth * std::f64::consts::TAU / np as f64;
                }
            }
        }
        ev / eh
    }

    #[test]
    fn sun_position_at_a_known_place_and_time() {
        // Equinox noon at the equator on the Greenwich meridian: the sun is near the zenith
        // (declination ~0, equation of time ~ -7 min on 2026-03-20: within 3 degrees).
        let (z, _) = sun_position(0.0, 0.0, "2026-03-20T12:00:00Z").unwrap();
        assert!(z < 3.0, "zenith {z}");
        // Summer solstice solar noon at 45 N: zenith = 45 - 23.44 = 21.56 degrees, due south.
        let (z, a) = sun_position(45.0, 0.0, "2026-06-21T12:02:00Z").unwrap();
        assert!((z - 21.56).abs() < 0.3, "zenith {z}");
        assert!((a - 180.0).abs() < 2.0, "azimuth {a}");
        assert!(sun_position(0.0, 0.0, "noon").is_err());
        assert!(sun_position(95.0, 0.0, "2026-03-20T12:00:00Z").is_err());
    }

    #[test]
    fn site_directions() {
        let s = Site::default();
        assert!((s.direction(0.0, 0.0) - DVec3::Z).length() < TOL);
        assert!((s.direction(std::f64::consts::FRAC_PI_2, 0.0) - DVec3::Y).length() < TOL);
        assert!((s.direction(std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2) - DVec3::X).length() < TOL);
        let y_up = Site::new(DVec3::Y, DVec3::NEG_Z).unwrap();
        assert!((y_up.direction(0.0, 1.0) - DVec3::Y).length() < TOL);
        assert!(Site::new(DVec3::Z, DVec3::Z).is_err());
        // A sun below the horizon gives no source.
        assert!(sun(DVec3::Z, [1.0; 3], &s).unwrap().is_none());
        assert!(sun(-DVec3::Z, [f64::NAN; 3], &s).is_err());
    }

    #[test]
    fn escape_cells_are_cosine_weights() {
        let cells = escape_cells();
        let total: f64 = cells.iter().map(|c| c.1).sum();
        assert!((total - 1.0).abs() < 1e-9);
        assert!(cells.iter().all(|(d, _)| d.z > 0.0 && (d.length() - 1.0).abs() < 1e-9));
    }
}
