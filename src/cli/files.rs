//! Output files written whole or not at all: to a temporary file beside the target,
//! then renamed over it, keeping the mode of a file being replaced. A symbolic link at
//! the output path is written through (its target is replaced, the link kept), as
//! editors and `cp` do.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporary files being written, removed if the process is interrupted.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// On Ctrl-C (SIGINT): remove any temporary file being written and end the process at
/// once with `code`, leaving every output as it was. Without this a render runs on and
/// an interrupt during encoding leaves a `.scnc-*.tmp` file behind.
pub(crate) fn stop_on_interrupt(code: i32) -> Result<(), String> {
    ctrlc::set_handler(move || {
        for path in PENDING.lock().map(|p| p.clone()).unwrap_or_default() {
            let _ = std::fs::remove_file(path);
        }
        #[allow(clippy::exit, reason = "the interrupt handler ends the process; the main thread may be mid-render")]
        std::process::exit(code);
    })
    .map_err(|e| format!("cannot handle Ctrl-C: {e}"))
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
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if ext.as_deref() != Some("png") {
        return Err(format!("cannot write `{shown}`: scnc writes PNG images; try a `.png` file name"));
    }
    check_output_as(path, "a file name ending in `.png`")
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

/// Why `path` could not be written, in the user's terms: their path (never the
/// temporary file beside it), the reason, and what to do.
/// The input among `inputs` that writing `output` would overwrite, if any: paths are
/// compared after resolving links and `..` (the output need not exist yet, its folder
/// must), so `-o ./model.obj` is caught for `mesh file("model.obj")`.
pub(crate) fn overwritten_input<'a>(output: &Path, inputs: impl IntoIterator<Item = &'a Path>) -> Option<&'a Path> {
    let resolve = |p: &Path| -> Option<std::path::PathBuf> {
        let name = p.file_name()?;
        let parent = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        Some(parent.canonicalize().ok()?.join(name))
    };
    let out = resolve(output)?;
    inputs.into_iter().find(|i| resolve(i).is_some_and(|p| p == out))
}

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
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The file a path finally names, following symbolic links (a dangling one names
/// where its target would be); `path` itself when it is not a link. A loop of links
/// stops after 40, like the kernel's limit.
fn link_target(path: &Path) -> PathBuf {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        let Ok(next) = std::fs::read_link(&p) else { break };
        p = if next.is_absolute() { next } else { parent_dir(&p).join(next) };
    }
    p
}

/// Writes `path` through `write` into a temporary file beside it (named with `suffix`),
/// then renames it into place: the target is replaced whole, or left as it was.
pub(crate) fn write_atomic(
    path: &Path,
    suffix: &str,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let path = &link_target(path);
    let dir = parent_dir(path);
    let mut builder = tempfile::Builder::new();
    builder.prefix(".scnc-").suffix(suffix);
    // A new file gets the mode any tool gives one (0666 less the umask, applied by the
    // system at creation), not the temporary file's private 0600.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir)?;
    let _pending = Pending::new(tmp.path());
    // Replacing a file keeps its permissions (a temporary file is private by default).
    if let Ok(meta) = std::fs::metadata(path) {
        tmp.as_file().set_permissions(meta.permissions())?;
    }
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

/// Encodes a PNG whole or not at all.
use scnc::render::BitDepth;

pub(crate) fn write_png(path: &Path, image: &scnc::render::Image) -> std::io::Result<()> {
    let colour = match image.depth {
        BitDepth::Eight => image::ExtendedColorType::Rgb8,
        BitDepth::Sixteen => image::ExtendedColorType::Rgb16,
    };
    encode_png(path, &image.pixels, image.width, image.height, colour)
}

/// Encodes `pixels` of a `width × height` image as a PNG, whole or not at all.
fn encode_png(
    path: &Path,
    pixels: &[u8],
    width: u32,
    height: u32,
    colour: image::ExtendedColorType,
) -> std::io::Result<()> {
    use image::ImageEncoder;
    write_atomic(path, ".png.tmp", |w| {
        image::codecs::png::PngEncoder::new(w).write_image(pixels, width, height, colour).map_err(std::io::Error::other)
    })
}

/// Encodes a part of a `width × height` image whole or not at all: RGBA at full size,
/// `image`'s pixels opaque at `region` and every other pixel transparent black, which
/// is what `scnc merge` assembles (and any viewer shows in place).
pub(crate) fn write_part_png(
    path: &Path,
    width: u32,
    height: u32,
    region: scnc::render::Region,
    image: &scnc::render::Image,
) -> std::io::Result<()> {
    // One sample is one byte, or two in the machine's order.
    let sample = image.depth.sample_bytes();
    let colour = match image.depth {
        BitDepth::Eight => image::ExtendedColorType::Rgba8,
        BitDepth::Sixteen => image::ExtendedColorType::Rgba16,
    };
    let mut rgba = vec![0u8; width as usize * height as usize * 4 * sample];
    for (dy, row) in image.pixels.chunks_exact(3 * sample * image.width as usize).enumerate() {
        let start = ((region.y0 as usize + dy) * width as usize + region.x0 as usize) * 4 * sample;
        for (px, out) in row.chunks_exact(3 * sample).zip(rgba[start..].chunks_exact_mut(4 * sample)) {
            out[..3 * sample].copy_from_slice(px);
            // Opaque: the largest sample, all bits set at either depth.
            out[3 * sample..].fill(255);
        }
    }
    encode_png(path, &rgba, width, height, colour)
}
