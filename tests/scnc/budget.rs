//! Work amplification: inputs whose work grows exponentially or quadratically while
//! every depth limit holds end with a clear error, judged by diagnostics and counts,
//! never by wall time. (The goldens `tests/data/diag/fuel-*`, `shape-doubling` and
//! `error-in-long-loop` pin the messages.)

use std::path::Path;

use scnc::source::FsLoader;

/// The codes of a compile's errors, in order.
fn error_codes(path: &Path) -> Vec<&'static str> {
    let text = std::fs::read_to_string(path).expect("reading the case");
    let c = scnc::compile_file("t.scn", path, text, &FsLoader);
    c.diagnostics.iter().filter(|d| d.is_error()).map(|d| d.code).collect()
}

/// Sixteen files each including the next twice would read 65,536 files: the include
/// count stops it after 1,000 with one error.
#[test]
fn doubling_includes_stop_at_the_include_count() {
    let dir = tempfile::tempdir().expect("temp dir");
    for i in 0..16 {
        let text = if i == 15 {
            "light ambient(1)\n".to_string()
        } else {
            format!("include \"f{}.scn\"\ninclude \"f{}.scn\"\n", i + 1, i + 1)
        };
        std::fs::write(dir.path().join(format!("f{i}.scn")), text).expect("write");
    }
    let codes = error_codes(&dir.path().join("f0.scn"));
    assert_eq!(codes, vec![scnc::diag::codes::INCLUDE_DEPTH], "one error: too many includes");
}

/// The same error in every iteration of a long loop is one diagnostic with a count,
/// and evaluation stops at the error cap: the loop of a million stops after 10,000.
#[test]
fn an_error_in_a_long_loop_is_reported_once() {
    let text = std::fs::read_to_string("tests/data/diag/error-in-long-loop.scn").expect("case");
    let c = scnc::compile_source("t.scn", Path::new("t.scn"), text, &FsLoader);
    let errors: Vec<_> = c.diagnostics.iter().filter(|d| d.is_error()).collect();
    assert_eq!(errors.len(), 2, "the unknown function once, then the cap: {errors:#?}");
    assert!(errors.iter().any(|d| d.notes.iter().any(|n| n == "and 9999 more times here")), "{errors:#?}");
    assert!(errors.iter().any(|d| d.code == scnc::diag::codes::TOO_MANY_ERRORS));
}

/// Doubling function calls, doubling shape DAGs and copied lists end with their own
/// error, whatever the depth limits say.
#[test]
fn doubling_work_ends_with_its_limit() {
    use scnc::diag::codes;
    for (case, code) in [
        ("fuel-doubling-calls", codes::OUT_OF_FUEL),
        ("shape-doubling", codes::SHAPE_TOO_LARGE),
        ("fuel-list-copies", codes::OUT_OF_FUEL),
    ] {
        let codes = error_codes(Path::new(&format!("tests/data/diag/{case}.scn")));
        assert_eq!(codes.first(), Some(&code), "{case}: {codes:?}");
        assert!(codes.len() <= 3, "{case}: a few errors, not one per step: {codes:?}");
    }
}

/// A compile can be cancelled part-way (the language server does so when the document
/// changes): it is asked every few thousand steps, and a yes ends it without a result.
#[test]
fn a_long_compile_asks_whether_to_go_on() {
    let path = Path::new("tests/data/diag/fuel-doubling-calls.scn");
    let text = std::fs::read_to_string(path).expect("case");
    let run = |cancel: &dyn Fn() -> bool| {
        let mut map = scnc::source::SourceMap::new();
        let root = map.add("t.scn", path, text.clone()).expect("fits");
        scnc::check::check_indexed(&mut map, root, &FsLoader, cancel).map(|(_, diags, _)| diags)
    };
    let asked = std::cell::Cell::new(0u64);
    let diags = run(&|| {
        asked.set(asked.get() + 1);
        false
    })
    .expect("not cancelled");
    assert!(diags.iter().any(|d| d.code == scnc::diag::codes::OUT_OF_FUEL));
    // Ten million steps, a question every 4,096.
    assert!((2000..=2500).contains(&asked.get()), "asked {} times", asked.get());
    let asked = std::cell::Cell::new(0u64);
    let cancelled = run(&|| {
        asked.set(asked.get() + 1);
        asked.get() == 3
    });
    assert!(cancelled.is_none(), "a yes ends the compile without a result");
    assert_eq!(asked.get(), 3, "and nothing is asked after it");
}

