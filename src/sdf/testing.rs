//! What the SDF back-end's unit tests share: random numbers, and the shape of a
//! one-object scene.

use std::sync::Arc;

use crate::ir::{Body, Shape};

/// Numbers uniform in `[lo, hi)` from a xorshift seeded with `seed` (not 0).
pub fn uniform(seed: u64, lo: f64, hi: f64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// The shape of the scene `object {text}` (with an ambient light), as compiled.
pub fn only_shape(text: &str) -> Arc<Shape> {
    let path = std::path::Path::new("t.scn");
    let c =
        crate::compile_source("t.scn", path, format!("light ambient(1)\nobject {text}\n"), &crate::source::FsLoader);
    match c.scene.expect("compiles").objects[0].geometry.clone() {
        Body::Shape(s) => s,
        Body::Mesh(_) => panic!("{text}: a mesh, not a shape"),
    }
}
