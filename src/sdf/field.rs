//! Fields, warps and displacements as distance bounds: the body's tape run in f32,
//! divided by the bound of its slope the checker stated, and cut to its box. The
//! surface closure runs the tape on dual numbers, so its normal is the body's exact
//! gradient.

use std::sync::Arc;

use glam::Vec3A;

use super::build::{Sdf, Surf, SurfSdf};
use crate::field::{Distances, Dual, Tape};
use crate::geom::Aabb;

/// The shapes a body's `dist` calls read, as the back-end's closures.
#[derive(Clone)]
pub struct Shapes {
    /// Distances, for marching.
    pub dist: Arc<[Sdf]>,
    /// Distances with gradients, for normals.
    pub surf: Arc<[SurfSdf]>,
}

impl Distances<f32> for Shapes {
    #[inline]
    fn dist(&self, i: u32, q: [f32; 3]) -> f32 {
        self.dist[i as usize](Vec3A::from_array(q))
    }
}

impl Distances<Dual> for Shapes {
    fn dist(&self, i: u32, q: [Dual; 3]) -> Dual {
        let s = self.surf[i as usize](Vec3A::new(q[0].v, q[1].v, q[2].v));
        // The chain rule through the point's map: ∇ = Σₖ ∂d/∂qₖ ∇qₖ.
        Dual { v: s.d, g: q[0].g * s.g.x + q[1].g * s.g.y + q[2].g * s.g.z }
    }
}

/// A compiled body with what its `dist` calls read.
#[derive(Clone)]
pub struct Body {
    tape: Arc<Tape>,
    shapes: Shapes,
}

impl Body {
    /// The body of `tape`, its shapes lowered to `shapes`.
    pub fn new(tape: Tape, shapes: Shapes) -> Body {
        Body { tape: Arc::new(tape), shapes }
    }

    /// Bytes it holds: its instructions and the closures' pointers.
    pub fn bytes(&self) -> usize {
        self.tape.ops.len() * std::mem::size_of::<(crate::field::Op, u32)>()
            + self.shapes.dist.len() * 2 * std::mem::size_of::<Sdf>()
    }

    /// The number at `p`.
    #[inline]
    pub fn num(&self, p: Vec3A) -> f32 {
        let v = self.tape.eval::<f32>(&p, &self.shapes);
        // A body undefined at a point (∞ − ∞) is taken as far outside, never as a hit.
        if v.is_nan() {
            f32::MAX
        } else {
            v
        }
    }

    /// The number at `p` with its gradient.
    pub fn dual(&self, p: Vec3A) -> Dual {
        let d = self.tape.eval::<Dual>(&p, &self.shapes);
        if d.v.is_nan() {
            Dual { v: f32::MAX, g: Vec3A::Y }
        } else {
            d
        }
    }

    /// The vector at `p`.
    #[inline]
    pub fn vec(&self, p: Vec3A) -> Vec3A {
        Vec3A::from_array(self.tape.eval3::<f32>(&p, &self.shapes))
    }

    /// The vector at `p`, each component with its gradient (the map's Jacobian by rows).
    pub fn vec_dual(&self, p: Vec3A) -> [Dual; 3] {
        self.tape.eval3::<Dual>(&p, &self.shapes)
    }
}

/// A box's exact signed distance (`f32`, in render space of the field's frame).
#[derive(Clone, Copy)]
pub struct BoxCut {
    centre: Vec3A,
    half: Vec3A,
}

impl BoxCut {
    /// The box `b`.
    pub fn new(b: &Aabb) -> BoxCut {
        BoxCut { centre: ((b.min + b.max) * 0.5).as_vec3a(), half: ((b.max - b.min) * 0.5).as_vec3a() }
    }

    /// The distance at `p`.
    #[inline]
    pub fn dist(&self, p: Vec3A) -> f32 {
        let q = (p - self.centre).abs() - self.half;
        q.max(Vec3A::ZERO).length() + q.max_element().min(0.0)
    }

    /// The distance at `p` with its gradient.
    pub fn surf(&self, p: Vec3A, mat: u32) -> Surf {
        let rel = p - self.centre;
        let q = rel.abs() - self.half;
        let sign = Vec3A::select(rel.cmplt(Vec3A::ZERO), Vec3A::NEG_ONE, Vec3A::ONE);
        let outside = q.max(Vec3A::ZERO);
        let len = outside.length();
        if len > 0.0 {
            return Surf { d: len, g: outside / len * sign, mat };
        }
        let axis = q.max_position();
        let mut g = Vec3A::ZERO;
        g[axis] = sign[axis];
        Surf { d: q[axis], g, mat }
    }
}

/// `max(box, field)`: the field cut to its box, when it has one.
#[inline]
pub fn cut(b: &Option<BoxCut>, p: Vec3A, d: f32) -> f32 {
    match b {
        Some(b) => b.dist(p).max(d),
        None => d,
    }
}

/// [`cut`] with gradients.
#[inline]
pub fn cut_surf(b: &Option<BoxCut>, p: Vec3A, s: Surf) -> Surf {
    match b {
        Some(b) => b.surf(p, s.mat).max(s),
        None => s,
    }
}
