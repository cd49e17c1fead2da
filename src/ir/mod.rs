//! The scene IR: what the file means, fully evaluated and checked, in f64.
//!
//! Loops, functions, arithmetic and includes are gone; what remains is a camera, render
//! settings, lights, and objects whose geometry is a tree of primitives, CSG operators,
//! modifiers, composed affine transforms and material nodes, or a mesh generator.
//!
//! **Invariant:** every number is finite and within the range its builtin documents
//! (radii > 0, reflectivity in [0, 1], scale factors > 0, counts ≥ 1); the checker
//! guarantees it, so back-ends never re-validate. Every node keeps its source span.

mod bounds;
mod convex;
mod dump;
pub mod field;
mod materials;
mod paint;
mod param;
mod view;

use std::path::PathBuf;
use std::sync::Arc;

use glam::{DAffine3, DVec3};

pub use crate::geom::DAabb;
pub use crate::primitive::{Facets, Primitive};
pub use bounds::{
    bounding_sphere, max_stretch, mesh_bounds, min_singular_value, shape_bounds, shape_half_space, shape_hull,
    shape_sphere, shape_sphere_with, similarity, transform_half_space, FieldPlanes, FieldSphere,
};
pub use dump::dump;
pub(crate) use dump::{num as dump_num, vec as dump_vec};
pub use materials::{materials_of, Material};
pub use paint::{Paint, Pattern, PatternKind};
pub use param::{ParamValue, SceneParam};
pub use view::{Camera, ColorSpace, Light, LightKind, Settings, DEFAULT_BOUNCES, SEED_FOV};

use crate::span::Span;

/// A fully evaluated scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The camera (the study's default when the file has no `camera`).
    pub camera: Camera,
    /// Image and tracer settings.
    pub settings: Settings,
    /// Lights in source order.
    pub lights: Vec<Light>,
    /// Objects in source order.
    pub objects: Vec<Object>,
    /// The names `let` gave materials, by the span of their `material(…)` call (what
    /// exported files call them).
    pub material_names: Vec<(Span, String)>,
    /// The scene's `param`s in source order, with the values this evaluation used.
    pub params: Vec<SceneParam>,
}

/// One `object` statement.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Its geometry.
    pub geometry: Body,
    /// The statement.
    pub span: Span,
    /// What exported files call it: the name its expression starts from (a `let`, a
    /// function, a builtin, a mesh file's stem), made unique in the scene with `_2`, `_3`….
    pub name: String,
}

/// What an object is made of: an SDF-able shape tree or an explicit mesh (the tracer meets
/// either through [`crate::trace::Geometry`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Body {
    /// A shape: sphere traced by the SDF back-end, tessellated by the mesh back-end.
    Shape(Arc<Shape>),
    /// A mesh: traced as triangles by both back-ends.
    Mesh(Arc<Mesh>),
}

/// A node of a shape tree.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    /// What it is.
    pub kind: ShapeKind,
    /// The expression it came from.
    pub span: Span,
    /// Nodes of the tree with shared parts counted each time they are used: what every
    /// walk of the tree (bounds, lowering, the dump) visits. A repeated shape counts once,
    /// as its evaluation visits one cell's neighbourhood. Saturates.
    pub nodes: u64,
}

impl Shape {
    /// A node over `kind`, counting its expanded size from its children's.
    pub fn new(kind: ShapeKind, span: Span) -> Shape {
        let mut shape = Shape { kind, span, nodes: 1 };
        let own = match &shape.kind {
            // A body is its operations and the shapes it measures.
            ShapeKind::Field { body: e, .. } | ShapeKind::Warp { map: e, .. } | ShapeKind::Displace { by: e, .. } => {
                e.shapes().iter().fold(e.size() as u64, |n, s| n.saturating_add(s.nodes))
            }
            _ => 1,
        };
        shape.nodes = shape.children().iter().fold(own, |n, c| n.saturating_add(c.nodes));
        shape
    }
}

/// How a CSG node combines its children.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CsgOp {
    /// Everything inside any child.
    Union,
    /// Only what is inside every child.
    Intersect,
    /// The first child minus the rest.
    Subtract,
}

impl CsgOp {
    /// The builtin's name.
    pub fn name(self) -> &'static str {
        match self {
            CsgOp::Union => "union",
            CsgOp::Intersect => "intersect",
            CsgOp::Subtract => "subtract",
        }
    }
}

