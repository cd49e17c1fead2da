//! The file the studio edits, the includes it may read (only below the file's
//! directory), and the watcher that tells open pages when either changes on disk.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, Weak};

use scnc::check::Overrides;
use scnc::source::{FsLoader, Loader};

use super::http::{Req, Stream};
use super::Studio;

/// Pages listening for changes at once; a new one past this ends the oldest.
const MAX_LISTENERS: usize = 8;

/// The edited file and what watches it.
pub(crate) struct Files {
    /// The file, absolute (its directory resolved, the name as given).
    pub(crate) root: PathBuf,
    /// Its directory, resolved: nothing outside it is read or written.
    dir: PathBuf,
    /// The files of the last compile (the file and its includes), which are watched.
    watched: Mutex<Vec<PathBuf>>,
    /// Directories under watch.
    watched_dirs: Mutex<Vec<PathBuf>>,
    watcher: Mutex<Option<notify::RecommendedWatcher>>,
    /// Open pages' event streams.
    listeners: Mutex<Vec<Stream>>,
    /// The parameters `scnc studio -D …` set, under the page's own.
    pub(crate) params: Overrides,
    /// The text the studio itself last saved: its own save coming back from the
    /// watcher is no news (and would undo keys typed since).
    saved: Mutex<Option<String>>,
}

impl Files {
    /// The file at `path`: it need not exist yet (the first save makes it), but its
    /// directory must, and if it exists it must be a scene-sized regular file.
    pub(crate) fn open(path: &Path, params: Overrides) -> Result<Files, String> {
        let name = path.file_name().ok_or_else(|| format!("`{}` does not name a file", path.display()))?;
        let dir = crate::cli::files::parent_dir(path)
            .canonicalize()
            .map_err(|e| format!("cannot open `{}`: its directory: {}", path.display(), scnc::source::io_reason(&e)))?;
        let root = dir.join(name);
        if root.exists() {
            FsLoader
                .read(&root)
                .map_err(|e| format!("cannot read `{}`: {}", path.display(), scnc::source::io_reason(&e)))?;
        }
        Ok(Files {
            watched: Mutex::new(vec![root.clone()]),
            root,
            dir,
            watched_dirs: Mutex::new(Vec::new()),
            watcher: Mutex::new(None),
            listeners: Mutex::new(Vec::new()),
            saved: Mutex::new(None),
            params,
        })
    }

    /// The file's text on disk (empty when it does not exist yet).
    pub(crate) fn text(&self) -> Result<String, String> {
        match FsLoader.read(&self.root) {
            Ok(t) => Ok(t),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(String::new()),
            Err(e) => Err(format!("cannot read `{}`: {}", self.root.display(), scnc::source::io_reason(&e))),
        }
    }

    /// `text` compiled as the file (its includes read through [`Files::loader`]), its
    /// parameters set by the command line's `-D` and then by the page's controls (`page`).
    pub(crate) fn compile(&self, text: String, page: &Overrides) -> scnc::Compiled {
        let name = self.root.file_name().map_or_else(|| "scene".into(), |n| n.to_string_lossy().into_owned());
        let mut set = self.params.clone();
        set.0.extend(page.0.iter().cloned());
        scnc::compile_file_with(&name, &self.root, text, &self.loader(), set)
    }

