//! The table of builtins: every function, shape, mesh generator, light and statement
//! argument list, with parameter names, types, defaults and a one-line doc. The checker,
//! the docs and (later) the editor tooling read this one table.

use std::fmt;

/// The types of the language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ty {
    /// A number.
    Num,
    /// A whole number.
    Int,
    /// `true` or `false`.
    Bool,
    /// A string.
    Str,
    /// `[x, y, z]`.
    Vec3,
    /// A number or a `vec3` (a number `k` means `[k, k, k]`).
    Size,
    /// `rgb(r, g, b)` or `#rrggbb`.
    Color,
    /// `material(…)`.
    Material,
    /// An SDF-able solid.
    Shape,
    /// A triangle mesh.
    Mesh,
    /// A light.
    Light,
    /// A list.
    List,
}

impl fmt::Display for Ty {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            Ty::Num => "num",
            Ty::Int => "int",
            Ty::Bool => "bool",
            Ty::Str => "string",
            Ty::Vec3 => "vec3",
            Ty::Size => "num or vec3",
            Ty::Color => "color",
            Ty::Material => "material",
            Ty::Shape => "shape",
            Ty::Mesh => "mesh",
            Ty::Light => "light",
            Ty::List => "list",
        };
        f.write_str(s)
    }
}

/// A parameter's default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Default {
    /// Must be given.
    Required,
    /// A number.
    Num(f64),
    /// A vector.
    Vec3([f64; 3]),
    /// A boolean.
    Bool(bool),
    /// A colour, 0–255.
    Color([f64; 3]),
    /// Absent means "derived from the other arguments" (documented per builtin).
    Derived,
}

/// One parameter.
#[derive(Clone, Copy, Debug)]
pub struct Param {
    /// Its name, for named arguments.
    pub name: &'static str,
    /// Its type.
    pub ty: Ty,
    /// Its default.
    pub default: Default,
}

/// Where a builtin may be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A function callable in expressions.
    Function,
    /// A generator after `mesh`.
    MeshGenerator,
    /// The argument list of the `camera` statement.
    Camera,
    /// The argument list of the `render` statement.
    Render,
}

/// A builtin.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// Its name.
    pub name: &'static str,
    /// Where it may be used.
    pub kind: Kind,
    /// Its parameters, in positional order.
    pub params: &'static [Param],
    /// For variadic builtins: the type of the extra positional arguments (before `params`).
    pub variadic: Option<Ty>,
    /// What it returns.
    pub result: Ty,
    /// One line for hover and docs.
    pub doc: &'static str,
}

impl Builtin {
    /// The signature as users read it, such as `sphere(r: num)` or `min(num…)`.
    pub fn signature(&self) -> String {
        let mut parts = Vec::new();
        if let Some(ty) = self.variadic {
            parts.push(format!("{ty}…"));
        }
        parts.extend(self.params.iter().map(Param::describe));
        format!("{}({})", self.name, parts.join(", "))
    }
}

impl Param {
    /// `name: type = default`, as in a signature.
    pub fn describe(&self) -> String {
        let default = match self.default {
            Default::Required => String::new(),
            Default::Num(x) => format!(" = {}", crate::ir::dump_num(x)),
            Default::Vec3(v) => format!(" = {}", crate::ir::dump_vec(v.into())),
            Default::Bool(b) => format!(" = {b}"),
            Default::Color(c) => format!(" = rgb({}, {}, {})", c[0], c[1], c[2]),
            Default::Derived => " = …".into(),
        };
        format!("{}: {}{default}", self.name, self.ty)
    }
}

const fn p(name: &'static str, ty: Ty, default: Default) -> Param {
    Param { name, ty, default }
}

const fn f(name: &'static str, params: &'static [Param], result: Ty, doc: &'static str) -> Builtin {
    Builtin { name, kind: Kind::Function, params, variadic: None, result, doc }
}

const fn variadic(name: &'static str, ty: Ty, params: &'static [Param], result: Ty, doc: &'static str) -> Builtin {
    Builtin { name, kind: Kind::Function, params, variadic: Some(ty), result, doc }
}

const fn gen(name: &'static str, params: &'static [Param], doc: &'static str) -> Builtin {
    Builtin { name, kind: Kind::MeshGenerator, params, variadic: None, result: Ty::Mesh, doc }
}

use self::Default::{Bool as B, Derived, Num as N, Required as Req, Vec3 as V};

