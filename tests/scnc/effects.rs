//! The effect set: exact ray counts, and the specialised tracer agreeing bit for bit with
//! the general one on scenes that do not use an effect.

use std::path::Path;

use glam::Vec3A;
use scnc::render::effects::{self, Effects};
use scnc::render::Image;
use scnc::trace::{Counters, Geometry, Ray};
use scnc::world::Mode;

use crate::support::{cases, check_golden, compile, finish};

fn scene(text: &str) -> scnc::ir::Scene {
    let c = scnc::compile_source("t.scn", Path::new("t.scn"), text.to_string(), &scnc::source::FsLoader);
    c.scene.unwrap_or_else(|| panic!("{}", scnc::diag::render_all(&c.diagnostics, &c.map)))
}

/// Renders at `size`² as SDFs with the given effect set (derived when `None`), and counts
/// the pixels whose centre ray hits geometry.
fn render(s: scnc::ir::Scene, size: u32, effects: Option<Effects>) -> (Image, Counters, u64) {
    render_in(s, size, effects, Mode::Sdf)
}

/// As [`render`], with shapes lowered by `mode`.
fn render_in(mut s: scnc::ir::Scene, size: u32, effects: Option<Effects>, mode: Mode) -> (Image, Counters, u64) {
    s.settings.width = size;
    s.settings.height = size;
    let effects = effects.unwrap_or_else(|| effects::derive(&s));
    let (frame, world) = scnc::world::prepare(&s, effects, mode, &scnc::source::FsLoader).expect("lowering");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    let (img, c) = pool.install(|| scnc::render::render(&world, &frame, &|| {}));
    let mut scratch = Counters::default();
    let hits = (0..size * size)
        .filter(|i| {
            let dir = frame.direction((i % size) as f32 + 0.5, (i / size) as f32 + 0.5);
            world.intersect(&Ray::new(Vec3A::ZERO, dir, frame.max_distance), &mut scratch).is_some()
        })
        .count() as u64;
    (img, c, hits)
}

const SPHERES: &str = "object sphere(1) at [0, 0, 5] with material(color = rgb(255, 0, 0), specular = 50)
object box(0.5) rotate [20, 30, 0] at [1.5, 0.5, 6] with material(color = rgb(0, 255, 0))
";

#[test]
fn no_reflection_rays_without_a_reflective_material() {
    let (_, c, hits) =
        render(scene(&format!("light ambient(0.2)\nlight point(0.6) at [2, 1, 0]\n{SPHERES}")), 64, None);
    assert!(hits > 0);
    assert_eq!(c.reflection_rays, 0);
}

#[test]
fn no_shadow_rays_from_ambient_or_unshadowed_lights() {
    let (_, c, _) = render(scene(&format!("light ambient(0.5)\n{SPHERES}")), 64, None);
    assert_eq!(c.shadow_rays, 0, "ambient light casts no shadow rays");
    let text = format!("light ambient(0.2)\nlight point(0.6, shadows = false) at [2, 1, 0]\nlight directional(0.3, towards = [1, 1, -1], shadows = false)\n{SPHERES}");
    let (_, c, _) = render(scene(&text), 64, None);
    assert_eq!(c.shadow_rays, 0, "lights with `shadows = false` cast no shadow rays");
    let e = effects::derive(&scene(&text));
    assert!(e.shadow_lights.is_empty() && e.unshadowed_lights.len() == 2);
}

/// Lights at the eye light every visible point, so each hit casts exactly one shadow ray
/// per casting light, and a non-casting light adds none.
#[test]
fn shadow_rays_are_hits_times_casting_lights() {
    let text = format!("light point(0.3) at [0, 0, 0]\nlight point(0.3) at [0, 0, 0.01]\nlight point(0.2, shadows = false) at [0, 0, 0]\n{SPHERES}");
    let (_, c, hits) = render(scene(&text), 64, None);
    assert!(hits > 500, "the objects should fill part of the frame ({hits} hits)");
    assert_eq!(c.shadow_rays, 2 * hits);
}

