//! Light transport's film: each sample lands at a point drawn uniformly in its pixel
//! and is splatted into every pixel whose tent filter (one pixel wide each side)
//! reaches it — its own and up to three neighbours — weighted by the filter there; a
//! pixel shows its weighted sum over its weights. This is Mitsuba's film and Cycles'
//! filter done as a splat: a pixel averages about 2.25 times as many samples as it
//! traces (the tent's squared weights integrate to 4/9 in two dimensions), which is
//! what the tent's importance-sampled offsets of one sample to one pixel gave away.
//!
//! Adaptive sampling: a pixel that stopped early is scaled to the weight of one that
//! took every sample ([`Patch::scale`]), so the splat still averages its neighbours as
//! a uniform density of samples would.
//!
//! Exactness: a sample's weights are fixed-point numbers that sum to [`WEIGHT_ONE`]
//! exactly, and every sum is an integer, so the pixels of any split of the samples
//! (`render --pass`, `scnc merge`), of any region (`--tile`, `--region`, the studio's
//! bands) and on any thread count are the same bits as one render of all of them.
//!
//! Rows are traced in strips of [`STRIP_ROWS`] in parallel. A row whose neighbours
//! are traced by the same strip is finished there; a strip's first and last rows, and
//! the rows it splats into beyond them, are kept as sums and added together once every
//! strip is done (so a strip holds four rows of sums, not all of its own).

use std::sync::atomic::{AtomicBool, Ordering};

use glam::Vec3A;
use rayon::prelude::*;

use super::Transport;
use crate::render::{encode, BitDepth, Frame, Image, PixelRect};
use crate::trace::{take_leaf_evals, Counters, Geometry};

/// One axis's weight of a whole sample: its two pixels' weights on that axis sum to it.
const AXIS_ONE: u32 = 1 << 16;

/// A whole sample's weight, spread over the pixels it reaches: 2³².
pub const WEIGHT_ONE: u64 = (AXIS_ONE as u64) * (AXIS_ONE as u64);

/// The most radiance one sample adds to a sum, 2⁷⁰ (about 1.2·10²¹): the largest
/// number of samples that reach a pixel (nine pixels' worth of
/// [`MAX_SAMPLES`](crate::check::MAX_SAMPLES)) times it times [`WEIGHT_ONE`] still fits
/// 128 bits. Only a sample beyond it (an emission strength of 10³⁰ seen directly) is
/// held to it, and its pixel is white in any image.
pub const MOST_SAMPLE_RADIANCE: f64 = 1_180_591_620_717_411_303_424.0;

/// 2⁶³: products below it convert to an integer through 64 bits.
const I64_LIMIT: f64 = 9_223_372_036_854_775_808.0;

/// Rows a strip of the film traces. Eight balance two threads better than sixteen did
/// (0.97× the wall time at 256² × 64, `farm-bench -n 5`); a strip keeps four rows of
/// sums until the end, 32 bytes a pixel beside the image's own.
const STRIP_ROWS: u32 = 8;

/// A pixel of light transport's film: the exact sums, in fixed point, of the radiance
/// of the samples that reach it times their weight here, and of the weights.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PathPixel {
    /// Radiance × weight (in units of [`WEIGHT_ONE`] a sample), summed per channel.
    pub sum: [i128; 3],
    /// The weights, summed.
    pub weight: u64,
}

impl PathPixel {
    /// Bytes of a pixel's sums as [`write_sums`](PathPixel::write_sums) writes them.
    pub const BYTES: usize = 56;

    /// Adds a sample of radiance `l` (finite, not negative) at weight `w`.
    fn splat(&mut self, l: [f64; 3], w: u64) {
        for (s, v) in self.sum.iter_mut().zip(l) {
            let x = v * w as f64;
            // The same integer either way; a float's conversion to 128 bits is a slow
            // library call, and almost every product fits 63.
            let x = if x < I64_LIMIT { x as i64 as i128 } else { x as i128 };
            *s = s.saturating_add(x);
        }
        self.weight = self.weight.saturating_add(w);
    }

