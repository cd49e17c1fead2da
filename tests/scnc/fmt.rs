//! `scnc fmt`: golden layouts, and on every example and golden input: formatting twice
//! changes nothing, only whitespace changes, and the file means the same.

use std::path::Path;

use scnc::source::FsLoader;
use scnc::syntax::{self, Token};

use crate::support::{cases, check_golden, finish};

/// `NAME.scn` formats to exactly `NAME.fmt`.
#[test]
fn fmt_goldens() {
    let cases = cases("tests/data/fmt");
    assert!(cases.len() >= 2, "expected fmt cases, found {}", cases.len());
    let mut failures = Vec::new();
    for path in cases {
        let text = std::fs::read_to_string(&path).expect("reading the case");
        match scnc::fmt::format(&text) {
            Ok(out) => failures.extend(check_golden(&path.with_extension("fmt"), &out)),
            Err(_) => failures.push(format!("{}: has syntax errors", path.display())),
        }
    }
    finish(failures);
}

fn tokens(text: &str) -> Vec<Token<'_>> {
    syntax::lex(text, 0).into_iter().map(|(t, _)| t).collect()
}

/// What a file means: its IR (without source positions) and effects, or its
/// diagnostics' codes and messages.
fn meaning(path: &Path, text: String) -> String {
    let c = scnc::compile_file("x.scn", path, text, &FsLoader);
    let mut out: String = c.diagnostics.iter().map(|d| format!("{} {}\n", d.code, d.message)).collect();
    if let Some(scene) = &c.scene {
        for line in scnc::ir::dump(scene, &c.map).lines() {
            // Source positions move when lines are re-broken; nothing else may change.
            let line = line.split("  @").next().unwrap_or(line);
            out.push_str(line);
            out.push('\n');
        }
        out.push_str(&scnc::render::effects::derive(scene).to_string());
    }
    out
}

#[test]
fn fmt_is_idempotent_and_changes_only_whitespace() {
    let dirs = [
        "examples/seed",
        "examples/features",
        "examples/animation",
        "tests/data/ir",
        "tests/data/time",
        "tests/data/animation",
        "tests/data/diag",
        "tests/data/render",
        "tests/data/fmt",
    ];
    let mut failures = Vec::new();
    let (mut formatted, mut refused) = (0, 0);
    for dir in dirs {
        for path in cases(dir) {
            let text = std::fs::read_to_string(&path).expect("reading the case");
            let Ok(once) = scnc::fmt::format(&text) else {
                // Files with syntax errors are left alone; they must really have them.
                assert!(!syntax::parse(&text, 0).1.is_empty(), "{}: refused without an error", path.display());
                refused += 1;
                continue;
            };
            formatted += 1;
            let name = path.display();
            match scnc::fmt::format(&once) {
                Ok(twice) if twice == once => {}
                Ok(twice) => failures.push(format!("{name}: not idempotent:\n{}", crate::support::diff(&once, &twice))),
                Err(_) => failures.push(format!("{name}: formatting introduced a syntax error:\n{once}")),
            }
            if tokens(&once) != tokens(&text) {
                failures.push(format!("{name}: tokens or comments changed:\n{once}"));
            }
            if meaning(&path, once.clone()) != meaning(&path, text.clone()) {
                failures.push(format!("{name}: the formatted file means something else:\n{once}"));
            }
        }
    }
    assert!(formatted >= 100 && refused >= 5, "formatted {formatted}, refused {refused}");
    finish(failures);
}

/// Shipped examples are in the canonical layout (`scnc fmt --check` is clean on them).
#[test]
fn shipped_examples_are_formatted() {
    let mut failures = Vec::new();
    for dir in [
        "examples/seed",
        "examples/features",
        "examples/animation",
        "examples/povray",
        "examples/light",
        "benches/scenes",
        "tests/data",
    ] {
        for path in cases(dir) {
            let text = std::fs::read_to_string(&path).expect("reading the example");
            if scnc::fmt::format(&text).is_ok_and(|f| f != text) {
                failures.push(format!("{}: not formatted (run `scnc fmt` on it)", path.display()));
            }
        }
    }
    finish(failures);
}

/// `text` with every gap between tokens widened (two more spaces, or a trailing space
/// before a line break) and glued tokens pulled apart, and, with `reals`, every integer
/// written as a real (`3` as `3.0`): what a person might type, meaning the same.
fn respaced(text: &str, reals: bool) -> String {
    let mut out = String::new();
    let mut end = 0;
    for (tok, span) in syntax::lex(text, 0) {
        let (start, stop) = (span.start as usize, span.end as usize);
        let gap = &text[end..start];
        if gap.contains('\n') {
            out.push(' ');
            out.push_str(gap);
        } else {
            out.push_str("  ");
            out.push_str(gap);
        }
        let word = &text[start..stop];
        match tok {
            Token::Number(_) if reals && word.bytes().all(|b| b.is_ascii_digit()) => {
                out.push_str(word);
                out.push_str(".0");
            }
            _ => out.push_str(word),
        }
        end = stop;
    }
    out.push_str(&text[end..]);
    out
}

/// A formatter must never change what a file means: every corpus file respaced formats
/// to the same layout as the file itself, and with its integers written as reals it
/// still formats, idempotently, to a file that means the same. (`for i in 0.0 .. 3`
/// used to format to `0.0..3`, which did not lex.)
#[test]
fn respaced_files_format_to_the_same_layout_and_meaning() {
    let mut failures = Vec::new();
    let mut checked = 0;
    for dir in [
        "examples/seed",
        "examples/features",
        "examples/animation",
        "tests/data/ir",
        "tests/data/fmt",
        "benches/scenes",
    ] {
        for path in cases(dir) {
            let text = std::fs::read_to_string(&path).expect("reading the case");
            let Ok(canonical) = scnc::fmt::format(&text) else { continue };
            checked += 1;
            let name = path.display();
            match scnc::fmt::format(&respaced(&text, false)) {
                Ok(f) if f == canonical => {}
                Ok(f) => failures.push(format!(
                    "{name}: respaced, it formats differently:\n{}",
                    crate::support::diff(&canonical, &f)
                )),
                Err(_) => failures.push(format!("{name}: respaced, it does not format")),
            }
            let reals = respaced(&text, true);
            match scnc::fmt::format(&reals) {
                Ok(once) => {
                    if scnc::fmt::format(&once).ok().as_deref() != Some(once.as_str()) {
                        failures.push(format!("{name}: with reals, formatting is not idempotent"));
                    }
                    if meaning(&path, once.clone()) != meaning(&path, text.clone()) {
                        failures.push(format!("{name}: with reals and formatted, it means something else:\n{once}"));
                    }
                }
                Err(_) => failures.push(format!("{name}: with reals, it does not format")),
            }
        }
    }
    assert!(checked >= 60, "checked {checked}");
    finish(failures);
}

/// A scene saved with a byte-order mark (Windows Notepad) compiles as without one, and
/// `fmt` writes it without the mark.
#[test]
fn a_byte_order_mark_is_skipped() {
    let plain = "light ambient(1)\nobject sphere(1) at [0, 0, 5]\n";
    let marked = format!("\u{feff}{plain}");
    let scene = crate::support::scene(&marked);
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scnc::fmt::format(&marked).expect("formats"), plain);
}
