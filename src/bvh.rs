//! A flat bounding-volume hierarchy over axis-aligned boxes, built with binned SAH.
//!
//! Used as the top-level structure over objects by the SDF back-end (and over
//! triangles by the mesh back-end). Nodes are 32 bytes, stored depth-first in one
//! `Vec`: an interior node's left child follows it, its right child is at `right`.
//!
//! **Invariant:** every node's box contains the boxes of all primitives below it, and
//! every primitive index appears in exactly one leaf ([`Bvh::validate`] checks both).

use glam::Vec3A;

/// An axis-aligned box in render space (f32).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3A,
    /// Largest corner.
    pub max: Vec3A,
}

impl Aabb {
    /// The empty box (contains nothing; the identity of `union`).
    pub const EMPTY: Aabb = Aabb { min: Vec3A::splat(f32::INFINITY), max: Vec3A::splat(f32::NEG_INFINITY) };

    /// The smallest box containing both.
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// Centre point.
    pub fn centre(self) -> Vec3A {
        (self.min + self.max) * 0.5
    }

    /// Half the surface area (the SAH cost of a box).
    pub fn half_area(self) -> f32 {
        let d = (self.max - self.min).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    /// Whether `o` lies inside (with a relative tolerance for rounding).
    pub fn contains(self, o: Aabb) -> bool {
        let tol = (self.max - self.min).abs().max_element() * 1e-5 + 1e-6;
        (o.min + tol).cmpge(self.min).all() && (o.max - tol).cmple(self.max).all()
    }

    /// The parametric interval `[t0, t1]` where the ray is inside the box, clipped to
    /// `[t_min, t_max]`; `None` on a miss. `inv_dir` is `1 / dir` (infinite for zero
    /// components, which the min/max formulation handles).
    #[inline]
    pub fn slab(self, origin: Vec3A, inv_dir: Vec3A, t_min: f32, t_max: f32) -> Option<(f32, f32)> {
        let t0 = (self.min - origin) * inv_dir;
        let t1 = (self.max - origin) * inv_dir;
        // `min`/`max` of glam ignore a NaN operand (0 × ∞ on a slab face), keeping the other.
        // The far distance is scaled by 1 + 2γ₃ (Ize 2013, "Robust BVH Ray Traversal") so
        // rounding never rejects a ray that touches the box, e.g. through a mesh vertex.
        const ROBUST: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON / (1.0 - 3.0 * f32::EPSILON));
        let near = t0.min(t1).max_element().max(t_min);
        let far = (t0.max(t1).min_element() * ROBUST).min(t_max);
        (near <= far).then_some((near, far))
    }
}

/// A node: 32 bytes, flat.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct Node {
    min: [f32; 3],
    /// Leaf: first index into `prims`. Interior: index of the right child.
    first_or_right: u32,
    max: [f32; 3],
    /// Leaf: number of primitives (> 0). Interior: 0.
    count: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 32);

impl Node {
    fn bounds(&self) -> Aabb {
        Aabb { min: Vec3A::from(self.min), max: Vec3A::from(self.max) }
    }
}

/// The hierarchy.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    prims: Vec<u32>,
}

/// Deepest traversal stack; the builder never makes a deeper tree.
const MAX_DEPTH: usize = 64;
const BINS: usize = 12;

impl Bvh {
    /// Builds over the given boxes (primitive `i` has box `boxes[i]`); leaves hold at
    /// most `leaf_size` primitives unless SAH finds no useful split.
    pub fn build(boxes: &[Aabb], leaf_size: usize) -> Bvh {
        let mut bvh = Bvh { nodes: Vec::with_capacity(boxes.len() * 2), prims: (0..boxes.len() as u32).collect() };
        if !boxes.is_empty() {
            let centres: Vec<Vec3A> = boxes.iter().map(|b| b.centre()).collect();
            bvh.build_node(boxes, &centres, 0, boxes.len(), 0, leaf_size.max(1));
        }
        bvh
    }

