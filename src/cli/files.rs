//! Output files written whole or not at all: to a temporary file beside the target,
//! then renamed over it, keeping the mode of a file being replaced. A symbolic link at
//! the output path is written through (its target is replaced, the link kept), as
//! editors and `cp` do. Also: SIGINT, SIGTERM and SIGHUP remove what is half-written and
//! stop a child process; PNGs are written with text chunks (an animation's rate) and
//! read back within the documented image limits; and the check that an output is not
//! one of the inputs.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporary files being written, removed if the process is interrupted.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// A child process (`ffmpeg`) working for us, killed if the process is interrupted.
static CHILD: Mutex<Option<std::process::Child>> = Mutex::new(None);

/// On SIGINT (Ctrl-C), SIGTERM or SIGHUP — what `timeout`, `kill`, Slurm's time limits
/// and Kubernetes send — remove any temporary file being written, stop the child
/// process working for us, and end the process at once: with `code` on SIGINT, with
/// 128 + the signal's number on the others, as a shell reports them. Every output is
/// left as it was; without this a render runs on, and a signal during encoding leaves
/// a `.scnc-*.tmp` file behind.
pub(crate) fn stop_on_interrupt(code: i32) -> Result<(), String> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
        .map_err(|e| format!("cannot handle signals: {e}"))?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                if let Some(child) = CHILD.lock().unwrap_or_else(|e| e.into_inner()).as_mut() {
                    let _ = child.kill();
                    let _ = child.wait();
                }
                for path in PENDING.lock().map(|p| p.clone()).unwrap_or_default() {
                    let _ = std::fs::remove_file(path);
                }
                let code = if signal == SIGINT { code } else { 128 + signal };
                #[allow(
                    clippy::exit,
                    reason = "the signal handler ends the process; the main thread may be mid-render"
                )]
                std::process::exit(code);
            }
        })
        .map(|_| ())
        .map_err(|e| format!("cannot handle signals: {e}"))
}

/// Runs `command` to its end as the child a signal stops (see [`stop_on_interrupt`]).
pub(crate) fn run_child(command: &mut std::process::Command) -> std::io::Result<std::process::ExitStatus> {
    let child = command.spawn()?;
    *CHILD.lock().unwrap_or_else(|e| e.into_inner()) = Some(child);
    loop {
        let mut guard = CHILD.lock().unwrap_or_else(|e| e.into_inner());
        let Some(child) = guard.as_mut() else { return Err(std::io::Error::other("the child was stopped")) };
        if let Some(status) = child.try_wait()? {
            *guard = None;
            return Ok(status);
        }
        drop(guard);
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Registers a temporary file for removal on interrupt while it lives.
pub(crate) struct Pending(PathBuf);

impl Pending {
    /// Registers `path` (a file another program may be writing, too).
    pub(crate) fn new(path: &Path) -> Pending {
        if let Ok(mut p) = PENDING.lock() {
            p.push(path.to_path_buf());
        }
        Pending(path.to_path_buf())
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        if let Ok(mut p) = PENDING.lock() {
            p.retain(|q| *q != self.0);
        }
    }
}

/// The usage error for an output path scnc cannot write a PNG to, found before any work.
pub(crate) fn check_output(path: &Path) -> Result<(), String> {
    let shown = path.display();
    if path.as_os_str().to_string_lossy().ends_with(std::path::MAIN_SEPARATOR) {
        return Err(format!("cannot write `{shown}`: it names a directory; give a file name ending in `.png`"));
    }
    if !is_png(path) {
        return Err(format!("cannot write `{shown}`: scnc writes PNG images; try a `.png` file name"));
    }
    check_output_as(path, "a file name ending in `.png`")
}

/// [`check_output`] for an image that may also be OpenEXR (`.exr`, linear float).
pub(crate) fn check_image_output(path: &Path) -> Result<(), String> {
    if is_exr(path) {
        return check_output_as(path, "a file name ending in `.exr`");
    }
    check_output(path).map_err(|e| {
        e.replace(
            "scnc writes PNG images; try a `.png` file name",
            "scnc writes PNG images, or OpenEXR for linear light; try a `.png` or `.exr` file name",
        )
    })
}

fn extension_is(path: &Path, ext: &str) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Whether `path` names a PNG file.
pub(crate) fn is_png(path: &Path) -> bool {
    extension_is(path, "png")
}

/// Whether `path` names an OpenEXR file.
pub(crate) fn is_exr(path: &Path) -> bool {
    extension_is(path, "exr")
}

/// Writes a float image (linear radiance) as OpenEXR, 32-bit float RGB, uncompressed,
/// whole or not at all (`cli::exr`; Mitsuba's reader reads it back exactly).
pub(crate) fn write_exr(path: &Path, image: &scnc::render::Image) -> std::io::Result<()> {
    if image.depth != BitDepth::Float {
        return Err(std::io::Error::other("an OpenEXR image holds float samples"));
    }
    let values = image.floats();
    let bytes = super::exr::encode(image.width, image.height, &values);
    write_atomic(path, ".exr.tmp", |w| w.write_all(&bytes))
}

/// The usage error for an output path that names a directory or a file in a directory
/// that does not exist, found before any work; `what` says what to give instead.
pub(crate) fn check_output_as(path: &Path, what: &str) -> Result<(), String> {
    let shown = path.display();
    if path.as_os_str().to_string_lossy().ends_with(std::path::MAIN_SEPARATOR) {
        return Err(format!("cannot write `{shown}`: it names a directory; give {what}"));
    }
    let target = link_target(path);
    if target.is_dir() {
        return Err(format!("cannot write `{shown}`: it is a directory"));
    }
    let out_dir = parent_dir(&target);
    if !out_dir.is_dir() {
        return Err(format!("cannot write `{shown}`: the directory `{}` does not exist", out_dir.display()));
    }
    Ok(())
}

/// `p` with its folder resolved (links and `..`; the folder must exist, the file need
/// not): two paths naming one file resolve alike.
pub(crate) fn resolved(p: &Path) -> Option<PathBuf> {
    Some(parent_dir(p).canonicalize().ok()?.join(p.file_name()?))
}

/// The input among `inputs` that writing `output` would overwrite, if any ([`resolved`]
/// paths compared), so `-o ./model.obj` is caught for `mesh file("model.obj")`.
pub(crate) fn overwritten_input<'a>(output: &Path, inputs: impl IntoIterator<Item = &'a Path>) -> Option<&'a Path> {
    let out = resolved(output)?;
    inputs.into_iter().find(|i| resolved(i).is_some_and(|p| p == out))
}

