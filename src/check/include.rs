//! `include`: reading another file into the compile, with cycle, count, depth and size
//! limits, and running a file's statements with includes relative to it.

use std::path::{Component, Path, PathBuf};
use std::rc::Rc;

use super::{Ctx, MAX_INCLUDES, MAX_INCLUDE_DEPTH};
use crate::diag::{codes, Diagnostic};
use crate::source::{io_reason, FileId, MAX_FILE_BYTES};
use crate::span::Span;
use crate::syntax;

impl Ctx<'_> {
    /// `include "path"` at `stmt`: the file's statements run here; names the root file's
    /// includes define are exported to it for editor tooling.
    pub(super) fn include_stmt(&mut self, written: &str, span: Span, stmt: Span) {
        let root = self.include_stack.len() == 1;
        let outer = self.export;
        if root {
            self.export = Some((stmt.end, self.block_end, self.env.depth().unwrap_or(0)));
        }
        self.include(written, span);
        self.export = outer;
    }

    fn include(&mut self, written: &str, span: Span) {
        let path = normalize(&self.dir.join(written));
        if let Some(pos) = self.include_stack.iter().position(|p| *p == path) {
            let chain: Vec<String> = self.include_stack[pos..]
                .iter()
                .chain(std::iter::once(&path))
                .map(|p| p.display().to_string())
                .collect();
            self.report(
                Diagnostic::error(
                    codes::INCLUDE_CYCLE,
                    span,
                    format!("`{written}` includes itself"),
                    "this include closes a cycle",
                )
                .with_note(format!("include chain: {}", chain.join(" → "))),
            );
            return;
        }
        self.includes += 1;
        if self.includes > MAX_INCLUDES {
            self.halted = true;
            self.report(
                Diagnostic::error(codes::INCLUDE_DEPTH, span, "too many includes", "include number 1,001 is here")
                    .with_note(format!("a compile may carry out at most {MAX_INCLUDES} includes in all")),
            );
            return;
        }
        if self.include_stack.len() >= MAX_INCLUDE_DEPTH {
            self.report(
                Diagnostic::error(
                    codes::INCLUDE_DEPTH,
                    span,
                    "includes nest too deeply",
                    format!("include depth {MAX_INCLUDE_DEPTH} is exceeded here"),
                )
                .with_note(format!("files may include each other at most {MAX_INCLUDE_DEPTH} levels deep")),
            );
            return;
        }
        let (known, key) = self.reuse.included(&path);
        if let Some(id) = known {
            self.run_file(id);
            return;
        }
        let text = match self.loader.read(&path) {
            Ok(text) if text.len() > MAX_FILE_BYTES => {
                self.report(Diagnostic::error(
                    codes::TOO_LARGE,
                    span,
                    format!("`{written}` is too large"),
                    format!("larger than {} MiB", MAX_FILE_BYTES >> 20),
                ));
                return;
            }
            Ok(text) => text,
            Err(e) => {
                self.report(
                    Diagnostic::error(codes::INCLUDE_READ, span, format!("cannot read `{written}`"), io_reason(&e))
                        .with_note(format!("looked for {}", path.display())),
                );
                return;
            }
        };
        let Some(id) = self.map.add(written, &path, text) else {
            self.report(Diagnostic::error(
                codes::TOO_LARGE,
                span,
                "the scene's files are too large in total",
                "including this file exceeds the limit",
            ));
            return;
        };
        self.reuse.read(key, id);
        self.run_file(id);
    }

    /// Parses the file `id` and runs its statements, with includes relative to it.
    pub(super) fn run_file(&mut self, id: FileId) {
        let parsed = {
            let f = self.map.file(id);
            self.reuse.parse(id, || syntax::parse(&f.text, f.base))
        };
        let (file, diags) = &*parsed;
        for d in diags {
            self.report(d.clone());
        }
        let path = self.map.file(id).path.clone();
        let old_dir = std::mem::replace(&mut self.dir, Rc::from(path.parent().unwrap_or(Path::new(""))));
        self.include_stack.push(normalize(&path));
        self.stmts(&file.stmts);
        self.include_stack.pop();
        self.dir = old_dir;
    }
}

/// Lexically normalises `a/./b/../c` to `a/c`, for include-cycle detection.
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            c => out.push(c),
        }
    }
    // `include "."` from a file in the working directory names that directory, not "".
    if out.as_os_str().is_empty() {
        out.push(".");
    }
    out
}
