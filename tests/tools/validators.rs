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

/// Text laid out by scnc and by POV-Ray's `text` object in the same font (the bundled
/// DejaVu Sans) covers the same pixels, at 256×256 without antialiasing, to 0.3 % of
/// them on both back-ends. (`scripts/text-vs-povray.sh` adds `ö`: POV-Ray does not kern
/// `W` with it, though the font's `kern` table does, so that pair differs by its 120 units.)
pub fn povray_lays_text_out_as_scnc_does() {
    let dir = tempfile::tempdir().expect("temp dir");
    let font = std::fs::canonicalize("assets/DejaVuSans.ttf").expect("the bundled font");
    let scene = dir.path().join("text.scn");
    std::fs::write(
        &scene,
        "camera(position = [1.25, 0.3, -6], look_at = [1.25, 0.3, 0], fov = 26)\n\
         render(width = 256, height = 256, background = rgb(0, 0, 0))\nlight ambient(1)\n\
         object extrude(text(\"Hello, World!\\ngyp @ 8\", size = 0.5), 0.001) rotate [-90, 0, 0] with material(rgb(255, 255, 255))\n",
    )
    .unwrap();
    // POV-Ray has no line breaks: the second line is one line height lower (DejaVu Sans:
    // ascender 1901 − descender −483 + gap 0 = 2384 of 2048 units per em).
    let pov = dir.path().join("text.pov");
    let f = font.display();
    std::fs::write(
        &pov,
        format!(
            "#version 3.7;\nglobal_settings {{ assumed_gamma 1 charset utf8 }}\n\
             camera {{ perspective location <1.25, 0.3, -6> look_at <1.25, 0.3, 0> right x up y angle 26 }}\n\
             background {{ rgb 0 }}\nunion {{\n\
             text {{ ttf \"{f}\" \"Hello, World!\" 0.002, 0 scale 0.5 }}\n\
             text {{ ttf \"{f}\" \"gyp @ 8\" 0.002, 0 scale 0.5 translate <0, -0.5 * 2384 / 2048, 0> }}\n\
             translate <0, 0, -0.001> pigment {{ rgb 1 }} finish {{ ambient 1 diffuse 0 }} }}\n"
        ),
    )
    .unwrap();
    let ppm = dir.path().join("pov.ppm");
    let run = std::process::Command::new("povray")
        .arg(format!("+I{}", pov.display()))
        .arg(format!("+O{}", ppm.display()))
        .args(["+FP", "+W256", "+H256", "-D", "-A"])
        .output()
        .expect("povray runs");
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let theirs = ppm_mask(&std::fs::read(&ppm).unwrap());
    for (mode, extra) in [("sdf", &[][..]), ("mesh", &["--geometry", "mesh", "--tolerance", "0.0002"][..])] {
        let png = dir.path().join(format!("{mode}.png"));
        let mut args = vec!["render", scene.to_str().unwrap(), "-o", png.to_str().unwrap()];
        args.extend(extra);
        let out = scnc(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let img = image::open(&png).unwrap().to_rgb8();
        let ours: Vec<bool> = img.pixels().map(|p| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]) > 381).collect();
        let differ = ours.iter().zip(&theirs).filter(|(a, b)| a != b).count();
        let ink = theirs.iter().filter(|b| **b).count();
        assert!(ink > 3000, "POV-Ray drew {ink} pixels of text");
        assert!(differ * 1000 <= 3 * ours.len(), "{mode}: {differ} of {} pixels differ from POV-Ray", ours.len());
    }
}

/// The pixels of a binary PPM (`P6`) that are lit, in reading order.
fn ppm_mask(bytes: &[u8]) -> Vec<bool> {
    let mut fields = Vec::new();
    let mut at = 0;
    while fields.len() < 4 {
        while bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        if bytes[at] == b'#' {
            while bytes[at] != b'\n' {
                at += 1;
            }
            continue;
        }
        let start = at;
        while !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        fields.push(String::from_utf8_lossy(&bytes[start..at]).into_owned());
    }
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    bytes[at + 1..at + 1 + w * h * 3]
        .chunks(3)
        .map(|p| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]) > 381)
        .collect()
}
