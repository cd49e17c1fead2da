//! The customizer from the command line: `param` declarations, `-D`, parameter-set
//! files and `scnc params`, each held to a golden under `tests/data/params/`.

use crate::support::{check_golden, finish, scnc};

const SCENE: &str = "tests/data/params/box.scn";
const SETS: &str = "tests/data/params/sets.json";

/// What a run printed, stdout then stderr, with its exit code.
/// The output path `out` stands as `OUT.png`, so that the golden does not name a
/// temporary directory.
fn transcript(args: &[&str], out: &str) -> String {
    let shown: Vec<&str> = args.iter().map(|a| if *a == out { "OUT.png" } else { a }).collect();
    let out = scnc(args);
    format!(
        "$ scnc {}\nexit {}\n{}{}",
        shown.join(" "),
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// `scnc params` lists the parameters with their defaults, and with the values `-D` and
/// a named set give them (`-D` winning); wrong values are coded errors naming the
/// parameter and where the value came from; nothing is written on an error.
#[test]
fn parameters_are_listed_set_and_checked() {
    let out = tempfile::tempdir().unwrap();
    let png = out.path().join("box.png");
    let png = png.to_str().unwrap();
    let runs: [(&str, Vec<&str>); 6] = [
        ("listed", vec!["params", SCENE]),
        ("set", vec!["params", SCENE, "--params", SETS, "--set-name", "large", "-D", "width=60", "-D", "lid=false"]),
        (
            "wrong",
            vec![
                "render",
                SCENE,
                "-o",
                png,
                "-D",
                "width=300",
                "-D",
                "lid=maybe",
                "-D",
                "stlye=round",
                "-D",
                "tint=red",
            ],
        ),
        ("wrong-set", vec!["render", SCENE, "-o", png, "--params", SETS, "--set-name", "bad"]),
        ("no-set", vec!["render", SCENE, "-o", png, "--params", SETS, "--set-name", "huge"]),
        ("choice", vec!["check", SCENE, "-D", "style=oval", "-D", "tint=rgb(10, 20, 30)"]),
    ];
    let mut failures = Vec::new();
    for (name, args) in runs {
        let actual = transcript(&args, png);
        failures.extend(check_golden(&std::path::Path::new(SCENE).with_file_name(format!("box.{name}.txt")), &actual));
    }
    assert!(!std::path::Path::new(png).exists(), "a failed render wrote its image");
    finish(failures);
}

/// A set's values render what the same values as `-D` render, and what the file
/// renders with those values written in.
#[test]
fn a_set_a_define_and_the_written_value_render_alike() {
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let (a, b, c) = (path("a.png"), path("b.png"), path("c.png"));
    let written = std::fs::read_to_string(SCENE)
        .unwrap()
        .replace("param lid = true", "param lid = false")
        .replace("param tint = #c83232", "param tint = #3264c8");
    let file = path("written.scn");
    std::fs::write(&file, written).unwrap();
    for args in [
        vec!["render", SCENE, "-o", &a, "--params", SETS, "--set-name", "open"],
        vec!["render", SCENE, "-o", &b, "-D", "lid=false", "-D", "tint=#3264c8"],
        vec!["render", &file, "-o", &c],
    ] {
        let out = scnc(&args);
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    }
    let read = |p: &str| image::open(p).unwrap().to_rgb8();
    assert_eq!(read(&a), read(&b), "a set and -D differ");
    assert_eq!(read(&a), read(&c), "-D and the written value differ");
    let default = path("d.png");
    assert!(scnc(&["render", SCENE, "-o", &default]).status.success());
    assert_ne!(read(&a), read(&default), "the set changed nothing");
}

/// Commands that do not render leave out what only a render needs: a part with no
/// lights and no camera lists its parameters, measures and exports without a warning.
#[test]
fn commands_that_do_not_render_say_nothing_of_lights() {
    let text = "param size = 10 in 2 .. 30 \"Letter size, mm\"\nobject extrude(text(\"scnc\", size = size), 1)\n";
    let dir = crate::support::files(&[("tag.scn", text.as_bytes())]);
    let scene = dir.path().join("tag.scn");
    let out = dir.path().join("tag.stl");
    let (scene, out) = (crate::support::path(&scene), crate::support::path(&out));
    for args in [
        vec!["params", scene],
        vec!["measure", scene, "--cells", "100000"],
        vec!["export", scene, "-o", out, "-D", "size=12"],
    ] {
        let run = scnc(&args);
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{args:?}: {err}");
        assert!(!err.contains("W0002") && !err.contains("Warning"), "{args:?}: {err}");
    }
}
