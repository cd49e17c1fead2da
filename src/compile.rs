//! The compile driver: a file's text to its scene and diagnostics, on a thread with the
//! stack deep expressions need; an animation's later frames from the same parses.

use std::path::Path;

use crate::diag::Diagnostic;
use crate::source::{self, Loader, SourceMap};
use crate::{check, diag, ir, span};

/// The result of compiling one file: its sources (for rendering diagnostics), the
/// scene if it compiled, and every diagnostic.
#[derive(Debug)]
pub struct Compiled {
    /// All files read.
    pub map: SourceMap,
    /// The scene; `None` when there were errors.
    pub scene: Option<ir::Scene>,
    /// Errors and warnings, in source order.
    pub diagnostics: Vec<Diagnostic>,
    /// The root file, when it could be read into `map`.
    root: Option<source::FileId>,
    /// The files and parses later evaluations ([`Compiled::at`]) reuse.
    reuse: check::Reuse,
    /// The parameters' values given from outside, for every evaluation.
    overrides: check::Overrides,
}

impl Compiled {
    /// The scene evaluated again at `time`, a frame of its animation: files are not read
    /// again nor parsed again (includes a later frame reaches for the first time are), and
    /// spans point into `map`. Returns the scene, or `None`, and that frame's diagnostics.
    pub fn at(&mut self, time: check::Time, loader: &dyn Loader) -> (Option<ir::Scene>, Vec<Diagnostic>) {
        match self.root {
            Some(root) => check::check_at(&mut self.map, root, loader, time, &mut self.reuse, &self.overrides),
            None => (None, self.diagnostics.clone()),
        }
    }

    /// Frame `number` of the animation frame 0 declared (`declared`, its settings): the
    /// scene at that frame's [`check::Time`], or `None` with an error when it has errors
    /// or its frame count, rate or looping differ from frame 0's.
    pub fn frame(
        &mut self,
        number: u32,
        declared: &ir::Settings,
        loader: &dyn Loader,
    ) -> (Option<ir::Scene>, Vec<Diagnostic>) {
        let (mut scene, mut diagnostics) = self.at(check::Time::of(number, declared), loader);
        if let Some(s) = scene.as_ref().map(|s| &s.settings) {
            if (s.frames, s.fps, s.cyclic) != (declared.frames, declared.fps, declared.cyclic) {
                let timing = |s: &ir::Settings| {
                    let looping = if s.cyclic { ", looping" } else { "" };
                    format!("{} frames at {} fps{looping}", s.frames, ir::dump_num(s.fps))
                };
                diagnostics.push(
                    Diagnostic::error(
                        diag::codes::ANIMATION_CHANGES,
                        s.span.unwrap_or_default(),
                        "the animation changes from frame to frame",
                        format!("at frame {number}: {}", timing(s)),
                    )
                    .with_note(format!("at frame 0: {}", timing(declared)))
                    .with_note("`frames`, `fps` and `cyclic` must not depend on `clock` or `frame`"),
                );
                scene = None;
            }
        }
        (scene, diagnostics)
    }
}

/// Compiles scene text named `name` (whose includes resolve relative to `path`). Text
/// over [`source::MAX_FILE_BYTES`] is refused whatever it came from (a file, or an
/// editor's open document).
pub fn compile_source(name: &str, path: &Path, text: String, loader: &dyn Loader) -> Compiled {
    compile_source_with(name, path, text, loader, check::Overrides::default())
}

/// [`compile_source`] with the scene's parameters set by `overrides`.
pub fn compile_source_with(
    name: &str,
    path: &Path,
    text: String,
    loader: &dyn Loader,
    overrides: check::Overrides,
) -> Compiled {
    let mut map = SourceMap::new();
    let bytes = text.len();
    let root = if bytes > source::MAX_FILE_BYTES { None } else { map.add(name, path, text) };
    let Some(root) = root else {
        let mut map = SourceMap::new();
        let _ = map.add(name, path, String::new());
        let d = Diagnostic::error(
            diag::codes::TOO_LARGE,
            span::Span::default(),
            format!("`{name}` is too large"),
            format!("the file has {bytes} bytes"),
        )
        .with_note(format!("a source file may have at most {} MiB", source::MAX_FILE_BYTES >> 20));
        return Compiled {
            map,
            scene: None,
            diagnostics: vec![d],
            root: None,
            reuse: check::Reuse::default(),
            overrides,
        };
    };
    let mut reuse = check::Reuse::default();
    let (scene, diagnostics) = check::check_at(&mut map, root, loader, check::Time::STILL, &mut reuse, &overrides);
    Compiled { map, scene, diagnostics, root: Some(root), reuse, overrides }
}

