//! Exports judged by validators that are not ours: admesh (STL) and lib3mf in strict
//! mode (3MF), both from Debian's or PyPI's packages, which `.ci/run` installs. The glb
//! files are validated by the `gltf` crate in `export.rs`.

use crate::support::scnc;

/// Scenes covering exact meshes, isosurfaces, mesh files, materials and a scene far from
/// the origin (where f32 rounding made degenerate facets and wrong normals).
const SCENES: [&str; 4] =
    ["examples/tour.scn", "examples/features/meshes.scn", "tests/data/export/far.scn", "tests/data/export/names.scn"];

/// Exports `scene` to `out` and returns scnc's count of objects and triangles.
fn export(scene: &str, out: &std::path::Path) -> (usize, usize) {
    let run = scnc(&["export", scene, "-o", out.to_str().expect("utf-8 path")]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{scene}: {err}");
    // "exported PATH: N objects, T triangles, …"
    let line = err.lines().find(|l| l.starts_with("exported ")).expect("a summary line");
    let words: Vec<&str> = line.rsplit(": ").next().expect("counts").split_whitespace().collect();
    (words[0].parse().expect("objects"), words[2].trim_end_matches(',').parse().expect("triangles"))
}

/// admesh finds every STL export closed: no disconnected or degenerate facets, no edge
/// to fix, nothing backwards, every stored normal what the corners give, one part per
/// object, and the facet count scnc reported.
pub fn admesh_finds_stl_exports_closed_and_consistent() {
    let dir = tempfile::tempdir().expect("temp dir");
    for scene in SCENES {
        let out = dir.path().join("x.stl");
        let (objects, triangles) = export(scene, &out);
        let run = std::process::Command::new("admesh").arg(&out).output().expect("admesh runs");
        let report = String::from_utf8_lossy(&run.stdout);
        assert!(run.status.success(), "{scene}: {report}");
        // "Name   :   N" (Processing Statistics) or "Name :  N   M" (original and final).
        let stat = |name: &str| -> Vec<f64> {
            let line = report.lines().find(|l| l.trim_start().starts_with(name)).expect(name);
            line.split(':').nth(1).expect("a value").split_whitespace().map_while(|w| w.parse().ok()).collect()
        };
        assert_eq!(stat("Number of facets"), [triangles as f64; 2], "{scene}: {report}");
        assert_eq!(stat("Number of parts"), [objects as f64], "{scene}: {report}");
        for zero in
            ["Total disconnected facets", "Degenerate facets", "Edges fixed", "Facets reversed", "Backwards edges"]
        {
            assert!(stat(zero).iter().all(|&v| v == 0.0), "{scene}: {zero} in\n{report}");
        }
        assert_eq!(stat("Normals fixed"), [0.0], "{scene}: {report}");
    }
}

/// lib3mf, the 3MF Consortium's library, reads every 3MF export in strict mode with no
/// warning and every object valid, in centimetres, with scnc's counts.
pub fn lib3mf_reads_3mf_exports_strictly() {
    let dir = tempfile::tempdir().expect("temp dir");
    for scene in SCENES {
        let out = dir.path().join("x.3mf");
        let (objects, triangles) = export(scene, &out);
        let run = std::process::Command::new("python3")
            .args(["tests/data/export/lib3mf_check.py", out.to_str().expect("utf-8")])
            .output()
            .expect("python3 runs");
        let said = String::from_utf8_lossy(&run.stdout);
        assert!(run.status.success(), "{scene}: {said}{}", String::from_utf8_lossy(&run.stderr));
        // lib3mf's eModelUnit: 2 is centimetre.
        let expected = format!("objects {objects} triangles {triangles} unit 2 warnings 0 invalid [] []");
        assert_eq!(said.trim(), expected, "{scene}");
    }
}

/// PrusaSlicer (Debian's `prusa-slicer`, headless) slices a two-colour export with two
/// extruders and no painting: each material is a volume with its extruder, so each layer
/// of two side-by-side parts changes tool. Without scnc's
/// `Metadata/Slic3r_PE_model.config` it printed everything with the first extruder.
pub fn prusaslicer_slices_two_colours_with_two_extruders() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("two.scn");
    std::fs::write(
        &scene,
        "let red = material(color = rgb(200, 30, 30))\nlet blue = material(color = rgb(30, 60, 200))\n\
         object box([1, 1, 1]) at [-1.2, 0, 0] with red\n\
         object union(box([1, 1, 1]) with blue, sphere(0.5) at [0, 1, 0] with red) at [1.2, 0, 0]\n",
    )
    .unwrap();
    let (threemf, gcode) = (dir.path().join("two.3mf"), dir.path().join("two.gcode"));
    let out = scnc(&["export", scene.to_str().unwrap(), "-o", threemf.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let run = std::process::Command::new("prusa-slicer")
        .args(["--export-gcode", "--nozzle-diameter", "0.4,0.4", "--temperature", "210,210"])
        .args(["--first-layer-temperature", "210,210", "--filament-diameter", "1.75,1.75", "--retract-length", "1,1"])
        .arg("-o")
        .arg(&gcode)
        .arg(&threemf)
        .output()
        .expect("prusa-slicer runs");
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let text = std::fs::read_to_string(&gcode).unwrap();
    let count = |p: &str| text.lines().filter(|l| l.starts_with(p)).count();
    let (t0, t1, layers) = (count("T0"), count("T1"), count(";LAYER_CHANGE"));
    assert!(t0 > 0 && t1 > 0, "tool changes: T0 {t0}, T1 {t1}");
    // Below the sphere both boxes print in every layer, one with each extruder.
    assert!(2 * (t0 + t1) >= layers, "{layers} layers but only {} tool changes", t0 + t1);
}
