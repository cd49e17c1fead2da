//! A flat bounding-volume hierarchy over axis-aligned boxes, built with binned SAH.
//!
//! Used as the top-level structure over objects and over each mesh's triangles. Each
//! interior node stores the boxes of both its children in one 64-byte cache line, so a
//! traversal step is one load and one 4-wide slab test; leaves are ranges of primitives
//! named in their parent. The builder makes the usual one-box-per-node tree first.
//!
//! - `build`: binned SAH.
//! - `walk`: closest and any hit for one ray.
//! - `packet`: the walk shared by packets of coherent rays.
//!
//! **Invariant:** every node's box contains the boxes of all primitives below it, and
//! every primitive index appears in exactly one leaf ([`Bvh::validate`] checks both).

mod build;
mod packet;
mod point;
mod walk;
mod wide;

use glam::{Vec3A, Vec4};

pub use packet::{group_lanes, splat3, Rays4};

use super::Aabb;

/// A reference to a child: an interior node, or a leaf's range of primitives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Child {
    /// Leaf: first primitive. Interior: index into `nodes`.
    pub(crate) index: u32,
    /// Leaf: number of primitives (> 0). Interior: 0.
    pub(crate) count: u32,
}

/// An interior node holding both children's boxes, one cache line in all. The boxes
/// are stored across lanes, `[left.min, right.min, left.max, right.max]` per axis, so
/// one pass of 4-wide arithmetic tests both children: a visit loads one line and
/// decides which children the ray enters and in which order.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct Node {
    x: Vec4,
    y: Vec4,
    z: Vec4,
    children: [Child; 2],
}

impl Node {
    /// A slot taken for a parent before its children are built, filled after.
    const PENDING: Node =
        Node { x: Vec4::ZERO, y: Vec4::ZERO, z: Vec4::ZERO, children: [Child { index: 0, count: 0 }; 2] };

    fn new(left: Aabb, right: Aabb, children: [Child; 2]) -> Node {
        Node {
            x: Vec4::new(left.min.x, right.min.x, left.max.x, right.max.x),
            y: Vec4::new(left.min.y, right.min.y, left.max.y, right.max.y),
            z: Vec4::new(left.min.z, right.min.z, left.max.z, right.max.z),
            children,
        }
    }

    fn child_box(&self, k: usize) -> Aabb {
        Aabb {
            min: Vec3A::new(self.x[k], self.y[k], self.z[k]),
            max: Vec3A::new(self.x[k + 2], self.y[k + 2], self.z[k + 2]),
        }
    }
}

/// The children a walk deferred, last in first out: a fixed array covers every tree but
/// degenerate ones, which spill to the heap (an empty `Vec` does not allocate).
struct Deferred<T, const N: usize = STACK> {
    fixed: [T; N],
    len: usize,
    spill: Vec<T>,
}

impl<T: Copy, const N: usize> Deferred<T, N> {
    #[inline(always)]
    fn new(fill: T) -> Deferred<T, N> {
        Deferred { fixed: [fill; N], len: 0, spill: Vec::new() }
    }

    #[inline(always)]
    fn push(&mut self, item: T) {
        if self.len < N {
            self.fixed[self.len] = item;
            self.len += 1;
        } else {
            self.spill.push(item);
        }
    }

    /// The last pushed: the spill holds the newest entries whenever it is not empty.
    #[inline(always)]
    fn pop(&mut self) -> Option<T> {
        match self.spill.pop() {
            Some(item) => Some(item),
            None if self.len > 0 => {
                self.len -= 1;
                Some(self.fixed[self.len])
            }
            None => None,
        }
    }
}

/// The hierarchy.
#[derive(Clone, Debug)]
pub struct Bvh {
    /// Interior nodes, parents before children.
    nodes: Vec<Node>,
    /// The root's box.
    root_box: Aabb,
    /// The root: interior node 0, or a leaf when there are few primitives; an empty
    /// tree has neither nodes nor a leaf.
    root: Child,
    /// Primitive indices of the leaves; empty when the caller ordered its primitives
    /// by the leaves ([`Bvh::build_ordered`]).
    prims: Vec<u32>,
    /// The same tree with four children a node, root first, which the single-ray walks
    /// take when it is there ([`Bvh::widen`]); empty otherwise.
    wide: Vec<wide::Wide>,
    /// The four-wide tree's leaves as blocks of at most four consecutive slots, in the
    /// order its leaves name them ([`Bvh::blocks`]); empty when there is no wide tree.
    blocks: Vec<LeafBlock>,
}

