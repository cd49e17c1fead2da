//! Closed outlines of straight and quadratic Bézier segments, as a font's glyphs are
//! drawn, with their exact signed distance: the nearest point of a quadratic from the
//! roots of a cubic in closed form (polished by Newton's method to the last bit), the
//! sign from the non-zero winding rule, so that a glyph's holes (the inside of `o`)
//! and its overlapping contours read as a type designer drew them.
//!
//! Segments are kept split where their `y` turns, so each is monotone in `y` and the
//! winding number counts one crossing per segment at most; glyphs keep their own boxes,
//! so a query reads the segments near it and the winding of the glyphs it is inside.

use std::f64::consts::TAU;

use glam::DVec2;

/// One segment of a contour: a line, or a quadratic Bézier through its control point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Seg {
    /// From the first point to the second.
    Line(DVec2, DVec2),
    /// From the first point to the third, pulled towards the second.
    Quad(DVec2, DVec2, DVec2),
}

impl Seg {
    /// The segment with each point moved by `f` (an affine map: a Bézier's image is the
    /// Bézier of its control points' images).
    fn moved(&self, f: &impl Fn(DVec2) -> DVec2) -> Seg {
        match *self {
            Seg::Line(a, b) => Seg::Line(f(a), f(b)),
            Seg::Quad(a, b, c) => Seg::Quad(f(a), f(b), f(c)),
        }
    }
}

/// A closed contour: each segment starts where the last ended.
pub type Contour = Vec<Seg>;

/// A `y`-monotone piece of a segment, with its control points' box.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Piece {
    /// Start, control point (the middle of a line) and end.
    p: [DVec2; 3],
    /// Whether it is straight.
    line: bool,
    min: DVec2,
    max: DVec2,
}

/// Pieces of one glyph (or any group of whole contours) and their box.
#[derive(Clone, Debug, PartialEq)]
struct Group {
    start: usize,
    end: usize,
    min: DVec2,
    max: DVec2,
}

/// Closed contours filled by the non-zero rule.
#[derive(Clone, Debug, PartialEq)]
pub struct Outline {
    /// The contours as given, by group.
    contours: Vec<(u32, Contour)>,
    pieces: Vec<Piece>,
    groups: Vec<Group>,
    /// The box of every control point.
    pub min: DVec2,
    /// See `min`.
    pub max: DVec2,
    /// What the outline shows as in the IR (the text it spells).
    pub label: String,
}

/// The signed distance at a point and its gradient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// Negative inside.
    pub d: f64,
    /// The gradient (a unit vector away from the nearest point, or across the segment
    /// there when the point is on it).
    pub g: DVec2,
}

/// The squared distance from `p` to the box `[min, max]` (0 inside).
fn box_dist2(p: DVec2, min: DVec2, max: DVec2) -> f64 {
    let d = (min - p).max(p - max).max(DVec2::ZERO);
    d.length_squared()
}

impl Outline {
    /// The outline of `contours`, each tagged with its group (a glyph), labelled `label`.
    /// Contours of fewer than one segment are dropped; `None` when none is left.
    pub fn new(contours: Vec<(u32, Contour)>, label: String) -> Option<Outline> {
        let contours: Vec<(u32, Contour)> = contours.into_iter().filter(|(_, c)| !c.is_empty()).collect();
        let mut pieces = Vec::new();
        let mut groups: Vec<Group> = Vec::new();
        let mut last_group = None;
        for (g, contour) in &contours {
            if last_group != Some(*g) {
                groups.push(Group { start: pieces.len(), end: pieces.len(), min: DVec2::MAX, max: DVec2::MIN });
                last_group = Some(*g);
            }
            for seg in contour {
                split_monotone(seg, &mut pieces);
            }
            let group = groups.last_mut().expect("pushed above");
            group.end = pieces.len();
            for piece in &pieces[group.start..] {
                group.min = group.min.min(piece.min);
                group.max = group.max.max(piece.max);
            }
        }
        if pieces.is_empty() {
            return None;
        }
        let min = groups.iter().fold(DVec2::MAX, |m, g| m.min(g.min));
        let max = groups.iter().fold(DVec2::MIN, |m, g| m.max(g.max));
        Some(Outline { contours, pieces, groups, min, max, label })
    }

