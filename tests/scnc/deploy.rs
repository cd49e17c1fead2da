//! The job-system files in `deploy/` run as their systems would run them, each task with
//! its own index, and together write every frame of the example animation exactly once,
//! byte-identical to a local render. (`scripts/slurm-smoke.sh` runs the Slurm one on a
//! real cluster.)

use std::path::Path;
use std::process::Command;

use crate::support::scnc;

const SCENE: &str = "examples/animation/orbit.scn";
const FRAMES: usize = 48;

fn run(cmd: &mut Command) {
    let out = cmd.output().expect("running a task");
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
}

/// The frames a local render writes, by name.
fn local_frames(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let out = scnc(&["render", SCENE, "-o", dir.join("orbit-####.png").to_str().expect("utf-8")]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    read_all(dir)
}

fn read_all(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut frames: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .expect("reading frames")
        .map(|e| {
            let e = e.expect("entry");
            (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).expect("frame"))
        })
        .collect();
    frames.sort();
    frames
}

/// The value after `key` on the first line of `text` that starts with it (after indentation).
fn field<'a>(text: &'a str, key: &str) -> &'a str {
    text.lines()
        .map(str::trim_start)
        .find_map(|l| l.strip_prefix(key))
        .unwrap_or_else(|| panic!("no `{key}` line"))
        .trim()
}

#[test]
fn job_system_files_cover_every_frame_once() {
    let dir = tempfile::tempdir().expect("tempdir");
    let local = local_frames(&mkdir(dir.path().join("local")));
    assert_eq!(local.len(), FRAMES);

    // Slurm: the batch script, once per index of its `--array`, as sbatch would.
    let script = std::fs::read_to_string("deploy/slurm/render-array.sbatch").expect("sbatch file");
    let (first, last) = field(&script, "#SBATCH --array=").split_once('-').expect("an array range A-B");
    let slurm = dir.path().join("slurm");
    for task in first.parse::<u32>().expect("A")..=last.parse::<u32>().expect("B") {
        run(Command::new("bash")
            .arg("deploy/slurm/render-array.sbatch")
            .env("SCNC", env!("CARGO_BIN_EXE_scnc"))
            .env("OUT", slurm.join("orbit-####.png"))
            .env("SLURM_ARRAY_TASK_ID", task.to_string())
            .env("SLURM_CPUS_PER_TASK", "2"));
    }
    assert_eq!(read_all(&slurm), local, "Slurm array");

    // Kubernetes: the container's arguments, once per completion index, with the
    // volumes' mount paths mapped to directories here.
    let job = std::fs::read_to_string("deploy/kubernetes/render-job.yaml").expect("job file");
    assert_eq!(field(&job, "completionMode:"), "Indexed");
    let completions: u32 = field(&job, "completions:").parse().expect("completions");
    let args: Vec<String> = serde_json::from_str(field(&job, "args:")).expect("args as a flow list");
    let k8s = mkdir(dir.path().join("k8s"));
    let mapped: Vec<String> = args
        .iter()
        .map(|a| a.replace("/work/scenes", "examples/animation").replace("/work/frames", k8s.to_str().expect("utf-8")))
        .collect();
    for index in 0..completions {
        run(Command::new(env!("CARGO_BIN_EXE_scnc")).args(&mapped).env("JOB_COMPLETION_INDEX", index.to_string()));
    }
    assert_eq!(read_all(&k8s), local, "Kubernetes Indexed Job");

    // OpenJD: the render step's command once per value of its task parameter, with the
    // job parameters filled in.
    let template = std::fs::read_to_string("deploy/openjd/render.template.yaml").expect("template");
    let chunks: Vec<String> = serde_json::from_str(field(&template, "range:")).expect("chunks as a flow list");
    let args: Vec<String> = serde_json::from_str(field(&template, "args:")).expect("render args");
    let openjd = mkdir(dir.path().join("openjd"));
    for chunk in &chunks {
        let filled: Vec<String> = args
            .iter()
            .map(|a| {
                a.replace("{{Param.Scene}}", SCENE)
                    .replace("{{Param.Frames}}", openjd.to_str().expect("utf-8"))
                    .replace("{{Task.Param.Chunk}}", chunk)
            })
            .collect();
        run(Command::new(env!("CARGO_BIN_EXE_scnc")).args(&filled));
    }
    let renamed: Vec<(String, Vec<u8>)> =
        read_all(&openjd).into_iter().map(|(n, b)| (n.replace("frame-", "orbit-"), b)).collect();
    assert_eq!(renamed, local, "OpenJD template");
}

/// `path`, created as a directory.
fn mkdir(path: std::path::PathBuf) -> std::path::PathBuf {
    std::fs::create_dir_all(&path).expect("creating a directory");
    path
}
