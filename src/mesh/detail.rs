//! How finely the mesh back-end tessellates shapes.

use glam::DAffine3;

use super::tree::Deviation;
use crate::primitive::Resolution;

/// How finely shapes are tessellated in mesh mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Detail {
    /// The study's low detail: spheres of 7 rings, circles of 10 points.
    Low,
    /// The study's high detail: spheres of 14 rings, circles of 50 points.
    High,
    /// Spheres of `N` rings (and `2N` segments), circles of `2N` points.
    N(u32),
    /// What `--tolerance` asks for: primitives at `rings`, isosurfaces with cells as
    /// coarse as keeps them within `deviation` of their surface (in the frame the scene
    /// is lowered in: [`in_frame`](Detail::in_frame) moves it).
    Within {
        /// Rings of primitives, as [`Detail::N`].
        rings: u32,
        /// The bound on an isosurface's distance from its surface.
        deviation: Deviation,
    },
}

impl Detail {
    /// Rings of a UV sphere (segments are twice this) and sides of a torus tube.
    pub fn rings(self) -> u32 {
        match self {
            Detail::Low => 7,
            Detail::High => 14,
            Detail::N(n) | Detail::Within { rings: n, .. } => n.max(3),
        }
    }

    /// Points on a circle (cylinder and cone caps, torus rings).
    pub fn circle(self) -> u32 {
        match self {
            Detail::Low => 10,
            Detail::High => 50,
            Detail::N(n) | Detail::Within { rings: n, .. } => 2 * n.max(3),
        }
    }

    /// The resolution primitives are tessellated at.
    pub fn resolution(self) -> Resolution {
        Resolution { rings: self.rings(), circle: self.circle() }
    }

    /// The detail as a command reports it.
    pub fn describe(self) -> String {
        match self {
            Detail::Low => "detail low".into(),
            Detail::High => "detail high".into(),
            Detail::N(n) => format!("detail {n}"),
            Detail::Within { rings, deviation } => {
                format!("detail {rings} for curved primitives, isosurfaces within {}", deviation.label())
            }
        }
    }

    /// The isosurfaces' bound, under a tolerance.
    pub fn deviation(self) -> Option<Deviation> {
        match self {
            Detail::Within { deviation, .. } => Some(deviation),
            Detail::Low | Detail::High | Detail::N(_) => None,
        }
    }

    /// The same detail for a scene placed by `xf` (its bound's nearest point moves with it;
    /// `xf` moves and turns, it does not scale).
    pub fn in_frame(self, xf: &DAffine3) -> Detail {
        match self {
            Detail::Within { rings, deviation } => {
                Detail::Within { rings, deviation: Deviation { eye: xf.transform_point3(deviation.eye), ..deviation } }
            }
            other => other,
        }
    }

    /// A finer detail: rings and, under a tolerance, the bound by `factor` (> 1).
    pub fn finer(self, factor: f64) -> Detail {
        let rings = (f64::from(self.rings()) * factor).ceil() as u32;
        match self {
            Detail::Within { deviation, .. } => Detail::Within {
                rings,
                deviation: Deviation {
                    absolute: deviation.absolute / factor,
                    per_distance: deviation.per_distance / factor,
                    ..deviation
                },
            },
            Detail::Low | Detail::High | Detail::N(_) => Detail::N(rings),
        }
    }
}
