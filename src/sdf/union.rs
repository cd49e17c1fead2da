//! Unions of many bounded parts, evaluated in time that depends on the parts near the
//! point rather than on how many there are.
//!
//! Each part's distance is taken as at least the distance to its bounding box and to
//! its bounding sphere (all are lower bounds of the distance to the part, so their
//! maximum is one too, and it is 1-Lipschitz; for a sphere part it is exact). A bounding volume hierarchy over the boxes is walked nearest first;
//! a node is skipped when the point lies outside its box by at least the best value so
//! far plus the blend radius `k` (0 for a sharp union). Every part it skips has a value
//! at least that large, so:
//! - a sharp union (the minimum) is exactly the minimum over all parts;
//! - a smooth union is defined as the polynomial smooth minimum folded over the parts
//!   in increasing order of distance, which stops at the first part `k` or more above
//!   the running value (the blend of such a part is exactly zero). Folding nearest
//!   first makes the result independent of the order the parts were written in and of
//!   the pruning, and keeps it 1-Lipschitz (a fold of `smin`, each 1-Lipschitz in the
//!   max norm, over order statistics).
//!
//! The point query is the idea of Barbier et al., *Lipschitz Pruning* (Eurographics
//! 2025), per point instead of per cell: no pruned tree is built, the hierarchy is the
//! cache.

use glam::Vec3A;

use super::prim;
use crate::accel::{sphere_interval, Aabb, ROBUST};

/// Parts per leaf of the hierarchy.
const LEAF: usize = 2;
/// Deepest walk stack: a median split of at most 2³² parts is 32 levels deep.
const STACK: usize = 64;
/// Values kept on the stack while gathering a smooth union's parts.
const INLINE: usize = 32;

/// One node: its box, and either two children (`count == 0`, at `first` and
/// `first + 1`) or `count` parts at `order[first..]`.
#[derive(Clone, Copy, Debug)]
struct Node {
    min: Vec3A,
    max: Vec3A,
    first: u32,
    count: u32,
}

/// The hierarchy over the parts' boxes.
#[derive(Clone, Debug)]
pub struct PartTree {
    nodes: Vec<Node>,
    /// Part indices in leaf order.
    order: Vec<u32>,
    /// Each part's box, by part index.
    boxes: Vec<Aabb>,
    /// Each part's bounding sphere (centre, radius), by part index: tight for a
    /// primitive under a similarity, where a ray entering it is on the surface.
    spheres: Vec<(Vec3A, f32)>,
    /// Whether nodes may be skipped (always, but in tests comparing with every part).
    prune: bool,
}

/// Distance from `p` to the box (0 inside).
#[inline]
fn outside(min: Vec3A, max: Vec3A, p: Vec3A) -> f32 {
    (min - p).max(p - max).max(Vec3A::ZERO).length()
}

/// A part's value raised to `bound` (its box and sphere distance) where that is positive.
/// Inside both, the part's own value stands, so a point inside a part keeps its
/// negative distance.
#[inline]
pub fn clamp(value: f32, bound: f32) -> f32 {
    if bound > 0.0 {
        value.max(bound)
    } else {
        value
    }
}

impl PartTree {
    /// The hierarchy over `boxes` (one per part, none empty): median splits on the
    /// longest axis of the centres, which for a point query does as well as SAH.
    /// `prune = false` visits every part (the reference the tests compare with).
    pub fn new(boxes: Vec<Aabb>, spheres: Vec<(Vec3A, f32)>, prune: bool) -> PartTree {
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut tree =
            PartTree { nodes: Vec::with_capacity(2 * boxes.len()), order: Vec::new(), boxes, spheres, prune };
        tree.nodes.push(Node { min: Vec3A::ZERO, max: Vec3A::ZERO, first: 0, count: 0 });
        tree.split(0, &mut order, 0);
        tree.order = order;
        tree
    }

    fn split(&mut self, node: usize, parts: &mut [u32], first: u32) {
        let bounds = parts.iter().fold(Aabb::EMPTY, |b, &i| b.union(self.boxes[i as usize]));
        self.nodes[node].min = bounds.min;
        self.nodes[node].max = bounds.max;
        if parts.len() <= LEAF {
            self.nodes[node].first = first;
            self.nodes[node].count = parts.len() as u32;
            return;
        }
        let centres = parts.iter().fold(Aabb::EMPTY, |b, &i| {
            let c = self.boxes[i as usize].centre();
            b.union(Aabb { min: c, max: c })
        });
        let extent = centres.max - centres.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = parts.len() / 2;
        let boxes = &self.boxes;
        parts.select_nth_unstable_by(mid, |&a, &b| {
            boxes[a as usize].centre()[axis].total_cmp(&boxes[b as usize].centre()[axis])
        });
        let left = self.nodes.len();
        self.nodes[node].first = left as u32;
        self.nodes.push(Node { min: Vec3A::ZERO, max: Vec3A::ZERO, first: 0, count: 0 });
        self.nodes.push(Node { min: Vec3A::ZERO, max: Vec3A::ZERO, first: 0, count: 0 });
        let (a, b) = parts.split_at_mut(mid);
        self.split(left, a, first);
        self.split(left + 1, b, first + mid as u32);
    }

