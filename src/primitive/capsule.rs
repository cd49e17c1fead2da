//! `capsule(r, half_height)`: a segment along y thickened into a solid.

use glam::{DVec3, Vec3A};

use super::{Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::Aabb;
use crate::sig::{Args, Param, Range};

crate::params! {
    /// The points within `r` of the segment from `[0, -half_height, 0]` to `[0, half_height, 0]`.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Capsule {
        /// the radius
        r: f64 as Num = required, Range::POSITIVE;
        /// half the length of the axis segment
        half_height: f64 as Num = required, Range::POSITIVE;
    }
}

impl Solid for Capsule {
    const NAME: &'static str = "capsule";
    const DOC: &'static str = "capsule along y: a segment of half-length `half_height` thickened by `r`";
    const PARAMS: &'static [Param] = Capsule::PARAMS;

    fn new(args: &dyn Args) -> Result<Capsule, Refusal> {
        Ok(Capsule::from_args(args))
    }

    fn bounds(&self) -> Option<Aabb> {
        Some(Aabb::centred(DVec3::new(self.r, self.half_height + self.r, self.r)))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.r + self.half_height)
    }

    fn half_space(&self) -> Option<(DVec3, f64)> {
        None
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn is_exact(&self) -> bool {
        true
    }

    fn distance(&self) -> impl Field<f32> {
        let (r, h) = (self.r as f32, self.half_height as f32);
        move |p: Vec3A| Vec3A::new(p.x, p.y - p.y.clamp(-h, h), p.z).length() - r
    }

    fn gradient(&self) -> impl Field<Vec3A> {
        let h = self.half_height as f32;
        move |p: Vec3A| Vec3A::new(p.x, p.y - p.y.clamp(-h, h), p.z).try_normalize().unwrap_or(Vec3A::X)
    }

    fn facets(&self) -> Facets {
        Facets::Isosurface
    }

    fn tessellate(&self, _: Resolution) -> Tessellation {
        Tessellation::Isosurface
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
