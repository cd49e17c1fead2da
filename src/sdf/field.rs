//! Fields, warps and displacements as distance bounds: the body's tape run in f32,
//! divided by the bound of its slope the checker stated, and cut to its box. The
//! surface closure runs the tape on dual numbers, so its normal is the body's exact
//! gradient.

use std::sync::Arc;

use glam::Vec3A;

use super::surf::{Sdf, Surf, SurfSdf};
use crate::field::{Dir, Distances, Dual, Flat, Interval, JetBox, Tape};
use crate::geom::DAabb;

/// The shapes a body's `dist` calls read, as the back-end's closures.
#[derive(Clone)]
pub struct Shapes {
    /// Distances, for marching.
    pub dist: Arc<[Sdf]>,
    /// Distances with gradients, for normals.
    pub surf: Arc<[SurfSdf]>,
}

impl Distances<f32> for Shapes {
    #[inline]
    fn dist(&self, i: u32, q: [f32; 3]) -> f32 {
        self.dist[i as usize](Vec3A::from_array(q))
    }
}

impl Distances<Dual> for Shapes {
    fn dist(&self, i: u32, q: [Dual; 3]) -> Dual {
        let s = self.surf[i as usize](Vec3A::new(q[0].v, q[1].v, q[2].v));
        // The chain rule through the point's map: ∇ = Σₖ ∂d/∂qₖ ∇qₖ.
        Dual { v: s.d, g: q[0].g * s.g.x + q[1].g * s.g.y + q[2].g * s.g.z }
    }
}

/// A compiled body with what its `dist` calls read.
#[derive(Clone)]
pub struct CompiledBody {
    /// The compiled body.
    pub tape: Arc<Tape>,
    /// The same, flattened for f32, when it fits.
    flat: Option<Arc<Flat>>,
    /// What its `dist` calls read.
    pub shapes: Shapes,
}

/// A body undefined at a point (∞ − ∞) is taken as far outside there, never as a hit.
#[inline]
fn far_if_undefined(v: f32) -> f32 {
    if v.is_nan() {
        f32::MAX
    } else {
        v
    }
}

impl CompiledBody {
    /// The body of `tape`, its shapes lowered to `shapes`.
    pub fn new(tape: Tape, shapes: Shapes) -> CompiledBody {
        CompiledBody { flat: Flat::new(&tape).map(Arc::new), tape: Arc::new(tape), shapes }
    }

    /// Bytes it holds: its instructions and the closures' pointers.
    pub fn bytes(&self) -> usize {
        self.tape.ops.len() * std::mem::size_of::<(crate::field::Op, u32)>()
            + self.shapes.dist.len() * 2 * std::mem::size_of::<Sdf>()
    }

    /// The number at `p`.
    #[inline]
    pub fn num(&self, p: Vec3A) -> f32 {
        let v = match &self.flat {
            Some(f) => f.eval(p, &self.shapes),
            None => self.tape.eval::<f32>(&p, &self.shapes),
        };
        far_if_undefined(v)
    }

    /// The number at each of `p` into `out`: [`num`](Self::num) point by point.
    #[inline]
    pub fn num_lanes(&self, p: &[Vec3A], out: &mut [f32]) {
        match &self.flat {
            Some(f) => f.eval_lanes(p, &self.shapes, out),
            None => {
                for (o, p) in out.iter_mut().zip(p) {
                    *o = self.tape.eval::<f32>(p, &self.shapes);
                }
            }
        }
        for v in out.iter_mut() {
            *v = far_if_undefined(*v);
        }
    }

    /// The number at `p` with its gradient.
    pub fn dual(&self, p: Vec3A) -> Dual {
        let d = match &self.flat {
            Some(f) => f.dual(p, &self.shapes),
            None => self.tape.eval::<Dual>(&p, &self.shapes),
        };
        if d.v.is_nan() {
            Dual { v: f32::MAX, g: Vec3A::Y }
        } else {
            d
        }
    }

    /// The vector at `p`.
    #[inline]
    pub fn vec(&self, p: Vec3A) -> Vec3A {
        match &self.flat {
            Some(f) => f.eval3(p, &self.shapes),
            None => Vec3A::from_array(self.tape.eval3::<f32>(&p, &self.shapes)),
        }
    }

