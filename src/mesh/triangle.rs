//! Watertight ray/triangle intersection (Woop, Benthin and Wald 2013, JCGT 2(1)).
//!
//! The ray is sheared so its direction becomes +z; the edge functions of the projected
//! triangle are then evaluated from the vertex positions alone, so two triangles sharing
//! an edge compute the same edge function with opposite signs and no ray can slip
//! between them. Exactly-zero edge functions are recomputed in f64. Both faces are hit
//! (closed meshes and reflections seen from inside need it); the tracer orients normals.

use std::ops::{Mul, Sub};

use glam::{Mat3A, Vec3A, Vec4};

/// Per-ray constants of the shear transform, as the rows of a matrix: row `x` picks
/// `p[kx] − sx·p[kz]`, row `y` picks `p[ky] − sy·p[kz]`, row `z` picks `sz·p[kz]`. Each
/// row has one zero entry, so a row times a point rounds exactly as the paper's
/// two-term formula does, without indexing vector lanes by a runtime axis.
#[derive(Clone, Copy, Debug)]
pub struct Shear {
    m: Mat3A,
    /// The axes `kx`, `ky`, `kz` and the factors `sx`, `sy`, `sz` the rows are made of,
    /// for [`Shear::intersect_block`]'s lane-wise form.
    k: [usize; 3],
    s: [f32; 3],
}

/// The shear's axes for a direction: `kz` the dominant axis, `kx` and `ky` the other
/// two, swapped when `dir[kz] < 0` to keep the winding consistent.
#[inline]
fn axes(dir: Vec3A) -> [usize; 3] {
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
    let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if dir[kz] < 0.0 {
        [ky, kx, kz]
    } else {
        [kx, ky, kz]
    }
}

impl Shear {
    /// Precomputes the shear for a direction.
    pub fn new(dir: Vec3A) -> Shear {
        let [kx, ky, kz] = axes(dir);
        let (sx, sy, sz) = (dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
        // Column `k` of the matrix holds what row x, y and z take from coordinate `k`.
        let mut cols = [Vec3A::ZERO; 3];
        cols[kx] = Vec3A::X;
        cols[ky] = Vec3A::Y;
        cols[kz] = Vec3A::new(-sx, -sy, sz);
        Shear { m: Mat3A::from_cols(cols[0], cols[1], cols[2]), k: [kx, ky, kz], s: [sx, sy, sz] }
    }

    /// [`intersect`] for the four triangles of `block` at once: the closest hit within
    /// `(t_min, t_max)` and its lane, the lowest lane on a tie, as four single tests in
    /// lane order would find it. Lane by lane the arithmetic is the single test's (its
    /// matrix rows add `0·p` terms, which can only change the sign of a zero), so the
    /// same hits, distances and weights, and shared edges stay watertight.
    #[inline(always)]
    pub fn intersect_block(&self, origin: Vec3A, block: &Block, t_min: f32, t_max: f32) -> Option<(usize, TriHit)> {
        let [kx, ky, kz] = self.k;
        let o = origin.to_array();
        let [sx, sy, sz] = self.s.map(Vec4::splat);
        let shear = |v: &[Vec4; 3]| {
            let axis = |k: usize| v[k] - Vec4::splat(o[k]);
            let (dx, dy, dz) = (axis(kx), axis(ky), axis(kz));
            [dx - sx * dz, dy - sy * dz, sz * dz]
        };
        let corners = [shear(&block.0[0]), shear(&block.0[1]), shear(&block.0[2])];
        let hits = lanes_hit(corners, Vec4::splat(t_min), Vec4::splat(t_max), 0b1111)?;
        let (mut mask, t) = (hits.mask, hits.t);
        let mut best = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        while mask != 0 {
            let l = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if t[l] < t[best] {
                best = l;
            }
        }
        Some((best, TriHit { t: t[best], bary: hits.bary.map(|b| b[best]) }))
    }
}

/// Four triangles' corners across lanes, `0[corner][axis]`, for
/// [`Shear::intersect_block`]: one test of a BVH leaf's block. A block of fewer than
/// four fills its other lanes with NaN, which never hit.
#[derive(Clone, Copy, Debug)]
pub struct Block([[Vec4; 3]; 3]);

impl Block {
    /// The block of `triangles` (at most four), their corners in order.
    pub fn new(triangles: impl IntoIterator<Item = [Vec3A; 3]>) -> Block {
        let mut lanes = [[[f32::NAN; 4]; 3]; 3];
        for (l, corners) in triangles.into_iter().enumerate() {
            assert!(l < 4, "a block holds at most four triangles");
            for (c, p) in corners.iter().enumerate() {
                for axis in 0..3 {
                    lanes[c][axis][l] = p[axis];
                }
            }
        }
        Block(lanes.map(|c| c.map(Vec4::from_array)))
    }

