//! Progress bars for work that may take a while: hidden for the first second (a quick
//! render or mesh build prints nothing), then drawn on stderr and redrawn on their own
//! even while no step finishes (one large mesh can take many seconds), and only when
//! stderr is a terminal.

use std::io::{BufRead, IsTerminal, Read};
use std::path::Path;

use scnc::source::{FsLoader, Loader};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, LazyLock};
use std::time::Duration;

/// Every bar shown, drawn together (a mesh file read while objects are lowered has a bar
/// of its own under the lowering one).
static SHOWN: LazyLock<indicatif::MultiProgress> = LazyLock::new(indicatif::MultiProgress::new);

/// How long work runs before its bar appears.
const QUIET: Duration = Duration::from_secs(1);

/// A bar of `len` steps of `unit` (e.g. "rows").
pub(crate) struct Progress {
    bar: Option<indicatif::ProgressBar>,
    done: Arc<AtomicBool>,
}

impl Progress {
    /// A bar for `len` steps, named `unit`, with what is being done (`doing`).
    pub(crate) fn new(len: u64, unit: &str, doing: &str) -> Progress {
        let done = Arc::new(AtomicBool::new(false));
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = indicatif::ProgressBar::with_draw_target(Some(len), indicatif::ProgressDrawTarget::hidden());
            let template = format!("{{spinner}} {doing} {{bar:40}} {{pos}}/{{len}} {unit}, {{elapsed}}");
            if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
                bar.set_style(style);
            }
            let (shown, done) = (bar.clone(), done.clone());
            // Without a thread for it (resources exhausted) the bar simply never shows.
            let _ = std::thread::Builder::new().spawn(move || {
                std::thread::sleep(QUIET);
                if !done.load(Ordering::Acquire) {
                    SHOWN.add(shown.clone());
                    shown.enable_steady_tick(Duration::from_millis(120));
                }
            });
            bar
        });
        Progress { bar, done }
    }

    /// One step done.
    pub(crate) fn step(&self) {
        self.steps(1);
    }

    /// `n` steps done.
    pub(crate) fn steps(&self, n: u64) {
        if let Some(bar) = &self.bar {
            bar.inc(n);
        }
    }

    /// All done: the bar, if it was drawn, is cleared.
    pub(crate) fn finish(&self) {
        self.done.store(true, Ordering::Release);
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
            SHOWN.remove(bar);
        }
    }
}

/// Reads files from the file system as [`FsLoader`] does (the same checks and limits),
/// with a bar for a data file (a mesh) that takes more than a second to read.
pub(crate) struct Reading;

impl Loader for Reading {
    fn read(&self, path: &Path) -> std::io::Result<String> {
        FsLoader.read(path)
    }

    fn read_bytes(&self, path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
        let (file, len) = Reading::counted(path, limit)?;
        scnc::source::read_all(file, len)
    }

    fn open_bytes(&self, path: &Path, limit: u64) -> std::io::Result<Box<dyn BufRead + '_>> {
        Ok(Box::new(std::io::BufReader::with_capacity(1 << 16, Reading::counted(path, limit)?.0)))
    }
}

impl Reading {
    /// `path` opened as [`scnc::source::open_regular_file`] opens it, with a bar, and its
    /// length.
    fn counted(path: &Path, limit: u64) -> std::io::Result<(Counted<scnc::source::Limited>, u64)> {
        let file = scnc::source::open_regular_file(path, limit)?;
        let len = file.len();
        let name = path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
        let progress = Progress::new(len.div_ceil(MIB), "MiB", &format!("reading {name}"));
        Ok((Counted { file, progress, read: 0 }, len))
    }
}

const MIB: u64 = 1 << 20;

/// A file whose reading moves a bar a mebibyte at a time.
struct Counted<R> {
    file: R,
    progress: Progress,
    /// Bytes read so far.
    read: u64,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.file.read(buf)?;
        let before = self.read / MIB;
        self.read += n as u64;
        self.progress.steps(self.read / MIB - before);
        Ok(n)
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}
