//! `cylinder(r, half_height)`: the capped cylinder along y.

use glam::{DVec3, Vec2, Vec3A};

use super::{profile, revolve, Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::hull::Hull;
use crate::geom::{tessellate, DAabb};
use crate::sig::{Args, Param, Range};

crate::params! {
    /// A capped cylinder along y, centred at the origin.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Cylinder {
        /// the radius
        r: f64 as Num = required, Range::POSITIVE;
        /// half the height, along y
        half_height: f64 as Num = required, Range::POSITIVE;
    }
}

impl Solid for Cylinder {
    const NAME: &'static str = "cylinder";
    const DOC: &'static str = "capped cylinder along y";
    const PARAMS: &'static [Param] = Cylinder::PARAMS;

    fn new(args: &dyn Args) -> Result<Cylinder, Refusal> {
        Ok(Cylinder::from_args(args))
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
        Hull::about_y([(1.0, 0.0, r), (0.0, 1.0, h), (0.0, -1.0, h)])
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
        move |p: Vec3A| {
            let q = profile(p);
            let d = Vec2::new(q.x - r, q.y.abs() - h);
            d.max_element().min(0.0) + d.max(Vec2::ZERO).length()
        }
    }

    fn gradient(&self) -> impl Field<Vec3A> {
        let (r, h) = (self.r as f32, self.half_height as f32);
        move |p: Vec3A| {
            let q = profile(p);
            let d = Vec2::new(q.x - r, q.y.abs() - h);
            let up = q.y.signum();
            let g = if d.max_element() > 0.0 {
                let w = d.max(Vec2::ZERO);
                Vec2::new(w.x, w.y * up).normalize()
            } else if d.x > d.y {
                Vec2::X
            } else {
                Vec2::new(0.0, up)
            };
            revolve(p, g)
        }
    }

    fn facets(&self) -> Facets {
        Facets::Inscribed(self.r)
    }

    fn tessellate(&self, res: Resolution) -> Tessellation {
        let (r, h, n) = (self.r, self.half_height, res.circle);
        Tessellation::Triangles(tessellate::count::cylinder(n), Box::new(move || tessellate::cylinder(r, h, n)))
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