    /// The outline moved by `f`, an affine map of the plane.
    pub fn moved(&self, f: &impl Fn(DVec2) -> DVec2) -> Outline {
        let contours = self.contours.iter().map(|(g, c)| (*g, c.iter().map(|s| s.moved(f)).collect())).collect();
        Outline::new(contours, self.label.clone()).expect("moving keeps every segment")
    }

    /// Bytes it holds (its contours, pieces and groups), for the memory counters.
    pub fn bytes(&self) -> usize {
        let segs: usize = self.contours.iter().map(|(_, c)| c.len()).sum();
        std::mem::size_of::<Outline>()
            + segs * std::mem::size_of::<Seg>()
            + self.pieces.len() * std::mem::size_of::<Piece>()
            + self.groups.len() * std::mem::size_of::<Group>()
    }

    /// The outline moved by `d`: a translation keeps every split, so nothing is rebuilt.
    pub fn translate(&mut self, d: DVec2) {
        for (_, contour) in &mut self.contours {
            for seg in contour.iter_mut() {
                *seg = seg.moved(&|p| p + d);
            }
        }
        for piece in &mut self.pieces {
            piece.p = piece.p.map(|p| p + d);
            (piece.min, piece.max) = (piece.min + d, piece.max + d);
        }
        for group in &mut self.groups {
            (group.min, group.max) = (group.min + d, group.max + d);
        }
        (self.min, self.max) = (self.min + d, self.max + d);
    }

    /// How many segments it has once split where `y` turns.
    pub fn pieces(&self) -> usize {
        self.pieces.len()
    }

    /// The contours, each with its group.
    pub fn contours(&self) -> &[(u32, Contour)] {
        &self.contours
    }

    /// The signed distance at `p` (negative inside by the non-zero rule) and its gradient.
    pub fn nearest(&self, p: DVec2) -> Nearest {
        let mut best = f64::INFINITY;
        let mut at = DVec2::ZERO;
        let mut across = DVec2::Y;
        let mut winding = 0i32;
        // The nearest box first, so that most other groups are ruled out by their boxes.
        let first = (0..self.groups.len())
            .min_by(|&a, &b| {
                let (ga, gb) = (&self.groups[a], &self.groups[b]);
                box_dist2(p, ga.min, ga.max).total_cmp(&box_dist2(p, gb.min, gb.max))
            })
            .unwrap_or(0);
        let order = std::iter::once(first).chain((0..self.groups.len()).filter(|&i| i != first));
        for gi in order {
            let g = &self.groups[gi];
            let to_box = box_dist2(p, g.min, g.max);
            let inside_box = to_box == 0.0;
            if !inside_box && to_box >= best {
                continue;
            }
            for piece in &self.pieces[g.start..g.end] {
                if inside_box {
                    winding += piece.crossing(p);
                }
                if box_dist2(p, piece.min, piece.max) < best {
                    let (d2, q, tangent) = piece.nearest(p);
                    if d2 < best {
                        best = d2;
                        at = q;
                        across = DVec2::new(tangent.y, -tangent.x);
                    }
                }
            }
        }
        let sign = if winding != 0 { -1.0 } else { 1.0 };
        let d = best.sqrt();
        let away = p - at;
        let g = if d > 0.0 { away / d } else { across.try_normalize().unwrap_or(DVec2::Y) };
        Nearest { d: sign * d, g: sign * g }
    }

