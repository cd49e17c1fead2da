//! `scnc watch`: renders, re-renders when the scene or an included file changes, keeps
//! the last good image on errors, and ends cleanly on Ctrl-C. Every wait is bounded.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

const TIMEOUT: Duration = Duration::from_secs(30);

/// Writes `text` to `path` until a stderr line containing `want` arrives: the first
/// write may land before the watcher is set up, and repeating it is harmless.
fn write_until(path: &Path, text: &str, lines: &Receiver<String>, want: &str, log: &mut Vec<String>) {
    let deadline = Instant::now() + TIMEOUT;
    loop {
        std::fs::write(path, text).expect("writing the watched file");
        let retry = Instant::now() + Duration::from_millis(700);
        while Instant::now() < retry {
            if let Ok(line) = lines.recv_timeout(Duration::from_millis(50)) {
                log.push(line.clone());
                if line.contains(want) {
                    return;
                }
            }
        }
        assert!(Instant::now() < deadline, "no `{want}` from scnc watch; it printed:\n{}", log.join("\n"));
    }
}

fn wait_for(lines: &Receiver<String>, want: &str, log: &mut Vec<String>) {
    let deadline = Instant::now() + TIMEOUT;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let line = lines.recv_timeout(left).unwrap_or_else(|_| panic!("no `{want}`; printed:\n{}", log.join("\n")));
        log.push(line.clone());
        if line.contains(want) {
            return;
        }
    }
}

/// `scnc watch ARGS` started in `dir`, and its stderr's lines as they come.
fn start_watch(dir: &Path, args: &[&str]) -> (std::process::Child, Receiver<String>) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_scnc"))
        .arg("watch")
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starting scnc watch");
    let stderr = BufReader::new(child.stderr.take().expect("stderr"));
    let (tx, lines) = mpsc::channel();
    std::thread::spawn(move || {
        for line in stderr.lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    (child, lines)
}

#[test]
fn watch_rerenders_on_change_keeps_the_last_image_on_error_and_stops_on_ctrl_c() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("scene.scn");
    let inc = dir.path().join("inc.scn");
    let out = dir.path().join("out.png");
    let good = "include \"inc.scn\"\nobject sphere(1) at [0, 0, 5] with m\n";
    std::fs::write(&scene, good).expect("writing");
    std::fs::write(&inc, "light ambient(1)\nlet m = material(color = #ff0000)\n").expect("writing");

    let (mut child, lines) =
        start_watch(dir.path(), &["scene.scn", "-o", "out.png", "--width", "24", "--height", "24"]);
    let mut log = Vec::new();
    wait_for(&lines, "rendered out.png", &mut log);
    let red = std::fs::read(&out).expect("the first render wrote the image");

    // An included file changes: the image follows.
    write_until(&inc, "light ambient(1)\nlet m = material(color = #00ff00)\n", &lines, "rendered out.png", &mut log);
    let green = std::fs::read(&out).expect("reading the image");
    assert_ne!(red, green, "the edit to inc.scn did not change the image");

    // A mistake: diagnostics, and the last good image stays.
    write_until(&scene, "object sphere(1 at [0, 0, 5]\n", &lines, "keeps the last good image", &mut log);
    assert!(log.iter().any(|l| l.contains("E0100")), "no diagnostic printed:\n{}", log.join("\n"));
    assert_eq!(std::fs::read(&out).expect("reading the image"), green);

    // Fixed again: renders again.
    write_until(&scene, good, &lines, "rendered out.png", &mut log);

    // Ctrl-C ends it with success and leaves no temporary file behind.
    let status = Command::new("kill").args(["-INT", &child.id().to_string()]).status().expect("running kill");
    assert!(status.success());
    let deadline = Instant::now() + TIMEOUT;
    let status = loop {
        if let Some(status) = child.try_wait().expect("waiting for scnc watch") {
            break status;
        }
        assert!(Instant::now() < deadline, "scnc watch did not stop on SIGINT");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success(), "scnc watch exited with {status}");
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .expect("listing")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["inc.scn", "out.png", "scene.scn"]);
}

/// An edit that fails only at a later frame of an animation leaves every frame as it
/// was: frames are written only when the whole revision has rendered.
#[test]
fn watch_writes_an_animation_whole_or_not_at_all() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("scene.scn");
    let head = "render(width = 16, height = 12, frames = 3)\nlight ambient(1)\n";
    std::fs::write(&scene, format!("{head}object sphere(0.5 + 0.2 * clock) at [0, 0, 3]\n")).expect("writing");
    let (mut child, lines) = start_watch(dir.path(), &["scene.scn", "-o", "f-#.png"]);
    let mut log = Vec::new();
    wait_for(&lines, "wrote 3 frames of f-#.png", &mut log);
    let frames =
        || (0..3).map(|i| std::fs::read(dir.path().join(format!("f-{i}.png"))).expect("a frame")).collect::<Vec<_>>();
    let before = frames();
    // Frames 0 and 1 would change; frame 2 reaches radius 0, an error.
    let failing = format!("{head}object sphere(1 - clock) at [0, 0, 3]\n");
    write_until(&scene, &failing, &lines, "keeps the last good image", &mut log);
    assert_eq!(frames(), before, "a failed revision changed some frames:\n{}", log.join("\n"));
    let _ = Command::new("kill").args(["-INT", &child.id().to_string()]).status();
    let _ = child.wait();
    let stray: Vec<String> = std::fs::read_dir(dir.path())
        .expect("listing")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".scnc-"))
        .collect();
    assert!(stray.is_empty(), "{stray:?}");
}
