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

/// What [`refine`] makes of a hit the bound alone accepted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Refined {
    /// The surface is within the threshold of `t`: the hit distance and threshold.
    Hit(f32, f32),
    /// The ray only passes near the surface: march on from `t`.
    Resume(f32),
    /// The ray left `[t0, t1]` or ran out of steps.
    Miss,
}

/// Confirms a hit at `t` on a distance bound `f` that may understate the distance
/// (divided by a stated or estimated slope `L` above the field's true one near its
/// surface): there `f < threshold` holds in a shell up to `L` thresholds thick, and
/// taking it for the surface draws the shape bigger the larger `L` is stated.
///
/// The hit stands where Newton's steps from it, with the object's surface closure
/// `surf` (the value and analytic gradient its hits are shaded with, scaled as `f` is),
/// reach the surface within the threshold (`on_surface`): that does not depend on
/// `L`. Where they do not, the ray steps by the first-order distance `f / |∇f|`, at
/// least the threshold (no surface nearer under the field's linear model, and a step
/// that still lands inside is bisected back to the crossing) until they do, or until
/// the bound rises past the threshold again, as beside a silhouette, where the march
/// resumes. A shape's silhouette is then where its field's zero set is, whatever `L`
/// says; `L` only sets how many steps the march takes getting there.
#[inline(never)]
pub fn refine(
    f: &dyn Fn(Vec3A) -> f32,
    surf: &dyn Fn(Vec3A) -> super::Surf,
    ray: &Ray,
    (t, t1): (f32, f32),
    params: MarchParams,
    c: &mut Counters,
    evals: &mut u64,
) -> Refined {
    let (origin, dir) = (ray.origin, ray.dir);
    let base = origin.length();
    let mut t = t;
    let super::Surf { mut d, mut g, .. } = surf(origin + dir * t);
    *evals += 1;
    for step in 0..params.max_steps {
        let threshold = threshold(params.epsilon, base, t);
        if d >= threshold {
            // Where the walk found the hit, the object's closure may differ by rounding
            // (a field marched in its own frame): the walk's word stands there.
            return if step == 0 { Refined::Hit(t, threshold) } else { Refined::Resume(t) };
        }
        if d <= 0.0 || d.is_nan() {
            return Refined::Hit(t, threshold);
        }
        // (A NaN slope fails the range test too.)
        let slope = g.length();
        if !(f32::MIN_POSITIVE..).contains(&slope) {
            return Refined::Hit(t, threshold);
        }
        if on_surface(surf, origin + dir * t, (d, g), threshold, evals) {
            return Refined::Hit(t, threshold);
        }
        // The step trusts the field's linear model where the model predicts the value at
        // its end. Where it does not (the field is not linear at the step's scale: a
        // crease where a `max` switches branches, features the size of the threshold),
        // a shorter step is tried, down to the bound's own step `d`, which no surface
        // can be nearer than whatever the model says. Taking the bound's hit there, as
        // this did before, drew surfaces that are not there: beside the crease of
        // `max(sheet, ball)` the ball's branch reads its distance over the whole field's
        // slope bound, a shell that many thresholds thick around a sphere the solid only
        // touches at its rim (the gyroid room's bright rim, docs/light.md).
        let mut reach = (d / slope).max(threshold);
        let (next, dn, gn) = loop {
            let next = (t + reach).min(t1);
            let super::Surf { d: dn, g: gn, .. } = surf(origin + dir * next);
            *evals += 1;
            let predicted = d + g.dot(dir) * (next - t);
            if reach <= d || (dn - predicted).abs() <= 0.5 * d {
                break (next, dn, gn);
            }
            reach = (reach * SHORTER).max(d);
        };
        if dn < 0.0 {
            // Crossed: bisect to the threshold, keeping the outside end.
            let (mut a, mut b) = (t, next);
            for _ in 0..BISECTIONS {
                if b - a <= threshold {
                    break;
                }
                let m = 0.5 * (a + b);
                *evals += 1;
                if f(origin + dir * m) < 0.0 {
                    b = m;
                } else {
                    a = m;
                }
            }
            return Refined::Hit(a, self::threshold(params.epsilon, base, a));
        }
        if next >= t1 {
            return Refined::Miss;
        }
        (t, d, g) = (next, dn, gn);
    }
    c.budget_misses += 1;
    Refined::Miss
}

/// Whether the solid's surface is within `reach` of `p`, where the bound is `d` and its
/// gradient `g`: Newton's steps onto the zero set, each along the gradient of the branch
/// that holds the value where it stands, so that beside a crease of `max(a, b)` they
/// alternate between the two faces and end on the edge where they meet. The first-order
/// distance of the branch in hand alone cannot see that: beside a gyroid sheet cut by a
/// ball, just outside the ball, the sheet's branch may read a distance under the
/// threshold where the solid is many thresholds away. Steps that do not converge (a flat
/// gradient, a field not smooth at this scale) cannot tell, and the point counts as on
/// the surface, as the bound alone would have it.
fn on_surface(
    surf: &dyn Fn(Vec3A) -> super::Surf,
    p: Vec3A,
    (mut d, mut g): (f32, Vec3A),
    reach: f32,
    evals: &mut u64,
) -> bool {
    let mut q = p;
    for _ in 0..NEWTON_STEPS {
        let gg = g.length_squared();
        if gg.is_nan() || gg <= 0.0 || d * d <= gg * (reach * CONVERGED).powi(2) {
            return true;
        }
        q -= g * (d / gg);
        if (q - p).length() > reach {
            return false;
        }
        let next = surf(q);
        *evals += 1;
        (d, g) = (next.d, next.g);
    }
    true
}

/// Newton's steps [`on_surface`] takes: a crease between two faces converges in a few.
const NEWTON_STEPS: u32 = 6;

/// The first-order distance, in parts of the reach, below which [`on_surface`] has
/// arrived.
const CONVERGED: f32 = 0.05;

/// What a step the linear model did not predict is cut to before it is tried again.
const SHORTER: f32 = 0.25;

/// Halvings of a crossed step: enough to bring any f32 span below a threshold of a
/// millionth of it, and an end where the threshold is zero (at the camera).
const BISECTIONS: u32 = 24;
