//! Hard cases stay numerically stable: each test states what correct looks like.

use glam::{DVec3, Vec3A};
use proptest::prelude::*;
use scnc::render::Image;
use scnc::trace::{Counters, Geometry, Ray};
use scnc::world::Mode;

use crate::support::{lower, scene, Rng};

fn render(s: &scnc::ir::Scene, size: u32, mode: Mode, threads: usize) -> (Image, Counters) {
    let (frame, world) = lower(s, size, mode);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| scnc::render::render(&world, &frame, &|| {}))
}

/// Pixels differing by more than `tol` in any channel.
fn differing(a: &Image, b: &Image, tol: u8) -> usize {
    a.pixels
        .chunks(3)
        .zip(b.pixels.chunks(3))
        .filter(|(x, y)| x.iter().zip(y.iter()).any(|(p, q)| p.abs_diff(*q) > tol))
        .count()
}

/// Hard case 1 (Grazing rays): the SDF silhouette of a sphere and the horizon of a plane match exact
/// ray intersection within one pixel, and plane hits lie within the stated epsilon.
#[test]
fn grazing_rays_match_analytic_coverage() {
    const N: u32 = 128;
    let s =
        scene("light ambient(1)\nobject sphere(1) at [0.3, 0.2, 5]\nobject plane(normal = [0, 1, 0], offset = -1.2)\n");
    let (frame, world) = lower(&s, N, Mode::Sdf);
    let analytic = |dir: DVec3| {
        let (c, r) = (DVec3::new(0.3, 0.2, 5.0), 1.0);
        let b = dir.dot(c);
        let sphere = r * r - (c - dir * b).length_squared() >= 0.0 && b > 0.0;
        let plane = dir.y < 0.0 && -1.2 / dir.y <= frame.max_distance as f64;
        sphere || plane
    };
    let mut exact = vec![false; (N * N) as usize];
    let mut traced = vec![false; (N * N) as usize];
    let mut c = Counters::default();
    for i in 0..N * N {
        let dir = frame.direction((i % N) as f32 + 0.5, (i / N) as f32 + 0.5);
        exact[i as usize] = analytic(dir.as_dvec3().normalize());
        let ray = Ray::new(Vec3A::ZERO, dir, frame.max_distance);
        if let Some(hit) = world.intersect(&ray, &mut c) {
            traced[i as usize] = true;
            if (hit.point.y + 1.2).abs() < 0.1 && hit.point.z > 7.0 {
                assert!(
                    (hit.point.y + 1.2).abs() <= 2.0 * hit.error,
                    "plane hit {} off the surface by more than epsilon",
                    hit.point
                );
            }
        }
    }
    let at = |x: i32, y: i32| exact[(y.clamp(0, N as i32 - 1) * N as i32 + x.clamp(0, N as i32 - 1)) as usize];
    for i in 0..(N * N) as usize {
        if exact[i] != traced[i] {
            let (x, y) = ((i as u32 % N) as i32, (i as u32 / N) as i32);
            let near_edge = (-1..=1).any(|dy| (-1..=1).any(|dx| at(x + dx, y + dy) != exact[i]));
            assert!(near_edge, "pixel ({x}, {y}) disagrees with exact intersection away from any silhouette");
        }
    }
    // A ray grazing the plane starts marching where it enters the plane's half-space,
    // so no ray spends its budget creeping towards the horizon.
    assert_eq!(c.budget_misses, 0, "rays ran out of steps");
}

const FAR_SCENE: &str = "render(depth = 2)
camera(position = [O, O, O], look_at = [O, O, O + 1])
light ambient(0.2)
light point(0.6) at [O + 2, O + 3, O]
light directional(0.3, towards = [1, 4, -2])
object sphere(1) at [O, O, O + 5] with material(color = rgb(255, 0, 0), specular = 300, reflective = 0.3)
object box(4, 0.2, 4) at [O, O - 1.2, O + 6] with material(color = rgb(200, 200, 200), specular = 50)
object torus(0.5, 0.15) rotate [60, 0, 0] at [O + 1.6, O - 0.5, O + 4.5] with material(color = rgb(0, 0, 255))
";

/// Hard case 2 (Far from the origin): the same scene moved by 1e3, 1e4 and 1e5 (camera too) renders
/// the same image (no acne, no leaks), and identically on 1 and 2 threads. Run for every
/// back-end mode by the conformance table (`conformance.rs`).
pub fn far_from_the_origin_renders_the_same(mode: Mode) {
    let base = render(&scene(&FAR_SCENE.replace('O', "0")), 96, mode, 2).0;
    for offset in ["1000", "10000", "100000"] {
        let s = scene(&FAR_SCENE.replace('O', offset));
        let (img, c) = render(&s, 96, mode, 2);
        assert_eq!(c.nonfinite_samples, 0);
        let n = differing(&base, &img, 2);
        assert!(n <= 96 * 96 / 100, "{mode:?} at offset {offset}: {n} pixels differ from the scene at the origin");
        let (one, _) = render(&s, 96, mode, 1);
        assert!(one == img, "{mode:?} at offset {offset}: 1 and 2 threads differ");
    }
}

