//! `cone(r, half_height)`: the cone along y, apex up; a [`CappedCone`](super::CappedCone)
//! whose top radius is 0.

use glam::{DVec3, Vec3A};

use super::capped_cone::{profile_distance, profile_gradient};
use super::{profile, revolve, Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::hull::Hull;
use crate::geom::{tessellate, DAabb};
use crate::sig::{Args, Param, Range};

crate::params! {
    /// A cone along y, base of radius `r` at `-half_height`, apex at `half_height`.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Cone {
        /// the base radius
        r: f64 as Num = required, Range::POSITIVE;
        /// half the height, along y
        half_height: f64 as Num = required, Range::POSITIVE;
    }
}

impl Solid for Cone {
    const NAME: &'static str = "cone";
    const DOC: &'static str = "capped cone along y with base radius `r`, apex up";
    const PARAMS: &'static [Param] = Cone::PARAMS;

    fn new(args: &dyn Args) -> Result<Cone, Refusal> {
        Ok(Cone::from_args(args))
    }

    fn bounds(&self) -> Option<DAabb> {
        Some(DAabb::centred(DVec3::new(self.r, self.half_height, self.r)))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.r.hypot(self.half_height))
    }

    fn half_space(&self) -> Option<(DVec3, f64)> {
        None
    }

    fn hull(&self) -> Option<Hull> {
        let (r, h) = (self.r, self.half_height);
        Hull::about_y([(2.0 * h, r, h * r), (0.0, 1.0, h), (0.0, -1.0, h)])
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
        let (r, h) = (self.r as f32, self.half_height as f32);
        move |p: Vec3A| profile_distance(profile(p), h, r, 0.0)
    }

    fn gradient(&self) -> impl Field<Vec3A> {
        let (r, h) = (self.r as f32, self.half_height as f32);
        move |p: Vec3A| revolve(p, profile_gradient(profile(p), h, r, 0.0))
    }

    fn facets(&self) -> Facets {
        Facets::Inscribed(self.r)
    }

    fn tessellate(&self, res: Resolution) -> Tessellation {
        let (r, h, n) = (self.r, self.half_height, res.circle);
        Tessellation::Triangles(tessellate::count::cone(n), Box::new(move || tessellate::cone(r, h, n)))
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
