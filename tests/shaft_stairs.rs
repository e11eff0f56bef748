//! Regression, stairs behind a beam (issue 4; the published shaft-occlusion failure "dark stairs"):
//! an occluder lying behind a step, seen from the light, was taken to block the light. Here no
//! step tread that the light sees may be classified invisible, at any level of the link
//! hierarchy, with any bounding volume; and the visibility cast against the shaft's candidates
//! agrees with the global ray caster.

use radiosity_core::hierarchy::{self, BuildConfig, Hierarchy};
use radiosity_core::scene::generated::stairs_with_beam;
use radiosity_core::visibility::shaft::{self, BoundingVolume, ObjectConfig, ShaftClass, ShaftObjects};
use radiosity_core::visibility::{RayCaster, VisibilityConfig};

/// Rays per link for the reference visibility.
const RAYS: u32 = 256;

/// What every check of one bounding volume shares.
struct Setup<'a> {
    objects: &'a ShaftObjects,
    h: &'a Hierarchy,
    caster: &'a RayCaster,
    light: u32,
}

fn check_link(n_checked: &mut usize, s: &Setup<'_>, tread: u32, parent: Option<&[u32]>, depth: u32) {
    let Setup { objects, h, caster, light } = *s;
    let config = VisibilityConfig { rays: RAYS, seed: 7 };
    let verdict = shaft::classify(objects, h, light, tread, parent);
    let global = caster.visibility(h, light, tread, &config);
    let (restricted, _) = shaft::visibility_among(objects, h, light, tread, &verdict.candidates, &config);
    *n_checked += 1;
    assert!(
        !(verdict.class == ShaftClass::Invisible && global > 0.0),
        "dark stairs: light {light} -> tread element {tread} classified invisible (occluder {:?}) but {:.3} of rays reach it",
        verdict.occluder,
        global
    );
    assert!((restricted - global).abs() <= 2.0 / RAYS as f64, "light {light} -> {tread}: restricted {restricted} vs global {global}");
    if depth > 0 {
        for &c in h.children_of(tread).to_vec().iter() {
            check_link(n_checked, s, c, Some(&verdict.candidates), depth - 1);
        }
    }
}

#[test]
fn stairs_behind_beam_are_never_dark() {
    let scene = stairs_with_beam();
    let mut h = hierarchy::build(&scene, &BuildConfig::default());
    let caster = RayCaster::new(&scene);
    let light = (0..scene.polygons.len() as u32).find(|&i| scene.material_of(i as usize).is_emitter()).expect("the scene has a light");
    // Treads: the upward faces of the steps.
    let treads: Vec<u32> = (0..scene.polygons.len() as u32)
        .filter(|&i| {
            scene.groups[scene.polygons[i as usize].group as usize].starts_with("step") && scene.polygons[i as usize].poly.normal().y > 0.99
        })
        .collect();
    assert_eq!(treads.len(), 10, "one tread per step");
    for &t in &treads {
        h.subdivide(t);
        for &c in h.children_of(t).to_vec().iter() {
            h.subdivide(c);
        }
    }
    for volume in [BoundingVolume::Aabb, BoundingVolume::Obb, BoundingVolume::Hull] {
        let objects = ShaftObjects::new(&scene, &ObjectConfig { volume, ..ObjectConfig::default() });
        assert!(objects.n_solids() >= 11, "steps and beam are closed solids");
        let mut n_checked = 0;
        let setup = Setup { objects: &objects, h: &h, caster: &caster, light };
        for &t in &treads {
            check_link(&mut n_checked, &setup, t, None, 2);
        }
        assert_eq!(n_checked, 10 * (1 + 4 + 16));
    }
}

/// The beam does hide the floor under it from the light: the shaft test finds that occlusion
/// (so the regression above is not passing merely because nothing is ever occluded).
#[test]
fn beam_hides_the_floor_below_it() {
    let scene = stairs_with_beam();
    let mut h = hierarchy::build(&scene, &BuildConfig::default());
    let light = (0..scene.polygons.len() as u32).find(|&i| scene.material_of(i as usize).is_emitter()).expect("the scene has a light");
    // The bottom face of the lowest step above the beam, seen from the beam's underside, is hidden;
    // simpler and just as telling: the floor patch straight under the beam, seen from the light.
    let floor = (0..scene.polygons.len() as u32)
        .find(|&i| scene.groups[scene.polygons[i as usize].group as usize].starts_with("wall y-"))
        .expect("the room has a floor");
    let objects = ShaftObjects::new(&scene, &ObjectConfig::default());
    // Subdivide the floor until an element lies under the middle of the beam and the flight.
    let mut id = floor;
    for _ in 0..5 {
        h.subdivide(id);
        let target = glam::DVec3::new(3.3, 0.0, 2.0);
        id = *h
            .children_of(id)
            .iter()
            .min_by(|&&a, &&b| (h.get(a).center - target).length().total_cmp(&(h.get(b).center - target).length()))
            .expect("4 children");
    }
    let verdict = shaft::classify(&objects, &h, light, id, None);
    assert_eq!(verdict.class, ShaftClass::Invisible, "floor element {:?} under the beam", h.get(id).bounds);
}
