//! No input panics or hangs: every prefix of every example, and deterministic random
//! mutations of them, compile to a scene or to diagnostics.

use std::path::Path;

use scnc::source::Loader;

use crate::support::Rng;

/// Serves includes from the examples but never fails on a mutated include path.
struct Examples;

impl Loader for Examples {
    fn read(&self, path: &Path) -> std::io::Result<String> {
        scnc::source::FsLoader.read(path)
    }
}

fn sources() -> Vec<(String, String)> {
    let mut out = Vec::new();
    for dir in ["examples/seed", "examples/features", "examples/animation"] {
        for path in crate::support::cases(dir) {
            let text = std::fs::read_to_string(&path).expect("example");
            out.push((path.display().to_string(), text));
        }
    }
    out
}

fn compile(path: &str, text: String) {
    let c = scnc::compile_source(path, Path::new(path), text, &Examples);
    // Whatever came out must render without panicking.
    let _ = scnc::diag::render_all(&c.diagnostics, &c.map);
    for d in &c.diagnostics {
        let _ = d.to_json(&c.map);
    }
    if let Some(scene) = &c.scene {
        let _ = scnc::ir::dump(scene, &c.map);
    }
}

#[test]
fn every_prefix_compiles_or_reports() {
    scnc::with_big_stack(|| {
        for (path, text) in sources() {
            for end in (0..=text.len()).filter(|&i| text.is_char_boundary(i)) {
                compile(&path, text[..end].to_string());
            }
        }
    })
    .expect("the compiler's thread");
}

#[test]
fn random_mutations_compile_or_report() {
    const SNIPPETS: &[&str] = &[
        "(",
        ")",
        "[",
        "]",
        "{",
        "}",
        ",",
        "=",
        "-",
        "..",
        "/*",
        "\"",
        "#",
        "1e",
        "0",
        "999999999",
        "let",
        "for",
        "mesh",
        "at",
        "with",
        "object",
        "include",
        "if",
        "then",
        "else",
        "and",
        "not",
        "==",
        "<",
        "=>",
        "&&",
        "[for i in 0..3 => ",
        " if i > 1 ",
        "ä",
        "\u{1F600}",
    ];
    scnc::with_big_stack(|| {
        let sources = sources();
        let mut rng = Rng(0x5eed_cafe_f00d);
        for n in 0..3000 {
            let (path, text) = &sources[n % sources.len()];
            let mut bytes = text.clone().into_bytes();
            for _ in 0..1 + rng.below(4) {
                let pos = rng.below(bytes.len() + 1);
                match rng.below(4) {
                    0 if !bytes.is_empty() => {
                        let i = pos.min(bytes.len() - 1);
                        bytes[i] = bytes[i].wrapping_add(1 + rng.below(255) as u8);
                    }
                    1 if !bytes.is_empty() => {
                        let end = (pos + 1 + rng.below(12)).min(bytes.len());
                        bytes.drain(pos.min(end)..end);
                    }
                    2 => {
                        let end = (pos + 1 + rng.below(20)).min(bytes.len());
                        let chunk: Vec<u8> = bytes[pos.min(end)..end].to_vec();
                        bytes.splice(pos..pos, chunk);
                    }
                    _ => {
                        let s = SNIPPETS[rng.below(SNIPPETS.len())];
                        bytes.splice(pos..pos, s.bytes());
                    }
                }
            }
            let text = String::from_utf8_lossy(&bytes).into_owned();
            compile(path, text);
        }
    })
    .expect("the compiler's thread");
}