/// Hard case 3 (Tiny and huge): the scene scaled by 1e-4 and 1e4 about the camera renders the same
/// image as at scale 1 (the hit threshold and spawn offsets are relative). Every mode
/// (`conformance.rs`).
pub fn tiny_and_huge_scenes_render_the_same(mode: Mode) {
    let text = |k: &str| {
        format!(
            "render(max_distance = 1000 * {k})
light ambient(0.2)
light point(0.7) at [2 * {k}, 3 * {k}, 0]
object sphere(1 * {k}) at [0, 0, 5 * {k}] with material(color = rgb(255, 0, 0), specular = 100)
object box(3 * {k}, 0.2 * {k}, 3 * {k}) at [0, -1.2 * {k}, 6 * {k}]
"
        )
    };
    let base = render(&scene(&text("1")), 96, mode, 2).0;
    for k in ["0.0001", "10000"] {
        let (img, c) = render(&scene(&text(k)), 96, mode, 2);
        assert_eq!(c.nonfinite_samples, 0);
        let n = differing(&base, &img, 2);
        assert!(n <= 96 * 96 / 100, "{mode:?} at scale {k}: {n} pixels differ from scale 1");
    }
}

/// Hard case 4 (Thin walls): sphere tracing never tunnels through a shell or a cut wall down to a
/// thickness of 1e-3: every ray that meets the outer surface exactly hits the wall.
#[test]
fn thin_walls_do_not_tunnel() {
    for t in ["0.1", "0.01", "0.001"] {
        for shape in [format!("shell(sphere(1), {t})"), format!("subtract(box(1), box(1 - {t}) at [0, 0, -{t}])")] {
            let s = scene(&format!("light ambient(1)\nobject {shape} rotate [10, 20, 0] at [0, 0, 4]\n"));
            let (frame, world) = lower(&s, 96, Mode::Sdf);
            let outer = scene(&format!(
                "light ambient(1)\nobject {} rotate [10, 20, 0] at [0, 0, 4]\n",
                if shape.starts_with("shell") { format!("sphere(1 + {t} / 2)") } else { "box(1)".to_string() }
            ));
            let (_, reference) = lower(&outer, 96, Mode::Sdf);
            let mut c = Counters::default();
            for i in 0..96 * 96 {
                let dir = frame.direction((i % 96) as f32 + 0.5, (i / 96) as f32 + 0.5);
                let ray = Ray::new(Vec3A::ZERO, dir, 100.0);
                if let Some(h) = reference.intersect(&ray, &mut c) {
                    // Away from the silhouette (normal facing the camera), the wall must be hit.
                    if h.normal.dot(-dir) > 0.2 {
                        assert!(
                            world.intersect(&ray, &mut c).is_some(),
                            "{shape}: a ray tunnelled through the wall at pixel {i}"
                        );
                    }
                }
            }
        }
    }
}

/// Hard case 7 (non-Lipschitz operators): they never make the march overstep: on sampled rays the sphere
/// tracer's hit is never beyond the first sign change found by a tiny fixed-step march.
#[test]
fn sphere_tracing_never_oversteps() {
    let shapes = [
        "sphere(1) scale [3, 0.2, 1]",
        "box(0.5) scale [0.05, 4, 1] rotate [30, 60, 10]",
        "union(sphere(0.6) at [-0.5, 0, 0], sphere(0.6) at [0.5, 0, 0], box(0.3) at [0, 0.7, 0], smooth = 1.5)",
        "torus(0.8, 0.2) rotate [10, 20, 30] rotate [40, 50, 60] rotate [70, 80, 90] rotate [15, 25, 35] rotate [45, 55, 65] scale [1, 0.5, 2]",
        "subtract(sphere(1), cylinder(0.3, 2) rotate [90, 0, 0], smooth = 0.4) scale [1, 2, 1]",
    ];
    let mut rng = Rng(0x57ab1e);
    for shape in shapes {
        let s = scene(&format!("light ambient(1)\nobject {shape} at [0, 0, 5]\n"));
        let (_, world) = lower(&s, 8, Mode::Sdf);
        let mut c = Counters::default();
        for _ in 0..300 {
            let target = Vec3A::new(0.0, 0.0, 5.0) + rng.vec(1.5);
            let dir = target.normalize();
            let ray = Ray::new(Vec3A::ZERO, dir, 20.0);
            let traced = world.intersect(&ray, &mut c).map(|h| h.t);
            let step = 1e-3;
            let mut t = 0.0f32;
            let mut first = None;
            while t < 20.0 {
                if world.sdf_eval(0, ray.at(t)).unwrap_or(1.0) < 0.0 {
                    first = Some(t);
                    break;
                }
                t += step;
            }
            if let (Some(t_trace), Some(t_ref)) = (traced, first) {
                assert!(
                    t_trace <= t_ref + 2.0 * step,
                    "{shape}: march stopped at {t_trace}, beyond the first surface at {t_ref}"
                );
            }
            if first.is_some() {
                assert!(traced.is_some(), "{shape}: the march missed a surface the fine march found at {first:?}");
            }
        }
    }
}

