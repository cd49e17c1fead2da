//! `scnc sweep`: the accuracy ladder written as CSV, Markdown and charts.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use scnc::source::FsLoader;
use scnc::study::sweep::{Options, PeakMemory, Step};
use scnc::study::{chart, report as table, sweep};

use super::files::{cannot_write, write_png, write_text};
use super::shared::{Accuracy, Messages, Params};
use super::{compile, report, usage_error};

#[derive(clap::Args)]
pub(crate) struct SweepArgs {
    /// The scene file.
    file: PathBuf,
    /// Directory for sweep.csv, sweep.md and the charts (created if missing).
    #[arg(short, long, alias = "out")]
    output: PathBuf,
    /// Image width for the sweep (default: the scene's own).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    width: Option<u32>,
    /// Image height for the sweep (default: the scene's own).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    height: Option<u32>,
    /// The fewest timed renders per setting (after one warm-up); more are made until the
    /// median's 95 % interval is within 2 % of it, or `--time-cap` is reached.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u16).range(1..=100))]
    runs: u16,
    /// Seconds one setting may be timed for before its median is taken as it is.
    #[arg(long, default_value_t = 3.0, value_parser = parse_cap)]
    time_cap: f64,
    /// Two settings per back-end instead of the full ladder.
    #[arg(long, conflicts_with = "tolerance")]
    quick: bool,
    #[command(flatten)]
    accuracy: Accuracy,
    /// Under light transport: the most samples a pixel of the samples ladder (1, 4, 16,
    /// … up to this); the reference is 16 times as many unless `--reference` gives one.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=65536))]
    most_samples: u32,
    /// Under light transport: an OpenEXR image of the scene (linear float, the sweep's
    /// size) to measure the ladder against instead of rendering a reference.
    #[arg(long, value_name = "EXR")]
    reference: Option<PathBuf>,
    #[command(flatten)]
    messages: Messages,
    #[command(flatten)]
    params: Params,
}

/// `scnc sweep`. Long because it is the sweep's one sequence: compile, pick the ladder,
/// render and measure each rung, write the chart and the table.
pub(crate) fn sweep_cmd(args: SweepArgs) -> ExitCode {
    if let Err(e) = std::fs::create_dir_all(&args.output) {
        return usage_error(&format!("cannot create `{}`: {e}", args.output.display()));
    }
    let Some(compiled) = compile(&args.file, args.messages.message_format, &args.params) else {
        return ExitCode::from(1);
    };
    if report(&compiled, args.messages.message_format) {
        return ExitCode::from(1);
    }
    let Some(mut scene) = compiled.scene else { return ExitCode::from(1) };
    scene.settings.width = args.width.unwrap_or(scene.settings.width);
    scene.settings.height = args.height.unwrap_or(scene.settings.height);
    let (width, height) = (scene.settings.width, scene.settings.height);
    if scnc::render::effects::derive(&scene).light_transport.is_some() {
        return samples_sweep(&args, &scene, &compiled.map);
    }
    if args.reference.is_some() {
        return usage_error("`--reference` is for a scene lit by light transport, whose sweep is a ladder of samples");
    }
    let ladder = match args.accuracy.tolerance {
        Some(tol) => sweep::picked(&scene, tol),
        None => sweep::ladder(args.quick),
    };
    // A bar on a terminal; elsewhere (CI, a pipe) one line per step, so a long sweep is
    // never silent.
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(ladder.len() as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} settings, {msg} ({elapsed})") {
            bar.set_style(style);
        }
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        bar
    });
    let started = std::time::Instant::now();
    let progress = |step: Step<'_>| {
        let what = match step {
            Step::Reference(s) => format!("the reference render ({} {})", s.backend(), s.label()),
            Step::Measured { setting, done, total } => {
                format!("measured {done}/{total}: {} {}", setting.backend(), setting.label())
            }
            Step::Timing { round, open } => format!("timing round {round}: {open} settings"),
        };
        match &bar {
            Some(bar) => {
                if let Step::Measured { done, .. } = step {
                    bar.set_position(done as u64);
                }
                bar.set_message(what);
            }
            None => {
                let _ = writeln!(std::io::stderr(), "sweep: {what} ({:.1} s)", started.elapsed().as_secs_f64());
            }
        }
    };
    let opts = Options {
        min_runs: args.runs as usize,
        cap: args.time_cap,
        cpu_seconds: &cpu_seconds,
        loader: &FsLoader,
        memory: &ProcPeakMemory,
        progress: &progress,
    };
    let rows = match sweep::run(&scene, &ladder, &opts) {
        Ok(rows) => rows,
        Err(d) => {
            super::report_in(&compiled.map, &[d], args.messages.message_format);
            return ExitCode::from(1);
        }
    };
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    // The file's name, not its path: a chart is read beside others of its kind.
    let name = args.file.file_name().map_or_else(|| args.file.display().to_string(), |n| n.to_string_lossy().into());
    let title = format!("{name} at {width}×{height}");
    for (name, text) in [("sweep.csv", table::csv(&rows)), ("sweep.md", table::markdown(&rows, &title))] {
        let path = args.output.join(name);
        if let Err(e) = write_text(&path, &text) {
            let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(&path, &e));
            return ExitCode::from(1);
        }
    }
    let charts = [
        ("time-vs-error.png", chart::Axis::Time),
        ("work-vs-error.png", chart::Axis::Work),
        ("memory-vs-error.png", chart::Axis::Memory),
    ];
    for (name, axis) in charts {
        let path = args.output.join(name);
        let written = chart::error_chart(&rows, axis, &title)
            .map_err(std::io::Error::other)
            .and_then(|img| write_png(&path, &img, &[]));
        if let Err(e) = written {
            let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(&path, &e));
            return ExitCode::from(1);
        }
    }
    let _ = writeln!(std::io::stderr(), "swept {} settings: {}", rows.len(), args.output.join("sweep.md").display());
    ExitCode::SUCCESS
}

