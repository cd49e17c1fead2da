//! Axis-aligned boxes and bounding spheres in render space, and the robust ray tests
//! against them, in one place: the scalar slab test here and the 4-wide one
//! ([`enters4`]) every hierarchy walk uses, and the ray/sphere interval.

use glam::{Vec3A, Vec4};

/// Where the ray `origin + t·dir` (`dir` of unit length) is inside the sphere, or
/// `None`. The discriminant is computed from the perpendicular distance to the centre
/// (Haines et al., *Ray Tracing Gems* ch. 7), which stays accurate for distant spheres
/// where `b² − c` would cancel catastrophically.
#[inline]
pub fn sphere_interval(origin: Vec3A, dir: Vec3A, centre: Vec3A, radius: f32) -> Option<(f32, f32)> {
    let oc = origin - centre;
    let b = oc.dot(dir);
    let perp = oc - dir * b;
    let disc = radius * radius - perp.length_squared();
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    Some((-b - s, -b + s))
}

/// A bounding sphere (f64, render space) in f32, its radius widened like
/// [`Aabb::padded`].
pub fn padded_sphere(centre: glam::DVec3, radius: f64) -> (Vec3A, f32) {
    let pad = (centre.abs().max_element() + radius) * 1e-6 + 1e-6;
    (centre.as_vec3a(), (radius + pad) as f32)
}

/// The far distance of every slab test is scaled by 1 + 2γ₃ (Ize 2013, "Robust BVH Ray
/// Traversal"), so rounding never rejects a ray that touches a box, e.g. through a mesh
/// vertex.
pub const ROBUST: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON / (1.0 - 3.0 * f32::EPSILON));

/// An axis-aligned box in render space (f32).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3A,
    /// Largest corner.
    pub max: Vec3A,
}

impl Aabb {
    /// `b` (f64, render space) in f32, widened by a few ulps so rounding never clips
    /// the surface it bounds.
    pub fn padded(b: crate::ir::DAabb) -> Aabb {
        let pad = b.max.abs().max(b.min.abs()).max_element() * 1e-6 + 1e-6;
        Aabb { min: (b.min - pad).as_vec3a(), max: (b.max + pad).as_vec3a() }
    }

    /// The empty box (contains nothing; the identity of `union`).
    pub const EMPTY: Aabb = Aabb { min: Vec3A::splat(f32::INFINITY), max: Vec3A::splat(f32::NEG_INFINITY) };

    /// The box of one point.
    pub fn point(p: Vec3A) -> Aabb {
        Aabb { min: p, max: p }
    }

    /// The smallest box containing both.
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// Grown by `d` on every side.
    pub fn grow(self, d: f32) -> Aabb {
        Aabb { min: self.min - Vec3A::splat(d), max: self.max + Vec3A::splat(d) }
    }

    /// Squared distance from `p` to the box (0 inside).
    pub fn outside_squared(self, p: Vec3A) -> f32 {
        (self.min - p).max(p - self.max).max(Vec3A::ZERO).length_squared()
    }

    /// Centre point.
    pub fn centre(self) -> Vec3A {
        (self.min + self.max) * 0.5
    }

