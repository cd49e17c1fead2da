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

/// A rectangle of the image's pixels, `x0..x1` by `y0..y1` (ends exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// Column after the last.
    pub x1: u32,
    /// Row after the last.
    pub y1: u32,
}

impl Region {
    /// The whole `width × height` image.
    pub fn full(width: u32, height: u32) -> Region {
        Region { x0: 0, y0: 0, x1: width, y1: height }
    }

    /// Band `i` of `n` bands of rows of a `width × height` image (band heights differ
    /// by at most a row; together the bands cover the image once).
    pub fn band(i: u32, n: u32, width: u32, height: u32) -> Region {
        let row = |k: u32| (u64::from(height) * u64::from(k) / u64::from(n.max(1))) as u32;
        Region { x0: 0, y0: row(i), x1: width, y1: row(i + 1) }
    }

    /// Columns.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    /// Rows.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }
}

/// Renders the frame with any geometry. Rows run in parallel on the current rayon
/// pool; `progress` is called once per finished row.
pub fn render(geometry: &dyn Geometry, frame: &Frame, progress: &(dyn Fn() + Sync)) -> (Image, Counters) {
    render_region(geometry, frame, Region::full(frame.width, frame.height), progress)
}

/// Renders the pixels of `region` (inside the frame, not empty) into an image of the
/// region's size, each pixel exactly as [`render`] gives it: camera rays are cast in
/// 4×4 blocks aligned to the whole image, so the blocks the region touches are traced
/// whole and cropped.
pub fn render_region(
    geometry: &dyn Geometry,
    frame: &Frame,
    region: Region,
    progress: &(dyn Fn() + Sync),
) -> (Image, Counters) {
    let e = &frame.effects;
    // Pick the tracer built for this effect set, once, before the first ray.
    macro_rules! pick {
        ($($s:literal $r:literal $p:literal $a:literal),*) => {
            match (e.shadows(), e.reflections, e.specular, e.ambient_occlusion.is_some()) {
                $(($s, $r, $p, $a) => rows::<$s, $r, $p, $a>(geometry, frame, region, progress),)*
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
    region: Region,
    progress: &(dyn Fn() + Sync),
) -> (Image, Counters) {
    let (w, h) = (frame.width, frame.height);
    // The blocks' first column, and where the region starts in a strip's rows.
    let bx = region.x0 / 4 * 4;
    let crop = 3 * (region.x0 - bx) as usize..3 * (region.x1 - bx) as usize;
    // Rows go in fours, so camera rays can be cast in 4×4 blocks.
    let rows: Vec<(Vec<u8>, Counters)> = (region.y0 / 4..region.y1.div_ceil(4))
        .into_par_iter()
        .flat_map_iter(|strip| {
            let (y, rows_here) = (4 * strip, (h - 4 * strip).min(4));
            let mut c = Counters::default();
            // Leaves are counted per thread; a strip runs on one thread from start to end.
            let _ = crate::sdf::take_leaf_evals();
            let mut rows: Vec<Vec<u8>> =
                (0..rows_here).map(|_| Vec::with_capacity((region.x1 - bx) as usize * 3)).collect();
            for x in (bx..region.x1).step_by(4) {
                let cols = (w - x).min(4);
                let px =
                    shade::block::<SHADOWS, REFLECT, SPECULAR, AO>(geometry, frame, (x, y), (cols, rows_here), &mut c);
                for (dy, row) in rows.iter_mut().enumerate() {
                    row.extend(px[4 * dy..4 * dy + cols as usize].iter().flatten());
                }
            }
            c.leaf_evals += crate::sdf::take_leaf_evals();
            let kept: Vec<Vec<u8>> = rows
                .into_iter()
                .enumerate()
                .filter(|&(dy, _)| (region.y0..region.y1).contains(&(y + dy as u32)))
                .map(|(_, mut row)| {
                    // In place: a whole-image render crops nothing.
                    row.truncate(crop.end);
                    row.drain(..crop.start);
                    row
                })
                .collect();
            for _ in 0..kept.len() {
                progress();
            }
            // The strip's counters travel with its first row.
            let mut counters = Some(c);
            kept.into_iter().map(move |row| (row, counters.take().unwrap_or_default()))
        })
        .collect();
    let mut counters = Counters::default();
    let mut pixels = Vec::with_capacity(region.width() as usize * region.height() as usize * 3);
    for (row, c) in rows {
        pixels.extend_from_slice(&row);
        counters.add(&c);
    }
    (Image { width: region.width(), height: region.height(), pixels }, counters)
}
