//! The link context itself: the two elements, their form factors, how near they are, the axis
//! between them, and the energy terms the criteria weigh.

use super::{CLUSTER_NEAR_FACTOR, CLUSTER_PROJECTED_FRACTION, Criterion, LinkAxis, LinkData, Services, source_kernel_spread};
use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::{Element, Hierarchy};

/// Everything an oracle sees of one link.
pub struct LinkCtx<'a> {
    /// Shared services.
    pub services: &'a Services<'a>,
    /// The emitter (source) element.
    pub emitter: u32,
    /// The receiver element.
    pub receiver: u32,
    /// Memoised terms.
    pub data: LinkData,
    /// Candidate occluders of the link this one was subdivided from (shaft culling).
    pub parent_candidates: Option<std::sync::Arc<[u32]>>,
    /// Memoised shaft classification and candidate list.
    pub shaft: Option<(crate::visibility::shaft::ShaftClass, std::sync::Arc<[u32]>)>,
}

/// What [`LinkCtx::fresh_visibility`] mixes into the seed, so that its segments are independent of
/// the ones an oracle decided on.
pub const FRESH_VISIBILITY_SALT: u64 = 0x5851_F42D_4C95_7F2D;

/// How many times [`LinkCtx::surfaces_cross`] has two crossing leaves quartered at least (both
/// pieces less deep than this below their polygons); below that the oracle's own criteria
/// decide.
pub const CROSSING_SPLIT_DEPTH: u16 = 2;

