//! Tests derived from the builtins table: every primitive and every shape operator or
//! modifier, with arguments sampled from its own declaration, is checked for what the
//! SDF back-end, the mesher and the docs rely on. A builtin is tested the moment it is
//! listed, without anyone writing a test for it.
//!
//! - Its distance is a *bound*: a ball of radius `f(p)` around `p` holds no point of the
//!   solid (probed along the direction to the nearest surface and around it, and along
//!   random directions). An overestimating distance makes the march step through the
//!   surface; this is what catches it.
//! - It is 1-Lipschitz, and its box, sphere and half-space hold the solid.
//! - For a primitive: its analytic gradient agrees with the distance, an exact distance
//!   leads from any point straight onto the surface, and its generator's mesh is closed,
//!   outward and on the zero set within the facet error the accuracy model states.
//! - Its docs exist, its defaults are in range, and each documented range is the range
//!   checked: boundary values are accepted or refused as the docs say.

use std::path::Path;
use std::sync::Arc;

use glam::{DVec3, Vec3A};
use scnc::builtins::{Builtin, Ctor, Kind, BUILTINS};
use scnc::ir::{Shape, ShapeKind};
use scnc::primitive::{Facets, Primitive, Resolution, Solid, Tessellation, Visit, PRIMITIVES};
use scnc::sig::{Limit, Param, Range, Ty};
use scnc::world::Mode;

use crate::support::{lower, Rng};

/// Where every sampled object is placed (the camera is at the origin, so this is also
/// where it lies in render space).
const AT: Vec3A = Vec3A::new(0.0, 0.0, 5.0);

/// Shapes a shape parameter is given: a variety of primitives, blends and transforms.
const CHILDREN: &[&str] = &[
    "sphere(0.6)",
    "box(0.5, 0.3, 0.4) rotate [20, 30, 10]",
    "torus(0.5, 0.15) rotate [70, 0, 0]",
    "union(sphere(0.4) at [0.3, 0, 0], box(0.3) at [-0.3, 0.1, 0])",
    "cylinder(0.3, 0.6) scale [1, 0.5, 2]",
    "capped_cone(0.5, 0.2, 0.4) rotate [0, 0, 40]",
];

/// Deeper compositions than one builtin over sampled children: nested and non-uniform
/// transforms, blends of scaled parts, shells of differences.
const COMPOSITES: &[&str] = &[
    "plane(normal = [1, 2, 3], offset = 0.5) rotate [10, 20, 30]",
    "union(sphere(1), box(0.8) at [1, 0, 0], smooth = 2)",
    "subtract(box(1), sphere(0.5) at [1, 1, 0], cylinder(0.2, 2))",
    "repeat(sphere(0.2), period = [0.5, 0.7, 1], count = [4, 3, 2])",
    "sphere(1) scale [3, 0.2, 1]",
    "box(1) scale [0.1, 5, 1] rotate [30, 40, 50]",
    "torus(1, 0.2) rotate [10, 0, 0] scale [1, 2, 1] rotate [0, 70, 0] scale 0.3 rotate [0, 0, 45]",
    "union(sphere(1) scale [2, 1, 1], torus(1, 0.2) scale 3, smooth = 0.4) rotate [5, 6, 7]",
    "shell(subtract(sphere(1), box(0.5) at [0.8, 0, 0]), 0.01) scale [1, 1, 4]",
    "round(intersect(box(0.6), sphere(0.8), smooth = 0.2), 0.1) scale [2, 1, 0.5]",
];

/// Field literals a number-valued field parameter is given: distances, a steep one, a
/// rippled one and one measuring a shape through noise.
const FIELDS: &[&str] = &[
    "p => length(p) - 0.6",
    "p => max(abs(p.x) - 0.4, length([p.y, p.z, 0]) - 0.3)",
    "p => 3 * (length(p * [1, 2, 1]) - 0.5) + 0.1 * sin(900 * p.x)",
    "p => dist(box(0.4), p) - 0.1 * noise3(p, 0.3, 2)",
];

/// Field literals a vector-valued one is given: the identity, a twist, a stretch.
const MAPS: &[&str] = &[
    "p => p",
    "p => [p.x * cos(60 * p.y) - p.z * sin(60 * p.y), p.y, p.x * sin(60 * p.y) + p.z * cos(60 * p.y)]",
    "p => p * [1, 1.5, 0.8] + [0.1, 0, 0]",
];

