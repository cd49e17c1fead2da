//! `scnc export`: every format read back by a real reader (stl_io, the gltf crate's
//! validating reader, the threemf crate, scnc's own OBJ reader, and a PLY header and
//! body parsed here), golden OBJ/MTL and ASCII STL files, and the errors.

use std::path::{Path, PathBuf};

use glam::DVec3;

use scnc::meshfile::{Format, WriteOptions};

use super::support::{check_golden, files, scnc};

/// Exports `scene` to `dir/name` with `extra` flags; the file's bytes.
fn export(scene: &str, dir: &Path, name: &str, extra: &[&str]) -> Vec<u8> {
    let out = dir.join(name);
    let mut args = vec!["export", scene, "-o", out.to_str().expect("utf-8 path")];
    args.extend_from_slice(extra);
    let run = scnc(&args);
    assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
    std::fs::read(&out).expect("the export")
}

/// Signed volume and bounds of a triangle soup.
fn measure(triangles: &[[DVec3; 3]]) -> (f64, DVec3, DVec3) {
    let volume = triangles.iter().map(|[a, b, c]| a.dot(b.cross(*c)) / 6.0).sum();
    let (lo, hi) =
        triangles.iter().flatten().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    (volume, lo, hi)
}

/// An STL file's triangles (read by `stl_io`) in scene units: STL is written in
/// millimetres, ten to a scene unit (a centimetre), unless `--scale` says otherwise.
fn stl_triangles(bytes: &[u8]) -> Vec<[DVec3; 3]> {
    let mesh = stl_io::read_stl(&mut std::io::Cursor::new(bytes)).expect("stl_io reads it");
    let unit = |v: usize| DVec3::from(mesh.vertices[v].0.map(f64::from)) / 10.0;
    mesh.faces.iter().map(|f| f.vertices.map(unit)).collect()
}

fn close(a: DVec3, b: DVec3, tol: f64) -> bool {
    (a - b).abs().max_element() <= tol
}

/// `unit.scn` in a Y-up right-handed frame: the sphere at x = −2, the box at x = 2
/// (mirrored z is still 0 at their centres).
const SPHERE: f64 = 4.0 * std::f64::consts::PI / 3.0;

#[test]
fn stl_reads_back_through_stl_io_with_its_volume_and_bounds() {
    let dir = tempfile::tempdir().expect("temp dir");
    for ascii in [false, true] {
        let extra: &[&str] = if ascii { &["--ascii", "--detail", "28"] } else { &["--detail", "28"] };
        let bytes = export("tests/data/export/unit.scn", dir.path(), "unit.stl", extra);
        assert_eq!(bytes.starts_with(b"solid scnc"), ascii);
        let tris = stl_triangles(&bytes);
        // Z up by default for STL: the box (side 2, at y = 1 in the scene) is at z ≈ 1.
        let box_tris: Vec<[DVec3; 3]> = tris.iter().copied().filter(|t| t[0].x > 0.0).collect();
        let sphere_tris: Vec<[DVec3; 3]> = tris.iter().copied().filter(|t| t[0].x < 0.0).collect();
        assert_eq!(box_tris.len(), 12);
        let (box_volume, _, _) = measure(&box_tris);
        assert!((box_volume - 8.0).abs() < 1e-4, "box volume {box_volume}");
        let (v, lo, hi) = measure(&sphere_tris);
        assert!((v - SPHERE).abs() < 0.01 * SPHERE, "sphere volume {v} at detail 28");
        assert!(close(lo, DVec3::new(-3.0, -1.0, -1.0), 1e-3) && close(hi, DVec3::new(-1.0, 1.0, 1.0), 1e-3));
        let (_, blo, bhi) = measure(&box_tris);
        assert!((blo.z + bhi.z) / 2.0 > 0.9, "Z is up: the box's centre is at z = 1, bounds {blo}..{bhi}");
    }
}

/// At the default `--detail high` (14 rings) a unit sphere's polyhedron holds 2.1% less
/// than the sphere: the chord error the README's accuracy table gives for 14 rings.
#[test]
fn the_default_detail_loses_the_chord_volume_and_no_more() {
    let dir = tempfile::tempdir().expect("temp dir");
    let bytes = export("tests/data/export/unit.scn", dir.path(), "unit.stl", &[]);
    let tris: Vec<[DVec3; 3]> = stl_triangles(&bytes).into_iter().filter(|t| t[0].x < 0.0).collect();
    let (v, _, _) = measure(&tris);
    assert!(v < SPHERE && v > 0.975 * SPHERE, "sphere volume {v} of {SPHERE}");
}

