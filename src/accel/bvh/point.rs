//! The point walk: the primitives nearest a point first, skipping what lies beyond a
//! threshold the caller lowers as it goes (a union's best value so far, say).

use glam::{Vec3A, Vec4, Vec4Swizzles};

use super::packet::splat3;
use super::{Bvh, Child, Deferred, Node};

impl Node {
    /// Squared distances from the point `p` (splat per axis) to the two children's
    /// boxes, in lanes 0 and 1 (0 inside): one pass of 4-wide arithmetic for both.
    #[inline(always)]
    fn outside2(&self, p: &[Vec4; 3]) -> Vec4 {
        let axis = |planes: Vec4, c: Vec4| {
            // Lanes 0, 1: min − p; lanes 2, 3: max − p, moved under 0, 1 and negated.
            let t = planes - c;
            let e = t.max(-t.zwxy()).max(Vec4::ZERO);
            e * e
        };
        axis(self.x, p[0]) + axis(self.y, p[1]) + axis(self.z, p[2])
    }
}

impl Bvh {
    /// Walks the leaves nearest `p` first, calling `prim(i)` for each primitive not
    /// skipped; `prim` returns the threshold from then on. A node is skipped when `p`
    /// lies outside its box (strictly) by at least the threshold (`start` at first), so
    /// every primitive skipped is at least the threshold away from `p`. With `prune`
    /// false nothing is skipped (the reference that tests compare with).
    #[inline]
    pub fn nearest_first(&self, p: Vec3A, start: f32, prune: bool, mut prim: impl FnMut(u32) -> f32) {
        let Some((root_box, root)) = self.root() else { return };
        let mut threshold = start;
        // Compared squared: `d ≥ threshold` for `d > 0` is `threshold ≤ 0 or d² ≥ threshold²`.
        let skip = |d2: f32, threshold: f32| prune && d2 > 0.0 && (threshold <= 0.0 || d2 >= threshold * threshold);
        if skip(root_box.outside_squared(p), threshold) {
            return;
        }
        let ps = splat3(p);
        let mut deferred = Deferred::<_>::new((Child { index: 0, count: 0 }, 0f32));
        let mut cur = root;
        loop {
            if cur.count > 0 {
                for k in cur.index..cur.index + cur.count {
                    threshold = prim(self.prim(k));
                }
            } else {
                let node = &self.nodes[cur.index as usize];
                let d2 = node.outside2(&ps);
                let (l, r) = (node.children[0], node.children[1]);
                let (near, far) = if d2.x <= d2.y { ((l, d2.x), (r, d2.y)) } else { ((r, d2.y), (l, d2.x)) };
                // The far child is no nearer, so it is skipped whenever the near one is.
                if !skip(near.1, threshold) {
                    if !skip(far.1, threshold) {
                        deferred.push(far);
                    }
                    cur = near.0;
                    continue;
                }
            }
            loop {
                let Some((next, d2)) = deferred.pop() else { return };
                if !skip(d2, threshold) {
                    cur = next;
                    break;
                }
            }
        }
    }
}
