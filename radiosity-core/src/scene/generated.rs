//! Procedurally generated test scenes (interiors with stairs and beams, visibility test scenes).
//!
//! Part of step `scene`. Each function returns a validated-by-construction [`Scene`] (metres, +y
//! up) with emitters and a camera, built through [`SceneBuilder`]. Every solid piece (step, beam,
//! slab, table top, leg) is its own group and a closed box with outward faces, so shaft culling
//! sees it as one convex occluder; walls, floors and ceilings are single inward-facing quads.

use super::shapes::box_faces;
use super::{Camera, Material, Scene, SceneBuilder};
use crate::geom::DVec3;
use std::path::Path;

/// Emitted radiosity of the generated lights, W/m².
pub const LIGHT_EXITANCE: f64 = 100.0;

/// A scene builder with a few shapes and named materials.
struct Gen {
    b: SceneBuilder,
    n_groups: usize,
}

impl Gen {
    fn new(name: &str) -> Gen {
        Gen { b: SceneBuilder::new(Path::new(&format!("{name} (generated)")), name), n_groups: 0 }
    }

    fn material(&mut self, name: &str, rho: [f64; 3], emission: f64) -> u32 {
        let mut m = Material::diffuse(name, rho);
        m.emission = [emission; 3];
        self.b.material(m).expect("generated materials are valid")
    }

    fn group(&mut self, name: &str) -> u32 {
        self.n_groups += 1;
        self.b.group(&format!("{name}.{}", self.n_groups))
    }

    fn quad(&mut self, vs: [DVec3; 4], mat: u32, name: &str) {
        let g = self.group(name);
        self.b.face(&vs, mat, g, 0).expect("generated faces are finite");
    }

    /// A closed box with outward faces, one group.
    fn solid(&mut self, lo: DVec3, hi: DVec3, mat: u32, name: &str) {
        let g = self.group(name);
        for (_, q) in box_faces(lo, hi, false) {
            self.b.face(&q, mat, g, 0).expect("generated faces are finite");
        }
    }

    /// A closed box of half-extents `half` turned by `rotation` about its centre `center`, outward
    /// faces, one group.
    fn turned_solid(&mut self, center: DVec3, half: DVec3, rotation: glam::DMat3, mat: u32, name: &str) {
        let g = self.group(name);
        for (_, q) in box_faces(-half, half, false) {
            let q = q.map(|v| center + rotation * v);
            self.b.face(&q, mat, g, 0).expect("generated faces are finite");
        }
    }

    /// The inward faces of a room `[lo, hi]`, each its own group; `skip` names faces left out.
    fn room(&mut self, lo: DVec3, hi: DVec3, mat: u32, skip: &[&str]) {
        for (face, q) in box_faces(lo, hi, true) {
            if !skip.contains(&face) {
                let g = self.group(&format!("wall {face}"));
                self.b.face(&q, mat, g, 0).expect("generated faces are finite");
            }
        }
    }

    /// A horizontal rectangular light at height `y`, facing down.
    fn light_down(&mut self, x0: f64, z0: f64, x1: f64, z1: f64, y: f64, mat: u32) {
        let p = |x: f64, z: f64| DVec3::new(x, y, z);
        self.quad([p(x0, z0), p(x1, z0), p(x1, z1), p(x0, z1)], mat, "light");
    }

    /// The inward faces of a room `[0, size]` whose floor (`y-`) and ceiling (`y+`) take their own
    /// materials: `(wall, floor, ceiling)`.
    fn furnished_shell(&mut self, size: DVec3, (wall, floor, ceiling): (u32, u32, u32)) {
        self.room(DVec3::ZERO, size, wall, &["y-", "y+"]);
        for (face, q) in box_faces(DVec3::ZERO, size, true) {
            match face {
                "y-" => self.quad(q, floor, "floor"),
                "y+" => self.quad(q, ceiling, "ceiling"),
                _ => {}
            }
        }
    }

    /// `nx × nz` lights facing down at height `y`, centred at `(x0 + i·dx, z0 + j·dz)`, of
    /// half-sizes `(hx, hz)`.
    fn lamp_grid(&mut self, (nx, nz): (usize, usize), (x0, dx, z0, dz): (f64, f64, f64, f64), (hx, hz): (f64, f64), y: f64, mat: u32) {
        for i in 0..nx {
            for j in 0..nz {
                let (x, z) = (x0 + dx * i as f64, z0 + dz * j as f64);
                self.light_down(x - hx, z - hz, x + hx, z + hz, y, mat);
            }
        }
    }