/// Under an address-space cap the memory limit allows more than the process can have:
/// the meshes' bytes are asked of the system before they are built, so the render ends
/// with an error naming the object (exit 1), not an allocation abort (SIGABRT).
#[cfg(target_os = "linux")]
#[test]
fn an_address_space_cap_is_an_error_not_an_abort() {
    let text = "light ambient(1)\nobject mesh uvsphere(rings = 2000, segments = 2000) at [0, 0, 5]\n";
    let dir = super::support::files(&[("big.scn", text.as_bytes())]);
    let out = dir.path().join("big.png");
    let args = ["render", "big.scn", "-o", "big.png", "--geometry", "mesh", "--width", "16", "--height", "16"];
    let run = super::support::scnc_capped(1_000_000, dir.path(), &[&args[..], &["--memory-limit", "16G"]].concat());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("the system would not give the memory"), "{stderr}");
    assert!(stderr.contains("big.scn:2:8"), "{stderr}");
    assert!(!out.exists(), "nothing written");
}

/// `==` walks values and spends fuel for it: a list that shares itself forty levels
/// deep (2⁴⁰ elements) compared with itself is equal at once (the same list), and
/// compared with an equal copy built apart it runs out of fuel with E0706 instead of
/// running for hours.
#[test]
fn equality_of_self_sharing_lists_is_counted() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut text = String::from("let a0 = [1, 1]\nlet b0 = [1, 1]\n");
    for i in 1..=40 {
        text.push_str(&format!("let a{i} = [a{p}, a{p}]\nlet b{i} = [b{p}, b{p}]\n", p = i - 1));
    }
    let tail = "object sphere(if same then 1 else 2) at [0, 0, 5]\nlight ambient(1)\n";
    let itself = dir.path().join("itself.scn");
    std::fs::write(&itself, format!("{text}let same = a40 == a40 and b40 == b40\n{tail}")).expect("write");
    assert_eq!(error_codes(&itself), Vec::<&str>::new());
    let apart = dir.path().join("apart.scn");
    std::fs::write(&apart, format!("{text}let same = a40 == b40\n{tail}")).expect("write");
    assert_eq!(error_codes(&apart), vec!["E0706"]);
}

/// A random shape of `depth` levels mixing what multiplies work: fields reading `dist`
/// of a shape twice at different points, `polar` of parts that cross their sectors,
/// `repeat`, warps, displacements, smooth and sharp CSG, over primitives.
fn random_shape(rng: &mut crate::support::Rng, depth: u32) -> String {
    const B: &str = "bounds = [[-2, -2, -2], [2, 2, 2]]";
    if depth == 0 {
        return ["sphere(0.5)", "box(0.4)", "torus(0.5, 0.1)", "cylinder(0.3, 0.5)"][rng.below(4)].to_string();
    }
    let mut sub = || random_shape(rng, depth - 1);
    let (a, b) = (sub(), sub());
    match rng.below(8) {
        0 => format!("field(p => min(dist({a}, p), dist({a}, p * 1.1)), {B})"),
        1 => format!("polar({a} at [0.3, 0, 0], 5)"),
        2 => format!("repeat({a}, [1.5, 1.5, 1.5], [3, 2, 1])"),
        3 => format!("warp({a}, p => p * 0.9, {B})"),
        4 => format!("displace({a}, p => 0.05 * sin(5 * p.x), lipschitz = 0.3)"),
        5 => format!("union({a}, {b} at [0.4, 0, 0], smooth = 0.1)"),
        6 => format!("intersect({a}, {b})"),
        _ => format!("union({a}, {b} at [1, 0, 0], field(p => dist({a}, p) - 0.1, {B}))"),
    }
}

