//! The `scnc` command line: the only code that reads arguments, prints, or exits.
//!
//! - `render` and `watch`: compile, lower and render to a PNG, once or on every change.
//! - `sweep`: the accuracy ladder, with the process's own peak memory.
//! - `stats`: what `render --stats` prints.
//! - `files`: output written whole or not at all.
//! - `fmt`: `scnc fmt`.
//! - `export`: the scene as a mesh file.
//! - `studio`: the web page that edits a scene and renders it as you type.

mod encode;
mod export;
mod exr;
mod files;
mod fmt;
mod frames;
mod measure;
mod merge;
mod passes;
mod progress;
mod render;
mod shared;
mod stats;
mod studio;
mod sweep;
mod watch;

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use scnc::diag::Diagnostic;
use scnc::source::{FsLoader, Loader};
use scnc::Compiled;

use render::RenderArgs;
use sweep::SweepArgs;

#[derive(Parser)]
#[command(name = "scnc", version, about = "Compile and render .scn scene files")]
pub(crate) struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum MessageFormat {
    /// Rendered for people, with source excerpts.
    Human,
    /// One JSON object per line, for editors and tests.
    Json,
}

#[derive(Subcommand)]
enum Command {
    /// Check files for errors without rendering (exit 0 clean, 1 on errors).
    Check {
        /// The scene files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        #[command(flatten)]
        messages: shared::Messages,
        #[command(flatten)]
        params: shared::Params,
        /// Print nothing on success (no summary line).
        #[arg(long, short)]
        quiet: bool,
    },
    /// Render a scene to an image (written whole or not at all).
    Render(RenderArgs),
    /// Render, then render again whenever the scene or a file it includes changes;
    /// on errors, print them and keep the last good image. Ctrl-C ends it.
    Watch(RenderArgs),
    /// Assemble parts rendered with `render --region` or `--tile` into one image; fails,
    /// writing nothing, on parts of different sizes, overlapping parts or a gap.
    Merge(merge::MergeArgs),
    /// Encode rendered frames (`out/frame-####.png`) as one animation: GIF, APNG
    /// (`.png`) or MP4 (through `ffmpeg`, when it is on PATH); written whole or not at all.
    Encode(encode::EncodeArgs),
    /// Write the scene's objects as a mesh file (STL, OBJ, PLY, 3MF or glb), meshed as
    /// `render --geometry mesh` meshes them (written whole or not at all).
    Export(export::ExportArgs),
    /// Measure each object: volume, centre of mass, bounding box and inertia as intervals
    /// proved from its distance bound, beside its mesh's figures and surface area.
    Measure(measure::MeasureArgs),
    /// Render a scene across a ladder of accuracy settings for both back-ends and write
    /// time, work, memory and error for each to DIR/sweep.csv and DIR/sweep.md.
    Sweep(SweepArgs),
    /// Run a Language Server Protocol server on stdin/stdout, for editors.
    Lsp,
    /// Edit a scene in the browser and watch it render as you type: a local web server
    /// (127.0.0.1 unless `--host` says otherwise) serving one page for one file.
    Studio(studio::StudioArgs),
    /// Format files in place in the canonical layout (comments and blank lines kept).
    Fmt {
        /// The scene files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Change nothing; list the files that would change and exit 1 if there are any.
        #[arg(long)]
        check: bool,
        /// Print nothing but errors (no summary line).
        #[arg(long, short)]
        quiet: bool,
    },
    /// Print the scene's parameters (its `param`s) as JSON: name, type, default, the
    /// value `-D` or `--set-name` gives, range, step, choices, description and group.
    Params {
        /// The scene file.
        file: PathBuf,
        #[command(flatten)]
        messages: shared::Messages,
        #[command(flatten)]
        params: shared::Params,
    },
    /// Print the evaluated scene IR.
    Ir {
        /// The scene file.
        file: PathBuf,
        /// The frame of the scene's animation to evaluate (default 0).
        #[arg(long, default_value = "0")]
        frame: u32,
        #[command(flatten)]
        messages: shared::Messages,
        #[command(flatten)]
        params: shared::Params,
    },
}

/// Reads and compiles a file, its parameters set by `params`. A file that cannot be read
/// has no source to point into, nor has a parameter-set file that cannot be read: either
/// is reported here, in the requested format, and `None` returned (exit 1).
pub(crate) fn compile(path: &Path, format: MessageFormat, params: &shared::Params) -> Option<Compiled> {
    let name = path.display().to_string();
    let overrides = match params.overrides() {
        Ok(o) => o,
        Err(message) => {
            let file = params.sets.as_deref().map_or(name.clone(), |p| p.display().to_string());
            file_error(&file, scnc::diag::codes::BAD_PARAM_VALUE, &message, "the parameter sets", format);
            return None;
        }
    };
    match FsLoader.read(path) {
        Ok(text) => Some(scnc::compile_file_with(&name, path, text, &FsLoader, overrides)),
        Err(e) => {
            let message = format!("cannot read `{name}`: {}", scnc::source::io_reason(&e));
            file_error(&name, scnc::diag::codes::INCLUDE_READ, &message, "cannot be read", format);
            None
        }
    }
}

