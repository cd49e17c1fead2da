//! The binary: exit codes, streams, and output formats.

use crate::support::{finish, ok, refused, scnc};

#[test]
fn check_clean_file_exits_0() {
    let out = scnc(&["check", "examples/seed/07-box-sphere-cylinder.scn"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    // One summary line, on stderr; nothing with `--quiet`.
    assert_eq!(String::from_utf8_lossy(&out.stderr), "ok: 3 objects, 3 lights, 0 warnings\n");
    assert!(out.stdout.is_empty());
    let out = scnc(&["check", "--quiet", "examples/seed/07-box-sphere-cylinder.scn"]);
    assert!(out.status.success() && out.stderr.is_empty() && out.stdout.is_empty());
    let two = ["check", "examples/seed/07-box-sphere-cylinder.scn", "examples/tour.scn"];
    assert!(String::from_utf8_lossy(&scnc(&two).stderr).starts_with("ok: 2 files, "));
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
    assert_eq!(scnc(&["check", "--message-format", "xml", "a.scn"]).status.code(), Some(2));
}

#[test]
fn missing_file_is_an_error() {
    let out = scnc(&["check", "no/such/file.scn"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read `no/such/file.scn`: no such file"));
}

#[test]
fn json_message_format_has_one_object_per_diagnostic() {
    let out = scnc(&["check", "--message-format", "json", "tests/data/diag/two-syntax-errors.scn"]);
    assert_eq!(out.status.code(), Some(1));
    // Machine output on stdout, as cargo's and rustc's; nothing for people on stderr.
    assert!(out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<serde_json::Value> =
        text.lines().map(|l| serde_json::from_str(l).expect("valid JSON line")).collect();
    assert_eq!(lines.len(), 2, "{text}");
    for v in &lines {
        assert_eq!(v["severity"], "error");
        assert_eq!(v["code"], "E0100");
        assert!(v["span"]["file"].as_str().is_some_and(|f| f.ends_with("two-syntax-errors.scn")));
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
    assert!(text.contains("sphere r 1"), "{text}");
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

#[test]
fn render_writes_a_png() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("seed1.png");
    let o = scnc(&[
        "render",
        "examples/seed/01-sphere.scn",
        "-o",
        out.to_str().unwrap_or_default(),
        "--width",
        "40",
        "--height",
        "30",
        "--stats",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(&out).expect("a PNG was written").to_rgb8();
    assert_eq!((img.width(), img.height()), (40, 30));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("rendered") && err.contains("1200 primary"), "{err}");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .expect("dir")
        .filter_map(Result::ok)
        .filter(|e| e.file_name() != "seed1.png")
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind: {leftovers:?}");
}

#[test]
fn failed_render_leaves_no_file_and_keeps_an_existing_one() {
    let dir = tempfile::tempdir().expect("tempdir");
    let fresh = dir.path().join("fresh.png");
    let o = scnc(&["render", "tests/data/diag/unknown-function.scn", "-o", fresh.to_str().unwrap_or_default()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(!fresh.exists(), "an image was written for a scene with errors");
    let existing = dir.path().join("existing.png");
    std::fs::write(&existing, b"keep me").expect("write");
    let o = scnc(&["render", "tests/data/diag/unknown-function.scn", "-o", existing.to_str().unwrap_or_default()]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(std::fs::read(&existing).expect("read"), b"keep me");
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 1, "no temporary file may remain");
}

#[test]
fn render_rejects_bad_flags_with_exit_2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let png = dir.path().join("a.png");
    let png = png.to_str().unwrap_or_default();
    for args in [
        vec!["render", "examples/seed/01-sphere.scn", "-o", png, "--width", "0"],
        vec!["render", "examples/seed/01-sphere.scn", "-o", png, "--epsilon", "2"],
        vec!["render", "examples/seed/01-sphere.scn", "-o", png, "--threads", "0"],
        vec!["render", "examples/seed/01-sphere.scn", "-o", png, "--max-steps", "lots"],
        vec!["render", "examples/seed/01-sphere.scn"],
    ] {
        let o = scnc(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    }
    let jpg = dir.path().join("a.jpg");
    let o = scnc(&["render", "examples/seed/01-sphere.scn", "-o", jpg.to_str().unwrap_or_default()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("scnc writes PNG"));
    let o = scnc(&["render", "examples/seed/01-sphere.scn", "-o", "/no/such/dir/a.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(std::fs::read_dir(dir.path()).expect("dir").next().is_none(), "nothing may be written");
}

/// The columns of `sweep.csv`.
const SWEEP_COLUMNS: &str = "backend,setting,work,runs,wall_ms_min,wall_ms,wall_ms_max,wall_ci_ms,cpu_ms,rays_per_s,sdf_evals_per_ray,leaf_evals_per_ray,node_visits_per_ray,triangle_tests_per_ray,geometry_bytes,triangles,peak_rss_kib,geo_error_mean,geo_error_max,geo_error_max_pixels,coverage_error_px,rmse,psnr_db";

/// The sweep runs on a seed scene at a tiny size with two settings per back-end, writes
/// the expected columns, and errors fall where the maths says they must.
#[test]
fn sweep_writes_csv_with_monotone_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().to_str().unwrap_or_default();
    let o = scnc(&[
        "sweep",
        "examples/seed/01-sphere.scn",
        "-o",
        out,
        "--width",
        "48",
        "--height",
        "48",
        "--runs",
        "1",
        "--quick",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    // Not a terminal: a line per step instead of a bar, so a long sweep is never silent.
    let said = String::from_utf8_lossy(&o.stderr);
    for step in [
        "sweep: the reference render",
        "sweep: measured 1/4: sdf",
        "sweep: measured 4/4: mesh",
        "sweep: timing round 1: 4 settings",
    ] {
        assert!(said.contains(step), "no `{step}` in:\n{said}");
    }
    let csv = std::fs::read_to_string(dir.path().join("sweep.csv")).expect("sweep.csv");
    let mut lines = csv.lines();
    // The documented columns (README, "scnc sweep"), in order.
    assert_eq!(lines.next(), Some(SWEEP_COLUMNS));
    let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(str::to_string).collect()).collect();
    assert_eq!(rows.len(), 4);
    let col = |name: &str| SWEEP_COLUMNS.split(',').position(|c| c == name).expect("column");
    let geo_max = |row: usize| rows[row][col("geo_error_max")].parse::<f64>().expect("number");
    assert!(rows.iter().all(|r| r.len() == SWEEP_COLUMNS.split(',').count()));
    let md = std::fs::read_to_string(dir.path().join("sweep.md")).expect("sweep.md");
    let table: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).collect();
    assert_eq!(table.len(), 2 + rows.len(), "heading, rule and one line per setting");
    assert!(table.iter().all(|l| l.matches('|').count() == SWEEP_COLUMNS.split(',').count() + 1), "{md}");
    // A coarser hit threshold never gives a closer hit; more tessellation never a larger
    // chord error of the UV sphere.
    assert!(geo_max(0) >= geo_max(1), "sdf: epsilon 1e-2 should not beat 1e-4");
    assert!(geo_max(2) >= geo_max(3), "mesh: low detail should not beat high");
    assert!(geo_max(2) > 0.0 && geo_max(1) < 1e-3, "errors in the expected ranges");
    assert!(std::fs::read_to_string(dir.path().join("sweep.md")).expect("sweep.md").contains("| mesh | detail high |"));
    for chart in ["time-vs-error.png", "work-vs-error.png", "memory-vs-error.png"] {
        let img = image::open(dir.path().join(chart)).expect("a chart was written").to_rgb8();
        assert!(
            img.pixels().any(|p| p.0 == [255, 0, 0]) && img.pixels().any(|p| p.0 == [0, 0, 255]),
            "{chart} has both curves"
        );
    }
}

/// The cost axis that does not depend on the machine: each setting's work (unit
/// operations per frame) is the same in two sweeps, and finer settings of a back-end
/// take more of it; the timing columns say how the median was reached. The scene is
/// the tori, whose march is what a threshold buys: the seed scenes' box, sphere and
/// cylinder cost one step at any threshold now that rays are clipped to their exact
/// hulls (seed 7's work at 1e-3, 1e-4, 1e-5: 6,006, 6,005, 5,993 — a coarser threshold
/// only fattens the surfaces, so a few more shadow rays hit).
#[test]
fn sweep_work_is_deterministic_and_grows_with_accuracy() {
    let work = |dir: &std::path::Path| {
        let o = scnc(&[
            "sweep",
            "examples/features/tori.scn",
            "-o",
            dir.to_str().unwrap_or_default(),
            "--width",
            "48",
            "--height",
            "48",
            "--runs",
            "2",
            "--time-cap",
            "0.05",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        let csv = std::fs::read_to_string(dir.join("sweep.csv")).expect("sweep.csv");
        let col = |name: &str| SWEEP_COLUMNS.split(',').position(|c| c == name).expect("column");
        csv.lines()
            .skip(1)
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                let num = |name: &str| f[col(name)].parse::<f64>().expect("a number");
                assert!(num("runs") >= 2.0, "{l}");
                assert!(num("wall_ms_min") <= num("wall_ms") && num("wall_ms") <= num("wall_ms_max"), "{l}");
                (f[col("backend")].to_string(), f[col("setting")].to_string(), num("work"))
            })
            .collect::<Vec<_>>()
    };
    let (a, b) = (tempfile::tempdir().expect("tempdir"), tempfile::tempdir().expect("tempdir"));
    let (first, second) = (work(a.path()), work(b.path()));
    assert_eq!(first, second, "work differs between two sweeps");
    // The thresholds' rungs, coarse to fine, and the mesh details, coarse to fine.
    let rung = |setting: &str| first.iter().find(|(_, s, _)| s == setting).map(|r| r.2).expect("a rung");
    let sdf = ["epsilon 1e-2 steps 512", "epsilon 1e-3 steps 512", "epsilon 1e-4 steps 512", "epsilon 1e-5 steps 512"];
    let mesh = ["detail low", "detail high", "detail 28", "detail 56", "detail 112"];
    for ladder in [&sdf[..], &mesh[..]] {
        let works: Vec<f64> = ladder.iter().map(|s| rung(s)).collect();
        assert!(works.windows(2).all(|w| w[0] <= w[1]), "{ladder:?}: {works:?}");
    }
}

/// `--tolerance pixel` picks settings whose measured geometric error stays within a
/// pixel's footprint, for both back-ends, and `render` reports what it picked.
#[test]
fn tolerance_picks_hold() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().to_str().unwrap_or_default();
    let o = scnc(&[
        "sweep",
        "examples/seed/07-box-sphere-cylinder.scn",
        "--out",
        out,
        "--width",
        "64",
        "--height",
        "64",
        "--runs",
        "1",
        "--tolerance",
        "pixel",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.path().join("sweep.csv")).expect("sweep.csv");
    let col = SWEEP_COLUMNS.split(',').position(|c| c == "geo_error_max_pixels").expect("column");
    let rows: Vec<f64> =
        csv.lines().skip(1).map(|l| l.split(',').nth(col).and_then(|v| v.parse().ok()).expect("number")).collect();
    assert_eq!(rows.len(), 2);
    assert!(rows.iter().all(|&px| px <= 1.0 + 1e-3), "an error over a pixel: {rows:?}");
    let png = dir.path().join("t.png");
    let sphere = |extra: &[&str]| {
        let mut args = vec!["render", "examples/seed/01-sphere.scn", "-o", png.to_str().unwrap_or_default()];
        args.extend_from_slice(extra);
        scnc(&args)
    };
    let o = sphere(&["--width", "32", "--height", "32", "--tolerance", "0.001", "--geometry", "mesh"]);
    assert_eq!(o.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&o.stderr).contains("tolerance 0.001: picked detail"));
    let o = sphere(&["--tolerance", "0", "--width", "8"]);
    assert_eq!(o.status.code(), Some(2), "a tolerance of 0 is a usage error");
    let o = sphere(&["--tolerance", "pixel", "--epsilon", "0.01"]);
    assert_eq!(o.status.code(), Some(2), "--tolerance and --epsilon conflict");
}

/// An empty scene is a warning (rendered with its source, exit 0), not an error; an
/// unreadable file is one error, also as a JSON line.
#[test]
fn empty_and_unreadable_files_are_reported_for_what_they_are() {
    let dir = tempfile::tempdir().expect("tempdir");
    let empty = dir.path().join("empty.scn");
    std::fs::write(&empty, "").expect("write");
    let o = scnc(&["check", empty.to_str().unwrap_or_default()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("[W0004] Warning: the scene has no objects") && !err.contains("error["), "{err}");
    let o = scnc(&["check", "--message-format", "json", "no/such/file.scn"]);
    assert_eq!(o.status.code(), Some(1));
    let line: serde_json::Value =
        serde_json::from_str(String::from_utf8_lossy(&o.stdout).trim()).expect("one JSON line");
    assert_eq!((line["code"].as_str(), line["severity"].as_str()), (Some("E0600"), Some("error")));
    assert_eq!(line["span"]["file"], "no/such/file.scn");
    // It has the documented fields of every diagnostic, a zero-length span at the start.
    let o = scnc(&["check", "--message-format", "json", "tests/data/diag/two-syntax-errors.scn"]);
    let text = String::from_utf8_lossy(&o.stdout);
    let normal: serde_json::Value = serde_json::from_str(text.lines().next().unwrap_or_default()).expect("JSON");
    let keys = |v: &serde_json::Value| v.as_object().map(|o| o.keys().cloned().collect::<Vec<_>>()).unwrap_or_default();
    assert_eq!(keys(&line), keys(&normal));
    assert_eq!(keys(&line["span"]), keys(&normal["span"]));
    assert_eq!((line["span"]["byte_start"].as_u64(), line["span"]["line_start"].as_u64()), (Some(0), Some(1)));
}

/// Output paths that cannot be a PNG file are usage errors (exit 2) before any work; a
/// symbolic link at the output path is written through, keeping the link and the mode.
#[cfg(unix)]
#[test]
fn output_paths_directories_and_links() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().expect("temp dir");
    let as_dir = dir.path().join("out.png");
    std::fs::create_dir(&as_dir).expect("mkdir");
    let o = scnc(&["render", "examples/seed/01-sphere.scn", "-o", as_dir.to_str().unwrap_or_default()]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("it is a directory"));
    assert!(!String::from_utf8_lossy(&o.stderr).contains("rendered"), "refused before rendering");
    let slash = format!("{}/", dir.path().join("x.png").display());
    let o = scnc(&["render", "examples/seed/01-sphere.scn", "-o", &slash]);
    assert_eq!(o.status.code(), Some(2));
    // A link to a readable 0644 image: the image is replaced, the link stays a link.
    let target = dir.path().join("target.png");
    std::fs::write(&target, b"old").expect("write");
    std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o644)).expect("chmod");
    let link = dir.path().join("link.png");
    std::os::unix::fs::symlink(&target, &link).expect("symlink");
    let o = scnc(&["render", "examples/seed/01-sphere.scn", "-o", link.to_str().unwrap_or_default(), "--width", "8"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::symlink_metadata(&link).expect("link").file_type().is_symlink(), "the link was replaced");
    assert!(image::open(&target).is_ok(), "the link's target holds the image");
    let mode = std::fs::metadata(&target).expect("target").permissions().mode() & 0o777;
    assert_eq!(mode, 0o644, "the replaced file keeps its mode");
    let stray: Vec<_> = std::fs::read_dir(dir.path())
        .expect("dir")
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with(".scnc-"))
        .collect();
    assert!(stray.is_empty(), "temporary files left: {stray:?}");
}

/// Only regular files are read: a device or a pipe named by `include` (or on the command
/// line) is a clear error at once, never an endless read or a blocked open.
#[cfg(unix)]
#[test]
fn devices_and_pipes_are_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("s.scn");
    std::fs::write(&scene, "include \"/dev/zero\"\ninclude \".\"\n").expect("write");
    let o = scnc(&["check", scene.to_str().unwrap_or_default()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("it is not a regular file"), "{err}");
    assert!(err.contains("it is a directory"), "`include \".\"` names the directory: {err}");
    let fifo = dir.path().join("pipe.scn");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success());
    if made {
        let o = scnc(&["check", fifo.to_str().unwrap_or_default()]);
        assert_eq!(o.status.code(), Some(1));
        assert!(String::from_utf8_lossy(&o.stderr).contains("it is not a regular file"));
    }
}

#[test]
fn fmt_rewrites_in_place_and_check_lists_what_would_change() {
    let dir = tempfile::tempdir().expect("temp dir");
    let messy = dir.path().join("messy.scn");
    let clean = dir.path().join("clean.scn");
    let broken = dir.path().join("broken.scn");
    std::fs::write(&messy, "light ambient(1)  object sphere( 1 )at[0,0,5]\n").expect("writing");
    std::fs::write(&clean, "light ambient(1)\n").expect("writing");
    std::fs::write(&broken, "object sphere(1 at [0, 0, 5]\n").expect("writing");
    let path = |p: &std::path::Path| p.to_string_lossy().into_owned();

    let out = scnc(&["fmt", "--check", &path(&messy), &path(&clean)]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&out.stdout), format!("{}\n", path(&messy)));
    assert!(std::fs::read_to_string(&messy).expect("reading").contains("sphere( 1 )"), "--check changed the file");

    let out = scnc(&["fmt", &path(&messy), &path(&clean)]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(String::from_utf8_lossy(&out.stderr), "1 of 2 files changed\n");
    assert!(scnc(&["fmt", "-q", &path(&clean)]).stderr.is_empty());
    let formatted = std::fs::read_to_string(&messy).expect("reading");
    assert_eq!(formatted, "light ambient(1)\nobject sphere(1) at [0, 0, 5]\n");
    assert_eq!(scnc(&["fmt", "--check", &path(&messy)]).status.code(), Some(0));

    let out = scnc(&["fmt", &path(&broken)]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("E0100") && err.contains("was not formatted"), "{err}");
    assert_eq!(std::fs::read_to_string(&broken).expect("reading"), "object sphere(1 at [0, 0, 5]\n");
}

/// `--memory-limit` takes sizes with K, M or G; a mesh over it is an error before it is
/// built, and a bad size is a usage error.
#[test]
fn memory_limit_refuses_meshes_before_building_them() {
    let dir = tempfile::tempdir().expect("temp dir");
    let png = dir.path().join("m.png");
    let png = png.to_str().unwrap_or_default();
    let scene = "examples/features/meshes.scn";
    let o = scnc(&["render", scene, "-o", png, "--width", "16", "--height", "16", "--memory-limit", "64K"]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("more memory than the limit"));
    assert!(std::fs::metadata(png).is_err(), "nothing is written");
    let o = scnc(&["render", scene, "-o", png, "--width", "16", "--height", "16", "--memory-limit", "512M"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    for bad in ["0", "lots", "4T", "99999999999G"] {
        let o = scnc(&["render", scene, "-o", png, "--memory-limit", bad]);
        assert_eq!(o.status.code(), Some(2), "--memory-limit {bad}");
    }
}

/// What a newcomer meets first, each said plainly: plurals, the unit a size was given
/// in, a cap on a flood of diagnostics, OS errors in terms of the user's own path, a
/// frame sequence's directory made for it, `-o` for every output.
#[test]
fn messages_a_newcomer_meets() {
    let dir = tempfile::tempdir().expect("temp dir");
    let at = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let seed = "examples/seed/01-sphere.scn";

    let out = scnc(&["render", seed, "-o", &at("a.png"), "--width", "8", "--height", "8", "--threads", "1"]);
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stderr).contains(" M rays/s, 1 thread)"), "{out:?}");

    let out = scnc(&["render", seed, "-o", &at("m.png"), "--geometry", "mesh", "--memory-limit", "1K"]);
    refused(&out, 1, "the memory limit is 1 KiB");

    let out = scnc(&["check", "README.md"]);
    refused(&out, 1, "more diagnostics (");
    let shown = String::from_utf8_lossy(&out.stderr).matches("] Error:").count();
    assert_eq!(shown, 50, "the first fifty are shown");

    // A directory that exists but cannot hold files: the error names the user's path,
    // never the temporary file beside it.
    let out = scnc(&["render", seed, "-o", "/proc/scnc-test.png", "--width", "8", "--height", "8"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot write `/proc/scnc-test.png`") && !err.contains(".tmp") && !err.contains("os error"),
        "{err}"
    );

    let frames = at("frames/f-##.png");
    ok(&scnc(&[
        "render",
        "tests/data/animation/bounce.scn",
        "-o",
        &frames,
        "--width",
        "8",
        "--height",
        "8",
        "--frames",
        "0..2",
    ]));
    assert!(dir.path().join("frames/f-00.png").exists() && dir.path().join("frames/f-01.png").exists());

    let out = scnc(&["sweep", "--help"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("-o, --output <OUTPUT>"));
}

/// Under an address space too small for the compiler's 256 MiB stack, `check` and
/// `render` say so with a code and exit 1; they do not panic (101).
#[test]
fn a_thread_the_system_refuses_is_an_error_not_a_panic() {
    let dir = crate::support::files(&[("s.scn", b"light ambient(1)\nobject sphere(1) at [0, 0, 5]\n")]);
    for args in [&["check", "s.scn"][..], &["render", "s.scn", "-o", "s.png", "--width", "8", "--height", "8"][..]] {
        let out = crate::support::scnc_capped(200_000, dir.path(), args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("E0709") && err.contains("cannot start the compiler's thread"), "{args:?}: {err}");
        assert!(!dir.path().join("s.png").exists(), "a render that did not compile wrote its image");
    }
}

/// A long flat expression is not a deep one: a sum of 300 terms compiles (it was E0700,
/// "nests too deeply"), and a sum of a million terms (a 4 MB file, a parse tree a
/// million deep) is checked and formatted without overflowing a stack.
#[test]
fn long_flat_sums_compile_and_format() {
    let sum = |n: usize| format!("light ambient(1)\nlet x = {}\nobject sphere(x / {n})\n", vec!["1"; n].join(" + "));
    let dir = crate::support::files(&[("a.scn", sum(300).as_bytes()), ("b.scn", sum(1_000_000).as_bytes())]);
    for file in ["a.scn", "b.scn"] {
        let path = dir.path().join(file);
        let path = path.to_str().expect("utf-8");
        for args in [&["check", path][..], &["fmt", "--check", path][..]] {
            let out = scnc(args);
            assert_eq!(out.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        }
    }
}

/// W0010 (radians written where degrees are meant) never fires on a shipped scene: every
/// example and golden input that uses trigonometry in a body means degrees.
#[test]
fn no_radians_warning_on_any_shipped_scene() {
    let out = std::process::Command::new("git").args(["ls-files", "*.scn"]).output().expect("git ls-files");
    let files: Vec<String> = String::from_utf8_lossy(&out.stdout).lines().map(str::to_string).collect();
    assert!(files.len() > 100, "{} scenes", files.len());
    let flagged: Vec<&String> = files
        .iter()
        .filter(|f| !f.ends_with("field-radians.scn"))
        .filter(|f| crate::support::compile(std::path::Path::new(f)).diagnostics.iter().any(|d| d.code == "W0010"))
        .collect();
    assert!(flagged.is_empty(), "W0010 on {flagged:?}");
}

/// The `--flags` a text names.
fn flags_in(text: &str) -> std::collections::BTreeSet<String> {
    let mut out = std::collections::BTreeSet::new();
    for (i, _) in text.match_indices("--") {
        let name: String = text[i + 2..].chars().take_while(|c| c.is_ascii_lowercase() || *c == '-').collect();
        let before = text[..i].chars().next_back();
        if name.len() > 1 && !before.is_some_and(|c| c.is_alphanumeric() || c == '-') {
            out.insert(name.trim_end_matches('-').to_string());
        }
    }
    out
}

/// `docs/cli.md` says what `--help` says: each command's row names every flag its
/// `--help` lists (or the shared-flags table does, for a flag shared by commands), and
/// names no flag the command does not take.
#[test]
fn the_cli_page_names_every_flag_help_lists() {
    let page = std::fs::read_to_string("docs/cli.md").expect("docs/cli.md");
    let shared_at = page.find("## Shared flags").expect("docs/cli.md has a Shared flags section");
    let shared_end = page[shared_at + 3..].find("\n## ").map_or(page.len(), |e| shared_at + 3 + e);
    let shared = flags_in(&page[shared_at..shared_end]);
    let help = |args: &[&str]| {
        let out = scnc(args);
        assert_eq!(out.status.code(), Some(0), "{args:?}");
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let top = help(&["--help"]);
    let commands: Vec<&str> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 10, "{commands:?}");
    let mut failures = Vec::new();
    let mut shared_used = std::collections::BTreeSet::new();
    for command in commands {
        let prefix = format!("| `scnc {command}");
        let Some(row) = page.lines().find(|l| l.starts_with(&prefix)) else {
            failures.push(format!("docs/cli.md has no row for `scnc {command}`"));
            continue;
        };
        let mut documented = flags_in(row);
        // `watch` takes `render`'s flags, and its row says so.
        if row.contains("same flags as `render`") {
            let render = page.lines().find(|l| l.starts_with("| `scnc render")).unwrap_or("");
            documented.extend(flags_in(render));
        }
        // Options are listed as `  -o, --output <OUTPUT>` or `      --stats`; a row may
        // give the short form (`-o OUT.png`).
        let mut listed = std::collections::BTreeSet::new();
        for line in help(&[command, "--help"]).lines().map(str::trim_start).filter(|l| l.starts_with('-')) {
            let head = line.split("  ").next().unwrap_or("");
            let short = head
                .strip_prefix('-')
                .and_then(|h| h.chars().next())
                .filter(|c| c.is_ascii_alphabetic() && head.as_bytes().get(2) == Some(&b','));
            for f in flags_in(head).into_iter().filter(|f| f != "help" && f != "version") {
                if let Some(c) = short {
                    if row.contains(&format!(" -{c} ")) || row.contains(&format!("[-{c}]")) {
                        documented.insert(f.clone());
                    }
                }
                listed.insert(f);
            }
        }
        for f in &listed {
            if shared.contains(f) {
                shared_used.insert(f.clone());
            } else if !documented.contains(f) {
                failures.push(format!("`scnc {command} --{f}` is not in its row of docs/cli.md"));
            }
        }
        for f in documented.difference(&listed) {
            failures.push(format!("docs/cli.md names `--{f}` for `scnc {command}`, which has no such flag"));
        }
    }
    for f in shared.difference(&shared_used) {
        failures.push(format!("the shared flag `--{f}` is taken by no command"));
    }
    finish(failures);
}