#[test]
fn obj_reads_back_through_scncs_reader_with_its_colours() {
    let dir = tempfile::tempdir().expect("temp dir");
    let bytes = export("tests/data/export/unit.scn", dir.path(), "unit.obj", &["--detail", "28"]);
    let mesh = scnc::meshfile::Format::Obj.read(&bytes).expect("scnc reads it");
    let text = String::from_utf8(bytes).expect("text");
    let tris: Vec<[DVec3; 3]> = mesh.triangles.iter().map(|t| t.map(|i| mesh.positions[i as usize])).collect();
    let (v, lo, _) = measure(&tris);
    // Read back into scnc's space, wound outward: the volume is positive and the
    // sphere's far side is at x = −3.
    assert!((v - 8.0 - SPHERE).abs() < 0.01 * SPHERE, "volume {v}");
    assert!((lo.x + 3.0).abs() < 1e-6, "bounds from {lo}");
    assert!(text.contains("mtllib unit.mtl\no sphere\n") && text.contains("\no box\n"));
    let mtl = std::fs::read_to_string(dir.path().join("unit.mtl")).expect("the MTL beside it");
    let kd: Vec<&str> = mtl.lines().filter(|l| l.starts_with("Kd ")).collect();
    assert_eq!(kd.len(), 2, "{mtl}");
    assert!(kd.iter().any(|l| l.starts_with("Kd 0.78431374 0.11764706 0.11764706")), "{mtl}");
}

/// Objects are named from the scene (a `let`, a function, a builtin; repeats numbered)
/// and materials by their `let`, the same in OBJ, 3MF and glb.
#[test]
fn objects_and_materials_are_named_from_the_scene() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = "tests/data/export/names.scn";
    let objects = ["wheel", "wheel_2", "bead", "bead_2", "sphere"];
    let obj = String::from_utf8(export(scene, dir.path(), "n.obj", &[])).expect("text");
    let named: Vec<&str> = obj.lines().filter_map(|l| l.strip_prefix("o ")).collect();
    assert_eq!(named, objects);
    let mtl = std::fs::read_to_string(dir.path().join("n.mtl")).expect("the MTL");
    let materials: Vec<&str> = mtl.lines().filter_map(|l| l.strip_prefix("newmtl ")).collect();
    assert_eq!(materials, ["default_grey", "gold", "material_2"]);
    let glb = export(scene, dir.path(), "n.glb", &[]);
    let gltf = gltf::Gltf::from_slice(&glb).expect("a valid glTF");
    let nodes: Vec<&str> = gltf.nodes().filter_map(|n| n.name()).collect();
    assert_eq!(nodes, objects);
    let used: Vec<&str> = gltf.materials().filter_map(|m| m.name()).collect();
    assert_eq!(used, ["default_grey", "gold", "material_2"]);
    let three_mf = export(scene, dir.path(), "n.3mf", &[]);
    let model = threemf::read(std::io::Cursor::new(three_mf)).expect("threemf reads it");
    let names: Vec<String> =
        model.iter().flat_map(|m| m.resources.object.iter().filter_map(|o| o.name.clone())).collect();
    assert_eq!(names, objects);
}

#[test]
fn glb_passes_the_gltf_crates_validation_with_nodes_colours_and_normals() {
    let dir = tempfile::tempdir().expect("temp dir");
    let bytes = export("tests/data/export/smooth.scn", dir.path(), "s.glb", &["--detail", "low"]);
    let gltf = gltf::Gltf::from_slice(&bytes).expect("a valid glTF");
    let blob = gltf.blob.clone().expect("a binary chunk");
    let nodes: Vec<String> = gltf.nodes().map(|n| n.name().unwrap_or("").to_string()).collect();
    assert_eq!(nodes, ["union", "uvsphere"]);
    let mut tris = Vec::new();
    let mut smooth = Vec::new();
    for mesh in gltf.meshes() {
        let mut has_normals = false;
        for p in mesh.primitives() {
            let reader = p.reader(|_| Some(&blob[..]));
            let positions: Vec<DVec3> =
                reader.read_positions().expect("positions").map(|p| DVec3::from(p.map(f64::from))).collect();
            has_normals |= reader.read_normals().is_some();
            let indices: Vec<u32> = reader.read_indices().expect("indices").into_u32().collect();
            tris.extend(indices.chunks(3).map(|c| [0, 1, 2].map(|k| positions[c[k] as usize])));
            let colour = p.material().pbr_metallic_roughness().base_color_factor();
            assert!(colour[3] == 1.0 && colour[..3].iter().all(|c| (0.0..=1.0).contains(c)));
        }
        smooth.push(has_normals);
    }
    // Normals for the smooth-shaded mesh sphere only.
    assert_eq!(smooth, [false, true]);
    let (v, _, _) = measure(&tris);
    assert!(v > 0.0, "wound outward: volume {v}");
    let colours: Vec<[f32; 4]> = gltf.materials().map(|m| m.pbr_metallic_roughness().base_color_factor()).collect();
    // rgb(255, 128, 0) in linear light.
    assert!(colours.iter().any(|c| c[0] == 1.0 && (c[1] - 0.2158605).abs() < 1e-5 && c[2] == 0.0), "{colours:?}");
}

