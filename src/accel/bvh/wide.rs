//! Four-wide nodes for the single-ray walks over a mesh's triangles: the binary tree
//! collapsed so that a visit tests four boxes at once and the chain of dependent node
//! loads from the root to a leaf is about half as long. A walk over a large mesh waits
//! on memory, one node per level (`perf annotate` put 48 % of its samples on the first
//! use of each node's boxes, `docs/light.md`); halving the levels halves those waits,
//! and quantising the boxes to bytes (as Embree's and Ylitie et al.'s compressed wide
//! BVHs do) makes a node one cache line instead of two.
//!
//! The binary nodes stay: the packet walks, the resumable ray walk and the point walks
//! use them, and the builder makes them first.

use glam::{Vec3A, Vec4};

use super::{Bvh, Child, LeafBlock, Node};
use crate::accel::aabb::enters4;

/// Four children's boxes, quantised against the node's own box: one cache line a node,
/// half the unquantised layout's two, so twice as much of a large mesh's tree stays in
/// cache (the walk waits on its nodes' first loads). Each plane is a byte `q` standing
/// for [`decode`]`(origin, exponent, q)`, rounded outwards ([`quantise`]) when the node is made and
/// checked there in the walk's own arithmetic, so a quantised box always holds its
/// child's box: a ray enters every box it entered before, and a few more.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(super) struct Wide {
    /// The node's box minimum, which every lane's planes are measured from.
    origin: [f32; 3],
    /// Per axis, the quantum's power of two.
    exponent: [i8; 3],
    /// The lanes in use, a bit each: an unused lane is never entered.
    used: u8,
    /// Leaf children's primitive counts; 0 for an interior child.
    counts: [u8; 4],
    /// Each lane's planes in quanta: `q[axis]` the minima, `q[3 + axis]` the maxima.
    q: [[u8; 4]; 6],
    /// Each lane's child: a leaf's first block in `blocks`, or an interior node's place
    /// in `wide`.
    index: [u32; 4],
}

/// A node with no lane in use, filled lane by lane.
const EMPTY: Wide = Wide { origin: [0.0; 3], exponent: [0; 3], used: 0, counts: [0; 4], q: [[0; 4]; 6], index: [0; 4] };

/// The plane a quantised coordinate stands for: `origin + q·2^exponent` in f32, a
/// multiply and an add, exactly as the walk computes it lane by lane.
#[inline(always)]
fn decode(origin: f32, exponent: i8, q: u8) -> f32 {
    origin + f32::from(q) * quantum(exponent)
}

/// `2^exponent` (`exponent` within f32's normal range, which [`quantise`] keeps).
#[inline(always)]
fn quantum(exponent: i8) -> f32 {
    f32::from_bits(((i32::from(exponent) + 127) as u32) << 23)
}

/// The exponent of one axis of a node spanning `[origin, top]`: the smallest quantum
/// whose 255 steps reach the top (and pass the origin), counted in [`decode`]'s rounded
/// arithmetic, since near a large origin a step may round away; `None` if the extent is
/// not finite.
fn exponent(origin: f32, top: f32) -> Option<i8> {
    if !(origin.is_finite() && top.is_finite() && origin <= top) {
        return None;
    }
    let wanted = ((top - origin) / 255.0).log2().ceil();
    let mut e = if wanted.is_finite() { (wanted as i32).clamp(-126, 127) } else { -126 };
    loop {
        let end = decode(origin, e as i8, 255);
        if end >= top && end > origin {
            return Some(e as i8);
        }
        if e >= 127 {
            return None;
        }
        e += 1;
    }
}

/// One lane's planes on an axis of [`exponent`] `e` from `origin`, rounded outwards as
/// [`decode`] computes them: the largest `q` not above `lo` (0, the origin, never is)
/// and the smallest not below `hi` (255 is at least the node's top).
fn quantise(origin: f32, e: i8, (lo, hi): (f32, f32)) -> (u8, u8) {
    let step = quantum(e);
    let mut q_lo = ((lo - origin) / step).floor().clamp(0.0, 255.0) as u8;
    while q_lo > 0 && decode(origin, e, q_lo) > lo {
        q_lo -= 1;
    }
    while q_lo < 255 && decode(origin, e, q_lo + 1) <= lo {
        q_lo += 1;
    }
    let mut q_hi = ((hi - origin) / step).ceil().clamp(0.0, 255.0) as u8;
    while q_hi < 255 && decode(origin, e, q_hi) < hi {
        q_hi += 1;
    }
    while q_hi > 0 && decode(origin, e, q_hi - 1) >= hi {
        q_hi -= 1;
    }
    (q_lo, q_hi)
}

