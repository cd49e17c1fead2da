//! The builtins: every function, shape, mesh generator, light and statement argument
//! list, with parameter names, types, defaults and a one-line doc, in one table
//! (`table`, with the named constants), and beside each family's declarations the
//! constructors that build its values (one file per family: maths, shapes, fields,
//! domain, profiles, meshes, values). Here are the table's types and lookups, the
//! [`Host`] a constructor asks of the evaluator, and the bound arguments it reads.
//! The checker, the docs and the editor tooling read this one table.

use std::collections::HashMap;
use std::path::Path;
use std::sync::OnceLock;

use foldhash::fast::FixedState;

use crate::diag::Diagnostic;
use crate::ir::CsgOp;
pub use crate::sig::{Default, Param, Range, Ty};
use crate::span::Span;

mod construct;
pub(crate) mod domain;
pub(crate) mod fields;
pub(crate) mod maths;
pub(crate) mod meshes;
pub(crate) mod profiles;
mod reference;
pub(crate) mod shapes;
mod table;
pub(crate) mod text;
mod value;
pub(crate) mod values;
pub use construct::{
    CameraArgs, RenderStatementArgs, EPSILON_RANGE, MAX_DEPTH, MAX_FPS, MAX_FRAMES, MAX_GENERATED_TRIANGLES,
    MAX_IMAGE_SIDE, MAX_LIST, MAX_MESH_RESOLUTION, MAX_OBJECTS, MAX_PIXELS, MAX_REACH, MAX_REPEAT, MAX_SAMPLES,
    MAX_SHAPE_NODES, MAX_STEPS, MIN_EPSILON,
};
pub use reference::reference;
pub use table::{constant, ConstValue, Constant, BUILTINS, CONSTANTS};
pub use value::{FieldLit, Profile, Value};

/// What a constructor asks of the evaluator calling it: to report, to spend fuel, and
/// two facts about where the call is. The constructors are methods of `dyn Host`, so
/// this room does not depend on the checker that implements it.
pub trait Host {
    /// Reports a diagnostic.
    fn report(&mut self, d: Diagnostic);
    /// Spends `steps` of the compile's fuel for work at `span`; `false` once it is out
    /// (reported) or the compile is no longer wanted.
    fn burn(&mut self, steps: u64, span: Span) -> bool;
    /// Whether the call is inside a field's body (`p => …`), where there is a point.
    fn in_field_body(&self) -> bool;
    /// The directory of the file being evaluated: a mesh file's path is relative to it.
    fn file_dir(&self) -> &Path;
    /// The bytes of a file (a font) the scene names, at most `limit` of them.
    fn read_file(&self, path: &Path, limit: u64) -> std::io::Result<Vec<u8>>;
}

/// Arguments bound to a builtin's parameters, after arity, name and type checks.
pub struct BoundArgs {
    /// The builtin's parameters, for the defaults of the slots not given.
    pub params: &'static [crate::sig::Param],
    /// One slot per parameter: the value and the span to blame for it.
    pub vals: Vec<Option<(Value, Span)>>,
    /// Variadic positional arguments.
    pub rest: Vec<(Value, Span)>,
    /// The whole call.
    pub call: Span,
}

/// The unit vector along `v`, or `None` for a zero or non-finite vector. Scaled by its
/// largest component first, as `hypot` does, so `[1e200, 1e200, 0]` (whose `x·x`
/// overflows) and `[1e-200, 0, 0]` (whose `x·x` underflows) have directions.
pub(crate) fn direction(v: glam::DVec3) -> Option<glam::DVec3> {
    let big = v.abs().max_element();
    if !big.is_finite() || big == 0.0 {
        return None;
    }
    let n = (v / big).try_normalize()?;
    n.is_finite().then_some(n)
}

/// The length of `v` without overflow or underflow in its squares (as `hypot`).
pub(crate) fn length(v: glam::DVec3) -> f64 {
    let big = v.abs().max_element();
    if big == 0.0 || !big.is_finite() {
        return big;
    }
    big * (v / big).length()
}

/// Where a builtin may be used (follows from its [`Ctor`]).
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

impl Kind {
    /// How many kinds there are (`Render` is the last).
    const COUNT: usize = Kind::Render as usize + 1;
}

/// What a builtin makes: the checker's constructors match on it exhaustively, so an
/// entry of [`BUILTINS`] cannot lack a constructor, nor a constructor its entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ctor {
    /// A primitive shape (its definition: [`crate::primitive`]).
    Primitive(&'static crate::primitive::Entry),
    /// A CSG operator.
    Csg(CsgOp),
    /// A shape modifier.
    Modifier(Modifier),
    /// A shape from a field literal.
    Field(FieldFn),
    /// A 2D profile, or a sweep of one into a shape.
    Profile(ProfileFn),
    /// `dist(shape, q)`, inside a field's body.
    Dist,
    /// `noise3(q, size, seed)`.
    Noise3,
    /// `material(…)`.
    Material,
    /// `rgb(…)`.
    Rgb,
    /// A pattern.
    Pattern(PatternFn),
    /// A light.
    Light(LightFn),
    /// A function of one number.
    Math(MathFn),
    /// Another function of numbers (several, or giving a list or colour).
    Numeric(NumFn),
    /// A function of vectors.
    Vector(VecFn),
    /// `min` or `max` of numbers.
    Extreme(Extreme),
    /// `len(list)`.
    Len,
    /// A mesh generator.
    Generator(Gen),
    /// The `camera` statement's arguments.
    Camera,
    /// The `render` statement's arguments.
    Render,
}

