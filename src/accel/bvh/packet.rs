//! The packet walk: `N` groups of four coherent rays follow their first active ray
//! through one tree.

use glam::{Vec3A, Vec4, Vec4Swizzles};

use super::walk::RaySplat;
use super::{Bvh, Child, Deferred, Node};
use crate::accel::aabb::{enters4, ROBUST};

/// Four rays in SIMD lanes (structure of arrays) for the packet walk
/// [`Bvh::each_packet`]: lane `k` holds ray `k`'s origin, `1 / dir` and `t_min`.
#[derive(Clone, Copy, Debug)]
pub struct Rays4 {
    /// Origin components, one vector per axis.
    pub origin: [Vec4; 3],
    /// `1 / dir` components, one vector per axis.
    pub inv_dir: [Vec4; 3],
    /// Nearest accepted distance per lane.
    pub t_min: Vec4,
}

impl Rays4 {
    /// Which lanes of `mask` enter `b` before their `t_max`, and the entry distances. Per
    /// lane this is exactly [`RaySplat::enters`]'s arithmetic for one child (same operand
    /// order in every `min`/`max`), so a lane enters a box here exactly when the same ray
    /// traced alone would.
    #[inline(always)]
    fn enters(&self, min: [Vec4; 3], max: [Vec4; 3], t_max: Vec4, mask: u32) -> (u32, Vec4) {
        let axis = |k: usize| {
            let t0 = (min[k] - self.origin[k]) * self.inv_dir[k];
            let t1 = (max[k] - self.origin[k]) * self.inv_dir[k];
            (t0.min(t1), t0.max(t1))
        };
        let (enters, near) = enters4([axis(0), axis(1), axis(2)], self.t_min, t_max);
        (enters & mask, near)
    }
}

/// The four lanes of group `g` in a packet's mask.
#[inline(always)]
pub fn group_lanes(mask: u32, g: usize) -> u32 {
    (mask >> (4 * g)) & 0b1111
}

/// The lanes of `mask` from lane `first` on.
#[inline(always)]
fn lanes_from(mask: u32, first: usize) -> u32 {
    mask & (u32::MAX << first)
}

/// The lanes of `mask` after lane `first`.
#[inline(always)]
fn lanes_after(mask: u32, first: usize) -> u32 {
    mask & (u32::MAX << first << 1)
}

/// Lane `lane` of a packet's per-lane values.
#[inline(always)]
fn lane_value<const N: usize>(v: &[Vec4; N], lane: usize) -> f32 {
    v[lane / 4][lane % 4]
}

/// The single-ray splat of one lane of a packet.
#[inline]
fn lane_splat<const N: usize>(rays: &[Rays4; N], lane: usize) -> RaySplat {
    let (r, l) = (&rays[lane / 4], lane % 4);
    let pick = |v: &[Vec4; 3]| Vec3A::new(v[0][l], v[1][l], v[2][l]);
    RaySplat::new(pick(&r.origin), pick(&r.inv_dir), r.t_min[l])
}

/// The lowest lane of `lanes` that enters the box `(min, max)` before its `t_max`, with
/// its entry distance; groups after the first that has one are not tested.
#[inline]
fn first_entering<const N: usize>(
    rays: &[Rays4; N],
    (min, max): ([Vec4; 3], [Vec4; 3]),
    t_max: &[Vec4; N],
    lanes: u32,
) -> Option<(usize, f32)> {
    for g in 0..N {
        let lanes = group_lanes(lanes, g);
        if lanes != 0 {
            let (m, near) = rays[g].enters(min, max, t_max[g], lanes);
            if m != 0 {
                let l = m.trailing_zeros() as usize & 3;
                return Some((4 * g + l, near[l]));
            }
        }
    }
    None
}

/// Bounds on every ray of a packet, for rejecting a node's child for all of them in one
/// test (interval arithmetic over origins, `1 / dir` and `[t_min, t_max]`).
struct Frustum {
    /// Least and greatest origin component, splat across lanes, per axis.
    origin: [[Vec4; 3]; 2],
    /// Least and greatest `1 / dir` component, splat across lanes, per axis.
    inv_dir: [[Vec4; 3]; 2],
    t_min: Vec4,
    t_max: Vec4,
}