/// Profiles a sweep is given: a disc, a rectangle across the axis, a concave polygon (an
/// L) and a triangle; and profiles moved and combined: a plate with two holes, a smooth
/// union of a disc and a turned bar, an intersection of a scaled rectangle and a disc;
/// glyphs, alone and cut from a plate.
const PROFILES: &[&str] = &[
    "circle(0.3)",
    "rect(0.4, 0.3)",
    "polygon([[0.1, -0.5], [0.7, -0.5], [0.7, -0.2], [0.35, -0.2], [0.35, 0.5], [0.1, 0.5]])",
    "polygon([[0.2, 0], [0.8, -0.3], [0.5, 0.6]])",
    "subtract(rect(0.6, 0.4) at [0.6, 0], circle(0.15) at [0.4, 0], circle(0.1) at [0.85, 0.1])",
    "union(circle(0.25) at [0.3, 0], rect(0.1, 0.4) rotate 30 at [0.6, 0], smooth = 0.1)",
    "intersect(rect(0.5, 0.3) scale 1.2 at [0.5, 0], circle(0.5) at [0.6, 0.1])",
    "text(\"Ag\", size = 0.6) at [0.1, -0.2]",
    "subtract(rect(0.6, 0.4) at [0.6, 0], text(\"o\", size = 0.5, halign = \"center\", valign = \"center\") at [0.6, 0])",
];

/// Transforms a sampled shape is seen through.
const PLACEMENTS: &[&str] = &["", "rotate [25, 40, 10]", "scale [1.5, 0.6, 1] rotate [10, 0, 30]", "scale 0.7"];

/// A literal for parameter `p` within its declared range, of a size that makes a
/// visible solid (lengths about 0.2–1.2).
fn literal(p: &Param, rng: &mut Rng) -> Option<String> {
    let number = |rng: &mut Rng| sample(&p.range, p.ty == Ty::Int, rng);
    Some(match p.ty {
        Ty::Num | Ty::Int => scnc::sig::num(number(rng)),
        Ty::Bool => (rng.below(2) == 0).to_string(),
        Ty::Vec3 | Ty::Size | Ty::Color => {
            let v = loop {
                let v = DVec3::new(number(rng), number(rng), number(rng));
                if p.range.admits_vec(v) {
                    break v;
                }
            };
            if p.ty == Ty::Color {
                format!("rgb({}, {}, {})", v.x, v.y, v.z)
            } else {
                scnc::sig::vec(v)
            }
        }
        Ty::Shape => CHILDREN[rng.below(CHILDREN.len())].to_string(),
        Ty::Paint => "rgb(10, 20, 30)".into(),
        Ty::Pattern => "checker(rgb(10, 20, 30), rgb(200, 100, 50))".into(),
        Ty::Material => "material()".into(),
        Ty::Light => "ambient(1)".into(),
        Ty::Mesh => "mesh box(1)".into(),
        Ty::List => "[1, 2]".into(),
        Ty::Linear => "0.5".into(),
        // `symmetric`'s axes; any other string parameter is a mesh file's path.
        Ty::Str if p.name == "axes" => ["\"x\"", "\"xz\"", "\"xyz\""][rng.below(3)].into(),
        Ty::Str => "\"tests/data/models/gem.obj\"".into(),
        Ty::FieldNum => FIELDS[rng.below(FIELDS.len())].to_string(),
        Ty::FieldVec => MAPS[rng.below(MAPS.len())].to_string(),
        Ty::Bounds => "[[-0.9, -0.8, -0.7], [0.8, 0.9, 1]]".into(),
        Ty::Profile => PROFILES[rng.below(PROFILES.len())].to_string(),
    })
}

/// A number admitted by `range`: near its low end (within about 1.2 of it), sometimes
/// exactly an included end or its special value.
fn sample(range: &Range, int: bool, rng: &mut Rng) -> f64 {
    if let Some(x) = range.also.filter(|_| rng.below(5) == 0) {
        return x;
    }
    let lo = match range.lo {
        Limit::Open => -1.0,
        Limit::Incl(l) if rng.below(4) == 0 => return l,
        Limit::Incl(l) => l,
        Limit::Excl(l) => l + 0.2,
    };
    let hi = match range.hi {
        Limit::Open => lo + 1.0,
        Limit::Incl(h) | Limit::Excl(h) => h.min(lo + 1.0),
    };
    loop {
        let mut x = lo + (hi - lo) * rng.f32() as f64;
        if int || range.whole {
            x = x.round();
        }
        if range.admits(x) {
            return x;
        }
    }
}

