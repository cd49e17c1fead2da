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

pub mod effects;
mod frame;
pub mod path;
mod shade;
mod transmit;

use glam::Vec3A;
use rayon::prelude::*;
pub use shade::{MAX_TREE_RAYS, MIN_WEIGHT};

pub use frame::{Frame, ShadeLight};

use crate::ir::ColorSpace;
use crate::trace::{pattern, take_leaf_evals, Counters, Geometry};

/// A rendered image: RGB, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Bits per channel.
    pub depth: BitDepth,
    /// `width × height × 3` samples of `depth` bits, a 16-bit one as two bytes in the
    /// machine's order (as `image`'s encoders take them).
    pub pixels: Vec<u8>,
}

/// Bits per channel of an image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BitDepth {
    /// 8 bits, 0–255: the study's.
    #[default]
    Eight,
    /// 16 bits, 0–65535.
    Sixteen,
    /// 32-bit float, linear and unclamped: radiance (1 = a white surface at full light,
    /// 255 in an 8-bit image) for OpenEXR output and measurements.
    Float,
    /// A light-transport pass's exact sums ([`path::PathPixel`]): per channel a 128-bit
    /// fixed-point sum of radiance × weight, and the 64-bit sum of the weights
    /// (little-endian), which passes of any split add to the same bits.
    Sums,
}

impl BitDepth {
    /// Bits of one sample.
    pub fn bits(self) -> u32 {
        match self {
            BitDepth::Eight => 8,
            BitDepth::Sixteen => 16,
            BitDepth::Float => 32,
            BitDepth::Sums => 128,
        }
    }

    /// Bytes of one sample.
    pub fn sample_bytes(self) -> usize {
        self.bits() as usize / 8
    }

    /// Bytes of one pixel: three channels (and a sums pixel's weight).
    pub fn pixel_bytes(self) -> usize {
        match self {
            BitDepth::Sums => path::PathPixel::BYTES,
            _ => 3 * self.sample_bytes(),
        }
    }
}

/// Writes a pixel's colour (linear, 0–255, clamped by the integer casts) as `frame`
/// asks: encoded to sRGB or not, at its bit depth; a float pixel keeps the linear value
/// unclamped, divided by 255. The study's 8-bit linear pixels round to nearest.
#[inline]
fn encode(colour: Vec3A, frame: &Frame, out: &mut Vec<u8>) {
    encode_as(colour, frame.color, frame.bit_depth, out);
}

/// A pixel's colour written as `encode` writes it, for a colour space and bit depth given on their own (`scnc merge`'s passes
/// have no frame). A [`BitDepth::Sums`] pixel has no colour to write: it writes nothing.
#[inline]
pub fn encode_as(colour: Vec3A, color: ColorSpace, depth: BitDepth, out: &mut Vec<u8>) {
    if depth == BitDepth::Float {
        for x in (colour * (1.0 / 255.0)).to_array() {
            out.extend(x.to_ne_bytes());
        }
        return;
    }
    let v = pattern::encoded(colour, color);
    match depth {
        BitDepth::Float | BitDepth::Sums => {}
        // Values are in [0, 255], so adding one half and truncating rounds to nearest.
        BitDepth::Eight => out.extend((v + 0.5).to_array().map(|x| x as u8)),
        BitDepth::Sixteen => {
            for x in (v * (65535.0 / 255.0) + 0.5).to_array() {
                out.extend((x as u16).to_ne_bytes());
            }
        }
    }
}

impl Image {
    /// A float image (linear radiance) or light transport's sums as the frame's pixels
    /// show them: scaled to 0–255 (sums by the frame's exposure), clamped and encoded as
    /// its colour mode says, 8 bits a channel. Any other image is returned as it is.
    pub fn tone_mapped(&self, frame: &Frame) -> Image {
        let mut pixels = Vec::with_capacity(self.width as usize * self.height as usize * 3);
        match self.depth {
            BitDepth::Float => {
                for c in self.floats().chunks_exact(3) {
                    encode_as(Vec3A::new(c[0], c[1], c[2]) * 255.0, frame.color, BitDepth::Eight, &mut pixels);
                }
            }
            BitDepth::Sums => {
                let exposure = frame.transport.as_ref().map_or(1.0, |t| t.exposure);
                for p in self.sums() {
                    encode_as(p.colour(exposure), frame.color, BitDepth::Eight, &mut pixels);
                }
            }
            BitDepth::Eight | BitDepth::Sixteen => return self.clone(),
        }
        Image { width: self.width, height: self.height, depth: BitDepth::Eight, pixels }
    }

    /// A sums image's pixels (empty for any other depth).
    pub fn sums(&self) -> Vec<path::PathPixel> {
        if self.depth != BitDepth::Sums {
            return Vec::new();
        }
        let bytes = self.pixels.chunks_exact(path::PathPixel::BYTES);
        bytes.map(|b| b.try_into().map_or_else(|_| path::PathPixel::default(), path::PathPixel::read_sums)).collect()
    }

    /// A float image's values, three a pixel (empty for any other depth).
    pub fn floats(&self) -> Vec<f32> {
        if self.depth != BitDepth::Float {
            return Vec::new();
        }
        self.pixels.chunks_exact(4).map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]])).collect()
    }
}

/// A rectangle of the image's pixels, `x0..x1` by `y0..y1` (ends exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// Column after the last.
    pub x1: u32,
    /// Row after the last.
    pub y1: u32,
}

