//! Convex sets holding a solid, cheap to clip a ray to: planes, and cones and a ball
//! about an axis of a frame of their own. A ray is clipped to its object's hull before
//! it is marched, so a miss costs no step and a hit starts at (or near) the surface —
//! exactly on it for a convex polyhedron, a cylinder, a capped cone or an ellipsoid.

use super::DAabb;
use glam::{DAffine3, DMat3, DVec3};

/// A convex set holding a solid: where every plane and the round part hold.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Hull {
    /// Planes `n·p ≤ offset` (unit `n`).
    pub planes: Vec<(DVec3, f64)>,
    /// Constraints about an axis, in a frame of their own.
    pub round: Option<Round>,
}

/// Cones and a ball about the `y` axis of a local frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Round {
    /// From the hull's frame to the local one.
    to_local: DAffine3,
    /// How far `to_local` can stretch a length (a bound on its largest singular value):
    /// a point within `g` of the set is within `g · stretch` of it in the local frame.
    stretch: f64,
    /// `a·r + b·y ≤ c` with `(a, b)` unit and `a ≥ 0`, `r` the local distance from the
    /// `y` axis: a cone's side (`b ≠ 0`), a cylinder (`b = 0`) or a cap (`a = 0`).
    cones: Vec<(f64, f64, f64)>,
    /// `|p| ≤ ball` in the local frame.
    ball: Option<f64>,
}

impl Round {
    /// Cones `a·r + b·y ≤ c` about the `y` axis of the hull's own frame (`(a, b)` is
    /// normalised; a cone with `a < 0` holds nothing a circle about the axis can cross,
    /// so it is refused as `None`).
    pub fn about_y(cones: impl IntoIterator<Item = (f64, f64, f64)>) -> Option<Round> {
        let cones: Option<Vec<_>> = cones
            .into_iter()
            .map(|(a, b, c)| {
                let k = a.hypot(b);
                (a >= 0.0 && k > 0.0 && c.is_finite()).then(|| (a / k, b / k, c / k))
            })
            .collect();
        Some(Round { to_local: DAffine3::IDENTITY, stretch: 1.0, cones: cones?, ball: None })
    }

    /// The ellipsoid of semi-axes `radii` along x, y and z.
    pub fn ellipsoid(radii: DVec3) -> Option<Round> {
        let to_local = DAffine3::from_scale(radii.recip());
        let stretch = max_stretch(to_local.matrix3);
        (radii.min_element() > 0.0 && stretch.is_finite()).then_some(Round {
            to_local,
            stretch,
            cones: Vec::new(),
            ball: Some(1.0),
        })
    }

    /// Whether the set is about the hull's own `y` axis (its frame is the hull's), so a
    /// turn about that axis leaves it as it is.
    pub fn turns_with_y(&self) -> bool {
        let t = self.to_local.translation;
        self.to_local.matrix3 == DMat3::IDENTITY && t.x == 0.0 && t.z == 0.0
    }

    /// Holding every point within `g` of this set.
    fn grown(mut self, g: f64) -> Round {
        let g = g * self.stretch;
        self.cones.iter_mut().for_each(|c| c.2 += g);
        self.ball = self.ball.map(|b| b + g);
        self
    }

    /// The image of the set under `xf`, or `None` if `xf` is too degenerate to invert.
    fn transformed(&self, xf: &DAffine3) -> Option<Round> {
        let to_local = self.to_local * xf.inverse();
        let stretch = max_stretch(to_local.matrix3);
        stretch.is_finite().then(|| Round { to_local, stretch, ..self.clone() })
    }

    /// Whether `p` is within `tol` of the set (in the local frame's units).
    fn contains(&self, p: DVec3, tol: f64) -> bool {
        let q = self.to_local.transform_point3(p);
        let r = q.x.hypot(q.z);
        self.cones.iter().all(|&(a, b, c)| a * r + b * q.y <= c + tol)
            && self.ball.is_none_or(|b| q.length() <= b + tol)
    }

    /// The interval of `t` where `origin + t·dir` is in the set grown by `g` (in the
    /// hull's frame): an interval, as the set is convex; possibly empty (`lo > hi`) or
    /// unbounded.
    pub fn interval(&self, origin: DVec3, dir: DVec3, g: f64) -> (f64, f64) {
        self.interval_local(self.local(origin, dir), g)
    }

    /// The ray `origin + t·dir` in the set's frame, for [`interval_local`](Self::interval_local).
    pub fn local(&self, origin: DVec3, dir: DVec3) -> (DVec3, DVec3) {
        (self.to_local.transform_point3(origin), self.to_local.transform_vector3(dir))
    }