    /// Bytes held, for `--stats`.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>()
            + self.order.len() * 4
            + self.boxes.len() * std::mem::size_of::<Aabb>()
            + self.spheres.len() * std::mem::size_of::<(Vec3A, f32)>()
    }

    /// How far `p` is at least from part `i`: outside its box or its sphere (0 inside both).
    #[inline]
    pub fn bound(&self, i: usize, p: Vec3A) -> f32 {
        let b = self.boxes[i];
        let (centre, radius) = self.spheres[i];
        outside(b.min, b.max, p).max((p - centre).length() - radius)
    }

    /// Walks the parts nearest first, calling `part(i, bound)` (see [`bound`](Self::bound))
    /// for each part not skipped. `part` returns the threshold from then on: a node is
    /// skipped when `p` is outside it by at least the threshold (`start` at first). A
    /// union's threshold is its best value plus `k`; a subtraction's, minus its value.
    #[inline]
    pub fn visit(&self, p: Vec3A, start: f32, mut part: impl FnMut(usize, f32) -> f32) {
        let mut threshold = start;
        let mut stack = [(0u32, 0f32); STACK];
        stack[0] = (0, outside(self.nodes[0].min, self.nodes[0].max, p));
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let (n, d) = stack[sp];
            if d > 0.0 && d >= threshold && self.prune {
                continue;
            }
            let node = self.nodes[n as usize];
            if node.count > 0 {
                for &i in &self.order[node.first as usize..(node.first + node.count) as usize] {
                    threshold = part(i as usize, self.bound(i as usize, p));
                }
                continue;
            }
            let (l, r) = (node.first, node.first + 1);
            let (nl, nr) = (self.nodes[l as usize], self.nodes[r as usize]);
            let dl = outside(nl.min, nl.max, p);
            let dr = outside(nr.min, nr.max, p);
            // The nearer child is popped first.
            let (near, far) = if dl <= dr { ((l, dl), (r, dr)) } else { ((r, dr), (l, dl)) };
            stack[sp] = far;
            stack[sp + 1] = near;
            sp += 2;
        }
    }
}

/// The smooth minimum of `values` folded nearest first with blend radius `k`; a value
/// `k` or more above the running result blends by exactly nothing, and so does every
/// value after it.
fn smooth_fold(values: &mut [f32], k: f32) -> f32 {
    values.sort_unstable_by(f32::total_cmp);
    let Some((&first, rest)) = values.split_first() else {
        return f32::INFINITY;
    };
    let mut acc = first;
    for &v in rest {
        if v - acc >= k {
            break;
        }
        acc = prim::smin(acc, v, k);
    }
    acc
}

/// A union's value, gathered part by part: the minimum for a sharp union (`k = 0`), the
/// nearest-first smooth fold for a smooth one, whose values are kept on the stack up to
/// [`INLINE`], then on the heap.
pub(crate) struct Fold {
    k: f32,
    best: f32,
    inline: [f32; INLINE],
    len: usize,
    spill: Vec<f32>,
}

impl Fold {
    /// Nothing gathered yet, blend radius `k`.
    #[inline]
    pub fn new(k: f32) -> Fold {
        Fold { k, best: f32::INFINITY, inline: [0.0; INLINE], len: 0, spill: Vec::new() }
    }

    /// The smallest value so far.
    #[inline]
    pub fn best(&self) -> f32 {
        self.best
    }

    /// Adds a part's value; returns the threshold of [`PartTree::visit`] from then on
    /// (parts at least `k` above the smallest value change nothing).
    #[inline]
    pub fn push(&mut self, v: f32) -> f32 {
        self.best = self.best.min(v);
        if self.k > 0.0 {
            if self.len < INLINE {
                self.inline[self.len] = v;
                self.len += 1;
            } else {
                self.spill.push(v);
            }
        }
        self.best + self.k
    }

    /// The union's value.
    pub fn finish(mut self) -> f32 {
        if self.k == 0.0 {
            return self.best;
        }
        if self.spill.is_empty() {
            return smooth_fold(&mut self.inline[..self.len], self.k);
        }
        self.spill.extend_from_slice(&self.inline[..self.len]);
        smooth_fold(&mut self.spill, self.k)
    }
}

/// A union at the root of an object, ready to be marched part by part along a ray: only
/// the parts whose box and sphere (grown by the blend radius) the ray is inside at `t`
/// are evaluated there, and a march between parts jumps to the next one.
///
/// Why this is exact: on a stretch of the ray outside every other part's grown box or
/// sphere, each other part's value (at least its box and sphere distance) exceeds `k`, so wherever the full union is at or below zero
/// (the surface and inside) those parts blend by exactly nothing and the field of the
/// parts in force equals the full one. That field is 1-Lipschitz, so a step by it never
/// crosses one of its zeros, and therefore never crosses the surface; a step never runs
/// past the next box's entry either, where the parts in force change.
pub struct RayParts {
    /// The parts' frame from render space (identity for unions built in render space).
    pub inv: glam::Affine3A,
    /// Render-space distance per unit of the parts' frame (the wrap's scale bound).
    pub scale: f32,
    /// The parts' hierarchy, in their frame.
    pub tree: std::sync::Arc<PartTree>,
    /// The parts' distance bounds, in their frame.
    pub parts: std::sync::Arc<[super::Sdf]>,
    /// Blend radius (0: sharp), in the parts' frame.
    pub k: f32,
}