    /// The contours flattened into polygons: a segment turning through angle θ gets the
    /// share `θ / 2π` of `segments` sides (at least one), as an arc of a circle of that
    /// many sides would.
    pub fn polygons(&self, segments: u32) -> Vec<Vec<[f64; 2]>> {
        self.contours
            .iter()
            .map(|(_, contour)| {
                let mut ring = Vec::new();
                for seg in contour {
                    match *seg {
                        Seg::Line(a, _) => ring.push(a.to_array()),
                        Seg::Quad(a, b, c) => {
                            let k = quad_sides(a, b, c, segments);
                            for i in 0..k {
                                let t = f64::from(i) / f64::from(k);
                                ring.push(quad_at(a, b, c, t).to_array());
                            }
                        }
                    }
                }
                ring
            })
            .filter(|ring| ring.len() >= 3)
            .collect()
    }

    /// The radius of the circle whose inscribed polygon at some number of sides strays
    /// from it as far as [`polygons`](Self::polygons) strays from the curves, at most over
    /// the segments: `2|a − 2b + c| / θ²` for a quadratic turning through θ; 0 when all
    /// are straight.
    pub fn equivalent_radius(&self) -> f64 {
        let mut r = 0.0f64;
        for (_, contour) in &self.contours {
            for seg in contour {
                if let Seg::Quad(a, b, c) = *seg {
                    let bend = (a - 2.0 * b + c).length();
                    let theta = turn(a, b, c);
                    if bend > 0.0 && theta > 0.0 {
                        r = r.max(2.0 * bend / (theta * theta));
                    }
                }
            }
        }
        r
    }
}

/// The angle through which a quadratic's tangent turns, radians.
fn turn(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let (u, v) = (b - a, c - b);
    if u == DVec2::ZERO || v == DVec2::ZERO {
        return 0.0;
    }
    u.perp_dot(v).atan2(u.dot(v)).abs()
}

/// The straight pieces a quadratic is flattened into for `segments` sides a circle: its
/// turn's share of them. The chord of a piece spanning `1/k` of the parameter strays at
/// most `|a − 2b + c| / 4k²` from the curve, which [`Outline::equivalent_radius`] keeps
/// within a circle's sagitta at the same number of sides.
fn quad_sides(a: DVec2, b: DVec2, c: DVec2, segments: u32) -> u32 {
    let k = (f64::from(segments) * turn(a, b, c) / TAU).ceil();
    if k.is_finite() {
        (k as u32).clamp(1, segments.max(1))
    } else {
        1
    }
}

/// The quadratic Bézier at `t`.
fn quad_at(a: DVec2, b: DVec2, c: DVec2, t: f64) -> DVec2 {
    let s = 1.0 - t;
    a * (s * s) + b * (2.0 * s * t) + c * (t * t)
}

/// Splits `seg` where its `y` turns, pushing `y`-monotone pieces.
fn split_monotone(seg: &Seg, out: &mut Vec<Piece>) {
    let piece =
        |p: [DVec2; 3], line: bool| Piece { p, line, min: p[0].min(p[1]).min(p[2]), max: p[0].max(p[1]).max(p[2]) };
    match *seg {
        Seg::Line(a, b) => out.push(piece([a, (a + b) * 0.5, b], true)),
        Seg::Quad(a, b, c) => {
            let denom = a.y - 2.0 * b.y + c.y;
            let turns = (b.y - a.y) * (c.y - b.y) < 0.0 && denom != 0.0;
            let t = if turns { (a.y - b.y) / denom } else { -1.0 };
            if t > 0.0 && t < 1.0 {
                let (mut ab, mut bc) = (a.lerp(b, t), b.lerp(c, t));
                let m = ab.lerp(bc, t);
                // The tangent is level at the turn: both new control points lie on it.
                ab.y = m.y;
                bc.y = m.y;
                out.push(piece([a, ab, m], false));
                out.push(piece([m, bc, c], false));
            } else {
                out.push(piece([a, b, c], false));
            }
        }
    }
}

