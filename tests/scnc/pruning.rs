//! Unions walked through a hierarchy of their parts' boxes give exactly what
//! evaluating every part gives, on random CSG trees, and stay 1-Lipschitz.

use glam::{DAffine3, Vec3A};
use scnc::sdf::{Builder, Sdf, SurfSdf};
use scnc::trace::MaterialTable;

use crate::support::{scene, Rng};

/// A random solid of at most `budget` leaves, as source text.
fn solid(rng: &mut Rng, depth: u32, budget: &mut usize) -> String {
    let num = |rng: &mut Rng, lo: f32, hi: f32| lo + (hi - lo) * rng.f32();
    if depth == 0 || *budget <= 1 || rng.below(3) == 0 {
        *budget = budget.saturating_sub(1);
        let (a, b, c) = (num(rng, 0.05, 0.4), num(rng, 0.05, 0.4), num(rng, 0.05, 0.4));
        let leaf = match rng.below(6) {
            0 => format!("sphere({a})"),
            1 => format!("box({a}, {b}, {c})"),
            2 => format!("cylinder({a}, {b})"),
            3 => format!("torus({}, {b})", a + b),
            4 => format!("capsule({a}, {b})"),
            _ => format!("cone({a}, {b})"),
        };
        let (x, y, z) = (num(rng, -2.0, 2.0), num(rng, -2.0, 2.0), num(rng, -2.0, 2.0));
        let moved = match rng.below(4) {
            0 => format!("{leaf} rotate [{}, {}, 0] at [{x}, {y}, {z}]", rng.below(90), rng.below(90)),
            // A non-uniform scale makes the part's distance a loose bound.
            1 => format!("{leaf} scale [{}, 1, {}] at [{x}, {y}, {z}]", num(rng, 0.5, 2.0), num(rng, 0.5, 2.0)),
            _ => format!("{leaf} at [{x}, {y}, {z}]"),
        };
        return format!("({moved})");
    }
    let kids = |rng: &mut Rng, n: usize, budget: &mut usize| -> Vec<String> {
        (0..n).map(|_| solid(rng, depth - 1, budget)).collect()
    };
    match rng.below(7) {
        0 => format!("intersect({})", kids(rng, 2, budget).join(", ")),
        // Many cutters take the subtraction's hierarchy; smooth ones take it always.
        1 => {
            let cutters = 1 + rng.below(if depth > 2 { 30 } else { 3 });
            let parts = kids(rng, 1 + cutters, budget).join(", ");
            match rng.below(2) {
                0 => format!("subtract({parts})"),
                _ => format!("subtract({parts}, smooth = {})", num(rng, 0.02, 0.3)),
            }
        }
        2 => format!("round({}, {})", solid(rng, depth - 1, budget), num(rng, 0.01, 0.1)),
        3 => format!("shell({}, {})", solid(rng, depth - 1, budget), num(rng, 0.01, 0.1)),
        n => {
            let count = 2 + rng.below(if depth > 2 { 60 } else { 12 });
            let parts = kids(rng, count, budget).join(", ");
            if n == 4 {
                format!("union({parts})")
            } else {
                format!("union({parts}, smooth = {})", num(rng, 0.02, 0.3))
            }
        }
    }
}

/// The shape of the first object of `text`.
fn shape_of(text: &str) -> std::sync::Arc<scnc::ir::Shape> {
    match &scene(text).objects[0].geometry {
        scnc::ir::Body::Shape(shape) => shape.clone(),
        scnc::ir::Body::Mesh(_) => panic!("not a shape:\n{text}"),
    }
}

fn build(shape: &scnc::ir::Shape, prune: bool) -> (Sdf, SurfSdf) {
    let mut materials = MaterialTable::default();
    let mut b = Builder::new(&mut materials);
    b.prune = prune;
    b.build(shape, DAffine3::IDENTITY, 0)
}

#[test]
fn pruned_unions_equal_every_part_and_stay_lipschitz() {
    let mut rng = Rng(0x0dd_ba11);
    let mut leaves = 0;
    let (mut compared, mut differing) = (0usize, Vec::new());
    for case in 0..60 {
        let mut budget = 300;
        // Every fifth tree has an unbounded part: its unions evaluate every part.
        let plane = if case % 5 == 0 { "union(plane([0, 1, 0], -2.5), " } else { "union(" };
        let text = format!(
            "light ambient(1)\nobject {plane}{}) with material(color = #ff0000) at [0, 0, 8]\n",
            solid(&mut rng, 4, &mut budget)
        );
        leaves += 300 - budget;
        let shape = &shape_of(&text);
        let (fast, fast_mat) = build(shape, true);
        let (every, every_mat) = build(shape, false);
        for _ in 0..1_000 {
            let p = Vec3A::new(rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 + 6.5);
            let (a, b) = (fast(p), every(p));
            assert_eq!(a.to_bits(), b.to_bits(), "case {case} at {p}: pruned {a}, every part {b}\n{text}");
            assert_eq!(fast_mat(p), every_mat(p), "case {case} at {p}\n{text}");
            assert_eq!(fast_mat(p).d.to_bits(), a.to_bits(), "case {case}: surface and distance disagree");
            // The gradient composed through the tree is the field's slope, where the
            // field is smooth (two finite-difference steps agree). A step may straddle
            // a kink and still agree with itself (where a smooth union's nearest-first
            // fold changes order, or two parts of a sharp one tie), so a few may differ.
            let slope_at = |h: f32| {
                let d = |e: Vec3A| (fast(p + e * h) - fast(p - e * h)) / (2.0 * h);
                Vec3A::new(d(Vec3A::X), d(Vec3A::Y), d(Vec3A::Z))
            };
            let (coarse, fine) = (slope_at(2e-3), slope_at(1e-3));
            if (coarse - fine).length() < 1e-3 * fine.length() && fine.length() > 0.1 {
                let g = fast_mat(p).g;
                compared += 1;
                if (g - fine).length() > 2e-3 * fine.length().max(1.0) {
                    differing.push(format!("case {case} at {p}: gradient {g}, slope {fine}"));
                }
            }
            let step = 0.01 + rng.f32() * 0.5;
            let dir = Vec3A::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5).normalize_or(Vec3A::X);
            let q = p + dir * step;
            let slope = (fast(q) - a).abs();
            assert!(slope <= step * 1.001 + 1e-5, "case {case}: |f(p) - f(q)| = {slope} > |p - q| = {step}\n{text}");
        }
    }
    assert!(leaves > 3_000, "the trees were too small: {leaves} leaves");
    assert!(compared > 20_000, "too few smooth points: {compared}");
    assert!(
        differing.len() * 500 < compared,
        "{} of {compared} gradients differ:\n{}",
        differing.len(),
        differing.join("\n")
    );
}