    /// The loader compiles use: the disk, below the file's directory only.
    pub(crate) fn loader(&self) -> Below<'_> {
        Below { dir: &self.dir }
    }

    /// Starts the watcher; changes are pushed to the pages listening.
    pub(crate) fn start_watching(&self, studio: &Arc<Studio>) {
        let weak: Weak<Studio> = Arc::downgrade(studio);
        let watcher = notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
            let (Ok(event), Some(studio)) = (event, weak.upgrade()) else { return };
            if !event.kind.is_access() {
                studio.files.changed(&event.paths);
            }
        });
        match watcher {
            Ok(w) => *lock(&self.watcher) = Some(w),
            Err(e) => {
                let _ =
                    writeln!(std::io::stderr(), "warning: cannot watch files; changes made outside will not show: {e}");
            }
        }
        self.watch(vec![self.root.clone()]);
    }

    /// Watches the files a compile read (those of its `map`) from now on.
    pub(crate) fn watch_read(&self, map: &scnc::source::SourceMap) {
        self.watch(map.files().map(|(_, f)| f.path.clone()).collect());
    }

    /// Watches `files` (the last compile's) from now on.
    pub(crate) fn watch(&self, files: Vec<PathBuf>) {
        use notify::Watcher as _;
        let mut dirs: Vec<PathBuf> = files.iter().filter_map(|f| f.parent().map(Path::to_path_buf)).collect();
        dirs.sort();
        dirs.dedup();
        *lock(&self.watched) = files;
        let mut guard = lock(&self.watcher);
        let Some(watcher) = guard.as_mut() else { return };
        let mut watched = lock(&self.watched_dirs);
        for d in watched.iter().filter(|d| !dirs.contains(d)) {
            let _ = watcher.unwatch(d);
        }
        for d in dirs.iter().filter(|d| !watched.contains(d)) {
            let _ = watcher.watch(d, notify::RecursiveMode::NonRecursive);
        }
        *watched = dirs;
    }

    /// A file-system event: the file's new text, or which include changed, to every page.
    fn changed(&self, paths: &[PathBuf]) {
        let watched = lock(&self.watched).clone();
        let Some(path) = paths.iter().find(|p| watched.contains(p)) else { return };
        let event = if *path == self.root {
            let Ok(text) = self.text() else { return };
            if lock(&self.saved).as_ref() == Some(&text) {
                return;
            }
            format!("event: file\ndata: {}\n\n", serde_json::json!({ "text": text }))
        } else {
            format!("event: include\ndata: {}\n\n", serde_json::json!({ "path": path.display().to_string() }))
        };
        lock(&self.listeners).retain_mut(|s| s.send(event.as_bytes()).is_ok());
    }

    /// Writes `text` to the file, whole or not at all, as `fmt` and `render` write.
    pub(crate) fn save(&self, text: String) -> std::io::Result<()> {
        crate::cli::files::write_text(&self.root, &text)?;
        *lock(&self.saved) = Some(text);
        Ok(())
    }

    /// Keeps `req` open as a server-sent event stream of changes.
    pub(crate) fn subscribe(&self, req: Req) {
        let Some(mut stream) = req.stream("text/event-stream") else { return };
        if stream.send(b": scnc studio: changes on disk\n\n").is_err() {
            return;
        }
        let mut listeners = lock(&self.listeners);
        if listeners.len() >= MAX_LISTENERS {
            listeners.remove(0);
        }
        listeners.push(stream);
    }
}

/// A lock whose holder panicked is still good: what it guards is replaced whole.
pub(crate) fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// The disk below one directory: an include (or mesh file) outside it, through `..`, an
/// absolute path or a symbolic link, is refused as unreadable.
pub(crate) struct Below<'a> {
    dir: &'a Path,
}

impl Below<'_> {
    fn inside(&self, path: &Path) -> std::io::Result<()> {
        let real = path.canonicalize()?;
        if real.starts_with(self.dir) {
            Ok(())
        } else {
            Err(std::io::Error::other(format!(
                "it is outside `{}`, the directory the studio serves",
                self.dir.display()
            )))
        }
    }
}

impl Loader for Below<'_> {
    fn read(&self, path: &Path) -> std::io::Result<String> {
        self.inside(path)?;
        FsLoader.read(path)
    }

    fn read_bytes(&self, path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
        self.inside(path)?;
        FsLoader.read_bytes(path, limit)
    }

    fn open_bytes(&self, path: &Path, limit: u64) -> std::io::Result<Box<dyn std::io::BufRead + '_>> {
        self.inside(path)?;
        FsLoader.open_bytes(path, limit)
    }
}