impl PixelRect {
    /// The whole `width × height` image.
    pub fn full(width: u32, height: u32) -> PixelRect {
        PixelRect { x0: 0, y0: 0, x1: width, y1: height }
    }

    /// Band `i` of `n` bands of rows of a `width × height` image (band heights differ
    /// by at most a row; together the bands cover the image once).
    pub fn band(i: u32, n: u32, width: u32, height: u32) -> PixelRect {
        let row = |k: u32| (u64::from(height) * u64::from(k) / u64::from(n.max(1))) as u32;
        PixelRect { x0: 0, y0: row(i), x1: width, y1: row(i + 1) }
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
    render_region(geometry, frame, PixelRect::full(frame.width, frame.height), progress)
}

/// Renders the pixels of `region` (inside the frame, not empty) into an image of the
/// region's size, each pixel exactly as [`render`] gives it: camera rays are cast in
/// 4×4 blocks aligned to the whole image, so the blocks the region touches are traced
/// whole and cropped; light transport's samples reach a pixel from its neighbours, so
/// its region is traced with a border of one pixel.
pub fn render_region(
    geometry: &dyn Geometry,
    frame: &Frame,
    region: PixelRect,
    progress: &(dyn Fn() + Sync),
) -> (Image, Counters) {
    render_region_until(geometry, frame, region, progress, &|| false).expect("a render never stopped ends")
}

/// [`render_region`], given up between one 4×4 block of camera rays and the next once
/// `stop` says so (`None` then): how a newer request preempts an older render in the
/// studio within a block's time, whatever stage the render is at.
pub fn render_region_until(
    geometry: &dyn Geometry,
    frame: &Frame,
    region: PixelRect,
    progress: &(dyn Fn() + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Option<(Image, Counters)> {
    if let Some(t) = &frame.transport {
        return path::rows(geometry, frame, t, region, progress, stop);
    }
    effects::specialise(&frame.effects, Rows { geometry, frame, region, progress, stop })
}

/// The rows of a region, for the tracer built for some effect flags.
struct Rows<'a> {
    geometry: &'a dyn Geometry,
    frame: &'a Frame,
    region: PixelRect,
    progress: &'a (dyn Fn() + Sync),
    stop: &'a (dyn Fn() -> bool + Sync),
}

impl effects::Variant for Rows<'_> {
    type Out = Option<(Image, Counters)>;
    fn run<const FX: u8>(self) -> Option<(Image, Counters)> {
        let (g, frame) = (self.geometry, self.frame);
        let block = |xy, wh, c: &mut Counters| shade::block::<FX>(g, frame, xy, wh, c);
        let write = |colour: &Vec3A, out: &mut Vec<u8>| encode(*colour, frame, out);
        rows(self.frame, self.region, self.progress, self.stop, block, write)
    }
}

/// The pixels of `region`, each 4×4 block of them from `block((x, y), (w, h), counters)`
/// and each pixel's bytes from `write`, strips of four rows in parallel.
fn rows<P>(
    frame: &Frame,
    region: PixelRect,
    progress: &(dyn Fn() + Sync),
    stop: &(dyn Fn() -> bool + Sync),
    block: impl Fn((u32, u32), (u32, u32), &mut Counters) -> [P; 16] + Sync,
    write: impl Fn(&P, &mut Vec<u8>) + Sync,
) -> Option<(Image, Counters)> {
    let stopped = std::sync::atomic::AtomicBool::new(false);
    let (w, h) = (frame.width, frame.height);
    // The blocks' first column, and where the region starts in a strip's rows.
    let bx = region.x0 / 4 * 4;
    let bytes = frame.bit_depth.pixel_bytes();
    let crop = bytes * (region.x0 - bx) as usize..bytes * (region.x1 - bx) as usize;
    // Rows go in fours, so camera rays can be cast in 4×4 blocks.
    let rows: Vec<(Vec<u8>, Counters)> = (region.y0 / 4..region.y1.div_ceil(4))
        .into_par_iter()
        .flat_map_iter(|strip| {
            let (y, rows_here) = (4 * strip, (h - 4 * strip).min(4));
            let mut c = Counters::default();
            // Leaves are counted per thread; a strip runs on one thread from start to end.
            let _ = take_leaf_evals();
            let mut rows: Vec<Vec<u8>> =
                (0..rows_here).map(|_| Vec::with_capacity((region.x1 - bx) as usize * bytes)).collect();
            for x in (bx..region.x1).step_by(4) {
                let cols = (w - x).min(4);
                if stopped.load(std::sync::atomic::Ordering::Relaxed) || stop() {
                    stopped.store(true, std::sync::atomic::Ordering::Relaxed);
                    break;
                }
                let px = block((x, y), (cols, rows_here), &mut c);
                for (dy, row) in rows.iter_mut().enumerate() {
                    for p in &px[4 * dy..4 * dy + cols as usize] {
                        write(p, row);
                    }
                }
            }
            c.leaf_evals += take_leaf_evals();
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
    if stopped.into_inner() {
        return None;
    }
    let mut counters = Counters::default();
    let mut pixels = Vec::with_capacity(region.width() as usize * region.height() as usize * bytes);
    for (row, c) in rows {
        pixels.extend_from_slice(&row);
        counters.add(&c);
    }
    Some((Image { width: region.width(), height: region.height(), depth: frame.bit_depth, pixels }, counters))
}
