//! Fields: a field covers what the shape it describes covers, whatever its slope, in
//! every back-end mode; its march misses no hit a much finer march finds (and would, if
//! its Lipschitz bound were too small); it meshes closed with the volume of its set.
//! The references here are written in Rust, independently of the checker and tapes.

use glam::{DAffine3, DVec3, Vec3A};
use scnc::trace::{Counters, Geometry, Ray};
use scnc::world::Mode;

use crate::support::{coverage, lower, scene, Rng};

const SIZE: u32 = 64;

/// Pixels where `a` and `b` disagree that are not within `reach` pixels of an edge of
/// `a` (a mesh's silhouette moves by a fraction of its cell).
fn disagreements_off_edges(a: &[bool], b: &[bool], reach: i32) -> usize {
    let n = SIZE as i32;
    let at = |x: i32, y: i32| a[(y.clamp(0, n - 1) * n + x.clamp(0, n - 1)) as usize];
    (0..a.len())
        .filter(|&i| a[i] != b[i])
        .filter(|&i| {
            let (x, y) = (i as i32 % n, i as i32 / n);
            !(-reach..=reach).any(|dy| (-reach..=reach).any(|dx| at(x + dx, y + dy) != a[i]))
        })
        .count()
}

fn covered(object: &str, mode: Mode) -> Vec<bool> {
    covered_from("[0, 1, -4]", object, mode)
}

fn covered_from(camera: &str, object: &str, mode: Mode) -> Vec<bool> {
    let text =
        format!("camera(position = {camera}, look_at = [0, 0, 0], fov = 50)\nlight ambient(1)\nobject {object}\n");
    coverage(&scene(&text), mode, SIZE)
}

/// `field(p => length(p) - 1)` covers what `sphere(1)` covers, and so does the same
/// field four times too steep or four times too shallow (the march divides by the
/// estimated slope); `dist(box(1), p)` covers what `box(1)` covers. Every mode
/// (`conformance.rs`): the mesher meshes the field where its bounds say.
pub fn fields_cover_what_their_shapes_cover(mode: Mode) {
    const B: &str = "bounds = [[-1.2, -1.2, -1.2], [1.2, 1.2, 1.2]]";
    let reach = if mode == Mode::Sdf { 1 } else { 2 };
    let cases = [
        ("sphere(1)", format!("field(p => length(p) - 1, {B})")),
        ("sphere(1)", format!("field(p => 4 * (length(p) - 1), {B})")),
        ("sphere(1)", format!("field(p => 0.25 * (length(p) - 1), {B})")),
        ("box(1) rotate [20, 30, 0]", format!("field(p => dist(box(1), p), {B}) rotate [20, 30, 0]")),
    ];
    for (shape, field) in cases {
        let (a, b) = (covered(shape, mode), covered(&field, mode));
        assert!(a.iter().filter(|&&c| c).count() > 100, "{mode:?}: {shape} covers too little to compare");
        let off = disagreements_off_edges(&a, &b, reach);
        assert_eq!(off, 0, "{mode:?}: {field} and {shape} disagree on {off} pixels away from the silhouette");
    }
}

/// The point `p` turned about `y` by `deg · p.y` degrees (the warp in the scenes below).
fn twist(p: DVec3, deg: f64) -> DVec3 {
    let (s, c) = (deg * p.y).to_radians().sin_cos();
    DVec3::new(p.x * c - p.z * s, p.y, p.x * s + p.z * c)
}

fn sd_box(p: DVec3, half: DVec3) -> f64 {
    let q = p.abs() - half;
    q.max(DVec3::ZERO).length() + q.max_element().min(0.0)
}

fn gyroid(p: DVec3) -> f64 {
    let (x, y, z) = ((450.0 * p.x).to_radians(), (450.0 * p.y).to_radians(), (450.0 * p.z).to_radians());
    x.sin() * y.cos() + y.sin() * z.cos() + z.sin() * x.cos()
}

/// A hard field, its scene text (with `{L}` where a stated bound goes) and its value in f64.
struct Case {
    name: &'static str,
    object: &'static str,
    value: fn(DVec3) -> f64,
}

