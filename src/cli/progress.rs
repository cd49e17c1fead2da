//! Progress bars for work that may take a while: hidden for the first second (a quick
//! render or mesh build prints nothing), then drawn on stderr and redrawn on their own
//! even while no step finishes (one large mesh can take many seconds), and only when
//! stderr is a terminal.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

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
            std::thread::spawn(move || {
                std::thread::sleep(QUIET);
                if !done.load(Ordering::Acquire) {
                    shown.set_draw_target(indicatif::ProgressDrawTarget::stderr());
                    shown.enable_steady_tick(Duration::from_millis(120));
                }
            });
            bar
        });
        Progress { bar, done }
    }

    /// One step done.
    pub(crate) fn step(&self) {
        if let Some(bar) = &self.bar {
            bar.inc(1);
        }
    }

    /// All done: the bar, if it was drawn, is cleared.
    pub(crate) fn finish(&self) {
        self.done.store(true, Ordering::Release);
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}