/// A call of builtin `b` with every parameter given a sampled value (and, for a
/// variadic one, two or three shapes), or `None` if samples cannot make its arguments.
fn sampled_call(b: &Builtin, rng: &mut Rng) -> Option<String> {
    let mut args: Vec<String> = Vec::new();
    if let Some(ty) = b.variadic {
        for k in 0..2 + rng.below(2) {
            let child = literal(
                &Param { name: "", ty, default: scnc::sig::Default::Required, range: Range::ANY, doc: "" },
                rng,
            )?;
            args.push(format!("{child} at [{}, 0, 0]", 0.35 * k as f64 - 0.35));
        }
    }
    for p in b.params {
        // A stated slope bound is the scene's promise; the estimate is what is tested.
        if p.name == "lipschitz" {
            continue;
        }
        args.push(format!("{} = {}", p.name, literal(p, rng)?));
    }
    Some(format!("{}({})", b.name, args.join(", ")))
}

/// A sampled object: its source, its IR and its distance in render space.
struct Case {
    text: String,
    shape: Arc<Shape>,
    world: scnc::world::World,
}

impl Case {
    fn f(&self, p: Vec3A) -> f32 {
        self.world.sdf_eval(0, p).expect("an SDF object")
    }
}

/// The object `expr` placed at [`AT`], compiled and lowered by the SDF back-end; `None`
/// if it does not compile (a sample that breaks a rule between parameters).
fn case(expr: &str) -> Option<Case> {
    let text = format!("light ambient(1)\nobject {expr} at [{}, {}, {}]\n", AT.x, AT.y, AT.z);
    let c = scnc::compile_source("t.scn", Path::new("t.scn"), text.clone(), &scnc::source::FsLoader);
    let scene = c.scene?;
    let scnc::ir::Body::Shape(shape) = scene.objects[0].geometry.clone() else { return None };
    let (_, world) = lower(&scene, 8, Mode::Sdf);
    Some(Case { text, shape, world })
}

/// The builtins that make shapes from numbers (primitives) or from shapes (operators and
/// modifiers), each sampled a few times under a few placements.
fn cases(rng: &mut Rng) -> Vec<Case> {
    let mut out = Vec::new();
    let shapes = BUILTINS.iter().filter(|b| b.kind() == Kind::Function && b.result == Ty::Shape);
    for b in shapes {
        let mut made = 0;
        for _ in 0..40 {
            let Some(call) = sampled_call(b, rng) else { break };
            let placement = PLACEMENTS[made % PLACEMENTS.len()];
            if let Some(c) = case(&format!("{call} {placement}")) {
                out.push(c);
                made += 1;
            }
            if made == 4 {
                break;
            }
        }
        assert_eq!(made, 4, "`{}`: samples of its declared ranges do not compile", b.name);
    }
    out.extend(COMPOSITES.iter().map(|expr| case(expr).unwrap_or_else(|| panic!("{expr} does not compile"))));
    out
}

/// How much f32 rounding a distance near `p` may carry, for a solid of size `size`.
fn noise(p: Vec3A, size: f32) -> f32 {
    2e-6 * p.length() + 2e-5 * size
}

/// The central finite-difference gradient of `f` at `p`, step `h`.
fn fd_gradient(f: &dyn Fn(Vec3A) -> f32, p: Vec3A, h: f32) -> Vec3A {
    let d = |e: Vec3A| (f(p + e * h) - f(p - e * h)) / (2.0 * h);
    Vec3A::new(d(Vec3A::X), d(Vec3A::Y), d(Vec3A::Z))
}

/// A unit vector, uniform on the sphere.
fn direction(rng: &mut Rng) -> Vec3A {
    loop {
        let v = rng.vec(1.0);
        if (0.01..=1.0).contains(&v.length_squared()) {
            return v.normalize();
        }
    }
}

