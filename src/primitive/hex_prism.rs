//! `hex_prism(r, half_height)`: a regular hexagonal prism along y.

use std::sync::Arc;

use glam::DVec3;

use super::polytope::{polyhedron_facts, Polytope};
use super::{Refusal, Solid};
use crate::geom::DAabb;
use crate::sig::{Args, Param, Range};

crate::params! {
    /// A regular hexagonal prism along y, its corners at radius `r` (the outer radius,
    /// as a six-sided `cylinder` of OpenSCAD's has), two of them on the x axis.
    #[derive(Clone, Debug, PartialEq)]
    pub struct HexPrism {
        /// the outer radius: centre to corner (the flats are at `r·√3/2`)
        r: f64 as Num = required, Range::POSITIVE;
        /// half the height, along y
        half_height: f64 as Num = required, Range::POSITIVE;
    }
}

impl HexPrism {
    fn solid(&self) -> Arc<Polytope> {
        let (r, h) = (self.r, self.half_height);
        let ring = |y: f64| {
            (0..6).map(move |k| {
                let a = (60.0 * k as f64).to_radians();
                DVec3::new(r * a.cos(), y, r * a.sin())
            })
        };
        let corners = ring(-h).chain(ring(h)).collect();
        let mut faces = vec![(0..6).collect::<Vec<u32>>(), (6..12).collect()];
        faces.extend((0..6).map(|k| vec![k, (k + 1) % 6, 6 + (k + 1) % 6, 6 + k]));
        Polytope::new(corners, faces)
    }
}

impl Solid for HexPrism {
    const NAME: &'static str = "hex_prism";
    const DOC: &'static str =
        "regular hexagonal prism along y: corners at the outer radius `r` (two on the x axis), flats at `r·√3/2`";
    const PARAMS: &'static [Param] = HexPrism::PARAMS;

    fn new(args: &dyn Args) -> Result<HexPrism, Refusal> {
        Ok(HexPrism::from_args(args))
    }

    fn bounds(&self) -> Option<DAabb> {
        Some(DAabb::centred(DVec3::new(self.r, self.half_height, self.r * 3f64.sqrt() / 2.0)))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.r.hypot(self.half_height))
    }

    polyhedron_facts!();

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