/// Hard case 8 (Extreme materials): exponents 0, 1 and 1e4 and two facing perfect mirrors at depth 50
/// give finite colours, bounded energy (clamped) and a predictable ray count. Every mode
/// (`conformance.rs`).
pub fn extreme_materials_stay_finite_and_bounded(mode: Mode) {
    for spec in ["0", "1", "10000"] {
        let (_, c) = render(&scene(&format!("light ambient(0.2)\nlight point(5) at [0, 3, 0]\nobject sphere(1) at [0, 0, 5] with material(specular = {spec})\n")), 48, mode, 2);
        assert_eq!(c.nonfinite_samples, 0, "specular {spec} in {mode:?}");
    }
    let mirrors = "render(depth = 50)\nlight ambient(0.3)\nlight point(2) at [0, 1.5, 3]
let mirror = material(color = rgb(255, 255, 255), specular = 100, reflective = 1)
object box(0.1, 3, 30) at [-1, 0, 10] with mirror
object box(0.1, 3, 30) at [1, 0, 10] with mirror
object sphere(0.3) at [0, 0, 6] with material(color = rgb(255, 0, 0))
";
    let (img, c) = render(&scene(mirrors), 48, mode, 2);
    assert_eq!(c.nonfinite_samples, 0);
    assert!(c.reflection_rays <= c.primary_rays * 50, "at most depth reflection rays per pixel");
    assert!(img.pixels.chunks(3).any(|p| p[0] as i32 > p[1] as i32 + 50), "the red sphere is seen in the mirrors");
}

/// Hard case 9 (normals): at sharp box edges and corners, at cusps and in the torus
/// hole, the gradient the normal comes from is finite and not zero, inside, on and
/// outside the solid.
#[test]
fn normals_at_edges_and_cusps_are_unit_and_finite() {
    let s = scene("light ambient(1)\nobject box(1, 0.5, 0.25) at [0, 0, 5]\nobject torus(1, 0.3) at [0, 0, 5]\nobject cone(0.5, 0.5) at [0, 0, 5]\nobject union(box(0.5), sphere(0.5) at [0.5, 0.5, 0], smooth = 0.2) at [0, 0, 5]\n");
    let points = [
        Vec3A::new(1.0, 0.5, 5.25),
        Vec3A::new(1.0, 0.0, 5.25),
        Vec3A::new(-1.0, -0.5, 4.75),
        Vec3A::new(0.7, 0.0, 5.0),
        Vec3A::new(0.0, 0.0, 5.0),
        Vec3A::new(0.0, 0.5, 5.0),
        Vec3A::new(0.5, -0.5, 5.0),
    ];
    for object in &s.objects {
        let scnc::ir::Body::Shape(shape) = &object.geometry else { continue };
        let mut materials = scnc::trace::MaterialTable::default();
        let sdf =
            scnc::sdf::SdfObject::new(shape, glam::DAffine3::IDENTITY, &mut scnc::sdf::Builder::new(&mut materials));
        for p in points {
            for e in [0.0, 1e-6, 1e-3] {
                let g = (sdf.mat)(p + Vec3A::splat(e)).g;
                assert!(g.is_finite() && g.length() > 1e-3, "{:?} at {p}: gradient {g}", object.span);
            }
        }
    }
}

