//! The table itself: every builtin's entry, and the named constants.

use super::{
    Builtin, Ctor, Default, Extreme, Gen, LightFn, MathFn, Modifier, NumFn, Param, PatternFn, Prim, Ty, VecFn,
};
use crate::ir::CsgOp;

const fn p(name: &'static str, ty: Ty, default: Default) -> Param {
    Param { name, ty, default }
}

const fn f(name: &'static str, ctor: Ctor, params: &'static [Param], result: Ty, doc: &'static str) -> Builtin {
    Builtin { name, ctor, params, variadic: None, result, doc }
}

const fn variadic(
    name: &'static str,
    ctor: Ctor,
    ty: Ty,
    params: &'static [Param],
    result: Ty,
    doc: &'static str,
) -> Builtin {
    Builtin { name, ctor, params, variadic: Some(ty), result, doc }
}

const fn gen(name: &'static str, g: Gen, params: &'static [Param], doc: &'static str) -> Builtin {
    Builtin { name, ctor: Ctor::Generator(g), params, variadic: None, result: Ty::Mesh, doc }
}

use Default::{Bool as B, Derived, Num as N, Required as Req, Vec3 as V};

const X: &[Param] = &[p("x", Ty::Num, Req)];

/// Every builtin function, mesh generator and statement argument list.
pub static BUILTINS: &[Builtin] = &[
    // Shapes.
    f(
        "sphere",
        Ctor::Primitive(Prim::Sphere),
        &[p("r", Ty::Num, Req)],
        Ty::Shape,
        "sphere of radius `r` centred at the origin",
    ),
    f(
        "box",
        Ctor::Primitive(Prim::Box),
        &[p("size", Ty::Size, Req)],
        Ty::Shape,
        "box with half-extents `size` (a number for a cube; `box(x, y, z)` also works)",
    ),
    f(
        "cylinder",
        Ctor::Primitive(Prim::Cylinder),
        &[p("r", Ty::Num, Req), p("half_height", Ty::Num, Req)],
        Ty::Shape,
        "capped cylinder along y",
    ),
    f(
        "torus",
        Ctor::Primitive(Prim::Torus),
        &[p("major", Ty::Num, Req), p("minor", Ty::Num, Req)],
        Ty::Shape,
        "torus in the xz plane",
    ),
    f(
        "plane",
        Ctor::Primitive(Prim::Plane),
        &[p("normal", Ty::Vec3, V([0.0, 1.0, 0.0])), p("offset", Ty::Num, N(0.0))],
        Ty::Shape,
        "the half-space below `normal·p = offset`",
    ),
    f(
        "capsule",
        Ctor::Primitive(Prim::Capsule),
        &[p("r", Ty::Num, Req), p("half_height", Ty::Num, Req)],
        Ty::Shape,
        "capsule along y: a segment of half-length `half_height` thickened by `r`",
    ),
    f(
        "cone",
        Ctor::Primitive(Prim::Cone),
        &[p("r", Ty::Num, Req), p("half_height", Ty::Num, Req)],
        Ty::Shape,
        "capped cone along y with base radius `r`, apex up",
    ),
    // Operators and modifiers.
    variadic(
        "union",
        Ctor::Csg(CsgOp::Union),
        Ty::Shape,
        &[p("smooth", Ty::Num, N(0.0))],
        Ty::Shape,
        "everything inside any of the shapes; `smooth` blends the seams",
    ),
    variadic(
        "intersect",
        Ctor::Csg(CsgOp::Intersect),
        Ty::Shape,
        &[p("smooth", Ty::Num, N(0.0))],
        Ty::Shape,
        "only what is inside all of the shapes",
    ),
    variadic(
        "subtract",
        Ctor::Csg(CsgOp::Subtract),
        Ty::Shape,
        &[p("smooth", Ty::Num, N(0.0))],
        Ty::Shape,
        "the first shape minus all the others",
    ),
    f(
        "round",
        Ctor::Modifier(Modifier::Round),
        &[p("shape", Ty::Shape, Req), p("r", Ty::Num, Req)],
        Ty::Shape,
        "rounds edges by growing the shape by `r`",
    ),
    f(
        "shell",
        Ctor::Modifier(Modifier::Shell),
        &[p("shape", Ty::Shape, Req), p("thickness", Ty::Num, Req)],
        Ty::Shape,
        "a hollow wall of `thickness` around the surface",
    ),
    f(
        "repeat",
        Ctor::Modifier(Modifier::Repeat),
        &[p("shape", Ty::Shape, Req), p("period", Ty::Size, Req), p("count", Ty::Size, Req)],
        Ty::Shape,
        "`count` copies per axis, `period` apart, centred at the origin",
    ),
    // Materials and colours.
    f(
        "material",
        Ctor::Material,
        &[
            p("color", Ty::Paint, Default::Color([200.0, 200.0, 200.0])),
            p("specular", Ty::Num, N(-1.0)),
            p("reflective", Ty::Num, N(0.0)),
            p("transparency", Ty::Num, N(0.0)),
            p("ior", Ty::Num, N(1.0)),
            p("absorption", Ty::Vec3, V([0.0, 0.0, 0.0])),
        ],
        Ty::Material,
        "surface: colour or pattern, Phong exponent (−1 = none), reflectivity in [0, 1]; light passing in \
         (`transparency` in [0, 1]), the medium's index of refraction and its absorption per unit length",
    ),
    f(
        "checker",
        Ctor::Pattern(PatternFn::Checker),
        &[p("a", Ty::Paint, Req), p("b", Ty::Paint, Req), p("size", Ty::Num, N(1.0))],
        Ty::Pattern,
        "cubes of edge `size` alternating `a` and `b`, in the painted object's space",
    ),
    f(
        "stripes",
        Ctor::Pattern(PatternFn::Stripes),
        &[
            p("a", Ty::Paint, Req),
            p("b", Ty::Paint, Req),
            p("width", Ty::Num, N(1.0)),
            p("axis", Ty::Vec3, V([1.0, 0.0, 0.0])),
        ],
        Ty::Pattern,
        "slabs `width` thick alternating `a` and `b` along `axis`, in the painted object's space",
    ),
    f(
        "gradient",
        Ctor::Pattern(PatternFn::Gradient),
        &[
            p("a", Ty::Paint, Req),
            p("b", Ty::Paint, Req),
            p("from", Ty::Vec3, V([0.0, 0.0, 0.0])),
            p("to", Ty::Vec3, V([0.0, 1.0, 0.0])),
        ],
        Ty::Pattern,
        "`a` at `from` blending linearly to `b` at `to`, in the painted object's space",
    ),
    f(
        "noise",
        Ctor::Pattern(PatternFn::Noise),
        &[p("a", Ty::Paint, Req), p("b", Ty::Paint, Req), p("size", Ty::Num, N(1.0)), p("seed", Ty::Int, N(0.0))],
        Ty::Pattern,
        "`a` and `b` mixed by Perlin gradient noise of feature size `size`, the same on every machine",
    ),
    f(
        "rgb",
        Ctor::Rgb,
        &[p("r", Ty::Num, Req), p("g", Ty::Num, Req), p("b", Ty::Num, Req)],
        Ty::Color,
        "a colour from 0–255 channels",
    ),
    // Lights.
    f(
        "ambient",
        Ctor::Light(LightFn::Ambient),
        &[p("intensity", Ty::Num, Req)],
        Ty::Light,
        "light reaching every point equally",
    ),
    f(
        "point",
        Ctor::Light(LightFn::Point),
        &[p("intensity", Ty::Num, Req), p("shadows", Ty::Bool, B(true)), p("radius", Ty::Num, N(0.0))],
        Ty::Light,
        "a point light, placed with `at`; `radius` > 0 gives soft shadows",
    ),
    f(
        "directional",
        Ctor::Light(LightFn::Directional),
        &[p("intensity", Ty::Num, Req), p("towards", Ty::Vec3, Req), p("shadows", Ty::Bool, B(true))],
        Ty::Light,
        "a light at infinity, shining from direction `towards`",
    ),
    // Maths (angles in degrees).
    f("sin", Ctor::Math(MathFn::Sin), X, Ty::Num, "sine of an angle in degrees"),
    f("cos", Ctor::Math(MathFn::Cos), X, Ty::Num, "cosine of an angle in degrees"),
    f("tan", Ctor::Math(MathFn::Tan), X, Ty::Num, "tangent of an angle in degrees"),
    f("sqrt", Ctor::Math(MathFn::Sqrt), X, Ty::Num, "square root of a non-negative number"),
    f("abs", Ctor::Math(MathFn::Abs), X, Ty::Num, "absolute value"),
    f("floor", Ctor::Math(MathFn::Floor), X, Ty::Num, "largest whole number not above `x`"),
    f("ceil", Ctor::Math(MathFn::Ceil), X, Ty::Num, "smallest whole number not below `x`"),
    f("sign", Ctor::Math(MathFn::Sign), X, Ty::Num, "-1, 0 or 1 as `x` is negative, zero or positive"),
    f(
        "random",
        Ctor::Math(MathFn::Random),
        &[p("seed", Ty::Num, Req)],
        Ty::Num,
        "a number in [0, 1) that depends only on `seed` (the same on every machine): `random(i * 7 + 3)`",
    ),
    f("exp", Ctor::Math(MathFn::Exp), X, Ty::Num, "e raised to `x`"),
    f("log", Ctor::Math(MathFn::Log), X, Ty::Num, "natural logarithm of a positive number"),
    f("asin", Ctor::Math(MathFn::Asin), X, Ty::Num, "arcsine in degrees, of a number in [-1, 1]"),
    f("acos", Ctor::Math(MathFn::Acos), X, Ty::Num, "arccosine in degrees, of a number in [-1, 1]"),
    f("atan", Ctor::Math(MathFn::Atan), X, Ty::Num, "arctangent in degrees"),
    // `round(x)` beside the shape modifier `round(shape, r)`: the first argument's type
    // chooses (see `overload`).
    f("round", Ctor::Math(MathFn::Round), X, Ty::Num, "nearest whole number, halves away from zero"),
    f(
        "pow",
        Ctor::Numeric(NumFn::Pow),
        &[p("x", Ty::Num, Req), p("y", Ty::Num, Req)],
        Ty::Num,
        "`x` raised to the power `y` (a whole `y` when `x` is negative)",
    ),
    f(
        "atan2",
        Ctor::Numeric(NumFn::Atan2),
        &[p("y", Ty::Num, Req), p("x", Ty::Num, Req)],
        Ty::Num,
        "angle in degrees, in (-180, 180], of the point (x, y) from the +x axis",
    ),
    f(
        "clamp",
        Ctor::Numeric(NumFn::Clamp),
        &[p("x", Ty::Num, Req), p("lo", Ty::Num, Req), p("hi", Ty::Num, Req)],
        Ty::Num,
        "`x` limited to [lo, hi]",
    ),
    f(
        "mix",
        Ctor::Numeric(NumFn::Mix),
        &[p("a", Ty::Linear, Req), p("b", Ty::Linear, Req), p("t", Ty::Num, Req)],
        Ty::Linear,
        "`a + (b - a) * t`: numbers, vectors or colours, `a` and `b` of one type",
    ),
    f(
        "hsv",
        Ctor::Numeric(NumFn::Hsv),
        &[p("h", Ty::Num, Req), p("s", Ty::Num, Req), p("v", Ty::Num, Req)],
        Ty::Color,
        "a colour from hue in degrees (0 red, 120 green, 240 blue), saturation and value in [0, 1]",
    ),
    f(
        "range",
        Ctor::Numeric(NumFn::Range),
        &[p("from", Ty::Num, Req), p("to", Ty::Num, Req), p("step", Ty::Num, N(1.0))],
        Ty::List,
        "the list of every `from + i * step` (i = 0, 1, …) before `to`: `range(0, 1, 0.25)` is [0, 0.25, 0.5, 0.75]",
    ),
    f(
        "sum",
        Ctor::Numeric(NumFn::Sum),
        &[p("list", Ty::List, Req)],
        Ty::Linear,
        "sum of a list of numbers, vectors or colours (0 for an empty list)",
    ),
    f("dot", Ctor::Vector(VecFn::Dot), &[p("a", Ty::Vec3, Req), p("b", Ty::Vec3, Req)], Ty::Num, "dot product"),
    f("cross", Ctor::Vector(VecFn::Cross), &[p("a", Ty::Vec3, Req), p("b", Ty::Vec3, Req)], Ty::Vec3, "cross product"),
    f(
        "normalize",
        Ctor::Vector(VecFn::Normalize),
        &[p("v", Ty::Vec3, Req)],
        Ty::Vec3,
        "`v` scaled to length 1 (not zero)",
    ),
    f("length", Ctor::Vector(VecFn::Length), &[p("v", Ty::Vec3, Req)], Ty::Num, "Euclidean length of a vector"),
    variadic("min", Ctor::Extreme(Extreme::Min), Ty::Num, &[], Ty::Num, "smallest of the numbers"),
    variadic("max", Ctor::Extreme(Extreme::Max), Ty::Num, &[], Ty::Num, "largest of the numbers"),
    f("len", Ctor::Len, &[p("list", Ty::List, Req)], Ty::Int, "number of elements of a list"),
    // Mesh generators (after `mesh`).
    gen(
        "uvsphere",
        Gen::UvSphere,
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
        Gen::IcoSphere,
        &[p("r", Ty::Num, N(1.0)), p("subdivisions", Ty::Int, N(2.0)), p("smooth", Ty::Bool, B(false))],
        "subdivided icosahedron",
    ),
    gen(
        "box",
        Gen::Box,
        &[p("size", Ty::Size, N(1.0)), p("smooth", Ty::Bool, B(false))],
        "box of 12 triangles with half-extents `size`",
    ),
    gen(
        "cylinder",
        Gen::Cylinder,
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
        Gen::Torus,
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
        Gen::Plane,
        &[p("size", Ty::Num, N(10.0)), p("smooth", Ty::Bool, B(false))],
        "a square of half-side `size` in the xz plane, facing +y",
    ),
    gen(
        "isosurface",
        Gen::Isosurface,
        &[p("shape", Ty::Shape, Req), p("cell", Ty::Num, N(0.02)), p("smooth", Ty::Bool, B(false))],
        "any shape triangulated on a grid of `cell`-sized cells",
    ),
    gen(
        "file",
        Gen::File,
        &[p("path", Ty::Str, Req), p("smooth", Ty::Bool, B(false))],
        "a triangle mesh read from an OBJ file (relative to this file)",
    ),
    // Statements.
    Builtin {
        name: "camera",
        ctor: Ctor::Camera,
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
        ctor: Ctor::Render,
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
            p("frames", Ty::Int, N(1.0)),
            p("fps", Ty::Num, N(24.0)),
            p("cyclic", Ty::Bool, Default::Bool(false)),
            p("color", Ty::Str, Default::Str("linear")),
        ],
        variadic: None,
        result: Ty::Num,
        doc:
            "image size, reflection depth, background, sphere-tracing accuracy, antialiasing, ambient-occlusion reach, \
              an animation's frame count, frame rate and whether it loops, and how colours are read and written \
              (`\"linear\"`, the study's, or `\"srgb\"`)",
    },
];

