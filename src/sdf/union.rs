//! Unions of many bounded parts, evaluated in time that depends on the parts near the
//! point rather than on how many there are.
//!
//! Each part's distance is taken as at least the distance to its bounding box and to
//! its bounding sphere (all are lower bounds of the distance to the part, so their
//! maximum is one too, and it is 1-Lipschitz; for a sphere part it is exact). A
//! bounding volume hierarchy over the boxes is walked nearest first; a node is skipped
//! when the point lies outside its box by at least the best value so far plus the blend
//! radius `k` (0 for a sharp union). Every part it skips has a value at least that
//! large, so:
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

use glam::{Vec3A, Vec4};

use super::prim;
use super::surf::Surf;
use crate::accel::{sphere_interval, Aabb, Bvh, Child, Rays4, ROBUST};

/// The field of no part at all: nothing there.
const NOTHING: Surf = Surf { d: f32::INFINITY, g: Vec3A::Y, mat: 0 };

/// Parts per leaf of the hierarchy.
const LEAF: usize = 2;
/// Values kept on the stack while gathering a smooth union's parts.
const INLINE: usize = 32;

/// The hierarchy over the parts' boxes, with each part's box and sphere.
#[derive(Clone, Debug)]
pub struct PartTree {
    bvh: Bvh,
    /// Each part's box, by part index.
    boxes: Vec<Aabb>,
    /// Each part's bounding sphere (centre, radius), by part index: tight for a
    /// primitive under a similarity, where a ray entering it is on the surface.
    spheres: Vec<(Vec3A, f32)>,
    /// Whether nodes may be skipped (always, but in tests comparing with every part).
    prune: bool,
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
    /// The hierarchy over `boxes` (one per part, none empty). `prune = false` visits
    /// every part (the reference the tests compare with).
    pub fn new(boxes: Vec<Aabb>, spheres: Vec<(Vec3A, f32)>, prune: bool) -> PartTree {
        PartTree { bvh: Bvh::build(&boxes, LEAF), boxes, spheres, prune }
    }

    /// Bytes held, for `--stats`.
    pub fn bytes(&self) -> usize {
        self.bvh.bytes()
            + self.boxes.len() * std::mem::size_of::<Aabb>()
            + self.spheres.len() * std::mem::size_of::<(Vec3A, f32)>()
    }

    /// How far `p` is at least from part `i`: outside its box or its sphere (0 inside both).
    #[inline]
    pub fn bound(&self, i: usize, p: Vec3A) -> f32 {
        let (centre, radius) = self.spheres[i];
        self.boxes[i].outside_squared(p).sqrt().max((p - centre).length() - radius)
    }

    /// Part `i`'s field at `p` raised to its bound as [`clamp`] raises its value, with the
    /// gradient of whichever decides: the part's, or its box's or sphere's distance's.
    #[inline]
    pub fn clamped(&self, i: usize, s: Surf, p: Vec3A) -> Surf {
        let (centre, radius) = self.spheres[i];
        let b = self.boxes[i];
        let outside = (b.min - p).max(p - b.max).max(Vec3A::ZERO);
        let (to_box, to_sphere) = (outside.length(), (p - centre).length() - radius);
        let bound = to_box.max(to_sphere);
        if bound <= 0.0 || bound <= s.d {
            return s;
        }
        // Outside the box, away from its nearest point: (p − clamp(p)) is `outside` with
        // each axis's sign.
        let g = if to_box >= to_sphere {
            Vec3A::select((p - b.centre()).cmplt(Vec3A::ZERO), -outside, outside) / to_box
        } else {
            (p - centre).normalize_or(Vec3A::Y)
        };
        Surf { d: bound, g, mat: s.mat }
    }