/// The size of the sampled solid (its bounding sphere's radius) and a box to sample
/// points in around it.
fn extent(c: &Case) -> (f32, Vec3A, Vec3A) {
    match scnc::ir::shape_bounds(&c.shape) {
        Some(b) => {
            let (lo, hi) = (b.min.as_vec3a(), b.max.as_vec3a());
            let size = (hi - lo).length() * 0.5;
            (size, lo - size * 0.5, hi + size * 0.5)
        }
        None => (1.0, AT - 2.0, AT + 2.0),
    }
}

fn point_in(lo: Vec3A, hi: Vec3A, rng: &mut Rng) -> Vec3A {
    lo + (hi - lo) * Vec3A::new(rng.f32(), rng.f32(), rng.f32())
}

/// No point of the solid lies in the ball of radius `f(p)` around `p`: probed along the
/// direction towards the nearest surface (down the gradient), in a cone around it, and
/// in random directions, at sixteen depths each.
fn distance_is_a_bound(c: &Case, rng: &mut Rng) -> Result<(), String> {
    let (size, lo, hi) = extent(c);
    let f = |p: Vec3A| c.f(p);
    for _ in 0..80 {
        let p = point_in(lo, hi, rng);
        let r = f(p);
        // Only points clearly outside (a NaN is not).
        if r.is_nan() || r <= noise(p, size) {
            continue;
        }
        let down = -fd_gradient(&f, p, 1e-3 * size).normalize_or_zero();
        let mut dirs = vec![down];
        dirs.extend((0..24).map(|_| (down + direction(rng) * 0.3).normalize_or_zero()));
        dirs.extend((0..120).map(|_| direction(rng)));
        for u in dirs.into_iter().filter(|u| *u != Vec3A::ZERO) {
            for k in 1..=16 {
                let q = p + u * (r * k as f32 / 16.0);
                let fq = f(q);
                if fq < -(noise(q, size) + 1e-4 * r) {
                    return Err(format!(
                        "f({p}) = {r}, but {q}, {} from p, is inside the solid (f = {fq}): the distance overestimates",
                        (q - p).length()
                    ));
                }
            }
        }
    }
    Ok(())
}

/// `|f(p) − f(q)| ≤ |p − q|` on random pairs, near and far apart.
fn distance_is_lipschitz(c: &Case, rng: &mut Rng) -> Result<(), String> {
    let (size, lo, hi) = extent(c);
    for _ in 0..1500 {
        let p = point_in(lo, hi, rng);
        let q = p + direction(rng) * size * rng.f32().powi(3);
        let (fp, fq) = (c.f(p), c.f(q));
        if !(fp.is_finite() && fq.is_finite()) {
            return Err(format!("not finite at {p} or {q}"));
        }
        let slack = noise(p, size) + noise(q, size) + 1e-4 * (p - q).length();
        if (fp - fq).abs() > (p - q).length() + slack {
            return Err(format!(
                "|f(p) − f(q)| = {} > |p − q| = {} at p = {p}, q = {q}",
                (fp - fq).abs(),
                (p - q).length()
            ));
        }
    }
    Ok(())
}

/// Points outside the solid's box, sphere or half-space are outside the solid.
fn bounds_hold_the_solid(c: &Case, rng: &mut Rng) -> Result<(), String> {
    let (size, lo, hi) = extent(c);
    let boxed = scnc::ir::shape_bounds(&c.shape);
    let sphere = scnc::ir::shape_sphere(&c.shape);
    let half = scnc::ir::shape_half_space(&c.shape);
    for _ in 0..3000 {
        let p = point_in(lo, hi, rng);
        let w = p.as_dvec3();
        let outside_box = boxed.is_some_and(|b| !(b.min.cmple(w).all() && w.cmple(b.max).all()));
        let outside_sphere = sphere.is_some_and(|(centre, r)| (w - centre).length() > r);
        let outside_half = half.is_some_and(|(n, offset)| n.dot(w) > offset);
        if (outside_box || outside_sphere || outside_half) && c.f(p) < -noise(p, size) {
            return Err(format!(
                "{p} is inside the solid (f = {}) but outside its {}",
                c.f(p),
                if outside_box {
                    "box"
                } else if outside_sphere {
                    "bounding sphere"
                } else {
                    "half-space"
                }
            ));
        }
    }
    Ok(())
}

