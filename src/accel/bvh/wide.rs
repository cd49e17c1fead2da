//! Four-wide nodes for the single-ray walks over a mesh's triangles: the binary tree
//! collapsed so that a visit tests four boxes at once and the chain of dependent node
//! loads from the root to a leaf is about half as long. A walk over a large mesh waits
//! on memory, one node per level (`perf annotate` put 48 % of its samples on the first
//! use of each node's boxes, `docs/light.md`); halving the levels halves those waits.
//!
//! The binary nodes stay: the packet walks, the resumable ray walk and the point walks
//! use them, and the builder makes them first.

use glam::{Vec3A, Vec4};

use super::{Bvh, Child, Node};
use crate::accel::aabb::enters4;

/// Four children's boxes across lanes: `planes[axis]` their minima and `planes[3 + axis]`
/// their maxima. An unused lane holds an empty box (minima +∞, maxima −∞), which no ray
/// enters because the walk takes each axis's near plane by the ray's direction.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(super) struct Wide {
    planes: [Vec4; 6],
    children: [Child; 4],
}

/// An unused lane's child (never entered: its box is empty).
const NONE: Child = Child { index: 0, count: 0 };

/// A node with every lane unused, filled lane by lane.
const EMPTY: Wide = Wide {
    planes: [
        Vec4::INFINITY,
        Vec4::INFINITY,
        Vec4::INFINITY,
        Vec4::NEG_INFINITY,
        Vec4::NEG_INFINITY,
        Vec4::NEG_INFINITY,
    ],
    children: [NONE; 4],
};

impl Bvh {
    /// Adds the four-wide copy of the tree that [`closest`](Bvh::closest) and
    /// [`any`](Bvh::any) then walk (`nodes` stay for the other walks).
    pub fn widen(&mut self) {
        self.wide.clear();
        let Some((_, root)) = self.root() else { return };
        if root.count > 0 {
            return;
        }
        let mut wide = Vec::with_capacity(self.nodes.len() / 2 + 1);
        collapse(&self.nodes, root.index, &mut wide);
        self.wide = wide;
    }

    /// Bytes of the four-wide copy.
    pub(super) fn wide_bytes(&self) -> usize {
        self.wide.len() * std::mem::size_of::<Wide>()
    }

    /// [`leaves`](Bvh::leaves) over the four-wide nodes, whose root is `wide[0]`.
    #[inline]
    pub(super) fn wide_leaves(
        &self,
        origin: Vec3A,
        inv_dir: Vec3A,
        t_min: f32,
        t_max: &mut f32,
        visits: &mut u64,
        leaf: impl FnMut(u32, u32, &mut f32) -> bool,
    ) {
        // Each axis's near plane is the minimum where the ray goes up it: lanes [0, 3)
        // or [3, 6) of the planes, picked once per ray.
        let up = [inv_dir.x >= 0.0, inv_dir.y >= 0.0, inv_dir.z >= 0.0];
        let near = [0, 1, 2].map(|k| if up[k] { k } else { 3 + k });
        let far = [0, 1, 2].map(|k| if up[k] { 3 + k } else { k });
        let o = [Vec4::splat(origin.x), Vec4::splat(origin.y), Vec4::splat(origin.z)];
        let inv = [Vec4::splat(inv_dir.x), Vec4::splat(inv_dir.y), Vec4::splat(inv_dir.z)];
        let t_low = Vec4::splat(t_min);
        let root = Child { index: 0, count: 0 };
        super::walk::descend::<WIDE_STACK>(root, t_max, visits, leaf, |index, t_max, deferred| {
            let node = &self.wide[index as usize];
            let axis = |k: usize| ((node.planes[near[k]] - o[k]) * inv[k], (node.planes[far[k]] - o[k]) * inv[k]);
            let (mut enters, entry) = enters4([axis(0), axis(1), axis(2)], t_low, Vec4::splat(t_max));
            enters &= 0b1111;
            if enters == 0 {
                return None;
            }
            // The lanes entered, nearest first: the nearest is walked now, the others
            // deferred farthest first so the next nearest pops first.
            let entry = entry.to_array();
            let mut order = [0usize; 4];
            let mut n = 0;
            while enters != 0 {
                let k = enters.trailing_zeros() as usize;
                enters &= enters - 1;
                let mut at = n;
                while at > 0 && entry[order[at - 1]] > entry[k] {
                    order[at] = order[at - 1];
                    at -= 1;
                }
                order[at] = k;
                n += 1;
            }
            for &k in order[1..n].iter().rev() {
                deferred.push((node.children[k], entry[k]));
            }
            Some(node.children[order[0]])
        });
    }
}

/// Deferred children a four-wide walk keeps on the call stack: up to three a level.
const WIDE_STACK: usize = 48;

/// Appends the four-wide node made from binary node `index` and, after it, those of its
/// descendants; returns its place in `wide`.
///
/// Each node takes the binary node's two children and opens the largest interior one
/// among them (by surface area) until it holds four or only leaves: the children a ray
/// is likeliest to enter are the ones worth testing together.
fn collapse(nodes: &[Node], index: u32, wide: &mut Vec<Wide>) -> u32 {
    let at = wide.len();
    wide.push(EMPTY);
    let node = &nodes[index as usize];
    let mut kids: Vec<(crate::accel::Aabb, Child)> = (0..2).map(|k| (node.child_box(k), node.children[k])).collect();
    while kids.len() < 4 {
        let open = kids
            .iter()
            .enumerate()
            .filter(|(_, (_, c))| c.count == 0)
            .max_by(|a, b| a.1 .0.half_area().total_cmp(&b.1 .0.half_area()))
            .map(|(k, _)| k);
        let Some(k) = open else { break };
        let (_, c) = kids.swap_remove(k);
        let n = &nodes[c.index as usize];
        kids.extend((0..2).map(|j| (n.child_box(j), n.children[j])));
    }
    let mut made = EMPTY;
    for (lane, (b, c)) in kids.into_iter().enumerate() {
        for axis in 0..3 {
            made.planes[axis][lane] = b.min[axis];
            made.planes[3 + axis][lane] = b.max[axis];
        }
        made.children[lane] = if c.count > 0 { c } else { Child { index: collapse(nodes, c.index, wide), count: 0 } };
    }
    wide[at] = made;
    at as u32
}
