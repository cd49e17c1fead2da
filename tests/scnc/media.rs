//! Light through glass that stays right where it is hard: glass inside glass on every
//! back-end, ray trees bounded by what they contribute, highlights of dielectrics, and an
//! accuracy ladder whose finer rungs are never worse.

use scnc::mesh::Detail;
use scnc::render::Image;
use scnc::trace::Counters;
use scnc::world::Mode;

use crate::conformance::MODES;
use crate::support::{lower, scene};

fn render(text: &str, size: u32, mode: Mode) -> (Image, Counters) {
    let (frame, world) = lower(&scene(text), size, mode);
    scnc::render::render(&world, &frame, &|| {})
}

/// Pixels of two images whose channels differ by more than `tolerance`.
fn apart(a: &Image, b: &Image, tolerance: u8) -> usize {
    a.pixels
        .chunks(3)
        .zip(b.pixels.chunks(3))
        .filter(|(p, q)| p.iter().zip(*q).any(|(x, y)| x.abs_diff(*y) > tolerance))
        .count()
}

/// A floor, a lit red box, looked down upon (no horizon, where one pixel spans many
/// checker cells and which one a ray lands in follows the last bits of its march).
const ROOM: &str = "camera(position = [0, 3.5, -5], look_at = [0, 0.5, 0.5], fov = 45)
render(depth = 8, background = rgb(160, 190, 235))
light ambient(0.3)
light point(0.7) at [3, 6, -4]
object plane([0, 1, 0], 0) with material(checker(rgb(235, 235, 235), rgb(45, 45, 45), size = 0.5))
object box(0.3) rotate [0, 30, 0] at [0.9, 0.3, 1.2] with material(color = rgb(200, 60, 40), specular = 30)
";

/// A sphere of `ior = 1` inside a box of `ior = 1`, both clear, are no interfaces at all:
/// the image is the room's without them, shadows included. On the SDF back-end a ray in
/// the sphere is still in the box, and must be marched out of both (every mode).
#[test]
fn nested_clear_objects_of_index_one_vanish() {
    let ghosts = format!(
        "{ROOM}object box([1.6, 1, 1]) at [0, 1.05, 0] with material(transparency = 1, ior = 1)
object sphere(0.5) at [-0.3, 1, 0] with material(transparency = 1, ior = 1)\n"
    );
    for mode in MODES {
        let (without, _) = render(ROOM, 128, mode);
        let (with, c) = render(&ghosts, 128, mode);
        assert!(c.refraction_rays > 2000, "{mode:?}: the objects are traced through");
        let off = apart(&without, &with, 8);
        assert!(off * 1000 <= 128 * 128, "{mode:?}: {off} pixels differ by more than 8/255");
    }
}

/// Water holding an air bubble and a glass ball, three separate objects: both back-ends
/// see the same thing (the mesh spheres fine enough that their facets do not decide),
/// and trace about as many rays (each spurious hit of the SDF back-end spawned two more).
#[test]
fn a_bubble_in_water_agrees_between_back_ends() {
    let water = format!(
        "{ROOM}object box([1.6, 1, 1]) at [0, 1.05, 0] with material(transparency = 1, ior = 1.33, absorption = [0.3, 0.08, 0.02], specular = 60)
object sphere(0.45) at [-0.6, 1, 0] with material(transparency = 1, ior = 1, specular = 60)
object sphere(0.45) at [0.6, 1, 0] with material(transparency = 1, ior = 1.5, specular = 60)\n"
    );
    let (sdf, cs) = render(&water, 128, Mode::Sdf);
    let (mesh, cm) = render(&water, 128, Mode::Mesh(Detail::N(96)));
    let off = apart(&sdf, &mesh, 16);
    assert!(off * 1000 <= 15 * 128 * 128, "{off} pixels differ by more than 16/255");
    let (a, b) = (cs.rays() as f64, cm.rays() as f64);
    assert!((a / b - 1.0).abs() < 0.1, "SDF {a} rays, mesh {b}");
}

/// A wall on a floor lit across the corner: a shadow ray from the wall beside the floor
/// starts within the floor's hit threshold, and must not take the floor for a blocker,
/// however coarse the threshold (every mode).
#[test]
fn concave_corners_do_not_shadow_themselves() {
    let corner = std::fs::read_to_string("tests/data/ladder/corner.scn").expect("the corner scene");
    let reference = render(&corner, 128, Mode::Mesh(Detail::Low)).0;
    for epsilon in ["1e-2", "1e-3"] {
        let coarse = corner.replace("depth = 2", &format!("depth = 2, epsilon = {epsilon}"));
        let (img, _) = render(&coarse, 128, Mode::Sdf);
        let off = apart(&img, &reference, 16);
        assert!(off <= 4, "epsilon {epsilon}: {off} pixels differ from the exact render");
    }
}