    /// [`interval`](Self::interval) of a ray already in the set's frame ([`local`](Self::local)).
    pub fn interval_local(&self, (o, d): (DVec3, DVec3), g: f64) -> (f64, f64) {
        let g = g * self.stretch;
        let mut span = (f64::NEG_INFINITY, f64::INFINITY);
        for &(a, b, c) in &self.cones {
            span = meet(span, cone_interval((a, b, c + g), o, d));
            if span.0 > span.1 {
                return span;
            }
        }
        if let Some(ball) = self.ball {
            let r = ball + g;
            span = meet(span, below(d.length_squared(), o.dot(d), o.length_squared() - r * r).0);
        }
        span
    }
}

/// Where `a·r(t) + b·y(t) ≤ c` along the local ray `o + t·d`: with `L(t) = c − b·y(t)`,
/// where `L ≥ 0` and `a²·r² ≤ L²`. Squaring adds the mirror cone's side (where `L < 0`),
/// which the half-line `L ≥ 0` cuts away; the hull of what is left is the answer (the
/// set is convex, so it is one interval).
fn cone_interval((a, b, c): (f64, f64, f64), o: DVec3, d: DVec3) -> (f64, f64) {
    let (l0, l1) = (c - b * o.y, -b * d.y);
    let ahead = linear_below(-l1, -l0);
    if a == 0.0 {
        return ahead;
    }
    let a2 = a * a;
    let qa = a2 * (d.x * d.x + d.z * d.z) - l1 * l1;
    let qb = a2 * (o.x * d.x + o.z * d.z) - l0 * l1;
    let qc = a2 * (o.x * o.x + o.z * o.z) - l0 * l0;
    let (first, second) = below(qa, qb, qc);
    let pieces = [meet(first, ahead), second.map_or((1.0, 0.0), |s| meet(s, ahead))];
    let kept = pieces.into_iter().filter(|p| p.0 <= p.1);
    kept.fold((f64::INFINITY, f64::NEG_INFINITY), |acc, p| (acc.0.min(p.0), acc.1.max(p.1)))
}

/// Where `k1·t + k0 ≤ 0`.
fn linear_below(k1: f64, k0: f64) -> (f64, f64) {
    if k1 > 0.0 {
        (f64::NEG_INFINITY, -k0 / k1)
    } else if k1 < 0.0 {
        (-k0 / k1, f64::INFINITY)
    } else if k0 <= 0.0 {
        (f64::NEG_INFINITY, f64::INFINITY)
    } else {
        (1.0, 0.0)
    }
}

/// Where `qa·t² + 2·qb·t + qc ≤ 0`: one interval (possibly empty or unbounded), or two
/// half-lines when the parabola opens downwards.
fn below(qa: f64, qb: f64, qc: f64) -> ((f64, f64), Option<(f64, f64)>) {
    if qa == 0.0 {
        return (linear_below(2.0 * qb, qc), None);
    }
    let disc = qb * qb - qa * qc;
    if disc < 0.0 {
        let all = (f64::NEG_INFINITY, f64::INFINITY);
        return (if qa > 0.0 { (1.0, 0.0) } else { all }, None);
    }
    // The two roots without cancellation: q/qa and qc/q.
    let q = -(qb + disc.sqrt().copysign(qb));
    let (r0, r1) = if q == 0.0 { (0.0, 0.0) } else { (q / qa, qc / q) };
    let (lo, hi) = (r0.min(r1), r0.max(r1));
    if qa > 0.0 {
        ((lo, hi), None)
    } else {
        ((f64::NEG_INFINITY, lo), Some((hi, f64::INFINITY)))
    }
}

/// The intersection of two intervals.
fn meet(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0.max(b.0), a.1.min(b.1))
}

/// The most planes [`Hull::corners`] searches: 64 planes are 41,664 triples.
pub const MAX_CORNER_PLANES: usize = 64;

/// The directions about `z` of a bent solid's planes ([`Hull::bent`]).
pub const BEND_PLANES: usize = 16;

/// The angle, in radians, over which [`Hull::bent`] bounds a bent solid's turned
/// corners by one piece: the pieces' triangles stand out of the arcs by at most
/// `r·(1/cos(θ/2) − 1)`, under 1.3e-5 of the radius.
pub const BEND_STRETCH: f64 = 0.01;

