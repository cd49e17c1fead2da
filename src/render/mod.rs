//! The common Whitted tracer: camera, lights, Phong shading, hard shadows, recursive
//! reflections. It knows geometry only through the [`Geometry`] contract, so the SDF
//! and mesh back-ends plug in unchanged.
//!
//! Everything here works in *render space*: world space translated so the camera sits at
//! the origin, in f32. Lowering subtracts the camera position in f64 first, so a scene
//! far from the world origin keeps its precision.
//!
//! **Invariant:** the image depends only on the scene and the settings, never on the
//! thread count: rows are independent and counters are summed exactly.

mod counters;
pub mod effects;
mod frame;
mod geometry;
mod ray;
mod shade;

use rayon::prelude::*;

pub use counters::Counters;
pub use frame::{Frame, MaterialTable, ShadeLight, ShadeMaterial};
pub use geometry::{intersect_each, Geometry, Hit};
pub use ray::{lanes, spawn_offset, Packet, Ray, NO_OBJECT};

/// A rendered image: RGB, 8 bits per channel, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height × 3` bytes.
    pub pixels: Vec<u8>,
}

/// Renders the frame with any geometry. Rows run in parallel on the current rayon
/// pool; `progress` is called once per finished row.
pub fn render(geometry: &dyn Geometry, frame: &Frame, progress: &(dyn Fn() + Sync)) -> (Image, Counters) {
    let e = &frame.effects;
    // Pick the tracer built for this effect set, once, before the first ray.
    macro_rules! pick {
        ($($s:literal $r:literal $p:literal $a:literal),*) => {
            match (e.shadows(), e.reflections, e.specular, e.ambient_occlusion.is_some()) {
                $(($s, $r, $p, $a) => rows::<$s, $r, $p, $a>(geometry, frame, progress),)*
            }
        };
    }
    pick!(
        false false false false, false false false true, false false true false, false false true true,
        false true false false, false true false true, false true true false, false true true true,
        true false false false, true false false true, true false true false, true false true true,
        true true false false, true true false true, true true true false, true true true true
    )
}

fn rows<const SHADOWS: bool, const REFLECT: bool, const SPECULAR: bool, const AO: bool>(
    geometry: &dyn Geometry,
    frame: &Frame,
    progress: &(dyn Fn() + Sync),
) -> (Image, Counters) {
    let (w, h) = (frame.width, frame.height);
    // Rows go in fours, so camera rays can be cast in 4×4 blocks.
    let rows: Vec<(Vec<u8>, Counters)> = (0..h.div_ceil(4))
        .into_par_iter()
        .flat_map_iter(|strip| {
            let (y, rows_here) = (4 * strip, (h - 4 * strip).min(4));
            let mut c = Counters::default();
            // Leaves are counted per thread; a strip runs on one thread from start to end.
            let _ = crate::sdf::take_leaf_evals();
            let mut rows: Vec<Vec<u8>> = (0..rows_here).map(|_| Vec::with_capacity(w as usize * 3)).collect();
            for x in (0..w).step_by(4) {
                let cols = (w - x).min(4);
                let px =
                    shade::block::<SHADOWS, REFLECT, SPECULAR, AO>(geometry, frame, (x, y), (cols, rows_here), &mut c);
                for (dy, row) in rows.iter_mut().enumerate() {
                    row.extend(px[4 * dy..4 * dy + cols as usize].iter().flatten());
                }
            }
            c.leaf_evals += crate::sdf::take_leaf_evals();
            for _ in 0..rows_here {
                progress();
            }
            // The strip's counters travel with its first row.
            let mut counters = Some(c);
            rows.into_iter().map(move |row| (row, counters.take().unwrap_or_default()))
        })
        .collect();
    let mut counters = Counters::default();
    let mut pixels = Vec::with_capacity(w as usize * h as usize * 3);
    for (row, c) in rows {
        pixels.extend_from_slice(&row);
        counters.add(&c);
    }
    (Image { width: w, height: h, pixels }, counters)
}
