//! A twist or a bend of a convex solid at an object's root, marched by a bound that
//! follows the ray instead of the map's stretch alone.
//!
//! The child's distance `f` is convex with slope at most 1
//! ([`crate::ir::Shape::has_convex_distance`]); the ray, read through the map, is a curve
//! `q(t)` that bends by at most `M` ([`Map::curvature`]). At every `t`, `f(q(t))` lies
//! above a parabola of curvature `−M` touching it there (a supporting plane of `f`, less
//! the curve's departure from its tangent), so `v(t) + M·t²/2` is convex. Two samples
//! `(t_a, v_a)`, `(t_b, v_b)` then bound it beyond `t_b`:
//! `v(t_b + Δ) ≥ v_b + s·Δ − M·Δ²/2` with `s = (v_b − v_a)/(t_b − t_a) − M·(t_b − t_a)/2`,
//! and no surface comes before that parabola's zero. A shadow ray leaving the twisted
//! solid (where the stretch-bound step only grows by a fixed ratio) crosses what is
//! left of it in a few such steps; a ray coming in converges like a secant.

use glam::Affine3A;

use super::domain::Map;
use super::field::{cut, BoxCut};
use super::march::{threshold, MarchParams};
use super::Sdf;
use crate::trace::{Counters, Ray};

/// A warp whose map is smooth ([`Map::curvature`]) of a child whose distance is convex.
#[derive(Clone)]
pub struct RayWarp {
    /// Render space to the warp's frame.
    pub inv: Affine3A,
    /// Render-space distance per unit of the frame's (its smallest stretch, as the
    /// object's closure scales).
    pub scale: f32,
    /// The map.
    pub map: Map,
    /// The child's distance, in the frame the map reads it in.
    pub child: Sdf,
    /// The box the warp is cut to, in its frame.
    pub cut: Option<BoxCut>,
    /// The warp's `1/L`, for [`Map::bound`].
    pub k: f32,
}

impl RayWarp {
    /// The first hit along `ray` within `[t0, t1]` and the threshold there, as
    /// [`march::march`](super::march::march) finds on the object's closure (whose value
    /// this computes at each point and judges hits by), with longer steps where the
    /// curvature bound allows.
    pub fn march(
        &self,
        ray: &Ray,
        (t0, t1): (f32, f32),
        params: MarchParams,
        c: &mut Counters,
        evals: &mut u64,
    ) -> Option<(f32, f32)> {
        let o = self.inv.transform_point3a(ray.origin);
        let d = self.inv.transform_vector3a(ray.dir);
        let base = ray.origin.length();
        let bend = self.map.curvature(o + d * t0, o + d * t1, d).unwrap_or(f32::INFINITY);
        // How far a computed value may be from the true one: f32 rounding of the point
        // (within a few units of the frame's origin) and of the distance's few operations.
        let noise = 16.0 * f32::EPSILON * (1.0 + o.length() + (d * t1).length());
        let mut last: Option<(f32, f32)> = None;
        let mut t = t0;
        for _ in 0..params.max_steps {
            let p = o + d * t;
            let v = (self.child)(self.map.apply(p));
            *evals += 1;
            // The object's closure.
            let r = cut(&self.cut, p, self.map.bound(p, v, self.k)) * self.scale;
            let threshold = threshold(params.epsilon, base, t);
            if r < threshold {
                return Some((t, threshold));
            }
            let mut step = r;
            if let Some((ta, va)) = last.filter(|&(ta, _)| t > ta) {
                // The samples taken at their least and most (`low` at `t`, `va` at `ta`).
                let (gap, low) = (t - ta, v - noise);
                let slope = (low - (va + noise)) / gap - 0.5 * bend * gap;
                // The parabola's zero beyond `t` (`low > 0`), written without
                // cancellation; infinite for a line rising.
                let reach = 2.0 * low / ((slope * slope + 2.0 * bend * low).sqrt() - slope);
                if low > 0.0 && reach > step {
                    step = reach;
                }
            }
            last = Some((t, v));
            t += step;
            if t > t1 {
                return None;
            }
        }
        c.budget_misses += 1;
        None
    }
}