impl Hull {
    /// The six planes of the box `b`.
    pub fn box_planes(b: DAabb) -> Vec<(DVec3, f64)> {
        [DVec3::X, DVec3::Y, DVec3::Z]
            .into_iter()
            .zip(0..3)
            .flat_map(|(n, a)| [(n, b.max[a]), (-n, -b.min[a])])
            .collect()
    }

    /// The hull of planes alone.
    pub fn planes(planes: Vec<(DVec3, f64)>) -> Hull {
        Hull { planes, round: None }
    }

    /// The cones `a·r + b·y ≤ c` about the `y` axis ([`Round::about_y`]).
    pub fn about_y(cones: impl IntoIterator<Item = (f64, f64, f64)>) -> Option<Hull> {
        Some(Hull { planes: Vec::new(), round: Some(Round::about_y(cones)?) })
    }

    /// The ellipsoid of semi-axes `radii` ([`Round::ellipsoid`]).
    pub fn ellipsoid(radii: DVec3) -> Option<Hull> {
        Some(Hull { planes: Vec::new(), round: Some(Round::ellipsoid(radii)?) })
    }

    /// A convex set holding a solid whose corners are `corners` (a convex polyhedron
    /// holding it) bent by `k` radians per unit: the point `p` reads the solid at `p`'s
    /// `(x, y)` turned by `k·p.y` about `z` (`sdf::domain::Map::Bend`), so the bent
    /// solid's point is a solid's point `q` turned back by `θ = k·p.y`, at the height
    /// `p.y = θ / k` that angle fixes. Split the angles `|θ| ≤ |k|·r` that can occur (`r`
    /// the corners' largest distance from `z`) into stretches of [`BEND_STRETCH`]: over
    /// one, the turned corners stay within the triangles their arcs span (the ends and
    /// the tangents' meeting point), and the point within that stretch's slab of
    /// heights. The corners of those pieces give [`BEND_PLANES`] planes about `z` (a
    /// polygon circumscribing their convex hull) and the corners' range of `z`. Where
    /// the angles reach further than half a turn each way, the cylinder about `z` round
    /// the corners holds as much, between the same depths. `None` for no corners.
    pub fn bent(corners: &[DVec3], k: f64) -> Option<Hull> {
        use glam::DVec2;
        let r = corners.iter().map(|c| c.truncate().length()).fold(0.0, f64::max);
        let (low, high) = corners.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), c| (l.min(c.z), h.max(c.z)));
        let flat = super::polygon::convex_hull(corners.iter().map(|c| c.truncate()).collect());
        let reach = k.abs() * r;
        if flat.len() < 3 || !reach.is_finite() || reach > std::f64::consts::PI {
            // The cylinder is about the y axis of a frame whose y is the scene's z.
            let cones = [(1.0, 0.0, r), (0.0, 1.0, high), (0.0, -1.0, -low)];
            return Hull::about_y(cones)?.transformed(&DAffine3::from_rotation_x(std::f64::consts::FRAC_PI_2));
        }
        let turned = |v: DVec2, a: f64| DVec2::from_angle(-a).rotate(v);
        let pieces = ((2.0 * reach / BEND_STRETCH).ceil() as usize).clamp(1, 1024);
        let half = reach / pieces as f64;
        let mut points = Vec::new();
        for i in 0..pieces {
            let (a, b) = (-reach + 2.0 * half * i as f64, -reach + 2.0 * half * (i + 1) as f64);
            let mid = 0.5 * (a + b);
            let span: Vec<DVec2> =
                flat.iter().flat_map(|&v| [turned(v, a), turned(v, b), turned(v, mid) / half.cos()]).collect();
            let mut piece = super::polygon::convex_hull(span);
            if k != 0.0 {
                let (y0, y1) = ((a / k).min(b / k), (a / k).max(b / k));
                piece = super::polygon::clip_convex(&piece, DVec2::Y, y1);
                piece = super::polygon::clip_convex(&piece, -DVec2::Y, -y0);
            }
            points.extend(piece);
        }
        let mut planes: Vec<(DVec3, f64)> = (0..BEND_PLANES)
            .map(|j| {
                let u = DVec2::from_angle(std::f64::consts::TAU * j as f64 / BEND_PLANES as f64);
                let offset = points.iter().map(|p| u.dot(*p)).fold(f64::NEG_INFINITY, f64::max);
                (u.extend(0.0), offset)
            })
            .collect();
        planes.extend([(DVec3::Z, high), (-DVec3::Z, -low)]);
        planes.iter().all(|(_, o)| o.is_finite()).then_some(Hull::planes(planes))
    }

    /// Holding every point within `g` of this set.
    pub fn grown(self, g: f64) -> Hull {
        Hull {
            planes: self.planes.into_iter().map(|(n, o)| (n, o + g)).collect(),
            round: self.round.map(|r| r.grown(g)),
        }
    }

    /// The image of the set under an invertible affine map; `None` if it is too
    /// degenerate to say.
    pub fn transformed(&self, xf: &DAffine3) -> Option<Hull> {
        let planes: Option<Vec<_>> = self.planes.iter().map(|&h| transform_half_space(h, xf)).collect();
        let round = match &self.round {
            Some(r) => Some(r.transformed(xf)?),
            None => None,
        };
        Some(Hull { planes: planes?, round })
    }

    /// Both sets' intersection: every plane, and the first round part (two frames'
    /// constraints do not combine).
    pub fn meet(mut self, other: Hull) -> Hull {
        self.planes.extend(other.planes);
        self.round = self.round.or(other.round);
        self
    }

    /// Whether `p` is within `tol` of every plane and of the round part (in its frame).
    pub fn contains(&self, p: DVec3, tol: f64) -> bool {
        self.planes.iter().all(|(n, o)| n.dot(p) <= o + tol) && self.round.as_ref().is_none_or(|r| r.contains(p, tol))
    }

    /// The corners of the planes' polyhedron (where three planes meet within every
    /// other), when the planes alone bound it; empty otherwise, and for more than
    /// [`MAX_CORNER_PLANES`] planes (the search tries every triple against every plane).
    pub fn corners(&self) -> Vec<DVec3> {
        let p = &self.planes;
        let mut out = Vec::new();
        if p.len() > MAX_CORNER_PLANES {
            return out;
        }
        for i in 0..p.len() {
            for j in i + 1..p.len() {
                for k in j + 1..p.len() {
                    let (a, b, c) = (p[i].0, p[j].0, p[k].0);
                    let det = a.dot(b.cross(c));
                    if det.abs() < 1e-9 {
                        continue;
                    }
                    let x = (b.cross(c) * p[i].1 + c.cross(a) * p[j].1 + a.cross(b) * p[k].1) / det;
                    let scale = 1e-9 * (1.0 + x.abs().max_element());
                    if p.iter().all(|(n, o)| n.dot(x) <= o + scale) {
                        out.push(x);
                    }
                }
            }
        }
        out
    }
}