const CASES: [Case; 4] = [
    Case {
        // The raw gyroid (slope about 12), a sheet 0.3 thick in g, in a ball.
        name: "gyroid sheet",
        object: "field(p => max(abs(sin(450 * p.x) * cos(450 * p.y) + sin(450 * p.y) * cos(450 * p.z) + sin(450 * p.z) * cos(450 * p.x)) - 0.15, length(p) - 1.2), bounds = [[-1.2, -1.2, -1.2], [1.2, 1.2, 1.2]]{L})",
        value: |p| (gyroid(p).abs() - 0.15).max(p.length() - 1.2),
    },
    Case {
        // Bumps of 0.35 on a unit sphere: where they stand out, islands float off it.
        name: "displaced sphere",
        object: "displace(sphere(1), p => 0.35 * sin(720 * p.x) * sin(720 * p.y) * sin(720 * p.z){L})",
        value: |p| {
            let s = (720f64.to_radians() * p).to_array().map(f64::sin);
            p.length() - 1.0 + 0.35 * s[0] * s[1] * s[2]
        },
    },
    Case {
        name: "twisted box",
        object: "warp(box(0.4, 1, 0.4), p => [p.x * cos(90 * p.y) - p.z * sin(90 * p.y), p.y, p.x * sin(90 * p.y) + p.z * cos(90 * p.y)], bounds = [[-0.6, -1.1, -0.6], [0.6, 1.1, 0.6]]{L})",
        value: |p| sd_box(twist(p, 90.0), DVec3::new(0.4, 1.0, 0.4)),
    },
    Case {
        // A lens 0.2 thick, four times too steep: a convex body, marched by secants.
        name: "steep lens",
        object: "field(p => max(4 * (length(p - [0, 0, 0.9]) - 1), 4 * (length(p + [0, 0, 0.9]) - 1)), bounds = [[-1, -1, -1], [1, 1, 1]]{L})",
        value: |p| {
            let a = DVec3::new(0.0, 0.0, 0.9);
            (4.0 * ((p - a).length() - 1.0)).max(4.0 * ((p + a).length() - 1.0))
        },
    },
];

/// What the march divides the scene's one object's value by: its Lipschitz bound (the
/// checker's estimate unless stated), for a displacement one more than the bound of `d`
/// (the shape's own distance has slope 1).
fn lipschitz(s: &scnc::ir::Scene) -> f64 {
    let scnc::ir::Body::Shape(shape) = &s.objects[0].geometry else { panic!("not a shape") };
    match &shape.kind {
        scnc::ir::ShapeKind::Field { lipschitz, .. } | scnc::ir::ShapeKind::Warp { lipschitz, .. } => lipschitz.value,
        scnc::ir::ShapeKind::Displace { lipschitz, .. } => 1.0 + lipschitz.value,
        k => panic!("not a field: {k:?}"),
    }
}

/// The first `t` in `[0, t1]` where `f` along the ray is below `eps`, by sphere tracing
/// with steps ten times smaller than `|f| / lipschitz` (and never below `eps / 10`).
fn reference_march(f: fn(DVec3) -> f64, o: DVec3, d: DVec3, t1: f64, lipschitz: f64, eps: f64) -> Option<f64> {
    let mut t = 0.0;
    while t <= t1 {
        let v = f(o + d * t);
        if v < eps {
            return Some(t);
        }
        t += (v / lipschitz / 10.0).max(eps / 10.0);
    }
    None
}

