//! A seeded Monte Carlo photon tracer for canopy scenes, written for the tests and independent of
//! the solver's code: its own ray–triangle intersection (Möller–Trumbore) and box hierarchy, its
//! own Lambertian reflection and transmission, its own sun and sky.
//!
//! Light is the solver's: a sun (parallel light of a given normal irradiance) and a uniform sky
//! (radiance `E_dh/π` over the upper hemisphere), both without bounds in extent. Photons start
//! where that light first lands: points drawn uniformly on each lit side of each surface, a
//! direction toward the sun or drawn cosine-weighted toward the sky, kept when nothing is in the
//! way. At every surface it meets a photon leaves its absorbed share `1 − ρ − τ` there and goes on
//! with the rest, reflected (to its side) or transmitted (to the other side) in proportion to ρ and
//! τ, until it leaves the scene or Russian roulette ends it. What reaches the back of a one-sided
//! surface is counted as lost there.
//!
//! The noise is measured, not assumed: photons run in independent batches and every figure comes
//! with the standard error of its batch means.

/// A planar convex quadrilateral (`v` in order around it; its front is where `(v1 − v0) × (v2 − v0)`
/// points) with its optics in one band.
#[derive(Clone, Debug)]
pub struct Surface {
    pub v: [[f64; 3]; 4],
    pub reflectance: f64,
    pub transmittance: f64,
    /// Whether the back is a side like the front (else light reaching the back is lost).
    pub two_sided: bool,
}

/// The scene's light in one band.
#[derive(Clone, Copy, Debug)]
pub struct Light {
    /// The direction the sun's light travels (need not be unit length).
    pub sun_direction: [f64; 3],
    /// The sun's irradiance on a plane facing it, W/m².
    pub sun_normal: f64,
    /// The uniform sky's irradiance on a horizontal plane, W/m².
    pub sky_horizontal: f64,
}

/// A figure and its standard error (from the spread of the batches).
#[derive(Clone, Copy, Debug)]
pub struct Figure {
    pub mean: f64,
    pub std_error: f64,
}

