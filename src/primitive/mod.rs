//! The primitive solids, each one definition: a file here declares its parameters (names,
//! types, defaults, ranges and docs, with [`params!`](crate::params)) and implements
//! [`Solid`] — its IR node, bounds, half-space, convexity, distance and gradient, and how
//! it is meshed. Every method is required, so a primitive that leaves one out does not
//! compile; one macro (`primitives!`) lists them once, and every stage reaches a primitive only
//! through [`Primitive`]'s dispatch or [`Visit`], never by naming one.
//!
//! The tests derived from this list (`tests/scnc/derived.rs`) check every primitive
//! without anyone writing a test for it: its distance is a bound on the true distance and
//! 1-Lipschitz, its gradient agrees with the distance, its box holds its surface, its
//! mesh is closed, outward and within tolerance of its zero set, and its docs and checked
//! ranges agree. `docs/ARCHITECTURE.md` says how to add one.

mod capped_cone;
mod capsule;
mod cone;
mod cuboid;
mod cylinder;
mod ellipsoid;
mod hex_prism;
mod octahedron;
mod plane;
mod polytope;
mod pyramid;
mod sphere;
mod torus;

use std::fmt;

use glam::{DVec3, Vec2, Vec3A, Vec3Swizzles};

pub use capped_cone::CappedCone;
pub use capsule::Capsule;
pub use cone::Cone;
pub use cuboid::Cuboid;
pub use cylinder::Cylinder;
pub use ellipsoid::Ellipsoid;
pub use hex_prism::HexPrism;
pub use octahedron::Octahedron;
pub use plane::Plane;
pub use pyramid::Pyramid;
pub use sphere::Sphere;
pub use torus::Torus;

use crate::geom::hull::Hull;
use crate::geom::{DAabb, TriMesh};
use crate::sig::{Args, Param};

/// A distance function in render-space f32, or its gradient: what the SDF back-end
/// composes into closures.
pub trait Field<T>: Fn(Vec3A) -> T + Clone + Send + Sync + 'static {}

impl<T, F: Fn(Vec3A) -> T + Clone + Send + Sync + 'static> Field<T> for F {}

/// Everything one primitive is, in one place. The solid is centred at the origin in its
/// own frame; transforms are the IR's business.
pub trait Solid: Clone + fmt::Debug + PartialEq + Send + Sync + 'static {
    /// The builtin's name, as written in scenes and IR dumps.
    const NAME: &'static str;
    /// One line for hover and the reference.
    const DOC: &'static str;
    /// Its parameters, declared with [`params!`](crate::params).
    const PARAMS: &'static [Param];

    /// The IR node from arguments already checked against [`PARAMS`](Self::PARAMS)
    /// (types and ranges): the rules that tie parameters together, and normal forms (a
    /// unit normal).
    fn new(args: &dyn Args) -> Result<Self, Refusal>;

    /// Axis-aligned bounds; `None` for an unbounded solid.
    fn bounds(&self) -> Option<DAabb>;

    /// The tightest origin-centred bounding sphere's radius; `None` when unbounded.
    fn sphere_radius(&self) -> Option<f64>;

    /// A half-space `n·p ≤ offset` (unit `n`) holding an unbounded solid, which a ray
    /// outside it can only meet once it has entered; `None` when bounded (its box and
    /// sphere say more).
    fn half_space(&self) -> Option<(DVec3, f64)>;

    /// A convex set holding the solid, as tight as cheap (the solid itself when it is
    /// a convex polyhedron, a cylinder, a capped cone or an ellipsoid): a ray is clipped
    /// to it before it is marched, so a miss costs no step and a hit starts at or near
    /// the surface. `None` where the bounding sphere is as good (a sphere) or there is
    /// none (unbounded).
    fn hull(&self) -> Option<Hull>;

    /// Whether the solid is convex (a half-space is).
    fn is_convex(&self) -> bool;

    /// Whether [`hull`](Self::hull) is the solid itself, not only a set holding it: then
    /// a ray from outside that enters the hull hits the solid there, with no step to take.
    fn hull_is_solid(&self) -> bool;

    /// Whether [`distance`](Self::distance) is the exact Euclidean distance to the
    /// surface, not only a bound on it.
    fn is_exact(&self) -> bool;

    /// The signed distance (negative inside): never more than the true distance to the
    /// surface, and 1-Lipschitz.
    fn distance(&self) -> impl Field<f32>;

    /// The gradient of [`distance`](Self::distance), analytic, unit length wherever the
    /// distance is exact and differentiable (a defined unit vector elsewhere).
    fn gradient(&self) -> impl Field<Vec3A>;

    /// How the mesh back-end's triangles approximate it.
    fn facets(&self) -> Facets;

    /// Its triangles at a resolution.
    fn tessellate(&self, res: Resolution) -> Tessellation;

    /// Its arguments as the IR dump shows them: `(name, value)` in declaration order.
    fn fields(&self) -> Vec<(&'static str, String)>;
}