/// The boxes a ray passes through (entry, exit, part), and those in force at a step.
type Scratch = (Vec<(f32, f32, u32)>, Vec<u32>);

thread_local! {
    /// Per-ray scratch, kept between rays so marching allocates nothing.
    static SCRATCH: std::cell::RefCell<Scratch> = const { std::cell::RefCell::new((Vec::new(), Vec::new())) };
}

impl PartTree {
    /// Every part whose box and sphere grown by `grow` the ray `origin + t·dir` (`dir` of
    /// any length) enters for `t` in `[t0, t1]`, as (entry, exit, part), in no
    /// particular order.
    fn along(&self, origin: Vec3A, dir: Vec3A, (t0, t1): (f32, f32), grow: f32, out: &mut Vec<(f32, f32, u32)>) {
        let inv_dir = dir.recip();
        // The sphere test wants a unit direction; its distances are divided back.
        let len = dir.length();
        let unit = dir / len;
        let enter = |min: Vec3A, max: Vec3A| {
            Aabb { min: min - Vec3A::splat(grow), max: max + Vec3A::splat(grow) }.slab(origin, inv_dir, t0, t1)
        };
        let mut stack = [0u32; STACK];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let node = self.nodes[stack[sp] as usize];
            if enter(node.min, node.max).is_none() {
                continue;
            }
            if node.count > 0 {
                for &i in &self.order[node.first as usize..(node.first + node.count) as usize] {
                    let b = self.boxes[i as usize];
                    let (centre, radius) = self.spheres[i as usize];
                    let (Some((a, z)), Some((a2, z2))) =
                        (enter(b.min, b.max), sphere_interval(origin, unit, centre, radius + grow))
                    else {
                        continue;
                    };
                    let (a, z) = (a.max(a2 / len), z.min(z2 / len * ROBUST));
                    if a <= z {
                        out.push((a, z, i));
                    }
                }
                continue;
            }
            stack[sp] = node.first;
            stack[sp + 1] = node.first + 1;
            sp += 2;
        }
    }
}

impl RayParts {
    /// Sphere traces the ray over `[t0, t1]` with the parts in force at each step (see
    /// [`march`](super::march::march) for the threshold); the hit distance and the
    /// threshold there.
    pub fn march(
        &self,
        ray: &crate::render::Ray,
        (t0, t1): (f32, f32),
        params: super::MarchParams,
        c: &mut crate::render::Counters,
        evals: &mut u64,
    ) -> Option<(f32, f32)> {
        SCRATCH.with(|s| {
            let (spans, active) = &mut *s.borrow_mut();
            spans.clear();
            active.clear();
            let origin = self.inv.transform_point3a(ray.origin);
            let dir = self.inv.transform_vector3a(ray.dir);
            self.tree.along(origin, dir, (t0, t1), self.k, spans);
            spans.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
            let base = ray.origin.length();
            let (mut t, mut next) = (t0, 0);
            let mut steps = 0;
            while steps < params.max_steps {
                while next < spans.len() && spans[next].0 <= t {
                    active.push(next as u32);
                    next += 1;
                }
                active.retain(|&j| spans[j as usize].1 >= t);
                if active.is_empty() {
                    // Between boxes nothing is near: jump to the next one.
                    match spans.get(next) {
                        Some(&(enter, _, _)) if enter <= t1 => t = enter,
                        _ => return None,
                    }
                    continue;
                }
                steps += 1;
                let d = self.value(ray.origin + ray.dir * t, active, spans);
                *evals += 1;
                let threshold = params.epsilon * (base + t);
                if d < threshold {
                    return Some((t, threshold));
                }
                let limit = spans.get(next).map_or(f32::INFINITY, |s| s.0 - t);
                t += d.min(limit);
                if t > t1 {
                    return None;
                }
            }
            c.budget_misses += 1;
            None
        })
    }

    /// The union's value at render-space `p` from the parts in force: those of `spans`
    /// listed in `active`.
    #[inline]
    fn value(&self, p: Vec3A, active: &[u32], spans: &[(f32, f32, u32)]) -> f32 {
        let q = self.inv.transform_point3a(p);
        let part = |j: u32| {
            let i = spans[j as usize].2 as usize;
            clamp(self.parts[i](q), self.tree.bound(i, q))
        };
        let mut fold = Fold::new(self.k);
        for &j in active {
            fold.push(part(j));
        }
        fold.finish() * self.scale
    }
}