/// Whether a builtin takes numbers and vectors that vary with a field's point (inside
/// `p => …`), declared for every builtin by [`Ctor::in_fields`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InFields {
    /// It does, in this form.
    Yes(FieldForm),
    /// A function of numbers that does not, for this reason (the error says it).
    No(&'static str),
    /// Not a function of numbers (a shape, a light, a setting, a list's length): its
    /// arguments' types refuse a value that varies with the point, or ignore it.
    NotMaths,
}

/// What a function of numbers becomes in a field's body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FieldForm {
    /// A function of one operand.
    Unary(crate::ir::field::Unary),
    /// A function of two operands, the first two arguments.
    Binary(crate::ir::field::Binary),
    /// `clamp(x, lo, hi)`: `min(max(x, lo), hi)`.
    Clamp,
    /// `mix(a, b, t)`: `a + (b − a)·t`.
    Mix,
    /// `sum(list)`: the items added.
    Sum,
    /// `min` or `max` of any number of operands, folded by this function.
    Fold(crate::ir::field::Binary),
    /// `dist(shape, q)`.
    Dist,
    /// `noise3(q, size, seed)`.
    Noise3,
}

impl Ctor {
    /// Whether the builtin has a form in fields. Every kind of builtin is listed: a new
    /// one must say, or this does not compile.
    pub fn in_fields(&self) -> InFields {
        use crate::ir::field::{Binary, Unary};
        let yes = InFields::Yes;
        match *self {
            Ctor::Math(MathFn::Unary(u)) => yes(FieldForm::Unary(u)),
            Ctor::Math(MathFn::Random) => InFields::No("`random`'s seed cannot depend on a field's point"),
            Ctor::Numeric(NumFn::Pow) => yes(FieldForm::Binary(Binary::Pow)),
            Ctor::Numeric(NumFn::Atan2) => yes(FieldForm::Binary(Binary::Atan2)),
            Ctor::Numeric(NumFn::Clamp) => yes(FieldForm::Clamp),
            Ctor::Numeric(NumFn::Mix) => yes(FieldForm::Mix),
            Ctor::Numeric(NumFn::Sum) => yes(FieldForm::Sum),
            Ctor::Numeric(NumFn::Hsv) => InFields::No("`hsv` gives a colour, which a field's body does not hold"),
            Ctor::Numeric(NumFn::Range) => {
                InFields::No("`range` gives a list, whose length cannot vary with the point")
            }
            Ctor::Vector(VecFn::Dot) => yes(FieldForm::Binary(Binary::Dot)),
            Ctor::Vector(VecFn::Cross) => yes(FieldForm::Binary(Binary::Cross)),
            Ctor::Vector(VecFn::Length) => yes(FieldForm::Unary(Unary::Length)),
            Ctor::Vector(VecFn::Normalize) => yes(FieldForm::Unary(Unary::Normalize)),
            Ctor::Extreme(Extreme::Min) => yes(FieldForm::Fold(Binary::Min)),
            Ctor::Extreme(Extreme::Max) => yes(FieldForm::Fold(Binary::Max)),
            Ctor::Dist => yes(FieldForm::Dist),
            Ctor::Noise3 => yes(FieldForm::Noise3),
            Ctor::Primitive(_)
            | Ctor::Csg(_)
            | Ctor::Modifier(_)
            | Ctor::Field(_)
            | Ctor::Profile(_)
            | Ctor::Material
            | Ctor::Rgb
            | Ctor::Pattern(_)
            | Ctor::Light(_)
            | Ctor::Len
            | Ctor::Generator(_)
            | Ctor::Camera
            | Ctor::Render => InFields::NotMaths,
        }
    }
}

/// The shape modifiers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the builtin of the same name, documented in BUILTINS")]
pub enum Modifier {
    Round,
    Shell,
    Repeat,
}

/// The shapes made from field literals.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the builtin of the same name, documented in BUILTINS")]
pub enum FieldFn {
    Field,
    Warp,
    Displace,
    Twist,
    Bend,
    Elongate,
    Symmetric,
    Polar,
}

/// The profiles and sweeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the builtin of the same name, documented in BUILTINS")]
pub enum ProfileFn {
    Csg(CsgOp),
    Circle,
    Rect,
    Polygon,
    Round,
    Shell,
    Extrude,
    Revolve,
    Text,
}

/// The patterns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the builtin of the same name, documented in BUILTINS")]
pub enum PatternFn {
    Checker,
    Stripes,
    Gradient,
    Noise,
}

/// The lights.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the builtin of the same name, documented in BUILTINS")]
pub enum LightFn {
    Ambient,
    Point,
    Directional,
    Area,
    Environment,
}

