//! Convex polyhedra from their corners and faces: the exact signed distance and its
//! gradient, and the exact mesh. Shared by `octahedron`, `pyramid` and `hex_prism`.
//!
//! Inside a convex solid the distance to the surface is the largest of the face planes'
//! signed distances (exact). Outside, the nearest point lies on a face whose plane the
//! point is in front of, so only those faces are searched: the point's projection if it
//! falls inside the face, else the nearest point of the face's edges.

use std::sync::Arc;

use glam::{DVec3, Vec3A};

use crate::geom::TriMesh;

/// A convex polyhedron, in f32 for the closures and f64 for its mesh.
#[derive(Debug)]
pub(super) struct Polytope {
    corners: Vec<DVec3>,
    /// Each face's corners (indices), counter-clockwise seen from outside.
    faces: Vec<Vec<u32>>,
    /// Each face: its outward unit normal, its offset (`n·p = d` on it) and its corners.
    planes: Vec<(Vec3A, f32, Vec<Vec3A>)>,
}

impl Polytope {
    /// The polyhedron with these corners and faces (convex, holding the origin inside,
    /// each face planar): faces are turned to wind counter-clockwise seen from outside.
    pub(super) fn new(corners: Vec<DVec3>, mut faces: Vec<Vec<u32>>) -> Arc<Polytope> {
        for f in &mut faces {
            let [a, b, c] = [0, 1, 2].map(|i| corners[f[i] as usize]);
            if (b - a).cross(c - a).dot(a) < 0.0 {
                f.reverse();
            }
        }
        let planes = faces
            .iter()
            .map(|f| {
                let p = |i: usize| corners[f[i] as usize];
                let n = newell(f.len(), p);
                let d = n.dot(p(0));
                (n.as_vec3a(), d as f32, (0..f.len()).map(|i| p(i).as_vec3a()).collect())
            })
            .collect();
        Arc::new(Polytope { corners, faces, planes })
    }

    /// In one pass over the faces: the face whose plane `p` is most in front of (or
    /// least behind) and by how much, and, when `p` is outside, the nearest point of the
    /// surface (searched only on faces `p` is in front of).
    #[inline]
    fn nearest(&self, p: Vec3A) -> (usize, f32, Option<Vec3A>) {
        let (mut face, mut most) = (0, f32::NEG_INFINITY);
        let mut best: Option<(f32, Vec3A)> = None;
        for (i, (n, d, corners)) in self.planes.iter().enumerate() {
            let s = n.dot(p) - d;
            if s > most {
                (face, most) = (i, s);
            }
            if s <= 0.0 {
                continue;
            }
            let c = nearest_on_face(p, *n, s, corners);
            let d2 = c.distance_squared(p);
            if best.is_none_or(|(b, _)| d2 < b) {
                best = Some((d2, c));
            }
        }
        (face, most, best.map(|(_, c)| c))
    }

    /// The exact signed distance.
    #[inline]
    pub(super) fn distance(&self, p: Vec3A) -> f32 {
        match self.nearest(p) {
            (_, _, Some(c)) => p.distance(c),
            (_, inside, None) => inside,
        }
    }

    /// The gradient of [`distance`](Self::distance): the nearest face's normal inside
    /// and on the surface, away from the nearest point outside.
    #[inline]
    pub(super) fn gradient(&self, p: Vec3A) -> Vec3A {
        let (face, _, outside) = self.nearest(p);
        let normal = self.planes[face].0;
        outside.and_then(|c| (p - c).try_normalize()).unwrap_or(normal)
    }

    /// Each face's plane `n·p ≤ d` in f64 (Newell's normal, as for the f32 planes).
    pub(super) fn face_planes(&self) -> Vec<(DVec3, f64)> {
        self.faces
            .iter()
            .map(|f| {
                let p = |i: usize| self.corners[f[i] as usize];
                let n = newell(f.len(), p);
                (n, n.dot(p(0)))
            })
            .collect()
    }

    /// Triangles: each face as a fan (exact, as the faces are flat and convex).
    pub(super) fn triangle_count(&self) -> u64 {
        self.faces.iter().map(|f| f.len() as u64 - 2).sum()
    }

    /// The exact mesh, corners shared between faces.
    pub(super) fn mesh(&self) -> TriMesh {
        let triangles = self.faces.iter().flat_map(|f| (1..f.len() - 1).map(move |i| [f[0], f[i], f[i + 1]])).collect();
        TriMesh { positions: self.corners.clone(), triangles }
    }
}

