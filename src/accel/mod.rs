//! Acceleration structures: boxes, the robust slab test and the bounding-volume
//! hierarchy that both the top-level world and every mesh walk.

mod aabb;
pub mod bvh;

pub use aabb::{padded_sphere, sphere_interval, Aabb, ROBUST};
pub(crate) use bvh::Child;
pub use bvh::{Bvh, Rays4};