/// A rule between parameters that the arguments break, to report at the parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    /// The parameter to blame.
    pub param: &'static str,
    /// What it must be, as "`param` must be …" completes it.
    pub rule: String,
}

/// How finely curved primitives are tessellated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolution {
    /// Rings of a sphere (its segments are twice this), sides of a torus tube.
    pub rings: u32,
    /// Points on a circle (cylinder and cone caps, torus rings).
    pub circle: u32,
}

/// How the mesh back-end makes a primitive's triangles.
pub enum Tessellation {
    /// A generator: the exact triangle count (charged to the budget before anything is
    /// allocated) and the call that makes them, in the primitive's frame.
    Triangles(u64, Box<dyn FnOnce() -> TriMesh + Send>),
    /// A half-space `n·p ≤ offset`: a square reaching the far limit.
    HalfSpace {
        /// Unit normal.
        normal: DVec3,
        /// Offset along it.
        offset: f64,
    },
    /// No generator: the isosurface mesher makes it from the distance.
    Isosurface,
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

/// Something done with one primitive, whatever it is: the SDF back-end builds its
/// closures this way, each primitive's distance inlined in its own closure type.
pub trait Visit {
    /// What the visit gives.
    type Out;
    /// The visit of primitive `s`.
    fn visit<S: Solid>(self, s: &S) -> Self::Out;
}

/// One primitive of the list: its builtin's name, doc and parameters, and the
/// constructor the checker calls.
pub struct Entry {
    /// The builtin's name.
    pub name: &'static str,
    /// Its one-line doc.
    pub doc: &'static str,
    /// Its parameters.
    pub params: &'static [Param],
    /// The IR node from checked arguments.
    pub build: fn(&dyn Args) -> Result<Primitive, Refusal>,
}

impl PartialEq for Entry {
    fn eq(&self, o: &Entry) -> bool {
        self.name == o.name
    }
}

impl Eq for Entry {}

impl fmt::Debug for Entry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "primitive `{}`", self.name)
    }
}

/// The list of primitives: the [`Primitive`] enum, its dispatch of every [`Solid`]
/// method (one exhaustive match each, written once here), and [`PRIMITIVES`].
macro_rules! primitives {
    ($($variant:ident($ty:ty)),* $(,)?) => {
        /// A primitive solid, centred at the origin; its arguments are its IR node.
        #[derive(Clone, Debug, PartialEq)]
        pub enum Primitive {
            $(
                #[doc = concat!("`", stringify!($variant), "`: see [`", stringify!($ty), "`].")]
                $variant($ty),
            )*
        }

        /// Every primitive, in the order the builtins list them.
        pub static PRIMITIVES: &[Entry] = &[
            $(
                Entry {
                    name: <$ty as Solid>::NAME,
                    doc: <$ty as Solid>::DOC,
                    params: <$ty as Solid>::PARAMS,
                    build: |a| <$ty as Solid>::new(a).map(Primitive::$variant),
                },
            )*
        ];

        impl Primitive {
            /// `v`'s visit of this primitive.
            pub fn visit<V: Visit>(&self, v: V) -> V::Out {
                match self {
                    $(Primitive::$variant(s) => v.visit(s),)*
                }
            }
        }
    };
}

primitives! {
    Sphere(Sphere),
    Box(Cuboid),
    Cylinder(Cylinder),
    Torus(Torus),
    Plane(Plane),
    Capsule(Capsule),
    Cone(Cone),
    CappedCone(CappedCone),
    Ellipsoid(Ellipsoid),
    Octahedron(Octahedron),
    Pyramid(Pyramid),
    HexPrism(HexPrism),
}