/// One property of a sampled case: `Err` says how it fails.
type Check = fn(&Case, &mut Rng) -> Result<(), String>;

#[test]
fn every_shape_builtin_has_a_bounded_lipschitz_distance_inside_its_bounds() {
    let mut rng = Rng(0x0de7_17ed);
    let mut failures = Vec::new();
    for c in cases(&mut rng) {
        let checks: [(&str, Check); 3] = [
            ("a distance bound", distance_is_a_bound),
            ("1-Lipschitz", distance_is_lipschitz),
            ("held by its bounds", bounds_hold_the_solid),
        ];
        for (what, check) in checks {
            if let Err(e) = check(&c, &mut rng) {
                failures.push(format!("not {what}: {e}\n{}", c.text));
            }
        }
    }
    crate::support::finish(failures);
}

/// A primitive's distance and gradient, boxed, in its own frame.
pub(crate) struct Functions;

impl Visit for Functions {
    type Out = (Box<dyn Fn(Vec3A) -> f32>, Box<dyn Fn(Vec3A) -> Vec3A>, bool);

    fn visit<S: Solid>(self, s: &S) -> Self::Out {
        let (d, g): (_, _) = (s.distance(), s.gradient());
        (Box::new(d), Box::new(g), s.is_exact())
    }
}

/// The primitive under a shape's transforms and paint.
fn primitive_of(shape: &Shape) -> Option<&Primitive> {
    match &shape.kind {
        ShapeKind::Primitive(p) => Some(p),
        ShapeKind::Transform { child, .. } | ShapeKind::Paint { child, .. } => primitive_of(child),
        _ => None,
    }
}

/// Each primitive, sampled from its declaration, in its own frame.
pub(crate) fn primitives(rng: &mut Rng) -> Vec<(String, Primitive)> {
    let mut out = Vec::new();
    for e in PRIMITIVES {
        let b =
            BUILTINS.iter().find(|b| matches!(b.ctor, Ctor::Primitive(p) if p == e)).expect("a builtin per primitive");
        let mut made = 0;
        while made < 6 {
            let call = sampled_call(b, rng).expect("primitives take numbers, vectors and flags");
            let Some(c) = case(&call) else { continue };
            out.push((call, primitive_of(&c.shape).expect("a primitive").clone()));
            made += 1;
        }
    }
    out
}

/// Where the gradient is defined (the finite difference is a unit vector, so no crease
/// lies within the step), it is the distance's gradient, and unit length; an exact
/// distance leads from any point along the gradient onto the surface.
#[test]
fn every_primitive_gradient_agrees_with_its_distance() {
    let mut rng = Rng(0x9ad1e27);
    let mut failures = Vec::new();
    for (call, p) in primitives(&mut rng) {
        let (f, g, exact) = p.visit(Functions);
        let size = p.sphere_radius().unwrap_or(1.0) as f32;
        let mut compared = 0;
        for _ in 0..3000 {
            let x = Vec3A::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5) * (3.0 * size);
            let analytic = g(x);
            if (analytic.length() - 1.0).abs() > 1e-3 {
                failures.push(format!("{call}: the gradient at {x} has length {}", analytic.length()));
                break;
            }
            // Compared where the distance is smooth: two steps give the same slope (no
            // crease within them), and it is not flat.
            let h = 1e-3 * size;
            let (fd, fine) = (fd_gradient(&*f, x, h), fd_gradient(&*f, x, h * 0.5));
            if (fd - fine).length() > 1e-3 * fd.length() || fd.length() < 0.1 {
                continue;
            }
            if fd.normalize().dot(analytic) < 0.999 {
                failures.push(format!("{call}: at {x} the gradient is {analytic}, the distance's slope {fd}"));
                break;
            }
            if exact && (fd.length() - 1.0).abs() > 2e-3 {
                failures.push(format!("{call}: at {x} an exact distance has slope {}", fd.length()));
                break;
            }
            compared += 1;
            if exact {
                let on = x - analytic * f(x);
                if f(on).abs() > 1e-4 * size + 2e-6 * x.length() {
                    failures.push(format!(
                        "{call}: from {x} (f = {}) down the gradient lands at {on}, where f = {}: not exact",
                        f(x),
                        f(on)
                    ));
                    break;
                }
            }
        }
        if compared < 100 && failures.is_empty() {
            failures.push(format!("{call}: the distance is smooth at too few points to compare ({compared})"));
        }
    }
    crate::support::finish(failures);
}