    /// Lane `l`'s corners.
    pub fn corners(&self, l: usize) -> [Vec3A; 3] {
        self.0.map(|c| Vec3A::new(c[0][l], c[1][l], c[2][l]))
    }
}

/// The three edge functions of a sheared triangle `a b c` from the x and y of its
/// vertices: one definition for the f32 test, its f64 redo and the 4-wide test, so that
/// all three compute exactly the same expressions.
#[inline(always)]
fn edge_functions<T: Copy + Mul<Output = T> + Sub<Output = T>>(
    (ax, ay): (T, T),
    (bx, by): (T, T),
    (cx, cy): (T, T),
) -> [T; 3] {
    [cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax]
}

/// The edge functions redone in f64, for a ray through an edge or vertex's projection,
/// where f32 rounds one of them to exactly zero.
#[inline(never)]
fn edge_functions_f64(a: (f32, f32), b: (f32, f32), c: (f32, f32)) -> [f32; 3] {
    let wide = |(x, y): (f32, f32)| (f64::from(x), f64::from(y));
    edge_functions(wide(a), wide(b), wide(c)).map(|e| e as f32)
}

/// The shear axes of four rays given as components across lanes (`axes` for four lanes
/// at once, the same comparisons as masks), or `None` when the lanes' axes differ.
fn axes4(dir: &[Vec4; 3]) -> Option<[usize; 3]> {
    let [ax, ay, az] = dir.map(Vec4::abs);
    let (x_over_y, x_over_z, y_over_z) = (ax.cmpgt(ay), ax.cmpgt(az), ay.cmpgt(az));
    let (x_major, y_major) = ((x_over_y & x_over_z).bitmask(), (!x_over_y & y_over_z).bitmask());
    let kz = match (x_major, y_major) {
        (0b1111, _) => 0,
        (_, 0b1111) => 1,
        (0, 0) => 2,
        _ => return None,
    };
    match dir[kz].cmplt(Vec4::ZERO).bitmask() {
        0 => Some([(kz + 1) % 3, (kz + 2) % 3, kz]),
        0b1111 => Some([(kz + 2) % 3, (kz + 1) % 3, kz]),
        _ => None,
    }
}

/// The shear of a packet: `N` groups of four rays from one origin whose directions share
/// their dominant axis and its sign, as coherent camera rays almost always do. Sharing
/// both, a triangle's vertices are moved to the origin and put in shear-axis order once
/// for the whole packet ([`PacketShear::triangle`]); only the shear itself is per lane.
#[derive(Clone, Copy, Debug)]
pub struct PacketShear<const N: usize> {
    origin: Vec3A,
    k: [usize; 3],
    /// `sx`, `sy`, `sz` per group, across its lanes.
    s: [[Vec4; 3]; N],
}

/// A triangle as a [`PacketShear`] sees it: each vertex relative to the packet's origin,
/// its coordinates in shear-axis order, each in all four lanes.
#[derive(Clone, Copy, Debug)]
pub struct PacketTriangle([[Vec4; 3]; 3]);

impl<const N: usize> PacketShear<N> {
    /// The shear of rays from `origin` with directions `dirs` (per group, components
    /// across lanes), or `None` when their shear axes differ.
    pub fn new(origin: Vec3A, dirs: &[[Vec4; 3]; N]) -> Option<PacketShear<N>> {
        let k = axes4(&dirs[0])?;
        if dirs[1..].iter().any(|dir| axes4(dir) != Some(k)) {
            return None;
        }
        let [kx, ky, kz] = k;
        // Lane-wise the same divisions as `Shear::new`.
        let s = dirs.map(|dir| [dir[kx] / dir[kz], dir[ky] / dir[kz], Vec4::ONE / dir[kz]]);
        Some(PacketShear { origin, k, s })
    }

    /// Triangle `v0 v1 v2` for [`intersect4`](Self::intersect4): `v − o` is the scalar
    /// test's own subtraction, done once for every lane.
    #[inline(always)]
    pub fn triangle(&self, v0: Vec3A, v1: Vec3A, v2: Vec3A) -> PacketTriangle {
        let splat = |v: Vec3A| {
            // Four entries so that `k & 3` needs no bounds check (`k` is below 3).
            let d = (v - self.origin).extend(0.0).to_array();
            self.k.map(|k| Vec4::splat(d[k & 3]))
        };
        PacketTriangle([splat(v0), splat(v1), splat(v2)])
    }

