//! The tracer's vocabulary, which the geometry back-ends and the tracer both stand on:
//! rays and packets of them, the hit a back-end reports and the [`Geometry`] contract it
//! meets, work counters, and the materials and patterns a hit refers to.
//!
//! Everything here works in *render space*: world space translated so the camera sits at
//! the origin, in f32.

mod counters;
mod geometry;
mod material;
pub mod pattern;
mod ray;

pub use counters::{count_leaf, take_leaf_evals, Counters, PATH_BINS};
pub use geometry::{intersect_each, Geometry, Hit};
pub use material::{MaterialTable, ShadeMaterial};
pub use ray::{lanes, spawn_offset, Packet, Ray, NO_OBJECT};
