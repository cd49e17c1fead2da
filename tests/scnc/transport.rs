//! Light transport's hard cases, on every back-end mode: the white furnace (a surface of
//! albedo 1 in a uniform environment of radiance 1 shows 1: energy is neither created
//! nor lost), no NaN or infinity from a torture set, error falling as 1/√N, and
//! Whitted scenes untouched. Images are float radiance, small, with few samples.

use scnc::render::{effects, BitDepth, Image};
use scnc::trace::Counters;
use scnc::world::Mode;

use crate::conformance::MODES;
use crate::support::{lower, scene};

/// The scene rendered at `size × size` by `mode` as float radiance, one value per
/// channel, rows top to bottom.
fn radiance(text: &str, size: u32, mode: Mode) -> (Vec<f32>, Counters) {
    let (mut frame, world) = lower(&scene(text), size, mode);
    frame.bit_depth = BitDepth::Float;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    let (image, counters): (Image, Counters) = pool.install(|| scnc::render::render(&world, &frame, &|| {}));
    let values = image.pixels.chunks_exact(4).map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]])).collect();
    (values, counters)
}

/// Mean and standard error of the mean of `values`.
fn mean_and_error(values: &[f32]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let var = values.iter().map(|&v| (f64::from(v) - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

const FURNACE: &str = "render(samples = 16)\nlight environment(1)\n";

/// A diffuse sphere of albedo 1 in the furnace is exactly the environment: on the SDF
/// sphere every path brings back 1, whichever technique found the light. A mesh's
/// interpolated normals disagree with its facets, so some directions leave above the
/// shading normal but into the facet and scatter on inside: there the furnace holds in
/// the mean, within three standard errors and 1 %.
#[test]
fn a_white_diffuse_sphere_vanishes_in_the_furnace() {
    let text = format!("{FURNACE}object sphere(1) at [0, 0, 4] with material(color = rgb(255, 255, 255))\n");
    for mode in MODES {
        let (px, c) = radiance(&text, 24, mode);
        assert_eq!(c.nonfinite_samples, 0);
        assert!(c.light_rays > 0 && c.bounce_rays > 0, "{mode:?}: both techniques run");
        if mode == Mode::Sdf {
            for (i, v) in px.iter().enumerate() {
                assert!((v - 1.0).abs() < 1e-3, "{mode:?}: pixel {} channel {} is {v}", i / 3, i % 3);
            }
        }
        let (mean, err) = mean_and_error(&px);
        assert!((mean - 1.0).abs() <= 3.0 * err + 0.01, "{mode:?}: mean {mean} ± {err}");
    }
}

/// The glossy lobe never creates energy: at every Phong exponent the furnace shows at
/// most 1 (within three standard errors), and a dielectric coat over a white base keeps
/// nearly all of it (what grazing lobes lose below the horizon).
#[test]
fn the_glossy_lobe_never_creates_energy() {
    for exponent in [1, 20, 200, 5000] {
        let text = format!(
            "{FURNACE}object sphere(1) at [0, 0, 4] with material(color = rgb(255, 255, 255), specular = {exponent})\n"
        );
        let (px, c) = radiance(&text, 24, Mode::Sdf);
        assert_eq!(c.nonfinite_samples, 0);
        let (mean, err) = mean_and_error(&px);
        assert!(mean <= 1.0 + 3.0 * err + 1e-4, "exponent {exponent}: mean {mean} ± {err}");
        assert!(mean > 0.9, "exponent {exponent}: mean {mean}");
        assert!(px.iter().all(|&v| v <= 1.5), "exponent {exponent}: a pixel brighter than 1.5");
    }
}

/// A glass sphere and a mirror sphere conserve energy: the furnace shows 1 within three
/// standard errors of the sample noise, on every back-end.
#[test]
fn glass_and_mirrors_vanish_in_the_furnace() {
    for (what, material) in [("glass", "transparency = 1, ior = 1.5"), ("mirror", "reflective = 1")] {
        let text = format!("{FURNACE}object sphere(1) at [0, 0, 4] with material({material})\n").replace("16", "64");
        for mode in MODES {
            let (px, c) = radiance(&text, 16, mode);
            assert_eq!(c.nonfinite_samples, 0);
            let (mean, err) = mean_and_error(&px);
            assert!((mean - 1.0).abs() <= 3.0 * err + 2e-3, "{what}, {mode:?}: mean {mean} ± {err}");
        }
    }
}

/// Scenes built to break an integrator: every pixel of every one is finite.
#[test]
fn no_pixel_of_the_torture_set_is_nan_or_infinite() {
    let room = "object box(3, 0.1, 3) at [0, -1.1, 0]\n";
    let cases = [
        // Rays grazing a plane from just above it, towards a bright environment.
        ("grazing", "camera(position = [0, 1e-4, -5], look_at = [0, 1e-4, 5])\nlight environment(1)\nobject plane([0, 1, 0], 0)\n".to_string()),
        // Creases and corners of a CSG solid, lit by an area light.
        ("creases", format!("light area(5, size = [1, 1]) at [0, 2.5, 0]\n{room}object subtract(box(1), sphere(1.3)) rotate [30, 40, 0] at [0, 0, 3]\n")),
        ("zero-area light", format!("light area(5, size = [0, 0]) at [0, 2, 3]\nlight area(5, size = [1, 0]) at [0, 2, 3]\n{room}object sphere(1) at [0, 0, 3]\n")),
        ("emitter inside glass", "light environment(0.2)\nobject sphere(0.3) at [0, 0, 3] with material(emission = rgb(255, 200, 100), emission_strength = 10)\nobject sphere(1) at [0, 0, 3] with material(transparency = 1, ior = 1.5)\n".to_string()),
        ("light in a closed box", "light area(5, size = [0.5, 0.5]) at [0, 0.9, 3]\nobject subtract(box(1.1), box(1)) at [0, 0, 3]\nobject sphere(0.3) at [0, -0.7, 3]\n".to_string()),
        ("camera in a closed box", "camera(position = [0, 0, 0], look_at = [0, 0, 1])\nlight area(5, size = [0.5, 0.5]) at [0, 0.9, 0]\nobject subtract(box(1.1), box(1))\nobject sphere(0.3) at [0, -0.7, 0.5]\n".to_string()),
        ("emission 1e30", format!("{room}object sphere(0.5) at [0, 0, 3] with material(emission = rgb(255, 255, 255), emission_strength = 1e30)\n")),
        ("a sphere light touching a surface", format!("light point(2, radius = 0.5) at [0, -0.5, 3]\n{room}object sphere(0.5) at [1, -0.5, 3]\n")),
        ("a point light on a surface", format!("light point(2) at [0, -1, 3]\n{room}")),
        ("glass against glass", "light environment(1)\nobject sphere(1) at [0, 0, 3] with material(transparency = 1, ior = 1.5)\nobject sphere(1) at [1, 0, 3] with material(transparency = 1, ior = 2.4, absorption = [0.5, 0, 0])\n".to_string()),
    ];
    for (what, body) in cases {
        let text = format!("render(samples = 4, bounces = 12)\n{body}");
        for mode in MODES {
            let (px, c) = radiance(&text, 16, mode);
            assert_eq!(c.nonfinite_samples, 0, "{what}, {mode:?}");
            assert!(px.iter().all(|v| v.is_finite() && *v >= 0.0), "{what}, {mode:?}: a pixel is not finite");
        }
    }
}

/// A scene without emitters, area or environment lights or `bounces` never reaches the
/// path tracer, and one with any of them always does.
#[test]
fn light_transport_is_on_exactly_when_asked_for() {
    let whitted = "light ambient(0.2)\nlight point(1, radius = 0.3) at [2, 3, 0]\nobject sphere(1) at [0, 0, 5] with material(reflective = 0.5, transparency = 0.5)\n";
    assert_eq!(effects::derive(&scene(whitted)).light_transport, None);
    let (_, c) = radiance(whitted, 16, Mode::Sdf);
    assert_eq!((c.paths, c.light_rays, c.bounce_rays), (0, 0, 0));
    for asks in [
        "light environment(1)\n",
        "light area(1) at [0, 3, 5]\n",
        "object sphere(0.2) at [1, 1, 4] with material(emission = rgb(255, 255, 255))\n",
        "render(bounces = 2)\n",
    ] {
        let text = format!("{whitted}{asks}");
        let e = effects::derive(&scene(&text));
        assert!(e.light_transport.is_some(), "{asks}");
        assert!(!e.reflections && !e.refraction && e.ambient == 0.0, "{asks}: Whitted's effects are off");
        let (_, c) = radiance(&text, 16, Mode::Sdf);
        assert_eq!(c.paths, 256, "{asks}");
    }
    // A glow of strength 0 asks for nothing.
    let dark = format!("{whitted}object sphere(0.2) with material(emission = rgb(255, 0, 0), emission_strength = 0)\n");
    assert_eq!(effects::derive(&scene(&dark)).light_transport, None);
}

/// `bounces = 1` is direct light alone, and a second bounce only adds light: the
/// underside of a sphere above a lit floor is black with one and lit with two.
#[test]
fn one_bounce_is_direct_light_only() {
    let text = "render(samples = 16, bounces = 1)
camera(position = [0, 0.2, -4], look_at = [0, 0.2, 0])
light area(10, size = [1, 1]) at [0, 3, 0]
object box(3, 0.05, 3) at [0, -0.05, 0]
object sphere(0.5) at [0, 1, 0]\n";
    // The sphere's underside, just above its lowest point, seen from slightly below.
    let under = |px: &[f32]| {
        let i = 3 * (13 * 32 + 16);
        px[i] + px[i + 1] + px[i + 2]
    };
    let (direct, _) = radiance(text, 32, Mode::Sdf);
    let (two, _) = radiance(&text.replace("bounces = 1", "bounces = 2"), 32, Mode::Sdf);
    assert!(direct.iter().sum::<f32>() > 0.0);
    assert!(two.iter().sum::<f32>() > direct.iter().sum::<f32>(), "a second bounce adds light");
    assert_eq!(under(&direct), 0.0, "nothing lights the underside directly");
    assert!(under(&two) > 0.0, "the floor lights it");
}

/// The error against a 16× reference falls at least as 1/√N, from 4 to 1,024 samples on
/// a Cornell box, and as 1/√N in the end. The fitted slope over the whole ladder is
/// −0.55 at 12×12 and −0.45 from 256 to 1,024 samples (with the splatting film; −0.65
/// and −0.56 before it, whose gain is largest at few samples).
#[test]
fn the_error_falls_as_one_over_the_root_of_the_samples() {
    let cornell = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/light/cornell.scn"))
        .expect("the Cornell box example");
    let at = |n: u32| {
        let text = cornell.replace("samples = 64", &format!("samples = {n}"));
        radiance(&text, 12, Mode::Sdf).0
    };
    let reference = at(16 * 1024);
    let rmse = |img: &[f32]| {
        let se: f64 = img.iter().zip(&reference).map(|(a, b)| (f64::from(*a) - f64::from(*b)).powi(2)).sum();
        (se / img.len() as f64).sqrt()
    };
    let ladder: Vec<(f64, f64)> =
        [4u32, 16, 64, 256, 1024].iter().map(|&n| (f64::from(n).ln(), rmse(&at(n)).ln())).collect();
    let (mx, my) = (
        ladder.iter().map(|p| p.0).sum::<f64>() / ladder.len() as f64,
        ladder.iter().map(|p| p.1).sum::<f64>() / ladder.len() as f64,
    );
    let slope = ladder.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / ladder.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    assert!((-1.0..=-0.4).contains(&slope), "slope {slope}: {ladder:?}");
    let [.., (n0, e0), (n1, e1)] = ladder[..] else { unreachable!() };
    let last = (e1 - e0) / (n1 - n0);
    assert!((last + 0.5).abs() <= 0.1, "slope {last} from 256 to 1,024 samples: {ladder:?}");
}

/// Adaptive sampling (`render(noise = ε)`) stops a pixel once its error estimate is
/// below ε: a furnace, where every sample is exact, takes the first 16 samples of every
/// pixel; a Cornell box takes more where it is noisy and never more than `samples`.
#[test]
fn adaptive_sampling_spends_samples_where_the_noise_is() {
    let furnace = format!("{FURNACE}object sphere(1) at [0, 0, 4] with material(color = rgb(255, 255, 255))\n")
        .replace("samples = 16", "samples = 1024, noise = 0.01");
    let (_, c) = radiance(&furnace, 16, Mode::Sdf);
    assert_eq!(c.paths, 16 * 256, "every pixel stops at its first estimate");
    let cornell = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/light/cornell.scn"))
        .expect("the Cornell box example")
        .replace("samples = 64", "samples = 256, noise = 0.05");
    let (img, c) = radiance(&cornell, 12, Mode::Sdf);
    let pixels = 144;
    assert!(c.paths > 16 * pixels && c.paths < 256 * pixels, "{} paths", c.paths);
    assert_eq!(c.noise_pixels, pixels);
    // The same image again: adaptive sampling is deterministic.
    assert_eq!(radiance(&cornell, 12, Mode::Sdf).0, img);
}

/// Adaptive sampling changes how many samples a pixel takes, not what the image
/// converges to: with the film splatting each sample into its neighbours, a pixel that
/// stopped early must still weigh in them as much as one that went on. Before that
/// held, the light's edge pixels in the Cornell box took the radiance of the noisy
/// ceiling beside them (12.6 where the light is 32.6 at 256², the image's mean 3 % low).
/// Here the adaptive box at 16² is held to a fixed-sample render of it: the light's
/// pixels and the whole image's mean within a few per cent.
#[test]
fn adaptive_sampling_leaves_the_image_unbiased() {
    let cornell = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/light/cornell.scn"))
        .expect("the Cornell box example");
    let (fixed, _) = radiance(&cornell.replace("samples = 64", "samples = 1024"), 16, Mode::Sdf);
    let (adaptive, c) = radiance(&cornell.replace("samples = 64", "samples = 1024, noise = 0.05"), 16, Mode::Sdf);
    let pixels = 16 * 16;
    assert!(c.paths < 512 * pixels, "adaptive sampling stopped early somewhere: {} paths", c.paths);
    let sum = |img: &[f32], keep: &dyn Fn(usize) -> bool| -> f64 {
        img.iter().enumerate().filter(|(i, _)| keep(i / 3)).map(|(_, &v)| f64::from(v)).sum()
    };
    let all = |_: usize| true;
    let (a, f) = (sum(&adaptive, &all), sum(&fixed, &all));
    assert!((a / f - 1.0).abs() < 0.02, "the image's mean: adaptive {a} against fixed {f}");
    // The light seen directly, and the pixels beside it that its edge splats into.
    let bright = |p: usize| fixed[3 * p] > 2.0;
    let (a, f) = (sum(&adaptive, &bright), sum(&fixed, &bright));
    assert!(f > 0.0, "the light is in view");
    assert!((a / f - 1.0).abs() < 0.05, "the light's pixels: adaptive {a} against fixed {f}");
}

/// `render --pass I/N` splits the samples and `scnc merge` adds the passes into the very
/// image one render of all of them makes, bit for bit, as PNG and as OpenEXR, in any
/// order and for any split; passes that miss or repeat samples, a scene without light
/// transport, and a pass to a PNG are refused.
#[test]
fn passes_merge_into_the_image_of_one_render_bit_for_bit() {
    use crate::support::{ok, refused, scnc};
    let dir = tempfile::tempdir().expect("temp dir");
    let at = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let cornell = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/light/cornell.scn");
    let small = ["--width", "12", "--height", "12", "--samples", "10"];
    let render = |out: &str, more: &[&str]| {
        let mut args = vec!["render", cornell, "-o", out];
        args.extend_from_slice(&small);
        args.extend_from_slice(more);
        scnc(&args)
    };
    for ext in ["png", "exr"] {
        ok(&render(&at(&format!("one.{ext}")), &[]));
        for n in [2u32, 3, 10] {
            let mut passes = Vec::new();
            for i in (0..n).rev() {
                let p = at(&format!("p{i}-{n}.scnpass"));
                ok(&render(&p, &["--pass", &format!("{i}/{n}")]));
                passes.push(p);
            }
            let merged = at(&format!("merged-{n}.{ext}"));
            let mut args = vec!["merge"];
            args.extend(passes.iter().map(String::as_str));
            args.extend(["-o", &merged]);
            ok(&scnc(&args));
            let (a, b) = (std::fs::read(at(&format!("one.{ext}"))).unwrap(), std::fs::read(&merged).unwrap());
            assert!(a == b, "{n} passes merged to .{ext} differ from one render");
        }
    }
    let merged = at("m.png");
    refused(&scnc(&["merge", &at("p0-3.scnpass"), &at("p1-3.scnpass"), "-o", &merged]), 1, "some are missing");
    refused(&scnc(&["merge", &at("p0-3.scnpass"), &at("p0-2.scnpass"), "-o", &merged]), 1, "overlaps");
    refused(&render(&at("x.png"), &["--pass", "0/2"]), 2, "`.scnpass`");
    let seed = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/seed/01-sphere.scn");
    refused(&scnc(&["render", seed, "--pass", "0/2", "-o", &at("w.scnpass")]), 2, "not lit by light transport");
    assert!(!std::path::Path::new(&at("w.scnpass")).exists());
}

/// A scene lit only by what glows has lights: no "the scene has no lights" warning;
/// one with nothing that glows still gets it.
#[test]
fn a_glowing_object_is_a_light_to_the_checker() {
    let lint = |text: &str| {
        let c = scnc::compile_source("t.scn", std::path::Path::new("t.scn"), text.to_string(), &scnc::source::FsLoader);
        c.diagnostics.iter().any(|d| d.code == "W0002")
    };
    assert!(!lint("object sphere(1) at [0, 0, 5] with material(emission = rgb(255, 255, 255))\n"));
    assert!(lint(
        "object sphere(1) at [0, 0, 5] with material(emission = rgb(255, 255, 255), emission_strength = 0)\n"
    ));
    assert!(lint("object sphere(1) at [0, 0, 5]\n"));
}

/// `scnc sweep` of a light-transport scene measures the samples ladder: a table whose
/// error falls rung by rung, a CSV and a chart; a reference of the wrong size is refused.
#[test]
fn the_sweep_of_a_light_transport_scene_is_a_samples_ladder() {
    use crate::support::{ok, refused, scnc};
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("sweep");
    let out_s = out.to_str().expect("utf-8");
    let cornell = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/light/cornell.scn");
    let small = ["--width", "8", "--height", "8", "--most-samples", "64"];
    let mut args = vec!["sweep", cornell, "-o", out_s];
    args.extend_from_slice(&small);
    ok(&scnc(&args));
    let csv = std::fs::read_to_string(out.join("samples.csv")).expect("samples.csv");
    let errors: Vec<f64> =
        csv.lines().skip(1).map(|l| l.split(',').nth(2).expect("a column").parse().expect("a number")).collect();
    assert_eq!(errors.len(), 4, "1, 4, 16 and 64 samples: {csv}");
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "the error falls rung by rung: {csv}");
    assert!(std::fs::read_to_string(out.join("samples.md")).expect("samples.md").contains("Fitted slope"));
    assert!(std::fs::metadata(out.join("time-vs-error.png")).expect("the chart").len() > 1000);
    // A reference of another size.
    let wrong = dir.path().join("wrong.exr");
    ok(&scnc(&[
        "render",
        cornell,
        "-o",
        wrong.to_str().expect("utf-8"),
        "--width",
        "4",
        "--height",
        "4",
        "--samples",
        "1",
    ]));
    args.extend(["--reference", wrong.to_str().expect("utf-8")]);
    refused(&scnc(&args), 1, "the sweep renders 8×8");
}

/// `render(clamp = c)` scales down only the samples brighter than `c` in some channel:
/// above every sample it changes no pixel; low, no pixel (a mean of samples) is above
/// `c` (the small bright light is in view, and lights the floor through a glass ball),
/// and the image has lost light (clamping is biased, so it is never the default).
#[test]
fn clamping_cuts_fireflies_and_only_them() {
    let text = |clamp: &str| {
        format!(
            "camera(position = [0, 1, -4], look_at = [0, 0.5, 0])\nrender(samples = 16, bounces = 4{clamp})\n\
             object box([3, 0.05, 3]) at [0, -0.05, 0] with material(color = rgb(200, 200, 200))\n\
             object sphere(0.5) at [0, 0.5, 0] with material(color = rgb(255, 255, 255), transparency = 1, ior = 1.5)\n\
             object sphere(0.06) at [0.6, 1.6, 0.2] with material(emission = rgb(255, 240, 220), emission_strength = 400)\n"
        )
    };
    let (free, c) = radiance(&text(""), 24, Mode::Sdf);
    assert_eq!(c.clamped_samples, 0);
    let (high, c) = radiance(&text(", clamp = 1e12"), 24, Mode::Sdf);
    assert_eq!((free.clone(), 0), (high, c.clamped_samples), "a clamp above every sample is no clamp");
    let (low, c) = radiance(&text(", clamp = 2"), 24, Mode::Sdf);
    assert!(c.clamped_samples > 0);
    assert!(low.iter().all(|v| *v <= 2.0 + 1e-4), "{}", low.iter().fold(0.0f32, |a, b| a.max(*b)));
    assert!(free.iter().any(|v| *v > 2.0), "the scene has fireflies to clamp");
    let sum = |v: &[f32]| v.iter().map(|x| f64::from(*x)).sum::<f64>();
    assert!(sum(&low) < sum(&free));
}