    /// The union's field at `p` from the parts' surface closures `surfs`, blend radius
    /// `k`: its value, its gradient and the material of the lowest part (ties go to the
    /// part written first, whatever order the walk takes). Nothing `start` or more from
    /// `p` is walked until a part is found (infinity: the whole reach; a smaller start is
    /// the caller's guess of the reach, to be checked against the value found).
    pub fn surface(&self, surfs: &[super::SurfSdf], k: f32, p: Vec3A, start: f32) -> Surf {
        // Once per hit, and a part may be a union itself: a list of its own.
        let mut near: Vec<(u32, Surf)> = Vec::with_capacity(8);
        let mut best = f32::INFINITY;
        self.visit(p, start, |i, _| {
            let s = self.clamped(i, surfs[i](p), p);
            best = best.min(s.d);
            near.push((i as u32, s));
            best + k
        });
        // In the order the parts were written, so the first of equal values wins.
        near.sort_unstable_by_key(|&(i, _)| i);
        if k == 0.0 {
            return near.iter().map(|&(_, s)| s).reduce(Surf::min).unwrap_or(NOTHING);
        }
        smooth_surf(near.iter().map(|&(_, s)| s), k)
    }

    /// A smooth subtraction's field at `p` (blend radius `k` > 0) from its first shape's
    /// field `first` there and its cutters' surface closures `surfs`: only the cutters
    /// that can blend in are evaluated (folded as `smooth_cut` folds them).
    pub fn cut_surface(&self, first: Surf, surfs: &[super::SurfSdf], k: f32, p: Vec3A) -> Surf {
        let mut near: Vec<(u32, Surf)> = Vec::with_capacity(8);
        let mut best = -first.d;
        self.visit(p, best + k, |i, _| {
            let s = self.clamped(i, surfs[i](p), p);
            best = best.min(s.d);
            near.push((i as u32, s));
            best + k
        });
        // In the order the cutters were written, so the first of equal values wins.
        near.sort_unstable_by_key(|&(i, _)| i);
        smooth_cut(first, near.into_iter().map(|(_, s)| s).collect(), k)
    }

    /// Walks the parts nearest first, calling `part(i, bound)` (see [`bound`](Self::bound))
    /// for each part not skipped. `part` returns the threshold from then on: a node is
    /// skipped when `p` is outside it by at least the threshold (`start` at first), and
    /// so is a part whose bound is positive and above it (its value, at least the bound,
    /// can change nothing: a leaf holds two parts, and the second is often far). A
    /// union's threshold is its best value plus `k`; a subtraction's, minus its value.
    #[inline]
    pub fn visit(&self, p: Vec3A, start: f32, mut part: impl FnMut(usize, f32) -> f32) {
        let mut threshold = start;
        self.bvh.nearest_first(p, start, self.prune, |i| {
            let bound = self.bound(i as usize, p);
            if !(self.prune && bound > 0.0 && bound > threshold) {
                threshold = part(i as usize, bound);
            }
            threshold
        });
    }
}

/// The smooth minimum of `values` folded nearest first with blend radius `k`; a value
/// `k` or more above the running result blends by exactly nothing, and so does every
/// value after it.
/// When `start` is given, the fold begins there (a subtraction's first shape, turned
/// inside out) and takes every value after it.
fn smooth_fold(start: Option<f32>, values: &mut [f32], k: f32) -> f32 {
    values.sort_unstable_by(f32::total_cmp);
    let (mut acc, rest) = match (start, values.split_first()) {
        (Some(a), _) => (a, &values[..]),
        (None, Some((&first, rest))) => (first, rest),
        (None, None) => return f32::INFINITY,
    };
    for &v in rest {
        if v - acc >= k {
            break;
        }
        acc = prim::smin(acc, v, k);
    }
    acc
}

