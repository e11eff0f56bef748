//! The daylight factor's reference: the illuminance the sky gives an unobstructed horizontal
//! plane outside, `DF = E_inside ÷ E_outside,horizontal`.

use super::DistantSource;

/// The irradiance per channel that `scene`'s sky gives an unobstructed horizontal plane (its
/// cells' vertical light, which sums to the sky's diffuse horizontal irradiance), when the scene is
/// lit by a sky alone: `None` with a sun that gives light, luminaires, emitting materials, or no
/// sky (cells made by hand, without their patch of sky, do not say which way is up). A daylight
/// factor is defined under such a sky (the CIE overcast sky, for the standards).
#[must_use]
pub fn sky_alone_horizontal(scene: &crate::scene::Scene) -> Option<[f64; 3]> {
    if !scene.luminaires.is_empty() || scene.materials.iter().any(crate::scene::Material::is_emitter) {
        return None;
    }
    outside_horizontal(&scene.distant)
}

/// [`sky_alone_horizontal`] for the distant sources only: `None` with a sun that gives light or
/// no sky cell with its patch.
#[must_use]
pub fn outside_horizontal(distant: &[DistantSource]) -> Option<[f64; 3]> {
    if distant.iter().any(|s| s.sharp && s.irradiance.iter().any(|&e| e > 0.0)) {
        return None;
    }
    let mut sum = [0.0; 3];
    let mut cells = 0;
    for s in distant.iter().filter(|s| !s.sharp) {
        let patch = s.patch.as_ref()?;
        let vertical = -s.toward.dot(patch.frame[2]);
        for c in 0..3 {
            sum[c] += s.irradiance[c] * vertical;
        }
        cells += 1;
    }
    (cells > 0 && sum.iter().any(|&e| e > 0.0)).then_some(sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::daylight::{Site, SkyModel, sky};

    /// The cells' vertical light is the diffuse horizontal irradiance they were made for, for every
    /// model and count; a sun with light, or a cell without its patch, gives no reference.
    #[test]
    fn the_reference_is_the_diffuse_horizontal_irradiance() {
        let site = Site::new(crate::geom::DVec3::new(0.0, 1.0, 0.0), crate::geom::DVec3::new(0.0, 0.0, -1.0)).unwrap();
        for model in [SkyModel::Uniform, SkyModel::CieOvercast] {
            for n in [46, 145, 577] {
                let cells = sky(model, [10_000.0, 9_000.0, 8_000.0], n, &site).unwrap();
                let e = outside_horizontal(&cells).unwrap();
                for (got, want) in e.iter().zip([10_000.0, 9_000.0, 8_000.0]) {
                    assert!((got / want - 1.0).abs() < 1e-12, "{model:?} {n}: {got} against {want}");
                }
                let mut with_sun = cells.clone();
                with_sun.push(DistantSource { toward: -site.up, irradiance: [1.0; 3], sharp: true, patch: None });
                assert_eq!(outside_horizontal(&with_sun), None);
                with_sun.last_mut().unwrap().irradiance = [0.0; 3];
                assert!(outside_horizontal(&with_sun).is_some(), "a sun without light is no sun");
                let mut bare = cells.clone();
                bare[0].patch = None;
                assert_eq!(outside_horizontal(&bare), None);
            }
        }
        assert_eq!(outside_horizontal(&[]), None);
    }
}
