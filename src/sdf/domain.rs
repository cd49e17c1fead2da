//! Domain operations' maps evaluated natively: `twist`, `bend`, `elongate` and `symmetric` move
//! the point by a few operations each, which the field interpreter paid a dispatch for
//! one by one. Each is the map its `warp` body states (`builtins::domain`), and
//! the chain rule carries the shape's gradient back through it.

use glam::Vec3A;

use crate::ir::DomainOp;

/// A native map of the point.
#[derive(Clone, Copy, Debug)]
pub enum Map {
    /// Turned about `y` by `k` radians per unit of height, backwards.
    Twist(f32),
    /// Turned about `z` by `k` radians per unit of height.
    Bend(f32),
    /// The slab `[-h, h]` taken out.
    Elongate(Vec3A),
    /// Mirrored where the flag is 1: the absolute value of those components.
    Mirror(Vec3A),
}

impl Map {
    /// The native form of a domain operation's map, where there is one.
    pub fn new(op: DomainOp) -> Option<Map> {
        match op {
            DomainOp::Twist(k) => Some(Map::Twist(k.to_radians() as f32)),
            DomainOp::Bend(k) => Some(Map::Bend(k.to_radians() as f32)),
            DomainOp::Elongate(h) => Some(Map::Elongate(h.as_vec3a())),
            DomainOp::Mirror(axes) => Some(Map::Mirror(Vec3A::from(axes.map(|a| if a { 1.0 } else { 0.0 })))),
            DomainOp::Polar(_) => None,
        }
    }

    /// Where the shape is read for the point `p`.
    #[inline]
    pub fn apply(&self, p: Vec3A) -> Vec3A {
        match *self {
            Map::Twist(k) => {
                // rotate [0, a, 0] turned the slice; (x, z) is turned by a·y back.
                let (s, c) = (k * p.y).sin_cos();
                Vec3A::new(p.x * c - p.z * s, p.y, p.x * s + p.z * c)
            }
            Map::Bend(k) => {
                let (s, c) = (k * p.y).sin_cos();
                Vec3A::new(p.x * c - p.y * s, p.x * s + p.y * c, p.z)
            }
            Map::Elongate(h) => p - p.clamp(-h, h),
            Map::Mirror(m) => Vec3A::select(m.cmpgt(Vec3A::ZERO), p.abs(), p),
        }
    }

    /// A bound of the map's stretch (the largest singular value of its Jacobian) over the
    /// ball of radius `reach` around `p`, or `None` where the global estimate serves.
    /// A twist's Jacobian has `JᵀJ = I + A` with `A`'s eigenvalues `0` and
    /// `(a² ± a·√(a² + 4))/2`, `a = k·ρ` for the distance `ρ` from the axis, so its
    /// stretch is `(a + √(a² + 4))/2` (the golden ratio at `a = 1`): near the axis a twist
    /// barely stretches, and the march there need not step as if at its rim.
    #[inline]
    pub fn stretch(&self, p: Vec3A, reach: f32) -> Option<f32> {
        match *self {
            Map::Twist(k) => {
                // Not `hypot`, a libm call (3 % of a twisted prism's time under `perf`).
                let a = k.abs() * ((p.x * p.x + p.z * p.z).sqrt() + reach);
                Some(0.5 * (a + (a * a + 4.0).sqrt()))
            }
            // J = R(θ)·M in x, y, with M = [[1, −k·y], [0, 1 + k·x]]; M's largest singular
            // value grows with |k·y| and |1 + k·x|, so their largest over the ball bound it.
            Map::Bend(k) => {
                let b = k.abs() * (p.y.abs() + reach);
                let d = (1.0 + k * (p.x - reach)).abs().max((1.0 + k * (p.x + reach)).abs());
                let t = 1.0 + b * b + d * d;
                Some((0.5 * (t + (t * t - 4.0 * d * d).max(0.0).sqrt())).sqrt())
            }
            Map::Elongate(_) | Map::Mirror(_) => None,
        }
    }

    /// The warp's distance bound at `p` from its shape's value `v` at `apply(p)`: `v`
    /// over the map's stretch near `p`, or times `k` (the warp's `1/L`) where the
    /// global estimate serves.
    #[inline]
    pub fn bound(&self, p: Vec3A, v: f32, k: f32) -> f32 {
        v * self.stretch(p, v.abs()).map_or(k, |s| 1.0 / s)
    }

    /// Whether the map is smooth, so that [`curvature`](Self::curvature) bounds it.
    pub fn is_smooth(&self) -> bool {
        self.curvature(Vec3A::ZERO, Vec3A::ZERO, Vec3A::ZERO).is_some()
    }

    /// A bound of how sharply the map bends the line `a + d·t` between `a` and `b`: the
    /// largest `|q''(t)|` of `q(t) = apply(a + d·t)` there, or `None` for a map that is
    /// not smooth (a mirror, an elongation). A turn by `θ = k·y` of the two components it
    /// turns, `q = R(θ)·p`, has `q'' = θ'²·R''·p + 2θ'·R'·d` with `θ' = k·d_y`, so
    /// `|q''| ≤ θ'²·ρ + 2|θ'|·|d|` in the turned plane, `ρ` the point's distance from
    /// the axis, which is largest at an end of the segment (a distance from a line is
    /// convex along another).
    #[inline]
    pub fn curvature(&self, a: Vec3A, b: Vec3A, d: Vec3A) -> Option<f32> {
        // The two components the map turns, and the rate it turns them along the line.
        let (plane, k) = match *self {
            Map::Twist(k) => (Vec3A::new(1.0, 0.0, 1.0), k),
            Map::Bend(k) => (Vec3A::new(1.0, 1.0, 0.0), k),
            Map::Elongate(_) | Map::Mirror(_) => return None,
        };
        let turned = |v: Vec3A| (v * plane).length_squared();
        let rate = k * d.y;
        let rho = turned(a).max(turned(b)).sqrt();
        Some(rate * rate * rho + 2.0 * rate.abs() * turned(d).sqrt())
    }