/// Work amplification (nested unclosed blocks, doubling calls, doubling shapes, long
/// loops of errors, many names) spliced into the examples at a line start: every case
/// ends, by one of the budgets or with a scene, with a handful of diagnostics rather
/// than one per step. The budgets bound the work (fuel, shape nodes, errors), so the
/// test is judged by what it reports, not by how long it takes.
#[test]
fn amplified_examples_end_by_a_budget() {
    fn unclosed(rng: &mut Rng) -> String {
        "for i in 0..1 {\n".repeat(1 + rng.below(200))
    }
    /// `first`, then `depth` lines each doubling the one before (`step(i)` writes line
    /// `i`), then `last(depth)`.
    fn doubling(first: &str, depth: usize, step: impl Fn(usize) -> String, last: impl Fn(usize) -> String) -> String {
        let steps: String = (1..=depth).map(step).collect();
        format!("{first}\n{steps}{}\n", last(depth))
    }
    fn doubling_calls(rng: &mut Rng) -> String {
        doubling(
            "let g0(x) = x + 1",
            4 + rng.below(22),
            |i| format!("let g{i}(x) = g{}(x) + g{}(x)\n", i - 1, i - 1),
            |d| format!("object sphere(g{d}(0) * 0 + 1) at [0, 0, 9]"),
        )
    }
    fn doubling_shapes(rng: &mut Rng) -> String {
        doubling(
            "let d0 = sphere(0.1)",
            4 + rng.below(24),
            |i| format!("let d{i} = union(d{}, d{} at [0.001, 0, 0])\n", i - 1, i - 1),
            |d| format!("object d{d} at [0, 0, 9]"),
        )
    }
    fn error_loop(rng: &mut Rng) -> String {
        format!("for i in 0..{} {{ object nowhere(i) }}\n", 1 + rng.below(1_000_000))
    }
    fn many_names(rng: &mut Rng) -> String {
        let n = 1 + rng.below(20_000);
        let mut s = String::from("let _n0 = 1\n");
        for i in 1..n {
            s += &format!("let _n{i} = _n0 + {i}\n");
        }
        s
    }
    let shapes: [fn(&mut Rng) -> String; 5] = [unclosed, doubling_calls, doubling_shapes, error_loop, many_names];
    scnc::with_big_stack(|| {
        let sources = sources();
        let mut rng = Rng(0xa3f1_77d0_0b1e);
        for n in 0..40 {
            let (path, text) = &sources[rng.below(sources.len())];
            let starts: Vec<usize> = std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect();
            let at = starts[rng.below(starts.len())];
            let amplified = shapes[n % shapes.len()](&mut rng);
            let text = format!("{}{amplified}{}", &text[..at], &text[at..]);
            let c = scnc::compile_source(path, Path::new(path), text, &Examples);
            assert!(c.scene.is_some() || c.diagnostics.iter().any(|d| d.is_error()), "case {n}: {path}");
            assert!(c.diagnostics.len() <= 40, "case {n} ({path}): {} diagnostics", c.diagnostics.len());
            let _ = scnc::diag::render_all(&c.diagnostics, &c.map);
        }
    })
    .expect("the compiler's thread");
}

/// The language server's questions at every position of every example and diagnostic
/// case (many of them broken files) answer without panicking, and every answer points
/// inside the compile's files.
#[test]
fn editor_queries_never_panic() {
    let mut files = sources();
    for path in crate::support::cases("tests/data/diag") {
        files.push((path.display().to_string(), std::fs::read_to_string(&path).expect("diag case")));
    }
    for (path, text) in files {
        let len = text.len() as u32;
        let a = scnc::lsp::analysis::Analysis::new(Path::new(&path), text, &scnc::source::FsLoader, &|| false)
            .expect("nothing cancels this analysis");
        let total: u32 = a.map.files().map(|(_, f)| f.base + f.text.len() as u32).max().unwrap_or(0);
        for at in 0..=len {
            if let Some((span, _)) = a.hover(at) {
                assert!(span.end <= total, "{path}:{at}: hover span {span:?} outside the files");
            }
            if let Some(def) = a.definition(at) {
                assert!(def.end <= total, "{path}:{at}: definition {def:?} outside the files");
            }
            let _ = a.references(at, true);
            let _ = a.complete(at);
        }
        let _ = a.symbols();
        let _ = a.fixable(0..len);
    }
}

/// Every builtin function of numbers and vectors, called with every combination of
/// extreme arguments (zeros of both signs, ±1, the ends of f64, tiny values), compiles
/// or reports an error: no panic.
#[test]
fn numeric_builtins_take_extreme_arguments() {
    use scnc::builtins::{Kind, Ty, BUILTINS};
    const EXTREMES: &[&str] = &["0", "-0", "1", "-1", "0.5", "1e308", "-1e308", "1e-308", "360", "-2"];
    let numeric = |t: Ty| matches!(t, Ty::Num | Ty::Int | Ty::Size | Ty::Vec3 | Ty::Linear);
    for b in BUILTINS.iter().filter(|b| b.kind() == Kind::Function) {
        if !b.params.iter().all(|p| numeric(p.ty)) || b.variadic.is_some_and(|t| !numeric(t)) {
            continue;
        }
        let n = b.params.len().clamp(1, 3);
        for combo in 0..EXTREMES.len().pow(n as u32) {
            let args: Vec<String> = (0..n)
                .map(|i| {
                    let x = EXTREMES[combo / EXTREMES.len().pow(i as u32) % EXTREMES.len()];
                    if b.params.get(i).is_some_and(|p| p.ty == Ty::Vec3) {
                        format!("[{x}, {x}, {x}]")
                    } else {
                        x.to_string()
                    }
                })
                .collect();
            let text =
                format!("let v = {}({})\nlet w = [v, v]\nobject sphere(1) at [0, 0, 5]\n", b.name, args.join(", "));
            let c = scnc::compile_source("x.scn", Path::new("x.scn"), text.clone(), &Examples);
            let errors = c.diagnostics.iter().filter(|d| d.severity == scnc::diag::Severity::Error).count();
            assert!(c.scene.is_some() || errors > 0, "{text}");
        }
    }
}