const X: &[Param] = &[p("x", Ty::Num, Req)];

/// Every builtin function, mesh generator and statement argument list.
pub const BUILTINS: &[Builtin] = &[
    // Shapes.
    f("sphere", &[p("r", Ty::Num, Req)], Ty::Shape, "sphere of radius `r` centred at the origin"),
    f(
        "box",
        &[p("size", Ty::Size, Req)],
        Ty::Shape,
        "box with half-extents `size` (a number for a cube; `box(x, y, z)` also works)",
    ),
    f("cylinder", &[p("r", Ty::Num, Req), p("half_height", Ty::Num, Req)], Ty::Shape, "capped cylinder along y"),
    f("torus", &[p("major", Ty::Num, Req), p("minor", Ty::Num, Req)], Ty::Shape, "torus in the xz plane"),
    f(
        "plane",
        &[p("normal", Ty::Vec3, V([0.0, 1.0, 0.0])), p("offset", Ty::Num, N(0.0))],
        Ty::Shape,
        "the half-space below `normal·p = offset`",
    ),
    f(
        "capsule",
        &[p("r", Ty::Num, Req), p("half_height", Ty::Num, Req)],
        Ty::Shape,
        "capsule along y: a segment of half-length `half_height` thickened by `r`",
    ),
    f(
        "cone",
        &[p("r", Ty::Num, Req), p("half_height", Ty::Num, Req)],
        Ty::Shape,
        "capped cone along y with base radius `r`, apex up",
    ),
    // Operators and modifiers.
    variadic(
        "union",
        Ty::Shape,
        &[p("smooth", Ty::Num, N(0.0))],
        Ty::Shape,
        "everything inside any of the shapes; `smooth` blends the seams",
    ),
    variadic(
        "intersect",
        Ty::Shape,
        &[p("smooth", Ty::Num, N(0.0))],
        Ty::Shape,
        "only what is inside all of the shapes",
    ),
    variadic("subtract", Ty::Shape, &[p("smooth", Ty::Num, N(0.0))], Ty::Shape, "the first shape minus all the others"),
    f(
        "round",
        &[p("shape", Ty::Shape, Req), p("r", Ty::Num, Req)],
        Ty::Shape,
        "rounds edges by growing the shape by `r`",
    ),
    f(
        "shell",
        &[p("shape", Ty::Shape, Req), p("thickness", Ty::Num, Req)],
        Ty::Shape,
        "a hollow wall of `thickness` around the surface",
    ),
    f(
        "repeat",
        &[p("shape", Ty::Shape, Req), p("period", Ty::Size, Req), p("count", Ty::Size, Req)],
        Ty::Shape,
        "`count` copies per axis, `period` apart, centred at the origin",
    ),
    // Materials and colours.
    f(
        "material",
        &[
            p("color", Ty::Color, Default::Color([200.0, 200.0, 200.0])),
            p("specular", Ty::Num, N(-1.0)),
            p("reflective", Ty::Num, N(0.0)),
        ],
        Ty::Material,
        "surface: colour, Phong exponent (−1 = none), reflectivity in [0, 1]",
    ),
    f(
        "rgb",
        &[p("r", Ty::Num, Req), p("g", Ty::Num, Req), p("b", Ty::Num, Req)],
        Ty::Color,
        "a colour from 0–255 channels",
    ),
    // Lights.
    f("ambient", &[p("intensity", Ty::Num, Req)], Ty::Light, "light reaching every point equally"),
    f(
        "point",
        &[p("intensity", Ty::Num, Req), p("shadows", Ty::Bool, B(true)), p("radius", Ty::Num, N(0.0))],
        Ty::Light,
        "a point light, placed with `at`; `radius` > 0 gives soft shadows",
    ),
    f(
        "directional",
        &[p("intensity", Ty::Num, Req), p("towards", Ty::Vec3, Req), p("shadows", Ty::Bool, B(true))],
        Ty::Light,
        "a light at infinity, shining from direction `towards`",
    ),
    // Maths (angles in degrees).
    f("sin", X, Ty::Num, "sine of an angle in degrees"),
    f("cos", X, Ty::Num, "cosine of an angle in degrees"),
    f("tan", X, Ty::Num, "tangent of an angle in degrees"),
    f("sqrt", X, Ty::Num, "square root of a non-negative number"),
    f("abs", X, Ty::Num, "absolute value"),
    f("floor", X, Ty::Num, "largest whole number not above `x`"),
    variadic("min", Ty::Num, &[], Ty::Num, "smallest of the numbers"),
    variadic("max", Ty::Num, &[], Ty::Num, "largest of the numbers"),
    f("len", &[p("list", Ty::List, Req)], Ty::Int, "number of elements of a list"),
    // Mesh generators (after `mesh`).
    gen(
        "uvsphere",
        &[
            p("r", Ty::Num, N(1.0)),
            p("rings", Ty::Int, N(14.0)),
            p("segments", Ty::Int, Derived),
            p("smooth", Ty::Bool, B(false)),
        ],
        "UV sphere; `segments` defaults to 2 × `rings`",
    ),
    gen(
        "icosphere",
        &[p("r", Ty::Num, N(1.0)), p("subdivisions", Ty::Int, N(2.0)), p("smooth", Ty::Bool, B(false))],
        "subdivided icosahedron",
    ),
    gen(
        "box",
        &[p("size", Ty::Size, N(1.0)), p("smooth", Ty::Bool, B(false))],
        "box of 12 triangles with half-extents `size`",
    ),
    gen(
        "cylinder",
        &[
            p("r", Ty::Num, N(1.0)),
            p("half_height", Ty::Num, N(1.0)),
            p("segments", Ty::Int, N(32.0)),
            p("smooth", Ty::Bool, B(false)),
        ],
        "capped cylinder along y, `segments` points per cap",
    ),
    gen(
        "torus",
        &[
            p("major", Ty::Num, N(1.0)),
            p("minor", Ty::Num, N(0.25)),
            p("segments", Ty::Int, N(32.0)),
            p("sides", Ty::Int, N(16.0)),
            p("smooth", Ty::Bool, B(false)),
        ],
        "torus in the xz plane",
    ),
    gen(
        "plane",
        &[p("size", Ty::Num, N(10.0)), p("smooth", Ty::Bool, B(false))],
        "a square of half-side `size` in the xz plane, facing +y",
    ),
    gen(
        "isosurface",
        &[p("shape", Ty::Shape, Req), p("cell", Ty::Num, N(0.02)), p("smooth", Ty::Bool, B(false))],
        "any shape triangulated on a grid of `cell`-sized cells",
    ),
    gen(
        "file",
        &[p("path", Ty::Str, Req), p("smooth", Ty::Bool, B(false))],
        "a triangle mesh read from an OBJ file (relative to this file)",
    ),
    // Statements.
    Builtin {
        name: "camera",
        kind: Kind::Camera,
        params: &[
            p("position", Ty::Vec3, V([0.0, 0.0, 0.0])),
            p("look_at", Ty::Vec3, V([0.0, 0.0, 1.0])),
            p("up", Ty::Vec3, V([0.0, 1.0, 0.0])),
            p("fov", Ty::Num, N(crate::ir::SEED_FOV)),
        ],
        variadic: None,
        result: Ty::Num,
        doc: "the pinhole camera; `fov` is vertical, in degrees",
    },
    Builtin {
        name: "render",
        kind: Kind::Render,
        params: &[
            p("width", Ty::Int, N(500.0)),
            p("height", Ty::Int, N(500.0)),
            p("depth", Ty::Int, N(5.0)),
            p("background", Ty::Color, Default::Color([245.0, 245.0, 245.0])),
            p("epsilon", Ty::Num, N(1e-4)),
            p("max_steps", Ty::Int, N(512.0)),
            p("max_distance", Ty::Num, N(1000.0)),
            p("samples", Ty::Int, N(1.0)),
            p("ambient_occlusion", Ty::Num, N(0.0)),
        ],
        variadic: None,
        result: Ty::Num,
        doc: "image size, reflection depth, background, sphere-tracing accuracy, antialiasing and ambient-occlusion reach",
    },
];

/// Named constants.
pub const CONSTANTS: &[(&str, f64)] = &[("pi", std::f64::consts::PI)];

/// Looks a builtin up by name and kind.
pub fn lookup(name: &str, kind: Kind) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name && b.kind == kind)
}

/// Names of builtins of one kind (for suggestions).
pub fn names(kind: Kind) -> impl Iterator<Item = &'static str> {
    BUILTINS.iter().filter(move |b| b.kind == kind).map(|b| b.name)
}
