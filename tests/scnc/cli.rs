//! The binary: exit codes, streams, and output formats.

use std::process::Command;

fn scnc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_scnc"))
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("running scnc")
}

#[test]
fn check_clean_file_exits_0() {
    let out = scnc(&["check", "examples/seed/07-box-sphere-cylinder.scn"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stderr.is_empty());
}

#[test]
fn check_errors_exit_1_with_diagnostics_on_stderr() {
    let out = scnc(&["check", "tests/data/diag/unknown-function.scn"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("E0201") && err.contains("did you mean `sphere`?"), "{err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn usage_errors_exit_2() {
    assert_eq!(scnc(&["check"]).status.code(), Some(2));
    assert_eq!(scnc(&["frobnicate"]).status.code(), Some(2));
    assert_eq!(
        scnc(&["check", "--message-format", "xml", "a.scn"]).status.code(),
        Some(2)
    );
}

#[test]
fn missing_file_is_an_error() {
    let out = scnc(&["check", "no/such/file.scn"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read `no/such/file.scn`: no such file"));
}

#[test]
fn json_message_format_has_one_object_per_diagnostic() {
    let out = scnc(&[
        "check",
        "--message-format",
        "json",
        "tests/data/diag/two-syntax-errors.scn",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("valid JSON line"))
        .collect();
    assert_eq!(lines.len(), 2, "{text}");
    for v in &lines {
        assert_eq!(v["severity"], "error");
        assert_eq!(v["code"], "E0100");
        assert!(v["span"]["file"]
            .as_str()
            .is_some_and(|f| f.ends_with("two-syntax-errors.scn")));
        assert!(v["span"]["line_start"].as_u64().is_some_and(|l| l >= 1));
        assert!(v["span"]["byte_end"].as_u64() >= v["span"]["byte_start"].as_u64());
    }
    assert_ne!(lines[0]["span"]["line_start"], lines[1]["span"]["line_start"]);
}

#[test]
fn ir_prints_the_scene() {
    let out = scnc(&["ir", "examples/seed/01-sphere.scn"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("sphere radius 1"), "{text}");
    assert!(text.starts_with("camera position [0, 0, 0]"), "{text}");
}

#[test]
fn check_many_files_reports_all() {
    let out = scnc(&[
        "check",
        "tests/data/diag/unknown-function.scn",
        "examples/seed/01-sphere.scn",
        "tests/data/diag/unknown-name.scn",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("E0201") && err.contains("E0200"), "{err}");
}