/// A smooth union's field from its parts' (in the order written): the smooth minimum
/// folded nearest first as [`smooth_fold`] does, gradients blended alike, and the lowest
/// part's material (ties to the first written).
pub(crate) fn smooth_surf(parts: impl Iterator<Item = Surf>, k: f32) -> Surf {
    let mut all: Vec<Surf> = parts.collect();
    let lowest = all.iter().copied().reduce(Surf::min).unwrap_or(NOTHING);
    // A stable sort keeps equal values in the order written, as `smooth_fold` folds them.
    all.sort_by(|a, b| a.d.total_cmp(&b.d));
    let Some((&first, rest)) = all.split_first() else {
        return NOTHING;
    };
    Surf { mat: lowest.mat, ..fold_sorted(first, rest, k) }
}

/// A smooth subtraction's field: the complement of the smooth minimum of `start` (its
/// first shape turned inside out) and its cutters' `cuts` folded nearest first, so that
/// it does not depend on the order the cutters were written in, and a cutter `k` or
/// more above the running value (with every one after it) blends by nothing, which is
/// what lets [`PartTree::visit`] skip it. The cut faces take the cutter's material.
pub(crate) fn smooth_cut(start: Surf, mut cuts: Vec<Surf>, k: f32) -> Surf {
    cuts.sort_by(|a, b| a.d.total_cmp(&b.d));
    fold_sorted(start.complement(), &cuts, k).complement()
}

/// `acc` folded with `sorted` (in increasing order of value) until one is `k` or more
/// above it.
fn fold_sorted(mut acc: Surf, sorted: &[Surf], k: f32) -> Surf {
    for &s in sorted {
        if s.d - acc.d >= k {
            break;
        }
        acc = acc.smin(s, k);
    }
    acc
}

/// A union's value, gathered part by part: the minimum for a sharp union (`k = 0`), the
/// nearest-first smooth fold for a smooth one, whose values are kept on the stack up to
/// [`INLINE`], then on the heap.
pub(crate) struct Fold {
    k: f32,
    /// Where a subtraction's fold begins (see [`Fold::cut`]).
    start: Option<f32>,
    best: f32,
    inline: [f32; INLINE],
    len: usize,
    spill: Vec<f32>,
}

impl Fold {
    /// Nothing gathered yet, blend radius `k`.
    #[inline]
    pub fn new(k: f32) -> Fold {
        Fold { k, start: None, best: f32::INFINITY, inline: [0.0; INLINE], len: 0, spill: Vec::new() }
    }

    /// A smooth subtraction's fold (`k` > 0): it begins at `start`, minus its first
    /// shape's value, and gathers its cutters' values; the subtraction's value is minus
    /// what [`finish`](Self::finish) gives (see [`smooth_cut`]).
    #[inline]
    pub fn cut(start: f32, k: f32) -> Fold {
        Fold { start: Some(start), best: start, ..Fold::new(k) }
    }

    /// The threshold of [`PartTree::visit`] before any part is pushed.
    #[inline]
    pub fn threshold(&self) -> f32 {
        self.best + self.k
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
            return smooth_fold(self.start, &mut self.inline[..self.len], self.k);
        }
        self.spill.extend_from_slice(&self.inline[..self.len]);
        smooth_fold(self.start, &mut self.spill, self.k)
    }
}

/// A union at the root of an object, ready to be marched part by part along a ray: only
/// the parts whose box and sphere (grown by the blend radius) the ray is inside at `t`
/// are evaluated there, and a march between parts jumps to the next one. The parts are
/// found by a walk of the hierarchy (boxes grown by `k`) that opens nodes only as far
/// as the march has come, so a ray that hits the first part it meets opens nothing
/// behind it.
///
/// Why this is exact: on a stretch of the ray outside every other part's grown box or
/// sphere, each other part's value (at least its box and sphere distance) exceeds `k`,
/// so wherever the full union is at or below zero (the surface and inside) those parts blend by exactly nothing and the field of the
/// parts in force equals the full one. That field is 1-Lipschitz, so a step by it never
/// crosses one of its zeros, and therefore never crosses the surface; a step never runs
/// past the next part's entry either, where the parts in force change.
#[derive(Clone)]
pub struct RayParts {
    /// The parts' frame from render space (identity for unions built in render space).
    pub inv: glam::Affine3A,
    /// Render-space distance per unit of the parts' frame (the wrap's scale bound).
    pub scale: f32,
    /// The parts' hierarchy, in their frame.
    pub tree: std::sync::Arc<PartTree>,
    /// The parts' distance bounds, in their frame.
    pub parts: std::sync::Arc<[super::Sdf]>,
    /// The parts' fields with gradients and materials, in their frame.
    pub surfs: std::sync::Arc<[super::SurfSdf]>,
    /// Blend radius (0: sharp), in the parts' frame.
    pub k: f32,
}