/// Newell's unit normal of a polygon of `n` corners `p(i)`: robust for any planar one.
fn newell(n: usize, p: impl Fn(usize) -> DVec3) -> DVec3 {
    (0..n)
        .map(|i| {
            let (a, b) = (p(i), p((i + 1) % n));
            DVec3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y))
        })
        .sum::<DVec3>()
        .normalize()
}

/// The [`Solid`](super::Solid) facts every convex polyhedron here states alike, given
/// its `fn solid(&self) -> Arc<Polytope>`: no half-space, convex, an exact distance and
/// gradient, and its own faces as its exact mesh at any resolution. Written into each
/// `impl Solid`, so the facts stay listed where the primitive is.
macro_rules! polyhedron_facts {
    () => {
        fn half_space(&self) -> Option<(glam::DVec3, f64)> {
            None
        }

        fn hull(&self) -> Option<crate::geom::hull::Hull> {
            Some(crate::geom::hull::Hull::planes(self.solid().face_planes()))
        }

        fn is_convex(&self) -> bool {
            true
        }

        fn hull_is_solid(&self) -> bool {
            true
        }

        fn is_exact(&self) -> bool {
            true
        }

        fn distance(&self) -> impl super::Field<f32> {
            let s = self.solid();
            move |p: glam::Vec3A| s.distance(p)
        }

        fn gradient(&self) -> impl super::Field<glam::Vec3A> {
            let s = self.solid();
            move |p: glam::Vec3A| s.gradient(p)
        }

        fn facets(&self) -> super::Facets {
            super::Facets::Exact
        }

        fn tessellate(&self, _: super::Resolution) -> super::Tessellation {
            let s = self.solid();
            super::Tessellation::Triangles(s.triangle_count(), Box::new(move || s.mesh()))
        }
    };
}
pub(super) use polyhedron_facts;

/// The nearest point to `p` of the convex face with unit normal `n` and `corners`, `p`
/// lying `s` in front of its plane: `p`'s projection if it falls inside the face, else
/// the nearest point of its edges.
#[inline]
fn nearest_on_face(p: Vec3A, n: Vec3A, s: f32, corners: &[Vec3A]) -> Vec3A {
    let q = p - n * s;
    let k = corners.len();
    let edge = |i: usize| (corners[i], corners[(i + 1) % k]);
    if (0..k).all(|i| {
        let (a, b) = edge(i);
        (b - a).cross(q - a).dot(n) >= 0.0
    }) {
        return q;
    }
    (0..k)
        .map(|i| {
            let (a, b) = edge(i);
            nearest_on_segment(p, a, b)
        })
        .min_by(|a, b| a.distance_squared(p).total_cmp(&b.distance_squared(p)))
        .unwrap_or(q)
}

#[inline]
fn nearest_on_segment(p: Vec3A, a: Vec3A, b: Vec3A) -> Vec3A {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    a + ab * t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_as_a_polytope_measures_as_a_box() {
        let corners = (0..8)
            .map(|i| {
                DVec3::new((i & 1) as f64 * 2.0 - 1.0, (i >> 1 & 1) as f64 * 2.0 - 1.0, (i >> 2) as f64 * 2.0 - 1.0)
            })
            .collect();
        let faces = vec![
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 5],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
        ];
        let cube = Polytope::new(corners, faces);
        let boxed = |p: Vec3A| {
            let q = p.abs() - Vec3A::ONE;
            q.max(Vec3A::ZERO).length() + q.max_element().min(0.0)
        };
        for p in [
            Vec3A::ZERO,
            Vec3A::new(0.5, 0.2, -0.1),
            Vec3A::new(3.0, 0.0, 0.0),
            Vec3A::new(2.0, 2.0, 0.0),
            Vec3A::new(-2.0, 3.0, 4.0),
        ] {
            assert!((cube.distance(p) - boxed(p)).abs() < 1e-5, "{p}: {} against {}", cube.distance(p), boxed(p));
        }
        assert_eq!(cube.gradient(Vec3A::new(2.0, 0.0, 0.0)), Vec3A::X);
        assert_eq!(cube.triangle_count(), 12);
        assert!((cube.mesh().signed_volume() - 8.0).abs() < 1e-12);
    }
}