impl Piece {
    /// The winding this piece adds at `p`: ±1 if it crosses the ray from `p` towards
    /// `+x` (upward +1), each end counted on one side only, so that a contour's shared
    /// ends count once.
    fn crossing(&self, p: DVec2) -> i32 {
        let (a, e) = (self.p[0], self.p[2]);
        let dir = if a.y <= p.y && p.y < e.y {
            1
        } else if e.y <= p.y && p.y < a.y {
            -1
        } else {
            return 0;
        };
        let x = if self.line {
            a.x + (p.y - a.y) * (e.x - a.x) / (e.y - a.y)
        } else {
            let t = monotone_root(a.y, self.p[1].y, e.y, p.y);
            quad_at(a, self.p[1], e, t).x
        };
        if x > p.x {
            dir
        } else {
            0
        }
    }

    /// The squared distance from `p` to its nearest point, that point, and the
    /// segment's direction there.
    fn nearest(&self, p: DVec2) -> (f64, DVec2, DVec2) {
        let [a, b, c] = self.p;
        if self.line {
            let d = c - a;
            let len2 = d.length_squared();
            let t = if len2 > 0.0 { ((p - a).dot(d) / len2).clamp(0.0, 1.0) } else { 0.0 };
            let q = a + d * t;
            return ((p - q).length_squared(), q, d);
        }
        // B(t) − p = a0 + a1 t + a2 t², B'(t) = a1 + 2 a2 t; the nearest point is an end
        // or a root of (B(t) − p)·B'(t), a cubic.
        let (a0, a1, a2) = (a - p, 2.0 * (b - a), a - 2.0 * b + c);
        let cubic = [a0.dot(a1), a1.dot(a1) + 2.0 * a0.dot(a2), 3.0 * a1.dot(a2), 2.0 * a2.dot(a2)];
        let mut best = (f64::INFINITY, a, a1);
        let mut consider = |t: f64| {
            let q = quad_at(a, b, c, t);
            let d2 = (p - q).length_squared();
            if d2 < best.0 {
                best = (d2, q, a1 + 2.0 * a2 * t);
            }
        };
        consider(0.0);
        consider(1.0);
        for t in cubic_roots(cubic) {
            if (0.0..=1.0).contains(&t) || (-0.5..=1.5).contains(&t) {
                consider(polish(cubic, t.clamp(0.0, 1.0)));
            }
        }
        best
    }
}

/// Two Newton steps on the cubic `c0 + c1 t + c2 t² + c3 t³` from `t`, kept in `[0, 1]`:
/// the closed form's roots lose bits to cancellation when the curve is nearly straight.
fn polish(c: [f64; 4], mut t: f64) -> f64 {
    for _ in 0..2 {
        let f = c[0] + t * (c[1] + t * (c[2] + t * c[3]));
        let df = c[1] + t * (2.0 * c[2] + t * 3.0 * c[3]);
        if df == 0.0 || !df.is_finite() {
            break;
        }
        let next = (t - f / df).clamp(0.0, 1.0);
        if !next.is_finite() {
            break;
        }
        t = next;
    }
    t
}

