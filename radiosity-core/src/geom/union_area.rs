//! Areas in a plane: convex clipping, and the area of a union of convex polygons, exactly (up to
//! rounding). What a parallel source's shadows cover of a surface element: the sun's lit share of
//! it without sampling ([`crate::luminaire`]).
//!
//! Written here rather than taken from a polygon-boolean crate (`geo`, `i_overlay`): those build
//! the union's outline, of which only the area is needed; a sweep over vertical slabs gives it in
//! a few dozen lines. Within a slab free of vertices and crossings every polygon covers an
//! interval whose ends move linearly, so the union's length is linear there and its value at the
//! slab's middle times the width is exact.
//!
//! The sweep finds where the intervals' ends cross by testing every pair of polygons active in a
//! slab, so it is quadratic in how many a slab holds: the 160,000 shadows of a canopy's leaves on
//! its ground would take hours. Many polygons are first split by area between the two halves of
//! their bounding box (each clipped to its half), recursively, until a region holds at most
//! [`SWEEP_MAX_POLYGONS`]: the union's area is the sum of the halves'.

/// At most this many polygons are swept together; more are split between two halves of their
/// bounding box first.
pub const SWEEP_MAX_POLYGONS: usize = 48;

/// A split is given up (the polygons are swept as they are) when the two halves hold more than
/// this many times the polygons together: most of them straddle the cut, so halving the region
/// does not make the sweep's work smaller.
const SPLIT_MAX_GROWTH: f64 = 1.5;

/// A point in the plane.
pub type Point2 = [f64; 2];

/// Twice the signed area of a polygon (positive counter-clockwise).
#[must_use]
pub fn signed_area2(p: &[Point2]) -> f64 {
    (0..p.len()).map(|i| cross(p[i], p[(i + 1) % p.len()])).sum()
}

fn cross(a: Point2, b: Point2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// The part of `subject` inside the convex counter-clockwise `window` (Sutherland–Hodgman); empty
/// when nothing of it with area is inside.
#[must_use]
pub fn clip_convex(subject: &[Point2], window: &[Point2]) -> Vec<Point2> {
    let mut out = subject.to_vec();
    for i in 0..window.len() {
        if out.len() < 3 {
            return Vec::new();
        }
        let (a, b) = (window[i], window[(i + 1) % window.len()]);
        let edge = [b[0] - a[0], b[1] - a[1]];
        // Positive on the window's side (left of the edge).
        let side = |p: Point2| cross(edge, [p[0] - a[0], p[1] - a[1]]);
        let input = std::mem::take(&mut out);
        clip_side(&input, side, |x| x, &mut out);
    }
    if out.len() < 3 { Vec::new() } else { out }
}

/// The area of the union of convex polygons (either orientation; fewer than three vertices count
/// for nothing).
#[must_use]
pub fn union_area(polys: &[Vec<Point2>]) -> f64 {
    if polys.len() <= SWEEP_MAX_POLYGONS {
        return sweep(polys);
    }
    let owned: Vec<Vec<Point2>> = polys.iter().filter(|p| p.len() >= 3).cloned().collect();
    split_area(owned)
}

/// [`union_area`] of many polygons: split between the halves of their bounding box along its
/// longer side, or swept where that does not pay.
fn split_area(polys: Vec<Vec<Point2>>) -> f64 {
    if polys.len() <= SWEEP_MAX_POLYGONS {
        return sweep(&polys);
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in polys.iter().flatten() {
        for k in 0..2 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let axis = usize::from(hi[1] - lo[1] > hi[0] - lo[0]);
    let mid = 0.5 * (lo[axis] + hi[axis]);
    if !(mid > lo[axis] && mid < hi[axis]) {
        return sweep(&polys);
    }
    let (mut below, mut above) = (Vec::new(), Vec::new());
    for p in &polys {
        let (min, max) = p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v[axis]), b.max(v[axis])));
        if max <= mid {
            below.push(p.clone());
        } else if min >= mid {
            above.push(p.clone());
        } else {
            let b = clip_half(p, axis, mid, false);
            if b.len() >= 3 {
                below.push(b);
            }
            let a = clip_half(p, axis, mid, true);
            if a.len() >= 3 {
                above.push(a);
            }
        }
    }
    if (below.len() + above.len()) as f64 > SPLIT_MAX_GROWTH * polys.len() as f64 {
        return sweep(&polys);
    }
    drop(polys);
    split_area(below) + split_area(above)
}

/// The part of convex polygon `p` on one side of the line `v[axis] = at`: where `v[axis] >= at`
/// when `keep_above`, else where `v[axis] <= at`.
fn clip_half(p: &[Point2], axis: usize, at: f64, keep_above: bool) -> Vec<Point2> {
    let side = |v: Point2| if keep_above { v[axis] - at } else { at - v[axis] };
    let mut out = Vec::with_capacity(p.len() + 1);
    // A crossing is put on the line exactly, so both halves meet without a gap or an overlap.
    clip_side(
        p,
        side,
        |mut x| {
            x[axis] = at;
            x
        },
        &mut out,
    );
    out
}