/// `--stats` counts primitive evaluations: one per evaluation of a lone sphere, and for
/// a union of a thousand spheres a handful per evaluation, not a thousand.
#[test]
fn primitive_evaluations_are_counted_and_pruned() {
    use crate::support::lower;
    use scnc::world::Mode;
    let render = |text: &str| {
        let s = scene(text);
        let (frame, world) = lower(&s, 48, Mode::Sdf);
        scnc::render::render(&world, &frame, &|| {}).1
    };
    let c = render("light ambient(1)\nobject sphere(1) at [0, 0, 5]\n");
    assert!(c.sdf_evals > 0);
    assert_eq!(c.leaf_evals, c.sdf_evals + c.sdf_shading_evals);
    let c = render(
        "light ambient(1)\nlight point(1) at [2, 4, -3]\n\
         object union([for i in 0..1000 => sphere(0.08) at [i % 10, floor(i / 10) % 10, floor(i / 100)] * 0.3 - [1.35, 1.35, 1.35]])\
         at [0, 0, 5]\n",
    );
    let per_eval = c.leaf_evals as f64 / (c.sdf_evals + c.sdf_shading_evals) as f64;
    assert!(per_eval < 12.0, "{per_eval:.1} primitives per evaluation of a union of 1000");
    assert!(c.leaf_evals > c.sdf_evals, "a union evaluates more than one primitive somewhere");
}

/// A union at an object's root is marched part by part along each ray; it never passes
/// the first crossing of the whole union's field (found by a march with a hundredth of
/// the threshold), and it finds that crossing. At the hit, the normal and material from
/// the parts gathered around it are those of the whole field.
#[test]
fn unions_marched_part_by_part_hit_where_the_whole_field_does() {
    use scnc::sdf::{march, MarchParams, SdfObject};
    use scnc::trace::{Counters, Ray};
    let mut rng = Rng(0xfee1_900d);
    let params = MarchParams { epsilon: 1e-4, max_steps: 2_000 };
    let tight = MarchParams { epsilon: 1e-6, max_steps: 100_000 };
    let (mut hits, mut rays) = (0, 0);
    for case in 0..40 {
        let mut budget = 200;
        let n = 8 + rng.below(40);
        let parts: Vec<String> = (0..n).map(|_| solid(&mut rng, 2, &mut budget)).collect();
        let smooth = if case % 2 == 0 { String::new() } else { format!(", smooth = {}", 0.02 + 0.3 * rng.f32()) };
        let placed = match case % 4 {
            0 | 1 => "at [0, 0, 8]".to_string(),
            2 => "rotate [20, 30, 0] at [0, 0, 8]".to_string(),
            _ => "scale [1.5, 0.7, 1] at [0, 0, 8]".to_string(),
        };
        let text = format!("light ambient(1)\nobject union({}{smooth}) {placed}\n", parts.join(", "));
        let shape = &shape_of(&text);
        let mut materials = MaterialTable::default();
        let object = SdfObject::new(shape, DAffine3::IDENTITY, &mut Builder::new(&mut materials));
        let mut c = Counters::default();
        for _ in 0..400 {
            let target = Vec3A::new(rng.f32() * 5.0 - 2.5, rng.f32() * 5.0 - 2.5, 8.0 + rng.f32() * 5.0 - 2.5);
            let ray = Ray::new(Vec3A::ZERO, target.normalize(), 100.0);
            let mut evals = 0;
            let by_parts = object.closest(&ray, (0.0, 100.0), false, params, &mut c, &mut evals);
            // The first crossing, found by marching the whole field with a tight threshold.
            let reference = march::march(&*object.dist, &ray, 0.0, 100.0, tight, &mut c, &mut evals);
            rays += 1;
            match (by_parts, reference) {
                // Grazing rays may stop early, within the threshold of the surface; no ray
                // may pass the first crossing.
                (Some((a, ea)), Some((r, _))) => {
                    hits += 1;
                    assert!(a <= r + 2.0 * ea, "case {case}: part by part {a}, first crossing {r}\n{text}");
                    let hit = object.surface(&ray, a, ea, 0, false, &mut c);
                    // The whole field's, every part walked.
                    let whole = (object.mat)(hit.point);
                    let (normal, material) = (whole.g.normalize(), whole.mat);
                    assert!(
                        hit.normal.dot(normal) > 1.0 - 1e-5,
                        "case {case}: normal {} from nearby parts, {normal} from all\n{text}",
                        hit.normal
                    );
                    assert_eq!(hit.material, material, "case {case}: material\n{text}");
                }
                (None, Some((r, _))) => panic!("case {case}: part by part missed the crossing at {r}\n{text}"),
                (_, None) => {}
            }
        }
    }
    assert!(hits > rays / 10 && hits < rays * 9 / 10, "{hits} hits of {rays} rays: the test sees too little");
}