/// The stack of the thread compiles run on: deep enough for every nesting the limits in
/// [`check`] and [`syntax`](crate::syntax) allow.
pub const COMPILER_STACK: usize = 256 << 20;

/// The operating system refused the compiler's thread (most often an address space
/// capped below its stack, `ulimit -v`): a coded error, never a panic.
#[derive(Debug)]
pub struct NoThread(pub std::io::Error);

impl std::fmt::Display for NoThread {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "cannot start the compiler's thread with its {} MiB stack: {} (is the address space capped, as by `ulimit -v`?)",
            COMPILER_STACK >> 20,
            source::io_reason(&self.0)
        )
    }
}

impl NoThread {
    /// The error as a diagnostic at the start of the file (E0709).
    pub fn diagnostic(&self) -> Diagnostic {
        Diagnostic::error(diag::codes::NO_RESOURCES, span::Span::default(), self.to_string(), "not compiled")
            .with_note("the compiler runs on a thread of its own so that deep nesting cannot overflow the stack")
    }

    /// The file `text` (named `name`, at `path`) and this error in it, to report.
    pub fn in_file(&self, name: &str, path: &Path, text: String) -> (SourceMap, Diagnostic) {
        let mut map = SourceMap::new();
        let _ = map.add(name, path, text);
        (map, self.diagnostic())
    }
}

/// Runs `f` on `text` on a thread with [`COMPILER_STACK`]; when the thread cannot be
/// had, the error with the text back (for the error's excerpt), never copied.
pub fn with_big_stack_on<T: Send>(text: String, f: impl FnOnce(String) -> T + Send) -> Result<T, (NoThread, String)> {
    // The text waits in a slot the thread takes it from, so a thread that never starts
    // leaves it there.
    let slot = std::sync::Mutex::new(Some(text));
    let take = || slot.lock().ok().and_then(|mut t| t.take()).unwrap_or_default();
    with_big_stack(|| f(take())).map_err(|e| (e, take()))
}

/// Runs `f` on a thread with a large stack, so that pathological nesting in user input
/// (bounded by the limits in [`check`] and [`syntax`](crate::syntax)) cannot overflow the stack; an
/// error when the thread cannot be had.
pub fn with_big_stack<T: Send>(f: impl FnOnce() -> T + Send) -> Result<T, NoThread> {
    std::thread::scope(|s| {
        let thread = std::thread::Builder::new().stack_size(COMPILER_STACK).spawn_scoped(s, f).map_err(NoThread)?;
        Ok(thread.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
    })
}

/// [`compile_source`] on a thread of [`COMPILER_STACK`]; when the thread cannot be had,
/// the file with that error (E0709) and no scene.
pub fn compile_file(name: &str, path: &Path, text: String, loader: &(dyn Loader + Sync)) -> Compiled {
    compile_file_with(name, path, text, loader, check::Overrides::default())
}

/// [`compile_file`] with the scene's parameters set by `overrides`.
pub fn compile_file_with(
    name: &str,
    path: &Path,
    text: String,
    loader: &(dyn Loader + Sync),
    overrides: check::Overrides,
) -> Compiled {
    let kept = overrides.clone();
    with_big_stack_on(text, |text| compile_source_with(name, path, text, loader, overrides)).unwrap_or_else(
        |(e, text)| {
            let (map, d) = e.in_file(name, path, text);
            let reuse = check::Reuse::default();
            Compiled { map, scene: None, diagnostics: vec![d], root: None, reuse, overrides: kept }
        },
    )
}
