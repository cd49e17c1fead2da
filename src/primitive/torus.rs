//! `torus(major, minor)`: the ring in the xz plane. A tube as wide as its ring or wider
//! (a horn or spindle torus) overlaps itself across the axis: its distance is then exact
//! only outside (inside it is a bound), and the isosurface mesher makes its triangles,
//! as a parametric surface would fold through the solid.

use glam::{DVec3, Vec2, Vec3A};

use super::{profile, revolve, Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::hull::Hull;
use crate::geom::{tessellate, DAabb};
use crate::sig::{Args, Param, Range};

crate::params! {
    /// A torus in the xz plane, centred at the origin.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Torus {
        /// the distance from the centre to the middle of the tube
        major: f64 as Num = required, Range::POSITIVE;
        /// the tube's radius
        minor: f64 as Num = required, Range::POSITIVE;
    }
}

impl Torus {
    /// Whether the tube leaves a hole: then the solid is the tube's parametric surface.
    fn is_ring(&self) -> bool {
        self.minor < self.major
    }
}

impl Solid for Torus {
    const NAME: &'static str = "torus";
    const DOC: &'static str = "torus in the xz plane";
    const PARAMS: &'static [Param] = Torus::PARAMS;

    fn new(args: &dyn Args) -> Result<Torus, Refusal> {
        Ok(Torus::from_args(args))
    }

    fn bounds(&self) -> Option<DAabb> {
        let outer = self.major + self.minor;
        Some(DAabb::centred(DVec3::new(outer, self.minor, outer)))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.major + self.minor)
    }

    fn half_space(&self) -> Option<(DVec3, f64)> {
        None
    }

    fn hull(&self) -> Option<Hull> {
        // The cylinder round the ring: a ray starts at it, not at the sphere.
        let (r, h) = (self.major + self.minor, self.minor);
        Hull::about_y([(1.0, 0.0, r), (0.0, 1.0, h), (0.0, -1.0, h)])
    }

    fn is_convex(&self) -> bool {
        false
    }

    fn hull_is_solid(&self) -> bool {
        // Its hull is the cylinder round the ring.
        false
    }

    fn is_exact(&self) -> bool {
        self.is_ring()
    }

    fn distance(&self) -> impl Field<f32> {
        let (major, minor) = (self.major as f32, self.minor as f32);
        move |p: Vec3A| {
            let q = profile(p);
            Vec2::new(q.x - major, q.y).length() - minor
        }
    }

    fn gradient(&self) -> impl Field<Vec3A> {
        let major = self.major as f32;
        move |p: Vec3A| {
            let q = profile(p);
            revolve(p, Vec2::new(q.x - major, q.y).try_normalize().unwrap_or(Vec2::Y))
        }
    }

    fn facets(&self) -> Facets {
        if self.is_ring() {
            Facets::Inscribed(self.major + self.minor)
        } else {
            Facets::Isosurface
        }
    }

    fn tessellate(&self, res: Resolution) -> Tessellation {
        if !self.is_ring() {
            return Tessellation::Isosurface;
        }
        let (major, minor, n, sides) = (self.major, self.minor, res.circle, res.rings);
        Tessellation::Triangles(
            tessellate::count::torus(n, sides),
            Box::new(move || tessellate::torus(major, minor, n, sides)),
        )
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
