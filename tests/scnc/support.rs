//! Shared helpers: listing cases, comparing against golden files, compiling test input.

use std::path::{Path, PathBuf};

use scnc::source::FsLoader;
use scnc::Compiled;

/// Runs the `scnc` binary with `args` (colour off), to completion.
pub fn scnc(args: &[&str]) -> std::process::Output {
    scnc_env(args, &[])
}

/// Runs the scnc binary with `args` under an address-space cap of `kib` KiB (`ulimit
/// -v`), from `dir`: what a memory test needs to see an error, not an allocation abort.
pub fn scnc_capped(kib: u64, dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new("sh")
        .args(["-c", &format!("ulimit -v {kib} && exec \"$0\" \"$@\""), env!("CARGO_BIN_EXE_scnc")])
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("running sh")
}

/// The run succeeded.
pub fn ok(out: &std::process::Output) {
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
}

/// The run failed with `code`, saying `says`.
pub fn refused(out: &std::process::Output, code: i32, says: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{err}");
    assert!(err.contains(says), "expected `{says}` in:\n{err}");
}

/// A path as a command-line argument.
pub fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// [`scnc`] with these environment variables set as well.
pub fn scnc_env(args: &[&str], env: &[(&str, &str)]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_scnc"))
        .args(args)
        .env("NO_COLOR", "1")
        .envs(env.iter().copied())
        .output()
        .expect("running scnc")
}

/// The `.scn` files directly inside `dir`, sorted.
pub fn cases(dir: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("reading {dir}: {e}"))
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "scn"))
        .collect();
    out.sort();
    out
}

/// Compiles a file, naming it by its file name only so goldens do not depend on the checkout.
pub fn compile(path: &Path) -> Compiled {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let name = path.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned());
    scnc::compile_file(&name, path, text, &FsLoader)
}

/// Scene text compiled as the file `t.scn`, or a panic showing its diagnostics.
pub fn scene(text: &str) -> scnc::ir::Scene {
    let c = scnc::compile_source("t.scn", Path::new("t.scn"), text.to_string(), &FsLoader);
    c.scene.unwrap_or_else(|| panic!("{}\n{text}", scnc::diag::render_all(&c.diagnostics, &c.map)))
}

/// The scene at `size × size` with its derived effects, lowered by `mode`: the frame and
/// world the renderer would get.
pub fn lower(scene: &scnc::ir::Scene, size: u32, mode: scnc::world::Mode) -> (scnc::render::Frame, scnc::world::World) {
    let mut s = scene.clone();
    s.settings.width = size;
    s.settings.height = size;
    scnc::world::prepare(&s, scnc::render::effects::derive(&s), mode, &FsLoader).expect("lowering")
}

/// Which pixels of a `size × size` image hit geometry when `scene` is lowered by `mode`
/// (primary rays only, no shading).
pub fn coverage(scene: &scnc::ir::Scene, mode: scnc::world::Mode, size: u32) -> Vec<bool> {
    use scnc::trace::{Counters, Geometry, Ray};
    let (frame, world) = lower(scene, size, mode);
    let mut counters = Counters::default();
    (0..size * size)
        .map(|i| {
            let dir = frame.direction((i % size) as f32 + 0.5, (i / size) as f32 + 0.5);
            world.intersect(&Ray::new(glam::Vec3A::ZERO, dir, frame.max_distance), &mut counters).is_some()
        })
        .collect()
}

/// Whether golden files should be rewritten (`UPDATE_EXPECT=1`).
pub fn updating() -> bool {
    std::env::var_os("UPDATE_EXPECT").is_some_and(|v| v == "1")
}

/// A line diff of expected and actual, for failure messages.
pub fn diff(expected: &str, actual: &str) -> String {
    let e: Vec<&str> = expected.lines().collect();
    let a: Vec<&str> = actual.lines().collect();
    let mut out = String::new();
    for i in 0..e.len().max(a.len()) {
        match (e.get(i), a.get(i)) {
            (Some(x), Some(y)) if x == y => {}
            (x, y) => {
                if let Some(x) = x {
                    out.push_str(&format!("{:>4} - {x}\n", i + 1));
                }
                if let Some(y) = y {
                    out.push_str(&format!("{:>4} + {y}\n", i + 1));
                }
            }
        }
    }
    out
}

/// Compares `actual` with the golden file; returns a failure description, or rewrites
/// the file when updating. A missing golden file is written and reported as a failure,
/// so a new case is never silently green.
pub fn check_golden(golden: &Path, actual: &str) -> Option<String> {
    let expected = std::fs::read_to_string(golden).ok();
    if expected.as_deref() == Some(actual) {
        return None;
    }
    if updating() || expected.is_none() {
        std::fs::write(golden, actual).unwrap_or_else(|e| panic!("writing {}: {e}", golden.display()));
        if updating() {
            return None;
        }
        return Some(format!("{}: golden file was missing; written, review it and run again", golden.display()));
    }
    Some(format!(
        "{} differs (rerun with UPDATE_EXPECT=1 to accept):\n{}",
        golden.display(),
        diff(&expected.unwrap_or_default(), actual)
    ))
}

/// Panics listing every failure.
pub fn finish(failures: Vec<String>) {
    assert!(failures.is_empty(), "{} case(s) failed:\n\n{}", failures.len(), failures.join("\n\n"));
}

/// A small deterministic generator (xorshift), so failures reproduce.
pub struct Rng(pub u64);

impl Rng {
    /// The next raw value.
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in `[0, n)`.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    /// Uniform in `[0, 1)`.
    pub fn f32(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in the cube `[-r, r]³`.
    pub fn vec(&mut self, r: f32) -> glam::Vec3A {
        glam::Vec3A::new(self.f32() * 2.0 - 1.0, self.f32() * 2.0 - 1.0, self.f32() * 2.0 - 1.0) * r
    }
}

/// Writes `files` (name, bytes; a name may have directories) into a new temporary directory.
pub fn files(list: &[(&str, &[u8])]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, bytes) in list {
        let at = dir.path().join(name);
        if let Some(parent) = at.parent() {
            std::fs::create_dir_all(parent).expect("a directory");
        }
        std::fs::write(at, bytes).expect("writing");
    }
    dir
}
