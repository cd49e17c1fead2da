//! Sweeps evaluated natively: an extruded or revolved profile of polygons and circles by
//! sharp CSG is the same distance as its field body (Quilez's polygon distance, a
//! circle's, their min and max; then the slab or the radius), computed here in f32 with
//! its gradient instead of by the field interpreter, which paid a dispatch per
//! operation for a polygon's dozens (`benches/scenes/library-100.scn`, one kind at a time).

use std::sync::Arc;

use glam::{Vec2, Vec3A};

use crate::geom::outline::Outline;
use crate::geom::region::{Combine, Region};
use crate::ir::Sweep;

/// A profile's region in f32, for the closures.
#[derive(Debug)]
enum Flat {
    /// Corners in order.
    Polygon(Vec<Vec2>),
    /// Centre and radius.
    Circle(Vec2, f32),
    /// Sharp CSG.
    Csg(Combine, Vec<Flat>),
    /// Glyphs: their exact distance, searched in f64.
    Outline(Arc<Outline>),
}

impl Flat {
    fn new(r: &Region) -> Flat {
        match r {
            Region::Polygon(c) => Flat::Polygon(c.iter().map(|p| p.as_vec2()).collect()),
            Region::Circle { centre, r } => Flat::Circle(centre.as_vec2(), *r as f32),
            Region::Csg(op, parts) => Flat::Csg(*op, parts.iter().map(Flat::new).collect()),
            Region::Outline(o) => Flat::Outline(o.clone()),
        }
    }

    /// The signed distance at `p` and its gradient, as the profile's field body has it.
    fn eval(&self, p: Vec2) -> (f32, Vec2) {
        match self {
            Flat::Polygon(c) => polygon(c, p),
            Flat::Outline(o) => {
                let n = o.nearest(p.as_dvec2());
                (n.d as f32, n.g.as_vec2())
            }
            Flat::Circle(centre, r) => {
                let w = p - *centre;
                let len = w.length();
                (len - r, if len > 0.0 { w / len } else { Vec2::Y })
            }
            Flat::Csg(op, parts) => {
                let mut it = parts.iter().map(|f| f.eval(p));
                let first = it.next().unwrap_or((f32::INFINITY, Vec2::Y));
                it.fold(first, |a, b| match op {
                    Combine::Union => pick(a, b, |x, y| x <= y),
                    Combine::Intersect => pick(a, b, |x, y| x >= y),
                    Combine::Subtract => pick(a, (-b.0, -b.1), |x, y| x >= y),
                })
            }
        }
    }
}

/// `a` when `keep(a, b)`, else `b` (the min or max of two distances, with its gradient).
fn pick(a: (f32, Vec2), b: (f32, Vec2), keep: impl Fn(f32, f32) -> bool) -> (f32, Vec2) {
    if keep(a.0, b.0) {
        a
    } else {
        b
    }
}

/// Quilez's exact polygon distance, as `builtins::profiles` writes it: the
/// nearest edge, the sign flipped by each edge the horizontal ray from `p` crosses.
fn polygon(c: &[Vec2], p: Vec2) -> (f32, Vec2) {
    let n = c.len();
    let (mut best, mut away, mut sign) = (f32::INFINITY, Vec2::Y, 1.0f32);
    for i in 0..n {
        let (vi, vj) = (c[i], c[(i + n - 1) % n]);
        let (e, w) = (vj - vi, p - vi);
        let t = (w.dot(e) / e.dot(e)).clamp(0.0, 1.0);
        let b = w - e * t;
        let bb = b.dot(b);
        if bb < best {
            (best, away) = (bb, b);
        }
        let (c1, c2, c3) = (p.y >= vi.y, p.y < vj.y, e.x * w.y > e.y * w.x);
        if (c1 && c2 && c3) || (!c1 && !c2 && !c3) {
            sign = -sign;
        }
    }
    let d = best.sqrt();
    // Away from the nearest point, outward: the sign turns it inward-out inside.
    let g = if d > 0.0 { away / d * sign } else { Vec2::Y };
    (sign * d, g)
}

/// A sweep's distance and gradient at a point of the solid.
#[derive(Debug)]
pub struct Swept {
    flat: Flat,
    /// Half the extrusion's height; `None` for a revolution about `y`.
    half_height: Option<f32>,
}

impl Swept {
    /// The native form of `sweep`.
    pub fn new(sweep: &Sweep) -> Swept {
        match sweep {
            Sweep::Extrude { region, half_height } => {
                Swept { flat: Flat::new(region), half_height: Some(*half_height as f32) }
            }
            Sweep::Revolve { region } => Swept { flat: Flat::new(region), half_height: None },
        }
    }

    /// The distance at `p`.
    pub fn distance(&self, p: Vec3A) -> f32 {
        self.eval(p).0
    }