    /// The vector at `p`, each component with its gradient (the map's Jacobian by rows).
    pub fn vec_dual(&self, p: Vec3A) -> [Dual; 3] {
        match &self.flat {
            Some(f) => f.dual3(p, &self.shapes),
            None => self.tape.eval3::<Dual>(&p, &self.shapes),
        }
    }
}

/// A box's exact signed distance (`f32`, in render space of the field's frame).
#[derive(Clone, Copy)]
pub struct BoxCut {
    centre: Vec3A,
    half: Vec3A,
}

impl BoxCut {
    /// The box `b`.
    pub fn new(b: &DAabb) -> BoxCut {
        BoxCut { centre: ((b.min + b.max) * 0.5).as_vec3a(), half: ((b.max - b.min) * 0.5).as_vec3a() }
    }

    /// The distance at `p`.
    #[inline]
    pub fn dist(&self, p: Vec3A) -> f32 {
        let q = (p - self.centre).abs() - self.half;
        q.max(Vec3A::ZERO).length() + q.max_element().min(0.0)
    }

    /// The distance at `p` with its gradient.
    pub fn surf(&self, p: Vec3A, mat: u32) -> Surf {
        let rel = p - self.centre;
        let q = rel.abs() - self.half;
        let sign = Vec3A::select(rel.cmplt(Vec3A::ZERO), Vec3A::NEG_ONE, Vec3A::ONE);
        let outside = q.max(Vec3A::ZERO);
        let len = outside.length();
        if len > 0.0 {
            return Surf { d: len, g: outside / len * sign, mat };
        }
        let axis = q.max_position();
        let mut g = Vec3A::ZERO;
        g[axis] = sign[axis];
        Surf { d: q[axis], g, mat }
    }
}

/// `max(box, field)`: the field cut to its box, when it has one.
#[inline]
pub fn cut(b: &Option<BoxCut>, p: Vec3A, d: f32) -> f32 {
    match b {
        Some(b) => b.dist(p).max(d),
        None => d,
    }
}

/// [`cut`] with gradients.
#[inline]
pub fn cut_surf(b: &Option<BoxCut>, p: Vec3A, s: Surf) -> Surf {
    match b {
        Some(b) => b.surf(p, s.mat).max(s),
        None => s,
    }
}

impl Distances<Dir> for Shapes {
    /// A shape's distance over a stretch of a ray: within the stretch's half-diagonal
    /// of its value at the middle, changing no faster than the point moves (a distance
    /// bound is 1-Lipschitz).
    fn dist(&self, i: u32, q: [Dir; 3]) -> Dir {
        let mid = Vec3A::new(q[0].v.mid() as f32, q[1].v.mid() as f32, q[2].v.mid() as f32);
        let r = (q.iter().map(|c| c.v.radius().powi(2)).sum::<f64>()).sqrt();
        let d = self.dist[i as usize](mid) as f64;
        let s = Dir::stretch(&q);
        Dir { v: Interval::new(d - r, d + r), g: [Interval::new(-s, s)], n: s }
    }
}

/// A field at the root of an object, marched by segment tracing (Galin et al., 2020):
/// along a stretch of the ray, the bound of the body's derivative *along the ray*
/// (interval arithmetic over the stretch's box, [`Dir`]) replaces the bound of its
/// slope over the whole box. Near a surface that bound is close to the derivative
/// itself, so a step lands close to the surface rather than a slope-ratio short of it;
/// far from one, a stretch with no surface is crossed in one step.
#[derive(Clone)]
pub struct RayField {
    /// Render space to the field's frame.
    pub inv: glam::Affine3A,
    /// Render-space distance per unit of the body's value: the frame's smallest
    /// stretch over the field's slope bound (the closure's scale, so a hit is judged
    /// as the closure judges it).
    pub scale: f32,
    /// The body.
    pub body: CompiledBody,
    /// The box it is cut to, in its frame.
    pub bounds: Option<(Vec3A, Vec3A)>,
    /// Whether the body is a convex function of the point ([`crate::ir::Shape::is_convex`]):
    /// then a ray's plain steps may go as far as the secant through its last two points.
    pub convex: bool,
}

