//! `pyramid(half_base, height)`: a square pyramid along y, apex up.

use std::sync::Arc;

use glam::DVec3;

use super::polytope::{polyhedron_facts, Polytope};
use super::{Refusal, Solid};
use crate::geom::DAabb;
use crate::sig::{Args, Param, Range};

crate::params! {
    /// A square pyramid centred on its bounding box: the base, `2·half_base` square, at
    /// `y = -height/2`, the apex at `y = height/2`.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Pyramid {
        /// half the side of the square base (along x and z)
        half_base: f64 as Num = required, Range::POSITIVE;
        /// the height from base to apex, along y
        height: f64 as Num = required, Range::POSITIVE;
    }
}

impl Pyramid {
    fn solid(&self) -> Arc<Polytope> {
        let (a, h) = (self.half_base, self.height / 2.0);
        let corners = vec![
            DVec3::new(-a, -h, -a),
            DVec3::new(a, -h, -a),
            DVec3::new(a, -h, a),
            DVec3::new(-a, -h, a),
            DVec3::new(0.0, h, 0.0),
        ];
        let faces = vec![vec![0, 1, 2, 3], vec![0, 1, 4], vec![1, 2, 4], vec![2, 3, 4], vec![3, 0, 4]];
        Polytope::new(corners, faces)
    }
}

impl Solid for Pyramid {
    const NAME: &'static str = "pyramid";
    const DOC: &'static str =
        "square pyramid along y, apex up: base of half-side `half_base` at `-height/2`, apex at `height/2`";
    const PARAMS: &'static [Param] = Pyramid::PARAMS;

    fn new(args: &dyn Args) -> Result<Pyramid, Refusal> {
        Ok(Pyramid::from_args(args))
    }

    fn bounds(&self) -> Option<DAabb> {
        Some(DAabb::centred(DVec3::new(self.half_base, self.height / 2.0, self.half_base)))
    }

    fn sphere_radius(&self) -> Option<f64> {
        Some(DVec3::new(self.half_base, self.height / 2.0, self.half_base).length())
    }

    polyhedron_facts!();

    fn fields(&self) -> Vec<(&'static str, String)> {
        self.shown::<()>()
    }
}