/// The builtin domain operation a warp is: the SDF back-end evaluates its map natively
/// (`sdf::domain`), and the mesh back-end makes its mesh from the child's own where it
/// can (all but `bend`, which the isosurface mesher meshes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DomainOp {
    /// `twist(s, k)`: `k` degrees per unit about `y`.
    Twist(f64),
    /// `bend(s, k)`: the point at height `y` turned about `z` by `k·y` degrees.
    Bend(f64),
    /// `polar(s, count)` of a part within its sector: `count` copies turned about `y`.
    Polar(u32),
    /// `elongate(s, h)`: the halves moved apart by `±h` along each axis, a band between.
    Elongate(glam::DVec3),
    /// `symmetric(s, axes)`: the half at positive coordinates mirrored along each axis set.
    Mirror([bool; 3]),
}

/// A mesh a sweep knows for its zero set, better than the isosurface mesher's.
#[derive(Clone, Debug, PartialEq)]
pub enum ExactMesh {
    /// Flat faces that are exactly the zero set (an extruded polygon's prism).
    Faces(Arc<crate::geom::TriMesh>),
    /// A polygon of corners `[radius, height]` (none at a negative radius, those on the
    /// axis next to each other) revolved about `y`: tessellated at lowering with as many
    /// segments as a circle has at the detail, every vertex on the surface.
    Lathe(Arc<Vec<glam::DVec2>>),
    /// A region of polygons and circles (but one polygon: [`ExactMesh::Lathe`]) revolved
    /// about `y`: tessellated at lowering, each outline a lathe and each hole one turned
    /// inside out (`geom::region::revolution`).
    Revolution {
        /// The profile's region, `[u, v]` as radius and height.
        region: Arc<crate::geom::region::Region>,
        /// Its largest radius (`u`), where its circles about `y` deviate most.
        radius: f64,
    },
    /// A region of polygons and circles with holes or several parts, extruded from
    /// `y = -half_height` to `half_height`: its circles tessellated at lowering, the
    /// booleans taken and the caps triangulated there (`geom::region::extrusion`).
    Extrusion {
        /// The profile's region, `[u, v]` as the solid's `x`, `z`.
        region: Arc<crate::geom::region::Region>,
        /// Half the extrusion's height.
        half_height: f64,
    },
}

/// A profile swept into a solid, for native evaluation ([`ShapeKind::Field::sweep`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Sweep {
    /// `[u, v]` as `x`, `z`, from `y = -half_height` to `half_height`.
    Extrude {
        /// The profile's region.
        region: Arc<crate::geom::region::Region>,
        /// Half the height.
        half_height: f64,
    },
    /// `[u, v]` as the radius from `y` and the height.
    Revolve {
        /// The profile's region.
        region: Arc<crate::geom::region::Region>,
    },
}

/// Shape nodes: a primitive leaf, a CSG operator, a modifier, a transform or a material.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeKind {
    /// A primitive solid (every per-primitive fact is stated there).
    Primitive(Primitive),
    /// A CSG operator over its children (`smooth` = 0 for a sharp one).
    Csg {
        /// Union, intersection or subtraction.
        op: CsgOp,
        /// At least one child.
        children: Vec<Arc<Shape>>,
        /// Smoothing radius ≥ 0.
        smooth: f64,
    },
    /// Rounded by `radius` (grows the shape).
    Round {
        /// The shape.
        child: Arc<Shape>,
        /// Radius ≥ 0.
        radius: f64,
    },
    /// Hollowed to a wall of `thickness` around the surface.
    Shell {
        /// The shape.
        child: Arc<Shape>,
        /// Thickness > 0.
        thickness: f64,
    },
    /// Finite repetition, `count` copies along each axis centred at the origin.
    Repeat {
        /// The shape.
        child: Arc<Shape>,
        /// Spacing per axis, > 0.
        period: DVec3,
        /// Copies per axis, ≥ 1.
        count: [u32; 3],
    },
    /// An affine transform (world from local), composed from `at`, `rotate` and `scale`.
    Transform {
        /// The shape.
        child: Arc<Shape>,
        /// World-from-local transform; always invertible.
        xf: DAffine3,
    },
    /// A material for every part below that has none of its own.
    Paint {
        /// The shape.
        child: Arc<Shape>,
        /// The material.
        material: Arc<Material>,
    },
    /// `field(p => f)`: inside where `f(p) < 0`, cut to `bounds` when given.
    Field {
        /// The body, a number.
        body: Arc<field::FieldExpr>,
        /// Where it lives; `None`: everywhere, like a plane.
        bounds: Option<DAabb>,
        /// The bound of the body's slope it is marched with.
        lipschitz: Lipschitz,
        /// A mesh of its zero set, when the builder knows one (an extruded polygon's
        /// prism, a revolved polygon's lathe): the mesh back-end uses it instead of the
        /// isosurface mesher.
        exact: Option<ExactMesh>,
        /// The sweep it is, when it is one of a region of polygons and circles: the SDF
        /// back-end evaluates that natively (`sdf::sweep`), the same distance as `body`.
        sweep: Option<Sweep>,
    },
    /// `warp(shape, p => q)`: the shape seen at `q(p)`, cut to `bounds` when given.
    Warp {
        /// The shape.
        child: Arc<Shape>,
        /// The map, a vector.
        map: Arc<field::FieldExpr>,
        /// Where the result lives; `None`: everywhere.
        bounds: Option<DAabb>,
        /// The bound of how much the map stretches a distance.
        lipschitz: Lipschitz,
        /// The domain operation the warp is, when a builtin made it.
        domain_op: Option<DomainOp>,
    },
    /// `displace(shape, p => d)`: the shape's distance plus `d(p)`.
    Displace {
        /// The shape.
        child: Arc<Shape>,
        /// The displacement, a number.
        by: Arc<field::FieldExpr>,
        /// Where the result lives, when given; otherwise the shape's bounds grown by `reach`.
        bounds: Option<DAabb>,
        /// The bound of the displacement's slope.
        lipschitz: Lipschitz,
        /// How far the displacement can push the surface out: the most `-d` gets
        /// where the shape's bounds grown by it reach (0 when `d` ≥ 0 there).
        reach: f64,
    },
}