/// Methods of [`Primitive`] that ask one [`Solid`] fact of whichever primitive it is.
macro_rules! ask {
    ($($(#[$doc:meta])* $name:ident -> $out:ty;)*) => {
        $(
            $(#[$doc])*
            pub fn $name(&self) -> $out {
                struct Fact;
                impl Visit for Fact {
                    type Out = $out;
                    fn visit<S: Solid>(self, s: &S) -> $out {
                        s.$name()
                    }
                }
                self.visit(Fact)
            }
        )*
    };
}

impl Primitive {
    ask! {
        /// Axis-aligned bounds; `None` for the unbounded half-space.
        bounds -> Option<DAabb>;
        /// The tightest origin-centred bounding sphere's radius; `None` when unbounded.
        sphere_radius -> Option<f64>;
        /// A half-space holding an unbounded solid ([`Solid::half_space`]).
        half_space -> Option<(DVec3, f64)>;
        /// A convex set holding the solid ([`Solid::hull`]).
        hull -> Option<Hull>;
        /// Whether the solid is convex (a half-space is).
        is_convex -> bool;
        /// Whether its hull is the solid itself ([`Solid::hull_is_solid`]).
        hull_is_solid -> bool;
        /// Whether its distance is exact ([`Solid::is_exact`]).
        is_exact -> bool;
        /// How the mesh back-end approximates it (tested against the generators in
        /// `tests/scnc/derived.rs`).
        facets -> Facets;
        /// Its arguments as the IR dump shows them.
        fields -> Vec<(&'static str, String)>;
    }

    /// The builtin's name, as written in scenes and IR dumps.
    pub fn name(&self) -> &'static str {
        struct Name;
        impl Visit for Name {
            type Out = &'static str;
            fn visit<S: Solid>(self, _: &S) -> &'static str {
                S::NAME
            }
        }
        self.visit(Name)
    }

    /// The analytic normal at each corner of each triangle of `mesh` (its
    /// tessellation), taken a hair inside the triangle so that each face gets its own
    /// side of a crease: the shading normals of a curved primitive's mesh.
    pub fn corner_normals(&self, mesh: &TriMesh) -> Vec<[DVec3; 3]> {
        struct Corners<'m>(&'m TriMesh);
        impl Visit for Corners<'_> {
            type Out = Vec<[DVec3; 3]>;
            fn visit<S: Solid>(self, s: &S) -> Self::Out {
                let g = s.gradient();
                let m = self.0;
                m.triangles
                    .iter()
                    .map(|t| {
                        let corners = t.map(|i| m.positions[i as usize]);
                        let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
                        corners.map(|c| {
                            let inside = c + (centre - c) * 1e-3;
                            g(inside.as_vec3a()).as_dvec3().normalize_or(DVec3::Y)
                        })
                    })
                    .collect()
            }
        }
        self.visit(Corners(mesh))
    }

    /// Its triangles at a resolution ([`Solid::tessellate`]).
    pub fn tessellate(&self, res: Resolution) -> Tessellation {
        struct Tess(Resolution);
        impl Visit for Tess {
            type Out = Tessellation;
            fn visit<S: Solid>(self, s: &S) -> Tessellation {
                s.tessellate(self.0)
            }
        }
        self.visit(Tess(res))
    }
}

/// The unit vector from the y axis towards `p` in the xz plane (`x` on the axis): the
/// radial direction of a solid of revolution.
#[inline]
fn radial(p: Vec3A) -> Vec3A {
    Vec3A::new(p.x, 0.0, p.z).try_normalize().unwrap_or(Vec3A::X)
}

/// A solid of revolution's gradient from its profile's, in the half-plane (radius, y).
#[inline]
fn revolve(p: Vec3A, g: Vec2) -> Vec3A {
    radial(p) * g.x + Vec3A::Y * g.y
}

/// `p` in the half-plane of a solid of revolution: (distance from the y axis, y).
#[inline]
fn profile(p: Vec3A) -> Vec2 {
    Vec2::new(p.xz().length(), p.y)
}

#[cfg(test)]
mod tests;
