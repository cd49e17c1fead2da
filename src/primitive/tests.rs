//! Each primitive's distance against an independent formulation of the same solid. (The
//! properties every primitive must have are checked for all of them at once, from the
//! list, in `tests/scnc/derived.rs`.)

use glam::{DVec3, Vec3A};

use super::*;

/// A small deterministic generator (xorshift), so failures reproduce.
struct Rng(u64);

impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn point(&mut self, r: f32) -> Vec3A {
        Vec3A::new(self.f() * 2.0 - 1.0, self.f() * 2.0 - 1.0, self.f() * 2.0 - 1.0) * r
    }
}

/// Distance from `p` to the box by clamping (outside) or the nearest face (inside):
/// an independent formulation of the exact box distance.
fn box_reference(p: Vec3A, b: Vec3A) -> f32 {
    let clamped = p.clamp(-b, b);
    if clamped != p {
        (p - clamped).length()
    } else {
        -(b - p.abs()).min_element()
    }
}

/// Distance in the (radial, y) half-plane to the rectangle `[0, r] × [−h, h]`.
fn cylinder_reference(p: Vec3A, r: f32, h: f32) -> f32 {
    let q = Vec3A::new((p.x * p.x + p.z * p.z).sqrt(), p.y, 0.0);
    // A huge z extent makes the 3D box reference act as a 2D rectangle.
    box_reference(q, Vec3A::new(r, h, 1e30))
}

fn segment_distance(p: Vec3A, a: Vec3A, b: Vec3A) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    (p - (a + ab * t)).length()
}

#[test]
fn exact_primitives_match_independent_formulas() {
    let mut rng = Rng(0x1234_5678_9abc);
    let b = Vec3A::new(0.7, 0.3, 1.1);
    let sphere = Sphere { r: 0.8 }.distance();
    let cuboid = Cuboid { size: DVec3::new(0.7, 0.3, 1.1) }.distance();
    let cylinder = Cylinder { r: 0.6, half_height: 0.9 }.distance();
    let torus = Torus { major: 1.2, minor: 0.3 }.distance();
    let capsule = Capsule { r: 0.4, half_height: 0.5 }.distance();
    let n = Vec3A::new(0.3, 0.9, -0.2).normalize();
    let plane = Plane { normal: n.as_dvec3(), offset: 0.25 }.distance();
    for _ in 0..20_000 {
        let p = rng.point(2.5);
        assert!((sphere(p) - (p.length() - 0.8)).abs() < 1e-5);
        assert!((cuboid(p) - box_reference(p, b)).abs() < 1e-5, "box at {p}");
        assert!((cylinder(p) - cylinder_reference(p, 0.6, 0.9)).abs() < 1e-5, "cylinder at {p}");
        let ring = Vec3A::new(p.x, 0.0, p.z).try_normalize().unwrap_or(Vec3A::X) * 1.2;
        assert!((torus(p) - ((p - ring).length() - 0.3)).abs() < 1e-5, "torus at {p}");
        let seg = segment_distance(p, Vec3A::new(0.0, -0.5, 0.0), Vec3A::new(0.0, 0.5, 0.0));
        assert!((capsule(p) - (seg - 0.4)).abs() < 1e-5, "capsule at {p}");
        assert!((plane(p) - (p.dot(n) - 0.25)).abs() < 1e-5);
    }
}

/// Cones have no simple independent formula, so compare outside points with the
/// distance to a dense sampling of the profile's boundary (error at most the sampling gap).
#[test]
fn cones_match_their_sampled_profiles() {
    let h = 0.6f32;
    for (r1, r2) in [(0.8f32, 0.0f32), (0.8, 0.3), (0.2, 0.9), (0.0, 0.7), (0.5, 0.5)] {
        let d = CappedCone { r_bottom: r1 as f64, r_top: r2 as f64, half_height: h as f64 }.distance();
        let mut boundary = Vec::new();
        let steps = 400;
        for i in 0..=steps {
            let s = i as f32 / steps as f32;
            boundary.push(Vec3A::new(r1 + (r2 - r1) * s, -h + 2.0 * h * s, 0.0)); // slanted side
            boundary.push(Vec3A::new(r1 * s, -h, 0.0)); // bottom
            boundary.push(Vec3A::new(r2 * s, h, 0.0)); // top
        }
        let gap = 2.0 * ((r1 - r2).powi(2) + 4.0 * h * h).sqrt().max(r1.max(r2)) / steps as f32;
        let mut rng = Rng(0xfeed_beef);
        for _ in 0..2000 {
            let p = rng.point(2.0);
            // By symmetry, measure in the (radial, y) plane.
            let q = Vec3A::new((p.x * p.x + p.z * p.z).sqrt(), p.y, 0.0);
            let nearest = boundary.iter().map(|s| (q - *s).length()).fold(f32::INFINITY, f32::min);
            assert!((d(p).abs() - nearest).abs() <= gap, "capped cone {r1} {r2} at {p}: {} vs {nearest}", d(p));
        }
    }
    // A cone is the capped cone with no top.
    let cone = Cone { r: 0.8, half_height: 0.6 }.distance();
    let capped = CappedCone { r_bottom: 0.8, r_top: 0.0, half_height: 0.6 }.distance();
    let mut rng = Rng(7);
    for _ in 0..1000 {
        let p = rng.point(2.0);
        assert_eq!(cone(p), capped(p));
    }
}