/// The bound of a field's slope (its Lipschitz constant) a march divides it by, so
/// that a step never crosses the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lipschitz {
    /// The bound, > 0.
    pub value: f64,
    /// Whether the scene states it (`lipschitz = …`) rather than the checker's estimate.
    pub given: bool,
}

impl Shape {
    /// The transforms that place this shape: the composition of the chain of
    /// [`ShapeKind::Transform`] nodes at its top (identity for none). A pattern painting the
    /// shape is laid in the space below them, so it moves with the shape however the
    /// transforms and the material are ordered (`sphere(1) at p with m` = `sphere(1) with m at p`).
    pub fn placement(&self) -> DAffine3 {
        match &self.kind {
            ShapeKind::Transform { child, xf } => *xf * child.placement(),
            ShapeKind::Primitive(_)
            | ShapeKind::Csg { .. }
            | ShapeKind::Round { .. }
            | ShapeKind::Shell { .. }
            | ShapeKind::Repeat { .. }
            | ShapeKind::Paint { .. }
            | ShapeKind::Field { .. }
            | ShapeKind::Warp { .. }
            | ShapeKind::Displace { .. } => DAffine3::IDENTITY,
        }
    }

    /// Whether the solid is convex, so a ray leaving its surface outward never meets it
    /// again. Conservative: `false` unless it follows from the shape's form (primitives
    /// other than the torus, a half-space, a field whose body is a convex function of
    /// the point by disciplined convex programming's composition rules, sharp
    /// intersections of convex solids, and rounding, painting or transforming one).
    pub fn is_convex(&self) -> bool {
        match &self.kind {
            ShapeKind::Primitive(p) => p.is_convex(),
            ShapeKind::Csg { op: CsgOp::Intersect, children, smooth } => {
                *smooth == 0.0 && children.iter().all(|c| c.is_convex())
            }
            ShapeKind::Csg { op: CsgOp::Union | CsgOp::Subtract, .. } => false,
            // Rounding grows the solid by a ball: still convex (its distance is exact or a
            // convex bound). An affine map keeps convexity; a material changes no shape.
            ShapeKind::Round { child, .. } | ShapeKind::Paint { child, .. } | ShapeKind::Transform { child, .. } => {
                child.is_convex()
            }
            // A field is when its body is a convex function of the point (cut to a box,
            // still convex).
            ShapeKind::Field { body, .. } => convex::is_convex(body),
            // A shell is hollow and repeated copies leave gaps between them; a warp or a
            // displacement may make any set at all.
            ShapeKind::Shell { .. }
            | ShapeKind::Repeat { .. }
            | ShapeKind::Warp { .. }
            | ShapeKind::Displace { .. } => false,
        }
    }

    /// Whether the shape's hull (`ir::shape_hull`) is the solid itself: a primitive
    /// whose hull is ([`crate::primitive::Solid::hull_is_solid`]), an extruded convex
    /// polygon or a revolved polygon that makes a convex solid, moved or painted.
    pub fn hull_is_solid(&self) -> bool {
        match &self.kind {
            ShapeKind::Primitive(p) => p.hull_is_solid(),
            ShapeKind::Paint { child, .. } | ShapeKind::Transform { child, .. } => child.hull_is_solid(),
            ShapeKind::Field { sweep: Some(Sweep::Extrude { region, .. }), .. } => region.is_convex_polygon(),
            ShapeKind::Field { sweep: Some(Sweep::Revolve { region }), .. } => region.revolves_convex(),
            // Hulls of operators and fields hold their solids; none is one.
            ShapeKind::Csg { .. }
            | ShapeKind::Round { .. }
            | ShapeKind::Shell { .. }
            | ShapeKind::Repeat { .. }
            | ShapeKind::Field { .. }
            | ShapeKind::Warp { .. }
            | ShapeKind::Displace { .. } => false,
        }
    }

