//! The binned-SAH builder.

use glam::Vec3A;

use super::{Bvh, Child, Node, MAX_DEPTH};
use crate::accel::Aabb;

/// SAH bins per axis.
const BINS: usize = 12;

/// The state of a build: the nodes so far and the primitive order being partitioned.
struct Builder {
    nodes: Vec<Node>,
    prims: Vec<u32>,
}

impl Bvh {
    /// Builds over the given boxes (primitive `i` has box `boxes[i]`); leaves hold at
    /// most `leaf_size` primitives unless SAH finds no useful split.
    pub fn build(boxes: &[Aabb], leaf_size: usize) -> Bvh {
        if boxes.is_empty() {
            return Bvh::default();
        }
        let mut b = Builder { nodes: Vec::with_capacity(boxes.len() / 2), prims: (0..boxes.len() as u32).collect() };
        let centres: Vec<Vec3A> = boxes.iter().map(|b| b.centre()).collect();
        let (root_box, root) = b.node(boxes, &centres, 0, boxes.len(), 0, leaf_size.max(1));
        Bvh { nodes: b.nodes, root_box, root, prims: b.prims }
    }

    /// Builds like [`build`](Self::build) and returns the leaves' primitive order: the
    /// caller stores its primitives in that order, and the tree then names primitive `k`
    /// by its position `k` (no index array, one indirection less per primitive test).
    pub fn build_ordered(boxes: &[Aabb], leaf_size: usize) -> (Bvh, Vec<u32>) {
        let mut bvh = Bvh::build(boxes, leaf_size);
        let order = std::mem::take(&mut bvh.prims);
        (bvh, order)
    }
}

impl Builder {
    /// Builds the subtree over `prims[start..end]`; returns its box and reference.
    fn node(
        &mut self,
        boxes: &[Aabb],
        centres: &[Vec3A],
        start: usize,
        end: usize,
        depth: usize,
        leaf_size: usize,
    ) -> (Aabb, Child) {
        // One pass for the node's bounds and the bounds of the primitives' centres.
        let (bounds, cb) = self.prims[start..end].iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), &p| {
            let centre = centres[p as usize];
            (b.union(boxes[p as usize]), c.union(Aabb { min: centre, max: centre }))
        });
        let n = end - start;
        let leaf = (bounds, Child { index: start as u32, count: n as u32 });
        if n <= leaf_size || depth + 1 >= MAX_DEPTH {
            return leaf;
        }
        let Some(mid) = self.split(boxes, centres, start, end, bounds, cb) else {
            return leaf;
        };
        // The slot is taken before the children's, so a parent precedes its subtree.
        let at = self.nodes.len();
        self.nodes.push(Node::new(Aabb::EMPTY, Aabb::EMPTY, [Child { index: 0, count: 0 }; 2]));
        let (left_box, left) = self.node(boxes, centres, start, mid, depth + 1, leaf_size);
        let (right_box, right) = self.node(boxes, centres, mid, end, depth + 1, leaf_size);
        self.nodes[at] = Node::new(left_box, right_box, [left, right]);
        (bounds, Child { index: at as u32, count: 0 })
    }

    /// Binned SAH split of `prims[start..end]` (all three axes binned in one pass);
    /// partitions in place and returns the middle, or `None` when a leaf is cheaper.
    fn split(
        &mut self,
        boxes: &[Aabb],
        centres: &[Vec3A],
        start: usize,
        end: usize,
        bounds: Aabb,
        cb: Aabb,
    ) -> Option<usize> {
        let extent = cb.max - cb.min;
        let scale = Vec3A::select(extent.cmpgt(Vec3A::ZERO), Vec3A::splat(BINS as f32) / extent, Vec3A::ZERO);
        let bin_of = |c: Vec3A, axis: usize| (((c[axis] - cb.min[axis]) * scale[axis]) as usize).min(BINS - 1);
        let mut bin_box = [[Aabb::EMPTY; BINS]; 3];
        let mut bin_n = [[0usize; BINS]; 3];
        for &p in &self.prims[start..end] {
            let (c, b) = (centres[p as usize], boxes[p as usize]);
            for axis in 0..3 {
                let k = bin_of(c, axis);
                bin_box[axis][k] = bin_box[axis][k].union(b);
                bin_n[axis][k] += 1;
            }
        }
        let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, bin)
        for axis in 0..3 {
            if extent[axis] <= 0.0 {
                continue;
            }
            let mut right_area = [0.0f32; BINS];
            let mut right_n = [0usize; BINS];
            let (mut acc, mut acc_n) = (Aabb::EMPTY, 0);
            for b in (1..BINS).rev() {
                acc = acc.union(bin_box[axis][b]);
                acc_n += bin_n[axis][b];
                right_area[b] = acc.half_area();
                right_n[b] = acc_n;
            }
            let (mut acc, mut acc_n) = (Aabb::EMPTY, 0);
            for b in 0..BINS - 1 {
                acc = acc.union(bin_box[axis][b]);
                acc_n += bin_n[axis][b];
                if acc_n == 0 || right_n[b + 1] == 0 {
                    continue;
                }
                let cost = acc.half_area() * acc_n as f32 + right_area[b + 1] * right_n[b + 1] as f32;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, b));
                }
            }
        }
        let n = end - start;
        let leaf_cost = bounds.half_area() * n as f32;
        match best {
            Some((cost, axis, bin)) if cost < leaf_cost || n > 8 => {
                let slice = &mut self.prims[start..end];
                let mut left = 0;
                for i in 0..slice.len() {
                    if bin_of(centres[slice[i] as usize], axis) <= bin {
                        slice.swap(i, left);
                        left += 1;
                    }
                }
                Some(start + left)
            }
            // All centres coincide: split in the middle so the tree still divides.
            None if n > 8 => Some(start + n / 2),
            _ => None,
        }
    }
}