/// Per-ray scratch: the ray hierarchy's closed nodes, the parts in force (exit, part)
/// and the parts met whose span has not begun (entry, exit, part).
type Scratch = (Vec<(Child, f32)>, Vec<(f32, u32)>, Vec<(f32, f32, u32)>);

thread_local! {
    /// Per-ray scratch, kept between rays so marching allocates nothing.
    static SCRATCH: std::cell::RefCell<Scratch> =
        const { std::cell::RefCell::new((Vec::new(), Vec::new(), Vec::new())) };
}

impl RayParts {
    /// The union's field at a hit, render-space `p` within `h` of its surface: value,
    /// gradient (analytic, in render space) and material, from one walk of the
    /// hierarchy that starts at the reach a hit can have (the value is below `h`, so
    /// every part that can blend in is within `h + k`), checked, and walked again from
    /// infinity when `p` is further out than that.
    pub fn surface(&self, p: Vec3A, h: f32) -> Surf {
        let q = self.inv.transform_point3a(p);
        let guess = h / self.scale + self.k;
        let mut s = self.tree.surface(&self.surfs, self.k, q, guess);
        if s.d + self.k > guess {
            s = self.tree.surface(&self.surfs, self.k, q, f32::INFINITY);
        }
        // The chain rule through the frame: scale·M⁻ᵀ∇f.
        let g = self.inv.matrix3.transpose() * s.g * self.scale;
        Surf { d: s.d * self.scale, g, mat: s.mat }
    }

    /// Where `ray` (in the parts' frame) is inside part `i`'s box and sphere grown by
    /// `k`, within `[t0, t1]`.
    #[inline]
    fn span(&self, i: u32, ray: &FrameRay, (t0, t1): (f32, f32)) -> Option<(f32, f32)> {
        let (centre, radius) = self.tree.spheres[i as usize];
        let (a, z) = self.tree.boxes[i as usize].grow(self.k).slab(ray.origin, ray.inv_dir, t0, t1)?;
        let (a2, z2) = sphere_interval(ray.origin, ray.unit, centre, radius + self.k)?;
        let (a, z) = (a.max(a2 / ray.len), z.min(z2 / ray.len * ROBUST));
        (a <= z).then_some((a, z))
    }

