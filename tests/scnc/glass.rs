//! Transparent materials, patterns and colour encoding: exact ray counts, physics with
//! known answers (a slab's sideways shift, an invisible sphere of `ior = 1`, energy that
//! never grows), patterns that stay on their object, and sRGB and 16-bit pixels.

use scnc::render::effects;
use scnc::render::{BitDepth, Frame, Image};
use scnc::trace::Counters;
use scnc::world::{Mode, World};

use crate::conformance::MODES;
use crate::support::{lower, scene};

fn render_with(frame: &Frame, world: &World) -> (Image, Counters) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    pool.install(|| scnc::render::render(world, frame, &|| {}))
}

fn render(text: &str, size: u32, mode: Mode) -> (Image, Counters) {
    let (frame, world) = lower(&scene(text), size, mode);
    render_with(&frame, &world)
}

/// Pixel `(x, y)`'s channels.
fn px(img: &Image, x: u32, y: u32) -> [u8; 3] {
    let i = 3 * (y * img.width + x) as usize;
    [img.pixels[i], img.pixels[i + 1], img.pixels[i + 2]]
}

/// A telephoto view of the plane z = 0 from 100 units in front: camera rays are parallel
/// to within 0.25°, and a pixel covers a known width of the plane.
const TELEPHOTO: &str = "camera(position = [0, 0, -100], look_at = [0, 0, 0], fov = 0.5)\n";
const SIZE: u32 = 256;

/// World units of the plane z = 0 per pixel of the telephoto view.
fn pixel_width() -> f64 {
    2.0 * 100.0 * 0.25f64.to_radians().tan() / SIZE as f64
}