    /// The gradient at `p` of the shape read through the map, from the shape's gradient
    /// `g` at `q = apply(p)`: `Jᵀ g`.
    #[inline]
    pub fn pull(&self, p: Vec3A, q: Vec3A, g: Vec3A) -> Vec3A {
        match *self {
            Map::Twist(k) => {
                let (s, c) = (k * p.y).sin_cos();
                Vec3A::new(g.x * c + g.z * s, g.y + k * (q.x * g.z - q.z * g.x), g.z * c - g.x * s)
            }
            Map::Bend(k) => {
                let (s, c) = (k * p.y).sin_cos();
                let dy = (-s - k * q.y) * g.x + (c + k * q.x) * g.y;
                Vec3A::new(c * g.x + s * g.y, dy, g.z)
            }
            // Inside the slab the point does not move the map: no slope along that axis.
            Map::Elongate(h) => Vec3A::select(p.abs().cmpgt(h), g, Vec3A::ZERO),
            Map::Mirror(m) => {
                let flip = Vec3A::select(m.cmpgt(Vec3A::ZERO) & p.cmplt(Vec3A::ZERO), -Vec3A::ONE, Vec3A::ONE);
                g * flip
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::DVec3;

    use super::super::testing::{only_shape, uniform};
    use super::Map;
    use crate::ir::{DomainOp, ShapeKind};

    /// Each native map lands where its `warp` body does, at random points, and its pulled
    /// gradient is the slope of a linear function read through it.
    #[test]
    fn native_maps_equal_their_bodies() {
        let ops = [
            "twist(box(0.5), 70)",
            "twist(box(0.5), -25)",
            "elongate(box(0.5), [0.3, 0, 0.7])",
            "symmetric(box(0.5), \"xz\")",
        ];
        let mut next = uniform(0xd000, -2.0, 2.0);
        for text in ops {
            let s = only_shape(text);
            let ShapeKind::Warp { map, domain_op: Some(op), .. } = &s.kind else { panic!("{text}: not a warp") };
            let native = Map::new(*op).expect("a native map");
            let none = |_: &Arc<crate::ir::Shape>, _: DVec3| 0.0;
            for _ in 0..1_000 {
                let p = DVec3::new(next(), next(), next());
                let want = map.eval(p, &none).vec();
                let got = native.apply(p.as_vec3a());
                assert!((got.as_dvec3() - want).length() < 1e-5, "{text} at {p}: {got} against {want}");
                // f(q) = w·q: its gradient through the map, by central differences.
                let w = glam::Vec3A::new(0.3, -0.8, 0.5);
                let f = |x: glam::Vec3A| w.dot(native.apply(x));
                let (q, h) = (p.as_vec3a(), 1e-3f32);
                let axes = [glam::Vec3A::X, glam::Vec3A::Y, glam::Vec3A::Z];
                let ahead = glam::Vec3A::from(axes.map(|a| (f(q + a * h) - f(q)) / h));
                let behind = glam::Vec3A::from(axes.map(|a| (f(q) - f(q - a * h)) / h));
                if (ahead - behind).length() < 1e-2 {
                    let g = native.pull(q, native.apply(q), w);
                    assert!((g - (ahead + behind) / 2.0).length() < 1e-2, "{text} at {p}: {g}");
                }
            }
        }
    }

    /// A twist's and a bend's stretch bound how far the map moves two points apart,
    /// relative to their distance, at random points and directions, and are reached within
    /// a tenth: the march's local step is not needlessly short.
    #[test]
    fn a_twists_stretch_bounds_and_is_reached() {
        let mut next = {
            let mut f = uniform(0x7 << 40, -2.0, 2.0);
            move || f() as f32
        };
        let ops = [15.0, 90.0, -200.0].into_iter().flat_map(|d| [DomainOp::Twist(d), DomainOp::Bend(d)]);
        for op in ops {
            let map = Map::new(op).expect("a map");
            let degrees = format!("{op:?}");
            for _ in 0..300 {
                let p = glam::Vec3A::new(next(), next(), next());
                let bound = map.stretch(p, 1e-3).expect("a bound");
                let mut most = 0.0f32;
                for _ in 0..200 {
                    let u = glam::Vec3A::new(next(), next(), next()).normalize_or(glam::Vec3A::X);
                    let moved = (map.apply(p + u * 1e-3) - map.apply(p)).length() / 1e-3;
                    assert!(moved <= bound * 1.002, "{degrees} at {p}: {moved} over {bound}");
                    most = most.max(moved);
                }
                assert!(most >= 0.9 * map.stretch(p, 0.0).expect("a bound"), "{degrees} at {p}: {most} of {bound}");
            }
        }
    }
}