/// A shape's box and bounding sphere contain every point where its field is at or below
/// zero, for random trees with rounded and shelled parts under non-uniform scales
/// (whose fields are loose bounds, so a `round` reaches further than its radius).
#[test]
fn bounds_contain_the_solid() {
    let mut rng = Rng(0xb0b_5eed);
    let mut inside = 0;
    for case in 0..80 {
        let mut budget = 40;
        let part = solid(&mut rng, 3, &mut budget);
        let wrapped = match case % 3 {
            0 => format!("round({part} scale [2.5, 0.6, 1], 0.2)"),
            1 => format!("shell({part} scale [0.4, 1.8, 1], 0.15)"),
            _ => part,
        };
        let text = format!("light ambient(1)\nobject {wrapped} at [0, 0, 8]\n");
        let shape = &shape_of(&text);
        let (Some(b), Some((centre, radius))) = (scnc::ir::shape_bounds(shape), scnc::ir::shape_sphere(shape)) else {
            continue;
        };
        let (field, _) = build(shape, true);
        for _ in 0..4_000 {
            let p = Vec3A::new(rng.f32() * 12.0 - 6.0, rng.f32() * 12.0 - 6.0, rng.f32() * 12.0 + 2.0);
            if field(p) > 0.0 {
                continue;
            }
            inside += 1;
            let q = p.as_dvec3();
            let slack = 1e-5;
            assert!(
                (q - b.min).min_element() >= -slack && (b.max - q).min_element() >= -slack,
                "case {case}: {q} is inside the solid but outside its box {b:?}\n{text}"
            );
            assert!((q - centre).length() <= radius + slack, "case {case}: {q} is outside the sphere\n{text}");
        }
    }
    assert!(inside > 1_000, "only {inside} points fell inside the solids");
}

/// `tree` cut by three random solids, rounded, shelled, turned or stretched in turn, each
/// operation picked at random, sharp or smooth (a smooth subtraction when `smooth_cut`).
fn cut_about(rng: &mut Rng, mut tree: String, smooth_cut: bool) -> String {
    let mut budget = 20;
    for _ in 0..3 {
        let other = solid(rng, 2, &mut budget);
        tree = match rng.below(7) {
            0 => format!("intersect({tree}, {other})"),
            1 => format!("intersect({other}, {tree}, smooth = {})", 0.05 + 0.3 * rng.f32()),
            2 if smooth_cut => format!("subtract({tree}, {other}, smooth = {})", 0.3 * rng.f32()),
            2 => format!("subtract({tree}, {other})"),
            3 => format!("round({tree}, {})", 0.02 + 0.2 * rng.f32()),
            4 => format!("shell({tree}, {})", 0.02 + 0.2 * rng.f32()),
            5 => format!("({tree}) rotate [{}, {}, 0]", rng.below(180), rng.below(180)),
            _ => format!("({tree}) scale [{}, 1, {}]", 0.3 + 2.0 * rng.f32(), 0.3 + 2.0 * rng.f32()),
        };
    }
    tree
}

/// A gyroid sheet cut by a ball, as a field.
const GYROID_BALL: &str = "field(p => max(abs(sin(450 * p.x) * cos(450 * p.y) + sin(450 * p.y) * cos(450 * p.z) + \
     sin(450 * p.z) * cos(450 * p.x)) - 0.3, length(p) - 0.7), bounds = [[-0.7, -0.7, -0.7], [0.7, 0.7, 0.7]])";