    /// Adds another pixel's sums (another pass, or another strip's samples).
    pub fn merge(&mut self, o: &PathPixel) {
        for (s, v) in self.sum.iter_mut().zip(o.sum) {
            *s = s.saturating_add(v);
        }
        self.weight = self.weight.saturating_add(o.weight);
    }

    /// The weighted mean radiance × `exposure`, in the tracer's 0–255 units (255 =
    /// radiance 1); black where no sample reached.
    pub fn colour(&self, exposure: f32) -> Vec3A {
        if self.weight == 0 {
            return Vec3A::ZERO;
        }
        let k = 255.0 * f64::from(exposure) / self.weight as f64;
        Vec3A::from_array(self.sum.map(|s| (s as f64 * k) as f32))
    }

    /// The three sums and the weight, little-endian: [`PathPixel::BYTES`] bytes.
    pub fn write_sums(&self, out: &mut Vec<u8>) {
        for s in self.sum {
            out.extend(s.to_le_bytes());
        }
        out.extend(self.weight.to_le_bytes());
    }

    /// A pixel read back from what [`write_sums`](PathPixel::write_sums) wrote.
    pub fn read_sums(bytes: &[u8; PathPixel::BYTES]) -> PathPixel {
        let word = |k: usize| bytes[k..k + 16].try_into().map_or(0, i128::from_le_bytes);
        let weight = bytes[48..56].try_into().map_or(0, u64::from_le_bytes);
        PathPixel { sum: [word(0), word(16), word(32)], weight }
    }
}

/// A sample's position in its pixel on one axis (in `[0, 1)`) as the neighbour it also
/// reaches (−1 or +1) and its weight there; its own pixel takes the rest of
/// [`AXIS_ONE`].
fn axis(u: f32) -> (i64, u32) {
    let d = u - 0.5;
    let neighbour = (d.abs() * AXIS_ONE as f32).round() as u32;
    (if d < 0.0 { -1 } else { 1 }, neighbour.min(AXIS_ONE))
}

/// One pixel's samples splatted: the sums of the pixel (the centre) and of the eight
/// around it that its samples reach.
#[derive(Default)]
pub(super) struct Patch {
    cells: [[PathPixel; 3]; 3],
}

impl Patch {
    /// Splats a sample of radiance `l` at `(u1, u2)` in the pixel.
    pub(super) fn splat(&mut self, (u1, u2): (f32, f32), l: Vec3A) {
        let l = l.to_array().map(|v| f64::from(v).min(MOST_SAMPLE_RADIANCE));
        let ((sx, nx), (sy, ny)) = (axis(u1), axis(u2));
        for (dy, wy) in [(0, AXIS_ONE - ny), (sy, ny)] {
            for (dx, wx) in [(0, AXIS_ONE - nx), (sx, nx)] {
                let w = u64::from(wx) * u64::from(wy);
                if w > 0 {
                    self.cells[(dy + 1) as usize][(dx + 1) as usize].splat(l, w);
                }
            }
        }
    }

    /// Scales the patch from `count` samples to the weight of `most`: with adaptive
    /// sampling, a pixel that stopped early must weigh in its neighbours as much as one
    /// that took every sample, or a neighbour's splatted pixel is a mean weighted by
    /// where the noise was (a light's edge pixels took the dark wall's radiance beside
    /// them: `adaptive_sampling_leaves_the_image_unbiased`). The scale is exact
    /// integer arithmetic up to the rounding of one division, and none at all when
    /// `count == most` (a fixed number of samples).
    pub(super) fn scale(&mut self, count: u32, most: u32) {
        if count == most || count == 0 {
            return;
        }
        let (n, m) = (i128::from(count), i128::from(most));
        let scaled = |x: i128| (x / n).saturating_mul(m).saturating_add((x % n) * m / n);
        for p in self.cells.iter_mut().flatten() {
            p.sum = p.sum.map(scaled);
            p.weight = u64::try_from(scaled(i128::from(p.weight))).unwrap_or(u64::MAX);
        }
    }
}

