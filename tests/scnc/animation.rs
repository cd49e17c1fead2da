//! Animation: `clock` and `frame` evaluated at frames (goldens), and the command-line
//! contract a job system relies on: frames named by `####`, exactly the frames asked
//! for, `--skip-existing`, the task index from the environment, a frame rendered alone
//! equal to the same frame rendered in a sequence, and `scnc encode`.

use std::path::Path;

use scnc::source::FsLoader;

use crate::support::{cases, check_golden, compile, finish, ok, path, refused, scnc, scnc_env};

/// The PNG files in `dir`, sorted by name.
fn pngs(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("reading the output directory")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png"))
        .collect();
    names.sort();
    names
}

/// Every case dumped at its first, middle and last frame matches `NAME.ir`.
#[test]
fn clock_and_frame_evaluate_per_frame() {
    let mut failures = Vec::new();
    for path in cases("tests/data/time") {
        let mut c = compile(&path);
        let Some(first) = c.scene.take() else {
            failures.push(format!("{}: did not compile", path.display()));
            continue;
        };
        let declared = first.settings.clone();
        let last = declared.frames - 1;
        let mut frames = vec![0, last / 2, last];
        frames.dedup();
        let mut actual = String::new();
        for k in frames {
            let time = scnc::check::Time::of(k, &declared);
            let (scene, diags) =
                scnc::with_big_stack(|| c.frame(k, &declared, &FsLoader)).expect("the compiler's thread");
            let scene = scene.unwrap_or_else(|| panic!("{}: frame {k}:\n{diags:?}", path.display()));
            actual.push_str(&format!("== frame {k}, clock {}\n", time.clock));
            actual.push_str(&scnc::ir::dump(&scene, &c.map));
        }
        failures.extend(check_golden(&path.with_extension("ir"), &actual));
    }
    finish(failures);
}

#[test]
fn the_clock_runs_to_one_or_one_frame_short_of_it_when_cyclic() {
    let mut s = scnc::ir::Settings { frames: 5, ..Default::default() };
    let clock = |k, s: &scnc::ir::Settings| scnc::check::Time::of(k, s).clock;
    assert_eq!([0, 1, 4].map(|k| clock(k, &s)), [0.0, 0.25, 1.0]);
    s.cyclic = true;
    assert_eq!([0, 1, 4].map(|k| clock(k, &s)), [0.0, 0.2, 0.8]);
    s.frames = 1;
    assert_eq!(clock(0, &s), 0.0);
    s.cyclic = false;
    assert_eq!(clock(0, &s), 0.0);
}

const SCENE: &str = "tests/data/animation/bounce.scn";

#[test]
fn frames_a_to_b_write_exactly_those_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let pattern = dir.path().join("f-####.png");
    ok(&scnc(&["render", SCENE, "-o", path(&pattern), "--frames", "2..5"]));
    assert_eq!(pngs(dir.path()), ["f-0002.png", "f-0003.png", "f-0004.png"]);
    // A single frame by number.
    ok(&scnc(&["render", SCENE, "-o", path(&pattern), "--frames", "7"]));
    assert_eq!(pngs(dir.path()).len(), 4);
}

#[test]
fn an_animation_without_hashes_or_past_its_end_is_refused_before_any_work() {
    let dir = tempfile::tempdir().expect("tempdir");
    let one = dir.path().join("one.png");
    let out = scnc(&["render", SCENE, "-o", path(&one)]);
    refused(&out, 2, "put `#` in the file name");
    let pattern = dir.path().join("f-##.png");
    let out = scnc(&["render", SCENE, "-o", path(&pattern), "--frames", "6..9"]);
    refused(&out, 2, "frames 0..8");
    let out = scnc(&["render", "examples/seed/01-sphere.scn", "-o", path(&pattern), "--frames", "0..2"]);
    refused(&out, 2, "the scene is a still");
    assert!(pngs(dir.path()).is_empty(), "nothing may be written");
}

#[test]
fn skip_existing_renders_nothing_the_second_time() {
    let dir = tempfile::tempdir().expect("tempdir");
    let pattern = dir.path().join("f-##.png");
    let args = ["render", SCENE, "-o", path(&pattern), "--frames", "0..3", "--skip-existing"];
    ok(&scnc(&args));
    let contents = || -> Vec<Vec<u8>> {
        pngs(dir.path()).iter().map(|n| std::fs::read(dir.path().join(n)).expect("read")).collect()
    };
    let before = contents();
    // One frame lost (a task killed before it wrote) is rendered again; the rest are not.
    std::fs::remove_file(dir.path().join("f-01.png")).expect("remove");
    let out = scnc(&args);
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("skipped").count(), 2, "{err}");
    assert_eq!(err.matches("rendered").count(), 1, "{err}");
    let out = scnc(&args);
    assert_eq!(String::from_utf8_lossy(&out.stderr).matches("rendered").count(), 0);
    assert_eq!(before, contents());
}