/// Six glass panes at depth 64: every glass hit may spawn a reflection and a refraction,
/// but a ray carrying less than 1/512 of its pixel is not traced, so the tree stays
/// small; and the image is the converged one (depth 32: a ray reflected once inside the
/// last pane crosses 23 surfaces; `tests/data/ladder/panes.scn`).
#[test]
fn ray_trees_are_bounded_by_what_they_contribute() {
    let panes = std::fs::read_to_string("tests/data/ladder/panes.scn").expect("the panes scene");
    for mode in [Mode::Sdf, Mode::Mesh(Detail::Low)] {
        let (deep, c) = render(&panes, 64, mode);
        let (converged, _) = render(&panes.replace("depth = 64", "depth = 32"), 64, mode);
        assert!(c.pruned_rays > 10_000, "{mode:?}: {} rays pruned", c.pruned_rays);
        assert_eq!(c.tree_budget_hits, 0, "{mode:?}");
        // Without pruning, depth 16 alone traced 72 million rays here.
        assert!(c.rays() < 400_000, "{mode:?}: {} rays", c.rays());
        assert_eq!(apart(&deep, &converged, 1), 0, "{mode:?}: depth 64 differs from depth 32");
    }
}

/// A dielectric's highlight is the light's colour whatever the glass's own: the brightest
/// pixel of a red glass sphere is as white as a clear one's (every mode).
#[test]
fn dielectric_highlights_are_the_lights_colour() {
    for colour in ["rgb(220, 40, 40)", "rgb(255, 255, 255)"] {
        let text = format!(
            "camera(position = [0, 0, -4], look_at = [0, 0, 0], fov = 40)
render(background = rgb(20, 20, 20), depth = 4)
light ambient(0.1)
light point(1) at [2, 3, -4]
object sphere(1) with material(color = {colour}, specular = 200, transparency = 0.9, ior = 1.5)\n"
        );
        for mode in MODES {
            let (img, _) = render(&text, 64, mode);
            let brightest =
                img.pixels.chunks(3).max_by_key(|p| p.iter().map(|&x| x as u32).sum::<u32>()).expect("pixels");
            // White over the glass's own tenth of red: no channel is dimmed by the tint
            // (the coarse mesh's interpolated normals peak a little lower).
            assert!(brightest.iter().all(|&x| x >= 200), "{colour} {mode:?}: the highlight is {brightest:?}");
        }
    }
}

/// The accuracy ladder: rendered at `--epsilon` 1e-3 down to 1e-6, each rung is at least
/// as close to a reference as the one above (up to noise of 0.1 % of the pixels). It was
/// U-shaped while the normal's step followed the threshold, and the corner's shadow
/// grew with it.
#[test]
fn finer_hit_thresholds_are_never_worse() {
    // (scene, reference): the exact mesh for flat solids, the finest render for curved.
    let ladder: [(&str, Option<Mode>); 3] = [
        ("tests/data/ladder/cube.scn", Some(Mode::Mesh(Detail::Low))),
        ("tests/data/ladder/corner.scn", Some(Mode::Mesh(Detail::Low))),
        ("tests/data/ladder/sphere.scn", None),
    ];
    for (path, reference) in ladder {
        let text = std::fs::read_to_string(path).expect("a ladder scene");
        let at = |epsilon: &str| text.replace("render(", &format!("render(epsilon = {epsilon}, max_steps = 100000, "));
        let reference = match reference {
            Some(mode) => render(&text, 128, mode).0,
            None => render(&at("1e-6"), 128, Mode::Sdf).0,
        };
        let errors: Vec<usize> = ["1e-3", "1e-4", "1e-5", "1e-6"]
            .iter()
            .map(|e| apart(&render(&at(e), 128, Mode::Sdf).0, &reference, 16))
            .collect();
        let noise = 128 * 128 / 1000;
        for pair in errors.windows(2) {
            assert!(pair[1] <= pair[0] + noise, "{path}: pixels off by more than 16/255 from 1e-3 to 1e-6: {errors:?}");
        }
        assert!(errors[0] > errors[3] || errors[0] == 0, "{path}: {errors:?}");
    }
}

/// A glass sphere meshed at `--tolerance pixel` refracts what is behind it as the exact
/// sphere does (within 1.5 % of the pixels by more than 16/255): its mesh shades with the
/// sphere's own normals, and the tolerance, for a surface that bends light, bounds the
/// normal's error as seen through it, not only the facets' distance.
#[test]
fn a_meshed_glass_sphere_at_pixel_tolerance_refracts_like_the_exact_one() {
    use scnc::study::tolerance::{mesh_detail, Tolerance};
    let text = std::fs::read_to_string("tests/data/ladder/sphere.scn").expect("the sphere scene");
    let s = scene(&text.replace("width = 256, height = 256", "width = 128, height = 128"));
    let detail = mesh_detail(&s, Tolerance::Pixel);
    let image = |mode: Mode| {
        let (frame, world) = scnc::world::prepare(&s, scnc::render::effects::derive(&s), mode, &scnc::source::FsLoader)
            .expect("lowering");
        scnc::render::render(&world, &frame, &|| {}).0
    };
    let off = apart(&image(Mode::Sdf), &image(Mode::Mesh(detail)), 16);
    assert!(off * 1000 <= 15 * 128 * 128, "{off} pixels differ by more than 16/255 at {detail:?}");
}
