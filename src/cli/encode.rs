//! `scnc encode`: an image sequence (`frame-####.png`) into one animation for previews:
//! GIF, APNG (a `.png` output), or MP4 through `ffmpeg` when it is installed.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::files::{
    cannot_write, check_output_as, link_target, parent_dir, png_header, read_png, resolved, run_child, stage_beside,
    stop_on_interrupt, write_atomic, Pending, FPS_KEY,
};
use super::frames::{frame_path, Pattern};
use super::usage_error;

#[derive(clap::Args)]
pub(crate) struct EncodeArgs {
    /// The frames, named as `render -o` named them: `out/frame-####.png`.
    frames: PathBuf,
    /// The animation: `.gif`, `.png` (APNG) or `.mp4` (needs `ffmpeg` on PATH).
    #[arg(short, long)]
    output: PathBuf,
    /// Frames per second, fractions allowed (23.976); by default the scene's `fps`,
    /// which `render` writes into each frame, or 24.
    #[arg(long, value_parser = parse_fps)]
    fps: Option<f64>,
}

/// A rate above 0 and at most `MAX_FPS`, as the scene's `fps` may be.
fn parse_fps(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x > 0.0 && x <= scnc::check::MAX_FPS => Ok(x),
        _ => Err(format!("`{s}` frames per second: give a number above 0 and at most {}", scnc::check::MAX_FPS)),
    }
}

/// What the output's extension asks for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Gif,
    Apng,
    Mp4,
}

/// The frames of one encode: where they are, their numbers and their common size.
struct Frames<'a> {
    pattern: &'a Path,
    numbers: Vec<u32>,
    width: u32,
    height: u32,
}