/// Functions of one number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the builtin of the same name, documented in BUILTINS")]
pub enum MathFn {
    /// A function the IR's field expressions hold too: evaluated, at check time and in
    /// a field alike, by [`Unary::apply`](crate::ir::field::Unary::apply).
    Unary(crate::ir::field::Unary),
    /// `random(seed)`, which is not in fields (its seed cannot vary with the point).
    Random,
}

/// Functions of several numbers, or giving a list or a colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the builtin of the same name, documented in BUILTINS")]
pub enum NumFn {
    Pow,
    Atan2,
    Clamp,
    Mix,
    Hsv,
    Range,
    Sum,
}

/// Functions of vectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the builtin of the same name, documented in BUILTINS")]
pub enum VecFn {
    Dot,
    Cross,
    Normalize,
    Length,
}

/// `min` and `max`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the builtin of the same name, documented in BUILTINS")]
pub enum Extreme {
    Min,
    Max,
}

/// The mesh generators, one variant per entry of [`BUILTINS`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs, reason = "each variant is the generator of the same name, documented in BUILTINS")]
pub enum Gen {
    UvSphere,
    IcoSphere,
    Box,
    Cylinder,
    Torus,
    Plane,
    Isosurface,
    File,
}

/// A builtin.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// Its name.
    pub name: &'static str,
    /// What it makes, and so where it may be used.
    pub ctor: Ctor,
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
    /// Where it may be used.
    pub fn kind(&self) -> Kind {
        match self.ctor {
            Ctor::Primitive(_)
            | Ctor::Csg(_)
            | Ctor::Modifier(_)
            | Ctor::Material
            | Ctor::Rgb
            | Ctor::Pattern(_)
            | Ctor::Light(_)
            | Ctor::Math(_)
            | Ctor::Numeric(_)
            | Ctor::Vector(_)
            | Ctor::Extreme(_)
            | Ctor::Field(_)
            | Ctor::Profile(_)
            | Ctor::Dist
            | Ctor::Noise3
            | Ctor::Len => Kind::Function,
            Ctor::Generator(_) => Kind::MeshGenerator,
            Ctor::Camera => Kind::Camera,
            Ctor::Render => Kind::Render,
        }
    }

    /// Its doc, then each parameter with its own doc and range, as Markdown: what hover
    /// and the reference show.
    pub fn explained(&self) -> String {
        let mut out = self.doc.to_string();
        for p in self.params {
            out.push_str(&format!("\n- `{}`: {}", p.name, p.explain()));
        }
        out
    }

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

/// The entries of each name, by kind (in [`Kind`]'s order), in table order.
type Index = HashMap<&'static str, [Vec<&'static Builtin>; Kind::COUNT], FixedState>;

/// Builtins by name and kind, built once: a generated scene calls builtins for every
/// part it makes, and scanning the table by name for each call (and again for its
/// overloads) was the largest single cost of evaluating
/// `benches/scenes/union-10000.scn` (`perf record scnc check …`).
fn index() -> &'static Index {
    static INDEX: OnceLock<Index> = OnceLock::new();
    INDEX.get_or_init(|| {
        let mut index = Index::default();
        for b in BUILTINS.iter() {
            index.entry(b.name).or_default()[b.kind() as usize].push(b);
        }
        index
    })
}

/// Looks a builtin up by name and kind (the first entry of that name and kind).
pub fn lookup(name: &str, kind: Kind) -> Option<&'static Builtin> {
    overloads(name, kind).first().copied()
}

/// Every entry of a name and kind, in table order: overloads told apart by the type of
/// their first parameter, such as `round(x)` and `round(shape, r)`. Empty when there
/// is none.
pub fn overloads(name: &str, kind: Kind) -> &'static [&'static Builtin] {
    index().get(name).map_or(&[], |kinds| kinds[kind as usize].as_slice())
}

/// Names of builtins of one kind (for suggestions).
pub fn names(kind: Kind) -> impl Iterator<Item = &'static str> {
    BUILTINS.iter().filter(move |b| b.kind() == kind).map(|b| b.name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each constructor belongs to one entry, and a name to one entry of each kind, or
    /// to overloads whose first parameters no value fits both of.
    #[test]
    fn constructors_and_names_are_unique() {
        for (i, a) in BUILTINS.iter().enumerate() {
            for b in &BUILTINS[i + 1..] {
                assert_ne!(a.ctor, b.ctor, "`{}` and `{}` share a constructor", a.name, b.name);
                if a.name == b.name && a.kind() == b.kind() {
                    let (x, y) = (a.params[0].ty, b.params[0].ty);
                    // Shapes, profiles and numbers are values no parameter of another takes.
                    let kinds = [Ty::Shape, Ty::Profile];
                    let distinct = match (a.variadic, b.variadic) {
                        // Variadic overloads are told apart by the type of their parts.
                        (Some(x), Some(y)) => kinds.contains(&x) && kinds.contains(&y) && x != y,
                        (None, None) => (kinds.contains(&x) || kinds.contains(&y)) && x != y,
                        _ => false,
                    };
                    assert!(distinct, "`{}` is listed twice and its overloads cannot be told apart", a.name);
                }
            }
        }
    }
}