/// The real roots of `c0 + c1 t + c2 t² + c3 t³` (Cardano's formula, or the
/// trigonometric one when there are three; a lower degree when the leading
/// coefficients vanish against the others).
fn cubic_roots(c: [f64; 4]) -> Vec<f64> {
    let scale = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 {
        return Vec::new();
    }
    let tiny = scale * 1e-12;
    if c[3].abs() <= tiny {
        if c[2].abs() <= tiny {
            return if c[1].abs() > tiny { vec![-c[0] / c[1]] } else { Vec::new() };
        }
        let disc = c[1] * c[1] - 4.0 * c[2] * c[0];
        if disc < 0.0 {
            return vec![-c[1] / (2.0 * c[2])];
        }
        let q = -0.5 * (c[1] + c[1].signum() * disc.sqrt());
        let mut out = vec![q / c[2]];
        if q != 0.0 {
            out.push(c[0] / q);
        }
        return out;
    }
    let (a, b, k) = (c[2] / c[3], c[1] / c[3], c[0] / c[3]);
    let p = b - a * a / 3.0;
    let q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + k;
    let shift = -a / 3.0;
    let disc = q * q / 4.0 + p * p * p / 27.0;
    if disc > 0.0 {
        let s = disc.sqrt();
        vec![(-q / 2.0 + s).cbrt() + (-q / 2.0 - s).cbrt() + shift]
    } else if p == 0.0 {
        vec![shift]
    } else {
        let r = (-p / 3.0).sqrt();
        let phi = (-q / (2.0 * r * r * r)).clamp(-1.0, 1.0).acos();
        (0..3).map(|i| 2.0 * r * ((phi - TAU * f64::from(i)) / 3.0).cos() + shift).collect()
    }
}