impl Bvh {
    /// Adds the four-wide copy of the tree that [`closest`](Bvh::closest) and
    /// [`any`](Bvh::any) then walk (`nodes` stay for the other walks). A tree a
    /// quantised node cannot hold (a leaf of more than 255 primitives, a box that is not
    /// finite) stays binary: the walks are the same either way, only slower.
    pub fn widen(&mut self) {
        self.wide.clear();
        self.blocks.clear();
        let Some((_, root)) = self.root() else { return };
        if root.count > 0 {
            return;
        }
        let mut made = (Vec::with_capacity(self.nodes.len() / 2 + 1), Vec::with_capacity(self.nodes.len() / 2 + 1));
        if collapse(&self.nodes, root.index, &mut made).is_some() {
            (self.wide, self.blocks) = made;
        }
    }

    /// The four-wide tree's leaves in blocks of up to four slots, numbered as
    /// [`block_leaves`](Bvh::block_leaves) hands them out; empty unless the tree was
    /// [widened](Bvh::widen).
    pub fn blocks(&self) -> &[LeafBlock] {
        &self.blocks
    }

    /// Bytes of the four-wide copy.
    pub(super) fn wide_bytes(&self) -> usize {
        self.wide.len() * std::mem::size_of::<Wide>() + self.blocks.len() * std::mem::size_of::<LeafBlock>()
    }

    /// Visits the four-wide tree's leaves front to back along the ray, a leaf as its
    /// blocks: `leaf(blocks, slots, t_max)` gets the leaf's range of [`blocks`](Bvh::blocks)
    /// and its number of slots, may lower `t_max` to the closest hit so far, and returns
    /// true to stop the walk. Only for a widened tree (`blocks` not empty); the root box
    /// is tested here. The slot-naming walks take it on a widened tree.
    #[inline]
    pub fn block_leaves(
        &self,
        origin: Vec3A,
        inv_dir: Vec3A,
        t_min: f32,
        t_max: &mut f32,
        visits: &mut u64,
        mut leaf: impl FnMut(std::ops::Range<u32>, u32, &mut f32) -> bool,
    ) {
        debug_assert!(!self.wide.is_empty());
        *visits += 1;
        if self.root_box.slab(origin, inv_dir, t_min, *t_max).is_none() {
            return;
        }
        // Each axis's near plane is the minimum where the ray goes up it: lanes [0, 3)
        // or [3, 6) of the planes, picked once per ray.
        let up = [inv_dir.x >= 0.0, inv_dir.y >= 0.0, inv_dir.z >= 0.0];
        let near = [0, 1, 2].map(|k| if up[k] { k } else { 3 + k });
        let far = [0, 1, 2].map(|k| if up[k] { 3 + k } else { k });
        let o = [Vec4::splat(origin.x), Vec4::splat(origin.y), Vec4::splat(origin.z)];
        let inv = [Vec4::splat(inv_dir.x), Vec4::splat(inv_dir.y), Vec4::splat(inv_dir.z)];
        let t_low = Vec4::splat(t_min);
        let root = Child { index: 0, count: 0 };
        let leaf = |first: u32, count: u32, t_max: &mut f32| leaf(first..first + count.div_ceil(4), count, t_max);
        super::walk::descend::<WIDE_STACK>(root, t_max, visits, leaf, |index, t_max, deferred| {
            let node = &self.wide[index as usize];
            let axis = |k: usize| {
                let (base, step) = (Vec4::splat(node.origin[k]), Vec4::splat(quantum(node.exponent[k])));
                // `decode`, lane by lane.
                let plane = |q: [u8; 4]| base + Vec4::from_array(q.map(f32::from)) * step;
                ((plane(node.q[near[k]]) - o[k]) * inv[k], (plane(node.q[far[k]]) - o[k]) * inv[k])
            };
            let (mut enters, entry) = enters4([axis(0), axis(1), axis(2)], t_low, Vec4::splat(t_max));
            enters &= u32::from(node.used);
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
            let child = |k: usize| Child { index: node.index[k], count: u32::from(node.counts[k]) };
            for &k in order[1..n].iter().rev() {
                deferred.push((child(k), entry[k]));
            }
            Some(child(order[0]))
        });
    }
}