/// The deviation the accuracy model allows a generator's triangles at a resolution.
fn facet_error(facets: Facets, res: Resolution) -> Option<f64> {
    match facets {
        Facets::Exact => Some(0.0),
        Facets::Inscribed(r) => {
            let sides = res.rings.min(res.circle / 2).max(3) as f64;
            Some(r * (1.0 - (std::f64::consts::PI / sides).cos()))
        }
        Facets::Isosurface => None,
    }
}

/// Every generator's mesh is closed (each edge shared by two triangles, consistently
/// wound), wound outward, its vertices on the zero set, and its faces within the facet
/// error of it.
#[test]
fn every_primitive_mesh_is_closed_outward_and_on_its_surface() {
    let mut rng = Rng(0x3e54);
    let mut failures = Vec::new();
    for (call, p) in primitives(&mut rng) {
        let (f, _, _) = p.visit(Functions);
        let size = p.sphere_radius().unwrap_or(1.0);
        for rings in [3, 7, 14, 40] {
            let res = Resolution { rings, circle: 2 * rings };
            let Some(allowed) = facet_error(p.facets(), res) else { continue };
            let mesh = match p.tessellate(res) {
                Tessellation::Triangles(n, make) => {
                    let mesh = make();
                    assert_eq!(mesh.triangles.len() as u64, n, "{call}: the count charged is not the count made");
                    mesh
                }
                // A half-space's square is made at lowering, around the camera.
                Tessellation::HalfSpace { .. } => continue,
                Tessellation::Isosurface => {
                    failures.push(format!("{call}: no generator, but its facets are not Isosurface"));
                    continue;
                }
            };
            if mesh.open_edges() != (0, 0) {
                failures.push(format!("{call} at {rings} rings: open or inconsistently wound edges"));
            }
            if mesh.signed_volume() <= 0.0 {
                failures.push(format!("{call} at {rings} rings: wound inward"));
            }
            let tolerance = 1e-5 * size;
            if let Some(v) = mesh.positions.iter().find(|v| (f(v.as_vec3a()) as f64).abs() > tolerance) {
                failures
                    .push(format!("{call} at {rings} rings: vertex {v} is off the surface (f = {})", f(v.as_vec3a())));
            }
            for t in &mesh.triangles {
                let centre = t.iter().map(|&i| mesh.positions[i as usize]).sum::<DVec3>() / 3.0;
                let d = f(centre.as_vec3a()) as f64;
                if d.abs() > allowed + tolerance {
                    failures.push(format!(
                        "{call} at {rings} rings: a face centre lies {d} from the surface, more than the facet error {allowed}"
                    ));
                    break;
                }
            }
        }
    }
    crate::support::finish(failures);
}

/// Every builtin, and every parameter of one, says what it is; a parameter's hover text
/// is its doc and its range.
#[test]
fn every_builtin_and_parameter_is_documented() {
    for b in BUILTINS.iter() {
        assert!(!b.doc.trim().is_empty(), "`{}` has no doc", b.name);
        for p in b.params {
            assert!(!p.doc.trim().is_empty(), "`{}`'s parameter `{}` has no doc", b.name, p.name);
            assert!(p.explain().starts_with(p.doc), "{}: {}", b.name, p.explain());
        }
    }
}

/// A default needs no check when binding: it is within its parameter's range. Whole
/// numbers fit the `u32` fields they are read into.
#[test]
fn every_default_is_in_range_and_every_int_fits_its_field() {
    use scnc::sig::Default;
    for b in BUILTINS.iter() {
        for p in b.params {
            let ok = match p.default {
                Default::Num(x) if p.is_vector() => p.range.admits_vec(DVec3::splat(x)),
                Default::Num(x) => p.range.admits(x),
                Default::Vec3(v) | Default::Color(v) => p.range.admits_vec(v.into()),
                Default::Required | Default::Derived | Default::Bool(_) | Default::Str(_) => true,
            };
            assert!(ok, "`{}`'s `{}` defaults outside its range ({})", b.name, p.name, p.range.rule(p.is_vector()));
            if p.ty == Ty::Int {
                let fits = matches!(p.range.lo, Limit::Incl(l) if l >= 0.0)
                    && matches!(p.range.hi, Limit::Incl(h) if h <= u32::MAX as f64);
                assert!(fits, "`{}`'s int `{}` may not fit a u32: {}", b.name, p.name, p.range.rule(false));
            }
        }
    }
}