/// The `t` in `[0, 1]` where a `y`-monotone quadratic with `y` values `y0, y1, y2` at its
/// control points reaches `y`.
fn monotone_root(y0: f64, y1: f64, y2: f64, y: f64) -> f64 {
    let (qa, qb, qc) = (y0 - 2.0 * y1 + y2, 2.0 * (y1 - y0), y0 - y);
    let t = if qa.abs() <= 1e-12 * (qb.abs() + qc.abs()) {
        if qb == 0.0 {
            0.0
        } else {
            -qc / qb
        }
    } else {
        let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
        let q = -0.5 * (qb + if qb < 0.0 { -disc } else { disc });
        let (r1, r2) = (q / qa, if q != 0.0 { qc / q } else { f64::INFINITY });
        // The root in [0, 1]; rounding may put it a hair outside.
        let off = |t: f64| {
            if t < 0.0 {
                -t
            } else if t > 1.0 {
                t - 1.0
            } else {
                0.0
            }
        };
        if off(r1) <= off(r2) {
            r1
        } else {
            r2
        }
    };
    t.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of side 2 with a square hole of side 1, the hole wound the other way,
    /// and a round blob of four quadratics beside it.
    fn sample() -> Outline {
        let sq = |h: f64, ccw: bool| -> Contour {
            let mut pts = [DVec2::new(-h, -h), DVec2::new(h, -h), DVec2::new(h, h), DVec2::new(-h, h)];
            if !ccw {
                pts.reverse();
            }
            (0..4).map(|i| Seg::Line(pts[i], pts[(i + 1) % 4])).collect()
        };
        let c = DVec2::new(4.0, 0.0);
        let blob: Contour = (0..4)
            .map(|i| {
                let at = |k: i32| {
                    let a = std::f64::consts::FRAC_PI_2 * f64::from(k);
                    c + DVec2::new(a.cos(), a.sin())
                };
                let corner = c + (at(i) - c + at(i + 1) - c);
                Seg::Quad(at(i), corner, at(i + 1))
            })
            .collect();
        Outline::new(vec![(0, sq(1.0, true)), (0, sq(0.5, false)), (1, blob)], "test".into()).unwrap()
    }

    /// The distance against a brute-force one: every segment sampled at 200,001 points
    /// (so within 1e-5 of the true nearest), the sign by whether the point is in the
    /// square less its hole or in the blob.
    #[test]
    fn distance_matches_dense_sampling_and_the_fill() {
        let o = sample();
        let mut samples = Vec::new();
        for (_, contour) in o.contours() {
            for seg in contour {
                for i in 0..=200_000 {
                    let t = f64::from(i) / 200_000.0;
                    samples.push(match *seg {
                        Seg::Line(a, b) => a.lerp(b, t),
                        Seg::Quad(a, b, c) => quad_at(a, b, c, t),
                    });
                }
            }
        }
        let mut state = 12345u64;
        let mut rand = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            let p = DVec2::new(rand() * 8.0 - 2.5, rand() * 4.0 - 2.0);
            let brute = samples.iter().map(|s| (p - *s).length()).fold(f64::INFINITY, f64::min);
            let n = o.nearest(p);
            assert!((n.d.abs() - brute).abs() < 1e-4, "at {p}: {} against {brute}", n.d);
            assert!(n.d.abs() <= brute + 1e-12, "never farther than a point of the curve, at {p}");
            let in_square = p.x.abs() < 1.0 && p.y.abs() < 1.0 && !(p.x.abs() < 0.5 && p.y.abs() < 0.5);
            // Each quarter of the blob is x = 1 − t², y = 1 − (1 − t)² about its centre
            // (mirrored into the other quarters): inside where y is below the curve's.
            let rel = (p - DVec2::new(4.0, 0.0)).abs();
            let in_blob = rel.x <= 1.0 && rel.y < 1.0 - (1.0 - (1.0 - rel.x).sqrt()).powi(2);
            if brute > 1e-3 {
                assert_eq!(n.d < 0.0, in_square || in_blob, "sign at {p}");
            }
            // The gradient is a unit vector pointing away from the nearest point.
            assert!((n.g.length() - 1.0).abs() < 1e-9);
            let h = 1e-6;
            let fd = DVec2::new(
                o.nearest(p + DVec2::X * h).d - o.nearest(p - DVec2::X * h).d,
                o.nearest(p + DVec2::Y * h).d - o.nearest(p - DVec2::Y * h).d,
            ) / (2.0 * h);
            if brute > 1e-3 {
                assert!((fd - n.g).length() < 1e-3, "gradient at {p}: {} against {fd}", n.g);
            }
        }
    }

    /// A nearly straight quadratic (its control point a hair off the chord) keeps its
    /// distance exact, where the cubic's closed form alone loses its bits.
    #[test]
    fn nearly_straight_quadratics_stay_exact() {
        let (a, c) = (DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0));
        for off in [0.0, 1e-12, 1e-9, 1e-6, 1e-3] {
            let b = DVec2::new(0.5, off);
            let piece = Piece { p: [a, b, c], line: false, min: a.min(b).min(c), max: a.max(b).max(c) };
            for x in [-0.5, 0.0, 0.25, 0.5, 0.9, 1.0, 1.7] {
                let p = DVec2::new(x, 0.3);
                let (d2, _, _) = piece.nearest(p);
                let brute = (0..=100_000)
                    .map(|i| (p - quad_at(a, b, c, f64::from(i) / 100_000.0)).length())
                    .fold(f64::INFINITY, f64::min);
                assert!((d2.sqrt() - brute).abs() < 1e-9, "off {off} x {x}: {} against {brute}", d2.sqrt());
            }
        }
    }

    /// Flattened at more sides, the polygons approach the curves: the blob's area goes to
    /// the exact area of its four quadratics (each adds 2/3 of its control triangle).
    #[test]
    fn polygons_converge_on_the_curves() {
        let o = sample();
        let area = |ring: &Vec<[f64; 2]>| {
            0.5 * (0..ring.len())
                .map(|i| {
                    let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                    a[0] * b[1] - a[1] * b[0]
                })
                .sum::<f64>()
        };
        // A unit square's corners pulled out to (±1, ±1) about the centre: the diamond of
        // the four ends (area 2) plus 2/3 of each control triangle (area 1/2 each).
        let exact = 2.0 + 4.0 * (2.0 / 3.0) * 0.5;
        let mut last = f64::INFINITY;
        for n in [8, 32, 128, 512] {
            let rings = o.polygons(n);
            let err = (area(&rings[2]) - exact).abs();
            assert!(err < last, "{n} sides: {err}");
            last = err;
        }
        assert!(last < 1e-4, "{last}");
        assert!(o.equivalent_radius() > 0.0);
    }
}