#[test]
fn reflection_rays_are_bounded_by_depth() {
    let mirrors = "light ambient(0.3)\nlight point(0.5) at [0, 2, 0]
let mirror = material(color = rgb(200, 200, 200), reflective = 1)
object box(0.2, 3, 20) at [-1.5, 0, 10] with mirror
object box(0.2, 3, 20) at [1.5, 0, 10] with mirror
object sphere(0.5) at [0, 0, 8] with material(color = rgb(255, 0, 0))
";
    let mut previous = 0;
    for depth in [0u32, 1, 3, 50] {
        let mut s = scene(mirrors);
        s.settings.depth = depth;
        let (img, c, hits) = render(s, 48, None);
        assert!(
            c.reflection_rays <= hits * depth as u64,
            "depth {depth}: {} reflection rays for {hits} hits",
            c.reflection_rays
        );
        assert!(c.reflection_rays >= previous, "more depth never means fewer bounces");
        assert_eq!(c.nonfinite_samples, 0, "depth {depth}: non-finite colours");
        assert_eq!(img.pixels.len(), 48 * 48 * 3);
        previous = c.reflection_rays;
        if depth == 0 {
            assert_eq!(c.reflection_rays, 0);
        }
    }
    assert!(previous > 0);
}

#[test]
fn antialiasing_multiplies_primary_rays_exactly() {
    for samples in [1u32, 2, 4, 9] {
        let mut s = scene(&format!("light ambient(1)\n{SPHERES}"));
        s.settings.samples = samples;
        let (_, c, _) = render(s, 40, None);
        assert_eq!(c.primary_rays, 40 * 40 * samples as u64);
    }
}

/// A lone convex reflective object gains nothing past one bounce: the derived tracer
/// stops at depth 1 and the image equals the general tracer's at the scene's depth.
#[test]
fn useful_depth_of_a_lone_convex_mirror_is_one() {
    let text = "light ambient(0.3)\nlight point(0.6) at [2, 1, 0]\nobject sphere(1) at [0, 0, 5] with material(color = rgb(255, 0, 0), specular = 40, reflective = 0.5)\n";
    let s = scene(text);
    assert_eq!(effects::derive(&s).useful_depth, 1);
    let (derived, c, hits) = render(s.clone(), 64, None);
    let (general, c_all, _) = render(s.clone(), 64, Some(Effects::all(&s)));
    assert_eq!(c.reflection_rays, hits);
    assert!(derived == general, "depth 1 and depth 5 differ for a lone convex mirror");
    assert_eq!(c.reflection_rays, c_all.reflection_rays, "the general tracer finds no second bounce either");
}

/// The tracer built for a scene's effects and the general tracer with every effect
/// compiled in produce the same pixels on scenes that do not use those effects.
#[test]
fn specialised_and_general_tracers_agree_bit_for_bit() {
    let scenes = [
        format!("light ambient(1)\n{SPHERES}"),
        format!("light ambient(0.2)\nlight point(0.6, shadows = false) at [2, 1, 0]\n{SPHERES}"),
        format!("light ambient(0.2)\nlight point(0.6) at [2, 1, 0]\nlight directional(0.2, towards = [1, 4, 4])\n{SPHERES}"),
        "light ambient(0.2)\nlight point(0.6) at [2, 1, 0]\nobject sphere(1) at [0, 0, 5] with material(reflective = 0.5)\nobject sphere(1) at [2, 0, 6]\n".to_string(),
    ];
    for text in scenes {
        let s = scene(&text);
        let (derived, c, _) = render(s.clone(), 64, None);
        let (general, c_all, _) = render(s.clone(), 64, Some(Effects::all(&s)));
        assert!(derived == general, "images differ for:\n{text}");
        assert_eq!(
            (c.shadow_rays, c.reflection_rays),
            (c_all.shadow_rays, c_all.reflection_rays),
            "ray counts differ for:\n{text}"
        );
    }
}

