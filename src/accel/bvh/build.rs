//! The binned-SAH builder, parallel over subtrees.
//!
//! The primitives' boxes are copied once into a flat array of [`Ref`]s (box and index
//! in 32 bytes) that the build partitions in place, so every pass reads memory in
//! order instead of chasing indices. Two passes per node: binning records each bin's
//! bounds and count, and the partition collects each side's centre bounds, so every
//! child starts with its bounds and centre bounds known.
//!
//! Subtrees of at least [`FORK`] primitives are built in parallel (`rayon::join`), each
//! into its own node array; one preorder pass then lays them out as the serial build
//! would, parent first and the left subtree before the right. Every step is a pure
//! function of its primitives (bin unions and counts are exact), so the tree is the
//! same for any number of threads.

use glam::{Vec3A, Vec4};
use rayon::prelude::*;

use super::{Bvh, Child, Node, MAX_DEPTH};
use crate::accel::Aabb;

/// SAH bins per axis.
const BINS: usize = 12;
/// Subtrees with at least this many primitives are built in parallel: below it the
/// work per task (`n log n` box unions) no longer pays for a task's overhead.
const FORK: usize = 4096;
/// Nodes with at least this many primitives bin them in parallel chunks of this size.
pub(super) const PAR_BIN: usize = 1 << 16;

/// A primitive's box, its index in the fourth lane of the lower corner.
#[derive(Clone, Copy)]
struct Ref {
    lo: Vec4,
    hi: Vec3A,
}

/// Set in the bits of an index stored as a float. The fourth lane takes part in the box
/// arithmetic (its results unused); a small index's bits alone would be a subnormal,
/// which costs a microcode assist per operation on many x86 cores, while with this bit
/// every index below 2²⁹ (ten times the scene's triangle limit) is a normal float
/// between 2 and 2⁶⁴.
const NORMAL: u32 = 1 << 30;

impl Ref {
    fn new(b: Aabb, id: u32) -> Ref {
        debug_assert!(id < 1 << 29);
        Ref { lo: b.min.extend(f32::from_bits(id ^ NORMAL)), hi: b.max }
    }

    fn aabb(&self) -> Aabb {
        Aabb { min: Vec3A::from_vec4(self.lo), max: self.hi }
    }

    fn id(&self) -> u32 {
        self.lo.w.to_bits() ^ NORMAL
    }

    fn centre(&self) -> Vec3A {
        self.aabb().centre()
    }
}

/// What a node knows before it is split: its bounds and its centres' bounds.
#[derive(Clone, Copy)]
struct Span {
    bounds: Aabb,
    centres: Aabb,
}

impl Span {
    const EMPTY: Span = Span { bounds: Aabb::EMPTY, centres: Aabb::EMPTY };

    fn of(refs: &[Ref]) -> Span {
        refs.iter().fold(Span::EMPTY, |s, r| s.add(r.aabb(), r.centre()))
    }

    fn add(self, b: Aabb, c: Vec3A) -> Span {
        Span { bounds: self.bounds.union(b), centres: self.centres.union(Aabb::point(c)) }
    }

    fn union(self, o: Span) -> Span {
        Span { bounds: self.bounds.union(o.bounds), centres: self.centres.union(o.centres) }
    }
}

/// Bins on all three axes: the bounds and number of the primitives whose centres fall
/// in each.
#[derive(Clone, Copy)]
struct Bins {
    boxes: [[Aabb; BINS]; 3],
    n: [[u32; BINS]; 3],
}

impl Bins {
    const EMPTY: Bins = Bins { boxes: [[Aabb::EMPTY; BINS]; 3], n: [[0; BINS]; 3] };

    fn add(&mut self, k: [usize; 3], b: Aabb) {
        for (axis, k) in k.into_iter().enumerate() {
            self.boxes[axis][k] = self.boxes[axis][k].union(b);
            self.n[axis][k] += 1;
        }
    }

    fn merge(&mut self, o: &Bins) {
        for axis in 0..3 {
            for k in 0..BINS {
                self.boxes[axis][k] = self.boxes[axis][k].union(o.boxes[axis][k]);
                self.n[axis][k] += o.n[axis][k];
            }
        }
    }
}

