//! The one owner of input text: every file of a compile, each at its own global base offset.

use std::path::{Path, PathBuf};

use crate::span::Span;

/// Largest source file.
pub const MAX_FILE_BYTES: usize = 4 * 1024 * 1024;

/// Largest mesh file (`mesh file(…)`): scanned models run to hundreds of megabytes.
pub const MAX_MESH_FILE_BYTES: u64 = 2 << 30;

/// Reads included files; the CLI reads the disk, tests may serve files from memory.
pub trait Loader {
    /// The text of the file at `path`.
    fn read(&self, path: &Path) -> std::io::Result<String>;

    /// The bytes of a data file (a mesh) at `path`, of at most `limit` bytes; from the
    /// disk unless a loader serves its own.
    fn read_bytes(&self, path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
        read_regular_file(path, limit)
    }

    /// A data file at `path` opened to be read a buffer at a time (a large mesh need not
    /// be held whole), failing once it passes `limit` bytes; from the disk unless a loader
    /// serves its own.
    fn open_bytes(&self, path: &Path, limit: u64) -> std::io::Result<Box<dyn std::io::BufRead + '_>> {
        Ok(Box::new(std::io::BufReader::with_capacity(1 << 16, open_regular_file(path, limit)?)))
    }
}

/// A regular file opened for reading, which fails once more than its limit is read.
pub struct Limited {
    file: std::fs::File,
    /// Its length when opened.
    len: u64,
    /// Bytes that may still be read.
    left: u64,
    /// The limit, for the error.
    limit: u64,
}

impl std::io::Read for Limited {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.file.read(buf)?;
        self.left = self.left.checked_sub(n as u64).ok_or_else(|| too_large(self.limit))?;
        Ok(n)
    }
}

fn too_large(limit: u64) -> std::io::Error {
    std::io::Error::other(format!("it is larger than the {} limit", size_name(limit)))
}

/// Opens a regular file of at most `limit` bytes, checked as [`read_regular_file`] checks
/// it, and again while it is read.
pub fn open_regular_file(path: &Path, limit: u64) -> std::io::Result<Limited> {
    let meta = regular(path)?;
    if meta.len() > limit {
        return Err(too_large(limit));
    }
    Ok(Limited { file: std::fs::File::open(path)?, len: meta.len(), left: limit, limit })
}

impl Limited {
    /// Its length when it was opened.
    pub fn len(&self) -> u64 {
        self.len
    }

    /// Whether it was empty when it was opened.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// All of `r`, a file of `len` bytes when opened: the bytes are asked of the system
/// first, so a file too large for memory is an error, not an abort.
pub fn read_all(mut r: impl std::io::Read, len: u64) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    bytes.try_reserve_exact(len as usize).map_err(|_| std::io::Error::other("not enough memory to read it"))?;
    r.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// The metadata of `path` if it is a regular file: a directory, device, pipe or socket is
/// refused before it is opened (`/dev/zero` would never end and opening a pipe blocks
/// until a writer comes).
fn regular(path: &Path) -> std::io::Result<std::fs::Metadata> {
    let meta = std::fs::metadata(path)?;
    if meta.is_dir() {
        return Err(std::io::Error::other("it is a directory"));
    }
    if !meta.is_file() {
        return Err(std::io::Error::other("it is not a regular file (a device, pipe or socket)"));
    }
    Ok(meta)
}

/// Reads a regular file of at most `limit` bytes, checking the limit while reading (a
/// file may grow after it was measured). A directory, device, pipe or socket is refused
/// before it is opened.
pub fn read_regular_file(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let file = open_regular_file(path, limit)?;
    let len = file.len();
    read_all(file, len)
}

/// A byte count as a limit is named: `4 MiB`, `2 GiB`.
fn size_name(bytes: u64) -> String {
    if bytes >= 1 << 30 && bytes.is_multiple_of(1 << 30) {
        format!("{} GiB", bytes >> 30)
    } else {
        format!("{} MiB", bytes >> 20)
    }
}

/// Reads files from the file system.
#[derive(Clone, Copy, Debug, Default)]
pub struct FsLoader;

impl Loader for FsLoader {
    /// Reads a regular file of at most [`MAX_FILE_BYTES`] (see [`read_regular_file`]).
    fn read(&self, path: &Path) -> std::io::Result<String> {
        let bytes = read_regular_file(path, MAX_FILE_BYTES as u64)?;
        String::from_utf8(bytes).map_err(|_| std::io::Error::other("it is not valid UTF-8"))
    }
}

/// A short, lowercase reason for an I/O error.
pub fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}

/// Index of a file in a [`SourceMap`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FileId(pub u32);