/// Hard case 6 (Degenerate input): each is a clear compile-time error (the diagnostics goldens show
/// the text) or, for meshes, defined behaviour.
#[test]
fn degenerate_input_is_an_error_or_defined() {
    for (text, code) in [
        ("camera(position = [1, 1, 1], look_at = [1, 1, 1])", "E0402"),
        ("camera(look_at = [0, 3, 0], up = [0, 2, 0])", "E0402"),
        ("camera(fov = 0)", "E0400"),
        ("camera(fov = 180)", "E0400"),
        ("light directional(1, towards = [0, 0, 0])", "E0400"),
        ("object sphere(1) scale 0", "E0400"),
        ("object sphere(1) scale [1, 0, 1]", "E0400"),
        ("object plane(normal = [0, 0, 0])", "E0400"),
    ] {
        let c = scnc::compile_source(
            "t.scn",
            std::path::Path::new("t.scn"),
            format!("light ambient(1)\n{text}\n"),
            &scnc::source::FsLoader,
        );
        assert!(
            c.scene.is_none() && c.diagnostics.iter().any(|d| d.code == code),
            "{text}: expected {code}, got {:?}",
            c.diagnostics.iter().map(|d| d.code).collect::<Vec<_>>()
        );
    }
    // Zero-area triangles and duplicate vertices in a mesh are dropped, not hit.
    let mut mesh = scnc::geom::tessellate::cuboid(DVec3::ONE);
    let dup = mesh.positions[0];
    mesh.positions.push(dup);
    let n = mesh.positions.len() as u32;
    mesh.triangles.push([0, n - 1, 1]);
    mesh.triangles.push([2, 2, 3]);
    let obj = scnc::mesh::MeshObject::new(
        &mesh,
        glam::DAffine3::from_translation(DVec3::new(0.0, 0.0, 5.0)),
        0,
        None,
        scnc::mesh::Normals::Vertex,
    );
    assert_eq!(obj.triangle_count(), 12);
}

/// Random CSG trees as source text: primitives, sharp and smooth operators, transforms
/// and modifiers, up to 24 leaves.
pub fn arb_shape() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        (0.2f64..1.5).prop_map(|r| format!("sphere({r:.3})")),
        (0.2f64..1.0, 0.2f64..1.0, 0.2f64..1.0).prop_map(|(a, b, c)| format!("box({a:.3}, {b:.3}, {c:.3})")),
        (0.2f64..1.0, 0.2f64..1.0).prop_map(|(r, h)| format!("cylinder({r:.3}, {h:.3})")),
        (0.5f64..1.0, 0.1f64..0.4).prop_map(|(a, b)| format!("torus({a:.3}, {b:.3})")),
        (0.2f64..1.0, 0.2f64..1.0).prop_map(|(r, h)| format!("cone({r:.3}, {h:.3})")),
        (0.1f64..0.5, 0.1f64..0.8).prop_map(|(r, h)| format!("capsule({r:.3}, {h:.3})")),
    ];
    leaf.prop_recursive(4, 24, 3, |inner| {
        prop_oneof![
            (inner.clone(), inner.clone(), 0.0f64..1.0, 0usize..3).prop_map(|(a, b, k, op)| format!(
                "{}({a}, {b}, smooth = {k:.3})",
                ["union", "intersect", "subtract"][op]
            )),
            (inner.clone(), -90.0f64..90.0, -90.0f64..90.0, -90.0f64..90.0)
                .prop_map(|(s, x, y, z)| format!("({s} rotate [{x:.1}, {y:.1}, {z:.1}])")),
            (inner.clone(), 0.1f64..3.0, 0.1f64..3.0, 0.1f64..3.0)
                .prop_map(|(s, x, y, z)| format!("({s} scale [{x:.3}, {y:.3}, {z:.3}])")),
            (inner.clone(), 0.0f64..0.3).prop_map(|(s, r)| format!("round({s}, {r:.3})")),
            (inner.clone(), 0.01f64..0.3).prop_map(|(s, t)| format!("shell({s}, {t:.3})")),
            (inner, -1.0f64..1.0, -1.0f64..1.0).prop_map(|(s, x, y)| format!("({s} at [{x:.3}, {y:.3}, 0])")),
        ]
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

    /// Random scenes of random primitives, operators and transforms never give a NaN or
    /// infinite colour or a panic, and their evaluators are distance bounds.
    #[test]
    fn random_scenes_are_finite_and_bounded(shape in arb_shape(), seed in any::<u64>()) {
        let text = format!("render(depth = 2)\nlight ambient(0.2)\nlight point(0.7, radius = 0.2) at [2, 3, 0]\nobject {shape} at [0, 0, 4] with material(specular = 20, reflective = 0.3)\n");
        let s = scene(&text);
        let (img, c) = render(&s, 24, Mode::Sdf, 1);
        prop_assert_eq!(c.nonfinite_samples, 0);
        prop_assert_eq!(img.pixels.len(), 24 * 24 * 3);
        let (_, world) = lower(&s, 8, Mode::Sdf);
        let mut rng = Rng(seed | 1);
        for _ in 0..200 {
            let p = Vec3A::new(0.0, 0.0, 4.0) + rng.vec(4.0);
            let q = p + rng.vec(0.5);
            let (fp, fq) = (world.sdf_eval(0, p).unwrap_or(0.0), world.sdf_eval(0, q).unwrap_or(0.0));
            prop_assert!(fp.is_finite() && fq.is_finite());
            prop_assert!((fp - fq).abs() <= (p - q).length() * 1.001 + 1e-4 * (1.0 + fp.abs().max(fq.abs())), "{}: bound broken at {} / {}", shape, p, q);
        }
    }
}
