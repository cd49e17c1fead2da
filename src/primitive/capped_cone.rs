//! `capped_cone(r_bottom, r_top, half_height)`: a frustum along y. Its profile's exact
//! distance (after Inigo Quilez's `sdCappedCone`) is shared with [`Cone`](super::Cone).

use glam::{DVec3, Vec2, Vec3A};

use super::{profile, revolve, Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::hull::Hull;
use crate::geom::{tessellate, DAabb};
use crate::sig::{Args, Param, Range};

crate::params! {
    /// A cone cut square to its axis: radius `r_bottom` at `y = -half_height`, `r_top` at
    /// `y = half_height`.
    #[derive(Clone, Debug, PartialEq)]
    pub struct CappedCone {
        /// the radius at the bottom (0 for an apex)
        r_bottom: f64 as Num = required, Range::NONNEG;
        /// the radius at the top (0 for an apex)
        r_top: f64 as Num = required, Range::NONNEG;
        /// half the height, along y
        half_height: f64 as Num = required, Range::POSITIVE;
    }
}

impl CappedCone {
    fn widest(&self) -> f64 {
        self.r_bottom.max(self.r_top)
    }
}

impl Solid for CappedCone {
    const NAME: &'static str = "capped_cone";
    const DOC: &'static str = "a cone along y cut at both ends: radius `r_bottom` at the bottom, `r_top` at the top";
    const PARAMS: &'static [Param] = CappedCone::PARAMS;

    fn new(args: &dyn Args) -> Result<CappedCone, Refusal> {
        let c = CappedCone::from_args(args);
        if c.widest() == 0.0 {
            return Err(Refusal { param: "r_top", rule: "greater than 0 when `r_bottom` is 0".into() });
        }
        Ok(c)
    }

    fn bounds(&self) -> Option<DAabb> {
        Some(DAabb::centred(DVec3::new(self.widest(), self.half_height, self.widest())))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.widest().hypot(self.half_height))
    }

    fn half_space(&self) -> Option<(DVec3, f64)> {
        None
    }

    fn hull(&self) -> Option<Hull> {
        // The side through (r_bottom, -h) and (r_top, h), and the caps.
        let (r1, r2, h) = (self.r_bottom, self.r_top, self.half_height);
        Hull::about_y([(2.0 * h, r1 - r2, h * (r1 + r2)), (0.0, 1.0, h), (0.0, -1.0, h)])
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn hull_is_solid(&self) -> bool {
        true
    }

    fn is_exact(&self) -> bool {
        true
    }

    fn distance(&self) -> impl Field<f32> {
        let (r1, r2, h) = (self.r_bottom as f32, self.r_top as f32, self.half_height as f32);
        move |p: Vec3A| profile_distance(profile(p), h, r1, r2)
    }

    fn gradient(&self) -> impl Field<Vec3A> {
        let (r1, r2, h) = (self.r_bottom as f32, self.r_top as f32, self.half_height as f32);
        move |p: Vec3A| revolve(p, profile_gradient(profile(p), h, r1, r2))
    }

    fn facets(&self) -> Facets {
        Facets::Inscribed(self.widest())
    }

    fn tessellate(&self, res: Resolution) -> Tessellation {
        let (r1, r2, h, n) = (self.r_bottom, self.r_top, self.half_height, res.circle);
        let count = tessellate::count::frustum(r1, r2, n);
        Tessellation::Triangles(count, Box::new(move || tessellate::frustum(r1, r2, h, n)))
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}

/// The profile's two candidates at `q` (radius, y): the vector from the nearest point
/// of the nearer cap, from the nearest point of the slanted side, and the sign (−1 inside).
#[inline]
fn candidates(q: Vec2, h: f32, r1: f32, r2: f32) -> (Vec2, Vec2, f32) {
    let k1 = Vec2::new(r2, h);
    let k2 = Vec2::new(r2 - r1, 2.0 * h);
    let cap = Vec2::new(q.x - q.x.min(if q.y < 0.0 { r1 } else { r2 }), q.y.abs() - h);
    let side = q - k1 + k2 * ((k1 - q).dot(k2) / k2.length_squared()).clamp(0.0, 1.0);
    let s = if side.x < 0.0 && cap.y < 0.0 { -1.0 } else { 1.0 };
    (cap, side, s)
}

/// The exact signed distance from `q` (radius, y) to the profile of the frustum of
/// half-height `h`, radius `r1` at the bottom and `r2` at the top.
#[inline]
pub(super) fn profile_distance(q: Vec2, h: f32, r1: f32, r2: f32) -> f32 {
    let (cap, side, s) = candidates(q, h, r1, r2);
    s * cap.length_squared().min(side.length_squared()).sqrt()
}

/// The gradient of [`profile_distance`]: away from the nearest point of the profile's
/// boundary, outward.
#[inline]
pub(super) fn profile_gradient(q: Vec2, h: f32, r1: f32, r2: f32) -> Vec2 {
    let (cap, side, s) = candidates(q, h, r1, r2);
    let up = q.y.signum();
    // `cap` measures |y|: its y component points away from the cap it is nearest.
    let away = if cap.length_squared() < side.length_squared() { Vec2::new(cap.x, cap.y * up) } else { side };
    (away * s).try_normalize().unwrap_or(Vec2::new(0.0, up))
}
