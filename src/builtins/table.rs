//! The table itself: every builtin's entry, and the named constants. Each entry's
//! parameters are declared once, with [`params!`](crate::params), beside the constructor
//! that reads them (primitives in [`crate::primitive`]).

use std::sync::LazyLock;

use super::construct::{CameraArgs, RenderStatementArgs};
use super::domain::{BendArgs, ElongateArgs, PolarArgs, SymmetricArgs, TwistArgs};
use super::fields::{DisplaceArgs, DistArgs, FieldArgs, Noise3Args, WarpArgs};
use super::maths::{
    Atan2Args, ClampArgs, HsvArgs, ListArgs, MixArgs, NumberArgs, PairArgs, PowArgs, RangeArgs, VectorArgs,
};
use super::meshes::{
    BoxMeshArgs, CylinderMeshArgs, FileArgs, IcoSphereArgs, IsosurfaceArgs, PlaneMeshArgs, TorusMeshArgs, UvSphereArgs,
};
use super::profiles::{
    CircleArgs, ExtrudeArgs, PolygonArgs, RectArgs, RevolveArgs, RoundProfileArgs, ShellProfileArgs,
};
use super::shapes::{CsgArgs, RepeatArgs, RoundArgs, ShellArgs};
use super::values::{
    AmbientArgs, AreaArgs, CheckerArgs, DirectionalArgs, EnvironmentArgs, GradientArgs, MaterialArgs, NoiseArgs,
    PointArgs, RgbArgs, StripesArgs,
};
use super::{Builtin, Ctor, Extreme, FieldFn, Gen, LightFn, MathFn, Modifier, NumFn, PatternFn, ProfileFn, Ty, VecFn};
use crate::ir::field::Unary;
use crate::ir::CsgOp;
use crate::primitive::PRIMITIVES;
use crate::sig::Param;

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

/// Every builtin function, mesh generator and statement argument list: the primitives
/// (from their definitions), then every other builtin.
pub static BUILTINS: LazyLock<Vec<Builtin>> = LazyLock::new(|| {
    let primitives = PRIMITIVES.iter().map(|e| f(e.name, Ctor::Primitive(e), e.params, Ty::Shape, e.doc));
    primitives.chain(REST.iter().copied()).collect()
});