/// One step of Sutherland–Hodgman: appends to `out` the part of polygon `input` where `side` is
/// not negative, each crossing of the boundary passed through `on_boundary`.
fn clip_side(input: &[Point2], side: impl Fn(Point2) -> f64, on_boundary: impl Fn(Point2) -> Point2, out: &mut Vec<Point2>) {
    for k in 0..input.len() {
        let (p, q) = (input[k], input[(k + 1) % input.len()]);
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            let t = sp / (sp - sq);
            out.push(on_boundary([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]));
        }
    }
}

/// The slab sweep of [`union_area`] (see the module docs), quadratic in the polygons a slab holds.
fn sweep(polys: &[Vec<Point2>]) -> f64 {
    let polys: Vec<(&[Point2], f64, f64)> = polys
        .iter()
        .filter(|p| p.len() >= 3)
        .map(|p| {
            let (lo, hi) = p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v[0]), hi.max(v[0])));
            (p.as_slice(), lo, hi)
        })
        .filter(|&(_, lo, hi)| hi > lo)
        .collect();
    let mut xs: Vec<f64> = polys.iter().flat_map(|(p, _, _)| p.iter().map(|v| v[0])).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let mut order: Vec<usize> = (0..polys.len()).collect();
    order.sort_by(|&a, &b| polys[a].1.total_cmp(&polys[b].1));
    let (mut next, mut active, mut area) = (0, Vec::<usize>::new(), 0.0);
    // Per active polygon, its interval's ends at the slab's two sides (as lines across it).
    let mut lines: Vec<[f64; 4]> = Vec::new();
    let mut cuts: Vec<f64> = Vec::new();
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for w in xs.windows(2) {
        let (xa, xb) = (w[0], w[1]);
        let width = xb - xa;
        if width <= 0.0 {
            continue;
        }
        while next < order.len() && polys[order[next]].1 < xb {
            active.push(order[next]);
            next += 1;
        }
        active.retain(|&i| polys[i].2 > xa);
        if active.is_empty() {
            continue;
        }
        // Each interval's ends at a quarter and three quarters of the slab (no vertex inside it).
        let (x1, x2) = (xa + 0.25 * width, xa + 0.75 * width);
        lines.clear();
        for &i in &active {
            let (lo1, hi1) = span_at(polys[i].0, x1);
            let (lo2, hi2) = span_at(polys[i].0, x2);
            // Values at the slab's sides, t = 0 and t = 1.
            lines.push([1.5 * lo1 - 0.5 * lo2, 1.5 * lo2 - 0.5 * lo1, 1.5 * hi1 - 0.5 * hi2, 1.5 * hi2 - 0.5 * hi1]);
        }
        // Where two of the ends cross inside the slab.
        cuts.clear();
        cuts.extend([0.0, 1.0]);
        let ends: Vec<(f64, f64)> = lines.iter().flat_map(|l| [(l[0], l[1]), (l[2], l[3])]).collect();
        for i in 0..ends.len() {
            for j in i + 1..ends.len() {
                let (d0, d1) = (ends[i].0 - ends[j].0, ends[i].1 - ends[j].1);
                if (d0 > 0.0 && d1 < 0.0) || (d0 < 0.0 && d1 > 0.0) {
                    cuts.push(d0 / (d0 - d1));
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        for c in cuts.windows(2) {
            let dt = c[1] - c[0];
            if dt <= 0.0 {
                continue;
            }
            let t = 0.5 * (c[0] + c[1]);
            spans.clear();
            spans.extend(lines.iter().map(|l| (l[0] + t * (l[1] - l[0]), l[2] + t * (l[3] - l[2]))));
            spans.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (mut length, mut reach) = (0.0, f64::NEG_INFINITY);
            for &(lo, hi) in &spans {
                let lo = lo.max(reach);
                if hi > lo {
                    length += hi - lo;
                }
                reach = reach.max(hi);
            }
            area += length * dt * width;
        }
    }
    area
}

/// The interval a convex polygon covers on the vertical line at `x` (strictly inside its span).
fn span_at(p: &[Point2], x: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..p.len() {
        let (a, b) = (p[k], p[(k + 1) % p.len()]);
        if (a[0] <= x && x <= b[0] || b[0] <= x && x <= a[0]) && a[0] != b[0] {
            let y = a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0]);
            lo = lo.min(y);
            hi = hi.max(y);
        }
    }
    if lo <= hi { (lo, hi) } else { (0.0, 0.0) }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: f64, y: f64, s: f64) -> Vec<Point2> {
        vec![[x, y], [x + s, y], [x + s, y + s], [x, y + s]]
    }

    fn rotated(c: Point2, r: f64, n: usize, phase: f64) -> Vec<Point2> {
        (0..n)
            .map(|k| {
                let a = phase + std::f64::consts::TAU * k as f64 / n as f64;
                [c[0] + r * a.cos(), c[1] + r * a.sin()]
            })
            .collect()
    }

    /// Seeded uniform numbers in [0, 1) (xorshift64).
    fn uniform(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Closed forms: disjoint, overlapping, nested and crossing squares, and a clipped triangle.
    #[test]
    fn union_areas_match_closed_forms() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12 * b.abs().max(1.0);
        assert!(close(union_area(&[square(0.0, 0.0, 1.0), square(2.0, 0.0, 1.0)]), 2.0));
        assert!(close(union_area(&[square(0.0, 0.0, 1.0), square(0.5, 0.5, 1.0)]), 1.75));
        assert!(close(union_area(&[square(0.0, 0.0, 2.0), square(0.5, 0.5, 1.0)]), 4.0));
        // A unit square and the same square turned by 45° about its centre: they overlap in a
        // regular octagon of area 2(√2 − 1).
        let diamond = rotated([0.5, 0.5], std::f64::consts::FRAC_1_SQRT_2, 4, 0.0);
        let octagon = 2.0 * (std::f64::consts::SQRT_2 - 1.0);
        assert!(close(union_area(&[square(0.0, 0.0, 1.0), diamond]), 2.0 - octagon));
        // Clipping: the unit square cut by a triangle's window along its diagonal.
        let window = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let clipped = clip_convex(&square(0.0, 0.0, 1.0), &window);
        assert!(close(0.5 * signed_area2(&clipped), 0.5));
        assert!(clip_convex(&square(2.0, 2.0, 1.0), &window).is_empty());
        // Degenerate polygons count for nothing; orientation does not matter.
        let mut cw = square(0.0, 0.0, 1.0);
        cw.reverse();
        assert!(close(union_area(&[cw, vec![[0.0, 0.0], [3.0, 0.0], [3.0, 0.0]]]), 1.0));
    }

    /// Many random convex polygons: the sweep against a fine grid count (the grid's own error,
    /// about the boundary's length times a cell, bounds the difference).
    #[test]
    fn union_area_matches_a_grid_count_of_many_polygons() {
        let mut rand = uniform(0x2545_f491_4f6c_dd1d);
        let polys: Vec<Vec<Point2>> =
            (0..40).map(|_| rotated([rand() * 4.0, rand() * 4.0], 0.2 + 0.5 * rand(), 3 + (rand() * 5.0) as usize, rand() * 6.3)).collect();
        let area = union_area(&polys);
        let n = 2000;
        let cell = 6.0 / f64::from(n);
        let inside = |p: &[Point2], x: Point2| {
            (0..p.len()).all(|k| {
                cross([p[(k + 1) % p.len()][0] - p[k][0], p[(k + 1) % p.len()][1] - p[k][1]], [x[0] - p[k][0], x[1] - p[k][1]]) >= 0.0
            })
        };
        let mut count = 0u64;
        for i in 0..n {
            for j in 0..n {
                let x = [-1.0 + (f64::from(i) + 0.5) * cell, -1.0 + (f64::from(j) + 0.5) * cell];
                if polys.iter().any(|p| inside(p, x)) {
                    count += 1;
                }
            }
        }
        let grid = count as f64 * cell * cell;
        let perimeter: f64 = polys
            .iter()
            .map(|p| {
                (0..p.len())
                    .map(|k| ((p[(k + 1) % p.len()][0] - p[k][0]).powi(2) + (p[(k + 1) % p.len()][1] - p[k][1]).powi(2)).sqrt())
                    .sum::<f64>()
            })
            .sum();
        assert!((area - grid).abs() <= 0.5 * perimeter * cell, "sweep {area} grid {grid} (perimeter {perimeter})");
        assert!(area > 1.0 && area < 16.0);
    }

    /// Splitting between halves: the same area as one sweep of the same polygons (many of them
    /// straddling the cuts, overlapping and piled up), and the closed form where squares of a
    /// lattice overlap their neighbours by a known amount.
    #[test]
    fn split_union_area_matches_one_sweep_and_a_lattice() {
        let mut rand = uniform(0x9e37_79b9_7f4a_7c15);
        for (n, spread) in [(300, 10.0), (400, 3.0), (200, 0.5)] {
            let polys: Vec<Vec<Point2>> = (0..n)
                .map(|_| rotated([rand() * spread, rand() * spread], 0.05 + 0.4 * rand(), 3 + (rand() * 5.0) as usize, rand() * 6.3))
                .collect();
            let (split, swept) = (union_area(&polys), sweep(&polys));
            assert!(polys.len() > SWEEP_MAX_POLYGONS);
            assert!((split - swept).abs() <= 1e-9 * swept, "{n} polygons over {spread}: split {split}, one sweep {swept}");
        }
        // A 100 × 100 lattice of squares of side 1.25 at a spacing of 1: the union is the square
        // of side 99 + 1.25.
        let lattice: Vec<Vec<Point2>> = (0..100).flat_map(|i| (0..100).map(move |j| square(f64::from(i), f64::from(j), 1.25))).collect();
        let area = union_area(&lattice);
        let exact = 100.25_f64.powi(2);
        assert!((area - exact).abs() <= 1e-9 * exact, "lattice {area}, exact {exact}");
    }
}