/// Random rays from a sphere of radius 4 around the object towards points within its
/// box: for how many does the renderer miss a hit the reference march finds (no hit, or
/// a hit more than 0.02 beyond it)? A hit the reference does not find, or finds later,
/// is right when it is within the hit threshold (`f / L` below the hit's error: a ray
/// grazing a sheet closer than the threshold hits it).
fn missed_hits(case: &Case, stated: Option<f64>, estimate: f64, rays: usize) -> usize {
    let text = case.object.replace("{L}", &stated.map_or(String::new(), |l| format!(", lipschitz = {l}")));
    let s = scene(&format!("camera(position = [0, 0, 0], look_at = [0, 0, 1])\nlight ambient(1)\nobject {text}\n"));
    let (_, world) = lower(&s, 64, Mode::Sdf);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let unit = |rng: &mut Rng| loop {
        let v = DVec3::new(rng.f32() as f64, rng.f32() as f64, rng.f32() as f64) * 2.0 - 1.0;
        if v.length_squared() <= 1.0 && v.length_squared() > 1e-6 {
            return v;
        }
    };
    let mut missed = 0;
    for _ in 0..rays {
        let origin = unit(&mut rng).normalize() * 4.0;
        let aim = unit(&mut rng) * 1.2;
        let dir = (aim - origin).normalize();
        let ray = Ray::new(origin.as_vec3a(), dir.as_vec3a(), 10.0);
        let hit = world.intersect(&ray, &mut Counters::default());
        let reference = reference_march(case.value, origin, dir, 10.0, estimate, 1e-4);
        let grazes = |h: &scnc::trace::Hit| (case.value)(origin + dir * h.t as f64) / estimate <= h.error as f64 * 1.01;
        let right = match (hit, reference) {
            (Some(h), Some(t)) => (h.t as f64 - t).abs() <= 0.02 || (h.t as f64) < t && grazes(&h),
            (Some(h), None) => grazes(&h),
            (None, r) => r.is_none(),
        };
        missed += usize::from(!right);
    }
    missed
}

/// No missed hits: the first hit of 10,000 random rays on a gyroid sheet, a sphere with
/// detached islands, a twisted box and a steep lens (convex, so marched by secants; a
/// secant twice as long misses 63 of its hits) agrees with a march of ten times
/// smaller steps.
/// The test sees a bound that is too small: on the thin sheet, marching with 0.35 of
/// the estimate (under half the slope sampled) steps over it on some rays. (Half the
/// estimate did too until rays were clipped to the field's support planes: starting
/// nearer the sheet, they take fewer of the long steps that overshoot.) On the solids, a step that overshoots lands
/// inside, where the march turns back, so only a bound below the true slope by more
/// than a part's thickness loses it: a quarter of the estimate does, on both.
#[test]
fn fields_miss_no_hit_a_finer_march_finds() {
    for case in &CASES {
        let s = scene(&format!("light ambient(1)\nobject {}\n", case.object.replace("{L}", "")));
        let divisor = lipschitz(&s);
        let missed = missed_hits(case, None, divisor, 10_000);
        assert_eq!(missed, 0, "{}: {missed} of 10,000 rays miss a hit the reference finds (L = {divisor})", case.name);
        let fraction = if case.name == "gyroid sheet" { 0.35 } else { 0.25 };
        // A displacement states the bound of `d`; the march divides by one more.
        let stated = if case.name == "displaced sphere" { divisor * fraction - 1.0 } else { divisor * fraction };
        let too_small = missed_hits(case, Some(stated), divisor, 10_000);
        assert!(too_small > 0, "{}: marching with {fraction} of the bound misses nothing", case.name);
    }
}

/// The lens is known convex (so the test above marches it by secants, and its shadow
/// rays skip it); the other cases are not.
#[test]
fn the_lens_alone_is_known_convex() {
    for case in &CASES {
        let s = scene(&format!("light ambient(1)\nobject {}\n", case.object.replace("{L}", "")));
        let scnc::ir::Body::Shape(shape) = &s.objects[0].geometry else { panic!("not a shape") };
        assert_eq!(shape.is_convex(), case.name == "steep lens", "{}", case.name);
    }
}