#[test]
fn three_mf_reads_back_through_the_threemf_crate_with_units_and_colours() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A scene unit is a centimetre for printing, unless `--units` says otherwise.
    let mm = export("tests/data/export/unit.scn", dir.path(), "mm.3mf", &["--units", "mm"]);
    let mm = threemf::read(std::io::Cursor::new(mm)).expect("threemf reads it");
    assert!(matches!(mm[0].unit, threemf::model::Unit::Millimeter));
    let bytes = export("tests/data/export/unit.scn", dir.path(), "unit.3mf", &["--detail", "28"]);
    let models = threemf::read(std::io::Cursor::new(bytes.clone())).expect("threemf reads it");
    assert_eq!(models.len(), 1);
    let objects = &models[0].resources.object;
    assert_eq!(objects.len(), 2);
    assert_eq!(models[0].build.item.len(), 2);
    let mut volumes = Vec::new();
    for o in objects {
        let mesh = o.mesh.as_ref().expect("a mesh object");
        let v: Vec<DVec3> = mesh.vertices.vertex.iter().map(|v| DVec3::new(v.x, v.y, v.z)).collect();
        let tris: Vec<[DVec3; 3]> = mesh.triangles.triangle.iter().map(|t| [v[t.v1], v[t.v2], v[t.v3]]).collect();
        volumes.push(measure(&tris).0);
    }
    assert!((volumes[0] - SPHERE).abs() < 0.01 * SPHERE && (volumes[1] - 8.0).abs() < 1e-4, "{volumes:?}");
    assert!(matches!(models[0].unit, threemf::model::Unit::Centimeter));
    // The colours are core-specification base materials, which this reader skips: read
    // the model's XML for them.
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).expect("a ZIP package");
    let mut model = String::new();
    std::io::Read::read_to_string(&mut zip.by_name("3D/3dmodel.model").expect("the model part"), &mut model)
        .expect("text");
    assert!(model.contains("displaycolor=\"#C81E1E\"") && model.contains("displaycolor=\"#1EC81E\""), "{model}");
}

/// A PLY vertex: position and colour.
type PlyVertex = (DVec3, [u8; 3]);

/// A binary PLY: the header's counts, then every vertex's position and colour.
fn read_ply(bytes: &[u8]) -> (Vec<PlyVertex>, Vec<[u32; 3]>) {
    let end = bytes.windows(11).position(|w| w == b"end_header\n").expect("a header") + 11;
    let header = std::str::from_utf8(&bytes[..end]).expect("text header");
    assert!(header.starts_with("ply\nformat binary_little_endian 1.0\n"), "{header}");
    let count = |element: &str| -> usize {
        let line = header.lines().find(|l| l.starts_with(&format!("element {element} "))).expect("element");
        line.rsplit(' ').next().and_then(|n| n.parse().ok()).expect("count")
    };
    let (nv, nf) = (count("vertex"), count("face"));
    let mut at = end;
    let f32_at = |at: &mut usize| {
        let v = f32::from_le_bytes(bytes[*at..*at + 4].try_into().expect("4 bytes"));
        *at += 4;
        v as f64
    };
    let mut vertices = Vec::new();
    for _ in 0..nv {
        let p = DVec3::new(f32_at(&mut at), f32_at(&mut at), f32_at(&mut at));
        vertices.push((p, [bytes[at], bytes[at + 1], bytes[at + 2]]));
        at += 3;
    }
    let mut faces = Vec::new();
    for _ in 0..nf {
        assert_eq!(bytes[at], 3);
        let idx = |k: usize| u32::from_le_bytes(bytes[at + 1 + 4 * k..at + 5 + 4 * k].try_into().expect("4 bytes"));
        faces.push([idx(0), idx(1), idx(2)]);
        at += 13;
    }
    assert_eq!(at, bytes.len(), "nothing after the faces");
    (vertices, faces)
}

#[test]
fn ply_has_colours_per_vertex_and_the_same_solid() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (vertices, faces) =
        read_ply(&export("tests/data/export/unit.scn", dir.path(), "unit.ply", &["--detail", "28"]));
    let tris: Vec<[DVec3; 3]> = faces.iter().map(|f| f.map(|i| vertices[i as usize].0)).collect();
    let (v, _, _) = measure(&tris);
    assert!((v - 8.0 - SPHERE).abs() < 0.01 * SPHERE, "volume {v}");
    for f in &faces {
        let [a, b, c] = f.map(|i| vertices[i as usize]);
        assert!(a.1 == b.1 && b.1 == c.1, "one colour per triangle");
        let expected = if a.0.x < 0.0 { [200, 30, 30] } else { [30, 200, 30] };
        assert_eq!(a.1, expected);
    }
}

