//! `ellipsoid(rx, ry, rz)`: the ellipsoid with these semi-axes. Its distance is a bound,
//! not exact (no closed form exists). Inigo Quilez's `k0·(k0 − 1)/k1` is closer, but it
//! is not 1-Lipschitz (`tests/scnc/derived.rs` found slopes of 1.33 near eccentric
//! ones), so a march could step through a thin one. Instead, the larger of two bounds
//! that are: the scaled level `(k0 − 1)·r_min` (the ellipsoid grown by `k0` holds every
//! point within `(k0 − 1)·r_min` of it) and the bounding sphere's `|p| − r_max`, which
//! takes over far away, where it has the true distance's slope.

use glam::{DVec3, Vec3A};

use super::{Facets, Field, Refusal, Resolution, Solid, Tessellation};
use crate::geom::hull::Hull;
use crate::geom::{tessellate, DAabb};
use crate::sig::{Args, Param, Range};

crate::params! {
    /// An axis-aligned ellipsoid centred at the origin.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Ellipsoid {
        /// the semi-axis along x
        rx: f64 as Num = required, Range::POSITIVE;
        /// the semi-axis along y
        ry: f64 as Num = required, Range::POSITIVE;
        /// the semi-axis along z
        rz: f64 as Num = required, Range::POSITIVE;
    }
}

impl Ellipsoid {
    fn radii(&self) -> DVec3 {
        DVec3::new(self.rx, self.ry, self.rz)
    }
}

impl Solid for Ellipsoid {
    const NAME: &'static str = "ellipsoid";
    const DOC: &'static str =
        "ellipsoid with semi-axes `rx`, `ry`, `rz` (its distance is a bound, not exact: an eccentric one takes more steps)";
    const PARAMS: &'static [Param] = Ellipsoid::PARAMS;

    fn new(args: &dyn Args) -> Result<Ellipsoid, Refusal> {
        Ok(Ellipsoid::from_args(args))
    }

    fn bounds(&self) -> Option<DAabb> {
        Some(DAabb::centred(self.radii()))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.radii().max_element())
    }

    fn half_space(&self) -> Option<(DVec3, f64)> {
        None
    }

    fn hull(&self) -> Option<Hull> {
        Hull::ellipsoid(DVec3::new(self.rx, self.ry, self.rz))
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn hull_is_solid(&self) -> bool {
        true
    }

    fn is_exact(&self) -> bool {
        false
    }

    fn distance(&self) -> impl Field<f32> {
        let r = self.radii().as_vec3a();
        let (inv, least, most) = (r.recip(), r.min_element(), r.max_element());
        move |p: Vec3A| (((p * inv).length() - 1.0) * least).max(p.length() - most)
    }

    fn gradient(&self) -> impl Field<Vec3A> {
        // The slope of whichever bound is the larger: the normal of the ellipsoid's level
        // set through `p` (the surface's normal on it), or the sphere's radial direction.
        let r = self.radii().as_vec3a();
        let (inv, inv2, least, most) = (r.recip(), (r * r).recip(), r.min_element(), r.max_element());
        move |p: Vec3A| {
            let level = ((p * inv).length() - 1.0) * least;
            let g = if level >= p.length() - most { p * inv2 } else { p };
            g.try_normalize().unwrap_or(Vec3A::Y)
        }
    }

    fn facets(&self) -> Facets {
        // A UV sphere's polygons under the stretch: off by no more than the sphere's
        // error at the longest semi-axis.
        Facets::Inscribed(self.radii().max_element())
    }

    fn tessellate(&self, res: Resolution) -> Tessellation {
        let (r, rings) = (self.radii(), res.rings);
        let count = tessellate::count::uvsphere(rings, 2 * rings);
        Tessellation::Triangles(
            count,
            Box::new(move || {
                let mut m = tessellate::uvsphere(1.0, rings, 2 * rings);
                m.positions.iter_mut().for_each(|p| *p *= r);
                m
            }),
        )
    }

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