/// The first stretch a derivative bound is asked for, as a share of what is left of
/// the ray's span within the field.
const FIRST_SEGMENT: f32 = 0.125;

/// Plain sphere-tracing steps before segments.
const PLAIN_STEPS: u32 = 128;

/// How much longer than its bound a plain step is tried (Keinert et al. suggest 1.2
/// to 1.6; 1.5 then 1.2 took the fewest steps on the gyroid of benches/scenes).
const OMEGA: f32 = 1.5;

/// The same after a longer step has failed on a ray: near a surface seen at a slant.
const OMEGA_AFTER_MISS: f32 = 1.2;

/// A ray in a field's frame and where its plain march has got to.
#[derive(Clone, Copy, Default)]
struct Lane {
    o: Vec3A,
    d: Vec3A,
    /// The ray origin's distance from the camera, for the hit threshold.
    base: f32,
    t: f32,
    end: f32,
    steps: u32,
    /// Where the last step started, how far its bound reached, and whether the step
    /// went further than that.
    prev_t: f32,
    prev_reach: f32,
    relaxed: bool,
    omega: f32,
    /// A secant step of a convex body went past the surface (by f32 rounding): the
    /// lane takes plain steps from then on.
    plain: bool,
}

/// What a plain step found.
enum Step {
    Hit(f32, f32),
    Miss,
    On,
}

impl Lane {
    fn at(&self) -> Vec3A {
        self.o + self.d * self.t
    }
}

impl RayField {
    /// `ray` over `[t0, t1]` in the field's frame, cut to its box; `None` if it misses
    /// the box.
    fn lane(&self, ray: &crate::trace::Ray, (t0, t1): (f32, f32)) -> Option<Lane> {
        let o = self.inv.transform_point3a(ray.origin);
        let d = self.inv.transform_vector3a(ray.dir);
        let (t, end) = match self.bounds {
            Some((lo, hi)) => {
                // The slab test in the field's frame: outside the box is empty.
                let inv_d = d.recip();
                let (a, b) = ((lo - o) * inv_d, (hi - o) * inv_d);
                let near = a.min(b).max_element().max(t0);
                let far = a.max(b).min_element().min(t1);
                // (NaN from a ray along a face: nothing to march.)
                if near > far || near.is_nan() || far.is_nan() {
                    return None;
                }
                (near, far)
            }
            None => (t0, t1),
        };
        let base = ray.origin.length();
        Some(Lane {
            o,
            d,
            base,
            t,
            end,
            steps: 0,
            prev_t: t,
            prev_reach: 0.0,
            relaxed: false,
            omega: OMEGA,
            plain: false,
        })
    }

    /// Plain steps a lane takes before segments.
    fn plain_steps(params: super::MarchParams) -> u32 {
        PLAIN_STEPS.min(params.max_steps)
    }

    /// One plain step of `lane`, the body being `v` where it stands.
    ///
    /// Plain sphere tracing first: most rays meet the surface in a few of its cheap
    /// steps. One that crawls (grazing, or where the body is shallow beside its
    /// steepest parts) goes on by segments ([`segments`](Self::segments)), whose bound
    /// follows the body along it.
    ///
    /// Over-relaxed (Keinert et al., "Enhanced Sphere Tracing", 2014): a step of OMEGA
    /// times the bound is kept when the bounds at both of its ends cover it (the
    /// spheres overlap); else the march goes back to the plain step and relaxes less
    /// from there. A field is rarely as steep near its surface as its bound, so the
    /// plain step lands a slope ratio short of the surface and converges to it
    /// geometrically; the longer step shortens that (28.6 → 22.0 evaluations per ray
    /// on the gyroid's primary rays, docs/fields.md).
    #[inline]
    fn plain_step(&self, lane: &mut Lane, v: f32, params: super::MarchParams) -> Step {
        if self.convex {
            return self.convex_step(lane, v, params);
        }
        lane.steps += 1;
        let (t, r) = (lane.t, v * self.scale);
        if lane.relaxed && r < t - lane.prev_t - lane.prev_reach {
            // A gap the bounds do not cover: it may hold a surface.
            (lane.t, lane.relaxed, lane.omega) = (lane.prev_t + lane.prev_reach, false, OMEGA_AFTER_MISS);
            return Step::On;
        }
        let threshold = super::march::threshold(params.epsilon, lane.base, t);
        if r < threshold {
            return Step::Hit(t, threshold);
        }
        (lane.prev_t, lane.prev_reach) = (t, r);
        lane.t = t + r * lane.omega;
        lane.relaxed = lane.omega > 1.0;
        if lane.t > lane.end {
            if !lane.relaxed || t + r > lane.end {
                return Step::Miss;
            }
            // The long step may have jumped a surface just before the end.
            (lane.t, lane.relaxed, lane.omega) = (t + r, false, OMEGA_AFTER_MISS);
        }
        Step::On
    }

