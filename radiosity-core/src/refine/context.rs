//! The link context an oracle reads: the two elements, shared services, and memoised link terms.

use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::{Element, Hierarchy};
use crate::visibility::{RayCaster, VisibilityConfig};

/// What the link criteria bound the error of, at each receiver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Criterion {
    /// The radiosity `B = E + ρ·H`: how a shadow falls within a receiver counts in proportion to
    /// its reflectance, so a black receiver's irradiance is never refined for a shadow.
    Radiosity,
    /// The irradiance `H`, whatever the receiver's reflectance: a black sensor's penumbra is
    /// refined like a white wall's (lux and absorbed power follow from `H`). The default.
    #[default]
    Irradiance,
}

impl Criterion {
    /// Every criterion, in the order the CLI lists them.
    pub const ALL: [Criterion; 2] = [Criterion::Radiosity, Criterion::Irradiance];

    /// The name the CLI and `stats.json` use.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Criterion::Radiosity => "radiosity",
            Criterion::Irradiance => "irradiance",
        }
    }

    /// The criterion named `name`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Criterion> {
        Criterion::ALL.into_iter().find(|c| c.name() == name)
    }

    /// How many segments the visibility a new link keeps is sampled with, for `--rays` `rays`:
    /// `rays`, or [`KEPT_VISIBILITY_FACTOR`] times as many under the irradiance criterion
    /// ([`LinkCtx::fresh_visibility`]), except for a link of reflected light that the oracle kept
    /// without drawing any ([`Services::reflected_rays`]). Each link records its count
    /// ([`crate::refine::Link::rays`]) for the error estimate's visibility noise.
    #[must_use]
    pub fn kept_rays(self, rays: u32) -> u32 {
        match self {
            Criterion::Radiosity => rays,
            Criterion::Irradiance => rays.saturating_mul(KEPT_VISIBILITY_FACTOR),
        }
    }
}

/// Under [`Criterion::Irradiance`], how many times `--rays` segments the visibility kept for a new
/// link is sampled with ([`LinkCtx::fresh_visibility`]; but see [`Services::reflected_rays`]).
/// CIE 171 case 5.7's black sensors at
/// `--eps 0.01`, seeds 1–3, worst error: a fresh sample of `--rays` segments 1.6–3.6%, of 4 times
/// as many 0.41–0.55% (17–23k links, 0.2 s); more rays for the oracle's own decision (up to 16
/// times, where the estimate's error was over half the threshold) doubled the links and changed
/// nothing.
pub const KEPT_VISIBILITY_FACTOR: u32 = 4;

/// The largest fraction of a link an occluder can hide (or a gap can open) while `n` segments
/// all miss it, about one time in twenty: `UNSEEN_FRACTION / n` (the rule of three).
pub const UNSEEN_FRACTION: f64 = 3.0;

/// Read-only services shared by every link of a refinement pass.
pub struct Services<'a> {
    /// The element arena.
    pub hierarchy: &'a Hierarchy,
    /// Ray caster, `None` when the scene needs no visibility (nothing can occlude).
    pub caster: Option<&'a RayCaster>,
    /// Visibility sampling.
    pub visibility: VisibilityConfig,
    /// What is known of each element (radiosity, its variation, the irradiance reference), for
    /// energy criteria.
    pub data: &'a super::ElementData,
    /// Factor on every threshold of this pass ([`LinkCtx::threshold`]): the pipeline refines
    /// coarse to fine, from a few times the oracle's eps down to it (or below, for a target error).
    pub threshold_scale: f64,
    /// Shaft culling for visibility, when enabled: links are classified by their shafts first and
    /// rays are cast against the shaft's candidate occluders only.
    pub shafts: Option<ShaftServices<'a>>,
    /// What the criteria bound the error of.
    pub criterion: Criterion,
    /// Under [`Criterion::Irradiance`], how many segments the visibility of a link of reflected
    /// light is sampled with when the oracle kept it without drawing any (see
    /// [`Criterion::kept_rays`]): `--rays`, or the kept count where calculation points read the
    /// solution (their error estimate does not count the links' sampling noise).
    pub reflected_rays: u32,
}