/// `scnc sweep` of a scene lit by light transport: the samples ladder, its table and its
/// chart of time against error.
fn samples_sweep(args: &SweepArgs, scene: &scnc::ir::Scene, map: &scnc::source::SourceMap) -> ExitCode {
    let (width, height) = (scene.settings.width, scene.settings.height);
    let reference = match &args.reference {
        None => None,
        Some(path) => match read_reference(path, width, height) {
            Ok(r) => Some(r),
            Err(e) => {
                let _ = writeln!(std::io::stderr(), "error: {e}");
                return ExitCode::from(1);
            }
        },
    };
    let started = std::time::Instant::now();
    let progress = |what: &str| {
        let _ = writeln!(std::io::stderr(), "sweep: {what} ({:.1} s)", started.elapsed().as_secs_f64());
    };
    let rungs = scnc::study::samples::ladder(args.most_samples);
    let rows = match scnc::study::samples::run(scene, &rungs, reference, &FsLoader, &progress) {
        Ok(rows) => rows,
        Err(d) => {
            super::report_in(map, &[d], args.messages.message_format);
            return ExitCode::from(1);
        }
    };
    let name = args.file.file_name().map_or_else(|| args.file.display().to_string(), |n| n.to_string_lossy().into());
    let title = format!("{name} at {width}×{height}");
    let text = [
        ("samples.csv", scnc::study::samples::csv(&rows)),
        ("samples.md", scnc::study::samples::markdown(&rows, &title)),
    ];
    for (file, body) in text {
        let path = args.output.join(file);
        if let Err(e) = write_text(&path, &body) {
            let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(&path, &e));
            return ExitCode::from(1);
        }
    }
    let path = args.output.join("time-vs-error.png");
    let written = scnc::study::samples::chart(&rows, &title)
        .map_err(std::io::Error::other)
        .and_then(|img| write_png(&path, &img, &[]));
    if let Err(e) = written {
        let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(&path, &e));
        return ExitCode::from(1);
    }
    let _ =
        writeln!(std::io::stderr(), "swept {} sample counts: {}", rows.len(), args.output.join("samples.md").display());
    ExitCode::SUCCESS
}

/// A reference image: an OpenEXR file of `width × height`, as linear float RGB.
fn read_reference(path: &Path, width: u32, height: u32) -> Result<Vec<f32>, String> {
    let cannot = |e: &dyn std::fmt::Display| format!("cannot read the reference `{}`: {e}", path.display());
    let bytes = std::fs::read(path).map_err(|e| cannot(&e))?;
    let (w, h, rgb) = super::exr::decode(&bytes, scnc::check::MAX_PIXELS).map_err(|e| cannot(&e))?;
    if (w, h) != (width, height) {
        return Err(format!("the reference `{}` is {w}×{h}, the sweep renders {width}×{height}", path.display()));
    }
    Ok(rgb)
}

/// A time cap from 0.01 to 3600 seconds.
fn parse_cap(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if (0.01..=3600.0).contains(&x) => Ok(x),
        _ => Err("must be a number of seconds from 0.01 to 3600".into()),
    }
}

/// The CPU time the process has used (user and system, all threads), from Linux's
/// procfs (`None` elsewhere): fields 14 and 15 of `/proc/self/stat`, in clock ticks of
/// 1/100 s (the kernel's USER_HZ on every Linux port).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The command name may hold spaces; the fields after it are counted from its ')'.
    let rest = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<f64>().ok();
    // After the name: state is field 3, so utime (14) and stime (15) are at 11 and 12.
    Some((ticks(11)? + ticks(12)?) / 100.0)
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
