//! The link context an oracle reads: the two elements, shared services, and memoised link terms.

use crate::formfactor::{self, FormFactorQuality};
use crate::hierarchy::{Element, Hierarchy};
use crate::visibility::{RayCaster, VisibilityConfig};

/// Read-only services shared by every link of a refinement pass.
pub struct Services<'a> {
    /// The element arena.
    pub hierarchy: &'a Hierarchy,
    /// Ray caster, `None` when the scene needs no visibility (nothing can occlude).
    pub caster: Option<&'a RayCaster>,
    /// Visibility sampling.
    pub visibility: VisibilityConfig,
    /// Current radiosity per element (W/m²), for energy criteria.
    pub radiosity: &'a [[f64; 3]],
    /// Reference radiosity that relative thresholds are measured against (the largest emission).
    pub b_ref: f64,
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
}

impl<'a> LinkCtx<'a> {
    /// A fresh context.
    #[must_use]
    pub fn new(services: &'a Services<'a>, emitter: u32, receiver: u32) -> LinkCtx<'a> {
        LinkCtx { services, emitter, receiver, data: LinkData::default() }
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
        if let Some((f, q)) = self.data.form_factor {
            if q >= quality {
                return f;
            }
        }
        let h = self.services.hierarchy;
        let f = match quality {
            FormFactorQuality::Estimate => formfactor::estimate(h, self.emitter, self.receiver),
            FormFactorQuality::Precise => formfactor::link_form_factor(h, self.emitter, self.receiver, quality),
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

    /// Visibility fraction with at least `rays` rays (1 when the scene needs no visibility).
    pub fn visibility(&mut self, rays: u32) -> f64 {
        if let Some((v, n)) = self.data.visibility {
            if n >= rays {
                return v;
            }
        }
        let v = match self.services.caster {
            None => 1.0,
            Some(caster) => {
                let config = VisibilityConfig { rays, ..self.services.visibility };
                caster.visibility(self.services.hierarchy, self.emitter, self.receiver, &config)
            }
        };
        self.data.visibility = Some((v, rays));
        v
    }

    /// Largest channel of the emitter's current radiosity.
    #[must_use]
    pub fn emitter_radiosity(&self) -> f64 {
        let b = self.services.radiosity[self.emitter as usize];
        b[0].max(b[1]).max(b[2])
    }

    /// Whether the two elements can exchange light at all, judged from the planes of surfaces:
    /// false when the receiver lies entirely behind the emitter's plane or the other way round.
    #[must_use]
    pub fn facing(&self) -> bool {
        let (s, r) = (self.emitter_element(), self.receiver_element());
        let behind = |plane_el: &Element, other: &Element| -> bool {
            let Some(p) = plane_el.poly() else { return false };
            let origin = p.v[0];
            let tol = 1e-9 * plane_el.radius;
            match other.poly() {
                Some(q) => q.vertices().iter().all(|v| plane_el.normal.dot(*v - origin) <= tol),
                None => {
                    let b = &other.bounds;
                    (0..8).all(|c| {
                        let corner = crate::geom::DVec3::new(
                            if c & 1 == 0 { b.min.x } else { b.max.x },
                            if c & 2 == 0 { b.min.y } else { b.max.y },
                            if c & 4 == 0 { b.min.z } else { b.max.z },
                        );
                        plane_el.normal.dot(corner - origin) <= tol
                    })
                }
            }
        };
        !behind(s, r) && !behind(r, s)
    }
}