/// Why `path` could not be written, in the user's terms: their path (never the
/// temporary file beside it), the reason, and what to do.
pub(crate) fn cannot_write(path: &Path, e: &std::io::Error) -> String {
    use std::io::ErrorKind;
    let dir = parent_dir(&link_target(path)).display().to_string();
    let reason = match e.kind() {
        ErrorKind::PermissionDenied => {
            format!("permission denied: `{dir}` is not writable (check its permissions, or write elsewhere)")
        }
        ErrorKind::NotFound => format!("the directory `{dir}` does not exist (or is not a real directory)"),
        ErrorKind::StorageFull => "the disk is full".to_string(),
        ErrorKind::ReadOnlyFilesystem => format!("`{dir}` is on a read-only file system"),
        ErrorKind::QuotaExceeded => "the disk quota is exceeded".to_string(),
        // An encoder's own error says what went wrong in its words.
        ErrorKind::Other => e.to_string(),
        kind => kind.to_string(),
    };
    format!("cannot write `{}`: {reason}", path.display())
}

/// The directory a file is in (`.` for a bare file name).
pub(crate) fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The file a path finally names, following symbolic links (a dangling one names
/// where its target would be); `path` itself when it is not a link. A loop of links
/// stops after 40, like the kernel's limit.
pub(crate) fn link_target(path: &Path) -> PathBuf {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        let Ok(next) = std::fs::read_link(&p) else { break };
        p = if next.is_absolute() { next } else { parent_dir(&p).join(next) };
    }
    p
}

/// An empty temporary file of a random name beside `path` (a resolved target), with
/// the mode the file will have: a new file's usual mode (0666 less the umask), or the
/// mode of the file it will replace.
pub(crate) fn stage_beside(path: &Path, suffix: &str) -> std::io::Result<tempfile::NamedTempFile> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(".scnc-").suffix(suffix);
    // A new file gets the mode any tool gives one (0666 less the umask, applied by the
    // system at creation), not the temporary file's private 0600.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = builder.tempfile_in(parent_dir(path))?;
    // Replacing a file keeps its permissions (a temporary file is private by default).
    if let Ok(meta) = std::fs::metadata(path) {
        tmp.as_file().set_permissions(meta.permissions())?;
    }
    Ok(tmp)
}