/// A job system's task index picks a chunk; a frame rendered by its own task (lowered
/// afresh) equals the same frame rendered in a sequence (its unchanged objects reused
/// from the frame before), byte for byte.
#[test]
fn tasks_render_their_chunk_and_frames_do_not_depend_on_how_they_were_grouped() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (seq, farm) = (dir.path().join("seq"), dir.path().join("farm"));
    std::fs::create_dir_all(&seq).expect("mkdir");
    std::fs::create_dir_all(&farm).expect("mkdir");
    let farm_frames = farm.join("f-##.png");
    let task = |mode: &str, index: &str| {
        let args =
            ["render", SCENE, "-o", path(&farm_frames), "--geometry", mode, "--frame-index-from", "SCNC_TEST_TASK"];
        scnc_env(&[&args[..], &["--chunk", "3"]].concat(), &[("SCNC_TEST_TASK", index)])
    };
    for mode in ["sdf", "mesh"] {
        ok(&scnc(&["render", SCENE, "-o", path(&seq.join("f-##.png")), "--geometry", mode]));
        for index in 0..3 {
            ok(&task(mode, &index.to_string()));
        }
        assert_eq!(pngs(&farm).len(), 8, "tasks 0-2 of 3 frames cover 8 frames");
        for name in pngs(&seq) {
            let same = std::fs::read(seq.join(&name)).expect("seq") == std::fs::read(farm.join(&name)).expect("farm");
            assert!(same, "{mode}: {name} differs between the sequence and its task");
        }
    }
    let out = task("sdf", "3");
    refused(&out, 2, "tasks 0 to 2");
    let out = scnc(&["render", SCENE, "-o", path(&farm_frames), "--frame-index-from", "SCNC_NOT_SET_X"]);
    refused(&out, 2, "is not set");
}

/// An error only some frames reach is reported at that frame, naming it; a frame count
/// that changes with the clock is E0503.
#[test]
fn errors_of_later_frames_name_the_frame() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = dir.path().join("shrink.scn");
    std::fs::write(&scene, "render(width = 16, height = 16, frames = 3)\nobject sphere(1 - clock) at [0, 0, 5]\n")
        .expect("write");
    let out = scnc(&["render", path(&scene), "-o", path(&dir.path().join("f-#.png"))]);
    refused(&out, 1, "at frame 2 (clock = 1)");
    refused(&out, 1, "E0400");
    assert_eq!(pngs(dir.path()), ["f-0.png", "f-1.png"], "frames before the error are written");
    std::fs::write(&scene, "render(width = 16, height = 16, frames = 3 + frame)\nobject sphere(1) at [0, 0, 5]\n")
        .expect("write");
    let out = scnc(&["render", path(&scene), "-o", path(&dir.path().join("g-#.png"))]);
    refused(&out, 1, "E0503");
    refused(&out, 1, "at frame 0: 3 frames");
}

/// Frames encoded as a GIF and an APNG decode to as many frames of the same size; a gap
/// in the sequence, a single file and MP4 without `ffmpeg` are refused, writing nothing.
#[test]
fn encode_round_trips_frame_count_and_size() {
    use image::AnimationDecoder;
    let dir = tempfile::tempdir().expect("tempdir");
    let pattern = dir.path().join("f-###.png");
    ok(&scnc(&["render", SCENE, "-o", path(&pattern), "--frames", "0..5"]));
    let gif = dir.path().join("a.gif");
    ok(&scnc(&["encode", path(&pattern), "-o", path(&gif), "--fps", "10"]));
    let reader = std::io::BufReader::new(std::fs::File::open(&gif).expect("gif"));
    let frames = image::codecs::gif::GifDecoder::new(reader).expect("decoding").into_frames().collect_frames();
    let frames = frames.expect("frames");
    assert_eq!(frames.len(), 5);
    assert!(frames.iter().all(|f| f.buffer().dimensions() == (48, 36)));
    assert_eq!(frames[0].delay().numer_denom_ms(), (100, 1));

    let apng = dir.path().join("a.png");
    ok(&scnc(&["encode", path(&pattern), "-o", path(&apng), "--fps", "8"]));
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&apng).expect("apng")));
    let reader = decoder.read_info().expect("png header");
    let info = reader.info();
    assert_eq!((info.width, info.height), (48, 36));
    assert_eq!(info.animation_control.map(|a| a.num_frames), Some(5));
    assert_eq!(info.frame_control.map(|f| (f.delay_num, f.delay_den)), Some((1, 8)));

    let out =
        scnc_env(&["encode", path(&pattern), "-o", path(&dir.path().join("b.mp4"))], &[("PATH", path(dir.path()))]);
    refused(&out, 1, "`ffmpeg`, which is not on PATH");

    std::fs::remove_file(dir.path().join("f-002.png")).expect("remove");
    let out = scnc(&["encode", path(&pattern), "-o", path(&dir.path().join("b.gif"))]);
    refused(&out, 2, "frame 2 is missing");
    let out = scnc(&["encode", path(&dir.path().join("f-000.png")), "-o", path(&dir.path().join("b.gif"))]);
    assert_eq!(out.status.code(), Some(2));
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('b') || n.starts_with(".scnc"))
        .collect();
    assert!(names.is_empty(), "nothing half-written: {names:?}");
}