    fn build_node(
        &mut self,
        boxes: &[Aabb],
        centres: &[Vec3A],
        start: usize,
        end: usize,
        depth: usize,
        leaf_size: usize,
    ) -> usize {
        let idx = self.nodes.len();
        // One pass for the node's bounds and the bounds of the primitives' centres.
        let (bounds, cb) = self.prims[start..end].iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), &p| {
            let centre = centres[p as usize];
            (b.union(boxes[p as usize]), c.union(Aabb { min: centre, max: centre }))
        });
        self.nodes.push(Node {
            min: bounds.min.into(),
            first_or_right: start as u32,
            max: bounds.max.into(),
            count: (end - start) as u32,
        });
        let n = end - start;
        if n <= leaf_size || depth + 1 >= MAX_DEPTH {
            return idx;
        }
        let Some(mid) = self.split(boxes, centres, start, end, bounds, cb) else {
            return idx;
        };
        self.build_node(boxes, centres, start, mid, depth + 1, leaf_size);
        let right = self.build_node(boxes, centres, mid, end, depth + 1, leaf_size);
        self.nodes[idx].first_or_right = right as u32;
        self.nodes[idx].count = 0;
        idx
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
        self.walk(origin, inv_dir, t_min, &mut t_max, visits, |prim, t_max| {
            if let Some(t) = visit(prim, *t_max) {
                *t_max = t;
                best = Some((prim, t));
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
        self.walk(origin, inv_dir, t_min, &mut t_max, visits, |prim, t_max| {
            found = visit(prim, *t_max);
            found
        });
        found
    }

    #[inline]
    fn walk(
        &self,
        origin: Vec3A,
        inv_dir: Vec3A,
        t_min: f32,
        t_max: &mut f32,
        visits: &mut u64,
        mut leaf: impl FnMut(u32, &mut f32) -> bool,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; MAX_DEPTH];
        let mut sp = 0;
        let mut node_idx = 0usize;
        if self.nodes[0].bounds().slab(origin, inv_dir, t_min, *t_max).is_none() {
            *visits += 1;
            return;
        }
        loop {
            *visits += 1;
            let node = &self.nodes[node_idx];
            if node.count > 0 {
                let first = node.first_or_right as usize;
                for &p in &self.prims[first..first + node.count as usize] {
                    if leaf(p, t_max) {
                        return;
                    }
                }
            } else {
                let (l, r) = (node_idx + 1, node.first_or_right as usize);
                let hl = self.nodes[l].bounds().slab(origin, inv_dir, t_min, *t_max);
                let hr = self.nodes[r].bounds().slab(origin, inv_dir, t_min, *t_max);
                match (hl, hr) {
                    (Some((tl, _)), Some((tr, _))) => {
                        let (near, far) = if tl <= tr { (l, r) } else { (r, l) };
                        stack[sp] = far as u32;
                        sp += 1;
                        node_idx = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node_idx = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        node_idx = r;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop, skipping nodes that start beyond the current closest hit.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let next = stack[sp] as usize;
                if self.nodes[next].bounds().slab(origin, inv_dir, t_min, *t_max).is_some() {
                    node_idx = next;
                    break;
                }
            }
        }
    }

    /// Bytes of the node and index arrays.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>() + self.prims.len() * 4
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Depth of the deepest leaf (a single leaf has depth 1).
    pub fn depth(&self) -> usize {
        fn go(nodes: &[Node], i: usize) -> usize {
            let n = &nodes[i];
            if n.count > 0 {
                1
            } else {
                1 + go(nodes, i + 1).max(go(nodes, n.first_or_right as usize))
            }
        }
        if self.nodes.is_empty() {
            0
        } else {
            go(&self.nodes, 0)
        }
    }

    /// Checks the invariants against the boxes it was built from.
    pub fn validate(&self, boxes: &[Aabb]) -> Result<(), String> {
        let mut seen = vec![false; boxes.len()];
        fn go(bvh: &Bvh, boxes: &[Aabb], seen: &mut [bool], i: usize, depth: usize) -> Result<Aabb, String> {
            let n = bvh.nodes.get(i).ok_or(format!("node {i} out of range"))?;
            if depth > MAX_DEPTH {
                return Err("tree deeper than the traversal stack".into());
            }
            let b = n.bounds();
            if n.count > 0 {
                let first = n.first_or_right as usize;
                for &p in bvh.prims.get(first..first + n.count as usize).ok_or("leaf range out of bounds")? {
                    let p = p as usize;
                    if std::mem::replace(&mut seen[p], true) {
                        return Err(format!("primitive {p} in two leaves"));
                    }
                    if !b.contains(boxes[p]) {
                        return Err(format!("leaf {i} does not contain primitive {p}"));
                    }
                }
            } else {
                for c in [i + 1, n.first_or_right as usize] {
                    let cb = go(bvh, boxes, seen, c, depth + 1)?;
                    if !b.contains(cb) {
                        return Err(format!("node {i} does not contain child {c}"));
                    }
                }
            }
            Ok(b)
        }
        if !self.nodes.is_empty() {
            go(self, boxes, &mut seen, 0, 1)?;
        }
        match seen.iter().position(|s| !s) {
            Some(p) => Err(format!("primitive {p} is in no leaf")),
            None => Ok(()),
        }
    }
}
