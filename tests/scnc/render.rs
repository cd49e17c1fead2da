//! Rendering through the SDF back-end: golden images, determinism, the bound property.

use std::path::Path;

use scnc::mesh::Detail;
use scnc::render::Image;
use scnc::trace::Counters;
use scnc::world::Mode;

use crate::support::{cases, finish, updating};

/// Compiles and renders scene text at `w × h` on a pool of `threads`.
pub fn render_text(text: &str, w: u32, h: u32, threads: usize) -> (Image, Counters) {
    let c = scnc::compile_source("t.scn", Path::new("t.scn"), text.to_string(), &scnc::source::FsLoader);
    let scene =
        c.scene.unwrap_or_else(|| panic!("scene did not compile:\n{}", scnc::diag::render_all(&c.diagnostics, &c.map)));
    render_scene(scene, w, h, threads)
}

pub fn render_scene(scene: scnc::ir::Scene, w: u32, h: u32, threads: usize) -> (Image, Counters) {
    render_mode(scene, w, h, threads, Mode::Sdf)
}

/// Renders with shapes lowered by `mode`.
pub fn render_mode(mut scene: scnc::ir::Scene, w: u32, h: u32, threads: usize, mode: Mode) -> (Image, Counters) {
    scene.settings.width = w;
    scene.settings.height = h;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| {
        let effects = scnc::render::effects::derive(&scene);
        let (frame, geometry) = scnc::world::prepare(&scene, effects, mode, &scnc::source::FsLoader).expect("lowering");
        scnc::render::render(&geometry, &frame, &|| {})
    })
}

/// Golden images: a channel may differ by up to 2/255 (float reassociation between
/// compilers), and at most 0.5 % of pixels may differ by more (silhouette pixels).
const CHANNEL_TOLERANCE: u8 = 2;
const MAX_DIFFERING_FRACTION: f64 = 0.005;
const GOLDEN_SIZE: u32 = 128;

fn compare(expected: &image::RgbImage, actual: &Image) -> Result<(), String> {
    if expected.width() != actual.width || expected.height() != actual.height {
        return Err(format!("size {}×{} vs {}×{}", expected.width(), expected.height(), actual.width, actual.height));
    }
    let differing = expected
        .as_raw()
        .chunks(3)
        .zip(actual.pixels.chunks(3))
        .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > CHANNEL_TOLERANCE))
        .count();
    let allowed = (MAX_DIFFERING_FRACTION * (actual.width * actual.height) as f64) as usize;
    if differing > allowed {
        return Err(format!("{differing} pixels differ by more than {CHANNEL_TOLERANCE}/255 (at most {allowed} may)"));
    }
    Ok(())
}

fn save(path: &Path, img: &Image) {
    image::save_buffer(path, &img.pixels, img.width, img.height, image::ExtendedColorType::Rgb8)
        .unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
}

fn golden_images(mode: Mode, suffix: &str, filter: &dyn Fn(&Path) -> bool) {
    let cases: Vec<_> = cases("tests/data/render").into_iter().filter(|p| filter(p)).collect();
    assert!(!cases.is_empty(), "no render cases");
    let mut failures = Vec::new();
    for path in cases {
        let c = crate::support::compile(&path);
        let Some(scene) = c.scene else {
            failures.push(format!("{}: did not compile", path.display()));
            continue;
        };
        let (img, counters) = render_mode(scene, GOLDEN_SIZE, GOLDEN_SIZE, 2, mode);
        assert_eq!(counters.nonfinite_samples, 0, "{}: non-finite colours", path.display());
        let golden = path.with_extension(format!("{suffix}.png"));
        let expected = image::open(&golden).ok().map(|i| i.to_rgb8());
        let verdict = expected.as_ref().map(|e| compare(e, &img));
        match verdict {
            // Within tolerance: keep the blessed file, so blessing rewrites only real changes.
            Some(Ok(())) => {}
            Some(Err(why)) if !updating() => {
                let out = Path::new("target/test-output");
                let _ = std::fs::create_dir_all(out);
                let name = golden.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                save(&out.join(format!("actual-{name}")), &img);
                failures.push(format!(
                    "{}: {why} (actual image in target/test-output; UPDATE_EXPECT=1 to accept)",
                    golden.display()
                ));
            }
            _ => {
                save(&golden, &img);
                if !updating() {
                    failures.push(format!(
                        "{}: golden image was missing; written, review it and run again",
                        golden.display()
                    ));
                }
            }
        }
    }
    finish(failures);
}

/// The cases with mesh goldens too: the seed scenes, and the features whose shading
/// must agree across back-ends (light through glass meets meshes from both sides;
/// patterns sit in the object's space however it is lowered; fields mesh through the
/// isosurface mesher; the library's polyhedra have exact meshes).
fn in_every_mode(p: &Path) -> bool {
    p.file_name().is_some_and(|n| {
        let n = n.to_string_lossy();
        n.starts_with("seed-")
            || n.starts_with("feature-glass.")
            || n.starts_with("feature-patterns.")
            || n.starts_with("feature-fields.")
            || n.starts_with("feature-library.")
    })
}

#[test]
fn golden_images_sdf() {
    golden_images(Mode::Sdf, "sdf", &|_| true);
}

#[test]
fn golden_images_mesh_low() {
    golden_images(Mode::Mesh(Detail::Low), "mesh-low", &in_every_mode);
}

#[test]
fn golden_images_mesh_high() {
    golden_images(Mode::Mesh(Detail::High), "mesh-high", &in_every_mode);
}

/// The image and every counter are the same on 1, 2 and 3 threads and between runs.
/// Every mode (`conformance.rs`).
pub fn image_is_identical_for_any_thread_count(mode: Mode) {
    let text = std::fs::read_to_string("examples/seed/05-mirrors.scn").expect("scene").replace(
        "include \"lights.scn\"",
        "light ambient(0.2)\nlight point(0.6) at [2, 1, 0]\nlight directional(0.2, towards = [1, 4, 4])",
    );
    let scene = crate::support::scene(&text);
    let (one, c1) = render_mode(scene.clone(), 96, 80, 1, mode);
    for threads in [2, 3] {
        let (many, cn) = render_mode(scene.clone(), 96, 80, threads, mode);
        assert!(one == many, "{mode:?}: image differs with {threads} threads");
        assert_eq!(c1, cn, "{mode:?}: counters differ with {threads} threads");
    }
    let (again, _) = render_mode(scene, 96, 80, 2, mode);
    assert!(one == again, "{mode:?}: image differs between runs");
}

/// A ray through the centre of a sphere hits; one beside it misses; colours are as shaded.
#[test]
fn centre_pixel_hits_and_corner_misses() {
    let (img, c) = render_text("render(background = rgb(1, 2, 3))\nlight ambient(1)\nobject sphere(1) at [0, 0, 5] with material(color = rgb(100, 150, 200))\n", 33, 33, 1);
    let px = |x: usize, y: usize| &img.pixels[(y * 33 + x) * 3..(y * 33 + x) * 3 + 3];
    assert_eq!(px(16, 16), &[100, 150, 200], "ambient 1 gives the material colour");
    assert_eq!(px(0, 0), &[1, 2, 3], "a miss shows the background");
    assert_eq!(c.primary_rays, 33 * 33);
    assert_eq!(c.shadow_rays, 0, "ambient light casts no shadow rays");
    assert_eq!(c.reflection_rays, 0, "nothing reflects");
}