    /// A table: top slab on four legs.
    fn table(&mut self, x: f64, z: f64, y0: f64, size: (f64, f64), mat: u32) {
        let (w, d) = size;
        let (h, t, leg) = (0.75, 0.04, 0.05);
        self.solid(DVec3::new(x - w / 2.0, y0 + h - t, z - d / 2.0), DVec3::new(x + w / 2.0, y0 + h, z + d / 2.0), mat, "table top");
        for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let (cx, cz) = (x + sx * (w / 2.0 - leg), z + sz * (d / 2.0 - leg));
            self.solid(
                DVec3::new(cx - leg / 2.0, y0, cz - leg / 2.0),
                DVec3::new(cx + leg / 2.0, y0 + h - t, cz + leg / 2.0),
                mat,
                "table leg",
            );
        }
    }

    /// A straight flight of `n` steps rising along +x from `start` (its low corner) by `rise` in
    /// all, each `going` deep, between `start.z` and `z1`; each step a solid box from the floor up.
    fn stairs(&mut self, start: DVec3, z1: f64, (n, going, rise): (usize, f64, f64), mat: u32) {
        let step_h = rise / n as f64;
        for k in 0..n {
            let xa = start.x + k as f64 * going;
            self.solid(DVec3::new(xa, start.y, start.z), DVec3::new(xa + going, start.y + (k + 1) as f64 * step_h, z1), mat, "step");
        }
    }

    fn finish(self, camera: Camera) -> Scene {
        let mut s = self.b.finish();
        s.camera = Some(camera);
        s
    }
}

/// A camera at `eye` looking at `target`, 50° vertical field of view, +y up.
fn look_at(eye: DVec3, target: DVec3) -> Camera {
    Camera { position: eye, direction: (target - eye).normalize(), up: DVec3::Y, fov_y: 50f64.to_radians() }
}

/// A two-storey "duplex" interior, 10 × 6 m, storeys 3 m high: a floor slab with a stairwell,
/// a straight staircase up through it, ceiling beams on both storeys, a partition wall with a door
/// opening, tables, and two ceiling lights per storey. About 300 polygons, most of them boxes.
#[must_use]
pub fn duplex() -> Scene {
    let mut g = Gen::new("duplex");
    let wall = g.material("wall", [0.7, 0.7, 0.68], 0.0);
    let wood = g.material("wood", [0.55, 0.4, 0.25], 0.0);
    let concrete = g.material("concrete", [0.5, 0.5, 0.5], 0.0);
    let light = g.material("light", [0.0; 3], LIGHT_EXITANCE);
    let (w, d, storey, slab) = (10.0, 6.0, 3.0, 0.25);
    g.room(DVec3::ZERO, DVec3::new(w, 2.0 * storey + slab, d), wall, &[]);
    // Floor slab between the storeys with a stairwell at x in [2, 6], z in [0, 1.2].
    let (y0, y1) = (storey, storey + slab);
    g.solid(DVec3::new(0.0, y0, 1.2), DVec3::new(w, y1, d), concrete, "slab");
    g.solid(DVec3::new(0.0, y0, 0.0), DVec3::new(2.0, y1, 1.2), concrete, "slab");
    g.solid(DVec3::new(6.0, y0, 0.0), DVec3::new(w, y1, 1.2), concrete, "slab");
    // Stairs along the +x wall side of the well, rising from the ground floor to the slab top.
    g.stairs(DVec3::new(2.0, 0.0, 0.05), 1.15, (16, 0.25, y1), wood);
    // Beams under the slab and under the roof, across the short side.
    for k in 1..5 {
        let x = k as f64 * 2.0 - 0.1;
        g.solid(DVec3::new(x, y0 - 0.3, 1.2), DVec3::new(x + 0.2, y0, d), wood, "beam");
        g.solid(DVec3::new(x, 2.0 * storey + slab - 0.3, 0.0), DVec3::new(x + 0.2, 2.0 * storey + slab, d), wood, "beam");
    }
    // Partition wall on the ground floor with a door opening (two solid pieces and a lintel).
    let (px, t) = (7.0, 0.1);
    g.solid(DVec3::new(px, 0.0, 1.2), DVec3::new(px + t, y0 - 0.3, 3.0), wall, "partition");
    g.solid(DVec3::new(px, 0.0, 4.0), DVec3::new(px + t, y0 - 0.3, d), wall, "partition");
    g.solid(DVec3::new(px, 2.1, 3.0), DVec3::new(px + t, y0 - 0.3, 4.0), wall, "lintel");
    // Furniture.
    g.table(4.0, 3.5, 0.0, (1.6, 0.9), wood);
    g.table(8.5, 3.0, 0.0, (1.2, 1.2), wood);
    g.table(3.0, 4.0, y1, (2.0, 1.0), wood);
    g.table(7.5, 2.5, y1, (1.2, 0.8), wood);
    // Lights: just below the slab (ground floor) and below the roof (upper floor).
    for (x, y) in [(1.0, y0 - 0.31), (8.4, y0 - 0.31), (3.0, 2.0 * storey + slab - 0.31), (7.0, 2.0 * storey + slab - 0.31)] {
        g.light_down(x, 2.5, x + 0.6, 3.5, y, light);
    }
    g.finish(look_at(DVec3::new(9.5, 1.6, 5.8), DVec3::new(3.0, 2.5, 0.5)))
}

