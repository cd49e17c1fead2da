//! `scnc merge`: parts rendered with `--region` or `--tile` assembled into one image.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use scnc::render::BitDepth;

use super::files::{cannot_write, check_image_output, is_exr, overwritten_input, write_exr, write_png};
use super::passes::{is_pass, merge_passes};

#[derive(clap::Args)]
pub(crate) struct MergeArgs {
    /// The parts (PNGs written by `scnc render --region` or `--tile`), or the passes
    /// (`.scnpass` files written by `scnc render --pass`).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// The assembled image (PNG; passes may also make an OpenEXR `.exr`).
    #[arg(short, long)]
    output: PathBuf,
}

/// A part opened, its header read: its size, bit depth and a reader at its first row.
struct Part {
    width: u32,
    height: u32,
    depth: BitDepth,
    rows: png::Reader<std::io::BufReader<std::fs::File>>,
}

/// Opens a part: an RGBA PNG of 8 or 16 bits, not interlaced, within the image limits.
/// Its rows are read one at a time, so a part costs a row of memory, not an image.
fn open_part(path: &Path) -> Result<Part, String> {
    let cannot = |e: &dyn std::fmt::Display| format!("cannot read `{}`: {e}", path.display());
    let file = std::fs::File::open(path).map_err(|e| cannot(&e))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    // Samples as stored: 16-bit ones big-endian, nothing expanded or stripped.
    decoder.set_transformations(png::Transformations::IDENTITY);
    let rows = decoder.read_info().map_err(|e| cannot(&e))?;
    let info = rows.info();
    let (width, height) = (info.width, info.height);
    let depth = match (info.color_type, info.bit_depth, info.interlaced) {
        (png::ColorType::Rgba, png::BitDepth::Eight, false) => BitDepth::Eight,
        (png::ColorType::Rgba, png::BitDepth::Sixteen, false) => BitDepth::Sixteen,
        _ => {
            return Err(format!(
                "`{}` is not a part (8- or 16-bit RGBA, not interlaced, as `scnc render --tile` writes)",
                path.display()
            ))
        }
    };
    let side = scnc::check::MAX_IMAGE_SIDE;
    if width > side || height > side || u64::from(width) * u64::from(height) > scnc::check::MAX_PIXELS {
        return Err(format!(
            "`{}` is {width}×{height}: larger than any image scnc renders ({side} a side, {} pixels)",
            path.display(),
            scnc::check::MAX_PIXELS
        ));
    }
    Ok(Part { width, height, depth, rows })
}

/// Whether a pixel of `sample`-byte channels is opaque (`Ok(true)`) or transparent
/// (`Ok(false)`); otherwise its alpha.
fn opaque(px: &[u8], sample: usize) -> Result<bool, u16> {
    let alpha = &px[3 * sample..];
    match alpha.iter().all(|&b| b == alpha[0]).then_some(alpha[0]) {
        Some(0) => Ok(false),
        Some(255) => Ok(true),
        _ if sample == 1 => Err(u16::from(alpha[0])),
        _ => Err(u16::from_be_bytes([alpha[0], alpha[1]])),
    }
}

/// Calls `pixel(index, rgba)` for each pixel of `part`, row by row.
fn each_pixel(
    part: &mut Part,
    path: &Path,
    mut pixel: impl FnMut(usize, &[u8]) -> Result<(), String>,
) -> Result<(), String> {
    let px = 4 * part.depth.sample_bytes();
    let width = part.width as usize;
    for y in 0..part.height as usize {
        let row = match part.rows.next_row() {
            Ok(Some(row)) => row,
            Ok(None) => return Err(format!("cannot read `{}`: it ends at row {y}", path.display())),
            Err(e) => return Err(format!("cannot read `{}`: {e}", path.display())),
        };
        for (x, rgba) in row.data().chunks_exact(px).enumerate() {
            pixel(y * width + x, rgba)?;
        }
    }
    Ok(())
}

/// The part before `parts[k]` that covers pixel `i` (an overlap was found there).
fn earlier_cover(parts: &[PathBuf], k: usize, i: usize) -> Option<&Path> {
    parts[..k].iter().map(PathBuf::as_path).find(|path| {
        let Ok(mut part) = open_part(path) else { return false };
        let sample = part.depth.sample_bytes();
        let mut covers = false;
        let _ = each_pixel(&mut part, path, |j, rgba| {
            covers |= j == i && opaque(rgba, sample) == Ok(true);
            // Stops at the pixel: nothing after it is read.
            if j >= i {
                Err(String::new())
            } else {
                Ok(())
            }
        });
        covers
    })
}

