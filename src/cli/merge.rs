//! `scnc merge`: parts rendered with `--region` or `--tile` assembled into one image.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use scnc::render::BitDepth;

use super::files::{cannot_write, check_output, overwritten_input, read_png, write_png};

#[derive(clap::Args)]
pub(crate) struct MergeArgs {
    /// The parts (PNGs written by `scnc render --region` or `--tile`).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// The assembled image (PNG).
    #[arg(short, long)]
    output: PathBuf,
}

/// A part read: its size, bit depth, and RGBA samples (16-bit ones in the machine's order).
struct Part {
    width: u32,
    height: u32,
    depth: BitDepth,
    rgba: Vec<u8>,
}

/// Reads a part.
fn read_part(path: &Path) -> Result<Part, String> {
    let image = read_png(path)?;
    let (width, height) = (image.width(), image.height());
    let (depth, rgba) = match image {
        image::DynamicImage::ImageRgba8(rgba) => (BitDepth::Eight, rgba.into_raw()),
        image::DynamicImage::ImageRgba16(rgba) => {
            (BitDepth::Sixteen, rgba.into_raw().into_iter().flat_map(u16::to_ne_bytes).collect())
        }
        _ => {
            return Err(format!(
                "`{}` is not a part (8- or 16-bit RGBA, as `scnc render --tile` writes)",
                path.display()
            ))
        }
    };
    Ok(Part { width, height, depth, rgba })
}

/// The full image from its parts: every pixel opaque in exactly one part.
fn merge(parts: &[PathBuf]) -> Result<scnc::render::Image, String> {
    let mut size = None;
    let mut pixels = Vec::new();
    // Which part covers each pixel, by index + 1 (0: none yet).
    let mut owner: Vec<u32> = Vec::new();
    for (k, path) in parts.iter().enumerate() {
        let Part { width: w, height: h, depth, rgba } = read_part(path)?;
        match size {
            None => {
                size = Some((w, h, depth, path));
                pixels = vec![0u8; w as usize * h as usize * depth.pixel_bytes()];
                owner = vec![0; w as usize * h as usize];
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
        for (i, px) in rgba.chunks_exact(4 * sample).enumerate() {
            // Parts are wholly opaque (every alpha bit set) or wholly transparent.
            let alpha = &px[3 * sample..];
            match alpha.iter().all(|&b| b == alpha[0]).then_some(alpha[0]) {
                Some(0) => continue,
                Some(255) => {}
                _ => {
                    let a = if sample == 1 { u16::from(alpha[0]) } else { u16::from_ne_bytes([alpha[0], alpha[1]]) };
                    return Err(format!(
                        "`{}` has a pixel of alpha {a} at ({}, {}): parts are opaque or transparent",
                        path.display(),
                        i as u32 % w,
                        i as u32 / w
                    ));
                }
            }
            if owner[i] != 0 {
                return Err(format!(
                    "`{}` and `{}` both cover pixel ({}, {}): parts must not overlap",
                    parts[owner[i] as usize - 1].display(),
                    path.display(),
                    i as u32 % w,
                    i as u32 / w
                ));
            }
            owner[i] = k as u32 + 1;
            pixels[px_bytes * i..px_bytes * (i + 1)].copy_from_slice(&px[..px_bytes]);
        }
    }
    let Some((width, height, depth, _)) = size else { return Err("no parts".into()) };
    let gaps = owner.iter().filter(|&&o| o == 0).count();
    if let Some(first) = owner.iter().position(|&o| o == 0) {
        return Err(format!(
            "{gaps} pixels are in no part, the first at ({}, {}): a part is missing",
            first as u32 % width,
            first as u32 / width
        ));
    }
    Ok(scnc::render::Image { width, height, depth, pixels })
}

pub(crate) fn merge_cmd(args: MergeArgs) -> ExitCode {
    if let Err(e) = check_output(&args.output) {
        return super::usage_error(&e);
    }
    if let Some(part) = overwritten_input(&args.output, args.parts.iter().map(PathBuf::as_path)) {
        return super::usage_error(&format!(
            "`{}` is one of the parts (`{}`): name another output",
            args.output.display(),
            part.display()
        ));
    }
    let image = match merge(&args.parts) {
        Ok(image) => image,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            return ExitCode::from(1);
        }
    };
    if let Err(e) = write_png(&args.output, &image, &[]) {
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