/// A light with a radius gives a penumbra: on the floor across the shadow, the largest
/// step between neighbouring pixels (the shadow's edge) is much smaller than with a hard
/// shadow; an SDF scene pays one shadow ray per hit (the penumbra estimate), a mesh scene sixteen.
#[test]
fn soft_shadows_have_a_penumbra() {
    let base = "render(background = rgb(0, 0, 0))\nlight ambient(0.2)\nlight point(0.8, radius = RADIUS) at [4, 2, 6]
object box(20, 0.5, 20) at [0, -1.5, 6] with material(color = rgb(200, 200, 200))
object sphere(0.8) at [0, -0.2, 6] with material(color = rgb(255, 60, 60))
";
    // The sharpest edge over the floor rows that cross the shadow (left of the sphere at 96²).
    let edge = |img: &Image, size: u32| {
        let n = size as usize;
        (65..70)
            .flat_map(|row| (1..n).map(move |x| (row, x)))
            .map(|(row, x)| img.pixels[(row * n + x) * 3].abs_diff(img.pixels[(row * n + x - 1) * 3]))
            .max()
            .unwrap_or(0)
    };
    let (hard, hc, _) = render(scene(&base.replace(", radius = RADIUS", "")), 96, None);
    let (soft, sc, hits) = render(scene(&base.replace("RADIUS", "0.8")), 96, None);
    let (h, s_) = (edge(&hard, 96), edge(&soft, 96));
    assert!(h >= 40, "the hard shadow should have a sharp edge (largest step {h})");
    assert!(s_ * 2 <= h, "the soft shadow's largest step {s_} should be far below the hard one's {h}");
    assert!(sc.shadow_rays <= hits && hc.shadow_rays <= hits, "one shadow query per lit hit in an SDF scene");
    let (_, mc, _) = render_in(scene(&base.replace("RADIUS", "0.8")), 48, None, Mode::Mesh(scnc::mesh::Detail::High));
    assert_eq!(mc.shadow_rays % 16, 0, "meshes sample the light with 16 rays");
    assert!(mc.shadow_rays > 0);
}

/// Ambient occlusion darkens ambient light near contacts and leaves open ground alone;
/// SDF scenes estimate it without rays, mesh scenes cast 16 per hit.
#[test]
fn ambient_occlusion_darkens_contacts_only() {
    let text = "render(background = rgb(0, 0, 0), depth = 0, ambient_occlusion = 0.6)\nlight ambient(1)
object box(6, 0.5, 6) at [0, -1.5, 7] with material(color = rgb(200, 200, 200))
object sphere(0.7) at [0, -0.3, 6.5] with material(color = rgb(200, 200, 200))
";
    let (with, c, hits) = render(scene(text), 80, None);
    let (without, _, _) = render(scene(&text.replace(", ambient_occlusion = 0.6", "")), 80, None);
    assert_eq!(c.occlusion_rays, 0, "SDF scenes estimate occlusion without rays");
    let px = |img: &Image, x: usize, y: usize| img.pixels[(y * 80 + x) * 3];
    // Just below the sphere, where it meets the floor: darker. A floor corner far away: unchanged.
    let contact = (40..80).map(|y| (px(&without, 40, y) as i32 - px(&with, 40, y) as i32).max(0)).max().unwrap_or(0);
    assert!(contact >= 40, "occlusion should darken the contact (largest change {contact})");
    assert_eq!(px(&with, 2, 78), px(&without, 2, 78), "open floor is not occluded");
    let (_, mc, _) = render_in(scene(text), 40, None, Mode::Mesh(scnc::mesh::Detail::High));
    assert!(hits > 0 && mc.occlusion_rays > 0 && mc.occlusion_rays % 16 == 0);
    // Without ambient light there is nothing to occlude, so the effect is not built.
    let e = effects::derive(&scene(&text.replace("light ambient(1)", "light point(1) at [0, 3, 0]")));
    assert_eq!(e.ambient_occlusion, None);
}

