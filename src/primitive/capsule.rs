//! `capsule(r, half_height)`: a segment along y thickened into a solid.

use glam::{DVec3, Vec3A};

use super::{Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::hull::Hull;
use crate::geom::{slab, tessellate, DAabb};
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

    fn bounds(&self) -> Option<DAabb> {
        Some(DAabb::centred(DVec3::new(self.r, self.half_height + self.r, self.r)))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.r + self.half_height)
    }

    fn half_space(&self) -> Option<(DVec3, f64)> {
        None
    }

    fn hull(&self) -> Option<Hull> {
        let (r, h) = (self.r, self.half_height + self.r);
        Hull::about_y([(1.0, 0.0, r), (0.0, 1.0, h), (0.0, -1.0, h)])
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn hull_is_solid(&self) -> bool {
        // Its hull is the cylinder round it, not its round ends.
        false
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
        Facets::Inscribed(self.r)
    }

    /// The sphere's mesh elongated: its halves moved to `±half_height`, a band of quads
    /// between (`geom::slab`).
    fn tessellate(&self, res: Resolution) -> Tessellation {
        // An even ring count puts a ring on the equator, where the halves part: the band
        // is then two triangles a segment, and no triangle is split.
        let (r, h, rings) = (self.r, self.half_height, res.rings.max(2).next_multiple_of(2));
        let count = tessellate::count::uvsphere(rings, 2 * rings) + 2 * 2 * u64::from(rings);
        Tessellation::Triangles(
            count,
            Box::new(move || slab::elongated(tessellate::uvsphere(r, rings, 2 * rings), DVec3::new(0.0, h, 0.0))),
        )
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
