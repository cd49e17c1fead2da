//! `scnc sweep`: the accuracy ladder written as CSV, Markdown and charts.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use scnc::source::FsLoader;
use scnc::study::sweep::{Options, PeakMemory, Setting};
use scnc::study::tolerance::Tolerance;
use scnc::study::{chart, report as table, sweep};

use super::files::{cannot_write, write_png, write_text};
use super::{compile, report, usage_error, MessageFormat};

#[derive(clap::Args)]
pub(crate) struct SweepArgs {
    /// The scene file.
    file: PathBuf,
    /// Directory for sweep.csv, sweep.md and the charts (created if missing).
    #[arg(short, long, alias = "out")]
    output: PathBuf,
    /// Image width for the sweep.
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..=4096))]
    width: u32,
    /// Image height for the sweep.
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..=4096))]
    height: u32,
    /// Timed renders per setting (after one warm-up); the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u16).range(1..=100))]
    runs: u16,
    /// Two settings per back-end instead of the full ladder.
    #[arg(long)]
    quick: bool,
    /// Sweep only the settings `render --tolerance` would pick (world units or `pixel`),
    /// to check that they hold.
    #[arg(long, conflicts_with = "quick")]
    tolerance: Option<Tolerance>,
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value = "human")]
    message_format: MessageFormat,
}

pub(crate) fn sweep_cmd(args: SweepArgs) -> ExitCode {
    if let Err(e) = std::fs::create_dir_all(&args.output) {
        return usage_error(&format!("cannot create `{}`: {e}", args.output.display()));
    }
    let Some(compiled) = compile(&args.file, args.message_format) else { return ExitCode::from(1) };
    if report(&compiled, args.message_format) {
        return ExitCode::from(1);
    }
    let Some(mut scene) = compiled.scene else { return ExitCode::from(1) };
    scene.settings.width = args.width;
    scene.settings.height = args.height;
    let ladder = match args.tolerance {
        Some(tol) => sweep::picked(&scene, tol),
        None => sweep::ladder(args.quick),
    };
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(ladder.len() as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} settings, {msg}") {
            bar.set_style(style);
        }
        bar
    });
    let progress = |s: &Setting| {
        if let Some(bar) = &bar {
            bar.set_message(format!("{} {}", s.backend(), s.label()));
            bar.inc(1);
        }
    };
    let opts = Options { runs: args.runs as usize, loader: &FsLoader, memory: &ProcPeakMemory, progress: &progress };
    let rows = match sweep::run(&scene, &ladder, &opts) {
        Ok(rows) => rows,
        Err(d) => {
            super::report_in(&compiled.map, &[d], args.message_format);
            return ExitCode::from(1);
        }
    };
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let title = format!("{} at {}×{}", args.file.display(), args.width, args.height);
    for (name, text) in [("sweep.csv", table::csv(&rows)), ("sweep.md", table::markdown(&rows, &title))] {
        let path = args.output.join(name);
        if let Err(e) = write_text(&path, &text) {
            let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(&path, &e));
            return ExitCode::from(1);
        }
    }
    for (name, axis) in [("time-vs-error.png", chart::Axis::Time), ("memory-vs-error.png", chart::Axis::Memory)] {
        let path = args.output.join(name);
        let written = chart::error_chart(&rows, axis, &title)
            .map_err(std::io::Error::other)
            .and_then(|img| write_png(&path, &img));
        if let Err(e) = written {
            let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(&path, &e));
            return ExitCode::from(1);
        }
    }
    let _ = writeln!(std::io::stderr(), "swept {} settings: {}", rows.len(), args.output.join("sweep.md").display());
    ExitCode::SUCCESS
}

/// The process's peak resident memory, from Linux's procfs (`None` elsewhere).
struct ProcPeakMemory;

impl PeakMemory for ProcPeakMemory {
    /// Resets the peak resident set size (Linux ≥ 4.0); a no-op elsewhere.
    fn reset(&self) {
        // Writing 5 to clear_refs resets VmHWM to the current RSS. Failure only means the
        // column is the peak since an earlier point, which `peak_kib` cannot tell; on
        // systems without procfs both calls do nothing.
        let _ = std::fs::write("/proc/self/clear_refs", "5");
    }

    /// The peak resident set size in KiB, from /proc/self/status.
    fn peak_kib(&self) -> Option<u64> {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        line.split_whitespace().nth(1)?.parse().ok()
    }
}
