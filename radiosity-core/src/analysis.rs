//! Step 1½, `analysis`: what a scene needs before it is solved, so the solver can leave out the
//! machinery it does not (DESIGN.md: SceneTraits).

use crate::scene::Scene;

/// Scenes with more polygons than this are not tested for convexity (the test is quadratic in the
/// worst case, though it usually stops at the first polygon that fails).
pub const CONVEXITY_MAX_POLYGONS: usize = 20_000;
/// Tolerance of "on or in front of a plane", relative to the scene's diagonal.
pub const PLANE_REL_TOL: f64 = 1e-9;

/// What a scene needs.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct SceneTraits {
    /// Some polygon may block light between two others (false for the inside of a convex
    /// enclosure, where every polygon sees every other one whole).
    pub needs_visibility: bool,
    /// Some material is coloured (reflectance or emission differs between channels).
    pub coloured: bool,
    /// Some material is two-sided or transmits light.
    pub two_sided: bool,
    /// Polygons that can send no light: they neither emit, reflect nor transmit in any channel.
    /// The refinement makes no link from them (their radiosity is zero whatever they receive).
    pub dark_polygons: usize,
    /// Polygons in all.
    pub polygons: usize,
}

impl SceneTraits {
    /// Analyses `scene`.
    #[must_use]
    pub fn of(scene: &Scene) -> SceneTraits {
        let coloured = scene.materials.iter().any(|m| {
            let ch = |v: [f64; 3]| v[0] != v[1] || v[1] != v[2];
            ch(m.reflectance) || ch(m.emission)
        });
        let two_sided = scene.materials.iter().any(|m| m.two_sided || m.transmittance.iter().any(|&t| t > 0.0));
        let positive = |v: &[f64; 3]| v.iter().any(|&x| x > 0.0);
        let dark: Vec<bool> =
            scene.materials.iter().map(|m| !(positive(&m.emission) || positive(&m.reflectance) || positive(&m.transmittance))).collect();
        let dark_polygons = scene.polygons.iter().filter(|p| dark.get(p.material as usize).copied().unwrap_or(false)).count();
        SceneTraits { needs_visibility: !is_convex_enclosure(scene), coloured, two_sided, dark_polygons, polygons: scene.polygons.len() }
    }

    /// The machinery a solve leaves out for this scene, in words (for the console and `stats.json`).
    #[must_use]
    pub fn left_out(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !self.needs_visibility {
            out.push("visibility rays (convex enclosure: no polygon can occlude another)".to_string());
        }
        if self.polygons > 0 && self.dark_polygons == self.polygons {
            out.push("links (no surface emits, reflects or transmits light: the direct light is the whole answer)".to_string());
        } else if self.dark_polygons > 0 {
            out.push(format!(
                "links from {} of {} polygons (black and not emitting: they send no light)",
                self.dark_polygons, self.polygons
            ));
        }
        out
    }
}

/// True when every polygon has all the scene's vertices on or in front of its plane: the polygons
/// bound a convex region from inside, and no segment between two of them can cross a third.
#[must_use]
pub fn is_convex_enclosure(scene: &Scene) -> bool {
    let n = scene.polygons.len();
    if n == 0 || n > CONVEXITY_MAX_POLYGONS {
        return n == 0;
    }
    let tol = PLANE_REL_TOL * scene.bounds().diagonal();
    scene.polygons.iter().all(|p| {
        let (o, normal) = (p.poly.v[0], p.poly.normal());
        scene.polygons.iter().all(|q| q.poly.vertices().iter().all(|v| normal.dot(*v - o) >= -tol))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::DVec3;
    use crate::scene::shapes::furnace_box;

    #[test]
    fn furnace_is_a_convex_enclosure_and_cornell_is_not() {
        assert!(is_convex_enclosure(&furnace_box(DVec3::ONE, 0.5, 1.0)));
        let cornell = crate::scene::cornell_box();
        let t = SceneTraits::of(&cornell);
        assert!(t.needs_visibility && t.coloured && !t.two_sided);
        assert!(t.left_out().is_empty());
    }

    #[test]
    fn black_polygons_are_left_out_as_sources() {
        let mut scene = crate::scene::cornell_box();
        let n = scene.polygons.len();
        scene.materials.push(crate::scene::Material::diffuse("black", [0.0; 3]));
        let black = (scene.materials.len() - 1) as u32;
        scene.polygons[0].material = black;
        let t = SceneTraits::of(&scene);
        assert_eq!((t.dark_polygons, t.polygons), (1, n));
        assert_eq!(t.left_out(), vec![format!("links from 1 of {n} polygons (black and not emitting: they send no light)")]);
        for p in &mut scene.polygons {
            p.material = black;
        }
        assert!(SceneTraits::of(&scene).left_out()[0].starts_with("links (no surface emits"));
    }
}