/// Shaft culling shared by a refinement pass.
#[derive(Clone, Copy)]
pub struct ShaftServices<'a> {
    /// The scene's objects and their bounding volumes.
    pub objects: &'a crate::visibility::shaft::ShaftObjects,
    /// Segments cast against candidate lists.
    pub rays: &'a std::sync::atomic::AtomicU64,
    /// Links classified invisible by a single occluder (no ray cast).
    pub invisible: &'a std::sync::atomic::AtomicU64,
    /// Links classified fully visible (no candidate, no ray cast).
    pub visible: &'a std::sync::atomic::AtomicU64,
}

/// Terms computed for one link and shared by the tools that read them.
#[derive(Clone, Copy, Debug, Default)]
pub struct LinkData {
    /// Form factor and the quality it was computed with.
    pub form_factor: Option<(f64, FormFactorQuality)>,
    /// Estimate of the largest point form factor over the receiver.
    pub form_factor_max: Option<f64>,
    /// Visibility fraction and the number of rays behind it.
    pub visibility: Option<(f64, u32)>,
    /// Smallest and largest point form factor over the receiver (estimated at the probe points).
    pub form_factor_range: Option<(f64, f64)>,
    /// The centre-to-centre axis and the areas projected along it.
    pub axis: Option<LinkAxis>,
    /// How strongly the emitter's radiosity variation shows at the receiver
    /// ([`LinkCtx::source_variation_weight`]).
    pub source_variation_weight: Option<f64>,
    /// A mark left by an oracle's command tool (studies, traces); the driver ignores it.
    pub mark: Option<u32>,
}

/// The centre-to-centre axis of a link and what is measured along it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinkAxis {
    /// Unit direction from the emitter's centre to the receiver's (zero when the centres coincide).
    pub dir: crate::geom::DVec3,
    /// Distance between the centres.
    pub distance: f64,
    /// Emitter area projected on the plane orthogonal to the axis (scene units²).
    pub projected_emitter: f64,
    /// Receiver area projected on the plane orthogonal to the axis (scene units²).
    pub projected_receiver: f64,
}

/// Weight of the source-variation error: the covariance of two quantities varying over the source
/// (the kernel and the radiosity) is at most a quarter of the product of their ranges.
pub const SOURCE_VARIATION_WEIGHT: f64 = 0.25;

/// Relative error of the point-source cluster approximation at separation `d` of elements of
/// bounding radii `r_S`, `r_R`: `CLUSTER_ERROR_COEF · ((r_S + r_R) / d)²` (the second-order term
/// of `1/r²` averaged over the two elements; the first order cancels about the area centroids).
pub const CLUSTER_ERROR_COEF: f64 = 1.0;

/// Mean fraction of a cluster's area seen from a random direction (isotropic clusters: a quarter,
/// as for the surface of a convex body).
pub const CLUSTER_PROJECTED_FRACTION: f64 = 0.25;

/// Largest kernel spread in [`LinkCtx::source_variation_weight`] (a kernel that varies from 0 to
/// twice its mean over the emitter).
pub const MAX_SOURCE_KERNEL_VARIATION: f64 = 2.0;

/// Clusters nearer than this many times the sum of the bounding radii (centre distance) are too
/// near for the isotropic cluster approximation (the criterion of the BF oracle).
pub const CLUSTER_NEAR_FACTOR: f64 = 2.0;

