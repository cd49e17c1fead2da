//! The single-ray walks: closest hit and any hit, front to back, and a walk that opens
//! the tree only as far along the ray as a march has come.

use glam::{Vec3A, Vec4, Vec4Swizzles};

use super::{Bvh, Child, Deferred, Node, STACK};
use crate::accel::aabb::enters4;

/// Per-ray constants of the two-box slab test, splat across lanes.
pub(super) struct RaySplat {
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    t_min: Vec4,
}

impl RaySplat {
    pub(super) fn new(origin: Vec3A, inv_dir: Vec3A, t_min: f32) -> RaySplat {
        RaySplat {
            origin: [Vec4::splat(origin.x), Vec4::splat(origin.y), Vec4::splat(origin.z)],
            inv_dir: [Vec4::splat(inv_dir.x), Vec4::splat(inv_dir.y), Vec4::splat(inv_dir.z)],
            t_min: Vec4::splat(t_min),
        }
    }

    /// Which of the node's two children the ray enters before `t_max` (bit 0 left,
    /// bit 1 right) and the entry distances (lanes 0 and 1). The same slab test as
    /// [`Aabb::slab`](crate::accel::Aabb::slab), including its robust far bound. A ray lying exactly in a face
    /// plane of a box makes `0 × ∞ = NaN` there and may miss that box, as it may in
    /// [`Aabb::slab`](crate::accel::Aabb::slab): it could only graze what the box holds, edge-on.
    #[inline(always)]
    pub(super) fn enters(&self, node: &Node, t_max: f32) -> (u32, Vec4) {
        self.enters_planes([node.x, node.y, node.z], t_max)
    }

    /// [`enters`](Self::enters) for a node's planes per axis (`[left.min, right.min,
    /// left.max, right.max]`), which a caller may have moved.
    #[inline(always)]
    fn enters_planes(&self, [x, y, z]: [Vec4; 3], t_max: f32) -> (u32, Vec4) {
        let axis = |planes: Vec4, k: usize| {
            let t = (planes - self.origin[k]) * self.inv_dir[k];
            // Lanes 2 and 3 moved to 0 and 1: each child's two planes side by side.
            let swapped = t.zwxy();
            (t.min(swapped), t.max(swapped))
        };
        let axes = [axis(x, 0), axis(y, 1), axis(z, 2)];
        let (enters, near) = enters4(axes, self.t_min, Vec4::splat(t_max));
        (enters & 0b11, near)
    }
}