/// OBJ/MTL and ASCII STL of a small scene, byte for byte, the same with one thread or two.
#[test]
fn obj_mtl_and_ascii_stl_match_their_golden_files() {
    let dir = tempfile::tempdir().expect("temp dir");
    let data = PathBuf::from("tests/data/export");
    let mut failures = Vec::new();
    for threads in ["1", "2"] {
        let flags = ["--detail", "low", "--threads", threads];
        let obj = export("tests/data/export/small.scn", dir.path(), "small.obj", &flags);
        let mtl = std::fs::read(dir.path().join("small.mtl")).expect("mtl");
        let mut ascii = flags.to_vec();
        ascii.push("--ascii");
        let stl = export("tests/data/export/small.scn", dir.path(), "small.stl", &ascii);
        for (name, bytes) in [("small.obj", obj), ("small.mtl", mtl), ("small.stl", stl)] {
            let text = String::from_utf8(bytes).expect("text");
            failures.extend(check_golden(&data.join(name), &text));
        }
    }
    super::support::finish(failures);
}

#[test]
fn every_example_exports_to_every_format_or_names_its_unbounded_object() {
    // Formats for printing leave an unbounded object out (W0803); the others stop at it
    // unless asked to leave it out.
    let dir = tempfile::tempdir().expect("temp dir");
    let mut scenes: Vec<PathBuf> = ["examples/seed", "examples/features"]
        .iter()
        .flat_map(|d| super::support::cases(d))
        .filter(|p| !p.ends_with("lights.scn"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 15, "{scenes:?}");
    for scene in &scenes {
        for format in Format::ALL {
            let ext = format.extensions()[0];
            let out = dir.path().join(format!("out.{ext}"));
            let args = ["export", scene.to_str().expect("path"), "-o", out.to_str().expect("path"), "--detail", "low"];
            let run = scnc(&args);
            let err = String::from_utf8_lossy(&run.stderr);
            if format.for_printing() {
                assert_eq!(run.status.code(), Some(0), "{}: {err}", scene.display());
            }
            if run.status.code() == Some(0) {
                // Warnings may come first (a shell thinner than the low-detail cell loses
                // volume, W0804), never an error.
                let exported = format!("exported {}", out.display());
                assert!(err.lines().any(|l| l.starts_with(&exported)), "{}: {err}", scene.display());
                assert!(!err.contains("] Error"), "{}: {err}", scene.display());
                assert!(std::fs::metadata(&out).is_ok_and(|m| m.len() > 0));
            } else {
                assert_eq!(run.status.code(), Some(1), "{}: {err}", scene.display());
                assert!(
                    err.contains("cannot export an unbounded shape") && err.contains(".scn:"),
                    "{}: {err}",
                    scene.display()
                );
                assert!(!out.exists(), "nothing written for {}", scene.display());
                let skipped = scnc(&[&args[..], &["--skip-unbounded"]].concat());
                let err = String::from_utf8_lossy(&skipped.stderr);
                assert_eq!(skipped.status.code(), Some(0), "{}: {err}", scene.display());
                assert!(err.contains("[W0803]"), "{}: {err}", scene.display());
            }
            let _ = std::fs::remove_file(&out);
        }
    }
}

#[test]
fn bad_exports_are_clear_errors_and_write_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let at = |name: &str| dir.path().join(name).to_str().expect("path").to_string();
    let cases: [(Vec<String>, i32, &str); 7] = [
        (vec![at("x.glb"), "--up".into(), "z".into()], 2, "glTF fixes +y as up"),
        (vec![at("x.dae")], 2, "cannot tell the format of"),
        (vec![at("x.obj"), "--ascii".into()], 2, "--ascii is for STL only"),
        (vec![at("x.stl"), "--units".into(), "mm".into()], 2, "--units is for 3MF"),
        (vec![at("no/such/dir/x.stl")], 2, "does not exist"),
        (vec![at("x.stl"), "--scale".into(), "0".into()], 2, "must be a number from 1e-12 to 1e12"),
        (vec![at("x.stl"), "--scale".into(), "inf".into()], 2, "must be a number from 1e-12 to 1e12"),
    ];
    for (rest, code, message) in cases {
        let mut args = vec!["export".to_string(), "tests/data/export/small.scn".into(), "-o".into()];
        args.extend(rest);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let run = scnc(&args);
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(message), "{args:?}: {err}");
    }
    let run = scnc(&["export", "tests/data/export/plane.scn", "-o", &at("p.glb")]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1));
    assert!(err.contains("E0800") && err.contains("plane.scn:5:1") && err.contains("--skip-unbounded"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0, "nothing written");
}

