//! Watertight ray/triangle intersection (Woop, Benthin and Wald 2013, JCGT 2(1)).
//!
//! The ray is sheared so its direction becomes +z; the edge functions of the projected
//! triangle are then evaluated from the vertex positions alone, so two triangles sharing
//! an edge compute the same edge function with opposite signs and no ray can slip
//! between them. Exactly-zero edge functions are recomputed in f64. Both faces are hit
//! (closed meshes and reflections seen from inside need it); the tracer orients normals.

use glam::{Mat3A, Vec3A};

/// Per-ray constants of the shear transform, as the rows of a matrix: row `x` picks
/// `p[kx] − sx·p[kz]`, row `y` picks `p[ky] − sy·p[kz]`, row `z` picks `sz·p[kz]`. Each
/// row has one zero entry, so a row times a point rounds exactly as the paper's
/// two-term formula does, without indexing vector lanes by a runtime axis.
#[derive(Clone, Copy, Debug)]
pub struct Shear {
    m: Mat3A,
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
        let (sx, sy, sz) = (dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
        // Column `k` of the matrix holds what row x, y and z take from coordinate `k`.
        let mut cols = [Vec3A::ZERO; 3];
        cols[kx] = Vec3A::X;
        cols[ky] = Vec3A::Y;
        cols[kz] = Vec3A::new(-sx, -sy, sz);
        Shear { m: Mat3A::from_cols(cols[0], cols[1], cols[2]) }
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
    let a = shear.m * (v0 - origin);
    let b = shear.m * (v1 - origin);
    let c = shear.m * (v2 - origin);
    let mut u = c.x * b.y - c.y * b.x;
    let mut v = a.x * c.y - a.y * c.x;
    let mut w = b.x * a.y - b.y * a.x;
    if u == 0.0 || v == 0.0 || w == 0.0 {
        let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        u = (c.x * b.y - c.y * b.x) as f32;
        v = (a.x * c.y - a.y * c.x) as f32;
        w = (b.x * a.y - b.y * a.x) as f32;
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let t_scaled = u * a.z + v * b.z + w * c.z;
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
