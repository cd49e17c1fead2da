//! Secondary rays skip the convex object they leave (`Ray::leaving`): which objects count
//! as convex in each mode, that a skipped object is never one the ray would have met,
//! and that the skip saves the work it is for.

use glam::Vec3A;
use scnc::mesh::Detail;
use scnc::trace::{spawn_offset, Counters, Geometry, Hit, Ray, NO_OBJECT};
use scnc::world::Mode;

use crate::support::{compile, lower, scene};

/// A hit is marked convex exactly when the object is a convex solid *as lowered*: an SDF
/// shape by its form, a tessellated shape only when a generator made it (an isosurface
/// may dent), an explicit mesh by its generator and only with flat normals. Every normal
/// points outward (a plane's square, laid in a left-handed frame, once pointed down).
#[test]
fn convexity_follows_the_lowered_object() {
    // (object, aim point, convex as an SDF, convex as a mesh)
    let cases = [
        ("sphere(1)", [0.0, 0.0, 5.0], true, true),
        ("box(1, 0.5, 0.7) rotate [20, 30, 40]", [0.0, 0.0, 5.0], true, true),
        ("cylinder(0.5, 1) rotate [30, 0, 0]", [0.0, 0.0, 5.0], true, true),
        ("cone(0.7, 0.8)", [0.0, 0.0, 5.0], true, true),
        ("plane(normal = [0, 1, 0], offset = -1)", [0.0, -1.0, 5.0], true, true),
        ("capsule(0.4, 0.6)", [0.0, 0.0, 5.0], true, true),
        ("round(box(0.5), 0.2)", [0.0, 0.0, 5.0], true, false),
        ("intersect(sphere(1), box(0.8))", [0.0, 0.0, 5.0], true, false),
        ("intersect(sphere(1), box(0.8), smooth = 0.2)", [0.0, 0.0, 5.0], false, false),
        ("torus(1, 0.3)", [1.0, 0.0, 5.0], false, false),
        ("union(sphere(1), box(0.8) at [1, 0, 0])", [0.0, 0.0, 5.0], false, false),
        ("subtract(box(1), sphere(0.5) at [1, 1, 0])", [0.0, 0.0, 5.0], false, false),
        ("shell(sphere(1), 0.1)", [0.0, 0.0, 5.0], false, false),
        ("mesh uvsphere(r = 1)", [0.0, 0.0, 5.0], true, true),
        ("mesh icosphere(r = 1)", [0.0, 0.0, 5.0], true, true),
        // Convex by its faces, whatever its shading normals.
        ("mesh uvsphere(r = 1, smooth = true)", [0.0, 0.0, 5.0], true, true),
        ("mesh torus(major = 1, minor = 0.3)", [1.0, 0.0, 5.0], false, false),
        ("mesh isosurface(sphere(1), cell = 0.1)", [0.0, 0.0, 5.0], false, false),
    ];
    for (object, [x, y, z], sdf, mesh) in cases {
        let text = format!("light ambient(1)\nobject {object} at [0, 0, 5]\n");
        for (mode, expected) in [(Mode::Sdf, sdf), (Mode::Mesh(Detail::High), mesh)] {
            let (_, world) = lower(&scene(&text), 16, mode);
            let ray = Ray::new(Vec3A::ZERO, Vec3A::new(x, y, z).normalize(), 100.0);
            let hit = world.intersect(&ray, &mut Counters::default()).unwrap_or_else(|| panic!("{object}: missed"));
            assert_eq!(hit.object, 0, "{object}: the only object is object 0");
            assert_eq!(hit.behind.is_some(), expected, "{object} in {mode:?}");
            // Seen from outside, an outward normal faces the viewer (the skip relies on it).
            assert!(hit.normal.dot(ray.dir) < 0.0, "{object} in {mode:?}: the normal {} points inward", hit.normal);
        }
    }
}

/// Secondary rays from `hit`, as the tracer spawns them: off the side the ray came from,
/// along the mirror direction and 32 directions spread over the hemisphere (shadow and
/// occlusion rays point anywhere there), and the same 32 turned into the surface (a
/// shadow ray for a highlight of a light below the horizon does).
fn secondary(hit: &Hit, ray: &Ray, t_max: f32) -> Vec<Ray> {
    let view = -ray.dir;
    let normal = if hit.normal.dot(view) < 0.0 { -hit.normal } else { hit.normal };
    let origin = hit.point + normal * spawn_offset(hit.point, hit.error);
    let u = normal.any_orthonormal_vector();
    let w = normal.cross(u);
    let spread = (0..32).map(|k| {
        let r2 = (k as f32 + 0.5) / 32.0;
        let a = k as f32 * 2.399_963;
        (u * (r2.sqrt() * a.cos()) + w * (r2.sqrt() * a.sin()) + normal * (1.0 - r2).sqrt()).normalize()
    });
    let mirror = (normal * (2.0 * normal.dot(view)) - view).normalize();
    std::iter::once(mirror)
        .chain(spread.flat_map(|d| [d, -d]))
        .map(|dir| Ray::leaving(hit, origin, dir, t_max))
        .collect()
}