/// The full image from its parts: every pixel opaque in exactly one part. The parts are
/// read a row at a time into the image (and a bit a pixel of which are covered), so the
/// largest 16-bit image render writes merges in the image's own memory.
///
/// Long because it is one pass over every part's rows with the checks each part must pass,
/// which keeps the memory at one image.
fn merge(parts: &[PathBuf]) -> Result<scnc::render::Image, String> {
    let mut size = None;
    let mut pixels = Vec::new();
    // Which pixels a part has covered, a bit each.
    let mut covered: Vec<u64> = Vec::new();
    for (k, path) in parts.iter().enumerate() {
        let mut part = open_part(path)?;
        let (w, h, depth) = (part.width, part.height, part.depth);
        match size {
            None => {
                size = Some((w, h, depth, path));
                let count = w as usize * h as usize;
                pixels = vec![0u8; count * depth.pixel_bytes()];
                covered = vec![0; count.div_ceil(64)];
            }
            Some((sw, sh, _, first)) if (sw, sh) != (w, h) => {
                return Err(format!(
                    "`{}` is {w}×{h} but `{}` is {sw}×{sh}: parts of one image have its size",
                    path.display(),
                    first.display()
                ));
            }
            Some((_, _, sd, first)) if sd != depth => {
                return Err(format!(
                    "`{}` has {} bits per channel but `{}` has {}: parts of one image have its bit depth",
                    path.display(),
                    depth.bits(),
                    first.display(),
                    sd.bits()
                ));
            }
            Some(_) => {}
        }
        let (px_bytes, sample) = (depth.pixel_bytes(), depth.sample_bytes());
        let at = |i: usize| (i as u32 % w, i as u32 / w);
        each_pixel(&mut part, path, |i, rgba| {
            // Parts are wholly opaque (every alpha bit set) or wholly transparent.
            match opaque(rgba, sample) {
                Ok(false) => return Ok(()),
                Ok(true) => {}
                Err(a) => {
                    let (x, y) = at(i);
                    return Err(format!(
                        "`{}` has a pixel of alpha {a} at ({x}, {y}): parts are opaque or transparent",
                        path.display()
                    ));
                }
            }
            let (word, bit) = (i / 64, 1u64 << (i % 64));
            if covered[word] & bit != 0 {
                let (x, y) = at(i);
                let other = earlier_cover(parts, k, i)
                    .map_or_else(|| "an earlier part".into(), |p| format!("`{}`", p.display()));
                return Err(format!(
                    "{other} and `{}` both cover pixel ({x}, {y}): parts must not overlap",
                    path.display()
                ));
            }
            covered[word] |= bit;
            let out = &mut pixels[px_bytes * i..px_bytes * (i + 1)];
            match depth {
                // A part is a PNG: never float.
                BitDepth::Eight | BitDepth::Float | BitDepth::Sums => out.copy_from_slice(&rgba[..3]),
                // The image keeps 16-bit samples in the machine's order; PNG's are big-endian.
                BitDepth::Sixteen => {
                    for (o, s) in out.chunks_exact_mut(2).zip(rgba.chunks_exact(2)) {
                        o.copy_from_slice(&u16::from_be_bytes([s[0], s[1]]).to_ne_bytes());
                    }
                }
            }
            Ok(())
        })?;
    }
    let Some((width, height, depth, _)) = size else { return Err("no parts".into()) };
    let count = width as usize * height as usize;
    let gap = |i: usize| covered[i / 64] & (1 << (i % 64)) == 0;
    if let Some(first) = (0..count).find(|&i| gap(i)) {
        let gaps = (first..count).filter(|&i| gap(i)).count();
        return Err(format!(
            "{gaps} pixels are in no part, the first at ({}, {}): a part is missing",
            first as u32 % width,
            first as u32 / width
        ));
    }
    Ok(scnc::render::Image { width, height, depth, pixels })
}

pub(crate) fn merge_cmd(args: MergeArgs) -> ExitCode {
    if let Err(e) = check_image_output(&args.output) {
        return super::usage_error(&e);
    }
    let passes = args.parts.iter().filter(|p| is_pass(p)).count();
    if passes > 0 && passes < args.parts.len() {
        return super::usage_error("merge either parts of an image (PNGs) or passes of samples (`.scnpass`), not both");
    }
    if passes == 0 && is_exr(&args.output) {
        return super::usage_error(
            "parts of an image merge into a PNG; passes of samples merge into a PNG or an `.exr`",
        );
    }
    if let Some(part) = overwritten_input(&args.output, args.parts.iter().map(PathBuf::as_path)) {
        return super::usage_error(&format!(
            "`{}` is one of the parts (`{}`): name another output",
            args.output.display(),
            part.display()
        ));
    }
    let depth = if is_exr(&args.output) { BitDepth::Float } else { BitDepth::Eight };
    let merged = if passes > 0 { merge_passes(&args.parts, depth) } else { merge(&args.parts) };
    let image = match merged {
        Ok(image) => image,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            return ExitCode::from(1);
        }
    };
    let written =
        if is_exr(&args.output) { write_exr(&args.output, &image) } else { write_png(&args.output, &image, &[]) };
    if let Err(e) = written {
        let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(&args.output, &e));
        return ExitCode::from(1);
    }
    let _ = writeln!(
        std::io::stderr(),
        "merged {} parts into {}: {}×{}",
        args.parts.len(),
        args.output.display(),
        image.width,
        image.height
    );
    ExitCode::SUCCESS
}