/// The gyroid sheet cut by a ball meshes closed (every edge shared by two triangles,
/// wound outward) with the volume of the implicit set within 2 %: a Monte Carlo
/// estimate over 400,000 points, whose standard error here is about 0.4 %.
#[test]
fn the_gyroid_sheet_meshes_closed_with_its_volume() {
    use scnc::mesh::isosurface::extract;
    use scnc::mesh::octree::Grid;
    let s = scene(&format!("light ambient(1)\nobject {}\n", CASES[0].object.replace("{L}", "")));
    let scnc::ir::Body::Shape(shape) = &s.objects[0].geometry else { panic!("not a shape") };
    let mut materials = scnc::trace::MaterialTable::default();
    let (f, _) = scnc::sdf::Builder::new(&mut materials).build(shape, DAffine3::IDENTITY, 0);
    let b = scnc::ir::shape_bounds(shape).expect("bounded");
    let grid = Grid::new(b.min, b.max, 0.02).expect("grid");
    let surface = extract(&*f, &grid).expect("a surface");
    assert_eq!(surface.mesh.open_edges(), (0, 0), "open or non-manifold edges");
    let meshed = surface.mesh.signed_volume();

    let mut rng = Rng(7);
    let n = 400_000;
    let side = b.max - b.min;
    let inside = (0..n)
        .filter(|_| {
            let u = DVec3::new(rng.f32() as f64, rng.f32() as f64, rng.f32() as f64);
            (CASES[0].value)(b.min + u * side) < 0.0
        })
        .count();
    let monte_carlo = inside as f64 / n as f64 * side.x * side.y * side.z;
    let off = (meshed / monte_carlo - 1.0).abs();
    assert!(off < 0.02, "meshed volume {meshed} vs Monte Carlo {monte_carlo}: {:.2} % off", off * 100.0);
}

/// With the camera at the origin, render space is the world's: a hit on a field lies
/// where the field divided by its bound is within the hit threshold (the march stops on
/// `f / L < error`, and `f / L` is all it knows of the distance).
#[test]
fn field_hits_lie_on_the_surface() {
    let case = &CASES[2];
    let s = scene(&format!(
        "camera(position = [0, 0, 0], look_at = [0, 0, 1])\nlight ambient(1)\nobject {}\n",
        case.object.replace("{L}", "")
    ));
    let l = lipschitz(&s);
    let (_, world) = lower(&s, 64, Mode::Sdf);
    let mut c = Counters::default();
    let mut hits = 0;
    for i in 0..200 {
        let a = i as f32 * 0.1;
        let origin = Vec3A::new(3.0 * a.cos(), 0.3 * (a * 0.7).sin(), 3.0 * a.sin());
        let ray = Ray::new(origin, (-origin).normalize(), 10.0);
        if let Some(h) = world.intersect(&ray, &mut c) {
            hits += 1;
            let v = (case.value)(h.point.as_dvec3());
            assert!(
                v.abs() / l <= h.error as f64 * 1.01 + 1e-6,
                "hit {} is {v} off the surface (t {}, error {})",
                h.point,
                h.t,
                h.error
            );
        }
    }
    assert_eq!(hits, 200, "every ray at the twisted box's axis hits it");
}

/// A field's crease is drawn where its solid is, not where one of its branches is: a
/// slab as steep as the stated bound, cut by a ball that the bound makes 20 times too
/// shallow, covers what the same intersection built from shapes covers. Just outside the
/// ball along the slab's face, the slab's branch reads a distance under the threshold
/// while the solid is many thresholds away; the march took that for a hit and drew a
/// phantom rim (as at the gyroid sheet's rim beside a light, docs/light.md).
#[test]
fn a_crease_is_drawn_where_the_solid_is() {
    const N: u32 = 128;
    const B: &str = "bounds = [[-1.2, -1.2, -1.2], [1.2, 1.2, 1.2]]";
    let mask = |object: &str| {
        let text = format!(
            "camera(position = [0, 1.2, -4], look_at = [0, 0, 0], fov = 40)\n\
             light ambient(1)\nobject {object}\n"
        );
        coverage(&scene(&text), Mode::Sdf, N)
    };
    let truth = mask("intersect(sphere(1), box(2, 0.3, 2))");
    assert!(truth.iter().filter(|&&c| c).count() > 2000, "the cut ball covers too little to compare");
    for object in [
        format!("field(p => max(20 * (abs(p.y) - 0.3), length(p) - 1), {B}, lipschitz = 20)"),
        format!("field(p => max(20 * (abs(p.y) - 0.3), length(p) - 1), {B})"),
    ] {
        let differ = truth.iter().zip(&mask(&object)).filter(|(a, b)| a != b).count();
        assert!(differ * 1000 <= (N * N) as usize, "{object} differs from its shape on {differ} of {} pixels", N * N);
    }
}

