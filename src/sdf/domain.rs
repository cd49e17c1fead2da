//! Domain operations' maps evaluated natively: `twist`, `elongate` and `symmetric` move
//! the point by a few operations each, which the field interpreter paid a dispatch for
//! one by one. Each is the map its `warp` body states (`check::construct::domain`), and
//! the chain rule carries the shape's gradient back through it.

use glam::Vec3A;

use crate::ir::MeshOp;

/// A native map of the point.
#[derive(Clone, Copy, Debug)]
pub enum Map {
    /// Turned about `y` by `k` radians per unit of height, backwards.
    Twist(f32),
    /// The slab `[-h, h]` taken out.
    Elongate(Vec3A),
    /// Mirrored where the flag is 1: the absolute value of those components.
    Mirror(Vec3A),
}

impl Map {
    /// The native form of a domain operation's map, where there is one.
    pub fn new(op: MeshOp) -> Option<Map> {
        match op {
            MeshOp::Twist(k) => Some(Map::Twist(k.to_radians() as f32)),
            MeshOp::Elongate(h) => Some(Map::Elongate(h.as_vec3a())),
            MeshOp::Mirror(axes) => Some(Map::Mirror(Vec3A::from(axes.map(|a| if a { 1.0 } else { 0.0 })))),
            MeshOp::Polar(_) => None,
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
            Map::Elongate(h) => p - p.clamp(-h, h),
            Map::Mirror(m) => Vec3A::select(m.cmpgt(Vec3A::ZERO), p.abs(), p),
        }
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

    use super::Map;
    use crate::ir::{Geometry, ShapeKind};

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
        let mut seed = 0xd0_u64 << 8;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for text in ops {
            let path = std::path::Path::new("t.scn");
            let c = crate::compile_source(
                "t.scn",
                path,
                format!("light ambient(1)\nobject {text}\n"),
                &crate::source::FsLoader,
            );
            let Geometry::Shape(s) = c.scene.expect("compiles").objects[0].geometry.clone() else { panic!("a shape") };
            let ShapeKind::Warp { map, mesh_op: Some(op), .. } = &s.kind else { panic!("{text}: not a warp") };
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
}