/// A tree's hull (`world::shape_hull`, the convex set a ray is clipped to before its
/// march) holds every point where its field is at or below zero: boxes, polyhedra,
/// extrusions (an L, a holed plate with a disc beside), round solids (cylinder, cones,
/// ellipsoid, torus, capsule), a revolved profile, a twisted prism and a twisted cone
/// moved along its axis, a bent bar, and fields (their support planes, found at the
/// level a rounding or a smooth operator above them asks for; a body with a `dist`), turned,
/// stretched, cut by random solids, rounded and shelled, sharp and smooth.
#[test]
fn hulls_contain_their_solids() {
    let mut rng = Rng(0xface5);
    let (mut inside, mut trees, mut field_hulls) = (0, 0, 0);
    let polyhedra = [
        "box(0.9, 0.5, 0.7)",
        "octahedron(1)",
        "pyramid(0.8, 1.2)",
        "hex_prism(0.8, 0.5)",
        "extrude(polygon([[0, 0], [1, 0], [1, 0.5], [0.5, 0.5], [0.5, 1], [0, 1]]) at [-0.5, -0.5], 0.6)",
        "extrude(union(subtract(rect(0.8, 0.6), circle(0.3)), circle(0.4) at [0.8, 0.6]), 0.5)",
        "cylinder(0.6, 0.5)",
        "capped_cone(0.8, 0.3, 0.6)",
        "cone(0.6, 0.7)",
        "ellipsoid(0.9, 0.5, 0.7)",
        "torus(0.7, 0.25)",
        "capsule(0.4, 0.5)",
        "revolve(union(polygon([[0, -0.5], [0.8, -0.4], [0.3, 0.6], [0, 0.6]]), circle(0.2) at [0.7, 0.5]))",
        "twist(hex_prism(0.5, 0.6), 60)",
        "twist(capped_cone(0.7, 0.3, 0.6) at [0, 0.2, 0], 45)",
        "bend(box(0.2, 0.9, 0.3) rotate [0, 30, 0] at [0.1, 0, 0.2], 50)",
        GYROID_BALL,
        // A body reading a shape through `dist`: its planes must see the box.
        "field(p => min(dist(box(0.4), p - [0.4, 0, 0]), length(p + [0.4, 0, 0]) - 0.4 + 0.01 * sin(900 * p.x) * \
         sin(900 * p.y) * sin(900 * p.z)), bounds = [[-0.9, -0.9, -0.9], [0.9, 0.9, 0.9]], lipschitz = 1.5)",
        "twist(intersect(box(0.5, 0.7, 0.5), field(p => sin(450 * p.x) * cos(450 * p.y) + sin(450 * p.y) * cos(450 * p.z) + 0.5 * length(p) - 0.2, bounds = [[-0.9, -0.9, -0.9], [0.9, 0.9, 0.9]], lipschitz = 16)), 40)",
    ];
    for case in 0..288 {
        let tree = cut_about(&mut rng, polyhedra[case % polyhedra.len()].to_string(), true);
        let text = format!("light ambient(1)\nobject {tree} at [0, 0, 8]\n");
        let shape = &shape_of(&text);
        let Some(hull) = scnc::world::shape_hull(shape) else {
            // A field's planes hold where its body is at most the level asked: a large
            // rounding or blend of a steep field asks a level its whole box is below.
            assert!(tree.contains("field("), "case {case}: no hull\n{text}");
            continue;
        };
        trees += 1;
        field_hulls += usize::from(tree.contains("field("));
        let (field, _) = build(shape, true);
        for _ in 0..2_000 {
            let p = Vec3A::new(rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 + 6.5);
            if field(p) > 0.0 {
                continue;
            }
            inside += 1;
            assert!(hull.contains(p.as_dvec3(), 1e-5), "case {case}: {p} is inside the solid, not its hull\n{text}");
        }
    }
    assert!(trees >= 260 && inside > 10_000, "only {trees} hulls, {inside} points inside the solids");
    assert!(field_hulls >= 16, "only {field_hulls} of the 32 trees over fields have hulls");
}

/// An object's sphere (`world::shape_sphere`, where its rays start) holds every point
/// of its solid when fields give it the ball their solid is found in
/// (`field::support_radius`): a gyroid sheet cut by a ball, turned and moved, stretched,
/// cut by a box, rounded; a steep field; a body reading a box through `dist`; and it
/// is tight on a ball written as a field (within 10 % of its radius, where the box's
/// sphere is 73 % further out).
#[test]
fn field_spheres_hold_their_solids() {
    let mut rng = Rng(0x5fe7e);
    let trees = [
        GYROID_BALL.to_string(),
        format!("({GYROID_BALL}) rotate [30, 40, 0] at [0.2, 0, 0.1]"),
        format!("({GYROID_BALL}) scale [1.4, 0.8, 1]"),
        format!("intersect({GYROID_BALL}, box(0.5, 0.6, 0.6) rotate [0, 20, 0])"),
        format!("round({GYROID_BALL}, 0.05)"),
        "field(p => 4 * (length(p - [0.1, 0.2, 0]) - 0.6), bounds = [[-1, -1, -1], [1, 1, 1]])".into(),
        "field(p => min(dist(box(0.4), p - [0.4, 0, 0]), length(p + [0.4, 0, 0]) - 0.4), \
         bounds = [[-0.9, -0.9, -0.9], [0.9, 0.9, 0.9]])"
            .into(),
    ];
    let mut inside = 0;
    for tree in &trees {
        let text = format!("light ambient(1)\nobject {tree} at [0, 0, 8]\n");
        let shape = &shape_of(&text);
        let (centre, radius) = scnc::world::shape_sphere(shape).expect("a sphere");
        let (field, _) = build(shape, true);
        for _ in 0..40_000 {
            let p = Vec3A::new(rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 + 6.5);
            if field(p) > 0.0 {
                continue;
            }
            inside += 1;
            let out = (p.as_dvec3() - centre).length() - radius;
            assert!(out <= 1e-6, "{p} is inside the solid, {out} beyond its sphere\n{text}");
        }
    }
    assert!(inside > 5_000, "only {inside} points inside");
    let ball = "object field(p => length(p) - 0.4, bounds = [[-0.4, -0.4, -0.4], [0.4, 0.4, 0.4]]) at [0, 0, 8]";
    let (_, radius) = scnc::world::shape_sphere(&shape_of(&format!("light ambient(1)\n{ball}\n"))).unwrap();
    assert!((0.4..0.44).contains(&radius), "{radius}");
}