/// How unevenly `receiver`, as a whole, weights the surface of `source`: the spread
/// `(max − min) / mean` of the point form factor from the source's probe points (centre, corners
/// pulled in by [`formfactor::MAX_PROBE_PULL`]) to the receiver, at most
/// [`MAX_SOURCE_KERNEL_VARIATION`] (and that for a cluster source, whose members' weights are not
/// probed, or one the receiver does not see). Near 0 for a far receiver, large for one touching
/// the source: a radiosity varying by `ΔB` over the source moves the receiver's mean irradiance by
/// at most `F · κ · ΔB / 4` (the covariance of kernel and radiosity, each within its range).
#[must_use]
pub fn source_kernel_spread(h: &Hierarchy, source: u32, receiver: u32) -> f64 {
    let s = h.get(source);
    let Some(sp) = s.poly() else { return MAX_SOURCE_KERNEL_VARIATION };
    let (mut lo, mut hi, mut sum) = (f64::INFINITY, 0.0f64, 0.0);
    let vs = sp.vertices();
    for x in std::iter::once(s.center).chain(vs.iter().map(|&v| v + formfactor::MAX_PROBE_PULL * (s.center - v))) {
        let f = formfactor::point_to_element(h, x, s.normal, receiver);
        lo = lo.min(f);
        hi = hi.max(f);
        sum += f;
    }
    let mean = sum / (vs.len() + 1) as f64;
    if mean > 0.0 { ((hi - lo) / mean).min(MAX_SOURCE_KERNEL_VARIATION) } else { MAX_SOURCE_KERNEL_VARIATION }
}

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

    /// The shaft classification of this link (memoised), when shaft culling is enabled: candidates
    /// are searched among the parent link's list when there is one.
    pub fn shaft_verdict(&mut self) -> Option<crate::visibility::shaft::ShaftClass> {
        let shafts = self.services.shafts?;
        self.services.caster?;
        if let Some((class, _)) = &self.shaft {
            return Some(*class);
        }
        let v = crate::visibility::shaft::classify(
            shafts.objects,
            self.services.hierarchy,
            self.emitter,
            self.receiver,
            self.parent_candidates.as_deref(),
        );
        self.shaft = Some((v.class, std::sync::Arc::from(v.candidates)));
        Some(v.class)
    }

    /// The candidate occluders of this link's shaft, once [`LinkCtx::shaft_verdict`] ran.
    #[must_use]
    pub fn shaft_candidates(&self) -> Option<std::sync::Arc<[u32]>> {
        self.shaft.as_ref().map(|(_, c)| c.clone())
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

    /// The visibility fraction to keep for the link: a sample of at least `rays` segments (as many
    /// as the oracle cast) drawn independently of the one the oracle decided on, when it cast any.
    /// An oracle keeps a link because its segments agreed (all clear, all blocked, or a fraction
    /// whose error looked small); kept with those same segments, the links along a penumbra were
    /// biased by that choice: black sensors of CIE 171 case 5.7 read 2.6–4.7% low at 16 rays (seeds
    /// 1–3), 1.6–3.6% with a fresh sample of as many, 0.2–0.8% with one of 4 times as many
    /// ([`KEPT_VISIBILITY_FACTOR`]).
    pub fn fresh_visibility(&mut self, rays: u32) -> f64 {
        match self.data.visibility {
            None => self.visibility(rays),
            Some((_, n)) => {
                self.sample_visibility(VisibilityConfig { rays: n.max(rays), seed: self.services.visibility.seed ^ FRESH_VISIBILITY_SALT })
            }
        }
    }

    /// The visibility fraction the partial-visibility criterion decides on, for a link whose
    /// transfer (`B_S · F_max · w`) is `transfer` and threshold `threshold`: a sample of `--rays`
    /// segments; under [`Criterion::Irradiance`], when they all agree (all clear or all blocked)
    /// and an occluder (or gap) covering the fraction they could have missed
    /// ([`UNSEEN_FRACTION`]` / rays`) would push the error over the threshold, a sample of
    /// [`Criterion::kept_rays`] segments instead. Sixteen clear segments miss an occluder hiding
    /// a tenth of a link one time in six: on the Cornell box the short block's corner stood in a
    /// floor element linked whole to the lamp (kept visibility 0.90, the 16 segments all clear),
    /// so the floor beside it took the lamp's light up to the block's base (a lit strip in
    /// `image.png`).
    pub fn decision_visibility(&mut self, transfer: f64, threshold: f64) -> f64 {
        let rays = self.services.visibility.rays;
        let v = self.visibility(rays);
        let more = self.services.criterion.kept_rays(rays);
        if more > rays && (v == 0.0 || v == 1.0) && 2.0 * (UNSEEN_FRACTION / f64::from(rays)) * transfer > threshold {
            return self.visibility(more);
        }
        v
    }

    /// How many segments the visibility last sampled for this link was drawn with (0 before any).
    #[must_use]
    pub fn sampled_rays(&self) -> u32 {
        self.data.visibility.map_or(0, |(_, n)| n)
    }

    /// Visibility fraction with at least `rays` rays (1 when the scene needs no visibility).
    pub fn visibility(&mut self, rays: u32) -> f64 {
        if let Some((v, n)) = self.data.visibility
            && n >= rays
        {
            return v;
        }
        self.sample_visibility(VisibilityConfig { rays, ..self.services.visibility })
    }

    /// Visibility fraction from the segments `config` draws (1 when the scene needs no
    /// visibility), memoised for the link.
    fn sample_visibility(&mut self, config: VisibilityConfig) -> f64 {
        let rays = config.rays;
        let v = match (self.services.caster, self.services.shafts) {
            (None, _) => 1.0,
            (Some(caster), Some(shafts)) => {
                use crate::visibility::shaft::{self, ShaftClass};
                use std::sync::atomic::Ordering;
                let h = self.services.hierarchy;
                // A classification the oracle asked for is reused; otherwise a light one is made,
                // without occlusion tests: they cost more than the few segments they could save
                // (measured on the bench scenes), and an occluded link's segments all come out
                // blocked anyway.
                let light;
                let parent_len = self.parent_candidates.as_deref().map_or(usize::MAX, <[u32]>::len);
                let (class, cands): (ShaftClass, &[u32]) = match &self.shaft {
                    Some((class, cands)) => (*class, cands),
                    None if parent_len > shaft::MAX_CULL_PARENT_OBJECTS => {
                        // A long (or no) inherited list seldom shrinks to nothing: culling would
                        // cost about what the rays cost.
                        let v = caster.visibility(h, self.emitter, self.receiver, &config);
                        self.data.visibility = Some((v, rays));
                        return v;
                    }
                    None => {
                        light =
                            shaft::classify_with(shafts.objects, h, self.emitter, self.receiver, self.parent_candidates.as_deref(), false);
                        (light.class, &light.candidates)
                    }
                };
                match class {
                    ShaftClass::Invisible => {
                        shafts.invisible.fetch_add(1, Ordering::Relaxed);
                        0.0
                    }
                    ShaftClass::Visible => {
                        shafts.visible.fetch_add(1, Ordering::Relaxed);
                        1.0
                    }
                    ShaftClass::Partial { .. } => {
                        if shaft::n_polygons_among(shafts.objects, cands) > shaft::MAX_LOOP_POLYGONS {
                            // Long lists: the scene's BVH draws the same segments and is faster.
                            caster.visibility(h, self.emitter, self.receiver, &config)
                        } else {
                            let (v, n) = shaft::visibility_among(shafts.objects, h, self.emitter, self.receiver, cands, &config);
                            shafts.rays.fetch_add(u64::from(n), Ordering::Relaxed);
                            v
                        }
                    }
                }
            }
            (Some(caster), None) => caster.visibility(self.services.hierarchy, self.emitter, self.receiver, &config),
        };
        self.data.visibility = Some((v, rays));
        v
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
    /// [`formfactor::MAX_PROBE_PULL`]) to the receiver (at most [`MAX_SOURCE_KERNEL_VARIATION`]).
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
    /// [`super::ElementData::variation`]).
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
    /// (its dimmest leaf's), at least the scene's floor ([`super::ElementData::reference`]).
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
