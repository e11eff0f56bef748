//! Analyse and build: what the scene needs ([`crate::analysis`]), the element hierarchy with the
//! luminaires' direct light, the ray caster, the shafts for visibility, and whether the scene is
//! closed. Everything here is made once, before the first level.

use super::{CLOSED_MAX_ESCAPE, Config, VisibilityMethod, effective_visibility};
use crate::analysis::SceneTraits;
use crate::hierarchy::{self, Hierarchy};
use crate::light::Lights;
use crate::refine::{self, Oracle};
use crate::scene::Scene;
use crate::visibility::RayCaster;
use crate::visibility::shaft::ShaftObjects;
use std::sync::atomic::{AtomicU64, Ordering};

/// What every level uses besides the hierarchy, built once for the scene.
pub(super) struct Services {
    /// What the scene needs, when analysed.
    pub(super) traits: Option<SceneTraits>,
    /// Machinery left out for this scene, in words.
    pub(super) left_out: Vec<String>,
    /// Whether refinement casts rays for visibility (asked for, and needed by the scene).
    pub(super) use_visibility: bool,
    /// Rays against every input triangle.
    pub(super) caster: RayCaster,
    /// The scene's luminaires and distant sources.
    pub(super) lights: Lights,
    /// Whether the direct light casts shadow rays ([`Config::use_visibility`]).
    direct_visibility: bool,
    /// The shafts' bounding volumes, when links are culled with shafts.
    shaft_objects: Option<ShaftObjects>,
    /// Rays cast through shafts.
    shaft_rays: AtomicU64,
    /// Links shaft culling found invisible without a ray.
    shaft_invisible: AtomicU64,
    /// Links shaft culling found visible without a ray.
    shaft_visible: AtomicU64,
    /// The fraction of the light leaving the surfaces that escapes the scene (NaN when not sampled).
    pub(super) escape_fraction: f64,
    /// Whether the scene is closed ([`CLOSED_MAX_ESCAPE`]).
    pub(super) closed: bool,
}

impl Services {
    /// The caster the direct light's shadow rays use, if any.
    pub(super) fn direct_caster(&self) -> Option<&RayCaster> {
        self.direct_visibility.then_some(&self.caster)
    }

    /// Shaft culling for a refinement pass, when links are culled with shafts.
    pub(super) fn shafts(&self) -> Option<refine::ShaftServices<'_>> {
        self.shaft_objects.as_ref().map(|objects| refine::ShaftServices {
            objects,
            rays: &self.shaft_rays,
            invisible: &self.shaft_invisible,
            visible: &self.shaft_visible,
        })
    }

    /// Rays cast so far, through the caster and through shafts.
    pub(super) fn rays(&self) -> u64 {
        self.caster.rays_cast() + self.shaft_rays.load(Ordering::Relaxed)
    }

    /// Links that shaft culling classified [invisible, visible] without casting a ray.
    pub(super) fn shaft_classified(&self) -> [u64; 2] {
        [self.shaft_invisible.load(Ordering::Relaxed), self.shaft_visible.load(Ordering::Relaxed)]
    }
}

/// Analyses `scene` (when [`Config::analyse`]) and builds its hierarchy, with the luminaires'
/// surfaces split for their light and every element's direct light, and the services the levels
/// use.
pub(super) fn build(scene: &Scene, oracle: &dyn Oracle, config: &Config) -> (Hierarchy, Services) {
    let traits = config.analyse.then(|| SceneTraits::of(scene));
    let left_out = traits.as_ref().map(SceneTraits::left_out).unwrap_or_default();
    let use_visibility = config.use_visibility && traits.as_ref().is_none_or(|t| t.needs_visibility);
    let mut h = hierarchy::build(scene, &config.build);
    let caster = RayCaster::new(scene);
    let lights = scene.lights();
    let direct_caster = config.use_visibility.then_some(&caster);
    // Luminaires: surfaces split for their light, every element's direct illuminance.
    crate::luminaire::prepare(&mut h, &lights, direct_caster, config.target_error.is_some());
    // Both sides of a transmitting leaf are cut into the same pieces (here and after every
    // refinement), so each piece passes its light through to the piece behind it.
    if !h.match_sides().is_empty() {
        crate::luminaire::update_direct(&mut h, &lights, direct_caster);
    }
    let shaft_objects = match effective_visibility(oracle, config.visibility_method) {
        VisibilityMethod::Shafts(volume) if use_visibility => Some(crate::visibility::shaft::ShaftObjects::new(
            scene,
            &crate::visibility::shaft::ObjectConfig { volume, ..Default::default() },
        )),
        _ => None,
    };
    let (shaft_rays, shaft_invisible, shaft_visible) = (AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0));
    // A closed scene delivers every bit of each surface's light to another: the leaf-resolution
    // solves then make it so exactly (see `solve::LeafCoefficients::for_cut`).
    let escape_fraction =
        if config.detect_closure { crate::visibility::escape_fraction(&h, &caster, config.visibility.seed) } else { f64::NAN };
    let closed = escape_fraction <= CLOSED_MAX_ESCAPE;
    let services = Services {
        traits,
        left_out,
        use_visibility,
        caster,
        lights,
        direct_visibility: config.use_visibility,
        shaft_objects,
        shaft_rays,
        shaft_invisible,
        shaft_visible,
        escape_fraction,
        closed,
    };
    (h, services)
}