/// A `.glb` of one triangle placed through nodes `0..levels`, each listing the next
/// `fan` times (the last places the mesh): instancing that multiplies.
fn fanned_glb(levels: usize, fan: usize) -> Vec<u8> {
    let bin: Vec<u8> =
        [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    let mut nodes: Vec<serde_json::Value> =
        (0..levels - 1).map(|i| serde_json::json!({ "children": vec![i + 1; fan] })).collect();
    nodes.push(serde_json::json!({ "mesh": 0 }));
    let doc = serde_json::json!({
        "asset": { "version": "2.0" }, "scene": 0, "scenes": [{ "nodes": [0] }], "nodes": nodes,
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 } }] }],
        "accessors": [{ "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                        "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0] }],
        "bufferViews": [{ "buffer": 0, "byteLength": 36 }], "buffers": [{ "byteLength": 36 }],
    });
    let mut json = serde_json::to_vec(&doc).expect("json");
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// A random object mixing what multiplies work: fields reading `dist` twice, `polar`
/// of parts crossing their sectors, twists, bends, warps, displacements, `repeat`,
/// smooth CSG and instanced mesh files, nested `depth` deep.
fn random_object(rng: &mut Rng, depth: u32) -> String {
    const B: &str = "bounds = [[-2, -2, -2], [2, 2, 2]]";
    if depth == 0 {
        return ["sphere(0.5)", "box(0.4)", "torus(0.5, 0.1)", "octahedron(0.5)"][rng.below(4)].to_string();
    }
    let a = random_object(rng, depth - 1);
    let n = 2 + rng.below(12);
    match rng.below(10) {
        0 => format!("field(p => min(dist({a}, p), dist({a}, p * 1.01)), {B})"),
        1 => format!("polar({a} at [0.4, 0, 0], {n})"),
        2 => format!("twist({a}, {})", rng.below(400)),
        3 => format!("bend({a}, {})", rng.below(200)),
        4 => format!("warp({a}, p => p * 0.9, {B}, lipschitz = {})", 1 + rng.below(50)),
        5 => format!("displace({a}, p => 0.05 * sin(400 * p.x))"),
        6 => format!("repeat({a}, [1.5, 1.5, 1.5], [{n}, 2, 1])"),
        7 => format!("union({a}, {} at [0.4, 0, 0], smooth = 0.1)", random_object(rng, depth - 1)),
        _ => format!("subtract({a}, sphere(0.3))"),
    }
}

/// 180 random scenes mixing fields, `dist`, `polar`, warps and instanced mesh
/// files, rendered (SDF and mesh) and exported at small sizes by the binary: none
/// panics, every exit is 0, 1 or 2, and none runs away (each budget ends it first;
/// the work estimate bounding what is evaluated is `budget::the_cost_estimate_bounds_the_leaves_evaluated`).
#[test]
fn random_scenes_of_multiplied_work_end_cleanly() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, levels, fan) in [("small.glb", 4, 3), ("bomb.glb", 41, 16), ("wide.glb", 16, 2)] {
        std::fs::write(dir.path().join(name), fanned_glb(levels, fan)).expect("writing a glb");
    }
    let mut rng = Rng(0xf022_5eed);
    let mut codes = [0usize; 3];
    for case in 0..180 {
        let object = match rng.below(6) {
            0 => ["mesh file(\"small.glb\")", "mesh file(\"bomb.glb\")", "mesh file(\"wide.glb\")"][rng.below(3)]
                .to_string(),
            _ => {
                let depth = 1 + rng.below(4) as u32;
                random_object(&mut rng, depth)
            }
        };
        let text = format!(
            "camera(position = [0, 1, -5], look_at = [0, 0, 0])\nrender(width = 16, height = 16)\n\
             light ambient(0.3)\nlight point(1) at [3, 4, -3]\nobject {object}\n"
        );
        let path = dir.path().join("s.scn");
        std::fs::write(&path, &text).expect("writing the scene");
        let out = dir.path().join("s.png");
        let stl = dir.path().join("s.stl");
        let (p, o, e) = (path.to_str().unwrap(), out.to_str().unwrap(), stl.to_str().unwrap());
        let run = match case % 3 {
            0 => crate::support::scnc(&["render", p, "-o", o, "--threads", "1"]),
            1 => crate::support::scnc(&["render", p, "-o", o, "--threads", "1", "--geometry", "mesh", "--detail", "8"]),
            _ => crate::support::scnc(&["export", p, "-o", e, "--detail", "8"]),
        };
        let stderr = String::from_utf8_lossy(&run.stderr);
        let code = run.status.code();
        assert!(matches!(code, Some(0..=2)), "{text}: exit {code:?}\n{stderr}");
        assert!(!stderr.contains("panicked"), "{text}: {stderr}");
        codes[code.unwrap_or(0) as usize] += 1;
    }
    assert!(codes[0] > 60 && codes[1] > 5, "exits 0/1/2: {codes:?}");
}
