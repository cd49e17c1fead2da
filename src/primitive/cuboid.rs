//! `box(size)`: the box of half-extents `size`.

use glam::{DVec3, Vec3A};

use super::{Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::hull::Hull;
use crate::geom::{tessellate, DAabb};
use crate::sig::{Args, Param, Range};

crate::params! {
    /// An axis-aligned box centred at the origin.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Cuboid {
        /// half-extents (a number for a cube)
        size: DVec3 as Size = required, Range::POSITIVE;
    }
}

impl Solid for Cuboid {
    const NAME: &'static str = "box";
    const DOC: &'static str = "box with half-extents `size` (a number for a cube; `box(x, y, z)` also works)";
    const PARAMS: &'static [Param] = Cuboid::PARAMS;

    fn new(args: &dyn Args) -> Result<Cuboid, Refusal> {
        Ok(Cuboid::from_args(args))
    }

    fn bounds(&self) -> Option<DAabb> {
        Some(DAabb::centred(self.size))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.size.length())
    }

    fn half_space(&self) -> Option<(DVec3, f64)> {
        None
    }

    fn hull(&self) -> Option<Hull> {
        Some(Hull::planes(Hull::box_planes(crate::geom::DAabb::centred(self.size))))
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
        let b = self.size.as_vec3a();
        move |p: Vec3A| {
            let q = p.abs() - b;
            q.max(Vec3A::ZERO).length() + q.max_element().min(0.0)
        }
    }

    fn gradient(&self) -> impl Field<Vec3A> {
        let b = self.size.as_vec3a();
        move |p: Vec3A| {
            let q = p.abs() - b;
            let s = p.signum();
            if q.max_element() > 0.0 {
                // Outside: from the nearest point of the box, a face, edge or corner.
                (q.max(Vec3A::ZERO) * s).normalize()
            } else {
                // Inside: towards the nearest face.
                let axis = if q.x >= q.y && q.x >= q.z {
                    Vec3A::X
                } else if q.y >= q.z {
                    Vec3A::Y
                } else {
                    Vec3A::Z
                };
                axis * s
            }
        }
    }

    fn facets(&self) -> Facets {
        Facets::Exact
    }

    fn tessellate(&self, _: Resolution) -> Tessellation {
        let half = self.size;
        Tessellation::Triangles(tessellate::count::CUBOID, Box::new(move || tessellate::cuboid(half)))
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