/// `scnc ir --frame K` prints the scene at frame K; a frame past the end is a usage error.
#[test]
fn ir_prints_any_frame() {
    let out = scnc(&["ir", "tests/data/time/cyclic.scn", "--frame", "2"]);
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stdout).contains("transform at [-2, 0, 6]"));
    let out = scnc(&["ir", "tests/data/time/cyclic.scn", "--frame", "4"]);
    refused(&out, 2, "frames 0..4");
}

/// A warning that holds at every frame is shown once, not once per frame.
#[test]
fn warnings_are_shown_once_per_render() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = dir.path().join("warn.scn");
    // The small spheres fit between the points of the 0.2 grid (W0801), the mesh never
    // moves (so later frames reuse it), the ball does.
    let text = "render(width = 16, height = 16, frames = 3)\nlight ambient(1)\nlet unused = 1\n\
                object mesh isosurface(union(sphere(1), [for i in 0..8 => sphere(0.04) at [i * 0.25 - 1, 1.6, 0]]), \
                cell = 0.2) at [0, 0, 5]\nobject sphere(0.2) at [2, clock, 5]\n";
    std::fs::write(&scene, text).expect("write");
    let out = scnc(&["render", path(&scene), "-o", path(&dir.path().join("f-#.png"))]);
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("W0001").count(), 1, "{err}");
    assert_eq!(err.matches("W0801").count(), 1, "{err}");
    assert_eq!(err.matches("rendered").count(), 3, "{err}");
}

/// An animation at `fps` frames per second, 16×12, three frames.
fn rated_scene(dir: &Path, fps: &str) -> std::path::PathBuf {
    let scene = dir.join("rated.scn");
    let text = format!(
        "render(width = 16, height = 12, frames = 3, fps = {fps})\nlight ambient(1)\nobject sphere(0.5 + 0.1 * clock) at [0, 0, 3]\n"
    );
    std::fs::write(&scene, text).expect("writing the scene");
    scene
}

/// The APNG's frame delay.
fn apng_delay(file: &Path) -> Option<(u16, u16)> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(file).expect("apng")));
    let reader = decoder.read_info().expect("png header");
    reader.info().frame_control.map(|f| (f.delay_num, f.delay_den))
}

#[test]
fn encode_plays_at_the_scenes_rate_unless_told_and_takes_fractional_rates() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = rated_scene(dir.path(), "10");
    let pattern = dir.path().join("f-##.png");
    ok(&scnc(&["render", path(&scene), "-o", path(&pattern)]));
    let apng = dir.path().join("a.png");
    let out = scnc(&["encode", path(&pattern), "-o", path(&apng)]);
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stderr).contains("at 10 fps (the scene's rate"), "{out:?}");
    assert_eq!(apng_delay(&apng), Some((1, 10)));
    ok(&scnc(&["encode", path(&pattern), "-o", path(&apng), "--fps", "23.976"]));
    assert_eq!(apng_delay(&apng), Some((1000, 23976)));
    let gif = dir.path().join("a.gif");
    ok(&scnc(&["encode", path(&pattern), "-o", path(&gif), "--fps", "12.5"]));
    for bad in ["0", "-3", "nan", "1001"] {
        refused(&scnc(&["encode", path(&pattern), "-o", path(&gif), &format!("--fps={bad}")]), 2, "frames per second");
    }
}

