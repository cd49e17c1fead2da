//! Tests that drive programs which are not ours: Chromium (the studio's page), Neovim
//! (the editor set-up), admesh and lib3mf (validators of STL and 3MF exports).
//!
//! A test whose program is not installed is reported as `ignored` in cargo's own
//! summary, with the program it needs as its kind (`test [needs chromium]
//! studio_in_a_browser ... ignored`), so a skipped test is never counted as passed.
//! With `SCNC_REQUIRE_TOOLS=1` (set by `.ci/run`, which installs them) a missing program
//! is a failure instead. This binary has its own harness (libtest-mimic) because the
//! standard one decides what is ignored when it is compiled, not when it runs.

#![allow(dead_code, reason = "the helpers of tests/scnc are shared by path; these tests use some of them")]

mod browser;
mod neovim;
mod page;
#[path = "../scnc/studio_server.rs"]
mod studio_server;
#[path = "../scnc/support.rs"]
mod support;
mod validators;

use libtest_mimic::{Arguments, Failed, Trial};

/// A program a test drives, and how to tell whether it can run.
#[derive(Clone, Copy)]
enum Tool {
    /// A program on `PATH` that answers `--version`.
    Program(&'static str),
    /// A program on `PATH` that answers this argument (PrusaSlicer 2.5 exits 1 on
    /// `--version`, 0 on `--help`).
    Answers(&'static str, &'static str),
    /// A module Python 3 can import.
    Python(&'static str),
}

impl Tool {
    fn name(self) -> &'static str {
        match self {
            Tool::Program(n) | Tool::Answers(n, _) | Tool::Python(n) => n,
        }
    }

    fn available(self) -> bool {
        let mut probe = match self {
            Tool::Program(n) => {
                let mut c = std::process::Command::new(n);
                c.arg("--version");
                c
            }
            Tool::Answers(n, arg) => {
                let mut c = std::process::Command::new(n);
                c.arg(arg);
                c
            }
            Tool::Python(m) => {
                let mut c = std::process::Command::new("python3");
                c.args(["-c", &format!("import {m}")]);
                c
            }
        };
        probe
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    }
}

/// Whether `.ci/run` asked for every tool to be there.
fn required() -> bool {
    std::env::var_os("SCNC_REQUIRE_TOOLS").is_some_and(|v| v == "1")
}

/// A test that needs `tool`, which `.ci/run` does not install: ignored (visibly) where
/// it is missing even when the others are required.
fn optional_trial(name: &'static str, (tool, present): (Tool, bool), test: fn()) -> Trial {
    Trial::test(name, move || {
        test();
        Ok(())
    })
    .with_kind(format!("needs {}, optional", tool.name()))
    .with_ignored_flag(!present)
}

/// A test that needs `tool` (`present`: probed once, before the run): ignored (visibly)
/// where it is missing, failed where it is missing but required, run otherwise.
/// `manual` tests (measurements, the README's picture) are always ignored unless asked
/// for with `--ignored`.
fn trial(name: &'static str, (tool, present): (Tool, bool), manual: bool, test: fn()) -> Trial {
    Trial::test(name, move || {
        if !present {
            let why = if required() { " (SCNC_REQUIRE_TOOLS=1)" } else { "" };
            return Err(Failed::from(format!("`{}` is required{why} but cannot be run", tool.name())));
        }
        test();
        Ok(())
    })
    .with_kind(format!("needs {}", tool.name()))
    .with_ignored_flag(manual || (!present && !required()))
}

fn main() {
    let args = Arguments::from_args();
    let probe = |t: Tool| (t, t.available());
    let (chromium, nvim, admesh, lib3mf) = (
        probe(Tool::Program("chromium")),
        probe(Tool::Program("nvim")),
        probe(Tool::Program("admesh")),
        probe(Tool::Python("lib3mf")),
    );
    // PrusaSlicer is large and optional: `.ci/run` leaves it out (`apt-get install
    // prusa-slicer` runs its test).
    let prusa = probe(Tool::Answers("prusa-slicer", "--help"));
    if !prusa.1 {
        #[allow(clippy::print_stderr, reason = "said once, before the run, where cargo shows it")]
        {
            eprintln!("note: prusa-slicer is not installed, so its slicing test is ignored (optional)");
        }
    }
    // POV-Ray too: `apt-get install povray` runs the comparison of text layouts.
    let povray = probe(Tool::Answers("povray", "--version"));
    if !povray.1 {
        #[allow(clippy::print_stderr, reason = "said once, before the run, where cargo shows it")]
        {
            eprintln!("note: povray is not installed, so the text layout comparison is ignored (optional)");
        }
    }
    let trials = vec![
        trial("studio_in_a_browser", chromium, false, page::studio_in_a_browser),
        trial("studio_helps_as_you_work", chromium, false, page::studio_helps_as_you_work),
        trial("studio_sliders_set_parameters", chromium, false, page::studio_sliders_set_parameters),
        trial("studio_latency_on_the_seed_scenes", chromium, true, page::studio_latency_on_the_seed_scenes),
        trial("studio_screenshot_for_the_readme", chromium, true, page::studio_screenshot_for_the_readme),
        trial("neovim_config_attaches_the_server", nvim, false, neovim::neovim_config_attaches_the_server),
        trial(
            "admesh_finds_stl_exports_closed_and_consistent",
            admesh,
            false,
            validators::admesh_finds_stl_exports_closed_and_consistent,
        ),
        trial("lib3mf_reads_3mf_exports_strictly", lib3mf, false, validators::lib3mf_reads_3mf_exports_strictly),
        optional_trial(
            "prusaslicer_slices_two_colours_with_two_extruders",
            prusa,
            validators::prusaslicer_slices_two_colours_with_two_extruders,
        ),
        optional_trial("povray_lays_text_out_as_scnc_does", povray, validators::povray_lays_text_out_as_scnc_does),
    ];
    let missing: Vec<&str> =
        [chromium, nvim, admesh, lib3mf].into_iter().filter(|(_, present)| !present).map(|(t, _)| t.name()).collect();
    if !missing.is_empty() && !required() {
        #[allow(clippy::print_stderr, reason = "said once, before the run, where cargo shows it")]
        {
            eprintln!(
                "note: not installed, so their tests are ignored: {} (`.ci/run` installs them)",
                missing.join(", ")
            );
        }
    }
    libtest_mimic::run(&args, trials).exit();
}
