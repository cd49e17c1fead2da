//! Rays in render space, packets of four, and where secondary rays start.

use glam::{Mat4, Vec3A, Vec4};

use super::Hit;

/// A ray in render space.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3A,
    /// Unit direction.
    pub dir: Vec3A,
    /// Component-wise `1 / dir`, for slab tests.
    pub inv_dir: Vec3A,
    /// Nearest accepted hit distance.
    pub t_min: f32,
    /// Farthest accepted hit distance.
    pub t_max: f32,
    /// An object the ray cannot meet, which a back-end may leave out ([`NO_OBJECT`] for none):
    /// the convex object a secondary ray leaves (see [`Ray::leaving`]).
    pub skip: u32,
    /// The object the ray starts inside ([`NO_OBJECT`] for none): a ray refracted into
    /// a transparent object, whose back-end must then find the surface from within
    /// (an SDF marches `−f`).
    pub inside: u32,
}

/// No object: the [`Ray::skip`] of a ray that may meet anything.
pub const NO_OBJECT: u32 = u32::MAX;

impl Ray {
    /// A ray from `origin` along the unit vector `dir`, accepting hits in `[0, t_max]`.
    pub fn new(origin: Vec3A, dir: Vec3A, t_max: f32) -> Ray {
        debug_assert!(origin.is_finite() && dir.is_finite(), "non-finite ray");
        Ray { origin, dir, inv_dir: dir.recip(), t_min: 0.0, t_max, skip: NO_OBJECT, inside: NO_OBJECT }
    }

    /// A secondary ray from `origin`, just off `hit`'s surface, along `dir`. When the hit
    /// object lies wholly behind its tangent plane at the hit ([`Hit::behind`]) and the ray
    /// starts in front of that plane and moves away from it, every point of the ray is in
    /// front of the plane, so the ray cannot meet the object again and skips it: that
    /// saves walking the object's own BVH, which every such ray starts inside, and makes
    /// self-intersection there impossible rather than only guarded by the offset.
    pub fn leaving(hit: &Hit, origin: Vec3A, dir: Vec3A, t_max: f32) -> Ray {
        let mut ray = Ray::new(origin, dir, t_max);
        if let Some(n) = hit.behind {
            if n.dot(origin - hit.point) > 0.0 && n.dot(dir) > 0.0 {
                ray.skip = hit.object;
            }
        }
        ray
    }

    /// The point at distance `t`.
    pub fn at(&self, t: f32) -> Vec3A {
        self.origin + self.dir * t
    }
}

/// Up to four rays traced together (a 2×2 block of camera rays; the tracer sends four
/// as a 4×4 block, [`Geometry::intersect16`](super::Geometry::intersect16)). Lane `k` is wanted when
/// bit `k` of `mask` is set; an unwanted lane holds a copy of a wanted ray, so every lane
/// is a valid ray and a back-end may trace all four.
#[derive(Clone, Copy, Debug)]
pub struct Packet {
    /// The rays, one per lane.
    pub rays: [Ray; 4],
    /// Wanted lanes.
    pub mask: u32,
}

impl Packet {
    /// A packet of one to four rays (lanes beyond `rays.len()` are unwanted copies of the last).
    pub fn new(rays: &[Ray]) -> Packet {
        Packet::from_fn(rays.len(), |l| rays[l])
    }

    /// A packet of `count` (one to four) rays, lane `l` being `ray(l)`; lanes beyond
    /// `count` are unwanted copies of the last.
    pub fn from_fn(count: usize, mut ray: impl FnMut(usize) -> Ray) -> Packet {
        assert!((1..=4).contains(&count), "a packet holds one to four rays");
        Packet { rays: std::array::from_fn(|l| ray(l.min(count - 1))), mask: (1 << count) - 1 }
    }

    /// A vector of the lanes' rays across SIMD lanes (structure of arrays) per axis:
    /// component `k` of `f(ray l)` is lane `l` of vector `k`. One transpose.
    #[inline(always)]
    pub fn across(&self, f: impl Fn(&Ray) -> Vec3A) -> [Vec4; 3] {
        let col = |l: usize| f(&self.rays[l]).extend(0.0);
        let m = Mat4::from_cols(col(0), col(1), col(2), col(3)).transpose();
        [m.x_axis, m.y_axis, m.z_axis]
    }

    /// `f(ray l)` in lane `l`.
    #[inline(always)]
    pub fn each(&self, f: impl Fn(&Ray) -> f32) -> Vec4 {
        Vec4::from_array(self.rays.each_ref().map(f))
    }
}

/// The lanes set in a packet's `mask`, lowest first (bit `k` is lane `k`; packets traced
/// together number their lanes on, four to a packet).
#[inline(always)]
pub fn lanes(mask: u32) -> impl Iterator<Item = usize> {
    let mut rest = mask;
    std::iter::from_fn(move || {
        let lane = (rest != 0).then(|| rest.trailing_zeros() as usize)?;
        rest &= rest - 1;
        Some(lane)
    })
}

/// How far a secondary ray must start from a hit point to not find the same surface:
/// beyond the back-end's stated error, plus a few f32 ulps of the point's magnitude
/// (so the offset grows with distance instead of being a fixed 1e-3).
pub fn spawn_offset(point: Vec3A, error: f32) -> f32 {
    2.0 * error + point.abs().max_element() * 4.0 * f32::EPSILON + f32::MIN_POSITIVE
}