/// What a call of `b` with parameter `p` set to `value` says of `p`'s range: `Some`
/// (the message) if refused, `None` if accepted.
fn refusal(b: &Builtin, p: &Param, value: &str) -> Option<String> {
    let mut rng = Rng(1);
    let others: Vec<String> = b
        .params
        .iter()
        .filter(|q| q.name != p.name && q.default == scnc::sig::Default::Required)
        .map(|q| format!("{} = {}", q.name, literal(q, &mut rng).expect("a sampled argument")))
        .collect();
    let variadic = b.variadic.map(|_| "sphere(1), ".to_string()).unwrap_or_default();
    let args = format!(
        "{variadic}{}",
        others.into_iter().chain([format!("{} = {value}", p.name)]).collect::<Vec<_>>().join(", ")
    );
    let text = match b.kind() {
        Kind::Camera | Kind::Render => format!("{}({args})\n", b.name),
        Kind::MeshGenerator => format!("object mesh {}({args})\n", b.name),
        Kind::Function => format!("let v = {}({args})\n", b.name),
    };
    let c = scnc::compile_source("t.scn", Path::new("t.scn"), text, &scnc::source::FsLoader);
    let wanted = format!("`{}` must be", p.name);
    c.diagnostics.iter().find(|d| d.message.starts_with(&wanted)).map(|d| d.message.clone())
}

/// A number as a literal of parameter `p`'s type: a vector of it for a vector.
fn as_literal(p: &Param, x: f64) -> String {
    let n = scnc::sig::num(x);
    match p.ty {
        Ty::Vec3 | Ty::Size => format!("[{n}, {n}, {n}]"),
        Ty::Color => format!("rgb({n}, {n}, {n})"),
        _ => n,
    }
}

/// Each end of each documented range is checked as documented: an included end is
/// accepted and a value just past it refused; an excluded end is refused and a value
/// just inside it accepted; zero is refused where the docs say "non-zero".
#[test]
fn every_documented_range_is_the_range_checked() {
    let mut failures = Vec::new();
    for b in BUILTINS.iter() {
        for p in b.params.iter().filter(|p| !p.range.is_any() && !matches!(p.ty, Ty::Color)) {
            let step = if p.ty == Ty::Int || p.range.whole { 1.0 } else { 1e-6 };
            let mut expect = |x: f64, accepted: bool| {
                let said = refusal(b, p, &as_literal(p, x));
                if said.is_some() == accepted {
                    failures.push(format!(
                        "`{}`'s `{}` = {x}: documented as {} ({}), but {}",
                        b.name,
                        p.name,
                        if accepted { "accepted" } else { "refused" },
                        p.range.rule(p.is_vector()),
                        said.map_or("accepted".to_string(), |m| format!("refused: {m}"))
                    ));
                }
            };
            let near = |x: f64, up: bool| if up { x + step * x.abs().max(1.0) } else { x - step * x.abs().max(1.0) };
            match p.range.lo {
                Limit::Incl(l) => {
                    expect(l, true);
                    if p.range.also != Some(near(l, false)) {
                        expect(near(l, false), false);
                    }
                }
                Limit::Excl(l) => {
                    expect(l, p.range.also == Some(l));
                    expect(near(l, true), true);
                }
                Limit::Open => {}
            }
            match p.range.hi {
                Limit::Incl(h) => {
                    expect(h, true);
                    expect(near(h, true), false);
                }
                Limit::Excl(h) => {
                    expect(h, false);
                    expect(near(h, false), true);
                }
                Limit::Open => {}
            }
            if p.range.nonzero {
                expect(0.0, false);
            }
        }
    }
    crate::support::finish(failures);
}