/// Warnings about how a scene renders (lights, the camera's view, a field's marching
/// cost), which commands that do not render (export, measure, params) leave out.
const RENDER_ONLY: [&str; 5] = [
    scnc::diag::codes::NO_LIGHTS,
    scnc::diag::codes::USELESS_LIGHT,
    scnc::diag::codes::BEHIND_CAMERA,
    scnc::diag::codes::NO_EFFECT,
    scnc::diag::codes::STEEP_FIELD,
];

/// Drops the warnings only a render needs from `compiled`.
pub(crate) fn drop_render_only(compiled: &mut Compiled) {
    compiled.diagnostics.retain(|d| d.is_error() || !RENDER_ONLY.contains(&d.code));
}

/// Prints an error about a whole file (one that could not be read), blamed on a
/// zero-length span at its start.
fn file_error(name: &str, code: &str, message: &str, label: &str, format: MessageFormat) {
    match format {
        MessageFormat::Human => {
            let _ = writeln!(std::io::stderr(), "error[{code}]: {message}");
        }
        // The documented fields of every diagnostic. Machine output goes to stdout, as
        // cargo's and rustc's does.
        MessageFormat::Json => {
            let line = serde_json::json!({
                "severity": "error", "code": code, "message": message,
                "span": {
                    "file": name, "byte_start": 0, "byte_end": 0, "line_start": 1, "column_start": 1,
                    "line_end": 1, "column_end": 1, "label": label,
                },
                "related": [], "notes": [], "hints": [], "fixes": [],
            });
            let _ = writeln!(std::io::stdout(), "{line}");
        }
    }
}

/// Prints diagnostics (to stderr for people, as JSON lines to stdout for tools); returns
/// whether any was an error.
pub(crate) fn report(c: &Compiled, format: MessageFormat) -> bool {
    report_in(&c.map, &c.diagnostics, format)
}

/// Prints diagnostics about the files of `map` (lowering's warnings come after the
/// checker's): rendered to stderr for people, at most [`SHOWN`] of them and then how many
/// more; or every one as a JSON line to stdout for tools, as cargo's and rustc's machine
/// output goes. Returns whether any was an error.
pub(crate) fn report_in(map: &scnc::source::SourceMap, diagnostics: &[Diagnostic], format: MessageFormat) -> bool {
    match format {
        MessageFormat::Human => {
            let color = std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none();
            let mut err = std::io::stderr().lock();
            let mut sources = scnc::diag::Sources::new(map);
            for d in diagnostics.iter().take(SHOWN) {
                let _ = err.write_all(d.render_with(&mut sources, color).as_bytes());
            }
            if let Some(more) = diagnostics.len().checked_sub(SHOWN).filter(|&n| n > 0) {
                let errors = diagnostics[SHOWN..].iter().filter(|d| d.is_error()).count();
                let _ = writeln!(
                    err,
                    "… and {more} more diagnostic{} ({errors} error{}); `--message-format json` lists every one",
                    if more == 1 { "" } else { "s" },
                    if errors == 1 { "" } else { "s" }
                );
            }
        }
        MessageFormat::Json => {
            let mut out = std::io::stdout().lock();
            for d in diagnostics {
                let _ = writeln!(out, "{}", d.to_json(map));
            }
        }
    }
    diagnostics.iter().any(Diagnostic::is_error)
}

/// Most diagnostics printed for people: past a screenful the rest are one mistake
/// repeated, or a file that is not a scene at all.
const SHOWN: usize = 50;

/// A usage problem found after argument parsing: printed like clap's, exit 2.
pub(crate) fn usage_error(msg: &str) -> ExitCode {
    let _ = writeln!(std::io::stderr(), "error: {msg}");
    ExitCode::from(2)
}

pub(crate) fn worker_pool(threads: Option<u16>) -> Result<rayon::ThreadPool, String> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        pool = pool.num_threads(n as usize);
    }
    pool.build().map_err(|e| format!("cannot start worker threads: {e}"))
}