    /// [`plain_step`](Self::plain_step) for a convex body: the step goes as far as
    /// the secant through the lane's last two points meets zero, when that is further
    /// than the bound. Along a line a convex body is a convex function, which lies above
    /// every secant beyond the secant's points, so no surface comes before that zero
    /// (and with two points outside, the body is falling there, the secant converging on
    /// the surface faster than the geometric approach of sphere tracing). Where the body
    /// rises instead, it rises from there on: the ray has passed the solid.
    ///
    /// The secant is taken only where the body fell by more than the hit threshold since
    /// the last point, so f32 rounding (far under the threshold) barely moves it; a step
    /// that still lands inside beyond the threshold goes back to the plain step, and the
    /// lane keeps to plain steps.
    #[inline]
    fn convex_step(&self, lane: &mut Lane, v: f32, params: super::MarchParams) -> Step {
        lane.steps += 1;
        let (t, r) = (lane.t, v * self.scale);
        let threshold = super::march::threshold(params.epsilon, lane.base, t);
        if r < threshold {
            if lane.relaxed && r < -threshold {
                (lane.t, lane.relaxed, lane.plain) = (lane.prev_t + lane.prev_reach, false, true);
                return Step::On;
            }
            return Step::Hit(t, threshold);
        }
        let fell = lane.prev_reach - r;
        if fell < -threshold && lane.steps > 1 {
            // Rising: beyond here the body is above the secant, which only rises.
            return Step::Miss;
        }
        let secant = if !lane.plain && fell > threshold { r * (t - lane.prev_t) / fell } else { 0.0 };
        (lane.prev_t, lane.prev_reach, lane.relaxed) = (t, r, secant > r);
        // Past the end only by the bound: a secant past it is checked at the end.
        if t + r > lane.end {
            return Step::Miss;
        }
        lane.t = (t + r.max(secant)).min(lane.end);
        Step::On
    }

    /// The first hit along `ray` within `[t0, t1]`, and the threshold there.
    pub fn march(
        &self,
        ray: &crate::trace::Ray,
        span: (f32, f32),
        params: super::MarchParams,
        c: &mut crate::trace::Counters,
        evals: &mut u64,
    ) -> Option<(f32, f32)> {
        let mut lane = self.lane(ray, span)?;
        while lane.steps < Self::plain_steps(params) {
            let v = self.body.num(lane.at());
            *evals += 1;
            match self.plain_step(&mut lane, v, params) {
                Step::Hit(t, threshold) => return Some((t, threshold)),
                Step::Miss => return None,
                Step::On => {}
            }
        }
        self.segments(lane, params, c, evals)
    }

