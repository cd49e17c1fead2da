//! Primitive solids and every per-primitive fact the back-ends and the accuracy model
//! share: bounds, bounding sphere, convexity and how the mesh back-end approximates them.
//!
//! Each fact is one exhaustive `match` here, so a new primitive does not compile until
//! every fact is stated for it; the back-ends' own exhaustive matches (the SDF leaf in
//! `sdf::build`, the generator in `mesh::lower`) do the same for how it is made.

use glam::DVec3;

use super::bounds::Aabb;

/// A primitive solid, centred at the origin; sizes are radii and half-extents.
#[derive(Clone, Debug, PartialEq)]
pub enum Primitive {
    /// Sphere of radius `radius`.
    Sphere {
        /// Radius > 0.
        radius: f64,
    },
    /// Box with half-extents `half`.
    Box {
        /// Half-extents, each > 0.
        half: DVec3,
    },
    /// Capped cylinder along y.
    Cylinder {
        /// Radius > 0.
        radius: f64,
        /// Half-height > 0.
        half_height: f64,
    },
    /// Torus in the xz plane.
    Torus {
        /// Distance from centre to tube centre, > 0.
        major: f64,
        /// Tube radius, > 0.
        minor: f64,
    },
    /// Half-space below the plane `n·p = offset`.
    Plane {
        /// Unit normal.
        normal: DVec3,
        /// Offset along the normal.
        offset: f64,
    },
    /// Capsule along y.
    Capsule {
        /// Radius > 0.
        radius: f64,
        /// Half-height of the axis segment, > 0.
        half_height: f64,
    },
    /// Capped cone along y, apex up, base of radius `radius` at `-half_height`.
    Cone {
        /// Base radius > 0.
        radius: f64,
        /// Half-height > 0.
        half_height: f64,
    },
}

/// How the mesh back-end approximates a primitive, and so how its geometric error
/// follows the detail level (the model `study::tolerance` inverts).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Facets {
    /// Made of the primitive's own flat faces (a box; a plane's square): exact at any detail.
    Exact,
    /// Polygons inscribed in circles of at most this radius, with at least `rings`
    /// sides per turn: the error is `r·(1 − cos(π/rings))`.
    Inscribed(f64),
    /// No generator: an isosurface of its bounds, deviating by up to half a cell.
    Isosurface,
}

impl Primitive {
    /// The builtin's name, as written in scenes and IR dumps.
    pub fn name(&self) -> &'static str {
        match self {
            Primitive::Sphere { .. } => "sphere",
            Primitive::Box { .. } => "box",
            Primitive::Cylinder { .. } => "cylinder",
            Primitive::Torus { .. } => "torus",
            Primitive::Plane { .. } => "plane",
            Primitive::Capsule { .. } => "capsule",
            Primitive::Cone { .. } => "cone",
        }
    }

    /// Axis-aligned bounds; `None` for the unbounded half-space.
    pub fn bounds(&self) -> Option<Aabb> {
        let centred = |h: DVec3| Some(Aabb::centred(h));
        match *self {
            Primitive::Sphere { radius } => centred(DVec3::splat(radius)),
            Primitive::Box { half } => centred(half),
            Primitive::Cylinder { radius: r, half_height: h } | Primitive::Cone { radius: r, half_height: h } => {
                centred(DVec3::new(r, h, r))
            }
            Primitive::Capsule { radius: r, half_height: h } => centred(DVec3::new(r, h + r, r)),
            Primitive::Torus { major, minor } => centred(DVec3::new(major + minor, minor, major + minor)),
            Primitive::Plane { .. } => None,
        }
    }

    /// The tightest origin-centred bounding sphere's radius; `None` when unbounded.
    pub fn sphere_radius(&self) -> Option<f64> {
        match *self {
            Primitive::Sphere { radius } => Some(radius),
            Primitive::Box { half } => Some(half.length()),
            Primitive::Cylinder { radius: r, half_height: h } | Primitive::Cone { radius: r, half_height: h } => {
                Some((r * r + h * h).sqrt())
            }
            Primitive::Capsule { radius, half_height } => Some(radius + half_height),
            Primitive::Torus { major, minor } => Some(major + minor),
            Primitive::Plane { .. } => None,
        }
    }

    /// A half-space `n·p ≤ offset` (unit `n`) holding an unbounded solid, which a ray
    /// outside it can only meet once it has entered; `None` when bounded (its box and
    /// sphere say more).
    pub fn half_space(&self) -> Option<(DVec3, f64)> {
        match *self {
            Primitive::Plane { normal, offset } => Some((normal, offset)),
            Primitive::Sphere { .. }
            | Primitive::Box { .. }
            | Primitive::Cylinder { .. }
            | Primitive::Capsule { .. }
            | Primitive::Cone { .. }
            | Primitive::Torus { .. } => None,
        }
    }

    /// Whether the solid is convex (a half-space is).
    pub fn is_convex(&self) -> bool {
        match self {
            Primitive::Sphere { .. }
            | Primitive::Box { .. }
            | Primitive::Cylinder { .. }
            | Primitive::Capsule { .. }
            | Primitive::Cone { .. }
            | Primitive::Plane { .. } => true,
            Primitive::Torus { .. } => false,
        }
    }

    /// How the mesh back-end makes its triangles (tested against the generators in
    /// `tests/scnc/primitives.rs`).
    pub fn facets(&self) -> Facets {
        match *self {
            Primitive::Sphere { radius } | Primitive::Cylinder { radius, .. } | Primitive::Cone { radius, .. } => {
                Facets::Inscribed(radius)
            }
            Primitive::Torus { major, minor } => Facets::Inscribed(major + minor),
            Primitive::Box { .. } | Primitive::Plane { .. } => Facets::Exact,
            Primitive::Capsule { .. } => Facets::Isosurface,
        }
    }
}