/// Runs the command. Long because it is one match over the commands.
fn run(cli: Cli) -> ExitCode {
    match cli.command {
        Command::Render(args) => render::render_cmd(args),
        Command::Watch(args) => watch::watch_cmd(args),
        Command::Sweep(args) => sweep::sweep_cmd(args),
        Command::Measure(args) => measure::measure_cmd(args),
        Command::Export(args) => export::export_cmd(args),
        Command::Studio(args) => studio::studio_cmd(args),
        Command::Merge(args) => merge::merge_cmd(args),
        Command::Encode(args) => encode::encode_cmd(args),
        Command::Fmt { files, check, quiet } => fmt::fmt_cmd(&files, check, quiet),
        Command::Lsp => match scnc::lsp::run_stdio(|why| {
            let _ = writeln!(std::io::stderr(), "scnc lsp: {why}");
        }) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                let _ = writeln!(std::io::stderr(), "error: the language server stopped: {e}");
                ExitCode::from(1)
            }
        },
        Command::Check { files, messages: shared::Messages { message_format }, params, quiet } => {
            let mut failed = false;
            let (mut objects, mut lights, mut warnings) = (0, 0, 0);
            for file in &files {
                match compile(file, message_format, &params) {
                    Some(c) => {
                        failed |= report(&c, message_format);
                        warnings += c.diagnostics.iter().filter(|d| !d.is_error()).count();
                        if let Some(scene) = &c.scene {
                            objects += scene.objects.len();
                            lights += scene.lights.len();
                        }
                    }
                    None => failed = true,
                }
            }
            if failed {
                return ExitCode::from(1);
            }
            // One line on success, as cargo says `Finished`: silence reads as "did it run?".
            if !quiet && message_format == MessageFormat::Human {
                let files = if files.len() > 1 { format!("{} files, ", files.len()) } else { String::new() };
                let _ = writeln!(
                    std::io::stderr(),
                    "ok: {files}{}, {}, {}",
                    plural(objects, "object"),
                    plural(lights, "light"),
                    plural(warnings, "warning")
                );
            }
            ExitCode::SUCCESS
        }
        Command::Params { file, messages: shared::Messages { message_format }, params } => {
            let Some(mut compiled) = compile(&file, message_format, &params) else { return ExitCode::from(1) };
            drop_render_only(&mut compiled);
            if report(&compiled, message_format) {
                return ExitCode::from(1);
            }
            let listed = compiled.scene.as_ref().map_or_else(Vec::new, |s| s.params.iter().map(param_json).collect());
            let text = serde_json::to_string_pretty(&serde_json::json!({ "parameters": listed })).unwrap_or_default();
            let _ = writeln!(std::io::stdout().lock(), "{text}");
            ExitCode::SUCCESS
        }
        Command::Ir { file, frame, messages: shared::Messages { message_format }, params } => {
            let Some(mut compiled) = compile(&file, message_format, &params) else { return ExitCode::from(1) };
            // Frame 0's diagnostics, unless another frame is asked for and frame 0 has no
            // errors: then that frame's own (its warnings include frame 0's that still hold).
            let later = compiled.scene.as_ref().map(|s| s.settings.clone()).filter(|_| frame > 0);
            if later.is_none() && report(&compiled, message_format) {
                return ExitCode::from(1);
            }
            if let Some(declared) = later {
                if frame >= declared.frames {
                    return usage_error(&format!(
                        "--frame {frame}: the scene's animation has frames 0..{}",
                        declared.frames
                    ));
                }
                let (scene, diagnostics) = scnc::with_big_stack(|| compiled.frame(frame, &declared, &FsLoader))
                    .unwrap_or_else(|e| (None, vec![e.diagnostic()]));
                if report_in(&compiled.map, &diagnostics, message_format) {
                    return ExitCode::from(1);
                }
                compiled.scene = scene;
            }
            if let Some(scene) = &compiled.scene {
                let text =
                    format!("{}{}\n", scnc::ir::dump(scene, &compiled.map), scnc::render::effects::derive(scene));
                let _ = std::io::stdout().lock().write_all(text.as_bytes());
            }
            ExitCode::SUCCESS
        }
    }
}

/// One parameter as `scnc params` lists it (null where the scene says nothing).
pub(crate) fn param_json(p: &scnc::ir::SceneParam) -> serde_json::Value {
    let choices: Option<Vec<_>> = (!p.choices.is_empty()).then(|| p.choices.iter().map(|c| c.to_json()).collect());
    serde_json::json!({
        "name": p.name,
        "type": p.default.ty(),
        "default": p.default.to_json(),
        "value": p.value.to_json(),
        "range": p.range.map(|(lo, hi)| [lo, hi]),
        "step": p.step,
        "choices": choices,
        "description": p.description,
        "group": p.group,
    })
}

/// `n thing` or `n things`.
pub(crate) fn plural(n: usize, thing: &str) -> String {
    format!("{n} {thing}{}", if n == 1 { "" } else { "s" })
}

/// Parses the arguments and runs the command.
pub fn main() -> ExitCode {
    run(Cli::parse())
}