    /// [`march`](Self::march) for the lanes `mask` of `N` packets of camera rays, lane
    /// `l` of packet `g` over `spans[g][l]`: the plain steps of all lanes still
    /// marching evaluate the body together ([`CompiledBody::num_lanes`]), the same steps to the
    /// bit as one by one.
    pub fn march_packet<const N: usize>(
        &self,
        quads: &[crate::trace::Packet; N],
        mask: u32,
        spans: &[[(f32, f32); 4]; N],
        params: super::MarchParams,
        c: &mut crate::trace::Counters,
        evals: &mut [[u64; 4]; N],
    ) -> [[Option<(f32, f32)>; 4]; N] {
        // Up to 4×4 camera rays: a block is four packets of four.
        const { assert!(N <= 4, "a packet march takes at most 16 lanes") };
        let mut hits = [[None; 4]; N];
        // Each lane's march by its number `4·g + l`; `active` lists those still taking
        // plain steps, `later` those going on by segments.
        let mut lanes = [Lane::default(); 16];
        let (mut active, mut m, mut later) = ([0u8; 16], 0, 0u32);
        for k in crate::trace::lanes(mask) {
            let (g, l) = (k / 4, k % 4);
            if let Some(lane) = self.lane(&quads[g].rays[l], spans[g][l]) {
                lanes[k] = lane;
                active[m] = k as u8;
                m += 1;
            }
        }
        let (mut points, mut values) = ([Vec3A::ZERO; 16], [0.0f32; 16]);
        while m > 0 {
            for (p, &k) in points.iter_mut().zip(&active[..m]) {
                *p = lanes[k as usize].at();
            }
            self.body.num_lanes(&points[..m], &mut values[..m]);
            let mut kept = 0;
            for j in 0..m {
                let k = active[j] as usize;
                let (g, l, lane) = (k / 4, k % 4, &mut lanes[k]);
                evals[g][l] += 1;
                match self.plain_step(lane, values[j], params) {
                    Step::Hit(t, threshold) => hits[g][l] = Some((t, threshold)),
                    Step::Miss => {}
                    Step::On if lane.steps >= Self::plain_steps(params) => later |= 1 << k,
                    Step::On => {
                        active[kept] = k as u8;
                        kept += 1;
                    }
                }
            }
            m = kept;
        }
        for k in crate::trace::lanes(later) {
            let (g, l) = (k / 4, k % 4);
            hits[g][l] = self.segments(lanes[k], params, c, &mut evals[g][l]);
        }
        hits
    }

    /// The march of `lane` after its plain steps: by segments, each with a bound of
    /// the body's slope along it.
    fn segments(
        &self,
        lane: Lane,
        params: super::MarchParams,
        c: &mut crate::trace::Counters,
        evals: &mut u64,
    ) -> Option<(f32, f32)> {
        let Lane { o, d, base, end, mut steps, .. } = lane;
        // The segments start where the bounds have reached.
        let mut t = if lane.relaxed { lane.prev_t + lane.prev_reach } else { lane.t };
        if steps >= params.max_steps {
            c.budget_misses += 1;
            return None;
        }
        let mut seg = (end - t) * FIRST_SEGMENT;
        loop {
            let v = self.body.num(o + d * t);
            *evals += 1;
            steps += 1;
            let threshold = super::march::threshold(params.epsilon, base, t);
            if v * self.scale < threshold {
                return Some((t, threshold));
            }
            if steps >= params.max_steps {
                c.budget_misses += 1;
                return None;
            }
            let stop = (t + seg).min(end);
            let lambda = self.along(o, d, t, stop);
            c.segment_bounds += 1;
            // Sphere-trace within the stretch with its bound: no surface before t + v/λ.
            let mut v = v;
            let mut inner = 0;
            loop {
                let step = v / lambda;
                if t + step >= stop || step.is_nan() {
                    // Nothing in the stretch: go to its end, and try a longer one.
                    t = stop;
                    seg *= 2.0;
                    break;
                }
                t += step;
                inner += 1;
                if inner == 4 {
                    // The bound is loose for what is left: a shorter stretch, a new bound.
                    seg = (stop - t) * 0.5;
                    break;
                }
                v = self.body.num(o + d * t);
                *evals += 1;
                steps += 1;
                let threshold = super::march::threshold(params.epsilon, base, t);
                if v * self.scale < threshold {
                    return Some((t, threshold));
                }
            }
            if t >= end {
                return None;
            }
        }
    }

    /// A bound of the body's rate of change along `o + t·d` for `t` in `[a, b]`.
    fn along(&self, o: Vec3A, d: Vec3A, a: f32, b: f32) -> f32 {
        let (p, q) = (o + d * a, o + d * b);
        let at = [0, 1, 2].map(|i| Interval::new(p[i].min(q[i]) as f64, p[i].max(q[i]) as f64));
        let region = JetBox { at, seed: [[d.x as f64], [d.y as f64], [d.z as f64]] };
        let j = self.body.tape.eval::<Dir>(&region, &self.body.shapes);
        // A little above, for the f32 rounding of the point's value; never zero.
        ((j.g[0].mag() * (1.0 + 1e-4)) as f32).max(f32::MIN_POSITIVE)
    }
}
