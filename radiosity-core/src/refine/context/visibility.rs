//! The visibility of a link: its shaft classification, the sample an oracle decides on, and the
//! fresh sample a kept link keeps.

use super::{FRESH_VISIBILITY_SALT, LinkCtx, UNSEEN_FRACTION};
use crate::visibility::VisibilityConfig;

impl<'a> LinkCtx<'a> {
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

    /// The visibility fraction to keep for the link: a sample of at least `rays` segments (as many
    /// as the oracle cast) drawn independently of the one the oracle decided on, when it cast any.
    /// An oracle keeps a link because its segments agreed (all clear, all blocked, or a fraction
    /// whose error looked small); kept with those same segments, the links along a penumbra were
    /// biased by that choice: black sensors of CIE 171 case 5.7 read 2.6–4.7% low at 16 rays (seeds
    /// 1–3), 1.6–3.6% with a fresh sample of as many, 0.2–0.8% with one of 4 times as many
    /// ([`KEPT_VISIBILITY_FACTOR`](super::KEPT_VISIBILITY_FACTOR)).
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
    /// segments; under [`Criterion::Irradiance`](super::Criterion::Irradiance), when they all agree (all clear or all blocked)
    /// and an occluder (or gap) covering the fraction they could have missed
    /// ([`UNSEEN_FRACTION`]` / rays`) would push the error over the threshold, a sample of
    /// [`Criterion::kept_rays`](super::Criterion::kept_rays) segments instead. Sixteen clear segments miss an occluder hiding
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
}