/// Over every seed scene and a scene of non-convex objects, in all three modes: a ray
/// that skips the object it leaves would not have met that object, and skipping it
/// changes nothing else (the closest and any-hit queries agree with the unskipped ones on
/// every other object). A mesh's skip is decided by its face's plane, whatever the
/// shading normal, so there it holds without exception. An SDF hit lies within the
/// threshold of the surface, where the gradient of a sharp edge already turns; a ray
/// leaving almost tangentially there may graze back in, so at most 1 in 10⁴ skipped SDF
/// rays may, and only one within 6° of the tangent plane. Rays leaving
/// non-convex objects, or a convex one from inside, are never skipped, and some of them
/// do meet their object again. Every mode (`conformance.rs`).
pub fn a_skipped_object_is_never_met_again(mode: Mode) {
    const SIZE: u32 = 40;
    let non_convex = "light ambient(0.2)\nlight point(0.8) at [3, 4, 0]\n\
        object torus(1, 0.3) rotate [60, 0, 0] at [-1.2, 0, 6]\n\
        object union(sphere(0.6), box(0.5) at [0.6, 0, 0]) at [1.5, 0.5, 7]\n\
        object subtract(box(1), sphere(1.1) at [0, 0, -1]) at [0.5, -2, 8]\n\
        object mesh torus(major = 0.5, minor = 0.15, smooth = true) at [1.5, -1, 5]\n";
    let mut scenes: Vec<(String, scnc::ir::Scene)> = crate::support::cases("examples/seed")
        .into_iter()
        .filter(|p| p.file_name().is_some_and(|n| n != "lights.scn"))
        .map(|p| (p.display().to_string(), compile(&p).scene.expect("seed scene compiles")))
        .collect();
    scenes.push(("non-convex objects".into(), scene(non_convex)));
    // Seen from inside, a convex solid is met again by every ray leaving its wall.
    scenes.push(("inside a box".into(), scene("light ambient(1)\nobject box(4, 3, 5) rotate [0, 20, 0]\n")));
    for (name, s) in &scenes {
        let (frame, world) = lower(s, SIZE, mode);
        let mut c = Counters::default();
        let (mut skipped, mut grazed_back, mut met_again_unskipped) = (0usize, 0usize, 0usize);
        for i in 0..SIZE * SIZE {
            let dir = frame.direction((i % SIZE) as f32 + 0.5, (i / SIZE) as f32 + 0.5);
            let camera = Ray::new(Vec3A::ZERO, dir, frame.max_distance);
            let Some(hit) = world.intersect(&camera, &mut c) else { continue };
            for ray in secondary(&hit, &camera, frame.max_distance) {
                let plain = Ray { skip: NO_OBJECT, ..ray };
                let unskipped = world.intersect(&plain, &mut c);
                if ray.skip == NO_OBJECT {
                    if unskipped.is_some_and(|h| h.object == hit.object) {
                        met_again_unskipped += 1;
                    }
                    continue;
                }
                assert!(
                    hit.behind.is_some() && ray.skip == hit.object,
                    "{name}: a ray skips an object it does not leave"
                );
                skipped += 1;
                let with_skip = world.intersect(&ray, &mut c);
                assert_eq!(
                    world.occluded(&ray, &mut c),
                    with_skip.is_some(),
                    "{name} {mode:?}: any-hit and closest-hit disagree on a skipping ray"
                );
                match unskipped {
                    Some(h) if h.object == hit.object => {
                        let leaving = ray.dir.dot(hit.normal);
                        assert!(
                            mode == Mode::Sdf && leaving < 0.1,
                            "{name} {mode:?}: a ray leaving object {} at {} along {} (cos {leaving}) meets it again at t = {}",
                            hit.object,
                            hit.point,
                            ray.dir,
                            h.t
                        );
                        grazed_back += 1;
                    }
                    Some(h) => {
                        let s = with_skip.expect("skipping one object loses no other hit");
                        assert_eq!((s.object, s.t), (h.object, h.t), "{name} {mode:?}: the skip changed another hit");
                    }
                    None => assert!(with_skip.is_none(), "{name} {mode:?}: the skip made a hit"),
                }
            }
        }
        assert!(grazed_back * 10_000 <= skipped.max(1), "{name} {mode:?}: {grazed_back} of {skipped} grazed back");
        if !name.starts_with("examples") {
            assert_eq!(skipped, 0, "{name} {mode:?}: no ray leaves the outside of a convex object");
            assert!(met_again_unskipped > 0, "{name} {mode:?}: some rays should meet their object again");
        } else {
            assert!(skipped > 0, "{name} {mode:?}: every seed object is convex, so rays skip");
        }
    }
}

/// The skip saves the work it is for: around a lone convex mesh (flat-faced, so every
/// reflection leaves its face's plane), shadow and reflection rays test no triangle at
/// all, so turning them on adds no triangle tests.
#[test]
fn rays_leaving_a_lone_convex_mesh_test_no_triangles() {
    let text = |extra: &str, material: &str| {
        format!("render(depth = 3)\nlight ambient(0.3)\n{extra}object box(1) rotate [20, 30, 0] at [0, 0, 5] with {material}\n")
    };
    let count = |text: &str| {
        let (frame, world) = lower(&scene(text), 48, Mode::Mesh(Detail::High));
        scnc::render::render(&world, &frame, &|| {}).1
    };
    let plain = count(&text("", "material(color = rgb(200, 0, 0))"));
    let shaded = count(&text(
        "light point(0.6) at [2, 3, 0]\nlight directional(0.3, towards = [1, 1, -1])\n",
        "material(color = rgb(200, 0, 0), reflective = 0.5)",
    ));
    assert_eq!((plain.shadow_rays, plain.reflection_rays), (0, 0));
    assert!(shaded.shadow_rays > 0 && shaded.reflection_rays > 0, "the shaded scene casts secondary rays");
    assert_eq!(shaded.triangle_tests, plain.triangle_tests, "secondary rays tested triangles of the object they leave");
}