/// A name the language defines as a value: a mathematical constant or the animation's time.
#[derive(Debug)]
pub struct Constant {
    /// The name.
    pub name: &'static str,
    /// Its type.
    pub ty: Ty,
    /// Where its value comes from.
    pub value: ConstValue,
    /// One line for hover and the docs.
    pub doc: &'static str,
}

/// Where a [`Constant`]'s value comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConstValue {
    /// Always this number.
    Num(f64),
    /// The frame's `clock` (see [`Time`](crate::check::Time)).
    Clock,
    /// The frame's number.
    Frame,
}

/// Named constants, and the two names that change from frame to frame.
pub const CONSTANTS: &[Constant] = &[
    Constant { name: "pi", ty: Ty::Num, value: ConstValue::Num(std::f64::consts::PI), doc: "π, 3.14159…" },
    Constant {
        name: "clock",
        ty: Ty::Num,
        value: ConstValue::Clock,
        doc: "the animation's time: 0 at the first frame, 1 at the last (or one frame before the \
              first again with `render(cyclic = true)`); 0 in a still",
    },
    Constant {
        name: "frame",
        ty: Ty::Int,
        value: ConstValue::Frame,
        doc: "the number of the frame being rendered, from 0 to `frames` − 1; 0 in a still",
    },
];

/// The constant named `name`, if there is one.
pub fn constant(name: &str) -> Option<&'static Constant> {
    CONSTANTS.iter().find(|c| c.name == name)
}