#[test]
fn samples_respect_their_ranges() {
    let mut rng = Rng(5);
    for b in BUILTINS.iter() {
        for p in b.params.iter().filter(|p| matches!(p.ty, Ty::Num | Ty::Int)) {
            for _ in 0..20 {
                let x = sample(&p.range, p.ty == Ty::Int, &mut rng);
                assert!(p.range.admits(x), "{}: {x} sampled outside {}", p.name, p.range.rule(false));
            }
        }
    }
}

/// A primitive that says its hull is the solid itself (so a ray entering the hull from
/// outside is taken to hit there, `world::query`) means it: at random points, inside
/// the hull exactly where the distance is at most zero (away from the surface by more
/// than f32 rounding); one that says otherwise has a hull holding the solid.
#[test]
fn every_hull_said_to_be_the_solid_is() {
    let mut rng = Rng(0x4011);
    let mut failures = Vec::new();
    let mut solids = 0;
    for (call, p) in primitives(&mut rng) {
        let Some(hull) = p.hull() else {
            if p.hull_is_solid() {
                failures.push(format!("{call}: no hull, but it is said to be the solid"));
            }
            continue;
        };
        solids += usize::from(p.hull_is_solid());
        let (f, _, _) = p.visit(Functions);
        let size = p.sphere_radius().unwrap_or(1.0) as f32;
        for _ in 0..4000 {
            let x = Vec3A::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5) * (2.4 * size);
            let d = f(x);
            if d.abs() < 1e-4 * size {
                continue;
            }
            let within = hull.contains(x.as_dvec3(), 0.0);
            if d < 0.0 && !within || p.hull_is_solid() && d > 0.0 && within {
                failures.push(format!("{call}: at {x}, distance {d}, but the hull holds it: {within}"));
                break;
            }
        }
    }
    assert!(solids >= 40, "only {solids} primitives whose hull is the solid");
    crate::support::finish(failures);
}

/// Every function of numbers declares whether it has a form in fields
/// (`Ctor::in_fields`), and the declaration holds: called inside `p => …` with every
/// argument it can take varying with the point, one declared `Yes` compiles without an
/// error, and one declared `No` is refused with its declared reason.
#[test]
fn every_function_of_numbers_works_in_fields_or_says_why_not() {
    use scnc::builtins::InFields;
    let mut failures = Vec::new();
    let mut rng = Rng(3);
    let maths = BUILTINS.iter().filter(|b| b.kind() == Kind::Function && b.ctor.in_fields() != InFields::NotMaths);
    let mut seen = 0;
    for b in maths {
        seen += 1;
        let varying = |ty: Ty| match ty {
            Ty::Num | Ty::Linear => Some("(p.x * 0.1 + 0.2)".to_string()),
            Ty::Vec3 | Ty::Size => Some("p".to_string()),
            Ty::List => Some("[p.x, p.y]".to_string()),
            _ => None,
        };
        let mut args: Vec<String> = b.variadic.map_or(Vec::new(), |t| vec![varying(t).unwrap_or_default(); 2]);
        for p in b.params.iter().filter(|p| p.default == scnc::sig::Default::Required) {
            let value = varying(p.ty).or_else(|| literal(p, &mut rng)).expect("an argument");
            args.push(format!("{} = {value}", p.name));
        }
        let call = format!("{}({})", b.name, args.join(", "));
        let body = if b.result == Ty::Vec3 { format!("length({call})") } else { call.clone() };
        let text = format!("object field(p => {body} - 0.5, bounds = [[-1, -1, -1], [1, 1, 1]], lipschitz = 100)\n");
        let c = scnc::compile_source("t.scn", Path::new("t.scn"), text.clone(), &scnc::source::FsLoader);
        let errors: Vec<&str> = c
            .diagnostics
            .iter()
            .filter(|d| d.severity == scnc::diag::Severity::Error)
            .map(|d| d.message.as_str())
            .collect();
        match b.ctor.in_fields() {
            InFields::Yes(_) if !errors.is_empty() => {
                failures.push(format!("`{}` is declared to work in fields, but `{call}` gives {errors:?}", b.name))
            }
            InFields::No(why) if !errors.contains(&why) => {
                failures.push(format!("`{}` is declared not in fields ({why}), but `{call}` gives {errors:?}", b.name))
            }
            _ => {}
        }
    }
    assert!(seen >= 25, "only {seen} functions of numbers");
    crate::support::finish(failures);
}
