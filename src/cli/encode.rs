//! `scnc encode`: an image sequence (`frame-####.png`) into one animation for previews:
//! GIF, APNG (a `.png` output), or MP4 through `ffmpeg` when it is installed.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::files::{cannot_write, check_output_as, stop_on_interrupt, write_atomic, Pending};
use super::frames::{frame_path, Pattern};
use super::usage_error;

#[derive(clap::Args)]
pub(crate) struct EncodeArgs {
    /// The frames, named as `render -o` named them: `out/frame-####.png`.
    frames: PathBuf,
    /// The animation: `.gif`, `.png` (APNG) or `.mp4` (needs `ffmpeg` on PATH).
    #[arg(short, long)]
    output: PathBuf,
    /// Frames per second.
    #[arg(long, default_value = "24", value_parser = clap::value_parser!(u16).range(1..=1000))]
    fps: u16,
}

/// What the output's extension asks for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Gif,
    Apng,
    Mp4,
}

/// The numbers of the frames on disk that `pattern` names, in order: every file in its
/// directory that is the pattern with its `#` run replaced by at least that many digits.
/// Frames must run without a gap: an animation missing a frame (a task that failed) is
/// refused rather than encoded with a jump.
fn find_frames(pattern: &Path) -> Result<Vec<u32>, String> {
    let names = Pattern::of(pattern).ok_or_else(|| {
        format!("`{}` names one file: give the frames' pattern, like `out/frame-####.png`", pattern.display())
    })?;
    let dir = match pattern.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let entries = std::fs::read_dir(dir).map_err(|e| format!("cannot read the directory `{}`: {e}", dir.display()))?;
    let mut numbers: Vec<u32> = entries.filter_map(|e| names.frame_of(e.ok()?.file_name().to_str()?)).collect();
    numbers.sort_unstable();
    let (Some(&first), Some(&last)) = (numbers.first(), numbers.last()) else {
        return Err(format!("no frames match `{}`", pattern.display()));
    };
    if let Some(w) = numbers.windows(2).find(|w| w[1] != w[0] + 1) {
        return Err(format!(
            "frame {} is missing: `{}` has frames {first} to {last} with a gap after {}",
            w[0] + 1,
            dir.display(),
            w[0]
        ));
    }
    Ok(numbers)
}

