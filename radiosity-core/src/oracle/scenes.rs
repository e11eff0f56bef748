//! Procedurally generated scenes for the oracle benchmark, of growing size and visibility
//! complexity: a simple room, a room with objects of very different sizes, a maze, a large
//! furnished interior, and a scene of heterogeneous object sizes. All are deterministic.

use crate::geom::DVec3;
use crate::scene::shapes::box_faces;
use crate::scene::{Material, Scene, SceneBuilder};
use crate::visibility::Rng;
use std::path::Path;

/// Radiosity emitted by the ceiling lights (W/m²).
pub const LIGHT_EMISSION: f64 = 10.0;
/// Seed of the heterogeneous scene's layout.
pub const HETEROGENEOUS_SEED: u64 = 7;

struct Room {
    b: SceneBuilder,
    wall: u32,
    object: u32,
    light: u32,
}

impl Room {
    fn new(name: &str) -> Room {
        let mut b = SceneBuilder::new(Path::new(name), name);
        let wall = b.material(Material::diffuse("wall", [0.6, 0.6, 0.6])).expect("valid material");
        let object = b.material(Material::diffuse("object", [0.4, 0.45, 0.5])).expect("valid material");
        let mut m = Material::diffuse("light", [0.0; 3]);
        m.emission = [LIGHT_EMISSION; 3];
        let light = b.material(m).expect("valid material");
        Room { b, wall, object, light }
    }

    /// The inward-facing box `[0, size]`.
    fn shell(&mut self, size: DVec3) {
        let g = self.b.group("room");
        for (_, quad) in box_faces(DVec3::ZERO, size, true) {
            self.b.face(&quad, self.wall, g, 0).expect("finite geometry");
        }
    }

    /// A box with outward faces (its bottom face omitted when it stands on the floor).
    fn block(&mut self, lo: DVec3, hi: DVec3) {
        let g = self.b.group("objects");
        for (name, quad) in box_faces(lo, hi, false) {
            if name == "y-" && lo.y <= 0.0 {
                continue;
            }
            self.b.face(&quad, self.object, g, 0).expect("finite geometry");
        }
    }

    /// A square light of half-width `half` just below the ceiling at height `y`, facing down.
    fn light(&mut self, x: f64, z: f64, y: f64, half: f64) {
        let g = self.b.group("lights");
        let y = y * (1.0 - 1e-3);
        let quad = [
            DVec3::new(x - half, y, z - half),
            DVec3::new(x + half, y, z - half),
            DVec3::new(x + half, y, z + half),
            DVec3::new(x - half, y, z + half),
        ];
        self.b.face(&quad, self.light, g, 0).expect("finite geometry");
    }

    fn finish(self) -> Scene {
        self.b.finish()
    }
}

/// A 4 × 3 × 5 room with one ceiling light.
#[must_use]
pub fn simple_room() -> Scene {
    let mut r = Room::new("simple-room");
    r.shell(DVec3::new(4.0, 3.0, 5.0));
    r.light(2.0, 2.5, 3.0, 0.4);
    r.finish()
}

/// The simple room with a large cabinet, a table, and small objects two orders of magnitude smaller.
#[must_use]
pub fn room_with_objects() -> Scene {
    let mut r = Room::new("room-objects");
    r.shell(DVec3::new(4.0, 3.0, 5.0));
    r.light(2.0, 2.5, 3.0, 0.4);
    r.block(DVec3::new(0.2, 0.0, 0.2), DVec3::new(1.4, 2.2, 0.8));
    r.block(DVec3::new(2.0, 0.7, 2.0), DVec3::new(3.4, 0.75, 3.2));
    for i in 0..6 {
        let x = 2.1 + 0.2 * i as f64;
        r.block(DVec3::new(x, 0.75, 2.5), DVec3::new(x + 0.04, 0.79, 2.54));
    }
    r.finish()
}