    /// Sphere traces the ray over `[t0, t1]` with the parts in force at each step (see
    /// [`march`](super::march::march) for the threshold); the hit distance and the
    /// threshold there. A sharp union is marched part by part, front to back.
    pub fn march(
        &self,
        ray: &crate::trace::Ray,
        (t0, t1): (f32, f32),
        params: super::MarchParams,
        c: &mut crate::trace::Counters,
        evals: &mut u64,
    ) -> Option<(f32, f32)> {
        let frame = FrameRay::new(self.inv.transform_point3a(ray.origin), self.inv.transform_vector3a(ray.dir));
        if self.k == 0.0 {
            return self.march_sharp(ray, &frame, (t0, t1), params, c, evals);
        }
        SCRATCH.with(|s| {
            let (closed, active, waiting) = &mut *s.borrow_mut();
            active.clear();
            waiting.clear();
            let walk = self.tree.bvh.ray_walk(frame.origin, frame.inv_dir, (t0, t1), self.k, closed);
            let base = ray.origin.length();
            let mut t = t0;
            let mut steps = 0;
            // Where the nearest node still closed begins: nothing opens before it.
            let mut unopened = f32::NEG_INFINITY;
            while steps < params.max_steps {
                if t >= unopened {
                    unopened = walk.open_until(t, closed, &mut c.node_visits, |i| {
                        if let Some((a, z)) = self.span(i, &frame, (t0, t1)) {
                            waiting.push((a, z, i));
                        }
                    });
                }
                // The next distance where the parts in force change by one beginning.
                let mut next = unopened;
                let mut w = 0;
                while w < waiting.len() {
                    let (a, z, i) = waiting[w];
                    if a <= t {
                        active.push((z, i));
                        waiting.swap_remove(w);
                    } else {
                        next = next.min(a);
                        w += 1;
                    }
                }
                active.retain(|&(z, _)| z >= t);
                if active.is_empty() {
                    // Between parts nothing is near: jump to the next one.
                    if next > t1 {
                        return None;
                    }
                    t = next;
                    continue;
                }
                steps += 1;
                let d = self.value(ray.origin + ray.dir * t, active.iter().map(|&(_, i)| i));
                *evals += 1;
                let threshold = super::march::threshold(params.epsilon, base, t);
                if d < threshold {
                    return Some((t, threshold));
                }
                t += d.min(next - t);
                if t > t1 {
                    return None;
                }
            }
            c.budget_misses += 1;
            None
        })
    }

    /// [`march`](Self::march) for a sharp union: its first hit is the nearest of its
    /// parts' first hits (from outside, the minimum first reaches zero where one of its
    /// terms does), so each part is marched alone inside its span, and the hierarchy is
    /// walked front to back as separate objects are, skipping every part that begins
    /// beyond the nearest hit so far. A part's own value steps at least as far as the
    /// union's would, and no span list is kept: on `benches/scenes/union-10000.scn` this
    /// walk traced in three quarters of the time of the resumable one (`scnc render …
    /// --stats`, medians of 15 alternating runs).
    fn march_sharp(
        &self,
        ray: &crate::trace::Ray,
        frame: &FrameRay,
        (t0, t1): (f32, f32),
        params: super::MarchParams,
        c: &mut crate::trace::Counters,
        evals: &mut u64,
    ) -> Option<(f32, f32)> {
        let base = ray.origin.length();
        let (mut visits, mut misses) = (0, 0);
        let hit = self.tree.bvh.closest(frame.origin, frame.inv_dir, t0, t1, &mut visits, |i, t_max| {
            self.march_part(i, frame, (t0, t_max), base, params, evals, &mut misses)
        });
        c.node_visits += visits;
        c.budget_misses += misses;
        hit.map(|(_, t)| (t, super::march::threshold(params.epsilon, base, t)))
    }