/// A "geometry" visibility test scene in the style of Smits and Jensen's test scenes: a room with
/// a 5 × 5 grid of boxes of varied sizes and heights on the floor, thin plates hovering at several
/// heights, and one square ceiling light. Exercises many small occluders of every aspect ratio.
#[must_use]
pub fn smits_jensen_geometry() -> Scene {
    let mut g = Gen::new("sj-geometry");
    let white = g.material("white", [0.75; 3], 0.0);
    let red = g.material("red", [0.7, 0.15, 0.1], 0.0);
    let blue = g.material("blue", [0.1, 0.2, 0.7], 0.0);
    let light = g.material("light", [0.0; 3], LIGHT_EXITANCE);
    let size = 6.0;
    g.room(DVec3::ZERO, DVec3::splat(size), white, &[]);
    for i in 0..5 {
        for j in 0..5 {
            let (x, z) = (0.8 + i as f64 * 1.1, 0.8 + j as f64 * 1.1);
            let h = 0.2 + 0.25 * ((i * 3 + j * 7) % 7) as f64;
            let half = 0.15 + 0.05 * ((i + 2 * j) % 4) as f64;
            let mat = if (i + j) % 2 == 0 { red } else { blue };
            g.solid(DVec3::new(x - half, 0.0, z - half), DVec3::new(x + half, h, z + half), mat, "block");
        }
    }
    for (k, y) in [2.5, 3.3, 4.1].into_iter().enumerate() {
        let x = 1.0 + 1.5 * k as f64;
        g.solid(DVec3::new(x, y, 1.0), DVec3::new(x + 1.2, y + 0.02, 5.0), white, "plate");
    }
    g.light_down(2.5, 2.5, 3.5, 3.5, size - 0.01, light);
    g.finish(look_at(DVec3::new(5.8, 4.5, 5.8), DVec3::new(2.5, 0.5, 2.5)))
}

/// A "shadow" visibility test scene in the style of Smits and Jensen's test scenes: a long
/// rectangular area light above a floor, with occluders at several heights between them (a large
/// square plate, a thin bar, a cube on the floor, a plate held close to the floor), producing
/// umbrae and penumbrae of every width.
#[must_use]
pub fn smits_jensen_shadow() -> Scene {
    let mut g = Gen::new("sj-shadow");
    let white = g.material("white", [0.75; 3], 0.0);
    let grey = g.material("grey", [0.4; 3], 0.0);
    let light = g.material("light", [0.0; 3], LIGHT_EXITANCE);
    let (w, h, d) = (8.0, 4.0, 6.0);
    g.room(DVec3::ZERO, DVec3::new(w, h, d), white, &[]);
    g.light_down(1.0, 2.7, 7.0, 3.3, h - 0.01, light);
    g.solid(DVec3::new(1.0, 2.5, 1.0), DVec3::new(3.0, 2.55, 3.0), grey, "square plate");
    g.solid(DVec3::new(3.5, 1.5, 0.5), DVec3::new(3.7, 1.7, 5.5), grey, "bar");
    g.solid(DVec3::new(5.0, 0.0, 3.5), DVec3::new(6.0, 1.0, 4.5), grey, "cube");
    g.solid(DVec3::new(6.0, 0.3, 1.0), DVec3::new(7.5, 0.32, 2.5), grey, "low plate");
    g.finish(look_at(DVec3::new(7.5, 3.5, 5.8), DVec3::new(3.5, 0.5, 2.5)))
}