/// Reads every frame as RGBA, all of one size.
fn read_frames(pattern: &Path, numbers: &[u32]) -> Result<(u32, u32, Vec<Vec<u8>>), String> {
    let mut size = None;
    let mut frames = Vec::with_capacity(numbers.len());
    for &n in numbers {
        let path = frame_path(pattern, n);
        let image = image::open(&path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?.to_rgba8();
        let (w, h) = image.dimensions();
        match size {
            None => size = Some((w, h, path)),
            Some((w0, h0, ref first)) if (w0, h0) != (w, h) => {
                return Err(format!(
                    "`{}` is {w}×{h} but `{}` is {w0}×{h0}: every frame must have one size",
                    path.display(),
                    first.display()
                ));
            }
            Some(_) => {}
        }
        frames.push(image.into_raw());
    }
    let (w, h, _) = size.ok_or("no frames")?;
    Ok((w, h, frames))
}

pub(crate) fn encode_cmd(args: EncodeArgs) -> ExitCode {
    let ext = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let format = match ext.as_deref() {
        Some("gif") => Format::Gif,
        Some("png" | "apng") => Format::Apng,
        Some("mp4") => Format::Mp4,
        _ => {
            return usage_error(&format!(
                "cannot write `{}`: scnc encodes `.gif`, `.png` (APNG) or `.mp4`",
                args.output.display()
            ))
        }
    };
    if let Err(e) = check_output_as(&args.output, "a file name ending in `.gif`, `.png` or `.mp4`") {
        return usage_error(&e);
    }
    // Interrupted, nothing is left behind: the shell's 128 + SIGINT.
    if let Err(e) = stop_on_interrupt(130) {
        let _ = writeln!(std::io::stderr(), "warning: {e}");
    }
    let numbers = match find_frames(&args.frames) {
        Ok(n) => n,
        Err(e) => return usage_error(&e),
    };
    let result = match format {
        Format::Mp4 => mp4(&args, &numbers),
        Format::Gif | Format::Apng => read_frames(&args.frames, &numbers).and_then(|(w, h, frames)| {
            let written = write_atomic(&args.output, ".tmp", |out| match format {
                Format::Gif => gif(out, &frames, w, h, args.fps),
                _ => apng(out, &frames, w, h, args.fps),
            });
            written.map_err(|e| cannot_write(&args.output, &e))
        }),
    };
    match result {
        Ok(()) => {
            let _ = writeln!(
                std::io::stderr(),
                "encoded {}: frames {} to {} ({}) at {} fps",
                args.output.display(),
                numbers[0],
                numbers[numbers.len() - 1],
                numbers.len(),
                args.fps
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            ExitCode::from(1)
        }
    }
}

/// A GIF looping forever. GIF delays are in hundredths of a second, so a rate that does
/// not divide 100 is rounded to the nearest hundredth (24 fps plays at 25).
fn gif(out: &mut dyn Write, frames: &[Vec<u8>], w: u32, h: u32, fps: u16) -> std::io::Result<()> {
    use image::codecs::gif::{GifEncoder, Repeat};
    let mut encoder = GifEncoder::new_with_speed(out, 10);
    encoder.set_repeat(Repeat::Infinite).map_err(std::io::Error::other)?;
    let delay = image::Delay::from_numer_denom_ms(1000, u32::from(fps));
    for rgba in frames {
        let buffer =
            image::RgbaImage::from_raw(w, h, rgba.clone()).ok_or_else(|| std::io::Error::other("frame size"))?;
        encoder.encode_frame(image::Frame::from_parts(buffer, 0, 0, delay)).map_err(std::io::Error::other)?;
    }
    Ok(())
}

/// An APNG looping forever, each frame shown 1/fps s exactly; viewers without APNG
/// support show the first frame.
fn apng(out: &mut dyn Write, frames: &[Vec<u8>], w: u32, h: u32, fps: u16) -> std::io::Result<()> {
    let mut encoder = png::Encoder::new(out, w, h);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_animated(frames.len() as u32, 0).map_err(std::io::Error::other)?;
    encoder.set_frame_delay(1, fps).map_err(std::io::Error::other)?;
    let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
    for rgba in frames {
        writer.write_image_data(rgba).map_err(std::io::Error::other)?;
    }
    writer.finish().map_err(std::io::Error::other)
}

/// MP4 (H.264, yuv420p for players' sake) by `ffmpeg`, into a temporary file renamed
/// over the output when it succeeds.
fn mp4(args: &EncodeArgs, numbers: &[u32]) -> Result<(), String> {
    let p = Pattern::of(&args.frames).ok_or("the frames are not a pattern")?;
    // ffmpeg's image2 pattern: `%04d` for `####` (a literal `%` doubled).
    let escaped = |s: &str| s.replace('%', "%%");
    let input = args.frames.with_file_name(format!("{}%0{}d{}", escaped(&p.prefix), p.width, escaped(&p.suffix)));
    let tmp = args.output.with_file_name(format!(
        ".scnc-{}.tmp.mp4",
        args.output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
    ));
    let _pending = Pending::new(&tmp);
    let status = std::process::Command::new("ffmpeg")
        .args(["-loglevel", "error", "-y", "-framerate", &args.fps.to_string()])
        .args(["-start_number", &numbers[0].to_string(), "-i"])
        .arg(&input)
        .args(["-frames:v", &numbers.len().to_string(), "-c:v", "libx264", "-pix_fmt", "yuv420p"])
        .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"])
        .arg(&tmp)
        .status();
    let result = match status {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Err("MP4 needs `ffmpeg`, which is not on PATH: install it, or encode a `.gif` or `.png` (APNG) instead"
                .to_string())
        }
        Err(e) => Err(format!("cannot run `ffmpeg`: {e}")),
        Ok(s) if !s.success() => Err(format!("`ffmpeg` failed ({s})")),
        Ok(_) => std::fs::rename(&tmp, &args.output).map_err(|e| cannot_write(&args.output, &e)),
    };
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
