//! Data-driven golden tests: `tests/data/<kind>/NAME.scn` next to its expected output.

use crate::support::{cases, check_golden, compile, finish};

/// Every IR case compiles without errors, and its dump (warnings, then IR) matches `NAME.ir`.
/// The effect set derived from each is kept in one golden of its own
/// (`effects::derived_over_every_scene`), so a new effect does not touch these.
#[test]
fn ir_dumps() {
    let cases = cases("tests/data/ir");
    assert!(cases.len() >= 25, "expected at least 25 IR cases, found {}", cases.len());
    let mut failures = Vec::new();
    for path in cases {
        let c = compile(&path);
        let Some(scene) = &c.scene else {
            failures.push(format!(
                "{}: did not compile:\n{}",
                path.display(),
                scnc::diag::render_all(&c.diagnostics, &c.map)
            ));
            continue;
        };
        let mut actual = scnc::diag::render_all(&c.diagnostics, &c.map);
        actual.push_str(&scnc::ir::dump(scene, &c.map));
        failures.extend(check_golden(&path.with_extension("ir"), &actual));
    }
    finish(failures);
}

/// Every diagnostic case reports at least one diagnostic, rendered exactly as in `NAME.txt`.
#[test]
fn diagnostics() {
    let cases = cases("tests/data/diag");
    assert!(cases.len() >= 40, "expected at least 40 diagnostic cases, found {}", cases.len());
    let mut failures = Vec::new();
    for path in cases {
        let c = compile(&path);
        if c.diagnostics.is_empty() {
            failures.push(format!("{}: expected diagnostics, got none", path.display()));
            continue;
        }
        let actual = scnc::diag::render_all(&c.diagnostics, &c.map);
        failures.extend(check_golden(&path.with_extension("txt"), &actual));
    }
    finish(failures);
}

/// Every example checks clean: no errors and no warnings.
#[test]
fn examples_check_clean() {
    let mut failures = Vec::new();
    for dir in ["examples/seed", "examples/features", "examples/animation", "examples/povray", "examples/light"] {
        for path in cases(dir) {
            if path.file_name().is_some_and(|n| n == "lights.scn") {
                continue;
            }
            let c = compile(&path);
            if !c.diagnostics.is_empty() || c.scene.is_none() {
                failures.push(format!("{}:\n{}", path.display(), scnc::diag::render_all(&c.diagnostics, &c.map)));
            }
        }
    }
    finish(failures);
}

/// A parse error does not stop checking: two bad statements give two errors.
#[test]
fn syntax_recovery_reports_independent_errors() {
    let text =
        "object sphere(1 at [0, 0, 5]\nlight ambient(0.2)\nobject box(1) rotate\nobject sphere(1) at [0, 0, 5]\n"
            .to_string();
    let c = scnc::compile_source("t.scn", std::path::Path::new("t.scn"), text, &scnc::source::FsLoader);
    let syntax: Vec<_> = c.diagnostics.iter().filter(|d| d.code == "E0100").collect();
    assert_eq!(syntax.len(), 2, "{:#?}", c.diagnostics);
}

/// Every byte of the input is covered by a token or by skipped whitespace/comments.
#[test]
fn lexer_covers_every_byte() {
    for path in cases("examples/seed").into_iter().chain(cases("examples/features")) {
        let text = std::fs::read_to_string(&path).expect("example");
        let mut covered = vec![false; text.len()];
        for (_, span) in scnc::syntax::lex(&text, 0) {
            for c in &mut covered[span.range()] {
                *c = true;
            }
        }
        for (i, b) in text.bytes().enumerate() {
            if !covered[i] {
                assert!(b.is_ascii_whitespace(), "{}: byte {i} ({:?}) not covered", path.display(), b as char);
            }
        }
    }
}

/// Every diagnostic code defined in `src/diag.rs` is documented in `docs/errors.md`.
#[test]
fn every_code_is_documented() {
    let src = std::fs::read_to_string("src/diag.rs").expect("src/diag.rs");
    let docs = std::fs::read_to_string("docs/errors.md").expect("docs/errors.md");
    let codes: Vec<&str> = src
        .split("pub const ")
        .skip(1)
        .filter_map(|rest| rest.split('"').nth(1))
        .filter(|c| c.len() == 5 && (c.starts_with('E') || c.starts_with('W')))
        .collect();
    assert!(codes.len() >= 30, "found only {} codes", codes.len());
    for code in codes {
        assert!(docs.contains(&format!("| {code} |")), "{code} is not documented in docs/errors.md");
    }
}

/// Lowering problems (mesh files, isosurface limits, parts an isosurface loses) are
/// diagnostics at the object's source, rendered exactly as in `NAME.txt`.
#[test]
fn lowering_diagnostics() {
    let mut failures = Vec::new();
    for path in cases("tests/data/lower") {
        let c = compile(&path);
        let Some(scene) = &c.scene else {
            failures.push(format!("{}: did not compile", path.display()));
            continue;
        };
        let effects = scnc::render::effects::derive(scene);
        match scnc::world::prepare(scene, effects, scnc::world::Mode::Sdf, &scnc::source::FsLoader) {
            Ok((_, world)) if !world.warnings.is_empty() => {
                let text: String = world.warnings.iter().map(|d| d.render(&c.map, false)).collect();
                failures.extend(check_golden(&path.with_extension("txt"), &text));
            }
            Ok(_) => failures.push(format!("{}: lowered without an error or a warning", path.display())),
            Err(d) => failures.extend(check_golden(&path.with_extension("txt"), &d.render(&c.map, false))),
        }
    }
    finish(failures);
}

/// `docs/builtins.md` is the reference the table writes (`UPDATE_EXPECT=1` rewrites it).
#[test]
fn reference_is_written_from_the_table() {
    let failures = check_golden(std::path::Path::new("docs/builtins.md"), &scnc::builtins::reference());
    finish(failures.into_iter().collect());
}