impl Bvh {
    /// Visits leaves front to back along the ray. `visit(prim, t_max)` tests one primitive
    /// and returns its hit distance if closer than `t_max`; the closest hit wins.
    /// Returns the closest hit (primitive, t) and counts nodes visited into `visits`.
    #[inline]
    pub fn closest(
        &self,
        origin: Vec3A,
        inv_dir: Vec3A,
        t_min: f32,
        mut t_max: f32,
        visits: &mut u64,
        mut visit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<(u32, f32)> {
        let mut best = None;
        self.leaves(origin, inv_dir, t_min, &mut t_max, visits, |first, count, t_max| {
            for k in first..first + count {
                let p = self.prim(k);
                if let Some(t) = visit(p, *t_max) {
                    *t_max = t;
                    best = Some((p, t));
                }
            }
            false
        });
        best
    }

    /// Whether any primitive reports a hit (`visit` returns true); stops at the first.
    #[inline]
    pub fn any(
        &self,
        origin: Vec3A,
        inv_dir: Vec3A,
        t_min: f32,
        mut t_max: f32,
        visits: &mut u64,
        mut visit: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        let mut found = false;
        self.leaves(origin, inv_dir, t_min, &mut t_max, visits, |first, count, t_max| {
            found = (first..first + count).any(|k| visit(self.prim(k), *t_max));
            found
        });
        found
    }

    /// The primitive in leaf slot `k`.
    #[inline(always)]
    pub(super) fn prim(&self, k: u32) -> u32 {
        if self.prims.is_empty() {
            k
        } else {
            self.prims[k as usize]
        }
    }

    /// Visits leaves front to back along the ray: `leaf(first, count, t_max)` gets the
    /// leaf's slots `first..first + count`, may lower `t_max` to the closest hit so far,
    /// and returns true to stop the walk.
    #[inline]
    fn leaves(
        &self,
        origin: Vec3A,
        inv_dir: Vec3A,
        t_min: f32,
        t_max: &mut f32,
        visits: &mut u64,
        mut leaf: impl FnMut(u32, u32, &mut f32) -> bool,
    ) {
        if !self.wide.is_empty() {
            return self.block_leaves(origin, inv_dir, t_min, t_max, visits, |blocks, count, t_max| {
                leaf(self.blocks[blocks.start as usize].first, count, t_max)
            });
        }
        let Some((root_box, root)) = self.root() else { return };
        *visits += 1;
        if root_box.slab(origin, inv_dir, t_min, *t_max).is_none() {
            return;
        }
        // A lone leaf needs no stack. The loop below would handle it, but the top-level
        // tree of every one-object scene is one, and skipping the stack's set-up there
        // measured ~10% more primary rays per second on seed scene 1 (bench
        // `primary rays/intersect sdf/01-sphere`).
        if root.count > 0 {
            leaf(root.index, root.count, t_max);
            return;
        }
        let ray = RaySplat::new(origin, inv_dir, t_min);
        descend::<STACK>(root, t_max, visits, leaf, |index, t_max, deferred| {
            let node = &self.nodes[index as usize];
            let (enters, near) = ray.enters(node, t_max);
            // Branching on the order, and storing only a real deferral, measured faster
            // than a branchless select that always writes the stack (bench `primary
            // rays/intersect mesh-high/06-many-spheres`).
            let (next, later) = match enters {
                0 => return None,
                0b01 => (node.children[0], None),
                0b10 => (node.children[1], None),
                _ if near.x <= near.y => (node.children[0], Some((node.children[1], near.y))),
                _ => (node.children[1], Some((node.children[0], near.x))),
            };
            if let Some(later) = later {
                deferred.push(later);
            }
            Some(next)
        });
    }
}

/// The loop both single-ray walks share, from `root` (an interior node): a leaf goes to
/// `leaf` (true stops the walk), an interior node to `open(index, t_max, deferred)`,
/// which defers the children to come back to, with their entry distances, and returns
/// the one to go down now (`None`: the ray enters none). Deferred children are popped
/// last in first out, and one that starts beyond the closest hit found since is skipped
/// without testing its box again.
#[inline(always)]
pub(super) fn descend<const N: usize>(
    root: Child,
    t_max: &mut f32,
    visits: &mut u64,
    mut leaf: impl FnMut(u32, u32, &mut f32) -> bool,
    mut open: impl FnMut(u32, f32, &mut Deferred<(Child, f32), N>) -> Option<Child>,
) {
    let mut deferred = Deferred::<(Child, f32), N>::new((Child { index: 0, count: 0 }, 0f32));
    let mut cur = root;
    loop {
        if cur.count > 0 {
            if leaf(cur.index, cur.count, t_max) {
                return;
            }
        } else {
            *visits += 1;
            if let Some(next) = open(cur.index, *t_max, &mut deferred) {
                cur = next;
                continue;
            }
        }
        loop {
            let Some((next, t_near)) = deferred.pop() else { return };
            if t_near <= *t_max {
                cur = next;
                break;
            }
        }
    }
}

/// A walk along one ray that opens nodes only up to the distance a caller has reached,
/// to be resumed further on: what a sphere tracer needs when every primitive whose box
/// the ray has entered by `t` must be known before stepping from `t`, and nothing
/// beyond its hit should be opened. The nodes not yet opened, with the distance at
/// which the ray enters each, live in a caller's vector so a march allocates nothing.
pub(crate) struct RayWalk<'a> {
    bvh: &'a Bvh,
    ray: RaySplat,
    t_max: f32,
    /// Added to every node's planes: every box grown by the same margin.
    grow: Vec4,
}

impl Bvh {
    /// A walk along `origin + t·dir` (`inv_dir` its reciprocal) over `[t_min, t_max]`
    /// through every box grown by `grow` on each side; `closed` is cleared and receives
    /// the root if the ray enters its box.
    pub(crate) fn ray_walk(
        &self,
        origin: Vec3A,
        inv_dir: Vec3A,
        (t_min, t_max): (f32, f32),
        grow: f32,
        closed: &mut Vec<(Child, f32)>,
    ) -> RayWalk<'_> {
        closed.clear();
        if let Some((root_box, root)) = self.root() {
            if let Some((near, _)) = root_box.grow(grow).slab(origin, inv_dir, t_min, t_max) {
                closed.push((root, near));
            }
        }
        let grow = Vec4::new(-grow, -grow, grow, grow);
        RayWalk { bvh: self, ray: RaySplat::new(origin, inv_dir, t_min), t_max, grow }
    }
}

impl RayWalk<'_> {
    /// Opens every node in `closed` the ray enters at or before `t`, and their children
    /// likewise, calling `prim` for each primitive of the leaves opened (each once over
    /// the walk); returns the nearest entry among the nodes left closed (infinity when
    /// none are), before which no further primitive's box begins.
    #[inline]
    pub(crate) fn open_until(
        &self,
        t: f32,
        closed: &mut Vec<(Child, f32)>,
        visits: &mut u64,
        mut prim: impl FnMut(u32),
    ) -> f32 {
        // The vector is short (about one node per level passed), so a scan beats a heap;
        // scanning from the end opens the children just pushed first, depth first.
        while let Some(at) = closed.iter().rposition(|&(_, near)| near <= t) {
            let (child, _) = closed.swap_remove(at);
            if child.count > 0 {
                (child.index..child.index + child.count).for_each(|k| prim(self.bvh.prim(k)));
                continue;
            }
            *visits += 1;
            let node = &self.bvh.nodes[child.index as usize];
            let planes = [node.x + self.grow, node.y + self.grow, node.z + self.grow];
            let (enters, near) = self.ray.enters_planes(planes, self.t_max);
            if enters & 1 != 0 {
                closed.push((node.children[0], near.x));
            }
            if enters & 2 != 0 {
                closed.push((node.children[1], near.y));
            }
        }
        closed.iter().fold(f32::INFINITY, |m, &(_, near)| m.min(near))
    }
}
