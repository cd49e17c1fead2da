//! How finely the mesh back-end tessellates shapes.

use crate::primitive::Resolution;

/// How finely shapes are tessellated in mesh mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Detail {
    /// The study's low detail: spheres of 7 rings, circles of 10 points.
    Low,
    /// The study's high detail: spheres of 14 rings, circles of 50 points.
    High,
    /// Spheres of `N` rings (and `2N` segments), circles of `2N` points.
    N(u32),
}

impl Detail {
    /// Rings of a UV sphere (segments are twice this) and sides of a torus tube.
    pub fn rings(self) -> u32 {
        match self {
            Detail::Low => 7,
            Detail::High => 14,
            Detail::N(n) => n.max(3),
        }
    }

    /// Points on a circle (cylinder and cone caps, torus rings).
    pub fn circle(self) -> u32 {
        match self {
            Detail::Low => 10,
            Detail::High => 50,
            Detail::N(n) => 2 * n.max(3),
        }
    }

    /// The resolution primitives are tessellated at.
    pub fn resolution(self) -> Resolution {
        Resolution { rings: self.rings(), circle: self.circle() }
    }
}