/// A strip's sums: the pixels of rows `y0 .. y0 + rows` and columns `x0 .. x0 + width`
/// (the traced pixels and a border of one around them, possibly outside the image).
struct Sums {
    x0: i64,
    y0: i64,
    width: usize,
    cells: Vec<PathPixel>,
}

impl Sums {
    fn new(x0: i64, y0: i64, width: usize, rows: usize) -> Sums {
        Sums { x0, y0, width, cells: vec![PathPixel::default(); width * rows] }
    }

    /// Adds pixel `(px, py)`'s samples, held in `patch`.
    fn add(&mut self, (px, py): (u32, u32), patch: &Patch) {
        let cx = (i64::from(px) - 1 - self.x0) as usize;
        for (dy, row) in patch.cells.iter().enumerate() {
            let start = (i64::from(py) + dy as i64 - 1 - self.y0) as usize * self.width + cx;
            for (cell, p) in self.cells[start..start + 3].iter_mut().zip(row) {
                cell.merge(p);
            }
        }
    }

    /// Image row `y`'s cells at image columns `x0 .. x1`.
    fn row(&self, y: u32, (x0, x1): (u32, u32)) -> &[PathPixel] {
        let start = (i64::from(y) - self.y0) as usize * self.width;
        &self.cells[start + (i64::from(x0) - self.x0) as usize..start + (i64::from(x1) - self.x0) as usize]
    }
}

/// A row of the region from one strip: finished, or sums still to be added to.
enum Row {
    Done(u32, Vec<u8>),
    Partial(u32, Vec<PathPixel>),
}