    /// Half the surface area (the SAH cost of a box).
    pub fn half_area(self) -> f32 {
        let d = (self.max - self.min).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    /// Whether `o` lies inside (with a relative tolerance for rounding).
    pub fn contains(self, o: Aabb) -> bool {
        let tol = (self.max - self.min).abs().max_element() * 1e-5 + 1e-6;
        (o.min + tol).cmpge(self.min).all() && (o.max - tol).cmple(self.max).all()
    }

    /// The parametric interval `[t0, t1]` where the ray is inside the box, clipped to
    /// `[t_min, t_max]`; `None` on a miss. `inv_dir` is `1 / dir` (infinite for zero
    /// components, which the min/max formulation handles).
    #[inline]
    pub fn slab(self, origin: Vec3A, inv_dir: Vec3A, t_min: f32, t_max: f32) -> Option<(f32, f32)> {
        let t0 = (self.min - origin) * inv_dir;
        let t1 = (self.max - origin) * inv_dir;
        // `min`/`max` of glam ignore a NaN operand (0 × ∞ on a slab face), keeping the other;
        // the far distance is scaled by [`ROBUST`].
        let near = t0.min(t1).max_element();
        let far = t0.max(t1).min_element() * ROBUST;
        // Clamped by comparisons rather than `f32::max`/`min`, which spend instructions on
        // a NaN in either operand: only `near` and `far` can be NaN, and then the bound wins
        // just as `f32::max`/`min` would choose it.
        let near = if near > t_min { near } else { t_min };
        let far = if far < t_max { far } else { t_max };
        (near <= far).then_some((near, far))
    }
}

/// The slab test four lanes at a time (four boxes for one ray, or one box for four
/// rays), from each axis's near and far plane distances per lane: the lanes that enter
/// before `t_max` (a bit per lane) and their entry distances. Every 4-wide box test of
/// the walks is this one function, so a ray tested in a packet enters exactly the boxes
/// it enters tested alone (same operations, same operand order).
#[inline(always)]
pub(crate) fn enters4(axes: [(Vec4, Vec4); 3], t_min: Vec4, t_max: Vec4) -> (u32, Vec4) {
    let mut near = t_min;
    let mut far = Vec4::INFINITY;
    for (lo, hi) in axes {
        near = max_keep(lo, near);
        far = min_keep(hi, far);
    }
    let far = min_keep(far * ROBUST, t_max);
    (near.cmple(far).bitmask(), near)
}

/// `a.max(b)`, and `b` where `a` is NaN (a ray in a slab's face plane makes `0 × ∞`):
/// then the bound so far stands, as in the scalar [`Aabb::slab`].
#[inline(always)]
fn max_keep(a: Vec4, b: Vec4) -> Vec4 {
    nan_keeps_second(a.max(b), a.cmpgt(b), a, b)
}

/// `a.min(b)`, and `b` where `a` is NaN (see [`max_keep`]).
#[inline(always)]
fn min_keep(a: Vec4, b: Vec4) -> Vec4 {
    nan_keeps_second(a.min(b), a.cmplt(b), a, b)
}

/// `native` (glam's `min`/`max`) where it is SSE's `minps`/`maxps`, which return the
/// second operand when either is NaN; elsewhere (NEON propagates NaN) `a` where `a_wins`,
/// else `b`, which says the same explicitly. The unused form compiles away.
#[inline(always)]
fn nan_keeps_second(native: Vec4, a_wins: glam::BVec4A, a: Vec4, b: Vec4) -> Vec4 {
    if cfg!(any(target_arch = "x86", target_arch = "x86_64")) {
        native
    } else {
        Vec4::select(a_wins, a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The perpendicular-distance form stays accurate where `b² − c` cancels: a unit
    /// sphere 1e4 and 1e5 away, hit near its silhouette, against the same maths in f64.
    #[test]
    fn sphere_interval_is_stable_far_away() {
        for dist in [10.0f64, 1e4, 1e5] {
            for offset in [0.0f64, 0.5, 0.9, 0.999] {
                let centre = glam::DVec3::new(offset, 0.0, dist);
                let dir = glam::DVec3::Z;
                let b = centre.dot(dir);
                let perp = (centre - dir * b).length_squared();
                let s = (1.0 - perp).sqrt();
                let (t0, t1) = (b - s, b + s);
                let (a0, a1) =
                    sphere_interval(Vec3A::ZERO, Vec3A::Z, centre.as_vec3a(), 1.0).expect("the ray hits the sphere");
                // Within a few f32 ulps of the distance, not the much larger cancellation error.
                let tol = dist * 4.0 * f32::EPSILON as f64;
                assert!(
                    (a0 as f64 - t0).abs() <= tol && (a1 as f64 - t1).abs() <= tol,
                    "at {dist}, offset {offset}: ({a0}, {a1}) vs ({t0}, {t1})"
                );
                // The naive form b² − c loses the chord entirely this far away.
                if dist >= 1e4 && offset > 0.9 {
                    let c32 = centre.as_vec3().length_squared() - 1.0;
                    let b32 = b as f32;
                    let naive = b32 * b32 - c32;
                    let truth = 1.0 - perp;
                    assert!(
                        (naive as f64 - truth).abs() > 0.5 * truth,
                        "this case should defeat the naive form ({naive} vs {truth})"
                    );
                }
            }
        }
    }

    /// A NaN lane (a ray in a face plane) leaves the bound so far, on every target.
    #[test]
    fn a_nan_distance_keeps_the_bound() {
        let nan = Vec4::new(f32::NAN, 1.0, f32::NAN, 5.0);
        let bound = Vec4::new(2.0, 2.0, 2.0, 2.0);
        assert_eq!(max_keep(nan, bound).to_array(), [2.0, 2.0, 2.0, 5.0]);
        assert_eq!(min_keep(nan, bound).to_array(), [2.0, 1.0, 2.0, 2.0]);
        // The explicit form other targets use agrees with the native one here.
        assert_eq!(Vec4::select(nan.cmpgt(bound), nan, bound).to_array(), max_keep(nan, bound).to_array());
        assert_eq!(Vec4::select(nan.cmplt(bound), nan, bound).to_array(), min_keep(nan, bound).to_array());
    }
}