/// Maps a centre to its bin on each axis.
#[derive(Clone, Copy)]
struct Binner {
    min: Vec3A,
    scale: Vec3A,
}

impl Binner {
    fn new(centres: Aabb) -> Binner {
        let extent = centres.max - centres.min;
        let scale = Vec3A::select(extent.cmpgt(Vec3A::ZERO), Vec3A::splat(BINS as f32) / extent, Vec3A::ZERO);
        Binner { min: centres.min, scale }
    }

    /// The bin on every axis: the product clamped to the bins in float (NaN and
    /// products below the lowest centre go to bin 0), then truncated.
    fn bins(&self, c: Vec3A) -> [usize; 3] {
        let k = ((c - self.min) * self.scale).max(Vec3A::ZERO).min(Vec3A::splat(BINS as f32 - 1.0));
        [k.x as usize, k.y as usize, k.z as usize]
    }

    /// A test of whether [`bins`](Self::bins) puts a centre in bin `bin` or lower on
    /// `axis` (`bin` < `BINS - 1`): the same product, compared in all lanes at once
    /// with the next bin's start on `axis` and infinity on the others (NaN compares
    /// false and stays left, as it converts to bin 0).
    fn at_most(&self, axis: usize, bin: usize) -> impl Fn(Vec3A) -> bool + '_ {
        let mut start = Vec3A::INFINITY;
        start[axis] = (bin + 1) as f32;
        move |c| !((c - self.min) * self.scale).cmpge(start).any()
    }

    /// Adds `refs` to `bins`. Neighbouring primitives of a mesh mostly fall in the same
    /// bin, so each update would wait for the previous one through memory: in large
    /// nodes alternate primitives go to a second set of bins, merged at the end.
    fn fill(&self, refs: &[Ref], bins: &mut Bins) {
        if refs.len() < 256 {
            for r in refs {
                bins.add(self.bins(r.centre()), r.aabb());
            }
            return;
        }
        let mut odd = Bins::EMPTY;
        let mut pairs = refs.chunks_exact(2);
        for pair in &mut pairs {
            bins.add(self.bins(pair[0].centre()), pair[0].aabb());
            odd.add(self.bins(pair[1].centre()), pair[1].aabb());
        }
        for r in pairs.remainder() {
            bins.add(self.bins(r.centre()), r.aabb());
        }
        bins.merge(&odd);
    }

    /// [`fill`](Self::fill), in parallel chunks for large nodes (unions and counts are
    /// exact, so the chunking does not change the result).
    fn fill_par(&self, refs: &[Ref], bins: &mut Bins) {
        if refs.len() < PAR_BIN {
            return self.fill(refs, bins);
        }
        let chunks: Vec<Bins> = refs
            .par_chunks(PAR_BIN)
            .map(|c| {
                let mut b = Bins::EMPTY;
                self.fill(c, &mut b);
                b
            })
            .collect();
        for c in &chunks {
            bins.merge(c);
        }
    }
}

/// A built subtree before layout.
enum Sub {
    /// Few primitives: a leaf.
    Leaf(Child),
    /// Built serially: its nodes, root first, interior references local to the array.
    Nodes(Vec<Node>),
    /// Built as two parallel halves.
    Fork(Box<[(Aabb, Sub); 2]>),
}

impl Sub {
    /// Its number of interior nodes.
    fn len(&self) -> usize {
        match self {
            Sub::Leaf(_) => 0,
            Sub::Nodes(nodes) => nodes.len(),
            Sub::Fork(halves) => 1 + halves[0].1.len() + halves[1].1.len(),
        }
    }
}

impl Bvh {
    /// Builds over the given boxes (primitive `i` has box `boxes[i]`); leaves hold at
    /// most `leaf_size` primitives unless SAH finds no useful split.
    pub fn build(boxes: &[Aabb], leaf_size: usize) -> Bvh {
        Bvh::build_with(boxes.len(), |i| boxes[i], leaf_size)
    }