/// A solid's rays are clipped to its hull before they are marched: they hit where
/// the march of the same distance without a hull (a union of it alone) hits and miss
/// where it misses, each hit within its threshold of the surface, for 4,000 rays aimed
/// at and around each of a turned box, octahedron, pyramid, hex prism, extruded
/// triangle, cylinder, capped cone, ellipsoid (stretched), revolved profile, twisted
/// prism, twisted capped cone (its own cones), bent bar and a gyroid sheet cut by a
/// ball (a field), alone and cut by a box; and they take fewer steps. (Along a ray
/// grazing an edge the two hits may be apart: the march stops where it first comes
/// within the threshold, the clipped ray where it enters the solid. A ray passing an
/// edge within the threshold without entering may be a hit to one and not the other:
/// allowed when it never enters the solid, for under 0.5 % of the hits.)
#[test]
fn rays_clipped_to_hulls_hit_where_the_march_does() {
    use scnc::trace::{Counters, Geometry, Ray};
    let mut rng = Rng(0xc119);
    // Each with how many times fewer steps its clipped rays must take: a fifth for the
    // solids the hull is exactly (they take 10–55× fewer), 6 for a twist, whose
    // cylinder only starts rays nearer (3.8×) but whose march steps by its bending
    // (`sdf::warp`: 8.3×), 8 for a bend, whose planes about z (`Hull::bent`) took 3.9×
    // where the drum about z took 3.2×, and 10.5× with the bending march, and 1.2 for
    // a field, whose planes from intervals (`field::support_planes`) cut the ball its
    // solid is in (`field::support_radius`), where the march without them starts too
    // (1.30×; against its box's sphere they took 3.0×).
    let solids = [
        ("box(0.9, 0.5, 0.7)", 5.0),
        ("octahedron(1)", 5.0),
        ("pyramid(0.8, 1.2)", 5.0),
        ("hex_prism(0.8, 0.5)", 5.0),
        ("extrude(polygon([[-0.8, -0.5], [0.9, -0.3], [0.1, 0.8]]), 0.4)", 5.0),
        ("cylinder(0.6, 0.5)", 5.0),
        ("capped_cone(0.9, 0.2, 0.6)", 5.0),
        ("ellipsoid(0.9, 0.5, 0.7) scale [1, 1.5, 0.8]", 5.0),
        ("revolve(polygon([[0, -0.5], [0.8, -0.4], [0.3, 0.6], [0, 0.6]]))", 5.0),
        ("twist(hex_prism(0.5, 0.6), 60)", 6.0),
        ("twist(capped_cone(0.9, 0.2, 0.6), 45)", 5.0),
        ("bend(box(0.35, 0.9, 0.4) rotate [0, 30, 0], 50)", 8.0),
        (GYROID_BALL, 1.2),
        // Its planes found below an intersection, not only at an object's root: 1.20×
        // fewer steps than the march from its ball (1.84× from the box's sphere, where
        // the box's planes alone gave 1.56×).
        (&format!("intersect({GYROID_BALL}, box(0.5, 0.6, 0.6) rotate [0, 20, 0])"), 1.1),
    ];
    for (solid, fewer) in solids {
        // The camera at the origin looking along +z: render space is scene space.
        let text = |s: &str| {
            format!(
                "camera(position = [0, 0, 0], look_at = [0, 0, 1])\nlight ambient(1)\n\
                 object {s} rotate [25, 40, 10] at [0.2, -0.1, 6]\n"
            )
        };
        let world = |s: &str| crate::support::lower(&scene(&text(s)), 64, scnc::world::Mode::Sdf).1;
        let (clipped, marched) = (world(solid), world(&format!("union({solid})")));
        let (field, _) = build(&shape_of(&text(solid)), true);
        let (mut a, mut b, mut hits, mut grazes) = (Counters::default(), Counters::default(), 0, 0);
        for _ in 0..4_000 {
            let aim = Vec3A::new(rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 - 1.5, 6.0);
            let ray = Ray::new(Vec3A::ZERO, aim.normalize(), 100.0);
            match (clipped.intersect(&ray, &mut a), marched.intersect(&ray, &mut b)) {
                (Some(h), Some(m)) => {
                    hits += 1;
                    for (hit, what) in [(h, "clipped"), (m, "marched")] {
                        let d = field(hit.point);
                        assert!(d.abs() <= 1.5 * hit.error + 1e-5, "{solid}: {what} hit {d} from the surface");
                    }
                }
                (None, None) => {}
                (h, m) => {
                    // Only a graze: the march took a pass within its threshold for a hit,
                    // the other went past. The ray never enters the solid.
                    let (t, error) = h.or(m).map(|h| (h.t, h.error)).unwrap();
                    let deepest =
                        (0..4_000).map(|i| field(ray.dir * (t - 0.2 + 1e-4 * i as f32))).fold(f32::INFINITY, f32::min);
                    assert!(
                        (-1e-5..=error).contains(&deepest),
                        "{solid}: {:?} against {:?} along {aim}, {deepest} deep",
                        h.map(|h| h.t),
                        m.map(|m| m.t)
                    );
                    grazes += 1;
                }
            }
        }
        assert!(hits > 500, "{solid}: only {hits} hits");
        assert!(grazes * 200 < hits, "{solid}: {grazes} grazes in {hits} hits");
        assert!(
            a.sdf_evals as f64 * fewer < b.sdf_evals as f64,
            "{solid}: {} steps clipped against {} marched",
            a.sdf_evals,
            b.sdf_evals
        );
    }
}

