//! Output files written whole or not at all: to a temporary file beside the target,
//! then renamed over it, keeping the mode of a file being replaced.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The usage error for an output path scnc cannot write a PNG to.
pub(crate) fn check_output(path: &Path) -> Result<(), String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if ext.as_deref() != Some("png") {
        return Err(format!("cannot write `{}`: scnc writes PNG images; try a `.png` file name", path.display()));
    }
    let out_dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !out_dir.is_dir() {
        return Err(format!("cannot write `{}`: the directory `{}` does not exist", path.display(), out_dir.display()));
    }
    Ok(())
}

/// Writes `path` through `write` into a temporary file beside it (named with `suffix`),
/// then renames it into place: the target is replaced whole, or left as it was.
pub(crate) fn write_atomic(
    path: &Path,
    suffix: &str,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new().prefix(".scnc-").suffix(suffix).tempfile_in(dir)?;
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
pub(crate) fn write_png(path: &Path, image: &scnc::render::Image) -> std::io::Result<()> {
    use image::ImageEncoder;
    write_atomic(path, ".png.tmp", |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(&image.pixels, image.width, image.height, image::ExtendedColorType::Rgb8)
            .map_err(std::io::Error::other)
    })
}
