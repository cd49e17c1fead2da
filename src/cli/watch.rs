//! `scnc watch`: render, then render again whenever the scene or a file it includes
//! changes.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::render::{render_once, RenderArgs};
use super::usage_error;

/// How long `watch` waits for more changes before rendering, so one save (often
/// several file-system events) renders once.
const DEBOUNCE: std::time::Duration = std::time::Duration::from_millis(150);

pub(crate) fn watch_cmd(mut args: RenderArgs) -> ExitCode {
    use notify::Watcher as _;
    args.whole_revisions = true;
    if args.skip_existing {
        // Every frame exists after the first render, so every later one would skip them
        // all and the images would never follow the edits.
        return usage_error(
            "`watch` renders every frame again on each change; `--skip-existing` would keep the old frames: leave it out",
        );
    }
    // Ctrl-C is how a watch ends: at once, even mid-render, with the last image whole
    // and no temporary file left.
    let pool = match args.checked_pool(0) {
        Ok(p) => p,
        Err(code) => return code,
    };
    // The paths each file-system event names.
    let (tx, rx) = std::sync::mpsc::channel::<Vec<PathBuf>>();
    let watcher = notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
        if let Ok(event) = event {
            if !event.kind.is_access() {
                let _ = tx.send(event.paths);
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
                Ok(paths) if paths.iter().any(|p| files.contains(p)) => break,
                Ok(_) => {}
                Err(_) => return ExitCode::SUCCESS,
            }
        }
        loop {
            match rx.recv_timeout(DEBOUNCE) {
                Ok(_) => {}
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => return ExitCode::SUCCESS,
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => break,
            }
        }
    }
}