    /// Whether the shape's distance bound is a convex function of the point with slope
    /// at most 1: the exact distance of a convex solid (a convex primitive whose distance
    /// is exact), rounded, painted, moved by an affine map (whose closure scales by the
    /// map's smallest stretch) or sharply intersected with others such. Along a curve
    /// through space such a distance is convex up to the curve's bending, which lets a
    /// twist or a bend of it be marched by a bound on that bending (`sdf::warp`).
    pub fn has_convex_distance(&self) -> bool {
        match &self.kind {
            ShapeKind::Primitive(p) => p.is_convex() && p.is_exact(),
            ShapeKind::Csg { op: CsgOp::Intersect, children, smooth } => {
                *smooth == 0.0 && children.iter().all(|c| c.has_convex_distance())
            }
            ShapeKind::Round { child, .. } | ShapeKind::Paint { child, .. } | ShapeKind::Transform { child, .. } => {
                child.has_convex_distance()
            }
            // A field's value is divided by an estimated slope, not a proven one.
            ShapeKind::Csg { .. }
            | ShapeKind::Shell { .. }
            | ShapeKind::Repeat { .. }
            | ShapeKind::Field { .. }
            | ShapeKind::Warp { .. }
            | ShapeKind::Displace { .. } => false,
        }
    }

    /// The node's children, in order (none for a primitive).
    pub fn children(&self) -> &[Arc<Shape>] {
        match &self.kind {
            // A field's shapes are inside its body ([`field::FieldExpr::shapes`]).
            ShapeKind::Primitive(_) | ShapeKind::Field { .. } => &[],
            ShapeKind::Csg { children, .. } => children,
            ShapeKind::Round { child, .. }
            | ShapeKind::Shell { child, .. }
            | ShapeKind::Repeat { child, .. }
            | ShapeKind::Transform { child, .. }
            | ShapeKind::Paint { child, .. }
            | ShapeKind::Warp { child, .. }
            | ShapeKind::Displace { child, .. } => std::slice::from_ref(child),
        }
    }
}

impl Body {
    /// Whether the object is convex as a solid (see [`Shape::is_convex`], [`Mesh::is_convex`]).
    pub fn is_convex(&self) -> bool {
        match self {
            Body::Shape(s) => s.is_convex(),
            Body::Mesh(m) => m.is_convex(),
        }
    }
}

impl Mesh {
    /// Whether the generator makes a convex polytope (a square counts: it lies in one
    /// plane); tested for every generator in `convex_generators_make_convex_polytopes`.
    pub fn is_convex(&self) -> bool {
        match self.source {
            MeshSource::UvSphere { .. }
            | MeshSource::IcoSphere { .. }
            | MeshSource::Box { .. }
            | MeshSource::Cylinder { .. }
            | MeshSource::Plane { .. } => true,
            // An isosurface may dent even a convex shape; a file may hold anything.
            MeshSource::Torus { .. } | MeshSource::Isosurface { .. } | MeshSource::File { .. } => false,
        }
    }
}

/// An explicit triangle mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// How the triangles are made.
    pub source: MeshSource,
    /// World-from-local transform.
    pub xf: DAffine3,
    /// Material, if one was given.
    pub material: Option<Arc<Material>>,
    /// Interpolate vertex normals instead of flat faces.
    pub smooth: bool,
    /// The `mesh` expression.
    pub span: Span,
}

/// Mesh generators.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshSource {
    /// UV sphere.
    UvSphere {
        /// Radius.
        radius: f64,
        /// Rings (latitude bands), ≥ 3.
        rings: u32,
        /// Segments (longitude), ≥ 3.
        segments: u32,
    },
    /// Subdivided icosahedron.
    IcoSphere {
        /// Radius.
        radius: f64,
        /// Subdivision steps.
        subdivisions: u32,
    },
    /// Box (12 triangles).
    Box {
        /// Half-extents.
        half: DVec3,
    },
    /// Capped cylinder along y.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Half-height.
        half_height: f64,
        /// Points per cap circle, ≥ 3.
        segments: u32,
    },
    /// Torus in the xz plane.
    Torus {
        /// Major radius.
        major: f64,
        /// Minor radius.
        minor: f64,
        /// Segments around the major circle.
        segments: u32,
        /// Sides around the tube.
        sides: u32,
    },
    /// A finite square in the xz plane.
    Plane {
        /// Half the side length.
        size: f64,
    },
    /// Any shape, triangulated.
    Isosurface {
        /// The shape.
        shape: Arc<Shape>,
        /// Cell size in world units.
        cell: f64,
    },
    /// A mesh file.
    File {
        /// The path resolved against the including file.
        path: PathBuf,
        /// The path as written.
        written: String,
    },
}