/// Every builtin but the primitives.
static REST: &[Builtin] = &[
    // Operators and modifiers.
    variadic(
        "union",
        Ctor::Csg(CsgOp::Union),
        Ty::Shape,
        CsgArgs::PARAMS,
        Ty::Shape,
        "everything inside any of the shapes; `smooth` blends the seams",
    ),
    variadic(
        "intersect",
        Ctor::Csg(CsgOp::Intersect),
        Ty::Shape,
        CsgArgs::PARAMS,
        Ty::Shape,
        "only what is inside all of the shapes",
    ),
    variadic(
        "subtract",
        Ctor::Csg(CsgOp::Subtract),
        Ty::Shape,
        CsgArgs::PARAMS,
        Ty::Shape,
        "the first shape minus all the others (smooth: the cutters blend nearest first, in any order written)",
    ),
    f(
        "round",
        Ctor::Modifier(Modifier::Round),
        RoundArgs::PARAMS,
        Ty::Shape,
        "rounds edges by growing the shape by `r`",
    ),
    f(
        "shell",
        Ctor::Modifier(Modifier::Shell),
        ShellArgs::PARAMS,
        Ty::Shape,
        "a hollow wall of `thickness` around the surface",
    ),
    f(
        "repeat",
        Ctor::Modifier(Modifier::Repeat),
        RepeatArgs::PARAMS,
        Ty::Shape,
        "`count` copies per axis, `period` apart, centred at the origin",
    ),
    // Fields.
    f(
        "field",
        Ctor::Field(FieldFn::Field),
        FieldArgs::PARAMS,
        Ty::Shape,
        "any function of the point as a shape: inside where `f` is negative (docs/fields.md)",
    ),
    f(
        "warp",
        Ctor::Field(FieldFn::Warp),
        WarpArgs::PARAMS,
        Ty::Shape,
        "the shape deformed: at each point `p` it is what the shape is at `f(p)` (a twist, a bend)",
    ),
    f(
        "displace",
        Ctor::Field(FieldFn::Displace),
        DisplaceArgs::PARAMS,
        Ty::Shape,
        "the shape's distance plus `f(p)`: bumps, ripples, noise on its surface",
    ),
    // Domain operations (warps with their maps and bounds written for you).
    f(
        "twist",
        Ctor::Field(FieldFn::Twist),
        TwistArgs::PARAMS,
        Ty::Shape,
        "the shape twisted about `y`: the slice at height `y` turned `degrees_per_unit * y` as `rotate [0, a, 0]` turns",
    ),
    f(
        "bend",
        Ctor::Field(FieldFn::Bend),
        BendArgs::PARAMS,
        Ty::Shape,
        "the shape's `y` axis bent towards `+x` by `degrees_per_unit` per unit of height",
    ),
    f(
        "elongate",
        Ctor::Field(FieldFn::Elongate),
        ElongateArgs::PARAMS,
        Ty::Shape,
        "the shape cut at its centre planes and pulled apart by a slab `2 * by` thick (exact)",
    ),
    f(
        "symmetric",
        Ctor::Field(FieldFn::Symmetric),
        SymmetricArgs::PARAMS,
        Ty::Shape,
        "the shape's half on the positive side of each of `axes` mirrored onto the negative side (exact)",
    ),
    f(
        "polar",
        Ctor::Field(FieldFn::Polar),
        PolarArgs::PARAMS,
        Ty::Shape,
        "`count` copies of the shape about `y`, `360 / count` degrees apart, the shape itself the one on `+x`",
    ),
    // Profiles and sweeps.
    variadic(
        "union",
        Ctor::Profile(ProfileFn::Csg(CsgOp::Union)),
        Ty::Profile,
        CsgArgs::PARAMS,
        Ty::Profile,
        "everything inside any of the profiles; `smooth` blends the seams",
    ),
    variadic(
        "intersect",
        Ctor::Profile(ProfileFn::Csg(CsgOp::Intersect)),
        Ty::Profile,
        CsgArgs::PARAMS,
        Ty::Profile,
        "only what is inside all of the profiles",
    ),
    variadic(
        "subtract",
        Ctor::Profile(ProfileFn::Csg(CsgOp::Subtract)),
        Ty::Profile,
        CsgArgs::PARAMS,
        Ty::Profile,
        "the first profile minus all the others (a hole through an extrusion)",
    ),
    f("circle", Ctor::Profile(ProfileFn::Circle), CircleArgs::PARAMS, Ty::Profile, "a disc of radius `r` about the origin of the `[u, v]` plane"),
    f("rect", Ctor::Profile(ProfileFn::Rect), RectArgs::PARAMS, Ty::Profile, "a rectangle `2 * half_u` by `2 * half_v` about the origin of the `[u, v]` plane"),
    f(
        "polygon",
        Ctor::Profile(ProfileFn::Polygon),
        PolygonArgs::PARAMS,
        Ty::Profile,
        "a simple polygon through `points`, either winding, with an exact signed distance",
    ),
    f(
        "text",
        Ctor::Profile(ProfileFn::Text),
        super::text::TextArgs::PARAMS,
        Ty::Profile,
        "glyphs of `string` in the bundled DejaVu Sans or a `font` file, the em `size` across, the first glyph at `u = 0` on the baseline `v = 0`, with an exact signed distance",
    ),
    f(
        "round",
        Ctor::Profile(ProfileFn::Round),
        RoundProfileArgs::PARAMS,
        Ty::Profile,
        "rounds a profile's corners by growing it by `r`",
    ),
    f(
        "shell",
        Ctor::Profile(ProfileFn::Shell),
        ShellProfileArgs::PARAMS,
        Ty::Profile,
        "a profile's outline, `thickness` wide, centred on its edge",
    ),
    f(
        "extrude",
        Ctor::Profile(ProfileFn::Extrude),
        ExtrudeArgs::PARAMS,
        Ty::Shape,
        "the profile's `[u, v]` as `x` and `z`, extruded along `y` from `-half_height` to `half_height` (POV-Ray's prism)",
    ),
    f(
        "revolve",
        Ctor::Profile(ProfileFn::Revolve),
        RevolveArgs::PARAMS,
        Ty::Shape,
        "the profile's `[u, v]` as radius and height, revolved about `y` (POV-Ray's lathe); parts at `u < 0` are clipped",
    ),
    f("dist", Ctor::Dist, DistArgs::PARAMS, Ty::Num, "inside a field's body, the shape's signed distance at `q`"),
    f(
        "noise3",
        Ctor::Noise3,
        Noise3Args::PARAMS,
        Ty::Num,
        "Perlin gradient noise at `q` (the `noise` pattern's), about −1 to 1, features `size` across",
    ),
    // Materials and colours.
    f(
        "material",
        Ctor::Material,
        MaterialArgs::PARAMS,
        Ty::Material,
        "surface: colour or pattern, Phong exponent (−1 = none), reflectivity in [0, 1]; light passing in \
         (`transparency` in [0, 1]), the medium's index of refraction and its absorption per unit length",
    ),
    f(
        "checker",
        Ctor::Pattern(PatternFn::Checker),
        CheckerArgs::PARAMS,
        Ty::Pattern,
        "cubes of edge `size` alternating `a` and `b`, in the painted object's space",
    ),
    f(
        "stripes",
        Ctor::Pattern(PatternFn::Stripes),
        StripesArgs::PARAMS,
        Ty::Pattern,
        "slabs `width` thick alternating `a` and `b` along `axis`, in the painted object's space",
    ),
    f(
        "gradient",
        Ctor::Pattern(PatternFn::Gradient),
        GradientArgs::PARAMS,
        Ty::Pattern,
        "`a` at `from` blending linearly to `b` at `to`, in the painted object's space",
    ),
    f(
        "noise",
        Ctor::Pattern(PatternFn::Noise),
        NoiseArgs::PARAMS,
        Ty::Pattern,
        "`a` and `b` mixed by Perlin gradient noise of feature size `size`, the same on every machine",
    ),
    f("rgb", Ctor::Rgb, RgbArgs::PARAMS, Ty::Color, "a colour from 0–255 channels"),
    // Lights.
    f("ambient", Ctor::Light(LightFn::Ambient), AmbientArgs::PARAMS, Ty::Light, "light reaching every point equally"),
    f(
        "point",
        Ctor::Light(LightFn::Point),
        PointArgs::PARAMS,
        Ty::Light,
        "a point light, placed with `at`; `radius` > 0 gives soft shadows",
    ),
    f(
        "directional",
        Ctor::Light(LightFn::Directional),
        DirectionalArgs::PARAMS,
        Ty::Light,
        "a light at infinity, shining from direction `towards`",
    ),
    f(
        "area",
        Ctor::Light(LightFn::Area),
        AreaArgs::PARAMS,
        Ty::Light,
        "a `size` rectangle of light facing -y, placed with `at` and `rotate`; it lights the scene by light transport",
    ),
    f(
        "environment",
        Ctor::Light(LightFn::Environment),
        EnvironmentArgs::PARAMS,
        Ty::Light,
        "light of radiance `intensity` arriving from every direction; it lights the scene by light transport",
    ),
    // Maths (angles in degrees). A function of one number checks its argument against
    // its declaration's range: `sqrt`'s, `log`'s and `asin`'s are their domains.
    f("sin", Ctor::Math(MathFn::Unary(Unary::Sin)), NumberArgs::ANY, Ty::Num, "sine of an angle in degrees"),
    f("cos", Ctor::Math(MathFn::Unary(Unary::Cos)), NumberArgs::ANY, Ty::Num, "cosine of an angle in degrees"),
    f("tan", Ctor::Math(MathFn::Unary(Unary::Tan)), NumberArgs::ANY, Ty::Num, "tangent of an angle in degrees"),
    f("sqrt", Ctor::Math(MathFn::Unary(Unary::Sqrt)), NumberArgs::NONNEG, Ty::Num, "square root of a non-negative number"),
    f("abs", Ctor::Math(MathFn::Unary(Unary::Abs)), NumberArgs::ANY, Ty::Num, "absolute value"),
    f("floor", Ctor::Math(MathFn::Unary(Unary::Floor)), NumberArgs::ANY, Ty::Num, "largest whole number not above `x`"),
    f("ceil", Ctor::Math(MathFn::Unary(Unary::Ceil)), NumberArgs::ANY, Ty::Num, "smallest whole number not below `x`"),
    f("sign", Ctor::Math(MathFn::Unary(Unary::Sign)), NumberArgs::ANY, Ty::Num, "-1, 0 or 1 as `x` is negative, zero or positive"),
    f(
        "random",
        Ctor::Math(MathFn::Random),
        NumberArgs::SEED,
        Ty::Num,
        "a number in [0, 1) that depends only on `seed` (the same on every machine): `random(i * 7 + 3)`",
    ),
    f("exp", Ctor::Math(MathFn::Unary(Unary::Exp)), NumberArgs::ANY, Ty::Num, "e raised to `x`"),
    f("log", Ctor::Math(MathFn::Unary(Unary::Log)), NumberArgs::POSITIVE, Ty::Num, "natural logarithm of a positive number"),
    f("asin", Ctor::Math(MathFn::Unary(Unary::Asin)), NumberArgs::UNIT, Ty::Num, "arcsine in degrees, of a number in [-1, 1]"),
    f("acos", Ctor::Math(MathFn::Unary(Unary::Acos)), NumberArgs::UNIT, Ty::Num, "arccosine in degrees, of a number in [-1, 1]"),
    f("atan", Ctor::Math(MathFn::Unary(Unary::Atan)), NumberArgs::ANY, Ty::Num, "arctangent in degrees"),
    // `round(x)` beside the shape modifier `round(shape, r)`: the first argument's type
    // chooses (see `overload`).
    f("round", Ctor::Math(MathFn::Unary(Unary::Round)), NumberArgs::ANY, Ty::Num, "nearest whole number, halves away from zero"),
    f("fract", Ctor::Math(MathFn::Unary(Unary::Fract)), NumberArgs::ANY, Ty::Num, "`x - floor(x)`, in [0, 1): repeats every 1"),
    f(
        "pow",
        Ctor::Numeric(NumFn::Pow),
        PowArgs::PARAMS,
        Ty::Num,
        "`x` raised to the power `y` (a whole `y` when `x` is negative)",
    ),
    f(
        "atan2",
        Ctor::Numeric(NumFn::Atan2),
        Atan2Args::PARAMS,
        Ty::Num,
        "angle in degrees, in (-180, 180], of the point (x, y) from the +x axis",
    ),
    f("clamp", Ctor::Numeric(NumFn::Clamp), ClampArgs::PARAMS, Ty::Num, "`x` limited to [lo, hi]"),
    f(
        "mix",
        Ctor::Numeric(NumFn::Mix),
        MixArgs::PARAMS,
        Ty::Linear,
        "`a + (b - a) * t`: numbers, vectors or colours, `a` and `b` of one type",
    ),
    f(
        "hsv",
        Ctor::Numeric(NumFn::Hsv),
        HsvArgs::PARAMS,
        Ty::Color,
        "a colour from hue in degrees (0 red, 120 green, 240 blue), saturation and value in [0, 1]",
    ),
    f(
        "range",
        Ctor::Numeric(NumFn::Range),
        RangeArgs::PARAMS,
        Ty::List,
        "the list of every `from + i * step` (i = 0, 1, …) before `to`: `range(0, 1, 0.25)` is [0, 0.25, 0.5, 0.75]",
    ),
    f(
        "sum",
        Ctor::Numeric(NumFn::Sum),
        ListArgs::PARAMS,
        Ty::Linear,
        "sum of a list of numbers, vectors or colours (0 for an empty list)",
    ),
    f("dot", Ctor::Vector(VecFn::Dot), PairArgs::PARAMS, Ty::Num, "dot product"),
    f("cross", Ctor::Vector(VecFn::Cross), PairArgs::PARAMS, Ty::Vec3, "cross product"),
    f("normalize", Ctor::Vector(VecFn::Normalize), VectorArgs::NONZERO, Ty::Vec3, "`v` scaled to length 1 (not zero)"),
    f("length", Ctor::Vector(VecFn::Length), VectorArgs::ANY, Ty::Num, "Euclidean length of a vector"),
    variadic("min", Ctor::Extreme(Extreme::Min), Ty::Num, &[], Ty::Num, "smallest of the numbers"),
    variadic("max", Ctor::Extreme(Extreme::Max), Ty::Num, &[], Ty::Num, "largest of the numbers"),
    f("len", Ctor::Len, ListArgs::PARAMS, Ty::Int, "number of elements of a list"),
    // Mesh generators (after `mesh`).
    gen("uvsphere", Gen::UvSphere, UvSphereArgs::PARAMS, "UV sphere; `segments` defaults to 2 × `rings`"),
    gen("icosphere", Gen::IcoSphere, IcoSphereArgs::PARAMS, "subdivided icosahedron"),
    gen("box", Gen::Box, BoxMeshArgs::PARAMS, "box of 12 triangles with half-extents `size`"),
    gen("cylinder", Gen::Cylinder, CylinderMeshArgs::PARAMS, "capped cylinder along y, `segments` points per cap"),
    gen("torus", Gen::Torus, TorusMeshArgs::PARAMS, "torus in the xz plane"),
    gen("plane", Gen::Plane, PlaneMeshArgs::PARAMS, "a square of half-side `size` in the xz plane, facing +y"),
    gen(
        "isosurface",
        Gen::Isosurface,
        IsosurfaceArgs::PARAMS,
        "any shape triangulated on a grid of `cell`-sized cells",
    ),
    gen("file", Gen::File, FileArgs::PARAMS, "a triangle mesh read from an OBJ file, or by extension an STL (`.stl`, z up, mm), PLY (`.ply`), binary glTF (`.glb`), 3MF (`.3mf`, z up, in its declared unit) or OFF (`.off`, z up, mm) file, relative to this file"),
    // Statements.
    Builtin {
        name: "camera",
        ctor: Ctor::Camera,
        params: CameraArgs::PARAMS,
        variadic: None,
        result: Ty::Num,
        doc: "the pinhole camera; `fov` is vertical, in degrees",
    },
    Builtin {
        name: "render",
        ctor: Ctor::Render,
        params: RenderStatementArgs::PARAMS,
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
    /// The frame's `clock` (see the checker's `Time`).
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
