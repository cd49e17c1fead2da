//! Time: the frame an evaluation is at (what `clock` and `frame` are), and what the
//! evaluations of one scene's frames share, so an animation reads and parses its files
//! once however many frames it evaluates.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use crate::diag::Diagnostic;
use crate::ir::Settings;
use crate::source::FileId;
use crate::syntax::ast;

/// The point of an animation an evaluation is at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Time {
    /// `clock`: 0 at the first frame, 1 at the last (see [`Time::of`]).
    pub clock: f64,
    /// `frame`: the frame's number, from 0.
    pub frame: u32,
}

impl Time {
    /// A still, or the first frame of an animation.
    pub const STILL: Time = Time { clock: 0.0, frame: 0 };

    /// Frame `frame` of the animation `settings` declares. The clock runs from 0 at the
    /// first frame to 1 at the last, as POV-Ray's does; a cyclic animation stops one frame
    /// short of 1, so that frame `frames` would be frame 0 again and a loop has no repeat.
    pub fn of(frame: u32, settings: &Settings) -> Time {
        let steps = if settings.cyclic { settings.frames } else { settings.frames.saturating_sub(1) };
        let clock = if steps == 0 { 0.0 } else { f64::from(frame) / f64::from(steps) };
        Time { clock, frame }
    }
}

/// A file parsed once: its syntax tree and the parser's diagnostics.
pub(super) type Parsed = Arc<(ast::File, Vec<Diagnostic>)>;

/// What the evaluations of one scene share: the files each `include` read, by path and
/// by how many times that path was included before in the same evaluation, and every
/// file's parse. A later frame whose evaluation includes the same files in the same
/// order reads nothing and parses nothing, and its spans are those of the first frame,
/// so its diagnostics are recognisably the same ones.
#[derive(Debug, Default)]
pub struct Reuse {
    files: HashMap<(PathBuf, u32), FileId>,
    /// In the evaluation under way: how many times each path was included so far.
    seen: HashMap<PathBuf, u32>,
    parsed: HashMap<FileId, Parsed>,
}

impl Reuse {
    /// Starts an evaluation: include counts from zero.
    pub(super) fn start(&mut self) {
        self.seen.clear();
    }

    /// The file an earlier evaluation read for this inclusion of `path`, if any; counts
    /// the inclusion either way.
    pub(super) fn included(&mut self, path: &std::path::Path) -> (Option<FileId>, (PathBuf, u32)) {
        let n = self.seen.entry(path.to_path_buf()).or_default();
        let key = (path.to_path_buf(), *n);
        *n += 1;
        (self.files.get(&key).copied(), key)
    }

    /// Remembers the file read for an inclusion.
    pub(super) fn read(&mut self, key: (PathBuf, u32), id: FileId) {
        self.files.insert(key, id);
    }

    /// The parse of file `id`, made by `parse` the first time.
    pub(super) fn parse(&mut self, id: FileId, parse: impl FnOnce() -> (ast::File, Vec<Diagnostic>)) -> Parsed {
        self.parsed.entry(id).or_insert_with(|| Arc::new(parse())).clone()
    }
}