    /// The distance at `p` and its gradient.
    pub fn eval(&self, p: Vec3A) -> (f32, Vec3A) {
        match self.half_height {
            Some(h) => {
                // The profile in x, z; the slab along y; joined as two orthogonal slabs.
                let (a, ga) = self.flat.eval(Vec2::new(p.x, p.z));
                let ga = Vec3A::new(ga.x, 0.0, ga.y);
                let (b, gb) = (p.y.abs() - h, Vec3A::new(0.0, if p.y < 0.0 { -1.0 } else { 1.0 }, 0.0));
                if a > 0.0 && b > 0.0 {
                    // Not `hypot`: its overflow guard is a libm call, and these are scene-sized.
                    let len = (a * a + b * b).sqrt();
                    (len, (ga * a + gb * b) / len)
                } else if a >= b {
                    (a, ga)
                } else {
                    (b, gb)
                }
            }
            None => {
                let r = (p.x * p.x + p.z * p.z).sqrt();
                let (d, g) = self.flat.eval(Vec2::new(r, p.y));
                let radial = if r > 0.0 { Vec3A::new(p.x / r, 0.0, p.z / r) } else { Vec3A::X };
                (d, radial * g.x + Vec3A::Y * g.y)
            }
        }
    }

    /// Bytes held, for the memory counters.
    pub fn bytes(&self) -> usize {
        fn of(f: &Flat) -> usize {
            std::mem::size_of::<Flat>()
                + match f {
                    Flat::Polygon(c) => c.len() * std::mem::size_of::<Vec2>(),
                    Flat::Circle(..) => 0,
                    Flat::Csg(_, parts) => parts.iter().map(of).sum(),
                    Flat::Outline(o) => o.bytes(),
                }
        }
        std::mem::size_of::<Swept>() + of(&self.flat)
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::{DVec3, Vec3A};

    use super::super::testing::{only_shape, uniform};
    use super::Swept;
    use crate::ir::ShapeKind;

    /// The sweep of the scene's only object, with its field body.
    fn sweep_of(text: &str) -> (Swept, Arc<crate::ir::field::FieldExpr>) {
        let mut s = only_shape(text);
        loop {
            match &s.kind {
                ShapeKind::Field { sweep: Some(sweep), body, .. } => return (Swept::new(sweep), body.clone()),
                ShapeKind::Transform { child, .. } | ShapeKind::Paint { child, .. } => s = child.clone(),
                _ => panic!("{text}: not a sweep"),
            }
        }
    }

    /// Every sweep of polygons and circles is evaluated natively to the value its field
    /// body has, at random points in and around it, and its gradient is the slope of
    /// that value (central differences, away from creases).
    #[test]
    fn native_sweeps_equal_their_bodies() {
        let profiles = [
            "polygon([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]) rotate 30 at [-0.5, -0.7]",
            "polygon([[0.3, -1], [0.2, 0.9], [-0.8, 0.1]])",
            "rect(0.6, 0.3) scale 1.5",
            "circle(0.8) at [0.2, 0.1]",
            "subtract(rect(1, 0.7), circle(0.3), rect(0.1, 0.2) rotate 20 at [0.6, 0])",
            "union(circle(0.5) at [0.5, 0], rect(0.2, 0.9))",
            "intersect(circle(1), rect(0.9, 0.5) rotate 45)",
            "shell(circle(0.7), 0.2)",
            "round(circle(0.4), 0.1) at [0.9, 0.2]",
        ];
        let mut next = uniform(0x5eed, -2.0, 2.0);
        let none = |_: &Arc<crate::ir::Shape>, _: DVec3| 0.0;
        for profile in profiles {
            for text in [format!("extrude({profile}, 0.6)"), format!("revolve({profile} at [1.2, 0])")] {
                let (swept, body) = sweep_of(&text);
                for _ in 0..2_000 {
                    let p = DVec3::new(next(), next(), next());
                    let want = body.eval(p, &none).num();
                    let (got, g) = swept.eval(p.as_vec3a());
                    assert!((f64::from(got) - want).abs() < 1e-4, "{text} at {p}: {got} against {want}");
                    // One-sided slopes on both sides: where they agree, no crease lies
                    // between, and the gradient is their slope.
                    let (q, h) = (p.as_vec3a(), 1e-3f32);
                    let f = |x: Vec3A| swept.distance(x);
                    let axes = [Vec3A::X, Vec3A::Y, Vec3A::Z];
                    let ahead = Vec3A::from(axes.map(|a| (f(q + a * h) - f(q)) / h));
                    let behind = Vec3A::from(axes.map(|a| (f(q) - f(q - a * h)) / h));
                    if (ahead - behind).length() < 1e-3 {
                        let slope = (ahead + behind) / 2.0;
                        assert!((slope - g).length() < 1e-2, "{text} at {p}: gradient {g} against {slope}");
                    }
                }
            }
        }
    }
}