/// One loaded source file.
#[derive(Debug)]
pub struct SourceFile {
    /// The name shown in diagnostics (the path as the user or the `include` wrote it).
    pub name: String,
    /// The resolved path, used for include resolution and cycle detection.
    pub path: PathBuf,
    /// The full text.
    pub text: String,
    /// Global offset of the first byte.
    pub base: u32,
    /// Where each line starts (see [`line_starts`]), so a position costs a binary search.
    line_starts: Vec<usize>,
}

/// All files of one compile, laid end to end in one offset space (with a gap byte
/// between files so an end-of-file span never touches the next file).
#[derive(Debug, Default)]
pub struct SourceMap {
    files: Vec<SourceFile>,
    next_base: u32,
}

/// The most text one compile may hold across all its files (so global `u32` offsets never overflow).
pub const MAX_TOTAL_BYTES: usize = 256 * 1024 * 1024;

impl SourceMap {
    /// An empty map.
    pub fn new() -> SourceMap {
        SourceMap::default()
    }

    /// Adds a file and returns its id; `None` when the compile's total size limit is exceeded.
    pub fn add(&mut self, name: impl Into<String>, path: impl AsRef<Path>, text: String) -> Option<FileId> {
        let end = self.next_base as usize + text.len() + 1;
        if end > MAX_TOTAL_BYTES {
            return None;
        }
        let id = FileId(self.files.len() as u32);
        self.files.push(SourceFile {
            name: name.into(),
            path: path.as_ref().to_path_buf(),
            line_starts: line_starts(&text),
            text,
            base: self.next_base,
        });
        self.next_base = end as u32;
        Some(id)
    }

    /// The file with this id.
    pub fn file(&self, id: FileId) -> &SourceFile {
        &self.files[id.0 as usize]
    }

    /// All files in load order.
    pub fn files(&self) -> impl Iterator<Item = (FileId, &SourceFile)> {
        self.files.iter().enumerate().map(|(i, f)| (FileId(i as u32), f))
    }

    /// The file a span lies in.
    pub fn file_of(&self, span: Span) -> FileId {
        let idx = self.files.partition_point(|f| f.base <= span.start);
        FileId(idx.saturating_sub(1) as u32)
    }

    /// The span's range local to its file, clamped to the file's text.
    pub fn local_range(&self, span: Span) -> (FileId, std::ops::Range<usize>) {
        let id = self.file_of(span);
        let f = self.file(id);
        let len = f.text.len();
        let start = (span.start.saturating_sub(f.base) as usize).min(len);
        let end = (span.end.saturating_sub(f.base) as usize).clamp(start, len);
        (id, start..end)
    }

    /// The source text a span covers.
    pub fn snippet(&self, span: Span) -> &str {
        let (id, r) = self.local_range(span);
        &self.file(id).text[r]
    }

    /// One-based line and column (in characters) of a file-local byte offset. Lines end
    /// at `\n`, `\r\n` or a lone `\r`, as for ariadne and the Language Server Protocol.
    pub fn line_col(&self, id: FileId, offset: usize) -> (usize, usize) {
        let f = self.file(id);
        let offset = floor_char_boundary(&f.text, offset.min(f.text.len()));
        let line = f.line_starts.partition_point(|&s| s <= offset);
        let line_start = f.line_starts[line - 1];
        let col = f.text[line_start..offset].chars().count() + 1;
        (line, col)
    }
}

/// The byte offsets where the lines of `text` start: 0, and after each `\n`, `\r\n` or
/// lone `\r` (a `\r` directly before a `\n` belongs to that line break).
pub fn line_starts(text: &str) -> Vec<usize> {
    let bytes = text.as_bytes();
    let mut starts = vec![0];
    for (i, &b) in bytes.iter().enumerate() {
        let lone_cr = b == b'\r' && bytes.get(i + 1) != Some(&b'\n');
        if b == b'\n' || lone_cr {
            starts.push(i + 1);
        }
    }
    starts
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// `name` with every character but ASCII letters, digits, `_`, `-` and `.` made `_`: a
/// name any file format, XML attribute, OBJ line or download header takes as it is.
pub fn file_safe(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || "_-.".contains(c) { c } else { '_' }).collect()
}

/// Whether the system would give `bytes` more now: address space only is taken (no page
/// is touched) and given back, so an allocation this size that follows at once is not
/// an abort but for what runs beside it.
pub fn system_gives(bytes: u64) -> bool {
    let Ok(bytes) = usize::try_from(bytes) else { return false };
    Vec::<u8>::new().try_reserve_exact(bytes).is_ok()
}