impl Frustum {
    /// The bounds of all the packet's lanes (unwanted lanes too: a wider frustum is
    /// still a bound), or `None` when a component is not finite (a direction along a
    /// plane makes `1 / dir` infinite, where bounds would be NaN).
    #[inline]
    fn new<const N: usize>(rays: &[Rays4; N], t_max: &[Vec4; N]) -> Option<Frustum> {
        let [mut o_lo, mut i_lo] = [rays[0].origin, rays[0].inv_dir];
        let [mut o_hi, mut i_hi] = [o_lo, i_lo];
        let (mut t_min, mut t_far) = (rays[0].t_min, t_max[0]);
        for g in 1..N {
            for k in 0..3 {
                (o_lo[k], o_hi[k]) = (o_lo[k].min(rays[g].origin[k]), o_hi[k].max(rays[g].origin[k]));
                (i_lo[k], i_hi[k]) = (i_lo[k].min(rays[g].inv_dir[k]), i_hi[k].max(rays[g].inv_dir[k]));
            }
            (t_min, t_far) = (t_min.min(rays[g].t_min), t_far.max(t_max[g]));
        }
        let lo = |v: [Vec4; 3]| Vec3A::new(v[0].min_element(), v[1].min_element(), v[2].min_element());
        let hi = |v: [Vec4; 3]| Vec3A::new(v[0].max_element(), v[1].max_element(), v[2].max_element());
        let (origin, inv_dir) = ([lo(o_lo), hi(o_hi)], [lo(i_lo), hi(i_hi)]);
        let (t_min, t_max) = (t_min.min_element(), t_far.max_element());
        // Checked on the four bounds, not on their splats: this runs once per walk.
        let finite = (origin[0].is_finite() & origin[1].is_finite())
            & (inv_dir[0].is_finite() & inv_dir[1].is_finite())
            & (t_min.is_finite() & !t_max.is_nan());
        finite.then(|| Frustum {
            origin: origin.map(splat3),
            inv_dir: inv_dir.map(splat3),
            t_min: Vec4::splat(t_min),
            t_max: Vec4::splat(t_max),
        })
    }

    /// The node's children that no ray of the packet enters (bit 0 left, bit 1 right).
    /// Conservative with the single-ray test's rounding: each bound is an end of the
    /// same f32 operations on interval ends, and rounding is monotonic, so no ray's
    /// entry is below the lower bound nor its exit above the upper one.
    #[inline]
    fn misses(&self, node: &Node) -> u32 {
        let mut near = self.t_min;
        let mut far = Vec4::INFINITY;
        for (axis, planes) in [node.x, node.y, node.z].into_iter().enumerate() {
            // Lanes: left min, right min, left max, right max plane.
            let (x0, x1) = (planes - self.origin[1][axis], planes - self.origin[0][axis]);
            let (i0, i1) = (self.inv_dir[0][axis], self.inv_dir[1][axis]);
            let (a, b, c, d) = (x0 * i0, x0 * i1, x1 * i0, x1 * i1);
            let (lo, hi) = (a.min(b).min(c.min(d)), a.max(b).max(c.max(d)));
            near = near.max(lo.min(lo.zwxy()));
            far = far.min(hi.max(hi.zwxy()));
        }
        let far = (far * ROBUST).min(self.t_max);
        near.cmpgt(far).bitmask() & 0b11
    }
}

/// A point in every lane: one vector per axis, as [`Rays4`] holds its components.
#[inline(always)]
pub fn splat3(p: Vec3A) -> [Vec4; 3] {
    [Vec4::splat(p.x), Vec4::splat(p.y), Vec4::splat(p.z)]
}

/// The planes of child `k` of a node, splat across lanes: `(min, max)` per axis.
#[inline(always)]
fn child_planes(node: &Node, k: usize) -> ([Vec4; 3], [Vec4; 3]) {
    let splat = |v: Vec4, lane: usize| Vec4::splat(v[lane]);
    (
        [splat(node.x, k), splat(node.y, k), splat(node.z, k)],
        [splat(node.x, k + 2), splat(node.y, k + 2), splat(node.z, k + 2)],
    )
}