/// The domain operations cover what the shapes they describe cover, in every mode: an
/// elongated sphere is a capsule, a sphere mirrored across x is the pair, six copies by
/// `polar` are the six spheres turned by hand (one copy crossing its sector, measured
/// copy by copy, and one not), a twist by 0 is the shape, and a twisted box's every
/// slice is the box turned as `rotate [0, a, 0]` turns it (checked on a thin slab).
pub fn domain_operations_cover_what_they_describe(mode: Mode) {
    let reach = if mode == Mode::Sdf { 1 } else { 2 };
    let ring = |r: f64, at: f64, n: u32| {
        let parts: Vec<String> = (0..n)
            .map(|j| format!("sphere({r}) at [{at}, 0, 0] rotate [0, {}, 0]", 360.0 * j as f64 / n as f64))
            .collect();
        format!("union({})", parts.join(", "))
    };
    let cases = [
        ("capsule(0.5, 0.6)".to_string(), "elongate(sphere(0.5), [0, 0.6, 0])".to_string()),
        (
            "union(sphere(0.5) at [0.7, 0, 0], sphere(0.5) at [-0.7, 0, 0])".into(),
            "symmetric(sphere(0.5) at [0.7, 0, 0], \"x\")".into(),
        ),
        (ring(0.3, 0.9, 6), "polar(sphere(0.3) at [0.9, 0, 0], 6)".into()),
        (ring(0.5, 0.7, 6), "polar(sphere(0.5) at [0.7, 0, 0], 6)".into()),
        ("box(0.6, 0.8, 0.3) rotate [10, 0, 0]".into(), "twist(box(0.6, 0.8, 0.3), 0) rotate [10, 0, 0]".into()),
        (
            "box(0.8, 0.05, 0.3) rotate [0, 27, 0] at [0, 0.6, 0]".into(),
            "intersect(twist(box(0.8, 1, 0.3), 45), box(1, 0.05, 1) at [0, 0.6, 0])".into(),
        ),
    ];
    for (i, (shape, op)) in cases.into_iter().enumerate() {
        // The slab is seen from above, where turning it one way or the other differs.
        let camera = if i == 5 { "[0, 4, -0.5]" } else { "[0, 1, -4]" };
        let (a, b) = (covered_from(camera, &shape, mode), covered_from(camera, &op, mode));
        assert!(a.iter().filter(|&&c| c).count() > 30, "{mode:?}: {shape} covers too little to compare");
        let off = disagreements_off_edges(&a, &b, reach);
        assert_eq!(off, 0, "{mode:?}: {op} and {shape} disagree on {off} pixels away from the silhouette");
    }
}