/// What the photons did.
#[derive(Clone, Debug)]
pub struct Tally {
    /// Power of the sun and sky landing on the surfaces (either side of a two-sided one), W.
    pub incident: Figure,
    /// Power absorbed per surface in each batch (each batch's a full estimate), W.
    pub absorbed_by_batch: Vec<Vec<f64>>,
    /// Power leaving the scene, W.
    pub escaped: Figure,
    /// Power reaching the back of a one-sided surface, W.
    pub lost: Figure,
}

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: V, s: f64) -> V {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn unit(a: V) -> V {
    scale(a, 1.0 / dot(a, a).sqrt())
}

/// SplitMix64: a small seeded generator of uniform numbers in [0, 1) (the tests' own scenes draw
/// from it too).
pub struct Rng(pub u64);

impl Rng {
    /// The next number.
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A direction drawn with density `cos/π` about the unit normal `n`.
fn cosine_direction(n: V, rng: &mut Rng) -> V {
    let (u1, u2) = (rng.next(), rng.next());
    let r = u1.sqrt();
    let phi = std::f64::consts::TAU * u2;
    let a = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let t = unit(cross(n, a));
    let b = cross(n, t);
    let (x, y, z) = (r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
    unit(add(add(scale(t, x), scale(b, y)), scale(n, z)))
}

/// One triangle of a surface.
#[derive(Clone, Copy)]
struct Triangle {
    a: V,
    e1: V,
    e2: V,
    surface: usize,
}

/// A box hierarchy over triangles: nodes hold their box and either two children or a range of
/// triangles.
struct Bvh {
    triangles: Vec<Triangle>,
    nodes: Vec<Node>,
}

struct Node {
    lo: V,
    hi: V,
    /// Children (`left`, `left + 1`) when `count == 0`; else the first triangle.
    first: usize,
    count: usize,
}

const LEAF_TRIANGLES: usize = 4;

impl Bvh {
    fn new(triangles: Vec<Triangle>) -> Bvh {
        let mut bvh = Bvh { triangles, nodes: Vec::new() };
        let n = bvh.triangles.len();
        bvh.nodes.push(Node { lo: [0.0; 3], hi: [0.0; 3], first: 0, count: 0 });
        bvh.build(0, 0, n);
        bvh
    }

    fn bounds(t: &Triangle) -> (V, V) {
        let (b, c) = (add(t.a, t.e1), add(t.a, t.e2));
        (std::array::from_fn(|k| t.a[k].min(b[k]).min(c[k])), std::array::from_fn(|k| t.a[k].max(b[k]).max(c[k])))
    }

    fn build(&mut self, node: usize, start: usize, end: usize) {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for t in &self.triangles[start..end] {
            let (l, h) = Bvh::bounds(t);
            for k in 0..3 {
                lo[k] = lo[k].min(l[k]);
                hi[k] = hi[k].max(h[k]);
            }
        }
        self.nodes[node].lo = lo;
        self.nodes[node].hi = hi;
        if end - start <= LEAF_TRIANGLES {
            self.nodes[node].first = start;
            self.nodes[node].count = end - start;
            return;
        }
        let axis = (0..3).max_by(|&i, &j| (hi[i] - lo[i]).total_cmp(&(hi[j] - lo[j]))).unwrap();
        let centre = |t: &Triangle| {
            let (l, h) = Bvh::bounds(t);
            l[axis] + h[axis]
        };
        let mid = (start + end) / 2;
        self.triangles[start..end].select_nth_unstable_by(mid - start, |p, q| centre(p).total_cmp(&centre(q)));
        let left = self.nodes.len();
        self.nodes.push(Node { lo: [0.0; 3], hi: [0.0; 3], first: 0, count: 0 });
        self.nodes.push(Node { lo: [0.0; 3], hi: [0.0; 3], first: 0, count: 0 });
        self.nodes[node].first = left;
        self.build(left, start, mid);
        self.build(left + 1, mid, end);
    }

    /// The nearest triangle along the ray `o + t·d`, `t > 0`, skipping surface `skip`: its
    /// distance and surface.
    fn hit(&self, o: V, d: V, skip: usize) -> Option<(f64, usize)> {
        let inv = d.map(|x| 1.0 / x);
        let mut best: Option<(f64, usize)> = None;
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i];
            let (mut t0, mut t1) = (0.0f64, best.map_or(f64::INFINITY, |b| b.0));
            for k in 0..3 {
                let (a, b) = ((node.lo[k] - o[k]) * inv[k], (node.hi[k] - o[k]) * inv[k]);
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
            if t0 > t1 {
                continue;
            }
            if node.count == 0 {
                stack.push(node.first);
                stack.push(node.first + 1);
                continue;
            }
            for t in &self.triangles[node.first..node.first + node.count] {
                if t.surface == skip {
                    continue;
                }
                // Möller–Trumbore.
                let p = cross(d, t.e2);
                let det = dot(t.e1, p);
                if det.abs() < 1e-14 {
                    continue;
                }
                let s = sub(o, t.a);
                let u = dot(s, p) / det;
                if !(0.0..=1.0).contains(&u) {
                    continue;
                }
                let q = cross(s, t.e1);
                let v = dot(d, q) / det;
                if v < 0.0 || u + v > 1.0 {
                    continue;
                }
                let dist = dot(t.e2, q) / det;
                if dist > 0.0 && best.is_none_or(|b| dist < b.0) {
                    best = Some((dist, t.surface));
                }
            }
        }
        best
    }
}

/// A photon fainter than this share of its starting weight plays Russian roulette (survives with
/// probability ½ at twice its weight): unbiased, and it ends every path.
const ROULETTE_BELOW: f64 = 0.01;

/// A lit side: its surface, its outward normal and the power of the sun and sky that would land
/// on it unshaded.
struct Side {
    surface: usize,
    normal: V,
    sun: f64,
    sky: f64,
}

/// Traces `photons` photons (in `batches` batches of different seeds, run on the available cores)
/// through `surfaces` under `light`.
#[must_use]
pub fn trace(surfaces: &[Surface], light: Light, photons: usize, batches: usize, seed: u64) -> Tally {
    let triangles: Vec<Triangle> = surfaces
        .iter()
        .enumerate()
        .flat_map(|(i, s)| {
            let [a, b, c, d] = s.v;
            [Triangle { a, e1: sub(b, a), e2: sub(c, a), surface: i }, Triangle { a, e1: sub(c, a), e2: sub(d, a), surface: i }]
        })
        .collect();
    let bvh = Bvh::new(triangles);
    let toward_sun = scale(unit(light.sun_direction), -1.0);
    let normals: Vec<V> = surfaces.iter().map(|s| unit(cross(sub(s.v[1], s.v[0]), sub(s.v[2], s.v[0])))).collect();
    let areas: Vec<[f64; 2]> = surfaces
        .iter()
        .map(|s| {
            let [a, b, c, d] = s.v;
            let half = |p: V, q: V, r: V| 0.5 * dot(cross(sub(q, p), sub(r, p)), cross(sub(q, p), sub(r, p))).sqrt();
            [half(a, b, c), half(a, c, d)]
        })
        .collect();
    let mut sides = Vec::new();
    for (i, s) in surfaces.iter().enumerate() {
        let area = areas[i][0] + areas[i][1];
        let facing: &[f64] = if s.two_sided { &[1.0, -1.0] } else { &[1.0] };
        for &f in facing {
            let n = scale(normals[i], f);
            let sun = area * light.sun_normal * dot(n, toward_sun).max(0.0);
            let sky = area * light.sky_horizontal * 0.5 * (1.0 + n[2]);
            if sun + sky > 0.0 {
                sides.push(Side { surface: i, normal: n, sun, sky });
            }
        }
    }
    // Photons per side in proportion to the square root of its unshaded power: small leaves get
    // enough to be measured next to a large ground (each photon carries its side's power over its
    // count, so the estimate stays unbiased).
    let total: f64 = sides.iter().map(|s| (s.sun + s.sky).sqrt()).sum();
    let per_batch = photons.div_ceil(batches.max(1));
    let run = |batch: usize| -> (f64, Vec<f64>, f64, f64) {
        let mut rng = Rng(seed ^ (batch as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
        let (mut incident, mut escaped, mut lost) = (0.0, 0.0, 0.0);
        let mut absorbed = vec![0.0; surfaces.len()];
        for side in &sides {
            let power = side.sun + side.sky;
            let n = ((per_batch as f64 * power.sqrt() / total).ceil() as usize).max(4);
            let weight = power / n as f64;
            let s = &surfaces[side.surface];
            for _ in 0..n {
                // A point uniform on the quad (its triangle by area).
                let [a, b, c, d] = s.v;
                let [a0, a1] = areas[side.surface];
                let (p, q) = if rng.next() * (a0 + a1) < a0 { (b, c) } else { (c, d) };
                let (mut u, mut v) = (rng.next(), rng.next());
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let x = add(a, add(scale(sub(p, a), u), scale(sub(q, a), v)));
                // The sun or the sky, in proportion to their unshaded power on this side.
                let from_sun = rng.next() * power < side.sun;
                let to_source = if from_sun {
                    toward_sun
                } else {
                    let w = cosine_direction(side.normal, &mut rng);
                    if w[2] <= 0.0 {
                        continue; // below the horizon: no sky there
                    }
                    w
                };
                // The sky's share: the cosine-weighted draw finds the sky with probability
                // (1 + n_z)/2, which `side.sky` already holds; a kept draw carries `1/that`.
                let w = if from_sun { weight } else { weight / (0.5 * (1.0 + side.normal[2])) };
                if bvh.hit(x, to_source, side.surface).is_some() {
                    continue;
                }
                incident += w;
                let (mut w, mut at, mut surface, mut normal) = (w, x, side.surface, side.normal);
                loop {
                    // The absorbed share is deposited, the rest goes on reflected or transmitted
                    // (in proportion), until Russian roulette ends a faint photon.
                    let m = &surfaces[surface];
                    absorbed[surface] += w * (1.0 - m.reflectance - m.transmittance);
                    w *= m.reflectance + m.transmittance;
                    if w < ROULETTE_BELOW * weight {
                        if rng.next() < 0.5 {
                            break;
                        }
                        w *= 2.0;
                    }
                    if w <= 0.0 {
                        break;
                    }
                    let out = if rng.next() * (m.reflectance + m.transmittance) < m.reflectance { normal } else { scale(normal, -1.0) };
                    let d = cosine_direction(out, &mut rng);
                    match bvh.hit(at, d, surface) {
                        None => {
                            escaped += w;
                            break;
                        }
                        Some((t, j)) => {
                            let n = normals[j];
                            let front = dot(d, n) < 0.0;
                            if !front && !surfaces[j].two_sided {
                                lost += w;
                                break;
                            }
                            at = add(at, scale(d, t));
                            surface = j;
                            normal = if front { n } else { scale(n, -1.0) };
                        }
                    }
                }
            }
        }
        (incident, absorbed, escaped, lost)
    };
    let results: Vec<(f64, Vec<f64>, f64, f64)> = std::thread::scope(|scope| {
        let threads = std::thread::available_parallelism().map_or(1, usize::from).min(batches.max(1));
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let run = &run;
                scope.spawn(move || (t..batches.max(1)).step_by(threads).map(run).collect::<Vec<_>>())
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("a batch runs")).collect()
    });
    Tally {
        incident: figure(results.iter().map(|r| r.0).collect()),
        escaped: figure(results.iter().map(|r| r.2).collect()),
        lost: figure(results.iter().map(|r| r.3).collect()),
        absorbed_by_batch: results.into_iter().map(|r| r.1).collect(),
    }
}

/// The mean of independent estimates and its standard error.
fn figure(values: Vec<f64>) -> Figure {
    let k = values.len() as f64;
    let mean = values.iter().sum::<f64>() / k;
    let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (k - 1.0).max(1.0);
    Figure { mean, std_error: (var / k).sqrt() }
}

/// The power absorbed by the surfaces `which` selects, with its standard error (from the
/// batches' sums).
#[must_use]
pub fn absorbed_by(tally: &Tally, which: impl Fn(usize) -> bool) -> Figure {
    figure(tally.absorbed_by_batch.iter().map(|b| b.iter().enumerate().filter(|(i, _)| which(*i)).map(|(_, a)| a).sum()).collect())
}
