//! The back-end conformance suite: one table of properties, each checked against every
//! back-end mode. A new mode is one entry of [`MODES`]; a new property is one line of
//! the table, naming a function `fn(Mode)` that panics when the property fails. The
//! properties live beside the tests of their subject (stability, skipping, packets).

use scnc::mesh::Detail;
use scnc::world::Mode;

use crate::support::{compile, lower};

/// Every way shapes can be lowered.
pub const MODES: [Mode; 3] = [Mode::Sdf, Mode::Mesh(Detail::Low), Mode::Mesh(Detail::High)];

/// One test per property, each running it in every mode (so the harness still runs the
/// properties in parallel).
macro_rules! conformance {
    ($($test:ident => $property:path),* $(,)?) => {
        $(
            #[test]
            fn $test() {
                for mode in MODES {
                    $property(mode);
                }
            }
        )*
    };
}

conformance! {
    far_from_the_origin_renders_the_same => crate::stability::far_from_the_origin_renders_the_same,
    tiny_and_huge_scenes_render_the_same => crate::stability::tiny_and_huge_scenes_render_the_same,
    extreme_materials_stay_finite_and_bounded => crate::stability::extreme_materials_stay_finite_and_bounded,
    a_skipped_object_is_never_met_again => crate::skip::a_skipped_object_is_never_met_again,
    packets_agree_with_single_rays => crate::mesh::packets_agree_with_single_rays,
    image_is_identical_for_any_thread_count => crate::render::image_is_identical_for_any_thread_count,
    every_primitive_hit_is_outside_in_and_finite => primitive_hits_are_outside_in_and_finite,
    glass_far_from_the_origin_renders_the_same => crate::glass::glass_far_from_the_origin_renders_the_same,
    thin_glass_walls_are_crossed_cleanly => crate::glass::thin_glass_walls_are_crossed_cleanly,
    fields_cover_what_their_shapes_cover => crate::fields::fields_cover_what_their_shapes_cover,
    domain_operations_cover_what_they_describe => crate::fields::domain_operations_cover_what_they_describe,
    sweeps_cover_what_they_describe => crate::fields::sweeps_cover_what_they_describe,
}

/// Every object of `tests/data/primitives.scn` is hit by some ray aimed inside its
/// bounding sphere (its centre first: a torus's centre is its hole), and every hit on it
/// is at a finite point, with a unit normal facing the ray (an outward normal seen from
/// outside). The world's memory is accounted for.
fn primitive_hits_are_outside_in_and_finite(mode: Mode) {
    use scnc::trace::{Counters, Geometry, Ray};
    let path = std::path::Path::new("tests/data/primitives.scn");
    let scene = compile(path).scene.expect("the primitives list compiles");
    let (frame, world) = lower(&scene, 64, mode);
    assert!(world.bytes() > 0, "{mode:?}: a world with objects has memory");
    let eye = scene.camera.position;
    for (i, object) in scene.objects.iter().enumerate() {
        // A mesh file's extent is known only once read: aim around where it is placed.
        let (centre, radius) = scnc::ir::bounding_sphere(&object.geometry).unwrap_or_else(|| match &object.geometry {
            scnc::ir::Body::Mesh(m) => (m.xf.translation, 0.5),
            scnc::ir::Body::Shape(_) => panic!("object {i} is unbounded"),
        });
        let (u, v) = (glam::DVec3::X * radius, glam::DVec3::Y * radius);
        let aims = [0.0, 0.3, 0.6].into_iter().flat_map(|k: f64| {
            (0..8).map(move |a| {
                let angle = a as f64 * std::f64::consts::TAU / 8.0;
                centre + (u * angle.cos() + v * angle.sin()) * k
            })
        });
        let mut hits = 0;
        for aim in aims {
            let ray = Ray::new(glam::Vec3A::ZERO, (aim - eye).as_vec3a().normalize(), frame.max_distance);
            let Some(hit) = world.intersect(&ray, &mut Counters::default()) else { continue };
            if hit.object as usize != i {
                continue;
            }
            hits += 1;
            assert!(hit.point.is_finite() && hit.t.is_finite() && hit.t > 0.0, "{mode:?}: object {i}: {hit:?}");
            assert!((hit.normal.length() - 1.0).abs() < 1e-3, "{mode:?}: object {i}: normal {}", hit.normal);
            assert!(hit.normal.dot(ray.dir) < 0.0, "{mode:?}: object {i}: the normal {} faces away", hit.normal);
        }
        assert!(hits > 0, "{mode:?}: no ray aimed inside object {i}'s bounding sphere hits it");
    }
}
