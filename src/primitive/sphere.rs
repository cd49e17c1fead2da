//! `sphere(r)`: the ball of radius `r`.

use glam::{DVec3, Vec3A};

use super::{Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::hull::Hull;
use crate::geom::{tessellate, DAabb};
use crate::sig::{Args, Param, Range};

crate::params! {
    /// A sphere centred at the origin.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Sphere {
        /// the radius
        r: f64 as Num = required, Range::POSITIVE;
    }
}

impl Solid for Sphere {
    const NAME: &'static str = "sphere";
    const DOC: &'static str = "sphere of radius `r` centred at the origin";
    const PARAMS: &'static [Param] = Sphere::PARAMS;

    fn new(args: &dyn Args) -> Result<Sphere, Refusal> {
        Ok(Sphere::from_args(args))
    }

    fn bounds(&self) -> Option<DAabb> {
        Some(DAabb::centred(DVec3::splat(self.r)))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.r)
    }

    fn half_space(&self) -> Option<(DVec3, f64)> {
        None
    }

    fn hull(&self) -> Option<Hull> {
        None
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn hull_is_solid(&self) -> bool {
        // It has none: its bounding sphere clips its rays, padded.
        false
    }

    fn is_exact(&self) -> bool {
        true
    }

    fn distance(&self) -> impl Field<f32> {
        let r = self.r as f32;
        move |p: Vec3A| p.length() - r
    }

    fn gradient(&self) -> impl Field<Vec3A> {
        |p: Vec3A| p.try_normalize().unwrap_or(Vec3A::Y)
    }

    fn facets(&self) -> Facets {
        Facets::Inscribed(self.r)
    }

    fn tessellate(&self, res: Resolution) -> Tessellation {
        let (r, rings) = (self.r, res.rings);
        let count = tessellate::count::uvsphere(rings, 2 * rings);
        Tessellation::Triangles(count, Box::new(move || tessellate::uvsphere(r, rings, 2 * rings)))
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