/// Up to four consecutive leaf slots of the four-wide tree, which a caller may test
/// together (a mesh tests a block's triangles in one four-lane test).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LeafBlock {
    /// The block's first slot.
    pub first: u32,
    /// Its slots, 1 to 4.
    pub count: u32,
}

/// Deepest tree the builder makes.
const MAX_DEPTH: usize = 64;
/// Deferred nodes kept on the call stack during a traversal (one per level at most).
const STACK: usize = 16;

impl Default for Bvh {
    fn default() -> Bvh {
        Bvh {
            nodes: Vec::new(),
            root_box: Aabb::EMPTY,
            root: Child { index: 0, count: 0 },
            prims: Vec::new(),
            wide: Vec::new(),
            blocks: Vec::new(),
        }
    }
}

impl Bvh {
    /// The box around every primitive (empty for an empty tree).
    pub fn bounds(&self) -> Aabb {
        self.root_box
    }

    /// The root's box and reference, unless the tree is empty.
    fn root(&self) -> Option<(Aabb, Child)> {
        (self.root.count > 0 || !self.nodes.is_empty()).then_some((self.root_box, self.root))
    }

    /// Bytes of the nodes, the root and the index array.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>()
            + std::mem::size_of::<(Aabb, Child)>()
            + self.prims.len() * 4
            + self.wide_bytes()
    }

    /// Number of nodes in the tree, leaves included.
    pub fn node_count(&self) -> usize {
        // A binary tree with `n` interior nodes has `n + 1` leaves.
        if self.root().is_some() {
            2 * self.nodes.len() + 1
        } else {
            0
        }
    }

    /// Depth of the deepest leaf (a single leaf has depth 1).
    pub fn depth(&self) -> usize {
        fn go(nodes: &[Node], c: Child) -> usize {
            if c.count > 0 {
                1
            } else {
                let n = &nodes[c.index as usize];
                1 + go(nodes, n.children[0]).max(go(nodes, n.children[1]))
            }
        }
        self.root().map_or(0, |(_, root)| go(&self.nodes, root))
    }

    /// Checks the invariants against the boxes it was built from.
    pub fn validate(&self, boxes: &[Aabb]) -> Result<(), String> {
        let mut seen = vec![false; boxes.len()];
        fn go(bvh: &Bvh, boxes: &[Aabb], seen: &mut [bool], b: Aabb, c: Child, depth: usize) -> Result<(), String> {
            if depth > MAX_DEPTH {
                return Err("tree deeper than the builder makes".into());
            }
            if c.count > 0 {
                let range = c.index as usize..c.index as usize + c.count as usize;
                let prims: Vec<u32> = if bvh.prims.is_empty() {
                    range.clone().map(|p| p as u32).filter(|&p| (p as usize) < boxes.len()).collect()
                } else {
                    bvh.prims.get(range.clone()).ok_or("leaf range out of bounds")?.to_vec()
                };
                if prims.len() != range.len() {
                    return Err("leaf range out of bounds".into());
                }
                for p in prims {
                    let p = p as usize;
                    if std::mem::replace(&mut seen[p], true) {
                        return Err(format!("primitive {p} in two leaves"));
                    }
                    if !b.contains(boxes[p]) {
                        return Err(format!("a leaf does not contain primitive {p}"));
                    }
                }
                return Ok(());
            }
            let n = bvh.nodes.get(c.index as usize).ok_or(format!("node {} out of range", c.index))?;
            for k in 0..2 {
                let cb = n.child_box(k);
                if !b.contains(cb) {
                    return Err(format!("node {} does not contain its child {k}", c.index));
                }
                go(bvh, boxes, seen, cb, n.children[k], depth + 1)?;
            }
            Ok(())
        }
        if let Some((b, root)) = self.root() {
            go(self, boxes, &mut seen, b, root, 1)?;
        }
        match seen.iter().position(|s| !s) {
            Some(p) => Err(format!("primitive {p} is in no leaf")),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every primitive whose box the ray passes through, by brute force.
    fn brute(boxes: &[Aabb], origin: Vec3A, dir: Vec3A) -> Vec<u32> {
        let mut out: Vec<u32> = (0..boxes.len() as u32)
            .filter(|&i| boxes[i as usize].slab(origin, dir.recip(), 0.0, f32::MAX).is_some())
            .collect();
        out.sort();
        out
    }

    fn visited(bvh: &Bvh, origin: Vec3A, dir: Vec3A, order: Option<&[u32]>) -> Vec<u32> {
        let mut seen = Vec::new();
        let mut visits = 0;
        bvh.any(origin, dir.recip(), 0.0, f32::MAX, &mut visits, |p, _| {
            seen.push(order.map_or(p, |o| o[p as usize]));
            false
        });
        seen.sort();
        seen
    }

    /// Numbers in [0, 1) from a xorshift generator seeded with `state`.
    fn xorshift(mut state: u64) -> impl FnMut() -> f32 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[test]
    fn ordered_and_indexed_trees_find_what_brute_force_finds() {
        let mut next = xorshift(0x2545_f491_4f6c_dd1d);
        let boxes: Vec<Aabb> = (0..500)
            .map(|i| {
                let c = if i % 7 == 0 { Vec3A::ONE } else { Vec3A::new(next(), next(), next()) * 10.0 };
                Aabb { min: c, max: c + Vec3A::new(next(), next(), next()) * 0.5 }
            })
            .collect();
        let indexed = Bvh::build(&boxes, 4);
        indexed.validate(&boxes).expect("indexed tree");
        let (ordered, order) = Bvh::build_ordered(boxes.len(), |i| boxes[i], 4, &|| false);
        let reordered: Vec<Aabb> = order.iter().map(|&k| boxes[k as usize]).collect();
        ordered.validate(&reordered).expect("ordered tree");
        for i in 0..200 {
            let dir = Vec3A::new((i as f32 * 0.37).sin(), (i as f32 * 0.11).cos(), 1.0).normalize();
            let origin = Vec3A::new(5.0, 5.0, -20.0);
            // Leaves are visited whole, so every box the ray meets is among those visited.
            let expected = brute(&boxes, origin, dir);
            let (a, b) = (visited(&indexed, origin, dir, None), visited(&ordered, origin, dir, Some(&order)));
            assert_eq!(a, b, "the ordered tree visits what the indexed one does");
            assert!(expected.iter().all(|p| a.contains(p)), "ray {i} missed a box: {expected:?} ⊄ {a:?}");
        }
    }

    /// The four-wide copy visits every box a ray meets, and its closest hit is the
    /// binary walk's, on trees large and deep (the peeled chain of the stack test
    /// below, whose boxes span 10⁰ to 10³⁷) and on a lone leaf; its quantised boxes hold
    /// their children's and are not much larger.
    #[test]
    fn wide_walks_find_what_binary_walks_find() {
        let chain: Vec<Aabb> = (0..35)
            .map(|i| {
                let x = 12.5f32.powi(i);
                Aabb { min: Vec3A::new(x, -1.0, -1.0), max: Vec3A::new(x * 1.01, 1.0, 1.0) }
            })
            .collect();
        for (boxes, leaf, loosest) in [(scattered(3000), 4, 1.05), (scattered(3), 4, 1.0), (chain, 1, f64::INFINITY)] {
            let binary = Bvh::build(&boxes, leaf);
            let mut wide = binary.clone();
            wide.widen();
            wide.validate(&boxes).expect("widening keeps the binary tree");
            assert!(wide.bytes() >= binary.bytes());
            let (held, looser) = wide.wide_holds(&boxes);
            assert!(held, "a quantised box lost part of its child's");
            // Scattered boxes lose 1.7 % of tightness in area; the chain's, spanning 37
            // orders of magnitude, are only held (a quantum is its node's 255th).
            assert!(looser <= loosest, "quantised boxes {looser}× the exact ones' area");
            let mut next = xorshift(0x51_7cc1_b727_220a);
            for i in 0..400 {
                let origin = Vec3A::new(next(), next(), next()) * 14.0 - 2.0;
                let mut dir = Vec3A::new(next(), next(), next()) * 2.0 - 1.0;
                if i % 10 == 0 {
                    dir.x = 0.0; // axis-parallel rays: an infinite reciprocal
                }
                let dir = if i % 50 == 1 { Vec3A::X } else { dir.normalize() };
                let inv = dir.recip();
                let expected = brute(&boxes, origin, dir);
                let seen = visited(&wide, origin, dir, None);
                assert!(expected.iter().all(|p| seen.contains(p)), "ray {i} missed a box: {expected:?} ⊄ {seen:?}");
                let hit = |bvh: &Bvh| {
                    let mut visits = 0;
                    bvh.closest(origin, inv, 0.0, f32::MAX, &mut visits, |p, t_max| {
                        boxes[p as usize].slab(origin, inv, 0.0, t_max).map(|(near, _)| near)
                    })
                };
                assert_eq!(hit(&wide).map(|h| h.1), hit(&binary).map(|h| h.1), "ray {i}");
            }
        }
    }

    /// A build told to stop ends at its next large subtree with a tree that is still
    /// valid (the studio drops it), asking about once per 4,096 primitives at most; never
    /// told, it is the plain build's tree.
    #[test]
    fn a_stopped_build_ends_early_with_a_valid_tree() {
        let boxes = scattered(3 * build::PAR_BIN);
        let asked = std::sync::atomic::AtomicUsize::new(0);
        let stop = || asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= 2;
        let stopped = Bvh::build_until(boxes.len(), |i| boxes[i], 4, &stop);
        stopped.validate(&boxes).expect("a valid tree");
        let whole = Bvh::build(&boxes, 4);
        assert!(
            stopped.node_count() < whole.node_count() / 4,
            "{} of {} nodes",
            stopped.node_count(),
            whole.node_count()
        );
        assert!(asked.into_inner() <= boxes.len() / 4096 + 2);
        let never = Bvh::build_until(boxes.len(), |i| boxes[i], 4, &|| false);
        assert_eq!((&never.nodes, never.root, &never.prims), (&whole.nodes, whole.root, &whole.prims));
    }

    /// Large enough for subtrees built in parallel and nodes binned in parallel chunks:
    /// the tree is valid, finds what brute force finds, and is the same node for node
    /// on one thread as on four.
    #[test]
    fn parallel_builds_are_valid_and_independent_of_the_thread_count() {
        let boxes = scattered(3 * build::PAR_BIN);
        let on = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            pool.install(|| Bvh::build(&boxes, 4))
        };
        let (one, four) = (on(1), on(4));
        four.validate(&boxes).expect("valid");
        assert_eq!((&one.nodes, one.root, &one.prims), (&four.nodes, four.root, &four.prims));
        assert_eq!(one.root_box, four.root_box);
        for i in 0..50 {
            let dir = Vec3A::new((i as f32 * 0.37).sin(), (i as f32 * 0.11).cos(), 1.0).normalize();
            let origin = Vec3A::new(5.0, 5.0, -20.0);
            let expected = brute(&boxes, origin, dir);
            let seen = visited(&four, origin, dir, None);
            assert!(expected.iter().all(|p| seen.contains(p)), "ray {i} missed a box");
        }
    }

    /// Boxes scattered in a 10-unit cube, a few stacked at one spot.
    fn scattered(n: usize) -> Vec<Aabb> {
        let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
        (0..n)
            .map(|i| {
                let c = if i % 9 == 0 { Vec3A::splat(5.0) } else { Vec3A::new(next(), next(), next()) * 10.0 };
                Aabb { min: c, max: c + Vec3A::new(next(), next(), next()) * 0.6 }
            })
            .collect()
    }

    fn outside(b: Aabb, p: Vec3A) -> f32 {
        b.outside_squared(p).sqrt()
    }

    /// A union-like walk (threshold = nearest box so far + 0.3) reaches every box
    /// nearer than its final threshold, and nothing is skipped without pruning.
    #[test]
    fn the_point_walk_reaches_every_box_within_the_threshold() {
        let boxes = scattered(400);
        let bvh = Bvh::build(&boxes, 2);
        for i in 0..300 {
            let f = i as f32;
            let p =
                Vec3A::new((f * 0.37).sin() * 7.0 + 5.0, (f * 0.11).cos() * 7.0 + 5.0, (f * 0.23).sin() * 6.0 + 4.0);
            for prune in [true, false] {
                let (mut seen, mut best) = (vec![false; boxes.len()], f32::INFINITY);
                bvh.nearest_first(p, f32::INFINITY, prune, |k| {
                    assert!(!std::mem::replace(&mut seen[k as usize], true), "box {k} visited twice");
                    best = best.min(outside(boxes[k as usize], p));
                    best + 0.3
                });
                for (k, b) in boxes.iter().enumerate() {
                    let wanted = !prune || outside(*b, p) < best + 0.3;
                    assert!(seen[k] || !wanted, "point {i}: box {k} at {} skipped, best {best}", outside(*b, p));
                }
            }
        }
    }

    /// Opening up to `t` in steps reports each box once, every box whose grown box the
    /// ray enters by `t`, and leaves closed only what begins after the frontier.
    #[test]
    fn the_resumable_ray_walk_opens_exactly_up_to_its_distance() {
        let boxes = scattered(400);
        let bvh = Bvh::build(&boxes, 2);
        let grow = 0.2;
        let mut closed = Vec::new();
        for i in 0..200 {
            let dir = Vec3A::new((i as f32 * 0.37).sin(), (i as f32 * 0.11).cos(), 1.0).normalize();
            let origin = Vec3A::new(5.0, 5.0, -20.0);
            let entry = |b: Aabb| b.grow(grow).slab(origin, dir.recip(), 0.0, 60.0).map(|(a, _)| a);
            let walk = bvh.ray_walk(origin, dir.recip(), (0.0, 60.0), grow, &mut closed);
            let mut seen = vec![false; boxes.len()];
            let mut visits = 0;
            for step in 0..=30 {
                let t = step as f32 * 2.0;
                let frontier = walk.open_until(t, &mut closed, &mut visits, |k| {
                    assert!(!std::mem::replace(&mut seen[k as usize], true), "box {k} reported twice");
                });
                for (k, b) in boxes.iter().enumerate() {
                    if let Some(a) = entry(*b) {
                        assert!(seen[k] || a > t, "ray {i}: box {k} entered at {a} not opened by {t}");
                        assert!(seen[k] || a >= frontier, "ray {i}: box {k} at {a} before frontier {frontier}");
                    }
                }
            }
        }
    }

    /// Boxes 12.5× farther out each: all but the farthest fall in the first of the 12
    /// bins, so SAH peels one box off per level, making a tree deeper than the fixed
    /// traversal stack, whose overflow goes to the heap.
    #[test]
    fn trees_deeper_than_the_fixed_stack_are_walked_completely() {
        let n = 35;
        let boxes: Vec<Aabb> = (0..n)
            .map(|i| {
                let x = 12.5f32.powi(i);
                Aabb { min: Vec3A::new(x, -1.0, -1.0), max: Vec3A::new(x * 1.01, 1.0, 1.0) }
            })
            .collect();
        let bvh = Bvh::build(&boxes, 1);
        bvh.validate(&boxes).expect("valid");
        assert!(bvh.depth() > STACK + 1, "depth {} does not exceed the stack", bvh.depth());
        // A ray along +x from the near end meets every box; at each level the nearer
        // child is the deep one and the peeled box is deferred, so the stack overflows.
        let origin = Vec3A::new(0.5, 0.0, 0.0);
        assert_eq!(visited(&bvh, origin, Vec3A::X, None), (0..n as u32).collect::<Vec<u32>>());
    }
}