#[test]
fn no_refraction_rays_without_a_transparent_material() {
    let text = "light ambient(0.3)\nlight point(0.7) at [2, 3, 0]
object sphere(1) at [0, 0, 5] with material(color = rgb(255, 0, 0), reflective = 0.5)
object plane([0, 1, 0], -1) with material(checker(#ffffff, #000000))\n";
    assert!(!effects::derive(&scene(text)).refraction);
    for mode in MODES {
        let (_, c) = render(text, 64, mode);
        assert!(c.reflection_rays > 0);
        assert_eq!(c.refraction_rays, 0, "{mode:?}");
    }
    // `transparency = 0` with an index of refraction is still opaque.
    let opaque = text.replace("reflective = 0.5", "reflective = 0.5, transparency = 0, ior = 1.5");
    assert!(!effects::derive(&scene(&opaque)).refraction);
}

/// Light that enters a lone sphere leaves it or reflects inside, once per bounce: at most
/// one refraction ray per hit per level of depth, and at least the one that enters.
#[test]
fn refraction_rays_are_bounded_by_hits_times_depth() {
    let text = "render(depth = 4)\nlight ambient(1)
object sphere(1) at [0, 0, 5] with material(transparency = 1, ior = 1.5)\n";
    let e = effects::derive(&scene(text));
    assert!(e.refraction && e.useful_depth == 4);
    for mode in MODES {
        let s = scene(text);
        let hits = crate::support::coverage(&s, mode, 64).iter().filter(|&&h| h).count() as u64;
        assert!(hits > 300, "{mode:?}: the sphere fills part of the frame");
        let (_, c) = render(text, 64, mode);
        assert!(
            c.refraction_rays >= hits && c.refraction_rays <= 4 * hits,
            "{mode:?}: {} for {hits} hits",
            c.refraction_rays
        );
        assert!(c.reflection_rays <= 4 * hits, "{mode:?}");
    }
}

/// The column where the middle row turns from the white stripe (x < 0) to the black one.
fn edge_column(img: &Image) -> u32 {
    let row = SIZE / 2;
    let brightness = |x: u32| px(img, x, row).iter().map(|&c| c as u32).sum::<u32>() / 3;
    (1..SIZE).find(|&x| brightness(x - 1) >= 128 && brightness(x) < 128).expect("an edge in the middle row")
}

/// A glass slab of thickness `d` and index `n`, met at angle θ, shifts a ray sideways by
/// `d · sin(θ − θt) / cos θt` (θt from Snell's law) and leaves it parallel: the edge of a
/// stripe seen through it moves by that many pixels. The view is a milder telephoto than
/// [`TELEPHOTO`] (20 units away, 5°): its rays are within 2.5° of parallel, which moves
/// the expected shift by under half a pixel, and the default `epsilon` (a distance
/// travelled of 1e-4) is a third of a pixel there rather than three.
#[test]
fn a_glass_slab_shifts_rays_by_the_analytic_offset() {
    let view = "camera(position = [0, 0, -20], look_at = [0, 0, 0], fov = 5)
light ambient(1)\nrender(depth = 5, background = rgb(128, 128, 128))
object plane([0, 0, -1], 0) with material(stripes(rgb(0, 0, 0), rgb(255, 255, 255), width = 100))\n";
    let pixel = 2.0 * 20.0 * 2.5f64.to_radians().tan() / SIZE as f64;
    let (d, n, theta) = (0.5f64, 1.5f64, 45f64.to_radians());
    let theta_t = (theta.sin() / n).asin();
    let shift = d * (theta - theta_t).sin() / theta_t.cos() / pixel;
    assert!(shift > 20.0, "the shift should be measurable: {shift} px");
    for mode in MODES {
        let plain = edge_column(&render(view, SIZE, mode).0);
        let slab = format!(
            "{view}object box(2, 2, {}) rotate [0, 45, 0] at [0, 0, -5] with material(transparency = 1, ior = {n})\n",
            d / 2.0
        );
        let through = edge_column(&render(&slab, SIZE, mode).0);
        let measured = (through as f64 - plain as f64).abs();
        assert!((measured - shift).abs() <= 1.5, "{mode:?}: shifted {measured} px, expected {shift:.2}");
    }
}

/// A sphere of `ior = 1` is no interface at all: no Fresnel reflection, no bending, and
/// shadows pass through it, so the image is the scene's without it.
#[test]
fn a_sphere_of_index_one_is_invisible() {
    // Looking down at the floor: at the horizon a pixel spans many checker cells, and
    // which one a ray lands in follows the last bits of where its march began.
    let base = "camera(position = [0, 3.5, -5], look_at = [0, 0.3, 0.5], fov = 45)
render(depth = 4, background = rgb(150, 180, 230))
light ambient(0.3)
light point(0.7) at [3, 6, -4]
object plane([0, 1, 0], 0) with material(checker(rgb(230, 230, 230), rgb(40, 40, 40), size = 0.7))
object box(0.4) rotate [0, 30, 0] at [0.3, 0.4, 1.5] with material(rgb(200, 60, 40), specular = 30)\n";
    let ghost = format!("{base}object sphere(1) at [0, 1, 0] with material(transparency = 1, ior = 1)\n");
    for mode in MODES {
        let (without, _) = render(base, 128, mode);
        let (with, c) = render(&ghost, 128, mode);
        assert!(c.refraction_rays > 1000, "{mode:?}: the sphere is traced through");
        let apart = |tol: u8| {
            without
                .pixels
                .chunks(3)
                .zip(with.pixels.chunks(3))
                .filter(|(a, b)| a.iter().zip(*b).any(|(p, q)| p.abs_diff(*q) > tol))
                .count()
        };
        // The rays through the sphere restart from just inside and just outside it, and
        // their hit thresholds start from nothing there, so their hits on the floor are
        // closer than a camera ray's: a few land across a far checker edge. At most
        // 0.1 % of the pixels may differ by more than 8/255.
        let (pixels, off) = (128 * 128, apart(8));
        assert!(off * 1000 <= pixels, "{mode:?}: {off} pixels differ by more than 8 ({} by more than 0)", apart(0));
    }
}

/// Clear glass only redistributes light: in a world where nothing is brighter than 200
/// (background, a floor under ambient light alone), no pixel is; absorbing glass is
/// never brighter than the same glass clear.
#[test]
fn energy_never_grows() {
    let world = "camera(position = [0, 2, -6], look_at = [0, 0.6, 0], fov = 45)
render(depth = 8, background = rgb(200, 200, 200))
light ambient(1)
object plane([0, 1, 0], 0) with material(checker(rgb(200, 200, 200), rgb(60, 60, 60), size = 0.5))\n";
    let glass = |absorption: &str| {
        format!(
            "{world}object sphere(1) at [-0.6, 1, 0] with material(transparency = 1, ior = 1.5, absorption = {absorption})
object sphere(0.6) at [1.2, 0.6, -0.5] with material(rgb(200, 200, 200), reflective = 0.5, transparency = 0.5, ior = 1.33)
object torus(0.6, 0.2) rotate [70, 0, 0] at [0.4, 0.5, 1.5] with material(rgb(60, 60, 60), transparency = 0.8, ior = 2.4)\n"
        )
    };
    for mode in MODES {
        let (clear, c) = render(&glass("[0, 0, 0]"), 128, mode);
        assert!(c.refraction_rays > 0);
        let brightest = clear.pixels.iter().copied().max().unwrap_or(0);
        assert!(brightest <= 200, "{mode:?}: a pixel of {brightest} in a world of at most 200");
        let (tinted, _) = render(&glass("[0.8, 0.2, 0.05]"), 128, mode);
        let brighter = clear.pixels.iter().zip(&tinted.pixels).filter(|(c, t)| t > c).count();
        assert_eq!(brighter, 0, "{mode:?}: absorbing glass let more light through than clear glass");
        assert!(tinted.pixels != clear.pixels, "{mode:?}: absorption shows");
    }
}

/// The pixel showing point `(x, y)` of the plane z = 0 in the telephoto view.
fn pixel_of(x: f64, y: f64) -> (u32, u32) {
    let p = pixel_width();
    ((SIZE as f64 / 2.0 + x / p) as u32, (SIZE as f64 / 2.0 - y / p) as u32)
}

/// A checker's cells are where the definition puts them, and a face lying on a cell
/// boundary (the plane z = 0 here) takes one colour, not speckles of both.
#[test]
fn checker_cells_are_where_they_belong() {
    let text = format!(
        "{TELEPHOTO}light ambient(1)
object plane([0, 0, -1], 0) with material(checker(rgb(255, 0, 0), rgb(0, 0, 255), size = 0.1))\n"
    );
    for mode in MODES {
        let (img, _) = render(&text, SIZE, mode);
        for (cx, cy, colour) in [(0, 0, [255, 0, 0]), (-1, 0, [0, 0, 255]), (0, -1, [0, 0, 255]), (-1, -1, [255, 0, 0])]
        {
            // Every pixel well inside the cell.
            for i in 1..9 {
                for j in 1..9 {
                    let (x, y) = ((cx as f64 + i as f64 / 10.0) * 0.1, (cy as f64 + j as f64 / 10.0) * 0.1);
                    let (u, v) = pixel_of(x, y);
                    assert_eq!(px(&img, u, v), colour, "{mode:?}: cell ({cx}, {cy}) at ({x:.3}, {y:.3})");
                }
            }
        }
    }
}

/// Patterns are painted in the object's space: moving an object and the camera by the
/// same amount gives the same picture (a pattern in world space would slide).
#[test]
fn patterns_move_with_their_object() {
    let at = |dx: f64| {
        format!(
            "camera(position = [{dx}, 1, -4], look_at = [{dx}, 0, 0])
light ambient(0.4)\nlight point(0.6) at [{}, 5, -3]
object sphere(1) rotate [0, 0, 30] at [{dx}, 0, 0] with material(stripes(#ff2020, #f0f0f0, width = 0.25, axis = [1, 1, 0]))
object box(0.5) rotate [20, 40, 0] at [{}, 0, -1.5] with material(noise(#2040ff, checker(#ffff40, #104010, 0.2), size = 0.3, seed = 5))\n",
            dx + 2.0,
            dx + 1.5
        )
    };
    for mode in MODES {
        let (here, _) = render(&at(0.0), 128, mode);
        let (there, _) = render(&at(3.3), 128, mode);
        let differing = here.pixels.chunks(3).zip(there.pixels.chunks(3)).filter(|(a, b)| a != b).count();
        let most = here.pixels.iter().zip(&there.pixels).map(|(a, b)| a.abs_diff(*b)).max().unwrap_or(0);
        assert!(differing <= 30 && most <= 1 || differing <= 5, "{mode:?}: {differing} pixels differ, by up to {most}");
        // And the pattern is really there: the sphere is not one colour.
        let mut colours: Vec<[u8; 3]> = (40..90).map(|x| px(&here, x, 64)).collect();
        colours.dedup();
        assert!(colours.len() > 5, "{mode:?}: the stripes show");
    }
}

/// `color = "srgb"` reads colours as sRGB and writes sRGB pixels: a face under full
/// ambient light shows its colour as written, and under half the light it shows half the
/// *linear* light, encoded (brighter than the linear default's half of the number).
#[test]
fn srgb_shades_in_linear_light() {
    let face = |space: &str, ambient: f64| {
        format!(
            "{TELEPHOTO}render(color = \"{space}\")\nlight ambient({ambient})
object plane([0, 0, -1], 0) with material(rgb(200, 64, 128))\n"
        )
    };
    let srgb = |x: f64| if x <= 0.003_130_8 { x * 12.92 } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
    let linear = |x: f64| if x <= 0.04045 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) };
    for mode in MODES {
        let (full, _) = render(&face("srgb", 1.0), 16, mode);
        assert_eq!(px(&full, 8, 8), [200, 64, 128], "{mode:?}");
        let (half, _) = render(&face("srgb", 0.5), 16, mode);
        let expected = [200.0, 64.0, 128.0].map(|c: f64| (srgb(0.5 * linear(c / 255.0)) * 255.0).round() as u8);
        assert_eq!(px(&half, 8, 8), expected, "{mode:?}");
        assert_eq!(expected, [146, 44, 92]);
        let (study, _) = render(&face("linear", 0.5), 16, mode);
        assert_eq!(px(&study, 8, 8), [100, 32, 64], "{mode:?}: the study's numbers");
    }
}

/// 16-bit output is the same image with finer steps: each sample is its 8-bit
/// counterpart times 257, to within the 8-bit rounding.
#[test]
fn sixteen_bit_pixels_refine_the_eight_bit_ones() {
    let text = "light ambient(0.25)\nlight point(0.7) at [2, 2, 0]
object sphere(1) at [0, 0, 4] with material(gradient(#102030, #f0e0d0, [-1, -1, 0], [1, 1, 0]), specular = 40)\n";
    for space in ["linear", "srgb"] {
        let text = format!("render(color = \"{space}\")\n{text}");
        let (mut frame, world) = lower(&scene(&text), 64, Mode::Sdf);
        let (eight, _) = render_with(&frame, &world);
        frame.bit_depth = BitDepth::Sixteen;
        let (sixteen, _) = render_with(&frame, &world);
        assert_eq!((sixteen.depth, sixteen.pixels.len()), (BitDepth::Sixteen, 2 * eight.pixels.len()));
        let wide: Vec<u16> = sixteen.pixels.chunks(2).map(|b| u16::from_ne_bytes([b[0], b[1]])).collect();
        let mut finer = false;
        for (&w, &n) in wide.iter().zip(&eight.pixels) {
            assert!((w as f64 / 257.0 - n as f64).abs() <= 0.51, "{space}: {w} against {n}");
            finer |= w % 257 != 0;
        }
        assert!(finer, "{space}: 16-bit samples between the 8-bit steps");
    }
}

/// Pixels of `a` and `b` differing by more than `tol` in some channel.
fn apart(a: &Image, b: &Image, tol: u8) -> usize {
    a.pixels
        .chunks(3)
        .zip(b.pixels.chunks(3))
        .filter(|(x, y)| x.iter().zip(*y).any(|(p, q)| p.abs_diff(*q) > tol))
        .count()
}

/// Hard case 10 (Glass far from the origin): a glass sphere, a tinted glass box and a
/// patterned floor moved by 1e4 and 1e5 (camera too) render as at the origin: rays
/// entering and leaving glass keep their footing where f32 has few digits left. Every
/// mode (`conformance.rs`).
pub fn glass_far_from_the_origin_renders_the_same(mode: Mode) {
    let at = |o: &str| {
        format!(
            "render(depth = 6)
camera(position = [{o}, {o} + 1.5, {o} - 5], look_at = [{o}, {o} + 0.6, {o}])
light ambient(0.3)\nlight point(0.7) at [{o} + 3, {o} + 6, {o} - 4]
object plane([0, 1, 0], {o}) with material(checker(#e8e8e8, #303030, size = 0.8))
object sphere(1) at [{o}, {o} + 1, {o}] with material(specular = 60, transparency = 1, ior = 1.5)
object box(0.4) rotate [0, 30, 0] at [{o} + 1.8, {o} + 0.4, {o} + 1] with material(transparency = 0.9, ior = 1.3, absorption = [1, 0.2, 0.5])\n"
        )
    };
    let base = render(&at("0"), 96, mode).0;
    for offset in ["10000", "100000"] {
        let (img, c) = render(&at(offset), 96, mode);
        assert_eq!(c.nonfinite_samples, 0);
        assert!(c.refraction_rays > 0);
        let n = apart(&base, &img, 2);
        assert!(n <= 96 * 96 / 100, "{mode:?} at offset {offset}: {n} pixels differ from the scene at the origin");
    }
}

/// Hard case 11 (Thin glass walls, grazing incidence): an invisible (`ior = 1`) glass
/// wall, crossed at every angle up to grazing, changes nothing: no ray stops in it,
/// turns back or loses its way between its two faces. SDF: a hollow sphere (`shell`)
/// 0.01 and 0.002 thick, about four hit thresholds at its distance (`epsilon` × 4.5;
/// the README states the limit: below it a grazing ray can end black); meshes: a thin
/// box of triangles 0.01 and 0.001 thick (triangle hits have no threshold).
pub fn thin_glass_walls_are_crossed_cleanly(mode: Mode) {
    let base = "camera(position = [0, 1.5, -4], look_at = [0, 0.5, 0])
render(depth = 6, background = rgb(150, 180, 230))
light ambient(0.3)\nlight point(0.7) at [2, 5, -3]
object plane([0, 1, 0], 0) with material(checker(#e8e8e8, #303030, size = 0.5))
object box(0.3) rotate [0, 25, 0] at [0.4, 0.3, 1] with material(#c04020)\n";
    let (plain, _) = render(base, 128, mode);
    let thicknesses = match mode {
        Mode::Sdf => ["0.01", "0.002"],
        Mode::Mesh(_) => ["0.01", "0.001"],
    };
    for t in thicknesses {
        let wall = match mode {
            Mode::Sdf => format!("shell(sphere(1), {t}) at [0, 1, 0.5]"),
            Mode::Mesh(_) => format!("mesh box([1.2, 1, {t} / 2]) rotate [10, 50, 0] at [0, 0.9, 0]"),
        };
        let (through, c) =
            render(&format!("{base}object {wall} with material(transparency = 1, ior = 1)\n"), 128, mode);
        assert!(c.refraction_rays > 1000, "{mode:?}, {t}: the wall is crossed");
        assert_eq!(c.nonfinite_samples, 0);
        // As for the invisible sphere: a few rounding-apart pixels at checker edges.
        let (some, many) = (apart(&plain, &through, 0), apart(&plain, &through, 2));
        assert!(some <= 60 && many <= 12, "{mode:?}, wall {t}: {some} pixels differ, {many} by more than 2");
    }
}