    /// [`march`](Self::march) of a sharp union for the lanes `mask` of `N` packets of
    /// camera rays, lane `l` of packet `g` over `spans[g][l]`: one walk of the hierarchy
    /// for all of them ([`Bvh::each_packet`]), each part met marched for each lane alone
    /// as the single ray's walk would. A lane's hit is the nearest of its parts' first
    /// hits whichever order they come in, so it is the single ray's. Per lane, the hit
    /// distance and the threshold there.
    pub fn march_packet<const N: usize>(
        &self,
        quads: &[crate::trace::Packet; N],
        mask: u32,
        spans: &[[(f32, f32); 4]; N],
        params: super::MarchParams,
        c: &mut crate::trace::Counters,
        evals: &mut [[u64; 4]; N],
    ) -> [[Option<(f32, f32)>; 4]; N] {
        debug_assert!(self.k == 0.0, "only a sharp union's first hit is the nearest of its parts'");
        let frames: [[FrameRay; 4]; N] = std::array::from_fn(|g| {
            std::array::from_fn(|l| {
                let ray = &quads[g].rays[l];
                FrameRay::new(self.inv.transform_point3a(ray.origin), self.inv.transform_vector3a(ray.dir))
            })
        });
        let across = |g: usize, f: fn(&FrameRay) -> Vec3A| {
            let v = frames[g].each_ref().map(f);
            [Vec4::from_array(v.map(|v| v.x)), Vec4::from_array(v.map(|v| v.y)), Vec4::from_array(v.map(|v| v.z))]
        };
        let rays: [Rays4; N] = std::array::from_fn(|g| Rays4 {
            origin: across(g, |f| f.origin),
            inv_dir: across(g, |f| f.inv_dir),
            t_min: Vec4::from_array(spans[g].map(|s| s.0)),
        });
        let mut t_max: [Vec4; N] = std::array::from_fn(|g| Vec4::from_array(spans[g].map(|s| s.1)));
        let base: [[f32; 4]; N] = std::array::from_fn(|g| quads[g].rays.each_ref().map(|r| r.origin.length()));
        let mut hits = [[None; 4]; N];
        let (mut visits, mut misses) = (0, 0);
        self.tree.bvh.each_packet(&rays, mask, &mut t_max, &mut visits, |i, lanes, t_max| {
            for lane in crate::trace::lanes(lanes) {
                let (g, l) = (lane / 4, lane % 4);
                let span = (spans[g][l].0, t_max[g][l]);
                if let Some(t) =
                    self.march_part(i, &frames[g][l], span, base[g][l], params, &mut evals[g][l], &mut misses)
                {
                    t_max[g][l] = t;
                    hits[g][l] = Some((t, super::march::threshold(params.epsilon, base[g][l], t)));
                }
            }
        });
        c.node_visits += visits;
        c.budget_misses += misses;
        hits
    }

    /// Part `i` alone marched along `frame` over its span within `(t0, t1)`: its first
    /// hit there. A part's own value steps at least as far as the union's would.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn march_part(
        &self,
        i: u32,
        frame: &FrameRay,
        (t0, t1): (f32, f32),
        base: f32,
        params: super::MarchParams,
        evals: &mut u64,
        misses: &mut u64,
    ) -> Option<f32> {
        let (a, z) = self.span(i, frame, (t0, t1))?;
        let i = i as usize;
        let mut t = a;
        for _ in 0..params.max_steps {
            let q = frame.origin + frame.dir * t;
            let d = clamp(self.parts[i](q), self.tree.bound(i, q)) * self.scale;
            *evals += 1;
            if d < super::march::threshold(params.epsilon, base, t) {
                return Some(t);
            }
            t += d;
            if t > z {
                return None;
            }
        }
        *misses += 1;
        None
    }

    /// The union's value at render-space `p` from the parts listed (the others being
    /// known to blend by nothing there).
    #[inline]
    fn value(&self, p: Vec3A, parts: impl Iterator<Item = u32>) -> f32 {
        let q = self.inv.transform_point3a(p);
        let part = |i: u32| clamp(self.parts[i as usize](q), self.tree.bound(i as usize, q));
        if self.k == 0.0 {
            // The minimum, without a fold's buffer to set up at every tap of a normal.
            return parts.map(part).fold(f32::INFINITY, f32::min) * self.scale;
        }
        let mut fold = Fold::new(self.k);
        for i in parts {
            fold.push(part(i));
        }
        fold.finish() * self.scale
    }
}

/// A ray in the parts' frame, with what every part's span test needs of it, computed
/// once per ray: its direction's reciprocal (slabs), unit direction and length
/// (spheres, whose distances are divided back by the length).
struct FrameRay {
    origin: Vec3A,
    dir: Vec3A,
    inv_dir: Vec3A,
    unit: Vec3A,
    len: f32,
}

impl FrameRay {
    fn new(origin: Vec3A, dir: Vec3A) -> FrameRay {
        let len = dir.length();
        FrameRay { origin, dir, inv_dir: dir.recip(), unit: dir / len, len }
    }
}