    /// [`intersect`] for the four rays of group `g` at once, for the lanes in `lanes`:
    /// per lane the same arithmetic, so the same hits, distances and weights as four
    /// single tests. The scalar matrix product adds `0·p` terms that this skips; they
    /// can only change the sign of a zero, never a value.
    #[inline(always)]
    pub fn intersect4(&self, g: usize, tri: &PacketTriangle, t_min: Vec4, t_max: Vec4, lanes: u32) -> Option<TriHit4> {
        let s = &self.s[g];
        let shear = |[dx, dy, dz]: [Vec4; 3]| [dx - s[0] * dz, dy - s[1] * dz, s[2] * dz];
        lanes_hit(tri.0.map(shear), t_min, t_max, lanes)
    }
}

/// The watertight test's second half for four lanes of sheared corners `a b c` (each
/// `[x, y, z]` across lanes): the lanes in `lanes` whose triangle the ray (the +z axis
/// after the shear) crosses within `(t_min, t_max)`, with their distances and weights.
/// Lane by lane the single test's arithmetic, so the same hits.
#[inline(always)]
fn lanes_hit(
    [[ax, ay, az], [bx, by, bz], [cx, cy, cz]]: [[Vec4; 3]; 3],
    t_min: Vec4,
    t_max: Vec4,
    lanes: u32,
) -> Option<TriHit4> {
    let [mut u, mut v, mut w] = edge_functions((ax, ay), (bx, by), (cx, cy));
    let zero = (u.cmpeq(Vec4::ZERO) | v.cmpeq(Vec4::ZERO) | w.cmpeq(Vec4::ZERO)).bitmask() & lanes;
    let inside = if zero == 0 {
        // No edge function is zero, so a lane is inside exactly when the three share
        // their sign bit (NaN lanes may pass; their `det` fails below).
        let (su, sv, sw) = (u.is_negative_bitmask(), v.is_negative_bitmask(), w.is_negative_bitmask());
        !((su ^ sv) | (su ^ sw)) & lanes
    } else {
        // Rare: the ray passes through an edge or vertex's projection.
        for l in crate::trace::lanes(zero) {
            [u[l], v[l], w[l]] = edge_functions_f64((ax[l], ay[l]), (bx[l], by[l]), (cx[l], cy[l]));
        }
        let neg = u.cmplt(Vec4::ZERO) | v.cmplt(Vec4::ZERO) | w.cmplt(Vec4::ZERO);
        let pos = u.cmpgt(Vec4::ZERO) | v.cmpgt(Vec4::ZERO) | w.cmpgt(Vec4::ZERO);
        !(neg & pos).bitmask() & lanes
    };
    if inside == 0 {
        return None;
    }
    let det = u + v + w;
    let t_scaled = u * az + v * bz + w * cz;
    let inv = Vec4::ONE / det;
    let t = t_scaled * inv;
    // `det` finite and non-zero, `t` inside the open interval; NaN lanes compare false.
    let ok = det.cmpne(Vec4::ZERO) & det.abs().cmplt(Vec4::INFINITY) & t.cmpgt(t_min) & t.cmplt(t_max);
    let mask = ok.bitmask() & inside;
    (mask != 0).then_some(TriHit4 { mask, t, bary: [u * inv, v * inv, w * inv] })
}

/// Hits of four rays on one triangle: the lanes that hit, their distances and barycentric weights.
#[derive(Clone, Copy, Debug)]
pub struct TriHit4 {
    /// Lanes that hit within their `(t_min, t_max)`.
    pub mask: u32,
    /// Distance per lane (meaningful where `mask` is set).
    pub t: Vec4,
    /// Weights of vertices 0, 1, 2 per lane.
    pub bary: [Vec4; 3],
}

impl TriHit4 {
    /// Lane `l` as a single-ray hit.
    pub fn lane(&self, l: usize) -> TriHit {
        TriHit { t: self.t[l], bary: [self.bary[0][l], self.bary[1][l], self.bary[2][l]] }
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
    let mut edges = edge_functions((a.x, a.y), (b.x, b.y), (c.x, c.y));
    if edges.contains(&0.0) {
        edges = edge_functions_f64((a.x, a.y), (b.x, b.y), (c.x, c.y));
    }
    let [u, v, w] = edges;
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

    /// Four lanes give exactly the single test's hits, distances and weights, also for
    /// rays through a shared edge (where an edge function is zero and f64 decides).
    #[test]
    fn four_lanes_match_the_single_test() {
        let (a, b) = (Vec3A::new(-1.0, -1.0, 3.0), Vec3A::new(1.0, 1.0, 3.0));
        let (c, d) = (Vec3A::new(1.0, -1.0, 3.0), Vec3A::new(-1.0, 1.0, 3.0));
        let origin = Vec3A::new(0.3, -0.7, -2.0);
        let mut checked = [0usize; 2];
        for i in 0..200 {
            // Lanes 0 and 1 aim at the shared edge, 2 and 3 around the quad and beyond it.
            let s = i as f32 / 200.0;
            let targets = [
                a + (b - a) * s,
                a + (b - a) * (1.0 - s),
                Vec3A::new(2.4 * s - 1.2, 0.7 - 1.3 * s, 3.0),
                Vec3A::new(0.9 - 2.0 * s, 1.1 * s - 0.2, 3.0),
            ];
            let dirs = targets.map(|t| (t - origin).normalize());
            let across = |v: [Vec3A; 4]| [0, 1, 2].map(|k| Vec4::new(v[0][k], v[1][k], v[2][k], v[3][k]));
            let shear = PacketShear::new(origin, &[across(dirs)]).expect("one dominant axis");
            for (v0, v1, v2) in [(a, c, b), (a, b, d), (c, b, a)] {
                let tri = shear.triangle(v0, v1, v2);
                let hits = shear.intersect4(0, &tri, Vec4::ZERO, Vec4::splat(f32::MAX), 0b1111);
                for (l, dir) in dirs.iter().enumerate() {
                    let single = intersect(origin, &Shear::new(*dir), v0, v1, v2, 0.0, f32::MAX);
                    let lane = hits.filter(|h| h.mask & (1 << l) != 0).map(|h| h.lane(l));
                    assert_eq!(single, lane, "target {} lane {l}", targets[l]);
                    checked[usize::from(single.is_some())] += 1;
                }
            }
        }
        assert!(checked[0] > 100 && checked[1] > 100, "hits and misses both tested: {checked:?}");
    }
    /// A block's test finds what single tests of its triangles in lane order find: the
    /// same closest hit, distance and weights, the lowest lane on a tie, none in the
    /// padding lanes, for rays through shared edges too.
    #[test]
    fn a_block_is_its_triangles_tested_in_order() {
        let (a, b) = (Vec3A::new(-1.0, -1.0, 3.0), Vec3A::new(1.0, 1.0, 3.0));
        let (c, d) = (Vec3A::new(1.0, -1.0, 3.0), Vec3A::new(-1.0, 1.0, 3.0));
        // Two halves of a quad, the quad again behind it (a tie with lane 0 at equal t is
        // impossible there, so its lane 3 copy of lane 0 makes one), and blocks of two
        // and one whose other lanes are padding.
        let far = Vec3A::new(0.0, 0.0, 1.5);
        let full = [[a, c, b], [a, b, d], [a + far, c + far, b + far], [a, c, b]];
        let origins = [Vec3A::new(0.3, -0.7, -2.0), Vec3A::new(-4.0, 2.0, 9.0), Vec3A::new(1e3, 1e3, -1e3)];
        let mut seen = [0usize; 3];
        for blocks in [&full[..], &full[..2], &full[1..2]] {
            let block = Block::new(blocks.iter().copied());
            for (l, tri) in blocks.iter().enumerate() {
                assert_eq!(block.corners(l), *tri);
            }
            for origin in origins {
                for i in 0..300 {
                    let s = i as f32 / 300.0;
                    for target in [a + (b - a) * s, Vec3A::new(2.4 * s - 1.2, 0.7 - 1.3 * s, 3.0)] {
                        let shear = Shear::new((target - origin).normalize());
                        let mut single = None;
                        let mut t_max = f32::MAX;
                        for (l, [v0, v1, v2]) in blocks.iter().enumerate() {
                            if let Some(hit) = intersect(origin, &shear, *v0, *v1, *v2, 0.0, t_max) {
                                t_max = hit.t;
                                single = Some((l, hit));
                            }
                        }
                        let found = shear.intersect_block(origin, &block, 0.0, f32::MAX);
                        assert_eq!(found, single, "{} triangles, origin {origin}, target {target}", blocks.len());
                        seen[found.map_or(0, |(l, _)| l.min(1) + 1)] += 1;
                    }
                }
            }
        }
        assert!(seen.iter().all(|&n| n > 50), "misses, lane 0 and later lanes all tested: {seen:?}");
    }
}
