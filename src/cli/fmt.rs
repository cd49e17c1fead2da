//! `scnc fmt`: files rewritten in the canonical layout.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use scnc::source::{FsLoader, Loader};

use super::files::{cannot_write, write_text};
use super::{report_in, MessageFormat};

/// Formats each file in place, or with `check` lists those that would change; then says
/// how many changed unless `quiet`.
pub(crate) fn fmt_cmd(files: &[PathBuf], check: bool, quiet: bool) -> ExitCode {
    let mut failed = false;
    let mut unformatted = false;
    let mut changed = 0;
    for path in files {
        let name = path.display().to_string();
        let text = match FsLoader.read(path) {
            Ok(text) => text,
            Err(e) => {
                let _ = writeln!(std::io::stderr(), "error: cannot read `{name}`: {}", scnc::source::io_reason(&e));
                failed = true;
                continue;
            }
        };
        let formatted = match scnc::fmt::format(&text) {
            Ok(f) => f,
            Err(diagnostics) => {
                let mut map = scnc::source::SourceMap::new();
                let _ = map.add(&name, path, text);
                report_in(&map, &diagnostics, MessageFormat::Human);
                let _ = writeln!(std::io::stderr(), "error: `{name}` was not formatted: it has syntax errors");
                failed = true;
                continue;
            }
        };
        if formatted == text {
            continue;
        }
        if check {
            let _ = writeln!(std::io::stdout(), "{name}");
            unformatted = true;
        } else if let Err(e) = write_text(path, &formatted) {
            let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(path, &e));
            failed = true;
        } else {
            changed += 1;
        }
    }
    if !quiet && !check {
        let _ = writeln!(std::io::stderr(), "{changed} of {} changed", super::plural(files.len(), "file"));
    }
    if failed || unformatted {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