/// Writes `path` through `write` into a temporary file beside it (named with `suffix`),
/// then renames it into place: the target is replaced whole, or left as it was.
pub(crate) fn write_atomic(
    path: &Path,
    suffix: &str,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let path = &link_target(path);
    let mut tmp = stage_beside(path, suffix)?;
    let _pending = Pending::new(tmp.path());
    {
        let mut w = std::io::BufWriter::new(tmp.as_file_mut());
        write(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Writes text whole or not at all.
pub(crate) fn write_text(path: &Path, text: &str) -> std::io::Result<()> {
    write_atomic(path, ".tmp", |w| w.write_all(text.as_bytes()))
}

use scnc::render::BitDepth;

/// The PNG text keyword under which an animation's frames carry its frame rate, which
/// `scnc encode` reads.
pub(crate) const FPS_KEY: &str = "scnc:fps";

/// Encodes a PNG whole or not at all, with `text` as tEXt chunks (keyword, text).
pub(crate) fn write_png(path: &Path, image: &scnc::render::Image, text: &[(&str, String)]) -> std::io::Result<()> {
    encode_png(path, &image.pixels, image.width, image.height, png::ColorType::Rgb, image.depth, text)
}

/// Encodes `pixels` of a `width × height` image (16-bit samples in the machine's
/// order) as a PNG, whole or not at all.
fn encode_png(
    path: &Path,
    pixels: &[u8],
    width: u32,
    height: u32,
    colour: png::ColorType,
    depth: BitDepth,
    text: &[(&str, String)],
) -> std::io::Result<()> {
    let depth_bits = match depth {
        BitDepth::Eight => png::BitDepth::Eight,
        BitDepth::Sixteen => png::BitDepth::Sixteen,
        BitDepth::Float | BitDepth::Sums => {
            return Err(std::io::Error::other("a PNG has 8 or 16 bits per channel, not float"))
        }
    };
    write_atomic(path, ".png.tmp", |w| {
        let mut encoder = png::Encoder::new(w, width, height);
        encoder.set_color(colour);
        encoder.set_depth(depth_bits);
        for (key, value) in text {
            encoder.add_text_chunk((*key).to_string(), value.clone()).map_err(std::io::Error::other)?;
        }
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        let mut stream = writer.stream_writer().map_err(std::io::Error::other)?;
        match depth {
            BitDepth::Eight | BitDepth::Float | BitDepth::Sums => stream.write_all(pixels)?,
            // PNG's samples are big-endian: converted a row's worth at a time.
            BitDepth::Sixteen => {
                for chunk in pixels.chunks(1 << 16) {
                    let be: Vec<u8> =
                        chunk.chunks_exact(2).flat_map(|s| u16::from_ne_bytes([s[0], s[1]]).to_be_bytes()).collect();
                    stream.write_all(&be)?;
                }
            }
        }
        stream.finish().map_err(std::io::Error::other)
    })
}

/// Most bytes a decoded image may take: the largest image `render` writes (at the
/// pixel limit, 16-bit RGBA), so every image scnc writes can be read back, and no more.
const MAX_DECODED_BYTES: u64 = scnc::check::MAX_PIXELS * 8;

/// Reads a PNG that scnc (or anyone) wrote, within the documented image limits: the
/// side and pixel limits of `render`, not the decoder's default of 512 MiB, which a
/// 16-bit 8200×8200 part exceeds.
pub(crate) fn read_png(path: &Path) -> Result<image::DynamicImage, String> {
    let cannot = |e: &dyn std::fmt::Display| format!("cannot read `{}`: {e}", path.display());
    let mut reader = image::ImageReader::open(path).map_err(|e| cannot(&e))?;
    reader.set_format(image::ImageFormat::Png);
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(scnc::check::MAX_IMAGE_SIDE);
    limits.max_image_height = Some(scnc::check::MAX_IMAGE_SIDE);
    limits.max_alloc = Some(MAX_DECODED_BYTES);
    reader.limits(limits);
    reader.decode().map_err(|e| cannot(&e))
}

/// A PNG's size (width, height) and its tEXt chunks (keyword, text).
pub(crate) type PngHeader = ((u32, u32), Vec<(String, String)>);

/// A PNG's size and its tEXt chunks, from its header alone.
pub(crate) fn png_header(path: &Path) -> Result<PngHeader, String> {
    let cannot = |e: &dyn std::fmt::Display| format!("cannot read `{}`: {e}", path.display());
    let file = std::fs::File::open(path).map_err(|e| cannot(&e))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    // The header only: no image data is read or allocated.
    decoder.set_limits(png::Limits { bytes: MAX_DECODED_BYTES as usize });
    let reader = decoder.read_info().map_err(|e| cannot(&e))?;
    let info = reader.info();
    let text = info.uncompressed_latin1_text.iter().map(|t| (t.keyword.clone(), t.text.clone())).collect();
    Ok(((info.width, info.height), text))
}

/// Encodes a part of a `width × height` image whole or not at all: RGBA at full size,
/// `image`'s pixels opaque at `region` and every other pixel transparent black, which
/// is what `scnc merge` assembles (and any viewer shows in place).
pub(crate) fn write_part_png(
    path: &Path,
    width: u32,
    height: u32,
    region: scnc::render::PixelRect,
    image: &scnc::render::Image,
) -> std::io::Result<()> {
    // One sample is one byte, or two in the machine's order.
    let sample = image.depth.sample_bytes();
    let mut rgba = vec![0u8; width as usize * height as usize * 4 * sample];
    for (dy, row) in image.pixels.chunks_exact(3 * sample * image.width as usize).enumerate() {
        let start = ((region.y0 as usize + dy) * width as usize + region.x0 as usize) * 4 * sample;
        for (px, out) in row.chunks_exact(3 * sample).zip(rgba[start..].chunks_exact_mut(4 * sample)) {
            out[..3 * sample].copy_from_slice(px);
            // Opaque: the largest sample, all bits set at either depth.
            out[3 * sample..].fill(255);
        }
    }
    encode_png(path, &rgba, width, height, png::ColorType::Rgba, image.depth, &[])
}
