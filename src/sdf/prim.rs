//! Distance functions of the primitives, centred at the origin. All are exact
//! Euclidean distances (after Inigo Quilez's formulas) unless noted.

use glam::{Vec2, Vec3A, Vec3Swizzles};

/// Sphere of radius `r`.
#[inline]
pub fn sphere(p: Vec3A, r: f32) -> f32 {
    p.length() - r
}

/// Box with half-extents `b`.
#[inline]
pub fn cuboid(p: Vec3A, b: Vec3A) -> f32 {
    let q = p.abs() - b;
    q.max(Vec3A::ZERO).length() + q.max_element().min(0.0)
}

/// Capped cylinder along y.
#[inline]
pub fn cylinder(p: Vec3A, r: f32, h: f32) -> f32 {
    let d = Vec2::new(p.xz().length() - r, p.y.abs() - h);
    d.max_element().min(0.0) + d.max(Vec2::ZERO).length()
}

/// Torus in the xz plane.
#[inline]
pub fn torus(p: Vec3A, major: f32, minor: f32) -> f32 {
    Vec2::new(p.xz().length() - major, p.y).length() - minor
}

/// Half-space below `n·p = offset` (`n` unit).
#[inline]
pub fn plane(p: Vec3A, n: Vec3A, offset: f32) -> f32 {
    p.dot(n) - offset
}

/// Capsule along y: the segment `y ∈ [−h, h]` thickened by `r`.
#[inline]
pub fn capsule(p: Vec3A, r: f32, h: f32) -> f32 {
    let q = Vec3A::new(p.x, p.y - p.y.clamp(-h, h), p.z);
    q.length() - r
}

/// Capped cone along y, base radius `r` at `y = −h`, apex at `y = h`.
#[inline]
pub fn cone(p: Vec3A, r: f32, h: f32) -> f32 {
    let q = Vec2::new(p.xz().length(), p.y);
    let k1 = Vec2::new(0.0, h);
    let k2 = Vec2::new(-r, 2.0 * h);
    let ca = Vec2::new(q.x - q.x.min(if q.y < 0.0 { r } else { 0.0 }), q.y.abs() - h);
    let cb = q - k1 + k2 * ((k1 - q).dot(k2) / k2.length_squared()).clamp(0.0, 1.0);
    let s = if cb.x < 0.0 && ca.y < 0.0 { -1.0 } else { 1.0 };
    s * ca.length_squared().min(cb.length_squared()).sqrt()
}

/// Polynomial smooth minimum (radius `k` > 0). It is 1-Lipschitz when `a` and `b` are:
/// in the blend its gradient is a convex combination of theirs.
#[inline]
pub fn smin(a: f32, b: f32, k: f32) -> f32 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

#[cfg(test)]
mod tests {
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
        for _ in 0..20_000 {
            let p = rng.point(2.5);
            assert!((sphere(p, 0.8) - (p.length() - 0.8)).abs() < 1e-5);
            assert!((cuboid(p, b) - box_reference(p, b)).abs() < 1e-5, "box at {p}");
            assert!((cylinder(p, 0.6, 0.9) - cylinder_reference(p, 0.6, 0.9)).abs() < 1e-5, "cylinder at {p}");
            let ring = Vec3A::new(p.x, 0.0, p.z).try_normalize().unwrap_or(Vec3A::X) * 1.2;
            assert!((torus(p, 1.2, 0.3) - ((p - ring).length() - 0.3)).abs() < 1e-5, "torus at {p}");
            let seg = segment_distance(p, Vec3A::new(0.0, -0.5, 0.0), Vec3A::new(0.0, 0.5, 0.0));
            assert!((capsule(p, 0.4, 0.5) - (seg - 0.4)).abs() < 1e-5, "capsule at {p}");
            let n = Vec3A::new(0.3, 0.9, -0.2).normalize();
            assert!((plane(p, n, 0.25) - (p.dot(n) - 0.25)).abs() < 1e-6);
        }
    }

    /// The cone has no simple independent formula, so compare outside points with the
    /// distance to a dense sampling of its surface (error at most the sampling gap).
    #[test]
    fn cone_matches_sampled_surface() {
        let (r, h) = (0.8f32, 0.6f32);
        let mut surface = Vec::new();
        let steps = 200;
        for i in 0..=steps {
            let s = i as f32 / steps as f32;
            surface.push(Vec3A::new(r * (1.0 - s), -h + 2.0 * h * s, 0.0)); // slanted side
            surface.push(Vec3A::new(r * s, -h, 0.0)); // base
        }
        let gap = 2.0 * (r * r + 4.0 * h * h).sqrt() / steps as f32;
        let mut rng = Rng(0xfeed_beef);
        for _ in 0..2000 {
            let p = rng.point(2.0);
            // By symmetry, measure in the (radial, y) plane.
            let q = Vec3A::new((p.x * p.x + p.z * p.z).sqrt(), p.y, 0.0);
            let nearest = surface.iter().map(|s| (q - *s).length()).fold(f32::INFINITY, f32::min);
            let d = cone(p, r, h);
            assert!((d.abs() - nearest).abs() <= gap, "cone at {p}: {d} vs {nearest}");
        }
    }

    #[test]
    fn smooth_min_is_below_min_and_lipschitz() {
        let mut rng = Rng(42);
        for _ in 0..10_000 {
            let (a, b, k) = (rng.f() * 4.0 - 2.0, rng.f() * 4.0 - 2.0, rng.f() + 0.01);
            let (da, db) = (rng.f() * 0.1 - 0.05, rng.f() * 0.1 - 0.05);
            let s = smin(a, b, k);
            assert!(s <= a.min(b) + 1e-6);
            assert!(s >= a.min(b) - k * 0.25 - 1e-6);
            // |Δsmin| ≤ max(|Δa|, |Δb|).
            assert!((smin(a + da, b + db, k) - s).abs() <= da.abs().max(db.abs()) + 1e-5);
        }
    }
}