impl Bvh {
    /// Visits the primitives along a packet of coherent rays: `N` groups of four in SIMD
    /// lanes, lane `l` of group `g` being bit `4g + l` of the masks. `visit(prim, lanes,
    /// t_max)` gets each primitive with a mask of lanes and may lower those lanes' `t_max`
    /// to a hit.
    ///
    /// The walk follows the packet's first active ray (Wald, Boulos and Shirley 2007): a
    /// node's children are tested for that ray alone, with the single-ray test's
    /// arithmetic, and only a child it does not enter is tested for the rays after it,
    /// the lowest of which that enters becomes the child's first active ray. A ray is
    /// dropped only where it was tested and missed, so every ray reaches every primitive
    /// it would reach traced alone with its final `t_max`, and some more (which the
    /// caller's exact test turns away): its closest hit is the one
    /// [`closest`](Self::closest) finds up to rounding. Leaves come front to back for the
    /// first active ray. Counts one visit per node for each wanted ray from the first
    /// active one.
    ///
    /// Long because the walk keeps its stack and the packet's masks in registers; split
    /// into calls, they would go through memory on the hottest path of a mesh scene.
    #[inline]
    pub fn each_packet<const N: usize>(
        &self,
        rays: &[Rays4; N],
        mask: u32,
        t_max: &mut [Vec4; N],
        visits: &mut u64,
        mut visit: impl FnMut(u32, u32, &mut [Vec4; N]),
    ) {
        let Some((root_box, root)) = self.root() else { return };
        let mut leaf = |first: u32, count: u32, lanes: u32, t_max: &mut [Vec4; N]| {
            for k in first..first + count {
                visit(self.prim(k), lanes, t_max);
            }
        };
        *visits += u64::from(mask.count_ones());
        let Some((mut first, _)) = first_entering(rays, (splat3(root_box.min), splat3(root_box.max)), t_max, mask)
        else {
            return;
        };
        if root.count > 0 {
            leaf(root.index, root.count, lanes_from(mask, first), t_max);
            return;
        }
        // Deferred children: the child, its first active ray and that ray's entry distance,
        // and where its box is (parent node, child slot) should that ray be done with it.
        let mut deferred_children = Deferred::<_>::new((Child { index: 0, count: 0 }, 0usize, 0f32, 0u32, 0usize));
        let mut ray = lane_splat(rays, first);
        // For one group of four, testing the group itself costs what the frustum would.
        let frustum = if N > 1 { Frustum::new(rays, t_max) } else { None };
        let mut cur = root;
        loop {
            if cur.count > 0 {
                leaf(cur.index, cur.count, lanes_from(mask, first), t_max);
            } else {
                let lanes = lanes_from(mask, first);
                *visits += u64::from(lanes.count_ones());
                let node = &self.nodes[cur.index as usize];
                let (enters, near) = ray.enters(node, lane_value(t_max, first));
                // Children the first ray misses and no ray can enter.
                let missed = match &frustum {
                    Some(f) if enters != 0b11 => f.misses(node),
                    _ => 0,
                };
                // A child the first ray misses is the next entering ray's, if any: the
                // child, its first ray, that ray's entry and the child's slot.
                let child = |k: usize| -> Option<(Child, usize, f32, usize)> {
                    let (first, near) = if enters & (1 << k) != 0 {
                        (first, near[k])
                    } else if missed & (1 << k) != 0 {
                        return None;
                    } else {
                        first_entering(rays, child_planes(node, k), t_max, lanes_after(mask, first))?
                    };
                    Some((node.children[k], first, near, k))
                };
                let entered = match (child(0), child(1)) {
                    (None, None) => None,
                    (Some(next), None) | (None, Some(next)) => Some((next, None)),
                    (Some(a), Some(b)) => {
                        // The child of the lower first ray, or of the nearer entry for one ray.
                        let (next, later) = if (a.1, a.2) <= (b.1, b.2) { (a, b) } else { (b, a) };
                        Some((next, Some((later.0, later.1, later.2, cur.index, later.3))))
                    }
                };
                if let Some(((next, next_first, _, _), later)) = entered {
                    if let Some(later) = later {
                        deferred_children.push(later);
                    }
                    cur = next;
                    if next_first != first {
                        first = next_first;
                        ray = lane_splat(rays, first);
                    }
                    continue;
                }
            }
            loop {
                let Some((next, f, near, parent, k)) = deferred_children.pop() else { return };
                let f = if near <= lane_value(t_max, f) {
                    f
                } else {
                    // That ray has hit something nearer: the rays after it, if any enter.
                    let planes = child_planes(&self.nodes[parent as usize], k);
                    match first_entering(rays, planes, t_max, lanes_after(mask, f)) {
                        Some((f, _)) => f,
                        None => continue,
                    }
                };
                cur = next;
                if f != first {
                    first = f;
                    ray = lane_splat(rays, first);
                }
                break;
            }
        }
    }
}