#[test]
fn an_output_that_is_an_input_is_refused_before_any_work() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = rated_scene(dir.path(), "10");
    let pattern = dir.path().join("f-##.png");
    ok(&scnc(&["render", path(&scene), "-o", path(&pattern)]));
    let before = std::fs::read(dir.path().join("f-01.png")).expect("frame 1");
    // Replacing frame 1, adding frame 6 (the next encode would include it), or the same
    // frame reached through `..`.
    let inner = dir.path().join("sub");
    std::fs::create_dir(&inner).expect("mkdir");
    for out in [dir.path().join("f-01.png"), dir.path().join("f-06.png"), inner.join("../f-02.png")] {
        refused(&scnc(&["encode", path(&pattern), "-o", path(&out)]), 2, "name another output");
    }
    assert_eq!(std::fs::read(dir.path().join("f-01.png")).expect("frame 1"), before);
    assert!(!dir.path().join("f-06.png").exists());
    // A part merged over itself.
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    ok(&scnc(&["render", path(&scene), "-o", path(&a), "--frames", "0", "--tile", "0/2"]));
    ok(&scnc(&["render", path(&scene), "-o", path(&b), "--frames", "0", "--tile", "1/2"]));
    let part = std::fs::read(&a).expect("part");
    refused(&scnc(&["merge", path(&a), path(&b), "-o", path(&a)]), 2, "is one of the parts");
    assert_eq!(std::fs::read(&a).expect("part"), part);
    // `watch` cannot keep frames that exist.
    refused(&scnc(&["watch", path(&scene), "-o", path(&pattern), "--skip-existing"]), 2, "--skip-existing");
}

#[test]
fn every_format_refuses_frames_of_two_sizes_before_encoding() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = rated_scene(dir.path(), "10");
    let pattern = dir.path().join("f-##.png");
    ok(&scnc(&["render", path(&scene), "-o", path(&pattern)]));
    ok(&scnc(&["render", path(&scene), "-o", path(&dir.path().join("f-01.png")), "--frames", "1", "--width", "20"]));
    for out in ["x.gif", "x.png", "x.mp4"] {
        // MP4 included: the sizes are checked before ffmpeg is looked for.
        let out = scnc_env(&["encode", path(&pattern), "-o", path(&dir.path().join(out))], &[("PATH", "/nonexistent")]);
        refused(&out, 2, "every frame must have one size");
    }
}

/// Memory holds one frame at a time: 40 frames of 1500×1500 (360 MB as RGBA, which the
/// old encoder held at once) encode under a 300 MB address-space limit.
#[cfg(unix)]
#[test]
fn encode_streams_its_frames_in_bounded_memory() {
    let dir = tempfile::tempdir().expect("tempdir");
    let frame = image::RgbImage::from_fn(1500, 1500, |x, y| image::Rgb([(x % 256) as u8, (y % 256) as u8, 90]));
    for i in 0..40 {
        frame.save(dir.path().join(format!("f-{i:02}.png"))).expect("writing a frame");
    }
    let out = super::support::scnc_capped(300_000, dir.path(), &["encode", "f-##.png", "-o", "a.png", "--fps", "10"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(dir.path().join("a.png")).expect("a")));
    assert_eq!(decoder.read_info().expect("header").info().animation_control.map(|a| a.num_frames), Some(40));
}

/// SIGTERM and SIGHUP (what `timeout`, `kill`, Slurm and Kubernetes send) end an
/// encode as Ctrl-C does: caught while the output's temporary file is being written, it
/// is removed, and the process ends with the shell's code for the signal.
#[cfg(unix)]
#[test]
fn a_signal_leaves_no_temporary_file_and_exits_with_its_code() {
    let dir = tempfile::tempdir().expect("tempdir");
    let frame = image::RgbImage::from_fn(1000, 1000, |x, y| image::Rgb([(x * y % 251) as u8, (x % 256) as u8, 90]));
    for i in 0..30 {
        frame.save(dir.path().join(format!("f-{i:02}.png"))).expect("writing a frame");
    }
    let temporary = || {
        std::fs::read_dir(dir.path())
            .expect("read dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with(".scnc-") || n == "a.png")
            .collect::<Vec<_>>()
    };
    for (signal, code) in [("TERM", 143), ("HUP", 129), ("INT", 130)] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_scnc"))
            .args(["encode", "f-##.png", "-o", "a.png"])
            .current_dir(dir.path())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("starting an encode");
        // Signalled once the temporary file is there (the encoder writes it frame by frame).
        let start = std::time::Instant::now();
        while temporary().is_empty() {
            assert!(start.elapsed().as_secs() < 30, "no temporary file appeared");
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        let sent = std::process::Command::new("kill").args([&format!("-{signal}"), &child.id().to_string()]).status();
        assert!(sent.expect("kill").success());
        let status = child.wait().expect("the encode ends");
        assert_eq!(status.code(), Some(code), "after SIG{signal}");
        assert!(temporary().is_empty(), "after SIG{signal}: {:?}", temporary());
    }
}
