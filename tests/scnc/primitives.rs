//! Every builtin, constructed from its own signature and lowered by every back-end: a
//! builtin in the table that the checker, the SDF back-end or the mesh back-end does not
//! handle fails here (the matches over kinds are exhaustive, so most fail to compile).

use scnc::builtins::{Builtin, Kind, Ty, BUILTINS};

use crate::support::{coverage, scene};

use crate::conformance::MODES;

/// An argument of type `ty` that every builtin accepts where it asks for one.
fn argument(ty: Ty) -> &'static str {
    match ty {
        Ty::Num => "0.5",
        Ty::Int => "3",
        Ty::Bool => "true",
        Ty::Str => "\"tests/data/models/gem.obj\"",
        Ty::Vec3 => "[0.5, 1, 0.25]",
        Ty::Size => "1",
        Ty::Color => "rgb(200, 100, 50)",
        Ty::Material => "material()",
        Ty::Pattern => "checker(rgb(10, 20, 30), rgb(200, 100, 50), 0.25)",
        Ty::Paint => "stripes(rgb(10, 20, 30), rgb(200, 100, 50), 0.25)",
        Ty::Shape => "sphere(0.5)",
        Ty::Mesh => "mesh box(0.5)",
        Ty::Light => "ambient(1)",
        Ty::List => "[1, 2]",
        Ty::Linear => "0.5",
        Ty::FieldNum => "p => length(p) - 0.5",
        Ty::FieldVec => "p => p * [1, 1.5, 1]",
        Ty::Bounds => "[[-1, -1, -1], [1, 1, 1]]",
        Ty::Profile => "rect(0.4, 0.3)",
    }
}

/// A second variadic argument, unlike the first (a shape minus itself is empty).
fn another(ty: Ty) -> &'static str {
    match ty {
        Ty::Shape => "box(0.3) at [0.4, 0.2, 0]",
        Ty::Num => "2",
        _ => argument(ty),
    }
}

/// A call of `b` with two variadic arguments and every required parameter (and a box
/// for a field, which every mode can then mesh).
fn call(b: &Builtin) -> String {
    let mut args: Vec<String> = b.variadic.map_or(vec![], |ty| vec![argument(ty).into(), another(ty).into()]);
    args.extend(
        b.params
            .iter()
            .filter(|p| p.default == scnc::builtins::Default::Required)
            // `symmetric`'s axes are a string that is not a path.
            .map(|p| match p.name {
                "axes" => "\"xz\"".to_string(),
                "points" => "[[0.1, 0], [0.6, 0], [0.3, 0.5]]".to_string(),
                _ => argument(p.ty).to_string(),
            }),
    );
    if b.params.iter().any(|p| p.ty == Ty::Bounds) {
        args.push(format!("bounds = {}", argument(Ty::Bounds)));
    }
    format!("{}({})", b.name, args.join(", "))
}

/// The statement that uses `b`'s value in a scene.
fn statement(b: &Builtin) -> String {
    match (b.kind(), b.result) {
        (Kind::MeshGenerator, _) => format!("object mesh {}", call(b)),
        (Kind::Function, Ty::Shape) => format!("object {}", call(b)),
        (Kind::Function, Ty::Light) => format!("light {}", call(b)),
        // `dist` measures at a field's point.
        (Kind::Function, _) if b.name == "dist" => "let value = field(p => dist(sphere(0.5), p))".into(),
        (Kind::Function, _) => format!("let value = {}", call(b)),
        (Kind::Camera, _) => "camera(position = [0, 0, -4], look_at = [0, 0, 0])".into(),
        (Kind::Render, _) => "render(width = 24, height = 24)".into(),
    }
}

/// A camera that frames an object: on its bounding sphere's axis, or above a half-space.
fn framing(geometry: &scnc::ir::Body) -> String {
    match scnc::ir::bounding_sphere(geometry) {
        Some((c, r)) => format!(
            "camera(position = [{}, {}, {}], look_at = [{}, {}, {}])",
            c.x + 0.3 * r,
            c.y + 0.5 * r,
            c.z - 3.0 * r,
            c.x,
            c.y,
            c.z
        ),
        None => "camera(position = [0, 2, -5], look_at = [0, 0, 0])".into(),
    }
}

#[test]
fn every_builtin_compiles_from_its_signature() {
    for b in BUILTINS.iter() {
        let text = format!("light ambient(1)\n{}\n", statement(b));
        let s = scene(&text);
        match (b.kind(), b.result) {
            (Kind::MeshGenerator, _) | (Kind::Function, Ty::Shape) => assert_eq!(s.objects.len(), 1, "{text}"),
            (Kind::Function, Ty::Light) => assert_eq!(s.lights.len(), 2, "{text}"),
            _ => assert!(s.objects.is_empty(), "{text}"),
        }
    }
}

/// Each geometry builtin, alone and framed, shows a surface in every back-end mode, and
/// the modes agree on which pixels it covers up to its silhouette.
#[test]
fn every_geometry_builtin_renders_in_every_mode() {
    const SIZE: u32 = 32;
    for b in BUILTINS.iter().filter(|b| b.result == Ty::Shape || b.result == Ty::Mesh) {
        let object = statement(b);
        let alone = scene(&format!("{object}\n"));
        let text = format!("light ambient(1)\n{}\n{object}\n", framing(&alone.objects[0].geometry));
        let s = scene(&text);
        let per_mode: Vec<Vec<bool>> = MODES.iter().map(|&mode| coverage(&s, mode, SIZE)).collect();
        for (mode, hits) in MODES.iter().zip(&per_mode) {
            let n = hits.iter().filter(|&&h| h).count();
            assert!(n > 10, "{}: {n} pixels hit in {mode:?}\n{text}", b.name);
        }
        // Meshes of a coarse detail differ on silhouettes; a tenth of the image is far more.
        let differing = per_mode[0].iter().zip(&per_mode[2]).filter(|(a, b)| a != b).count();
        assert!(differing <= (SIZE * SIZE / 10) as usize, "{}: {differing} pixels differ, SDF vs mesh high", b.name);
    }
}

/// `tests/data/primitives.scn`, the list tests and benches read, names every builtin
/// that makes geometry.
#[test]
fn every_geometry_builtin_is_listed() {
    let text = std::fs::read_to_string("tests/data/primitives.scn").expect("reading the primitives list");
    let code: String = text.lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n");
    for b in BUILTINS.iter() {
        let listed = match (b.kind(), b.result) {
            (Kind::MeshGenerator, _) => code.contains(&format!("mesh {}(", b.name)),
            (Kind::Function, Ty::Shape) => code
                .match_indices(&format!("{}(", b.name))
                .any(|(i, _)| !code[..i].ends_with("mesh ") && !code[..i].ends_with(|c: char| c.is_alphanumeric())),
            _ => true,
        };
        assert!(listed, "`{}` is missing from tests/data/primitives.scn", b.name);
    }
    let s = crate::support::compile(std::path::Path::new("tests/data/primitives.scn"));
    assert!(s.scene.is_some(), "{}", scnc::diag::render_all(&s.diagnostics, &s.map));
}
