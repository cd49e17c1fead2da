//! `scnc watch`: render, then render again whenever the scene or a file it includes
//! changes.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::render::{render_once, RenderArgs};
use super::usage_error;

/// What wakes `watch` up.
enum Wake {
    /// These paths changed.
    Changed(Vec<PathBuf>),
    /// Ctrl-C.
    Stop,
}

/// How long `watch` waits for more changes before rendering, so one save (often
/// several file-system events) renders once.
const DEBOUNCE: std::time::Duration = std::time::Duration::from_millis(150);

pub(crate) fn watch_cmd(args: RenderArgs) -> ExitCode {
    use notify::Watcher as _;
    let pool = match args.checked_pool() {
        Ok(p) => p,
        Err(code) => return code,
    };
    let (tx, rx) = std::sync::mpsc::channel();
    let stop = tx.clone();
    // The handler only wakes the loop, so a render in progress finishes and its output
    // is written whole (or not at all) before the process ends.
    if let Err(e) = ctrlc::set_handler(move || {
        let _ = stop.send(Wake::Stop);
    }) {
        let _ = writeln!(std::io::stderr(), "warning: Ctrl-C will stop watch abruptly: {e}");
    }
    let watcher = notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
        if let Ok(event) = event {
            if !event.kind.is_access() {
                let _ = tx.send(Wake::Changed(event.paths));
            }
        }
    });
    let mut watcher = match watcher {
        Ok(w) => w,
        Err(e) => return usage_error(&format!("cannot watch files: {e}")),
    };
    let mut watched_dirs: Vec<PathBuf> = Vec::new();
    loop {
        let attempt = render_once(&args, &pool);
        if attempt.result.is_err() {
            let _ = writeln!(
                std::io::stderr(),
                "not rendered; `{}` keeps the last good image. Watching for changes…",
                args.output.display()
            );
        }
        // Editors save by replacing files, which ends a watch on the file itself, so
        // the directories are watched and events filtered by path.
        let files: Vec<PathBuf> = attempt.files.iter().filter_map(|f| std::path::absolute(f).ok()).collect();
        let mut dirs: Vec<PathBuf> = files.iter().filter_map(|f| f.parent().map(Path::to_path_buf)).collect();
        dirs.sort();
        dirs.dedup();
        for dir in watched_dirs.iter().filter(|d| !dirs.contains(d)) {
            let _ = watcher.unwatch(dir);
        }
        for dir in dirs.iter().filter(|d| !watched_dirs.contains(d)) {
            if let Err(e) = watcher.watch(dir, notify::RecursiveMode::NonRecursive) {
                let _ = writeln!(std::io::stderr(), "warning: cannot watch `{}`: {e}", dir.display());
            }
        }
        watched_dirs = dirs;
        // Wait for a change to one of the files, then for the burst of events to end.
        loop {
            match rx.recv() {
                Ok(Wake::Changed(paths)) if paths.iter().any(|p| files.contains(p)) => break,
                Ok(Wake::Changed(_)) => {}
                Ok(Wake::Stop) | Err(_) => return ExitCode::SUCCESS,
            }
        }
        loop {
            match rx.recv_timeout(DEBOUNCE) {
                Ok(Wake::Changed(_)) => {}
                Ok(Wake::Stop) | Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => return ExitCode::SUCCESS,
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => break,
            }
        }
    }
}