/// Every scene the repository ships or tests against: the examples, the bench scenes and
/// the IR cases.
fn every_scene() -> Vec<std::path::PathBuf> {
    let dirs =
        ["examples", "examples/seed", "examples/features", "examples/animation", "examples/povray", "examples/light"];
    let mut out: Vec<_> =
        dirs.iter().chain(["benches/scenes", "tests/data/ir"].iter()).flat_map(|d| cases(d)).collect();
    // A fragment that `include`s are for, not a scene.
    out.retain(|p| !p.ends_with("lights.scn"));
    out
}

/// The effect set derived from every shipped scene and IR case, one line each, against
/// `tests/data/effects/derived.txt`: the table's rules over every example.
#[test]
fn derived_over_every_scene() {
    let mut actual = String::new();
    for path in every_scene() {
        let c = compile(&path);
        let scene =
            c.scene.unwrap_or_else(|| panic!("{}: {}", path.display(), scnc::diag::render_all(&c.diagnostics, &c.map)));
        actual.push_str(&format!("{}: {}\n", path.display(), effects::derive(&scene)));
    }
    finish(check_golden(Path::new("tests/data/effects/derived.txt"), &actual).into_iter().collect());
}

/// Each tracer flag is one bit of its own, and every effect's word is distinct.
#[test]
fn the_table_is_well_formed() {
    let flags: Vec<u8> = effects::TABLE.iter().map(|e| e.flag).filter(|&f| f != 0).collect();
    assert!(flags.iter().all(|f| f.is_power_of_two()), "{flags:?}");
    assert_eq!(flags.iter().fold(0, |a, f| a | f).count_ones() as usize, flags.len(), "a bit used twice: {flags:?}");
    let mut words: Vec<&str> = effects::TABLE.iter().map(|e| e.word).collect();
    words.sort_unstable();
    words.dedup();
    assert_eq!(words.len(), effects::TABLE.len(), "two effects share a word");
}

/// Over every shipped scene, on both back-ends: a counter that the table ties to effects
/// stays 0 when all of those effects are off: what an effect the scene does not call for
/// costs is nothing, counted.
#[test]
fn an_effect_that_is_off_casts_nothing() {
    let mut failures = Vec::new();
    let scenes: Vec<_> = every_scene().into_iter().filter(|p| !p.starts_with("benches")).collect();
    for path in scenes {
        let c = compile(&path);
        let Some(scene) = c.scene else { continue };
        let derived = effects::derive(&scene);
        for mode in [Mode::Sdf, Mode::Mesh(scnc::mesh::Detail::Low)] {
            let mut small = scene.clone();
            (small.settings.width, small.settings.height) = (24, 24);
            // Some scenes cannot be meshed (an unbounded field); their SDF run counts.
            let Ok((frame, world)) = scnc::world::prepare(&small, derived.clone(), mode, &scnc::source::FsLoader)
            else {
                continue;
            };
            let (_, counts) = scnc::render::render(&world, &frame, &|| {});
            for (name, read) in effects::TABLE.iter().flat_map(|e| e.counters) {
                let raised_by: Vec<_> =
                    effects::TABLE.iter().filter(|e| e.counters.iter().any(|(n, _)| n == name)).collect();
                if raised_by.iter().all(|e| !(e.on)(&derived)) && read(&counts) != 0 {
                    failures.push(format!(
                        "{} ({mode:?}): {name} = {} with {} off",
                        path.display(),
                        read(&counts),
                        raised_by.iter().map(|e| e.word).collect::<Vec<_>>().join(" and ")
                    ));
                }
            }
        }
    }
    finish(failures);
}
