//! Watertight ray/triangle intersection (Woop, Benthin and Wald 2013, JCGT 2(1)).
//!
//! The ray is sheared so its direction becomes +z; the edge functions of the projected
//! triangle are then evaluated from the vertex positions alone, so two triangles sharing
//! an edge compute the same edge function with opposite signs and no ray can slip
//! between them. Exactly-zero edge functions are recomputed in f64. Both faces are hit
//! (closed meshes and reflections seen from inside need it); the tracer orients normals.

use glam::Vec3A;

/// Per-ray constants of the shear transform.
#[derive(Clone, Copy, Debug)]
pub struct Shear {
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

impl Shear {
    /// Precomputes the shear for a direction.
    pub fn new(dir: Vec3A) -> Shear {
        let a = dir.abs();
        let kz = if a.x > a.y {
            if a.x > a.z {
                0
            } else {
                2
            }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Swap to keep the winding consistent when the dominant axis points backwards.
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Shear { kx, ky, kz, sx: dir[kx] / dir[kz], sy: dir[ky] / dir[kz], sz: 1.0 / dir[kz] }
    }
}

/// A hit: distance and barycentric weights of the three vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriHit {
    /// Ray parameter.
    pub t: f32,
    /// Weights of vertices 0, 1, 2 (sum 1).
    pub bary: [f32; 3],
}

/// Intersects the ray `origin + t·dir` (with `shear` from `dir`) with triangle `v0 v1 v2`
/// for `t` in `(t_min, t_max)`.
#[inline]
pub fn intersect(
    origin: Vec3A,
    shear: &Shear,
    v0: Vec3A,
    v1: Vec3A,
    v2: Vec3A,
    t_min: f32,
    t_max: f32,
) -> Option<TriHit> {
    let Shear { kx, ky, kz, sx, sy, sz } = *shear;
    let a = v0 - origin;
    let b = v1 - origin;
    let c = v2 - origin;
    let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
    let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
    let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || v == 0.0 || w == 0.0 {
        let (ax, ay, bx, by, cx, cy) = (ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64);
        u = (cx * by - cy * bx) as f32;
        v = (ax * cy - ay * cx) as f32;
        w = (bx * ay - by * ax) as f32;
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let (az, bz, cz) = (sz * a[kz], sz * b[kz], sz * c[kz]);
    let t_scaled = u * az + v * bz + w * cz;
    let inv = 1.0 / det;
    let t = t_scaled * inv;
    if !(t > t_min && t < t_max) {
        return None;
    }
    Some(TriHit { t, bary: [u * inv, v * inv, w * inv] })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_inside_misses_outside_both_faces() {
        let (v0, v1, v2) = (Vec3A::new(-1.0, -1.0, 5.0), Vec3A::new(1.0, -1.0, 5.0), Vec3A::new(0.0, 1.0, 5.0));
        let dir = Vec3A::Z;
        let s = Shear::new(dir);
        let hit = intersect(Vec3A::ZERO, &s, v0, v1, v2, 0.0, 100.0).expect("hit");
        assert!((hit.t - 5.0).abs() < 1e-6);
        assert!((hit.bary.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        // The back face is hit too.
        assert!(intersect(Vec3A::ZERO, &s, v0, v2, v1, 0.0, 100.0).is_some());
        assert!(intersect(Vec3A::new(3.0, 0.0, 0.0), &s, v0, v1, v2, 0.0, 100.0).is_none());
        assert!(intersect(Vec3A::ZERO, &s, v0, v1, v2, 0.0, 4.0).is_none(), "beyond t_max");
        let back = Shear::new(-dir);
        assert!(intersect(Vec3A::ZERO, &back, v0, v1, v2, 0.0, 100.0).is_none(), "behind the origin");
    }

    /// A ray through the shared edge of two triangles hits at least one of them.
    #[test]
    fn shared_edges_are_watertight() {
        let (a, b) = (Vec3A::new(-1.0, -1.0, 3.0), Vec3A::new(1.0, 1.0, 3.0));
        let (c, d) = (Vec3A::new(1.0, -1.0, 3.0), Vec3A::new(-1.0, 1.0, 3.0));
        // The open interval: the end points are corners of the quad's open boundary.
        for i in 1..1000 {
            let s = i as f32 / 1000.0;
            let target = a + (b - a) * s;
            for origin in [Vec3A::ZERO, Vec3A::new(0.3, -0.7, -2.0), Vec3A::new(1e3, 1e3, -1e3)] {
                let dir = (target - origin).normalize();
                let sh = Shear::new(dir);
                let hit = intersect(origin, &sh, a, c, b, 0.0, f32::MAX).is_some()
                    || intersect(origin, &sh, a, b, d, 0.0, f32::MAX).is_some();
                assert!(hit, "ray through the shared edge at s = {s} from {origin} slipped through");
            }
        }
    }
}
