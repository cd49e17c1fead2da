//! The ten integrals a solid's mass properties come from — ∫1, ∫x, ∫y, ∫z, ∫x², ∫y²,
//! ∫z², ∫xy, ∫yz, ∫zx over its volume — for axis-aligned cubes (closed form) and closed
//! triangle meshes (the divergence theorem, exact for the polyhedron).

use glam::DVec3;

/// The ten volume integrals, in the order the module's comment lists them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments(pub [f64; 10]);

impl Moments {
    /// The integrals over the cube of centre `c` and half-side `h`.
    pub fn cube(c: DVec3, h: f64) -> Moments {
        let v = 8.0 * h * h * h;
        let s = h * h / 3.0;
        Moments([
            v,
            v * c.x,
            v * c.y,
            v * c.z,
            v * (c.x * c.x + s),
            v * (c.y * c.y + s),
            v * (c.z * c.z + s),
            v * c.x * c.y,
            v * c.y * c.z,
            v * c.z * c.x,
        ])
    }

    /// Adds `other`'s integrals.
    pub fn add(&mut self, other: &Moments) {
        for (a, b) in self.0.iter_mut().zip(other.0) {
            *a += b;
        }
    }

    /// These integrals less `other`'s.
    pub fn minus(&self, other: &Moments) -> Moments {
        let mut out = *self;
        for (a, b) in out.0.iter_mut().zip(other.0) {
            *a -= b;
        }
        out
    }

    /// The integrals over the solid a closed mesh bounds, its triangles counter-clockwise
    /// seen from outside (clockwise meshes give every integral negated), with its surface
    /// area. Each triangle makes a signed tetrahedron with the point `origin`, which is
    /// the origin of the integrals' coordinates too.
    pub fn of_mesh(positions: &[DVec3], triangles: &[[u32; 3]], origin: DVec3) -> (Moments, f64) {
        let mut m = [0.0; 10];
        let mut area = 0.0;
        for t in triangles {
            let [a, b, c] = t.map(|i| positions[i as usize] - origin);
            let cross = (b - a).cross(c - a);
            area += 0.5 * cross.length();
            let det = a.dot(b.cross(c));
            let s = a + b + c;
            m[0] += det / 6.0;
            m[1] += det / 24.0 * s.x;
            m[2] += det / 24.0 * s.y;
            m[3] += det / 24.0 * s.z;
            // ∫ x_i x_j over a tetrahedron with one corner at the origin is
            // det/120 · (Σ_k p_ki p_kj + S_i S_j) over its other three corners p_k.
            let pair = |i: usize, j: usize| {
                let g = |p: DVec3, k: usize| p.to_array()[k];
                det / 120.0 * (g(a, i) * g(a, j) + g(b, i) * g(b, j) + g(c, i) * g(c, j) + g(s, i) * g(s, j))
            };
            m[4] += pair(0, 0);
            m[5] += pair(1, 1);
            m[6] += pair(2, 2);
            m[7] += pair(0, 1);
            m[8] += pair(1, 2);
            m[9] += pair(2, 0);
        }
        (Moments(m), area)
    }

    /// The volume.
    pub fn volume(&self) -> f64 {
        self.0[0]
    }

    /// The centre of mass (at uniform density).
    pub fn centre(&self) -> DVec3 {
        DVec3::new(self.0[1], self.0[2], self.0[3]) / self.0[0]
    }

    /// The inertia tensor about the centre of mass at unit density, row by row.
    pub fn inertia(&self) -> [[f64; 3]; 3] {
        let m = &self.0;
        let c = self.centre();
        let v = m[0];
        // Second moments about the centre: ∫x_i x_j − V c_i c_j.
        let xx = m[4] - v * c.x * c.x;
        let yy = m[5] - v * c.y * c.y;
        let zz = m[6] - v * c.z * c.z;
        let xy = m[7] - v * c.x * c.y;
        let yz = m[8] - v * c.y * c.z;
        let zx = m[9] - v * c.z * c.x;
        [[yy + zz, -xy, -zx], [-xy, xx + zz, -yz], [-zx, -yz, xx + yy]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube's integrals are the same from its closed form and from its mesh,
    /// and a cube's inertia about its centre is V·a²/6 on the diagonal.
    #[test]
    fn a_cube_measures_alike_both_ways() {
        let c = DVec3::new(0.5, 1.5, 2.5);
        let closed = Moments::cube(c, 0.5);
        let p: Vec<DVec3> = (0..8).map(|i| c + DVec3::new(f(i & 1), f(i >> 1 & 1), f(i >> 2 & 1)) - 0.5).collect();
        fn f(b: i32) -> f64 {
            f64::from(b)
        }
        // Each face counter-clockwise seen from outside.
        let faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let tris: Vec<[u32; 3]> = faces.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        let (mesh, area) = Moments::of_mesh(&p, &tris, DVec3::ZERO);
        for (a, b) in closed.0.iter().zip(mesh.0) {
            assert!((a - b).abs() < 1e-12, "{closed:?}\n{mesh:?}");
        }
        assert!((area - 6.0).abs() < 1e-12);
        let i = closed.inertia();
        assert!((i[0][0] - 1.0 / 6.0).abs() < 1e-12 && i[0][1].abs() < 1e-12, "{i:?}");
    }
}
