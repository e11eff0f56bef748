//! A small binary BVH over the objects' boxes, in `f64` (the shaft tests need exact conservative
//! bounds, which the `f32` ray-casting BVH cannot give).

use crate::geom::Aabb;

/// Most objects in a leaf.
const LEAF_SIZE: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    /// Leaf: first index into `items`; inner: index of the left child (the right one follows it).
    first: u32,
    /// Number of items of a leaf; 0 for an inner node.
    count: u32,
}

/// The BVH: nodes in a flat vector, children of an inner node adjacent.
#[derive(Clone, Debug, Default)]
pub struct ObjectBvh {
    nodes: Vec<Node>,
    items: Vec<u32>,
}

impl ObjectBvh {
    /// Builds over `boxes` (object `k` has box `boxes[k]`) by median splits along the longest axis.
    #[must_use]
    pub fn build(boxes: &[Aabb]) -> ObjectBvh {
        let mut bvh = ObjectBvh { nodes: Vec::with_capacity(2 * boxes.len() / LEAF_SIZE + 1), items: (0..boxes.len() as u32).collect() };
        if boxes.is_empty() {
            return bvh;
        }
        bvh.nodes.push(Node { bounds: Aabb::EMPTY, first: 0, count: 0 });
        let mut stack = vec![(0usize, 0usize, boxes.len())];
        while let Some((node, start, end)) = stack.pop() {
            let mut bounds = Aabb::EMPTY;
            let mut centers = Aabb::EMPTY;
            for &i in &bvh.items[start..end] {
                bounds.merge(&boxes[i as usize]);
                centers.grow(boxes[i as usize].center());
            }
            if end - start <= LEAF_SIZE {
                bvh.nodes[node] = Node { bounds, first: start as u32, count: (end - start) as u32 };
                continue;
            }
            let axis = centers.longest_axis();
            let mid = (start + end) / 2;
            bvh.items[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
                boxes[a as usize].center()[axis].total_cmp(&boxes[b as usize].center()[axis]).then(a.cmp(&b))
            });
            let left = bvh.nodes.len();
            bvh.nodes.push(Node { bounds: Aabb::EMPTY, first: 0, count: 0 });
            bvh.nodes.push(Node { bounds: Aabb::EMPTY, first: 0, count: 0 });
            bvh.nodes[node] = Node { bounds, first: left as u32, count: 0 };
            stack.push((left + 1, mid, end));
            stack.push((left, start, mid));
        }
        bvh
    }

    /// Calls `hit(object)` for every object in a leaf whose node boxes all pass `node_test`, in a
    /// fixed (depth-first) order.
    pub fn traverse(&self, mut node_test: impl FnMut(&Aabb) -> bool, mut hit: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !node_test(&node.bounds) {
                continue;
            }
            if node.count > 0 {
                for &i in &self.items[node.first as usize..(node.first + node.count) as usize] {
                    hit(i);
                }
            } else {
                stack.push(node.first + 1);
                stack.push(node.first);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::DVec3;

    #[test]
    fn traversal_finds_exactly_the_overlapping_boxes() {
        let boxes: Vec<Aabb> = (0..50)
            .map(|k| {
                let c = DVec3::new((k % 7) as f64, (k / 7) as f64, (k % 3) as f64);
                Aabb { min: c, max: c + 0.5 }
            })
            .collect();
        let bvh = ObjectBvh::build(&boxes);
        let q = Aabb { min: DVec3::new(1.2, 1.2, 0.0), max: DVec3::new(3.1, 4.0, 0.7) };
        let overlaps = |b: &Aabb| b.min.cmple(q.max).all() && b.max.cmpge(q.min).all();
        let mut found = Vec::new();
        bvh.traverse(overlaps, |i| {
            if overlaps(&boxes[i as usize]) {
                found.push(i)
            }
        });
        found.sort_unstable();
        let expected: Vec<u32> = (0..50).filter(|&k| overlaps(&boxes[k as usize])).collect();
        assert_eq!(found, expected);
        assert!(!expected.is_empty());
    }
}