/// Deferred children a four-wide walk keeps on the call stack: up to three a level.
const WIDE_STACK: usize = 48;

/// Appends the four-wide node made from binary node `index` and, after it, those of its
/// descendants, and their leaves' blocks, in the order the nodes name them; returns its
/// place in `wide`, or `None` if some node cannot be quantised.
///
/// Each node takes the binary node's two children and opens the largest interior one
/// among them (by surface area) until it holds four or only leaves: the children a ray
/// is likeliest to enter are the ones worth testing together.
fn collapse(nodes: &[Node], index: u32, made_so_far: &mut (Vec<Wide>, Vec<LeafBlock>)) -> Option<u32> {
    let at = made_so_far.0.len();
    made_so_far.0.push(EMPTY);
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
    let whole = kids.iter().fold(crate::accel::Aabb::EMPTY, |b, (k, _)| b.union(*k));
    let mut made = EMPTY;
    for axis in 0..3 {
        let (origin, e) = (whole.min[axis], exponent(whole.min[axis], whole.max[axis])?);
        made.origin[axis] = origin;
        made.exponent[axis] = e;
        for (lane, (b, _)) in kids.iter().enumerate() {
            (made.q[axis][lane], made.q[3 + axis][lane]) = quantise(origin, e, (b.min[axis], b.max[axis]));
        }
    }
    for (lane, (_, c)) in kids.into_iter().enumerate() {
        made.used |= 1 << lane;
        if c.count > 0 {
            made.counts[lane] = u8::try_from(c.count).ok()?;
            let blocks = &mut made_so_far.1;
            made.index[lane] = blocks.len() as u32;
            blocks
                .extend((0..c.count).step_by(4).map(|k| LeafBlock { first: c.index + k, count: (c.count - k).min(4) }));
        } else {
            made.index[lane] = collapse(nodes, c.index, made_so_far)?;
        }
    }
    made_so_far.0[at] = made;
    Some(at as u32)
}

/// A quantised node is one cache line.
const _: () = assert!(std::mem::size_of::<Wide>() == 64);

#[cfg(test)]
impl Bvh {
    /// Whether every quantised lane's box holds the exact union of the primitive boxes
    /// below it, with the quantised boxes' summed half-area over the exact ones' (how
    /// much looser quantising made the tree).
    pub(super) fn wide_holds(&self, boxes: &[crate::accel::Aabb]) -> (bool, f64) {
        use crate::accel::Aabb;
        fn below(bvh: &Bvh, boxes: &[Aabb], index: u32, ok: &mut bool, area: &mut (f64, f64)) -> Aabb {
            let node = &bvh.wide[index as usize];
            let mut whole = Aabb::EMPTY;
            for lane in (0..4).filter(|&l| node.used & (1 << l) != 0) {
                let exact = if node.counts[lane] > 0 {
                    let first = bvh.blocks[node.index[lane] as usize].first;
                    (first..first + u32::from(node.counts[lane]))
                        .fold(Aabb::EMPTY, |b, k| b.union(boxes[bvh.prim(k) as usize]))
                } else {
                    below(bvh, boxes, node.index[lane], ok, area)
                };
                let plane = |axis: usize, q: u8| decode(node.origin[axis], node.exponent[axis], q);
                let min = Vec3A::from_array([0, 1, 2].map(|a| plane(a, node.q[a][lane])));
                let max = Vec3A::from_array([0, 1, 2].map(|a| plane(a, node.q[3 + a][lane])));
                *ok &= min.cmple(exact.min).all() && max.cmpge(exact.max).all();
                area.0 += f64::from(Aabb { min, max }.half_area());
                area.1 += f64::from(exact.half_area());
                whole = whole.union(exact);
            }
            whole
        }
        let (mut ok, mut area) = (true, (0.0, 0.0));
        if !self.wide.is_empty() {
            below(self, boxes, 0, &mut ok, &mut area);
        }
        (ok, area.0 / area.1.max(f64::MIN_POSITIVE))
    }
}
