//! `plane(normal, offset)`: the half-space below a plane.

use glam::{DVec3, Vec3A};

use super::{Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::hull::Hull;
use crate::geom::DAabb;
use crate::sig::{Args, Param, Range};

crate::params! {
    /// The half-space `normal·p ≤ offset`; the IR keeps `normal` unit.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Plane {
        /// the direction out of the solid (any length)
        normal: DVec3 as Vec3 = [0.0, 1.0, 0.0], Range::NONZERO;
        /// how far the plane lies along `normal` from the origin
        offset: f64 as Num = 0.0;
    }
}

impl Solid for Plane {
    const NAME: &'static str = "plane";
    const DOC: &'static str = "the half-space below `normal·p = offset`";
    const PARAMS: &'static [Param] = Plane::PARAMS;

    fn new(args: &dyn Args) -> Result<Plane, Refusal> {
        let Plane { normal, offset } = Plane::from_args(args);
        // The offset is along the unit normal, as written with a unit one.
        let normal = normal.try_normalize().ok_or(Refusal { param: "normal", rule: "a non-zero vector".into() })?;
        Ok(Plane { normal, offset })
    }

    fn bounds(&self) -> Option<DAabb> {
        None
    }

    fn sphere_radius(&self) -> Option<f64> {
        None
    }

    fn half_space(&self) -> Option<(DVec3, f64)> {
        Some((self.normal, self.offset))
    }

    fn hull(&self) -> Option<Hull> {
        None
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn hull_is_solid(&self) -> bool {
        // It has none: a half-space clips its rays instead.
        false
    }

    fn is_exact(&self) -> bool {
        true
    }

    fn distance(&self) -> impl Field<f32> {
        let (n, offset) = (self.normal.as_vec3a(), self.offset as f32);
        move |p: Vec3A| p.dot(n) - offset
    }

    fn gradient(&self) -> impl Field<Vec3A> {
        let n = self.normal.as_vec3a();
        move |_: Vec3A| n
    }

    fn facets(&self) -> Facets {
        Facets::Exact
    }

    fn tessellate(&self, _: Resolution) -> Tessellation {
        Tessellation::HalfSpace { normal: self.normal, offset: self.offset }
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