/// The numbers of the frames on disk that `pattern` names, in order: every file in its
/// directory that is the pattern with its `#` run replaced by at least that many digits.
/// Frames must run without a gap: an animation missing a frame (a task that failed) is
/// refused rather than encoded with a jump.
fn find_frames(pattern: &Path) -> Result<Vec<u32>, String> {
    let names = Pattern::of(pattern).ok_or_else(|| {
        format!("`{}` names one file: give the frames' pattern, like `out/frame-####.png`", pattern.display())
    })?;
    let dir = parent_dir(pattern);
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

impl Frames<'_> {
    /// The frames `pattern` names, all of one size (read from their headers, so a frame
    /// of another size is refused before any is decoded, whatever the format), and the
    /// rate the first one carries, if any.
    fn find(pattern: &Path) -> Result<(Frames<'_>, Option<f64>), String> {
        let numbers = find_frames(pattern)?;
        let first = frame_path(pattern, numbers[0]);
        let ((width, height), text) = png_header(&first)?;
        for &n in &numbers[1..] {
            let path = frame_path(pattern, n);
            let ((w, h), _) = png_header(&path)?;
            if (w, h) != (width, height) {
                return Err(format!(
                    "`{}` is {w}×{h} but `{}` is {width}×{height}: every frame must have one size",
                    path.display(),
                    first.display()
                ));
            }
        }
        let fps = text.iter().find(|(k, _)| k == FPS_KEY).and_then(|(_, v)| parse_fps(v).ok());
        Ok((Frames { pattern, numbers, width, height }, fps))
    }

    /// Frame `n` decoded as RGBA: one at a time, so memory holds one frame whatever the
    /// animation's length.
    fn read(&self, n: u32) -> Result<Vec<u8>, String> {
        let path = frame_path(self.pattern, n);
        let image = read_png(&path)?.to_rgba8();
        if image.dimensions() != (self.width, self.height) {
            return Err(format!("`{}` changed size while it was being encoded", path.display()));
        }
        Ok(image.into_raw())
    }
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
    if let Some(frame) = output_is_a_frame(&args.output, &args.frames) {
        return usage_error(&format!(
            "`{}` is frame {frame} of `{}`: writing it would change the frames; name another output",
            args.output.display(),
            args.frames.display()
        ));
    }
    // Interrupted, nothing is left behind: the shell's 128 + SIGINT.
    if let Err(e) = stop_on_interrupt(130) {
        let _ = writeln!(std::io::stderr(), "warning: {e}");
    }
    let (frames, carried) = match Frames::find(&args.frames) {
        Ok(f) => f,
        Err(e) => return usage_error(&e),
    };
    let fps = args.fps.or(carried).unwrap_or(DEFAULT_FPS);
    let result = match format {
        Format::Mp4 => mp4(&args.output, &frames, fps),
        Format::Gif | Format::Apng => {
            let written = write_atomic(&args.output, ".tmp", |out| match format {
                Format::Gif => gif(out, &frames, fps),
                _ => apng(out, &frames, fps),
            });
            written.map_err(|e| cannot_write(&args.output, &e))
        }
    };
    let n = &frames.numbers;
    match result {
        Ok(()) => {
            let _ = writeln!(
                std::io::stderr(),
                "encoded {}: frames {} to {} ({}) at {fps} fps{}",
                args.output.display(),
                n[0],
                n[n.len() - 1],
                n.len(),
                match (args.fps, carried) {
                    (None, Some(_)) => " (the scene's rate, from its frames)",
                    _ => "",
                }
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            ExitCode::from(1)
        }
    }
}

/// The rate when neither `--fps` nor the frames give one.
const DEFAULT_FPS: f64 = 24.0;

/// The frame number `output` would be in the sequence `pattern` names (after resolving
/// links and `..`), if any: writing there would replace a frame or add one.
fn output_is_a_frame(output: &Path, pattern: &Path) -> Option<u32> {
    let names = Pattern::of(pattern)?;
    let frame = names.frame_of(output.file_name()?.to_str()?)?;
    (resolved(output)?.parent() == resolved(pattern)?.parent()).then_some(frame)
}

/// Adapts a fallible frame reader to the encoders' `io::Error`.
fn read_frame(frames: &Frames<'_>, n: u32) -> std::io::Result<Vec<u8>> {
    frames.read(n).map_err(std::io::Error::other)
}

/// A GIF looping forever. GIF delays are in hundredths of a second, so a rate that does
/// not divide 100 is rounded to the nearest hundredth (24 fps plays at 25).
fn gif(out: &mut dyn Write, frames: &Frames<'_>, fps: f64) -> std::io::Result<()> {
    use image::codecs::gif::{GifEncoder, Repeat};
    let mut encoder = GifEncoder::new_with_speed(out, 10);
    encoder.set_repeat(Repeat::Infinite).map_err(std::io::Error::other)?;
    let delay = image::Delay::from_saturating_duration(std::time::Duration::from_secs_f64(1.0 / fps));
    for &n in &frames.numbers {
        let rgba = read_frame(frames, n)?;
        let buffer = image::RgbaImage::from_raw(frames.width, frames.height, rgba)
            .ok_or_else(|| std::io::Error::other("frame size"))?;
        encoder.encode_frame(image::Frame::from_parts(buffer, 0, 0, delay)).map_err(std::io::Error::other)?;
    }
    Ok(())
}

/// The frame delay `1/fps` as APNG's fraction of two 16-bit numbers: exact for whole
/// rates and for thousandths up to 65.535 fps (23.976 is 1000/23976 s).
fn apng_delay(fps: f64) -> (u16, u16) {
    let thousandths = (fps * 1000.0).round();
    if (thousandths / 1000.0 - fps.round()).abs() > 0.0 && thousandths <= u16::MAX as f64 {
        (1000, thousandths as u16)
    } else {
        (1, fps.round().clamp(1.0, u16::MAX as f64) as u16)
    }
}

/// An APNG looping forever, each frame shown 1/fps s; viewers without APNG support show
/// the first frame.
fn apng(out: &mut dyn Write, frames: &Frames<'_>, fps: f64) -> std::io::Result<()> {
    let mut encoder = png::Encoder::new(out, frames.width, frames.height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_animated(frames.numbers.len() as u32, 0).map_err(std::io::Error::other)?;
    let (num, den) = apng_delay(fps);
    encoder.set_frame_delay(num, den).map_err(std::io::Error::other)?;
    let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
    for &n in &frames.numbers {
        writer.write_image_data(&read_frame(frames, n)?).map_err(std::io::Error::other)?;
    }
    writer.finish().map_err(std::io::Error::other)
}

/// MP4 (H.264, yuv420p for players' sake) by `ffmpeg`, run in the frames' directory
/// (so nothing in the directory's name reaches its pattern syntax), into a temporary
/// file of a random name beside the output (through a link at the output, as every
/// writer goes), renamed over it when ffmpeg succeeds. A signal stops ffmpeg too.
fn mp4(output: &Path, frames: &Frames<'_>, fps: f64) -> Result<(), String> {
    let p = Pattern::of(frames.pattern).ok_or("the frames are not a pattern")?;
    // ffmpeg's image2 pattern: `%04d` for `####` (a literal `%` doubled).
    let escaped = |s: &str| s.replace('%', "%%");
    let input = format!("{}%0{}d{}", escaped(&p.prefix), p.width, escaped(&p.suffix));
    let dir = parent_dir(frames.pattern);
    let target = link_target(output);
    let tmp = stage_beside(&target, ".tmp.mp4").map_err(|e| cannot_write(output, &e))?;
    let _pending = Pending::new(tmp.path());
    let tmp_path = std::path::absolute(tmp.path()).map_err(|e| cannot_write(output, &e))?;
    let status = run_child(
        std::process::Command::new("ffmpeg")
            .current_dir(dir)
            .args(["-loglevel", "error", "-nostdin", "-y", "-framerate", &fps.to_string()])
            .args(["-start_number", &frames.numbers[0].to_string(), "-i"])
            .arg(&input)
            .args(["-frames:v", &frames.numbers.len().to_string(), "-c:v", "libx264", "-pix_fmt", "yuv420p"])
            .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-f", "mp4"])
            .arg(&tmp_path),
    );
    match status {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Err("MP4 needs `ffmpeg`, which is not on PATH: install it, or encode a `.gif` or `.png` (APNG) instead"
                .to_string())
        }
        Err(e) => Err(format!("cannot run `ffmpeg`: {e}")),
        Ok(s) if !s.success() => Err(format!("`ffmpeg` failed ({s})")),
        Ok(_) => tmp.persist(&target).map(|_| ()).map_err(|e| cannot_write(output, &e.error)),
    }
}

#[cfg(test)]
mod tests {
    use super::apng_delay;

    #[test]
    fn apng_delays_are_exact_for_whole_and_film_rates() {
        assert_eq!(apng_delay(24.0), (1, 24));
        assert_eq!(apng_delay(23.976), (1000, 23976));
        assert_eq!(apng_delay(29.97), (1000, 29970));
        assert_eq!(apng_delay(1000.0), (1, 1000));
    }
}