/// A `cells × cells` maze of 1 m cells with 2 m walls (a fixed pattern of openings) and a light
/// per row of cells.
#[must_use]
pub fn maze(cells: usize) -> Scene {
    let n = cells.max(2);
    let size = n as f64;
    let mut r = Room::new("maze");
    r.shell(DVec3::new(size, 2.5, size));
    let t = 0.05;
    let mut rng = Rng::for_link(HETEROGENEOUS_SEED, n as u32, 1);
    for i in 1..n {
        let c = i as f64;
        for j in 0..n {
            let lo = j as f64;
            // Walls along z (at x = i) and along x (at z = i), each cell edge open one time in three.
            if !rng.next_u64().is_multiple_of(3) {
                r.block(DVec3::new(c - t, 0.0, lo), DVec3::new(c + t, 2.0, lo + 1.0));
            }
            if !rng.next_u64().is_multiple_of(3) {
                r.block(DVec3::new(lo, 0.0, c - t), DVec3::new(lo + 1.0, 2.0, c + t));
            }
        }
    }
    for i in 0..n {
        r.light(i as f64 + 0.5, 0.5 + (i % n) as f64, 2.5, 0.2);
    }
    r.finish()
}

/// A 16 × 3 × 12 hall with rows of tables, each with four chairs, and a grid of lights.
#[must_use]
pub fn furnished_interior() -> Scene {
    let mut r = Room::new("furnished-interior");
    r.shell(DVec3::new(16.0, 3.0, 12.0));
    for i in 0..4 {
        for j in 0..3 {
            let (x, z) = (2.0 + 4.0 * i as f64, 2.0 + 4.0 * j as f64);
            r.light(x, z, 3.0, 0.3);
            // Table top and legs.
            r.block(DVec3::new(x - 0.8, 0.72, z - 0.5), DVec3::new(x + 0.8, 0.76, z + 0.5));
            for (dx, dz) in [(-0.75, -0.45), (0.7, -0.45), (-0.75, 0.4), (0.7, 0.4)] {
                r.block(DVec3::new(x + dx, 0.0, z + dz), DVec3::new(x + dx + 0.05, 0.72, z + dz + 0.05));
            }
            // Chairs: seat and back.
            for side in [-1.0, 1.0] {
                let cz = z + side * 0.8;
                r.block(DVec3::new(x - 0.2, 0.42, cz - 0.2), DVec3::new(x + 0.2, 0.45, cz + 0.2));
                let bz = cz + side * 0.2;
                r.block(DVec3::new(x - 0.2, 0.45, bz.min(bz - side * 0.03)), DVec3::new(x + 0.2, 0.9, bz.max(bz - side * 0.03)));
            }
        }
    }
    r.finish()
}

/// A 10 × 4 × 10 room with 40 boxes whose sizes span three orders of magnitude (seeded).
#[must_use]
pub fn heterogeneous() -> Scene {
    let mut r = Room::new("heterogeneous");
    r.shell(DVec3::new(10.0, 4.0, 10.0));
    r.light(5.0, 5.0, 4.0, 0.5);
    r.light(2.0, 8.0, 4.0, 0.2);
    let mut rng = Rng::for_link(HETEROGENEOUS_SEED, 0, 0);
    for _ in 0..40 {
        let s = 0.01 * 10f64.powf(3.0 * rng.next_f64()).min(150.0);
        let x = 0.5 + 9.0 * rng.next_f64();
        let z = 0.5 + 9.0 * rng.next_f64();
        let y = 3.0 * rng.next_f64();
        let half = 0.5 * s.min(1.5);
        r.block(DVec3::new(x - half, y, z - half), DVec3::new(x + half, (y + 2.0 * half).min(3.9), z + half));
    }
    r.finish()
}

/// The five benchmark scenes, smallest first.
#[must_use]
pub fn bench_scenes() -> Vec<Scene> {
    vec![simple_room(), room_with_objects(), maze(6), furnished_interior(), heterogeneous()]
}
