//! Sample passes of light transport: `render --pass I/N` writes pass `I` of `N` — the
//! samples `⌊I·n/N⌋ .. ⌊(I+1)·n/N⌋` of every pixel — as exact fixed-point sums, and
//! `scnc merge` adds passes into the image one render of all `n` samples makes, bit for
//! bit (integer sums do not depend on how they are grouped).
//!
//! A pass file (`.scnpass`) is the line `SCNPASS2`, one line of JSON (the image's size,
//! the samples in all and in this pass, exposure, colour mode), then per pixel, rows top
//! to bottom, the film's sums (`render::path::PathPixel`): three little-endian 128-bit
//! sums of radiance × weight and the 64-bit sum of the weights (`WEIGHT_ONE` a
//! sample). `SCNPASS1` passes, from before the film splatted its samples, held no
//! weights and are refused.

use std::io::{BufRead, Read};
use std::path::Path;

use scnc::ir::ColorSpace;
use scnc::render::path::PathPixel;
use scnc::render::{encode_as, BitDepth, Image};

const MAGIC: &str = "SCNPASS2";

/// The first line of a pass from before the film splatted its samples.
const OLD_MAGIC: &str = "SCNPASS1";

/// What a pass says of itself.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct PassInfo {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples a pixel of the whole render.
    pub samples: u32,
    /// This pass's first sample.
    pub first: u32,
    /// This pass's samples.
    pub count: u32,
    /// The scene's exposure factor (`2^exposure`).
    pub exposure: f32,
    /// `"linear"` or `"srgb"`.
    pub color: String,
}

/// Whether `path` names a pass file.
pub(crate) fn is_pass(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("scnpass"))
}

/// The samples `first .. first + count` of pass `i` of `n` of `samples`; `None` when
/// the pass would be empty.
pub(crate) fn range(i: u32, n: u32, samples: u32) -> Option<(u32, u32)> {
    let at = |k: u32| (u64::from(samples) * u64::from(k) / u64::from(n.max(1))) as u32;
    let (a, b) = (at(i), at(i + 1));
    (b > a).then_some((a, b - a))
}

/// Writes a pass: `image` is the render of its samples at [`BitDepth::Sums`].
pub(crate) fn write_pass(path: &Path, info: &PassInfo, image: &Image) -> std::io::Result<()> {
    let json = serde_json::to_string(info).map_err(std::io::Error::other)?;
    super::files::write_atomic(path, ".scnpass.tmp", |w| {
        writeln!(w, "{MAGIC}")?;
        writeln!(w, "{json}")?;
        w.write_all(&image.pixels)
    })
}

/// Most bytes a pass's header line may have.
const MAX_HEADER: u64 = 4096;

/// Reads a pass: its header and sums.
fn read_pass(path: &Path) -> Result<(PassInfo, Vec<PathPixel>), String> {
    let cannot = |e: &dyn std::fmt::Display| format!("cannot read `{}`: {e}", path.display());
    let not_a_pass = || format!("`{}` is not a pass (as `scnc render --pass I/N -o x.scnpass` writes)", path.display());
    let file = std::fs::File::open(path).map_err(|e| cannot(&e))?;
    let mut r = std::io::BufReader::new(file);
    let mut line = String::new();
    (&mut r).take(MAX_HEADER).read_line(&mut line).map_err(|e| cannot(&e))?;
    if line.trim_end() == OLD_MAGIC {
        return Err(format!(
            "`{}` is a pass of an older scnc, whose film kept no weights: render it again",
            path.display()
        ));
    }
    if line.trim_end() != MAGIC {
        return Err(not_a_pass());
    }
    line.clear();
    (&mut r).take(MAX_HEADER).read_line(&mut line).map_err(|e| cannot(&e))?;
    let info: PassInfo = serde_json::from_str(line.trim_end()).map_err(|_| not_a_pass())?;
    let pixels = u64::from(info.width) * u64::from(info.height);
    if info.width == 0 || info.height == 0 || pixels > scnc::check::MAX_PIXELS {
        return Err(format!(
            "`{}` says it is {}×{}: not an image scnc renders",
            path.display(),
            info.width,
            info.height
        ));
    }
    let size = PathPixel::BYTES as u64;
    let mut bytes = Vec::new();
    r.take(pixels * size + 1).read_to_end(&mut bytes).map_err(|e| cannot(&e))?;
    if bytes.len() as u64 != pixels * size {
        return Err(format!("`{}` is cut short or too long for a {}×{} pass", path.display(), info.width, info.height));
    }
    let sums = bytes
        .chunks_exact(PathPixel::BYTES)
        .map(|p| p.try_into().map_or_else(|_| PathPixel::default(), PathPixel::read_sums))
        .collect();
    Ok((info, sums))
}

/// The image of the passes at `paths` added together, as `depth` pixels (8 or 16 bits
/// tone-mapped, or float for OpenEXR): an error unless they are passes of one render
/// that together hold each of its samples once.
pub(crate) fn merge_passes(paths: &[std::path::PathBuf], depth: BitDepth) -> Result<Image, String> {
    let mut passes = Vec::with_capacity(paths.len());
    for p in paths {
        passes.push((p, read_pass(p)?));
    }
    let (first_path, (info, _)) = &passes[0];
    let info = info.clone();
    for (p, (other, _)) in &passes {
        let same = (other.width, other.height, other.samples, other.exposure.to_bits(), &other.color)
            == (info.width, info.height, info.samples, info.exposure.to_bits(), &info.color);
        if !same {
            return Err(format!(
                "`{}` and `{}` are passes of different renders (size, samples, exposure or colour differ)",
                first_path.display(),
                p.display()
            ));
        }
    }
    // Each sample once: sorted by first sample, each pass starts where the last ended.
    passes.sort_by_key(|(_, (i, _))| i.first);
    let mut next = 0u32;
    for (p, (i, _)) in &passes {
        if i.first != next {
            let what = if i.first < next { "overlaps the pass before it" } else { "leaves a gap before it" };
            return Err(format!(
                "`{}` (samples {}..{}) {what}: the passes must hold samples 0..{} once each",
                p.display(),
                i.first,
                i.first + i.count,
                info.samples
            ));
        }
        next = i.first + i.count;
    }
    if next != info.samples {
        return Err(format!("the passes hold samples 0..{next} of {}: some are missing", info.samples));
    }
    let color = if info.color == "srgb" { ColorSpace::Srgb } else { ColorSpace::Linear };
    let count = (info.width * info.height) as usize;
    let mut pixels = Vec::with_capacity(count * depth.pixel_bytes());
    for k in 0..count {
        let mut px = PathPixel::default();
        for (_, (_, sums)) in &passes {
            px.merge(&sums[k]);
        }
        encode_as(px.colour(info.exposure), color, depth, &mut pixels);
    }
    Ok(Image { width: info.width, height: info.height, depth, pixels })
}