/// The image of the half-space `n·p ≤ offset` under an invertible affine map, which is
/// exactly a half-space: its normal is `M⁻ᵀ n`, through the image of a point on the
/// plane. `None` if the map is too degenerate to say.
pub fn transform_half_space((n, offset): (DVec3, f64), xf: &DAffine3) -> Option<(DVec3, f64)> {
    let normal = (xf.matrix3.inverse().transpose() * n).try_normalize()?;
    let on_plane = xf.transform_point3(n * offset);
    let offset = normal.dot(on_plane);
    (normal.is_finite() && offset.is_finite()).then_some((normal, offset))
}

/// An upper bound of the largest singular value (how far the map can stretch a
/// vector): the largest column-norm sum bound, exact for rotations and scales.
pub fn max_stretch(m: DMat3) -> f64 {
    let mtm = m.transpose() * m;
    // The largest eigenvalue of the symmetric mᵀm is at most its largest absolute row sum.
    let rows = [mtm.row(0), mtm.row(1), mtm.row(2)];
    let bound = rows.iter().map(|r| r.abs().element_sum()).fold(0.0, f64::max);
    bound.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bent box lies within its planes (every point whose turned reading falls in the
    /// box, over a grid), for bends either way, near half a turn and none; for a bend
    /// of 50° or 120° a unit they hold under half of what the drum about `z` holds.
    #[test]
    fn bent_planes_hold_the_bent_box() {
        let half = DVec3::new(0.2, 0.9, 0.3);
        let corners: Vec<DVec3> = (0..8)
            .map(|i| half * DVec3::new([-1.0, 1.0][i & 1], [-1.0, 1.0][(i >> 1) & 1], [-1.0, 1.0][i >> 2]))
            .collect();
        let r = corners.iter().map(|c| c.truncate().length()).fold(0.0, f64::max);
        for deg in [50.0_f64, -120.0, 190.0, 0.0] {
            let k = deg.to_radians();
            let hull = Hull::bent(&corners, k).unwrap();
            let (mut inside, mut in_planes, mut in_drum) = (0, 0, 0);
            let n = 120;
            for i in 0..n * n {
                let p = DVec3::new((i % n) as f64, (i / n) as f64, 0.5 * n as f64) / n as f64 * 2.2 - 1.1;
                let (s, c) = (k * p.y).sin_cos();
                let q = DVec3::new(p.x * c - p.y * s, p.x * s + p.y * c, p.z);
                if q.abs().cmple(half).all() {
                    inside += 1;
                    assert!(hull.contains(p, 1e-9), "{deg}°: {p} reads {q} in the box, outside the planes");
                }
                in_planes += usize::from(hull.contains(p, 0.0));
                in_drum += usize::from(p.truncate().length() <= r);
            }
            assert!(inside > 500, "{deg}°: only {inside} points in the bent box");
            if (50.0..=120.0).contains(&deg.abs()) {
                assert!(2 * in_planes < in_drum, "{deg}°: {in_planes} points in the planes, {in_drum} in the drum");
            }
        }
        // Bent further than half a turn each way: the drum about z, which holds every
        // point of the corners' radius and depth.
        let drum = Hull::bent(&corners, 250f64.to_radians()).unwrap();
        assert!(drum.round.is_some() && drum.contains(DVec3::new(-0.9, 0.0, 0.2), 1e-9));
    }

    /// Points along random rays are inside the interval exactly where they are in the
    /// set: a cylinder, a cone's frustum and an ellipsoid, turned and stretched.
    #[test]
    fn intervals_are_where_the_ray_is_inside() {
        let frustum = Round::about_y([(1.0, 0.0, 0.5), (0.0, 1.0, 0.4), (0.0, -1.0, 0.4), (0.8, 0.3, 0.5)]).unwrap();
        let ellipsoid = Round::ellipsoid(DVec3::new(0.3, 0.7, 0.5)).unwrap();
        let xf = DAffine3::from_scale_rotation_translation(
            DVec3::new(1.3, 0.6, 1.0),
            glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.4, 1.1, -0.3),
            DVec3::new(0.1, -0.2, 0.3),
        );
        let mut seed = 0x5eed_u64;
        let mut next = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut inside = 0;
        for round in
            [frustum.clone(), ellipsoid.clone(), frustum.transformed(&xf).unwrap(), ellipsoid.transformed(&xf).unwrap()]
        {
            for _ in 0..2_000 {
                let o = DVec3::new(next(), next(), next()) * 2.0;
                let d = DVec3::new(next(), next(), next());
                let (lo, hi) = round.interval(o, d, 0.0);
                for s in 0..=40 {
                    let t = f64::from(s) / 10.0 - 2.0;
                    let p = o + t * d;
                    let slack = 1e-9 * (1.0 + t.abs());
                    let within = t >= lo - slack && t <= hi + slack;
                    let on_edge = (t - lo).abs() < 1e-6 || (t - hi).abs() < 1e-6;
                    assert!(on_edge || within == round.contains(p, 0.0), "{round:?}: t {t} in ({lo}, {hi})");
                    inside += usize::from(within);
                }
            }
        }
        assert!(inside > 1_500, "only {inside} points inside");
    }

    /// A grown set holds every point within `g` of the set.
    #[test]
    fn grown_sets_hold_their_neighbourhood() {
        let ellipsoid = Round::ellipsoid(DVec3::new(0.3, 0.7, 0.5)).unwrap();
        let grown = ellipsoid.clone().grown(0.1);
        for i in 0..2_000 {
            let (s, c) = (f64::from(i) * 0.37).sin_cos();
            let (s2, c2) = (f64::from(i) * 0.11).sin_cos();
            let n = DVec3::new(c * c2, s2, s * c2);
            // The surface point whose normal is n: radii² n / |radii n|.
            let r = DVec3::new(0.3, 0.7, 0.5);
            let p = r * r * n / (r * n).length();
            assert!(ellipsoid.contains(p, 1e-9));
            assert!(grown.contains(p + 0.1 * n.normalize(), 1e-9), "{p}");
        }
    }

    /// A box's planes meet at its eight corners.
    #[test]
    fn corners_of_a_box() {
        let planes = [DVec3::X, DVec3::Y, DVec3::Z].iter().flat_map(|&n| [(n, 1.0), (-n, 2.0)]).collect();
        let corners = Hull::planes(planes).corners();
        assert_eq!(corners.len(), 8);
        assert!(corners.iter().all(|c| c.to_array().iter().all(|&v| v == 1.0 || v == -2.0)));
    }
}