    /// Builds over `count` primitives, primitive `i` having the box `bounds(i)`, so a
    /// caller need not hold the boxes besides the builder's own copy.
    pub fn build_with(count: usize, bounds: impl Fn(usize) -> Aabb + Sync, leaf_size: usize) -> Bvh {
        Bvh::build_until(count, bounds, leaf_size, &|| false)
    }

    /// [`build_with`](Self::build_with) that ends early once `stop` says so (the studio's
    /// lowering for a request a newer one replaced): asked at every subtree of 4,096 or
    /// more primitives, which a stopped build makes one leaf. The tree is then valid but
    /// useless, for the caller to drop; with `stop` never true it is `build_with`'s.
    pub fn build_until(
        count: usize,
        bounds: impl Fn(usize) -> Aabb + Sync,
        leaf_size: usize,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Bvh {
        if count == 0 {
            return Bvh::default();
        }
        let mut refs: Vec<Ref> = (0..count).into_par_iter().map(|i| Ref::new(bounds(i), i as u32)).collect();
        let span = refs.par_chunks(PAR_BIN).map(Span::of).reduce(|| Span::EMPTY, Span::union);
        let root = subtree(&mut refs, 0, span, 0, leaf_size.max(1), stop);
        // The boxes go before the nodes are laid out, which briefly holds them twice.
        let prims = refs.par_iter().map(Ref::id).collect();
        drop(refs);
        let mut nodes = Vec::with_capacity(root.len());
        let root = lay_out(root, &mut nodes);
        Bvh { nodes, root_box: span.bounds, root, prims, wide: Vec::new(), blocks: Vec::new() }
    }

    /// Builds like [`build_until`](Self::build_until) and returns the leaves' primitive order: the
    /// caller stores its primitives in that order, and the tree then names primitive `k`
    /// by its position `k` (no index array, one indirection less per primitive test).
    pub fn build_ordered(
        count: usize,
        bounds: impl Fn(usize) -> Aabb + Sync,
        leaf_size: usize,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> (Bvh, Vec<u32>) {
        let mut bvh = Bvh::build_until(count, bounds, leaf_size, stop);
        let order = std::mem::take(&mut bvh.prims);
        (bvh, order)
    }
}

/// Builds the subtree over `refs`, which start at primitive `start`: in parallel halves
/// while it is large, serially below.
fn subtree(
    refs: &mut [Ref],
    start: usize,
    span: Span,
    depth: usize,
    leaf_size: usize,
    stop: &(dyn Fn() -> bool + Sync),
) -> Sub {
    if refs.len() < FORK {
        // At most four a leaf, SAH makes about one interior node per three primitives.
        let mut nodes = Vec::with_capacity(refs.len() / 3);
        return match serial(&mut nodes, refs, start, span, depth, leaf_size) {
            Child { count: 0, .. } => Sub::Nodes(nodes),
            leaf => Sub::Leaf(leaf),
        };
    }
    let split = if stop() { None } else { split(refs, span, depth, leaf_size) };
    let Some((mid, left, right)) = split else {
        return Sub::Leaf(Child { index: start as u32, count: refs.len() as u32 });
    };
    let (lo, hi) = refs.split_at_mut(mid);
    let (l, r) = rayon::join(
        || subtree(lo, start, left, depth + 1, leaf_size, stop),
        || subtree(hi, start + mid, right, depth + 1, leaf_size, stop),
    );
    Sub::Fork(Box::new([(left.bounds, l), (right.bounds, r)]))
}

/// Builds the subtree over `refs` (starting at primitive `start`) into `nodes`, parent
/// before children; returns its reference, local to `nodes`.
fn serial(nodes: &mut Vec<Node>, refs: &mut [Ref], start: usize, span: Span, depth: usize, leaf_size: usize) -> Child {
    let Some((mid, left, right)) = split(refs, span, depth, leaf_size) else {
        return Child { index: start as u32, count: refs.len() as u32 };
    };
    let at = nodes.len();
    nodes.push(Node::PENDING);
    let (lo, hi) = refs.split_at_mut(mid);
    let l = serial(nodes, lo, start, left, depth + 1, leaf_size);
    let r = serial(nodes, hi, start + mid, right, depth + 1, leaf_size);
    nodes[at] = Node::new(left.bounds, right.bounds, [l, r]);
    Child { index: at as u32, count: 0 }
}

/// Appends `sub` to `out` in preorder and returns its reference.
fn lay_out(sub: Sub, out: &mut Vec<Node>) -> Child {
    match sub {
        Sub::Leaf(leaf) => leaf,
        Sub::Nodes(nodes) => {
            let base = out.len() as u32;
            out.extend(nodes.into_iter().map(|mut n| {
                for c in &mut n.children {
                    if c.count == 0 {
                        c.index += base;
                    }
                }
                n
            }));
            Child { index: base, count: 0 }
        }
        Sub::Fork(halves) => {
            let at = out.len();
            out.push(Node::PENDING);
            let [(left_box, left), (right_box, right)] = *halves;
            let (l, r) = (lay_out(left, out), lay_out(right, out));
            out[at] = Node::new(left_box, right_box, [l, r]);
            Child { index: at as u32, count: 0 }
        }
    }
}

/// Binned SAH split of `refs` (all three axes binned in one pass): partitions in place
/// and returns the middle with each side's span, or `None` when a leaf is cheaper or
/// allowed no deeper.
fn split(refs: &mut [Ref], span: Span, depth: usize, leaf_size: usize) -> Option<(usize, Span, Span)> {
    let n = refs.len();
    if n <= leaf_size || depth + 1 >= MAX_DEPTH {
        return None;
    }
    let binner = Binner::new(span.centres);
    let mut bins = Bins::EMPTY;
    binner.fill_par(refs, &mut bins);
    let extent = span.centres.max - span.centres.min;
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, bin)
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let (boxes, count) = (&bins.boxes[axis], &bins.n[axis]);
        let mut right_area = [0.0f32; BINS];
        let mut right_n = [0u32; BINS];
        let (mut acc, mut acc_n) = (Aabb::EMPTY, 0);
        for b in (1..BINS).rev() {
            acc = acc.union(boxes[b]);
            acc_n += count[b];
            right_area[b] = acc.half_area();
            right_n[b] = acc_n;
        }
        let (mut acc, mut acc_n) = (Aabb::EMPTY, 0);
        for b in 0..BINS - 1 {
            acc = acc.union(boxes[b]);
            acc_n += count[b];
            if acc_n == 0 || right_n[b + 1] == 0 {
                continue;
            }
            let cost = acc.half_area() * acc_n as f32 + right_area[b + 1] * right_n[b + 1] as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    let leaf_cost = span.bounds.half_area() * n as f32;
    match best {
        Some((cost, axis, bin)) if cost < leaf_cost || n > 8 => {
            let (mid, left_centres, right_centres) = partition(refs, binner.at_most(axis, bin));
            let bounds =
                |range: std::ops::Range<usize>| bins.boxes[axis][range].iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
            Some((
                mid,
                Span { bounds: bounds(0..bin + 1), centres: left_centres },
                Span { bounds: bounds(bin + 1..BINS), centres: right_centres },
            ))
        }
        // All centres coincide: split in the middle so the tree still divides.
        None if n > 8 => {
            let mid = n / 2;
            Some((mid, Span::of(&refs[..mid]), Span::of(&refs[mid..])))
        }
        _ => None,
    }
}

/// Moves the primitives whose centres satisfy `left` before the others (two cursors
/// swapping only misplaced pairs); returns how many satisfy it and the bounds of both
/// sides' centres.
fn partition(refs: &mut [Ref], left: impl Fn(Vec3A) -> bool) -> (usize, Aabb, Aabb) {
    let (mut l, mut r) = (Aabb::EMPTY, Aabb::EMPTY);
    let (mut i, mut j) = (0, refs.len());
    loop {
        while i < j {
            let c = refs[i].centre();
            if !left(c) {
                break;
            }
            l = l.union(Aabb::point(c));
            i += 1;
        }
        while i < j {
            let c = refs[j - 1].centre();
            if left(c) {
                break;
            }
            r = r.union(Aabb::point(c));
            j -= 1;
        }
        if i >= j {
            return (i, l, r);
        }
        // refs[i] belongs right and refs[j - 1] left: swap them into place.
        refs.swap(i, j - 1);
    }
}
