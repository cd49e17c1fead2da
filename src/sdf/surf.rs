//! The closures a shape lowers to and what they return: the vocabulary the builder,
//! its union hierarchy and its field marcher share (each stands on this, not on the
//! others).

use std::sync::Arc;

use glam::Vec3A;

use super::prim;

/// A distance bound: never more than the true distance to the surface.
pub type Sdf = Arc<dyn Fn(Vec3A) -> f32 + Send + Sync>;
/// The distance bound with its gradient and the material of the nearest part:
/// evaluated once per hit, for its normal and material.
pub type SurfSdf = Arc<dyn Fn(Vec3A) -> Surf + Send + Sync>;

/// The field at a point: its value, its gradient (composed analytically through the
/// tree, so a normal carries no finite-difference noise at any hit threshold) and the
/// material of the part that decides it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surf {
    /// The distance bound.
    pub d: f32,
    /// Its gradient (not normalised: blends weigh their parts' gradients by it).
    pub g: Vec3A,
    /// Index into the material table.
    pub mat: u32,
}

impl Surf {
    /// The lower of two (a sharp union); ties go to `self`.
    #[inline]
    pub fn min(self, o: Surf) -> Surf {
        if o.d < self.d {
            o
        } else {
            self
        }
    }

    /// The higher of two (a sharp intersection); ties go to `self`.
    #[inline]
    pub fn max(self, o: Surf) -> Surf {
        if o.d > self.d {
            o
        } else {
            self
        }
    }

    /// The complement's field: the solid turned inside out.
    #[inline]
    pub fn complement(self) -> Surf {
        Surf { d: -self.d, g: -self.g, ..self }
    }

    /// The polynomial smooth minimum of two (radius `k` > 0), its gradient the same
    /// blend of theirs; the material is the lower part's.
    #[inline]
    pub fn smin(self, o: Surf, k: f32) -> Surf {
        let (d, w) = prim::smin_weighted(self.d, o.d, k);
        Surf { d, g: self.g * (1.0 - w) + o.g * w, mat: if o.d < self.d { o.mat } else { self.mat } }
    }
}