impl<'a> LinkCtx<'a> {
    /// A fresh context.
    #[must_use]
    pub fn new(services: &'a Services<'a>, emitter: u32, receiver: u32) -> LinkCtx<'a> {
        LinkCtx { services, emitter, receiver, data: LinkData::default(), parent_candidates: None, shaft: None }
    }

    /// The hierarchy.
    #[must_use]
    pub fn hierarchy(&self) -> &'a Hierarchy {
        self.services.hierarchy
    }

    /// The emitter element.
    #[must_use]
    pub fn emitter_element(&self) -> &'a Element {
        self.services.hierarchy.get(self.emitter)
    }

    /// The receiver element.
    #[must_use]
    pub fn receiver_element(&self) -> &'a Element {
        self.services.hierarchy.get(self.receiver)
    }

    /// The form factor at (at least) the given quality, computed once per quality level.
    pub fn form_factor(&mut self, quality: FormFactorQuality) -> f64 {
        if let Some((f, q)) = self.data.form_factor
            && q >= quality
        {
            return f;
        }
        let h = self.services.hierarchy;
        let f = match quality {
            FormFactorQuality::Estimate => formfactor::estimate(h, self.emitter, self.receiver),
            FormFactorQuality::Shape | FormFactorQuality::Precise => formfactor::link_form_factor(h, self.emitter, self.receiver, quality),
        };
        self.data.form_factor = Some((f, quality));
        f
    }

    /// Estimate of the largest point-to-emitter form factor over the receiver (memoised).
    pub fn form_factor_max(&mut self) -> f64 {
        if let Some(f) = self.data.form_factor_max {
            return f;
        }
        let f = formfactor::estimate_max(self.services.hierarchy, self.emitter, self.receiver);
        self.data.form_factor_max = Some(f);
        f
    }

    /// Whether a cluster is involved and the two elements are too near for the isotropic
    /// approximation: centre distance below `CLUSTER_NEAR_FACTOR` times the sum of the radii.
    #[must_use]
    pub fn clusters_too_near(&self) -> bool {
        let (s, r) = (self.emitter_element(), self.receiver_element());
        (s.is_cluster() || r.is_cluster()) && (s.center - r.center).length() < CLUSTER_NEAR_FACTOR * (s.radius + r.radius)
    }

    /// Whether the two are surfaces that cross each other ([`formfactor::surfaces_cross`]) with
    /// centres nearer than [`formfactor::NEAR_SEPARATION`] times the sum of their radii: leaves
    /// through leaves. The light they exchange gathers along the crossing line, where the kernel
    /// has no scale, and a link between them shares its transfer out over their pieces by the
    /// shape of its form factor alone: two crossing 10 cm leaves linked whole absorbed 1.1% less
    /// NIR than an independent photon tracer finds, an error no coarsening of the mesh shows.
    /// Only while both are less deep than [`CROSSING_SPLIT_DEPTH`] below their polygons: past
    /// that the oracle's own criteria subdivide the pieces along the line. Quartered once each, the
    /// two leaves absorb what they absorb split down to 1/4096 (to five digits), and a 3,200-leaf
    /// canopy's first level made 26 k leaves and 586 k links instead of 45 k and 710 k.
    #[must_use]
    pub fn surfaces_cross(&self) -> bool {
        let (s, r) = (self.emitter_element(), self.receiver_element());
        !s.is_cluster()
            && !r.is_cluster()
            && (s.center - r.center).length() < formfactor::NEAR_SEPARATION * (s.radius + r.radius)
            && self.below_polygon(s) < CROSSING_SPLIT_DEPTH
            && self.below_polygon(r) < CROSSING_SPLIT_DEPTH
            && formfactor::surfaces_cross(s, r)
    }

    /// How many times surface element `e` is quartered below its polygon (0 for a cluster).
    fn below_polygon(&self, e: &Element) -> u16 {
        let h = self.services.hierarchy;
        e.polygon().map_or(0, |p| e.depth.saturating_sub(h.get(p).depth))
    }

    /// Too near for a link: [`LinkCtx::clusters_too_near`] or [`LinkCtx::surfaces_cross`]; the
    /// pair is subdivided.
    #[must_use]
    pub fn too_near(&self) -> bool {
        self.clusters_too_near() || self.surfaces_cross()
    }

    /// Smallest and largest point-to-emitter form factor over the receiver, at the centre and near
    /// each corner (the probe points of [`formfactor::estimate_max`]); both equal the cluster
    /// estimate when a cluster is involved (memoised).
    pub fn form_factor_range(&mut self) -> (f64, f64) {
        if let Some(r) = self.data.form_factor_range {
            return r;
        }
        let (s, r) = (self.emitter_element(), self.receiver_element());
        let range = match (s.poly(), r.poly()) {
            (Some(sp), Some(rp)) => {
                let sv = sp.vertices();
                let f0 = formfactor::point_polygon(r.center, r.normal, sv, s.normal);
                let mut range = (f0, f0);
                for &v in rp.vertices() {
                    let x = v + formfactor::MAX_PROBE_PULL * (r.center - v);
                    let f = formfactor::point_polygon(x, r.normal, sv, s.normal);
                    range = (range.0.min(f), range.1.max(f));
                }
                range
            }
            _ => {
                let f = self.form_factor(FormFactorQuality::Estimate);
                (f, f)
            }
        };
        self.data.form_factor_range = Some(range);
        range
    }

    /// How strongly an uneven radiosity over the emitter shows in the receiver's mean irradiance:
    /// `F · κ`, the link's form factor times the spread `(max − min) / mean` of the point form
    /// factor from the emitter's probe points (centre, corners pulled in by
    /// [`formfactor::MAX_PROBE_PULL`]) to the receiver (at most [`MAX_SOURCE_KERNEL_VARIATION`](super::MAX_SOURCE_KERNEL_VARIATION)).
    /// By reciprocity `κ` is how unevenly the receiver, as a whole, weights the emitter's surface:
    /// near 0 for a far receiver, large for one touching the emitter. A radiosity varying by `ΔB`
    /// over the emitter then changes the receiver's mean irradiance by at most about
    /// `F · κ · ΔB / 4` (the covariance of kernel and radiosity). A cluster emitter, whose
    /// members' weights are not probed, gets `κ = MAX_SOURCE_KERNEL_VARIATION` (memoised).
    pub fn source_variation_weight(&mut self) -> f64 {
        if let Some(w) = self.data.source_variation_weight {
            return w;
        }
        let kappa = source_kernel_spread(self.services.hierarchy, self.emitter, self.receiver);
        let w = self.form_factor(FormFactorQuality::Precise) * kappa;
        self.data.source_variation_weight = Some(w);
        w
    }

    /// The centre-to-centre axis and the projected areas along it (memoised).
    pub fn axis(&mut self) -> LinkAxis {
        if let Some(a) = self.data.axis {
            return a;
        }
        let (s, r) = (self.emitter_element(), self.receiver_element());
        let d = r.center - s.center;
        let distance = d.length();
        let dir = d.normalize_or_zero();
        let projected = |e: &Element| {
            if e.is_cluster() { CLUSTER_PROJECTED_FRACTION * e.area } else { e.area * e.normal.dot(dir).abs() }
        };
        let a = LinkAxis { dir, distance, projected_emitter: projected(s), projected_receiver: projected(r) };
        self.data.axis = Some(a);
        a
    }

    /// Largest channel of the emitter's current radiosity.
    #[must_use]
    pub fn emitter_radiosity(&self) -> f64 {
        let b = self.services.data.radiosity[self.emitter as usize];
        b[0].max(b[1]).max(b[2])
    }

    /// How much the emitter's radiosity varies over it (largest channel of `max − min`, W/m²; see
    /// [`super::ElementData::variation`](crate::refine::ElementData::variation)).
    #[must_use]
    pub fn emitter_variation(&self) -> f64 {
        self.services.data.variation[self.emitter as usize]
    }

    /// The receiver's reflectance, largest channel (the area-weighted mean of a cluster's).
    #[must_use]
    pub fn receiver_reflectance(&self) -> f64 {
        let h = self.services.hierarchy;
        let rho = match self.receiver_element().polygon() {
            Some(p) => h.reflectance[p as usize],
            None => h.reflectance_of(self.receiver),
        };
        rho[0].max(rho[1]).max(rho[2])
    }

    /// How much an error in the distribution of the receiver's irradiance counts: its reflectance
    /// under [`Criterion::Radiosity`] (the light it passes on), 1 under [`Criterion::Irradiance`].
    #[must_use]
    pub fn receiver_weight(&self) -> f64 {
        match self.services.criterion {
            Criterion::Radiosity => self.receiver_reflectance(),
            Criterion::Irradiance => 1.0,
        }
    }

    /// The irradiance a relative threshold on this link is measured against: the receiver's own
    /// (its dimmest leaf's), at least the scene's floor ([`super::ElementData::reference`](crate::refine::ElementData::reference)).
    #[must_use]
    pub fn receiver_irradiance(&self) -> f64 {
        self.services.data.reference(self.receiver)
    }

    /// `eps` as an irradiance at the receiver: `eps` times the pass's scale times
    /// [`LinkCtx::receiver_irradiance`]. An error below it changes the receiver's irradiance (and
    /// radiosity) by less than that fraction, however dim the receiver is next to the brightest
    /// source: the same eps means the same relative accuracy on every surface.
    #[must_use]
    #[inline]
    pub fn threshold(&self, eps: f64) -> f64 {
        eps * self.services.threshold_scale * self.receiver_irradiance()
    }

    /// Whether the two elements can exchange light at all, judged from the planes of surfaces:
    /// false when the receiver lies entirely behind the emitter's plane or the other way round.
    #[must_use]
    pub fn facing(&self) -> bool {
        let (s, r) = (self.emitter_element(), self.receiver_element());
        let behind = |plane_el: &Element, other: &Element| -> bool {
            match other.poly() {
                Some(q) => formfactor::behind_surface(plane_el, q.vertices().iter().copied()),
                None => {
                    let b = &other.bounds;
                    formfactor::behind_surface(
                        plane_el,
                        (0..8).map(|c| {
                            crate::geom::DVec3::new(
                                if c & 1 == 0 { b.min.x } else { b.max.x },
                                if c & 2 == 0 { b.min.y } else { b.max.y },
                                if c & 4 == 0 { b.min.z } else { b.max.z },
                            )
                        }),
                    )
                }
            }
        };
        !behind(s, r) && !behind(r, s)
    }
}