/// The published failure case of shaft occlusion (dark stairs): a straight staircase with a beam
/// behind it, under the flight, lit by a ceiling light above. The beam hides nothing the light
/// sees: every step's tread is directly lit. Steps and beam are solid boxes; the room is 6 × 4 × 4 m.
#[must_use]
pub fn stairs_with_beam() -> Scene {
    let mut g = Gen::new("stairs-beam");
    let white = g.material("white", [0.7; 3], 0.0);
    let wood = g.material("wood", [0.55, 0.4, 0.25], 0.0);
    let light = g.material("light", [0.0; 3], LIGHT_EXITANCE);
    let (w, h, d) = (6.0, 4.0, 4.0);
    g.room(DVec3::ZERO, DVec3::new(w, h, d), white, &[]);
    // Steps hung from a stringer: each step a slab at its height (the space below the flight open).
    let (n, going, rise) = (10usize, 0.3, 0.25);
    for k in 0..n {
        let x = 1.0 + k as f64 * going;
        let y = (k + 1) as f64 * rise;
        g.solid(DVec3::new(x, y - 0.05, 1.5), DVec3::new(x + going, y, 2.5), wood, "step");
    }
    // The beam: under the upper half of the flight (steps 6 to 10 are above it), wider than the
    // steps, behind them as seen from the light.
    g.solid(DVec3::new(2.6, 0.7, 1.4), DVec3::new(4.0, 0.9, 2.6), wood, "beam");
    g.light_down(2.0, 1.5, 3.0, 2.5, h - 0.01, light);
    g.finish(look_at(DVec3::new(5.5, 2.5, 3.8), DVec3::new(2.5, 1.2, 2.0)))
}

/// Occluders not aligned with the axes, where oriented bounding boxes cull far tighter than
/// axis-aligned ones: in an 8 × 4 × 6 m room, a ceiling light over five thin rafters (10 × 10 cm)
/// running diagonally in plan, whose bounding boxes cover most of the room's plan while the rafters
/// cover a tenth of it, and two crates turned 30° about the vertical.
#[must_use]
pub fn rotated_occluders() -> Scene {
    use glam::DMat3;
    let mut g = Gen::new("rotated");
    let white = g.material("white", [0.75; 3], 0.0);
    let wood = g.material("wood", [0.55, 0.4, 0.25], 0.0);
    let light = g.material("light", [0.0; 3], LIGHT_EXITANCE);
    let (w, h, d) = (8.0, 4.0, 6.0);
    g.room(DVec3::ZERO, DVec3::new(w, h, d), white, &[]);
    g.light_down(2.0, 2.0, 6.0, 4.0, h - 0.01, light);
    let diagonal = DMat3::from_rotation_y(40f64.to_radians());
    for k in 0..3 {
        let x = 1.6 + 2.4 * k as f64;
        g.turned_solid(DVec3::new(x, 2.6, 3.0), DVec3::new(0.05, 0.05, 2.4), diagonal, wood, "rafter");
    }
    for (x, z) in [(2.0, 1.5), (5.5, 4.2)] {
        g.turned_solid(DVec3::new(x, 0.4, z), DVec3::splat(0.4), DMat3::from_rotation_y(30f64.to_radians()), wood, "crate");
    }
    g.finish(look_at(DVec3::new(7.5, 3.5, 5.8), DVec3::new(3.5, 0.8, 2.5)))
}

/// A RenderPark-like office, 6 × 2.8 × 4.5 m: eight small lamps (30 cm squares, facing down)
/// hanging 30 cm under the ceiling in a 4 × 2 grid, four desks (solid blocks) with chairs, a low
/// partition between them and a cabinet standing off a wall; carpet, walls, ceiling, wood, fabric
/// and metal of distinct reflectances. 74 polygons. For the error estimate on interiors lit by
/// many small emitters among furniture (RenderPark's office scenes are GPL and stay outside the
/// project).
#[must_use]
pub fn office() -> Scene {
    let mut g = Gen::new("office");
    let carpet = g.material("carpet", [0.25, 0.22, 0.2], 0.0);
    let wall = g.material("wall", [0.7, 0.68, 0.62], 0.0);
    let ceiling = g.material("ceiling", [0.8; 3], 0.0);
    let wood = g.material("wood", [0.5, 0.35, 0.2], 0.0);
    let fabric = g.material("fabric", [0.3, 0.35, 0.5], 0.0);
    let metal = g.material("metal", [0.6, 0.6, 0.55], 0.0);
    let light = g.material("light", [0.0; 3], LIGHT_EXITANCE);
    let h = 2.8;
    g.furnished_shell(DVec3::new(6.0, h, 4.5), (wall, carpet, ceiling));
    g.lamp_grid((4, 2), (0.9, 1.4, 1.2, 2.1), (0.15, 0.15), h - 0.3, light);
    for (x, z, back) in [(1.5, 1.2, -1.0), (3.6, 1.2, -1.0), (1.5, 3.3, 1.0), (3.6, 3.3, 1.0)] {
        g.solid(DVec3::new(x - 0.7, 0.0, z - 0.4), DVec3::new(x + 0.7, 0.74, z + 0.4), wood, "desk");
        let zc = z + back * 0.75;
        g.solid(DVec3::new(x - 0.25, 0.0, zc - 0.25), DVec3::new(x + 0.25, 0.46, zc + 0.25), fabric, "chair");
    }
    g.solid(DVec3::new(0.6, 0.0, 2.2), DVec3::new(4.5, 1.2, 2.3), fabric, "partition");
    g.solid(DVec3::new(5.0, 0.0, 1.4), DVec3::new(5.6, 1.9, 3.1), metal, "cabinet");
    g.finish(look_at(DVec3::new(5.8, 2.3, 4.3), DVec3::new(2.5, 0.6, 1.5)))
}