/// An unbounded tree's half-space (`ir::shape_half_space`, where a ray's march starts)
/// holds every point where its field is at or below zero: a plane turned, stretched,
/// cut by random solids, rounded and shelled, in sharp and smooth operators.
#[test]
fn half_spaces_contain_unbounded_solids() {
    let mut rng = Rng(0x4a1f_5bac);
    let mut inside = 0;
    for case in 0..80 {
        let mut num = |lo: f32, hi: f32| lo + (hi - lo) * rng.f32();
        let (nx, ny, nz) = (num(-1.0, 1.0), num(-1.0, 1.0), num(-1.0, 1.0));
        let plane = format!("plane([{nx}, {ny}, {nz}], {})", num(-1.0, 1.0));
        let tree = cut_about(&mut rng, plane, false);
        let text = format!("light ambient(1)\nobject {tree} at [0, 0, 8]\n");
        let shape = &shape_of(&text);
        if scnc::ir::shape_bounds(shape).is_some() {
            continue;
        }
        let (n, offset) =
            scnc::ir::shape_half_space(shape).unwrap_or_else(|| panic!("case {case}: no half-space\n{text}"));
        assert!((n.length() - 1.0).abs() < 1e-12, "case {case}: normal {n} is not unit");
        let (field, _) = build(shape, true);
        for _ in 0..2_000 {
            let p = Vec3A::new(rng.f32() * 12.0 - 6.0, rng.f32() * 12.0 - 6.0, rng.f32() * 12.0 + 2.0);
            if field(p) > 0.0 {
                continue;
            }
            inside += 1;
            let beyond = n.dot(p.as_dvec3()) - offset;
            assert!(beyond <= 1e-5, "case {case}: {p} is inside the solid, {beyond} beyond its half-space\n{text}");
        }
    }
    assert!(inside > 10_000, "only {inside} points fell inside the solids");
}

/// The same spheres as one union and as separate objects make the same picture: the
/// union's part-by-part march finds what the world's object hierarchy finds.
#[test]
fn a_union_of_spheres_looks_like_the_spheres() {
    use crate::render::render_scene;
    let load = |kind: &str| crate::support::compile(std::path::Path::new(&format!("benches/scenes/{kind}-1000.scn")));
    let (union, objects) = (load("union"), load("objects"));
    let (a, _) = render_scene(union.scene.expect("union compiles"), 96, 96, 2);
    let (b, _) = render_scene(objects.scene.expect("objects compile"), 96, 96, 2);
    let differing = a
        .pixels
        .chunks(3)
        .zip(b.pixels.chunks(3))
        .filter(|(x, y)| x.iter().zip(*y).any(|(p, q)| p.abs_diff(*q) > 8))
        .count();
    assert!(differing <= 96 * 96 / 200, "{differing} of {} pixels differ", 96 * 96);
}

/// A plate with a hundred holes, cut sharp and smooth: the subtraction's hierarchy of
/// cutters gives what subtracting every cutter gives, inside the plate (where cutters
/// matter) and out. Smooth, the cutters overlap within the blend, so the nearest-first
/// fold is what makes the value independent of the order they are written in.
#[test]
fn a_perforated_plate_equals_every_cut() {
    for smooth in ["", ", smooth = 0.15"] {
        let cutters = |index: &str| {
            format!(
                "light ambient(1)\nlet cut(i) = sphere(0.05 + 0.1 * random(i)) \
                 at [(i % 10) * 0.4 - 1.8, 0.3 * random(i + 0.5) - 0.15, floor(i / 10) * 0.4 - 1.8]\n\
                 object subtract(box(2, 0.3, 2) rotate [10, 20, 0], [for j in 0..100 => cut({index})]{smooth}) \
                 with material(color = #ff0000) at [0, 0, 8]\n"
            )
        };
        let shape = &shape_of(&cutters("j"));
        let (fast, fast_mat) = build(shape, true);
        let (every, every_mat) = build(shape, false);
        let (reversed, reversed_mat) = build(&shape_of(&cutters("99 - j")), true);
        let mut rng = Rng(0x9e7f_07a7e);
        for _ in 0..20_000 {
            let p = Vec3A::new(rng.f32() * 4.4 - 2.2, rng.f32() * 1.2 - 0.6, rng.f32() * 4.4 + 5.8);
            let (a, b) = (fast(p), every(p));
            assert_eq!(a.to_bits(), b.to_bits(), "{smooth} at {p}: pruned {a}, every cutter {b}");
            assert_eq!(fast_mat(p), every_mat(p), "{smooth} at {p}");
            assert_eq!(reversed(p).to_bits(), a.to_bits(), "{smooth} at {p}: cutters reversed");
            assert_eq!(reversed_mat(p).d.to_bits(), a.to_bits(), "{smooth} at {p}: cutters reversed");
        }
    }
}

