//! `octahedron(r)`: the regular octahedron with its corners at `r` on each axis.

use std::sync::Arc;

use glam::DVec3;

use super::polytope::{polyhedron_facts, Polytope};
use super::{Refusal, Solid};
use crate::geom::DAabb;
use crate::sig::{Args, Param, Range};

crate::params! {
    /// A regular octahedron centred at the origin, corners on the axes.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Octahedron {
        /// the distance from the centre to each corner
        r: f64 as Num = required, Range::POSITIVE;
    }
}

impl Octahedron {
    fn solid(&self) -> Arc<Polytope> {
        let r = self.r;
        let corners = vec![
            DVec3::new(r, 0.0, 0.0),
            DVec3::new(-r, 0.0, 0.0),
            DVec3::new(0.0, r, 0.0),
            DVec3::new(0.0, -r, 0.0),
            DVec3::new(0.0, 0.0, r),
            DVec3::new(0.0, 0.0, -r),
        ];
        // One face per octant: the corners on its three half-axes.
        let faces = (0..8u32).map(|o| vec![o & 1, 2 + (o >> 1 & 1), 4 + (o >> 2 & 1)]).collect();
        Polytope::new(corners, faces)
    }
}

impl Solid for Octahedron {
    const NAME: &'static str = "octahedron";
    const DOC: &'static str = "regular octahedron with its six corners at `r` on the axes";
    const PARAMS: &'static [Param] = Octahedron::PARAMS;

    fn new(args: &dyn Args) -> Result<Octahedron, Refusal> {
        Ok(Octahedron::from_args(args))
    }

    fn bounds(&self) -> Option<DAabb> {
        Some(DAabb::centred(DVec3::splat(self.r)))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(self.r)
    }

    polyhedron_facts!();

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