/// A RenderPark-like classroom, 9 × 3.2 × 7 m: eighteen small lamps (20 × 60 cm, facing down) in
/// three rows hanging 40 cm under the ceiling, sixteen desks and chairs (solid blocks) in four rows,
/// a teacher's desk and a dark board standing before the front wall. 222 polygons.
#[must_use]
pub fn classroom() -> Scene {
    let mut g = Gen::new("classroom");
    let floor = g.material("floor", [0.35, 0.3, 0.25], 0.0);
    let wall = g.material("wall", [0.65, 0.65, 0.6], 0.0);
    let ceiling = g.material("ceiling", [0.75; 3], 0.0);
    let wood = g.material("wood", [0.55, 0.4, 0.25], 0.0);
    let seat = g.material("seat", [0.5, 0.15, 0.1], 0.0);
    let board = g.material("board", [0.08, 0.15, 0.1], 0.0);
    let light = g.material("light", [0.0; 3], LIGHT_EXITANCE);
    let h = 3.2;
    g.furnished_shell(DVec3::new(9.0, h, 7.0), (wall, floor, ceiling));
    g.lamp_grid((6, 3), (1.0, 1.4, 1.4, 2.1), (0.1, 0.3), h - 0.4, light);
    for i in 0..4 {
        for j in 0..4 {
            let (x, z) = (2.4 + 1.7 * i as f64, 1.2 + 1.5 * j as f64);
            g.solid(DVec3::new(x - 0.6, 0.0, z - 0.25), DVec3::new(x + 0.6, 0.72, z + 0.25), wood, "desk");
            g.solid(DVec3::new(x - 0.2, 0.0, z + 0.4), DVec3::new(x + 0.2, 0.45, z + 0.8), seat, "chair");
        }
    }
    g.solid(DVec3::new(0.8, 0.0, 2.7), DVec3::new(1.6, 0.75, 4.3), wood, "teacher's desk");
    g.solid(DVec3::new(0.15, 0.9, 2.0), DVec3::new(0.2, 2.1, 5.0), board, "board");
    g.finish(look_at(DVec3::new(8.7, 2.6, 6.7), DVec3::new(2.0, 0.8, 2.5)))
}

/// Names of the scenes built by code rather than loaded (`radiosity solve NAME`): the embedded
/// Cornell box and the generated scenes of this module ([`by_name`] builds them).
pub const NAMES: &[&str] =
    &["cornell", "gen:duplex", "gen:sj-geometry", "gen:sj-shadow", "gen:stairs", "gen:rotated", "gen:office", "gen:classroom"];

/// The scene of a name in [`NAMES`]; `None` for any other name.
#[must_use]
pub fn by_name(name: &str) -> Option<Scene> {
    Some(match name {
        "cornell" => super::cornell_box(),
        "gen:duplex" => duplex(),
        "gen:sj-geometry" => smits_jensen_geometry(),
        "gen:sj-shadow" => smits_jensen_shadow(),
        "gen:stairs" => stairs_with_beam(),
        "gen:rotated" => rotated_occluders(),
        "gen:office" => office(),
        "gen:classroom" => classroom(),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::LoadOptions;

    #[test]
    fn generated_scenes_are_valid_and_lit() {
        for scene in [duplex(), smits_jensen_geometry(), smits_jensen_shadow(), stairs_with_beam(), rotated_occluders()] {
            scene.check(Path::new(&scene.name), &LoadOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", scene.name));
            assert_eq!(scene.warnings.degenerate_faces, 0, "{}", scene.name);
            assert!(scene.camera.is_some());
            assert!(scene.polygons.len() > 20, "{}: {} polygons", scene.name, scene.polygons.len());
        }
        for name in NAMES {
            assert!(by_name(name).is_some(), "{name} builds");
        }
        assert!(by_name("gen:nothing").is_none());
    }
}
