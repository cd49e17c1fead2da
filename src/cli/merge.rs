//! `scnc merge`: parts rendered with `--region` or `--tile` assembled into one image.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::files::{check_output, write_png};

#[derive(clap::Args)]
pub(crate) struct MergeArgs {
    /// The parts (PNGs written by `scnc render --region` or `--tile`).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// The assembled image (PNG).
    #[arg(short, long)]
    output: PathBuf,
}

/// Reads a part: its size and RGBA pixels.
fn read_part(path: &Path) -> Result<(u32, u32, Vec<u8>), String> {
    let image = image::open(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
    let rgba = match image {
        image::DynamicImage::ImageRgba8(rgba) => rgba,
        _ => return Err(format!("`{}` is not a part (8-bit RGBA, as `scnc render --tile` writes)", path.display())),
    };
    Ok((rgba.width(), rgba.height(), rgba.into_raw()))
}

/// The full image from its parts: every pixel opaque in exactly one part.
fn merge(parts: &[PathBuf]) -> Result<scnc::render::Image, String> {
    let mut size = None;
    let mut pixels = Vec::new();
    // Which part covers each pixel, by index + 1 (0: none yet).
    let mut owner: Vec<u32> = Vec::new();
    for (k, path) in parts.iter().enumerate() {
        let (w, h, rgba) = read_part(path)?;
        match size {
            None => {
                size = Some((w, h, path));
                pixels = vec![0u8; w as usize * h as usize * 3];
                owner = vec![0; w as usize * h as usize];
            }
            Some((sw, sh, first)) if (sw, sh) != (w, h) => {
                return Err(format!(
                    "`{}` is {w}×{h} but `{}` is {sw}×{sh}: parts of one image have its size",
                    path.display(),
                    first.display()
                ));
            }
            Some(_) => {}
        }
        for (i, px) in rgba.chunks_exact(4).enumerate() {
            match px[3] {
                0 => continue,
                255 => {}
                a => {
                    return Err(format!(
                        "`{}` has a pixel of alpha {a} at ({}, {}): parts are opaque or transparent",
                        path.display(),
                        i as u32 % w,
                        i as u32 / w
                    ))
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
            pixels[3 * i..3 * i + 3].copy_from_slice(&px[..3]);
        }
    }
    let Some((width, height, _)) = size else { return Err("no parts".into()) };
    let gaps = owner.iter().filter(|&&o| o == 0).count();
    if let Some(first) = owner.iter().position(|&o| o == 0) {
        return Err(format!(
            "{gaps} pixels are in no part, the first at ({}, {}): a part is missing",
            first as u32 % width,
            first as u32 / width
        ));
    }
    Ok(scnc::render::Image { width, height, pixels })
}

pub(crate) fn merge_cmd(args: MergeArgs) -> ExitCode {
    if let Err(e) = check_output(&args.output) {
        return super::usage_error(&e);
    }
    let image = match merge(&args.parts) {
        Ok(image) => image,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            return ExitCode::from(1);
        }
    };
    if let Err(e) = write_png(&args.output, &image) {
        let _ = writeln!(std::io::stderr(), "error: cannot write `{}`: {e}", args.output.display());
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