/// The reproducer of issue 44: a smooth subtraction of 99,999 cutters spread over a
/// plate evaluates a few primitives per step, not every cutter (it took 11 s at 64×64
/// when it had no hierarchy); counted, not timed.
#[test]
fn a_smooth_subtraction_of_many_cutters_is_pruned() {
    use crate::support::lower;
    use scnc::world::Mode;
    let s = scene(
        "light ambient(1)\nobject subtract(box([2, 2, 0.1]), [for i in 0..99999 => sphere(0.004) \
         at [i % 316 / 80 - 2, floor(i / 316) / 80 - 2, 0]], smooth = 0.002) at [0, 0, 5]\n",
    );
    let (frame, world) = lower(&s, 32, Mode::Sdf);
    let c = scnc::render::render(&world, &frame, &|| {}).1;
    let per_eval = c.leaf_evals as f64 / (c.sdf_evals + c.sdf_shading_evals) as f64;
    assert!(c.sdf_evals > 0);
    assert!(per_eval < 50.0, "{per_eval:.1} primitives per evaluation of a subtraction of 99,999 cutters");
}

/// A twist or bend of a solid whose distance is convex is marched by a bound on how the
/// map bends the ray (`sdf::warp`), far longer steps than its stretch alone allows.
/// Rays from all around (the bending grows with the ray's slope along the axis) and
/// rays leaving the surface as shadow rays do hit where the plain march of the same
/// closure (the solid in a union of one) hits, within its threshold; where only one of
/// them hits, the ray grazes the solid within that threshold and never enters it. The
/// rays leaving the surface take at least 5× fewer steps (8–12× here): they are what
/// the bound is for. Halving the bound fails this test; so does dropping it.
#[test]
fn twists_and_bends_marched_by_their_bending_miss_nothing() {
    use scnc::trace::{Counters, Geometry, Ray};
    let mut rng = Rng(0x7a15);
    // Rays leaving the surface that meet the solid again (where the twist or bend
    // makes it concave): about 440 of the 6 × 3,000.
    let mut again_all = 0;
    let solids = [
        "twist(hex_prism(0.5, 0.6), 60)",
        "twist(box(0.3, 1, 0.2), 200)",
        "twist(capped_cone(0.7, 0.3, 0.6) at [0.1, 0.2, 0], 45)",
        "twist(round(intersect(box(0.4, 0.8, 0.4), sphere(0.55)), 0.05), -120)",
        "bend(box(0.35, 0.9, 0.4) rotate [0, 30, 0], 50)",
        "bend(cylinder(0.3, 1) at [0.3, 0, 0], -90)",
    ];
    for solid in solids {
        let text = |s: &str| {
            format!(
                "camera(position = [0, 0, 0], look_at = [0, 0, 1])\nlight ambient(1)\n\
                 object {s} rotate [25, 40, 10] at [0.2, -0.1, 6]\n"
            )
        };
        let world = |s: &str| crate::support::lower(&scene(&text(s)), 64, scnc::world::Mode::Sdf).1;
        let (bent, plain) = (world(solid), world(&format!("union({solid})")));
        let (field, _) = build(&shape_of(&text(solid)), true);
        let centre = Vec3A::new(0.2, -0.1, 6.0);
        let mut unit = || loop {
            let v = Vec3A::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - 1.0;
            if (1e-4..=1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        };
        let (mut hits, mut grazes, mut again) = (0, 0, 0);
        let (mut leaving_bent, mut leaving_plain) = (0u64, 0u64);
        for _ in 0..3_000 {
            let origin = centre + unit() * 3.0;
            let ray = Ray::new(origin, (centre + unit() * 0.8 - origin).normalize(), 10.0);
            let Some(h) = bent.intersect(&ray, &mut Counters::default()) else { continue };
            // Leaving the hit point, from where a shadow ray starts, into its outer half.
            let out = unit();
            let out = if out.dot(h.normal) < 0.0 { -out } else { out };
            let leaving = Ray::new(h.point + h.normal * 2.0 * h.error, out, 10.0);
            for (ray, is_leaving) in [(ray, false), (leaving, true)] {
                let (mut a, mut b) = (Counters::default(), Counters::default());
                let found = (bent.intersect(&ray, &mut a), plain.intersect(&ray, &mut b));
                if is_leaving {
                    again += usize::from(found.0.is_some());
                    leaving_bent += a.sdf_evals;
                    leaving_plain += b.sdf_evals;
                }
                match found {
                    (Some(x), Some(y)) => {
                        hits += 1;
                        for hit in [x, y] {
                            let d = field(hit.point);
                            assert!(d.abs() <= 1.5 * hit.error + 1e-5, "{solid}: a hit {d} from the surface");
                        }
                    }
                    (None, None) => {}
                    (x, y) => {
                        let (t, error) = x.or(y).map(|h| (h.t, h.error)).unwrap();
                        let deepest =
                            (0..4_000).map(|i| field(ray.at(t - 0.2 + 1e-4 * i as f32))).fold(f32::INFINITY, f32::min);
                        assert!(
                            (-1e-5..=error).contains(&deepest),
                            "{solid}: {:?} against {:?} from {} along {}, {deepest} deep",
                            x.map(|h| h.t),
                            y.map(|h| h.t),
                            ray.origin,
                            ray.dir
                        );
                        grazes += 1;
                    }
                }
            }
        }
        assert!(hits > 1_000, "{solid}: only {hits} hits");
        assert!(grazes * 100 < hits, "{solid}: {grazes} grazes in {hits} hits");
        assert!(
            leaving_bent * 5 < leaving_plain,
            "{solid}: {leaving_bent} steps leaving against {leaving_plain} by the stretch"
        );
        again_all += again;
    }
    assert!(again_all > 200, "only {again_all} rays leaving the surface meet the solid again");
}

/// `Shape::has_convex_distance` (what lets a twist or bend of the shape be marched by
/// its bending) holds for exact distances of convex solids, moved, rounded, painted and
/// sharply intersected, and not for bounds or non-convex solids; and the distances it
/// names are convex with slope at most 1 along 2,000 random lines each (the midpoint
/// at most the ends' mean, the ends' difference at most their distance apart).
#[test]
fn convex_distances_are_told_from_others() {
    let cases = [
        ("sphere(0.7)", true),
        ("box(0.5, 0.3, 0.4) rotate [10, 20, 30] scale [1, 2, 0.5]", true),
        ("round(hex_prism(0.5, 0.4), 0.1)", true),
        ("intersect(box(0.5), sphere(0.6) at [0.2, 0, 0] with material(color = rgb(255, 0, 0)))", true),
        ("capped_cone(0.7, 0.2, 0.5)", true),
        ("octahedron(0.6)", true),
        ("pyramid(0.5, 0.8)", true),
        ("cylinder(0.4, 0.5)", true),
        ("capsule(0.3, 0.5)", true),
        ("ellipsoid(0.9, 0.5, 0.7)", false),
        ("torus(0.7, 0.2)", false),
        ("union(box(0.5), sphere(0.6) at [1, 0, 0])", false),
        ("intersect(box(0.5), sphere(0.6), smooth = 0.1)", false),
        ("field(p => length(p) - 1, bounds = [[-1, -1, -1], [1, 1, 1]])", false),
        ("twist(box(0.5), 30)", false),
    ];
    let mut rng = Rng(0xc0ee);
    for (text, expected) in cases {
        let shape = shape_of(&format!("light ambient(1)\nobject {text}\n"));
        assert_eq!(shape.has_convex_distance(), expected, "{text}");
        if !expected {
            continue;
        }
        let (f, _) = build(&shape, true);
        for _ in 0..2_000 {
            let mut point = || Vec3A::new(rng.f32(), rng.f32(), rng.f32()) * 3.0 - 1.5;
            let (a, b) = (point(), point());
            let (fa, fb, mid) = (f(a), f(b), f((a + b) * 0.5));
            assert!(mid <= 0.5 * (fa + fb) + 1e-5, "{text}: not convex between {a} and {b}");
            assert!((fa - fb).abs() <= a.distance(b) * (1.0 + 1e-5) + 1e-6, "{text}: steeper than 1 from {a} to {b}");
        }
    }
}

/// Sweeps whose hull is the solid itself (a ray entering it from outside hits there,
/// `world::query`): an extruded convex polygon and a revolved polygon whose union with
/// its mirror image is convex, and no other; where it is said, random points are inside
/// the hull exactly where the distance is at most zero (away from the surface).
#[test]
fn sweeps_whose_hull_is_the_solid_are_told() {
    let cases = [
        ("extrude(polygon([[-0.2, -0.2], [0.25, -0.1], [0, 0.22]]), 0.18)", true),
        ("extrude(polygon([[0.5, 0], [0.1, 0.1], [0, 0.5], [-0.5, 0], [0, -0.5]]), 0.3)", false),
        ("extrude(rect(0.4, 0.3), 0.5)", true),
        ("extrude(union(polygon([[0, 0], [1, 0], [0, 1]]), polygon([[0, 0], [-1, 0], [0, -1]])), 0.3)", false),
        ("revolve(polygon([[0, -0.22], [0.2, -0.22], [0.1, 0.22], [0, 0.22]]))", true),
        ("revolve(polygon([[0, -0.5], [0.5, -0.3], [0.6, 0.2], [0, 0.5]]))", true),
        // Not touching the axis: a ring.
        ("revolve(polygon([[0.2, -0.2], [0.5, -0.2], [0.5, 0.2], [0.2, 0.2]]))", false),
        // Touching it only at the bottom: a cone's cup.
        ("revolve(polygon([[0, -0.5], [0.5, 0.3], [0.1, 0.4]]))", false),
        ("revolve(polygon([[0, -0.5], [0.5, -0.5], [0.2, 0], [0.5, 0.5], [0, 0.5]]))", false),
    ];
    let mut rng = Rng(0x5e1d);
    for (text, expected) in cases {
        let shape = shape_of(&format!("light ambient(1)\nobject {text} rotate [20, 30, 0]\n"));
        assert_eq!(shape.hull_is_solid(), expected, "{text}");
        if !expected {
            continue;
        }
        let hull = scnc::world::shape_hull(&shape).expect("a hull");
        let (f, _) = build(&shape, true);
        let mut inside = 0;
        for _ in 0..8_000 {
            let p = Vec3A::new(rng.f32(), rng.f32(), rng.f32()) - 0.5;
            let d = f(p);
            if d.abs() < 1e-4 {
                continue;
            }
            inside += usize::from(d < 0.0);
            assert_eq!(hull.contains(p.as_dvec3(), 0.0), d < 0.0, "{text}: at {p}, distance {d}");
        }
        assert!(inside > 100, "{text}: only {inside} points inside");
    }
}