/// The checker's estimate of one distance evaluation's work is an upper bound: over
/// random trees mixing every operation that multiplies work, the primitives evaluated
/// at any point (counted by the SDF back-end's leaves, as `--stats` counts them) never
/// exceed the estimate's, and a chain where each level reads the last twice is
/// estimated at what it evaluates (2^levels).
#[test]
fn the_cost_estimate_bounds_the_leaves_evaluated() {
    use glam::DAffine3;
    use scnc::trace::{take_leaf_evals, MaterialTable};
    let mut rng = crate::support::Rng(0xc057_e571);
    let leaves_at = |shape: &scnc::ir::Shape, rng: &mut crate::support::Rng| {
        let mut materials = MaterialTable::default();
        let (f, _) = scnc::sdf::Builder::new(&mut materials).build(shape, DAffine3::IDENTITY, 0);
        (0..64)
            .map(|_| {
                take_leaf_evals();
                f(rng.vec(2.5));
                take_leaf_evals()
            })
            .max()
            .unwrap_or(0)
    };
    let mut tight = 0;
    for case in 0..120 {
        let text = format!("light ambient(1)\nobject {}\n", random_shape(&mut rng, 1 + case % 4));
        let c = scnc::compile_source("t.scn", Path::new("t.scn"), text.clone(), &FsLoader);
        let Some(scene) = c.scene else { continue };
        let Some(scnc::ir::Body::Shape(shape)) = scene.objects.first().map(|o| o.geometry.clone()) else {
            continue;
        };
        let estimate = scnc::field::evaluation_cost(&shape);
        let measured = leaves_at(&shape, &mut rng);
        assert!(measured <= estimate.leaves, "{text}: {measured} leaves evaluated, {} estimated", estimate.leaves);
        tight += usize::from(measured == estimate.leaves);
    }
    assert!(tight > 10, "the estimate is exact on only {tight} trees");
    let mut text = String::from("let s0 = sphere(1)\n");
    for i in 1..=10 {
        let b = "bounds = [[-2, -2, -2], [2, 2, 2]]";
        text += &format!("let s{i} = field(p => min(dist(s{}, p), dist(s{}, p * 1.01)), {b})\n", i - 1, i - 1);
    }
    let shape = match &crate::support::scene(&format!("{text}light ambient(1)\nobject s10\n")).objects[0].geometry {
        scnc::ir::Body::Shape(s) => s.clone(),
        scnc::ir::Body::Mesh(_) => unreachable!("a field is a shape"),
    };
    let estimate = scnc::field::evaluation_cost(&shape);
    assert_eq!(estimate.leaves, 2047, "1024 spheres and 1023 fields");
    assert_eq!(leaves_at(&shape, &mut rng), 2047);
}

/// Work that multiplies through `dist` and `polar` is refused past the ceiling with
/// E0710 naming the object, and warned about below it (W0011), at `check`, before
/// anything runs: 20 levels of a field reading the last twice (2 M primitives per
/// evaluation; the 23 never finished), and `polar` of `polar` of `polar` of a
/// part crossing its sectors (64³ copies measured).
#[test]
fn work_multiplied_through_dist_and_polar_is_refused_or_warned() {
    let chain = |levels: usize| {
        let mut text = String::from("let s0 = sphere(1)\n");
        for i in 1..=levels {
            let b = "bounds = [[-2, -2, -2], [2, 2, 2]]";
            text += &format!("let s{i} = field(p => min(dist(s{}, p), dist(s{}, p * 1.01)), {b})\n", i - 1, i - 1);
        }
        text + &format!("light ambient(1)\nobject s{levels}\n")
    };
    let polar = |levels: usize| {
        let mut s = String::from("box(0.3) at [0.5, 0, 0]");
        for _ in 0..levels {
            s = format!("polar({s}, 64) at [0.5, 0, 0]");
        }
        format!("light ambient(1)\nobject {s}\n")
    };
    let codes = |text: String| {
        let c = scnc::compile_source("t.scn", Path::new("t.scn"), text, &FsLoader);
        let codes: Vec<&str> =
            c.diagnostics.iter().map(|d| d.code).filter(|c| c.starts_with("E07") || *c == "W0011").collect();
        (codes, c.scene.is_some())
    };
    use scnc::diag::codes::{COSTLY, TOO_COSTLY};
    assert_eq!(codes(chain(10)), (vec![], true));
    assert_eq!(codes(chain(16)), (vec![COSTLY], true));
    assert_eq!(codes(chain(20)), (vec![TOO_COSTLY], false));
    assert_eq!(codes(polar(2)), (vec![], true));
    assert_eq!(codes(polar(3)), (vec![TOO_COSTLY], false));
}