#[test]
fn stats_report_each_object_closed_and_scale_multiplies_lengths() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("u.stl");
    let run = scnc(&[
        "export",
        "tests/data/export/unit.scn",
        "-o",
        out.to_str().expect("path"),
        "--stats",
        "--scale",
        "10",
        "--up",
        "y",
    ]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert!(lines[0].starts_with(&format!("exported {}: 2 objects, 740 triangles", out.display())), "{err}");
    assert!(
        lines[1].contains("sphere (tests/data/export/unit.scn:6): 728 triangles, watertight and manifold"),
        "{err}"
    );
    // A side-2 box scaled by 10: 8000 cubic units, wherever it is turned.
    assert!(lines[2].contains("12 triangles, watertight and manifold, 0 degenerate dropped, volume 8000.000"), "{err}");
}

/// Under `--tolerance` an isosurface's cells follow the error: a gyroid sheet thinner
/// than the cell a fixed detail would pick (which lost volume at it) exports watertight,
/// without warnings, its deviation from the field measured within the tolerance.
#[test]
fn a_tolerance_export_follows_a_sheet_thinner_than_a_detail_cell() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("sheet.scn");
    std::fs::write(
        &scene,
        "let g(p) = sin(450 * p.x) * cos(450 * p.y) + sin(450 * p.y) * cos(450 * p.z) + sin(450 * p.z) * cos(450 * p.x)\n\
         object field(p => max(abs(g(p)) - 0.3, length(p) - 0.8) / 16, bounds = [[-0.8, -0.8, -0.8], [0.8, 0.8, 0.8]])\n\
         light ambient(1)\n",
    )
    .expect("writing the scene");
    let out = dir.path().join("sheet.stl");
    let run = scnc(&[
        "export",
        scene.to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
        "--tolerance",
        "0.05",
        "--stats",
    ]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{err}");
    assert!(!err.contains("refining to detail") && !err.contains("W0804"), "{err}");
    assert!(err.contains("watertight and manifold"), "{err}");
    // In the file's units: an STL's scene units are written as 10 mm each.
    let deviation = err.lines().find(|l| l.contains("deviation from the surface")).expect("a deviation line");
    let max = deviation.split("max ").nth(1).and_then(|s| s.split(',').next()).expect("max");
    let max: f64 = max.parse().expect("a number");
    assert!(max > 0.0 && max <= 0.05 * 10.0, "{deviation}");
}

/// A model exported to OBJ, STL, PLY, glb or 3MF and read back with `mesh file(…)` lands
/// where it was, not mirrored: an asymmetric arrangement of boxes (which tell left from
/// right, and front from back) renders the same, pixel for pixel, as the scene itself as
/// meshes. A 3MF declared in millimetres (numbers ten times larger) reads back at its size too.
#[test]
fn an_exported_mesh_file_reads_back_where_it_was() {
    let dir = tempfile::tempdir().expect("temp dir");
    let common = "camera(position = [1.4, 2, -3.6], look_at = [0.5, 0.5, 0.5])\n\
                  render(width = 96, height = 96)\n\
                  light ambient(0.3)\nlight point(0.7) at [4, 6, -3]\n\
                  let m = material(color = rgb(200, 150, 60), specular = 30)\n";
    let scene = dir.path().join("l.scn");
    std::fs::write(
        &scene,
        format!(
            "{common}object box(1, 0.25, 0.25) at [0.5, 0, 0] with m\n\
             object box(0.25, 1, 0.25) at [-0.25, 0.75, 0] with m\n\
             object box(0.25, 0.25, 0.6) rotate [0, 20, 0] at [1.2, 0.5, 1] with m\n"
        ),
    )
    .expect("writing the scene");
    let render = |scene: &Path, out: &str, extra: &[&str]| {
        let png = dir.path().join(out);
        let mut args = vec!["render", scene.to_str().expect("utf-8"), "-o", png.to_str().expect("utf-8")];
        args.extend_from_slice(extra);
        let run = scnc(&args);
        assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
        image::open(&png).expect("a PNG").to_rgb8()
    };
    let meshed = render(&scene, "meshed.png", &["--geometry", "mesh"]);
    // OBJ, PLY and glb are y up, STL z up and in millimetres, 3MF z up in its declared
    // unit (as export writes them); every one reads back unmirrored, at its size.
    let every: Vec<(String, &[&str])> =
        Format::ALL.iter().map(|f| (format!("l.{}", f.extensions()[0]), &[][..])).collect();
    for (name, extra) in every.into_iter().chain([("mm.3mf".to_string(), &["--units", "mm", "--scale", "10"][..])]) {
        let name = name.as_str();
        let file = dir.path().join(name);
        let mut args = vec!["export", scene.to_str().expect("utf-8"), "-o", file.to_str().expect("utf-8")];
        args.extend_from_slice(extra);
        let run = scnc(&args);
        assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
        let back = dir.path().join(format!("back-{name}.scn"));
        std::fs::write(&back, format!("{common}object mesh file(\"{name}\") with m\n")).expect("writing");
        let read_back = render(&back, &format!("back-{name}.png"), &[]);
        let off = meshed.pixels().zip(read_back.pixels()).filter(|(a, b)| a != b).count();
        assert_eq!(off, 0, "{off} pixels differ between the scene as meshes and its {name} read back");
    }
    let background = meshed.pixels().filter(|p| **p == meshed[(0, 0)]).count();
    assert!(background < 96 * 96 * 9 / 10, "the boxes fill a tenth of the view");
}