/// The pixels of `region` under light transport, as [`render_region_until`]
/// gives them (`None` once `stop` says so): the traced pixels are the region and the
/// border of one pixel around it inside the image, whose samples reach into it.
///
/// [`render_region_until`]: crate::render::render_region_until
pub(crate) fn rows(
    g: &dyn Geometry,
    frame: &Frame,
    t: &Transport,
    region: PixelRect,
    progress: &(dyn Fn() + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Option<(Image, Counters)> {
    let traced = PixelRect {
        x0: region.x0.saturating_sub(1),
        y0: region.y0.saturating_sub(1),
        x1: (region.x1 + 1).min(frame.width),
        y1: (region.y1 + 1).min(frame.height),
    };
    let write = |p: &PathPixel, out: &mut Vec<u8>| {
        if frame.bit_depth == BitDepth::Sums {
            p.write_sums(out);
        } else {
            encode(p.colour(t.exposure), frame, out);
        }
    };
    let bytes = frame.bit_depth.pixel_bytes();
    let columns = (region.x0, region.x1);
    let encoded = |cells: &[PathPixel]| {
        let mut out = Vec::with_capacity(cells.len() * bytes);
        for p in cells {
            write(p, &mut out);
        }
        out
    };
    let stopped = AtomicBool::new(false);
    let strips: Vec<(Vec<Row>, Counters)> = (traced.y0..traced.y1)
        .step_by(STRIP_ROWS as usize)
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|y0| {
            let y1 = (y0 + STRIP_ROWS).min(traced.y1);
            let mut c = Counters::default();
            // Leaves are counted per thread; a strip runs on one thread from start to end.
            let _ = take_leaf_evals();
            let width = (traced.width() + 2) as usize;
            let mut sums = Sums::new(i64::from(traced.x0) - 1, i64::from(y0) - 1, width, (y1 - y0 + 2) as usize);
            'blocks: for by in (y0..y1).step_by(4) {
                for bx in (traced.x0..traced.x1).step_by(4) {
                    if stopped.load(Ordering::Relaxed) || stop() {
                        stopped.store(true, Ordering::Relaxed);
                        break 'blocks;
                    }
                    for py in by..(by + 4).min(y1) {
                        for px in bx..(bx + 4).min(traced.x1) {
                            let mut patch = Patch::default();
                            super::pixel(g, frame, t, (px, py), &mut c, &mut patch);
                            sums.add((px, py), &patch);
                        }
                    }
                }
            }
            c.leaf_evals += take_leaf_evals();
            // Another strip traces the rows beyond this one's ends: their samples reach
            // its first and last rows, and its samples reach them.
            let elsewhere = |y: u32| (traced.y0..traced.y1).contains(&y) && !(y0..y1).contains(&y);
            let mut rows = Vec::new();
            for y in y0.saturating_sub(1).max(region.y0)..(y1 + 1).min(region.y1) {
                let cells = sums.row(y, columns);
                let done = (y0..y1).contains(&y) && !(y > 0 && elsewhere(y - 1)) && !elsewhere(y + 1);
                if done {
                    rows.push(Row::Done(y, encoded(cells)));
                    progress();
                } else {
                    rows.push(Row::Partial(y, cells.to_vec()));
                }
            }
            (rows, c)
        })
        .collect();
    if stopped.into_inner() {
        return None;
    }
    let mut counters = Counters::default();
    let height = region.height() as usize;
    let mut done: Vec<Option<Vec<u8>>> = vec![None; height];
    let mut partial: Vec<Option<Vec<PathPixel>>> = vec![None; height];
    for (rows, c) in strips {
        counters.add(&c);
        for row in rows {
            match row {
                Row::Done(y, bytes) => done[(y - region.y0) as usize] = Some(bytes),
                Row::Partial(y, cells) => match &mut partial[(y - region.y0) as usize] {
                    Some(sum) => sum.iter_mut().zip(&cells).for_each(|(s, p)| s.merge(p)),
                    empty => *empty = Some(cells),
                },
            }
        }
    }
    let mut pixels = Vec::with_capacity(region.width() as usize * height * bytes);
    for (done, partial) in done.into_iter().zip(partial) {
        match (done, partial) {
            (Some(row), _) => pixels.extend_from_slice(&row),
            (None, Some(cells)) => {
                pixels.extend_from_slice(&encoded(&cells));
                progress();
            }
            // Every row of the region is traced by one strip.
            (None, None) => unreachable!("a row of the region no strip traced"),
        }
    }
    Some((Image { width: region.width(), height: region.height(), depth: frame.bit_depth, pixels }, counters))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample's four weights sum to a whole sample's wherever it lands, and the
    /// neighbour it reaches is the one nearer to it.
    #[test]
    fn a_sample_weighs_one_in_all() {
        for k in 0..=1000 {
            let u = (k as f32 / 1000.0).min(0.999_999_94);
            let (side, n) = axis(u);
            assert!(n <= AXIS_ONE / 2);
            assert_eq!(side, if u < 0.5 { -1 } else { 1 });
            let mut patch = Patch::default();
            patch.splat((u, 1.0 - u), Vec3A::ONE);
            let total: u64 = patch.cells.iter().flatten().map(|p| p.weight).sum();
            assert_eq!(total, WEIGHT_ONE, "u = {u}");
            assert!(patch.cells.iter().flatten().all(|p| p.sum[0] as u64 == p.weight));
        }
    }

    /// A pixel's sums survive being written and read, and split sums merge to the whole.
    #[test]
    fn sums_are_written_read_and_merged_exactly() {
        let (mut a, mut b, mut whole) = (PathPixel::default(), PathPixel::default(), PathPixel::default());
        for (k, l) in [[0.25, 1.0, 3.5], [1e20, 0.0, 7.0], [0.1, 0.2, 0.3]].into_iter().enumerate() {
            let w = WEIGHT_ONE / (k as u64 + 2);
            if k % 2 == 0 {
                a.splat(l, w)
            } else {
                b.splat(l, w)
            }
            whole.splat(l, w);
        }
        a.merge(&b);
        assert_eq!(a, whole);
        let mut bytes = Vec::new();
        whole.write_sums(&mut bytes);
        assert_eq!(bytes.len(), PathPixel::BYTES);
        assert_eq!(PathPixel::read_sums(bytes[..].try_into().expect("56 bytes")), whole);
        assert_eq!(PathPixel::default().colour(1.0), Vec3A::ZERO);
    }
}
