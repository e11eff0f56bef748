//! Occluders inherited from the levels above: the polygons that cross a closed instance's box (a
//! trunk through a branch's box), which the beams that reach the instance are tested against.

use super::proxy::padded;
use super::task::{Closed, OwnPolygon};
use crate::geom::{Aabb, DVec3, Poly};

/// Polygons of the levels above that an instance's beams are tested against: indices into a pool
/// shared by the instance's siblings (their level's own polygons and its inherited occluders),
/// so that a level with a thousand closed instances around a trunk holds its polygons once.
#[derive(Clone, Default)]
pub(super) struct Occluders {
    pool: Option<std::sync::Arc<[Poly]>>,
    index: Vec<u32>,
}

impl Occluders {
    /// Occluders holding `polys` alone, in order (a task received from another process).
    pub(super) fn from_polys(polys: Vec<Poly>) -> Occluders {
        if polys.is_empty() {
            return Occluders::default();
        }
        let index = (0..polys.len() as u32).collect();
        Occluders { pool: Some(polys.into()), index }
    }

    pub(super) fn iter(&self) -> impl Iterator<Item = &Poly> {
        self.pool.iter().flat_map(|pool| self.index.iter().map(move |&i| &pool[i as usize]))
    }
}

/// Most polygons of the levels above handed to an instance as occluders (the largest kept).
pub const MAX_INHERITED_OCCLUDERS: usize = 64;

/// The polygons of `pool` (scene frame) whose box meets `bx`, largest first, at most
/// [`MAX_INHERITED_OCCLUDERS`]. The polygons of a closed instance see only their own level's
/// geometry in its visibility table; a trunk passing through a branch's box, or leaves hugging it,
/// are otherwise lit as if it were not there (on the age-30 tree, crown-centre leaves next to the
/// trunk got ten times the light the full solve gives them).
fn inherited_occluders(pool: &[Poly], grid: &PoolGrid, bx: &Aabb) -> Vec<u32> {
    let mut index = grid.meeting(bx);
    if index.len() > MAX_INHERITED_OCCLUDERS {
        index.sort_by(|&a, &b| pool[b as usize].area().total_cmp(&pool[a as usize].area()));
        index.truncate(MAX_INHERITED_OCCLUDERS);
    }
    index
}

/// The instances' occluder lists (indices into `pool`) over one shared pool that keeps only the
/// polygons some list names (a forest's top level has 190,000 trunk polygons, of which the
/// pending instances name a few thousand); each list without spare capacity.
fn share_pool(pool: &[Poly], lists: &mut [Vec<u32>]) -> Vec<Occluders> {
    let mut remap = vec![u32::MAX; pool.len()];
    let mut kept: Vec<Poly> = Vec::new();
    for list in lists.iter_mut() {
        for i in list.iter_mut() {
            if remap[*i as usize] == u32::MAX {
                remap[*i as usize] = kept.len() as u32;
                kept.push(pool[*i as usize]);
            }
            *i = remap[*i as usize];
        }
    }
    let shared: std::sync::Arc<[Poly]> = kept.into();
    lists
        .iter_mut()
        .map(|list| {
            let mut index = std::mem::take(list);
            index.shrink_to_fit();
            Occluders { pool: (!index.is_empty()).then(|| shared.clone()), index }
        })
        .collect()
}

/// The occluders handed to each of the `closed` instances of a level: the polygons of the level's
/// `own` and of its `inherited` occluders that meet the instance's padded box (see
/// [`inherited_occluders`]), over one shared pool.
pub(super) fn child_occluders(own: &[OwnPolygon], inherited: &Occluders, closed: &[Closed], bounds: &[Aabb]) -> Vec<Occluders> {
    let pool: std::sync::Arc<[Poly]> =
        if closed.is_empty() { std::sync::Arc::from([]) } else { own.iter().map(|o| o.0).chain(inherited.iter().copied()).collect() };
    let grid = PoolGrid::new(&pool);
    let mut child_occluders: Vec<Vec<u32>> =
        closed.iter().map(|&(c, t, _, _)| inherited_occluders(&pool, &grid, &t.aabb(&padded(&bounds[c as usize])))).collect();
    drop(grid);
    share_pool(&pool, &mut child_occluders)
}

/// The boxes of a level's pool of occluders in a grid over x and y (CSR layout), so that finding
/// those that meet an instance's box does not scan the pool once per instance (a forest's top
/// level: 69,000 instances, 190,000 trunk polygons).
struct PoolGrid {
    boxes: Vec<Aabb>,
    lo: DVec3,
    cell: DVec3,
    n: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl PoolGrid {
    fn new(pool: &[Poly]) -> PoolGrid {
        let boxes: Vec<Aabb> = pool.iter().map(|p| Aabb::from_points(p.vertices())).collect();
        let mut all = Aabb::EMPTY;
        for b in &boxes {
            all.merge(b);
        }
        let n = ((boxes.len() as f64).sqrt().ceil() as usize).clamp(1, 256);
        let (lo, size) = if boxes.is_empty() { (DVec3::ZERO, DVec3::ONE) } else { (all.min, all.extent()) };
        let cell = (size / n as f64).max(DVec3::splat(f64::MIN_POSITIVE));
        let mut grid = PoolGrid { boxes, lo, cell, n, start: vec![0; n * n + 1], items: Vec::new() };
        for pass in 0..2 {
            let mut fill = grid.start.clone();
            for (i, b) in grid.boxes.iter().enumerate() {
                let ((x0, x1), (y0, y1)) = grid.span(b);
                for x in x0..=x1 {
                    for y in y0..=y1 {
                        let c = x * n + y;
                        if pass == 0 {
                            grid.start[c + 1] += 1;
                        } else {
                            grid.items[fill[c] as usize] = i as u32;
                            fill[c] += 1;
                        }
                    }
                }
            }
            if pass == 0 {
                for c in 0..n * n {
                    grid.start[c + 1] += grid.start[c];
                }
                grid.items = vec![0; grid.start[n * n] as usize];
            }
        }
        grid
    }

    /// Cells covered by `b` along x and y (clamped to the grid).
    fn span(&self, b: &Aabb) -> ((usize, usize), (usize, usize)) {
        let at = |v: f64, k: usize| (((v - self.lo[k]) / self.cell[k]).floor().max(0.0) as usize).min(self.n - 1);
        ((at(b.min.x, 0), at(b.max.x, 0)), (at(b.min.y, 1), at(b.max.y, 1)))
    }

    /// Indices of the pool's polygons whose box meets `bx`, ascending.
    fn meeting(&self, bx: &Aabb) -> Vec<u32> {
        let mut found = Vec::new();
        if self.boxes.is_empty() {
            return found;
        }
        let ((x0, x1), (y0, y1)) = self.span(bx);
        for x in x0..=x1 {
            for y in y0..=y1 {
                let c = x * self.n + y;
                for &i in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
                    let b = &self.boxes[i as usize];
                    if (0..3).all(|k| b.min[k] <= bx.max[k] && b.max[k] >= bx.min[k]) {
                        found.push(i);
                    }
                }
            }
        }
        found.sort_unstable();
        found.dedup();
        found
    }
}