/// Sweeps cover what the solids they describe cover, in every mode: a rectangle
/// extruded is a box (`u`, `v` as `x`, `z`; along `y`), a disc extruded a cylinder, a
/// disc revolved a sphere, a rectangle off the axis revolved a tube, a disc's outline
/// (`shell`) extruded a pipe, a disc grown by `round` a wider cylinder, and an L extruded
/// the L of two boxes (a concave polygon's exact distance).
pub fn sweeps_cover_what_they_describe(mode: Mode) {
    let reach = if mode == Mode::Sdf { 1 } else { 2 };
    let cases = [
        ("box(0.7, 0.4, 0.3) rotate [20, 30, 0]", "extrude(rect(0.7, 0.3), 0.4) rotate [20, 30, 0]"),
        ("cylinder(0.6, 0.5) rotate [30, 0, 0]", "extrude(circle(0.6), 0.5) rotate [30, 0, 0]"),
        ("sphere(0.8)", "revolve(circle(0.8))"),
        (
            "subtract(cylinder(0.7, 0.5), cylinder(0.5, 0.6)) rotate [-40, 0, 0]",
            "extrude(shell(circle(0.6), 0.2), 0.5) rotate [-40, 0, 0]",
        ),
        ("cylinder(0.8, 0.3) rotate [-30, 0, 0]", "extrude(round(circle(0.5), 0.3), 0.3) rotate [-30, 0, 0]"),
        (
            "subtract(cylinder(0.9, 0.5), cylinder(0.5, 0.6)) rotate [-40, 0, 0]",
            "revolve(polygon([[0.5, -0.5], [0.9, -0.5], [0.9, 0.5], [0.5, 0.5]])) rotate [-40, 0, 0]",
        ),
        (
            "union(box(0.8, 0.2, 0.2) at [0, 0, -0.6], box(0.2, 0.2, 0.8) at [-0.6, 0, 0]) rotate [-50, 0, 0]",
            "extrude(polygon([[-0.8, -0.8], [0.8, -0.8], [0.8, -0.4], [-0.4, -0.4], [-0.4, 0.8], [-0.8, 0.8]]), 0.2) rotate [-50, 0, 0]",
        ),
    ];
    for (shape, sweep) in cases {
        let (a, b) = (covered(shape, mode), covered(sweep, mode));
        assert!(a.iter().filter(|&&c| c).count() > 30, "{mode:?}: {shape} covers too little to compare");
        let off = disagreements_off_edges(&a, &b, reach);
        assert_eq!(off, 0, "{mode:?}: {sweep} and {shape} disagree on {off} pixels away from the silhouette");
    }
}

/// A stated `lipschitz` changes only the cost: the march's hits are confirmed on the
/// field's own first-order distance, so a sphere drawn by a field stated up to 1000
/// times steeper than it is covers the pixels it covers at its true slope, to 0.1 % of
/// them (before, a hit was taken where the value over `L` fell below the threshold:
/// +1.2 % of the disc at 10, +18 % at 1000). A warp, a displacement and a field in a
/// union are marched by the bound alone until the hit test, so there `L` times the steps
/// is the cost, and their step budget grows with `L` so that the steps are all it costs
/// (before, at L = 100 a warp lost about 5 % of its pixels to the budget).
#[test]
fn a_stated_lipschitz_changes_only_the_cost() {
    const N: u32 = 128;
    const B: &str = "bounds = [[-1.5, -1.5, -1.5], [1.5, 1.5, 1.5]]";
    let mask = |object: &str| {
        let text = format!(
            "camera(position = [0, 0, -4], look_at = [0, 0, 0], fov = 40)\nlight ambient(1)\nobject {object}\n"
        );
        coverage(&scene(&text), Mode::Sdf, N)
    };
    let check = |truth: &[bool], object: String| {
        let differ = truth.iter().zip(&mask(&object)).filter(|(a, b)| a != b).count();
        assert!(differ * 1000 <= (N * N) as usize, "{object} differs from its shape on {differ} of {} pixels", N * N);
    };
    let sphere = mask("sphere(1)");
    let with_box = mask("union(sphere(1), box(0.2) at [0, 0, -1.5])");
    let disc = sphere.iter().filter(|&&c| c).count();
    assert!(disc > 2000, "the sphere covers {disc} pixels, too few to compare");
    for l in [1.0, 10.0, 100.0, 1000.0] {
        check(&sphere, format!("field(p => length(p) - 1, {B}, lipschitz = {l})"));
        check(&sphere, format!("field(p => length(p) - 1, {B}, lipschitz = {l}) rotate [10, 20, 0]"));
    }
    for l in [1.0, 10.0, 100.0, 1000.0] {
        check(&sphere, format!("warp(sphere(1), p => p, {B}, lipschitz = {l})"));
        check(&sphere, format!("displace(sphere(1), p => 0 * p.x, lipschitz = {l})"));
        check(&with_box, format!("union(field(p => length(p) - 1, {B}, lipschitz = {l}), box(0.2) at [0, 0, -1.5])"));
    }
}