/// The reproducers of what validators and slicers refused: an object with no triangle
/// of any area is left out with W0805 (it was written as an invalid empty object); an
/// object f32 cannot hold where it stands (a 0.01 sphere at 1e6, written as a flat disk
/// of volume 0) is an error with nothing written; so is a scene with nothing to write.
#[test]
fn exports_hold_only_what_a_file_can() {
    let dir = files(&[
        ("flat.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
        ("empty.scn", b"object mesh file(\"flat.obj\")\nobject box(1) at [3, 0, 0]\nlight ambient(1)\n"),
        ("far.scn", b"object sphere(0.01) at [0, 0, 1e6]\nlight ambient(1)\n"),
        ("plane.scn", b"object plane()\nlight ambient(1)\n"),
    ]);
    let path = |n: &str| dir.path().join(n).to_str().expect("utf-8").to_string();
    let run = scnc(&["export", &path("empty.scn"), "-o", &path("empty.3mf"), "--stats"]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{err}");
    assert!(err.contains("W0805") && err.contains("1 objects, 12 triangles"), "{err}");
    for (scene, says) in [("far.scn", "cannot be written where it stands"), ("plane.scn", "nothing written")] {
        let out = path(&format!("{scene}.stl"));
        let run = scnc(&["export", &path(scene), "-o", &out]);
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{scene}: {err}");
        assert!(err.contains(says), "{scene}: {err}");
        assert!(!Path::new(&out).exists(), "{scene}: a file was written");
    }
}

/// Mesh files have their own limit (2 GiB), not a scene file's 4 MiB: a 6 MB OBJ loads.
#[test]
fn mesh_files_larger_than_a_scene_file_load() {
    let mut obj = String::from("# a strip of 100,000 triangles\n");
    let n = 50_000;
    for i in 0..=n {
        let x = i as f64 / n as f64;
        obj.push_str(&format!("v {x:.9} 0.000000000 0.000000000\nv {x:.9} 0.100000000 0.000000000\n"));
    }
    for i in 0..n {
        let (a, b) = (2 * i + 1, 2 * i + 3);
        obj.push_str(&format!("f {a} {b} {}\nf {} {b} {}\n", a + 1, a + 1, b + 1));
    }
    assert!(obj.len() > 5 << 20, "the file is {} bytes", obj.len());
    let dir = files(&[
        ("big.obj", obj.as_bytes()),
        ("big.scn", b"camera(position = [0.5, 0.05, -1], look_at = [0.5, 0.05, 0])\nobject mesh file(\"big.obj\")\nlight ambient(1)\n"),
    ]);
    let png = dir.path().join("big.png");
    let run = scnc(&[
        "render",
        dir.path().join("big.scn").to_str().expect("utf-8"),
        "-o",
        png.to_str().expect("utf-8"),
        "--width",
        "32",
        "--height",
        "32",
        "--stats",
    ]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{err}");
    assert!(err.contains("100000 triangles"), "{err}");
}

/// An export never overwrites its inputs: an output naming the scene's mesh file (by
/// any spelling of its path) is a usage error, and the file is untouched.
#[test]
fn an_export_never_overwrites_its_inputs() {
    let tet = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    let dir = files(&[("tet.obj", tet), ("tet.scn", b"object mesh file(\"tet.obj\")\nlight ambient(1)\n")]);
    let scene = dir.path().join("tet.scn");
    let dotted = dir.path().join(".").join("tet.obj");
    let run = scnc(&["export", scene.to_str().expect("utf-8"), "-o", dotted.to_str().expect("utf-8")]);
    assert_eq!(run.status.code(), Some(2), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(String::from_utf8_lossy(&run.stderr).contains("is an input of the scene"));
    assert_eq!(std::fs::read(dir.path().join("tet.obj")).expect("still there"), tet);
}

/// An export says nothing about how the scene would render: no lights (W0002) or a
/// steep field (W0007) are not its business; what concerns the file still is.
#[test]
fn an_export_leaves_out_render_only_warnings() {
    let dir = files(&[(
        "s.scn",
        b"object field(p => 4 * (length(p) - 1), bounds = [[-1.1, -1.1, -1.1], [1.1, 1.1, 1.1]])\nlet unused = 1\n",
    )]);
    let scene = dir.path().join("s.scn");
    let out = dir.path().join("s.stl");
    let run = scnc(&["export", scene.to_str().expect("utf-8"), "-o", out.to_str().expect("utf-8")]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{err}");
    assert!(!err.contains("W0002") && !err.contains("W0007"), "{err}");
    assert!(err.contains("W0001"), "{err}");
}

/// The triangles and volume of `object {text}` (under an ambient light) exported to STL
/// with `extra` flags.
fn exported(text: &str, extra: &[&str]) -> (usize, f64) {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("s.scn");
    std::fs::write(&scene, format!("light ambient(1)\nobject {text}\n")).expect("writing");
    let tris = stl_triangles(&export(scene.to_str().expect("utf-8"), dir.path(), "s.stl", extra));
    (tris.len(), measure(&tris).0)
}

/// An extruded polygon (a rectangle or polygon, moved or not) is meshed exactly, as its
/// own flat faces: an L of 6 corners is 20 triangles holding exactly its volume, at any
/// detail. So is a profile with holes (the booleans taken on its outlines, the caps
/// triangulated with the holes left out): a square less a turned rectangle holds
/// exactly the difference, and less a circle the square less the circle's polygon at the
/// detail (10 sides at `low`); a disc's `shell` is a pipe.
#[test]
fn extruded_polygons_mesh_exactly_and_holes_go_through() {
    let volume_of = |text: &str| exported(text, &["--detail", "low"]);
    let l = "polygon([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]])";
    let (n, v) = volume_of(&format!("extrude({l} rotate 30 at [0.5, 0], 0.25)"));
    assert_eq!(n, 20);
    assert!((v - 3.0 * 0.5).abs() < 1e-5, "the L holds {v}, not 1.5");
    let (n, v) = volume_of("extrude(rect(0.5, 0.25) scale 2, 1)");
    assert_eq!(n, 12);
    assert!((v - 4.0).abs() < 1e-5, "{v}");
    let (n, v) = volume_of("extrude(subtract(rect(1, 1), rect(0.5, 0.25) rotate 30), 0.2)");
    assert!(n <= 32, "{n} triangles for two rectangles");
    assert!((v - 1.4).abs() < 1e-6, "the cut plate holds {v}, not 1.4");
    let polygon = |r: f64, n: f64| 0.5 * n * r * r * (std::f64::consts::TAU / n).sin();
    let (n, v) = volume_of("extrude(subtract(rect(1, 1), circle(0.4)), 0.2)");
    let exact = (4.0 - polygon(0.4, 10.0)) * 0.4;
    assert!(n <= 2 * (2 * 14 + 14), "{n} triangles for a square and a decagon");
    assert!((v - exact).abs() < 1e-6, "the holed plate holds {v}, not {exact}");
    let (_, v) = volume_of("extrude(shell(circle(0.5), 0.2), 0.5)");
    let exact = polygon(0.6, 10.0) - polygon(0.4, 10.0);
    assert!((v - exact).abs() < 1e-6, "the pipe holds {v}, not {exact}");
}

/// `elongate` and `symmetric` of a shape with a mesh of its own are that mesh cut at
/// the axes' planes (`geom::slab`), not an isosurface: an elongated sphere exports as
/// about as many triangles as the capsule primitive, holding the capsule's volume as
/// closely, and a box mirrored across `x` holds exactly the wider box's volume.
#[test]
fn elongated_and_mirrored_shapes_are_cut_from_their_childs_mesh() {
    let of = |text: &str| exported(text, &["--tolerance", "0.001"]);
    let (n_capsule, v_capsule) = of("capsule(0.5, 0.6)");
    let (n, v) = of("elongate(sphere(0.5), [0, 0.6, 0])");
    let exact = std::f64::consts::PI * 0.25 * (4.0 / 3.0 * 0.5 + 1.2);
    assert!(n < 2 * n_capsule, "{n} triangles where the capsule has {n_capsule}");
    assert!(
        (v - exact).abs() < 2.0 * (v_capsule - exact).abs().max(1e-4 * exact),
        "{v} against {exact}; capsule {n_capsule} {v_capsule}, {n}"
    );
    let (n, v) = of("symmetric(box(0.5) at [0.25, 0, 0], \"x\")");
    // The box cut across four faces: their kept halves split in three, twice over.
    assert!(n <= 28, "{n}");
    assert!((v - 1.5).abs() < 1e-6, "{v}");
}

/// A revolved circle or ring is meshed as lathes of its outlines (`geom::region`), not
/// an isosurface: a disc off the axis exports as a torus of about the torus primitive's
/// count and volume error (each is a lathe of a polygon); a ring's
/// hole is a torus turned inside out within it.
#[test]
fn revolved_circles_are_lathes() {
    let of = |text: &str| exported(text, &["--tolerance", "0.001"]);
    let pappus = |r: f64, at: f64| std::f64::consts::PI * r * r * std::f64::consts::TAU * at;
    let (n_torus, v_torus) = of("torus(1, 0.3)");
    let (n, v) = of("revolve(circle(0.3) at [1, 0])");
    // The profile's circle has the sides that keep its sagitta within the revolution's,
    // as the torus's tube does: about the torus's count and error (25,272 triangles
    // 0.13 % under against 26,244 0.12 % under; 52,488 with the revolution's sides).
    assert!(10 * n <= 11 * n_torus, "{n} triangles where the torus has {n_torus}");
    let exact = pappus(0.3, 1.0);
    assert!((v - exact).abs() <= 1.25 * (v_torus - exact).abs(), "{v} against {exact}; the torus {v_torus}");
    let (_, v) = of("revolve(subtract(circle(0.4), circle(0.2)) at [1, 0])");
    let exact = pappus(0.4, 1.0) - pappus(0.2, 1.0);
    assert!((v - exact).abs() < 1e-3 * exact, "{v} against {exact}");
}

/// 20 million triangles export to 3MF under a 3.5 GB address-space cap, all of them
/// written and nothing left beside the package. Making the meshes is the peak (2.44 GB
/// resident); the streamed writer adds a 64 KiB buffer where the whole package was built
/// in memory before (1.5 GB of XML and its ZIP: 2.58 GB peak then, same scene).
#[test]
#[cfg(target_os = "linux")]
fn twenty_million_triangles_stream_to_3mf_under_an_address_space_cap() {
    // 16,769,024 + 3,236,400 triangles.
    let text = "object sphere(1) at [-1.2, 0, 0]\nobject mesh uvsphere(r = 1, rings = 900) at [1.2, 0, 0]\n";
    let dir = super::support::files(&[("big.scn", text.as_bytes())]);
    let out = dir.path().join("big.3mf");
    let run =
        super::support::scnc_capped(3_500_000, dir.path(), &["export", "big.scn", "-o", "big.3mf", "--detail", "2048"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("2 objects, 20005424 triangles"), "{stderr}");
    // The package's directory says what the model holds, without inflating it.
    let zip = zip::ZipArchive::new(std::fs::File::open(&out).expect("the package")).expect("a ZIP");
    let model = zip.index_for_name("3D/3dmodel.model").expect("the model part");
    let mut zip = zip;
    let size = zip.by_index_raw(model).expect("its entry").size();
    assert!(size > 1_000_000_000, "the model's XML is {size} bytes");
    let left: Vec<_> = std::fs::read_dir(dir.path()).expect("dir").map(|e| e.expect("entry").file_name()).collect();
    assert_eq!(left.len(), 2, "only the scene and the package: {left:?}");
}

/// Every listed format, written and read back in the library: the same triangles (each
/// reader welds and maps the file's frame back), within f32 of the same places, from
/// each format's own default frame and scale. And the list itself: names and
/// extensions are unique, and each extension asks for its format.
#[test]
fn every_format_round_trips_through_its_reader() {
    let scene = super::support::scene(
        "object box(1, 0.5, 0.25) at [0.5, 0, 0] with material(color = rgb(200, 20, 20))\n\
         object sphere(0.5) at [-1, 0.5, 2] with material(color = rgb(20, 20, 200))\n",
    );
    let mut names = std::collections::BTreeSet::new();
    for &format in Format::ALL {
        assert!(names.insert(format.name()), "two formats are named {}", format.name());
        for ext in format.extensions() {
            assert_eq!(Format::from_extension(ext), Some(format));
            assert_eq!(Format::from_extension(&ext.to_uppercase()), Some(format));
        }
        let frame = scnc::export::Placement { up: format.default_up(), scale: format.default_scale() };
        let export = scnc::export::collect(
            &scene,
            scnc::mesh::Detail::Low,
            frame,
            scnc::mesh::lower::DEFAULT_MEMORY_LIMIT,
            false,
            &scnc::source::FsLoader,
        )
        .expect("meshes");
        let mut bytes = Vec::new();
        format.write(&export, &WriteOptions::default(), &mut bytes).expect("writes");
        let back = format.read(&bytes).unwrap_or_else(|e| panic!("{}: {e}", format.name()));
        assert_eq!(back.triangles.len(), export.triangle_count(), "{}", format.name());
        // In scene space, where the export's own vertices map back to.
        let bounds = |points: &mut dyn Iterator<Item = DVec3>| {
            points.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
        };
        let (lo, hi) = bounds(&mut back.positions.iter().copied());
        let (want_lo, want_hi) = bounds(
            &mut export
                .parts
                .iter()
                .flat_map(|p| &p.mesh.positions)
                .map(|&p| scnc::geom::axes::from_file(p / frame.scale, frame.up)),
        );
        assert!(hi.x > 0.9 && hi.z > 2.3, "{}: the box and the sphere are there ({lo} to {hi})", format.name());
        assert!(close(lo, want_lo, 1e-5) && close(hi, want_hi, 1e-5), "{}: {lo} to {hi}", format.name());
    }
}
