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

/// The sample-pass files in `deploy/` split a light-transport render's samples between
/// their tasks, and merging what the tasks wrote gives the image of one local render,
/// byte for byte (a smaller Cornell box than the example, for time).
#[test]
fn job_system_pass_files_merge_into_one_render() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenes = mkdir(dir.path().join("scenes"));
    let text = std::fs::read_to_string("examples/light/cornell.scn").expect("the Cornell box");
    let small = text.replace("width = 256, height = 256, samples = 64", "width = 24, height = 24, samples = 13");
    assert_ne!(small, text, "the example's render statement changed");
    let scene = scenes.join("cornell.scn");
    std::fs::write(&scene, small).expect("writing the scene");
    let scene = scene.to_str().expect("utf-8");
    let local = dir.path().join("local.exr");
    run(Command::new(env!("CARGO_BIN_EXE_scnc")).args(["render", scene, "-o", local.to_str().expect("utf-8")]));
    let local = std::fs::read(local).expect("the local render");
    let merged = |passes: &Path| {
        let mut files: Vec<String> =
            read_all(passes).into_iter().map(|(n, _)| passes.join(n).to_string_lossy().into_owned()).collect();
        files.retain(|f| f.ends_with(".scnpass"));
        let out = passes.join("merged.exr");
        run(Command::new(env!("CARGO_BIN_EXE_scnc")).arg("merge").args(&files).arg("-o").arg(&out));
        std::fs::read(out).expect("the merged image")
    };

    // Slurm: the batch script once per index of its `--array`.
    let script = std::fs::read_to_string("deploy/slurm/render-passes.sbatch").expect("sbatch file");
    let (first, last) = field(&script, "#SBATCH --array=").split_once('-').expect("an array range A-B");
    let slurm = dir.path().join("slurm");
    for task in first.parse::<u32>().expect("A")..=last.parse::<u32>().expect("B") {
        run(Command::new("bash")
            .arg("deploy/slurm/render-passes.sbatch")
            .env("SCNC", env!("CARGO_BIN_EXE_scnc"))
            .env("SCENE", scene)
            .env("OUT", &slurm)
            .env("SLURM_ARRAY_TASK_ID", task.to_string())
            .env("SLURM_CPUS_PER_TASK", "2"));
    }
    assert!(merged(&slurm) == local, "Slurm passes");

    // Kubernetes: the container's arguments once per completion index, `$(VAR)` filled
    // in from the pod's environment as Kubernetes does.
    let job = std::fs::read_to_string("deploy/kubernetes/render-passes-job.yaml").expect("job file");
    assert_eq!(field(&job, "completionMode:"), "Indexed");
    let completions: u32 = field(&job, "completions:").parse().expect("completions");
    let args: Vec<String> = serde_json::from_str(field(&job, "args:")).expect("args as a flow list");
    let k8s = mkdir(dir.path().join("k8s"));
    for index in 0..completions {
        let mapped: Vec<String> = args
            .iter()
            .map(|a| {
                a.replace("/work/scenes", scenes.to_str().expect("utf-8"))
                    .replace("/work/frames", k8s.to_str().expect("utf-8"))
                    .replace("$(JOB_COMPLETION_INDEX)", &index.to_string())
            })
            .collect();
        run(Command::new(env!("CARGO_BIN_EXE_scnc")).args(&mapped).env("JOB_COMPLETION_INDEX", index.to_string()));
    }
    assert!(merged(&k8s) == local, "Kubernetes passes");

    // OpenJD: the render step once per value of its task parameter, then the merge step.
    let template = std::fs::read_to_string("deploy/openjd/render-passes.template.yaml").expect("template");
    let passes: Vec<u32> = serde_json::from_str(field(&template, "range:")).expect("passes as a flow list");
    let steps: Vec<Vec<String>> = template
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("args:"))
        .map(|a| serde_json::from_str(a.trim()).expect("args as a flow list"))
        .collect();
    let openjd = mkdir(dir.path().join("openjd"));
    let fill = |a: &String, pass: Option<u32>| {
        let a = a.replace("{{Param.Scene}}", scene).replace("{{Param.Out}}", openjd.to_str().expect("utf-8"));
        pass.map_or(a.clone(), |p| a.replace("{{Task.Param.Pass}}", &p.to_string()))
    };
    for &p in &passes {
        run(Command::new(env!("CARGO_BIN_EXE_scnc")).args(steps[0].iter().map(|a| fill(a, Some(p)))));
    }
    run(Command::new(env!("CARGO_BIN_EXE_scnc")).args(steps[1].iter().map(|a| fill(a, None))));
    assert!(std::fs::read(openjd.join("image.exr")).expect("the merge step's image") == local, "OpenJD passes");
}
