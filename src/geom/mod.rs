//! Plain geometry in f64 that every stage shares: axis-aligned boxes, indexed triangle
//! meshes and the parametric generators that make them.

pub mod axes;
pub mod font;
pub mod hull;
pub mod noise;
pub mod outline;
pub mod polygon;
pub mod region;
pub mod slab;
pub mod tessellate;

pub use noise::noise;

use glam::{DAffine3, DVec3};

/// An axis-aligned box in f64 (scene space; [`crate::accel::Aabb`] is its f32 render-space kin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DAabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl DAabb {
    /// A box centred at the origin.
    pub fn centred(half: DVec3) -> DAabb {
        DAabb { min: -half, max: half }
    }

    /// The largest distance from the `y` axis within it.
    pub fn radius_about_y(&self) -> f64 {
        let x = self.min.x.abs().max(self.max.x.abs());
        let z = self.min.z.abs().max(self.max.z.abs());
        x.hypot(z)
    }

    /// Grown by `d` on every side.
    pub fn grow(self, d: f64) -> DAabb {
        DAabb { min: self.min - d, max: self.max + d }
    }

    /// The smallest box containing both.
    pub fn union(self, o: DAabb) -> DAabb {
        DAabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// The overlap of both (may be empty: `min > max` on some axis).
    pub fn intersect(self, o: DAabb) -> DAabb {
        DAabb { min: self.min.max(o.min), max: self.max.min(o.max) }
    }

    /// The bounds of this box after an affine map.
    pub fn transform(self, xf: &DAffine3) -> DAabb {
        let centre = (self.min + self.max) * 0.5;
        let half = (self.max - self.min) * 0.5;
        let m = xf.matrix3;
        let abs = glam::DMat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        let c = xf.transform_point3(centre);
        let h = abs * half;
        DAabb { min: c - h, max: c + h }
    }

    /// Centre point.
    pub fn centre(self) -> DVec3 {
        (self.min + self.max) * 0.5
    }
}

/// An indexed triangle mesh in some frame (local for generators, render space once lowered).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles as vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Adds `other`'s triangles and vertices (its own, not welded to these).
    pub fn append(&mut self, other: TriMesh) {
        let base = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.triangles.extend(other.triangles.into_iter().map(|t| t.map(|i| i + base)));
    }

    /// Signed volume (positive for a closed mesh wound outward).
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Edges used by a number of triangles other than two, counting each undirected edge;
    /// 0 for a closed (watertight) mesh. Directed edges used twice mean inconsistent winding.
    pub fn open_edges(&self) -> (usize, usize) {
        let mut undirected = std::collections::HashMap::new();
        let mut directed = std::collections::HashMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *undirected.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
                *directed.entry((a, b)).or_insert(0usize) += 1;
            }
        }
        (undirected.values().filter(|&&n| n != 2).count(), directed.values().filter(|&&n| n > 1).count())
    }
}
