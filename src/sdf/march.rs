//! Sphere tracing: step along the ray by the distance bound until it falls below the
//! hit threshold, the ray leaves the interval, or the step budget runs out.
//!
//! The threshold is *relative* ([`threshold`]): a hit is accepted when
//! `f(p) < epsilon · (t + min(t, |origin|))`. For a camera ray (the camera is the origin of
//! render space) that is `epsilon · t`, a cone around the ray whose width grows like a
//! pixel's footprint, so the same `epsilon` means the same on-screen accuracy at any
//! depth. A secondary ray starting `|origin|` from the camera is seen through that pixel,
//! at `|origin| + t` from the camera: far along it, its cone is that footprint; near its
//! start it narrows to nothing, as the ray leaves an exact point. So a surface beside the
//! point a ray leaves (the floor at the foot of a wall, for the wall's shadow rays) is
//! never taken for a hit at the start, as it was when the cone began at the footprint's
//! width.

use glam::Vec3A;

use crate::trace::{Counters, Ray};

/// The hit threshold `t` along a ray whose origin is `base` from the camera.
#[inline(always)]
pub fn threshold(epsilon: f32, base: f32, t: f32) -> f32 {
    epsilon * (t + t.min(base))
}

/// The accuracy knobs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchParams {
    /// Relative hit threshold.
    pub epsilon: f32,
    /// Step budget per march.
    pub max_steps: u32,
}

/// Marches `f` along the ray for `t` in `[t0, t1]`. Returns the hit distance and
/// the threshold used there (the hit point's error bound).
#[inline]
pub fn march(
    f: &dyn Fn(Vec3A) -> f32,
    ray: &Ray,
    t0: f32,
    t1: f32,
    params: MarchParams,
    c: &mut Counters,
    evals: &mut u64,
) -> Option<(f32, f32)> {
    // Written so that a NaN distance steps (and runs out of budget) rather than hits.
    walk(f, ray, (t0, t1), params, c, evals, |d, threshold, _| if d < threshold { None } else { Some(d) })
}

/// Marches out of the solid `f < 0` from a ray that starts inside it (a refracted ray),
/// for `t` in `[t0, t1]`: steps by `−f`, the distance to the nearest face from within.
/// A wall thinner than the hit threshold must still be crossed, not found where the ray
/// came in, so no hit is taken before the ray has moved, a step is at least the
/// threshold, and a ray found outside the solid (at the start, or after a step that
/// crossed a face closer than the threshold) has left it there. Returns the hit distance
/// and the threshold used there.
#[inline]
pub fn march_out(
    f: &dyn Fn(Vec3A) -> f32,
    ray: &Ray,
    t0: f32,
    t1: f32,
    params: MarchParams,
    c: &mut Counters,
    evals: &mut u64,
) -> Option<(f32, f32)> {
    walk(f, ray, (t0, t1), params, c, evals, |d, threshold, t| {
        if d >= 0.0 || (-d < threshold && t > t0) {
            None
        } else {
            Some((-d).max(threshold))
        }
    })
}

/// The loop both marches share: evaluate `f` at `t`, ask `step(f, threshold, t)` how far
/// to go (`None`: a hit here), until the ray passes `t1` or the step budget runs out.
#[inline(always)]
fn walk(
    f: &dyn Fn(Vec3A) -> f32,
    ray: &Ray,
    (t0, t1): (f32, f32),
    params: MarchParams,
    c: &mut Counters,
    evals: &mut u64,
    step: impl Fn(f32, f32, f32) -> Option<f32>,
) -> Option<(f32, f32)> {
    let (origin, dir) = (ray.origin, ray.dir);
    let base = origin.length();
    let mut t = t0;
    for _ in 0..params.max_steps {
        let d = f(origin + dir * t);
        *evals += 1;
        let threshold = threshold(params.epsilon, base, t);
        let Some(dt) = step(d, threshold, t) else {
            return Some((t, threshold));
        };
        t += dt;
        if t > t1 {
            return None;
        }
    }
    c.budget_misses += 1;
    None
}
