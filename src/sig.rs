//! Signatures: what a builtin declares of each of its parameters (name, type, default,
//! range and doc), once. The checker binds arguments and checks ranges from these
//! declarations, and the editor's hover, completion and signature help and the
//! generated reference (`docs/builtins.md`) print them, so what is documented is what is
//! checked.
//!
//! A builtin's parameters are declared with [`params!`](crate::params), which makes a
//! typed struct of the arguments: constructors read fields by name, never by position.

use std::fmt;

use glam::DVec3;

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
    /// `checker(…)`, `stripes(…)`, `gradient(…)` or `noise(…)`.
    Pattern,
    /// A colour or a pattern: what a material's colour can be.
    Paint,
    /// An SDF-able solid.
    Shape,
    /// A triangle mesh.
    Mesh,
    /// A light.
    Light,
    /// A list.
    List,
    /// A number, a `vec3` or a colour: what can be scaled and added (`mix`, `sum`).
    Linear,
    /// A field literal `p => …` whose body is a number.
    FieldNum,
    /// A field literal `p => …` whose body is a vector.
    FieldVec,
    /// A box, `[[x0, y0, z0], [x1, y1, z1]]`.
    Bounds,
    /// A 2D profile (`circle`, `rect`, `polygon`), for `extrude` and `revolve`.
    Profile,
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
            Ty::Pattern => "pattern",
            Ty::Paint => "color or pattern",
            Ty::Shape => "shape",
            Ty::Mesh => "mesh",
            Ty::Light => "light",
            Ty::List => "list",
            Ty::Linear => "num, vec3 or color",
            Ty::FieldNum => "p => num",
            Ty::FieldVec => "p => vec3",
            Ty::Bounds => "[vec3, vec3]",
            Ty::Profile => "profile",
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
    /// A string.
    Str(&'static str),
    /// Absent means "derived from the other arguments" (the parameter's doc says how).
    Derived,
}

/// One end of a [`Range`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Limit {
    /// No limit on this side.
    Open,
    /// The value may equal it.
    Incl(f64),
    /// The value must differ from it.
    Excl(f64),
}

/// The values a number parameter takes (each component, for a vector), checked by the
/// binder and printed in the docs from this one declaration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// The lower end.
    pub lo: Limit,
    /// The upper end.
    pub hi: Limit,
    /// One value allowed outside `lo..hi` (`specular = -1`: no highlight).
    pub also: Option<f64>,
    /// Whether zero is refused: a number other than 0, or a vector other than `[0, 0, 0]`
    /// (a direction).
    pub nonzero: bool,
    /// Whether only whole numbers are admitted (an `int` parameter is whole by its type;
    /// this is for the components of a vector of counts).
    pub whole: bool,
}

impl Range {
    /// Any value.
    pub const ANY: Range = Range { lo: Limit::Open, hi: Limit::Open, also: None, nonzero: false, whole: false };
    /// Greater than 0.
    pub const POSITIVE: Range = Range::gt(0.0);
    /// At least 0.
    pub const NONNEG: Range = Range::ge(0.0);
    /// Between 0 and 1.
    pub const UNIT: Range = Range::closed(0.0, 1.0);
    /// Anything but zero (a direction, for a vector).
    pub const NONZERO: Range = Range { nonzero: true, ..Range::ANY };

    /// Greater than `x`.
    pub const fn gt(x: f64) -> Range {
        Range { lo: Limit::Excl(x), ..Range::ANY }
    }

    /// At least `x`.
    pub const fn ge(x: f64) -> Range {
        Range { lo: Limit::Incl(x), ..Range::ANY }
    }

    /// Between `lo` and `hi`, both included.
    pub const fn closed(lo: f64, hi: f64) -> Range {
        Range { lo: Limit::Incl(lo), hi: Limit::Incl(hi), ..Range::ANY }
    }

    /// Between `lo` and `hi`, neither included.
    pub const fn open(lo: f64, hi: f64) -> Range {
        Range { lo: Limit::Excl(lo), hi: Limit::Excl(hi), ..Range::ANY }
    }

    /// Greater than `lo` and at most `hi`.
    pub const fn gt_le(lo: f64, hi: f64) -> Range {
        Range { lo: Limit::Excl(lo), hi: Limit::Incl(hi), ..Range::ANY }
    }

    /// At least `lo` and less than `hi`.
    pub const fn ge_lt(lo: f64, hi: f64) -> Range {
        Range { lo: Limit::Incl(lo), hi: Limit::Excl(hi), ..Range::ANY }
    }

    /// This range, whole numbers only.
    pub const fn whole(self) -> Range {
        Range { whole: true, ..self }
    }

    /// This range, or exactly `x`.
    pub const fn or(self, x: f64) -> Range {
        Range { also: Some(x), ..self }
    }

    /// Whether the number `x` is in the range.
    pub fn admits(&self, x: f64) -> bool {
        if self.also == Some(x) {
            return true;
        }
        let above = match self.lo {
            Limit::Open => true,
            Limit::Incl(l) => x >= l,
            Limit::Excl(l) => x > l,
        };
        let below = match self.hi {
            Limit::Open => true,
            Limit::Incl(h) => x <= h,
            Limit::Excl(h) => x < h,
        };
        above && below && !x.is_nan() && !(self.nonzero && x == 0.0) && !(self.whole && x.fract() != 0.0)
    }

    /// Whether the vector `v` is in the range: each component is, and it is not zero
    /// when the range refuses zero.
    pub fn admits_vec(&self, v: DVec3) -> bool {
        let each = Range { nonzero: false, ..*self };
        let nonzero = !self.nonzero || (v != DVec3::ZERO && v.is_finite());
        nonzero && each.admits(v.x) && each.admits(v.y) && each.admits(v.z)
    }

    /// Whether every value is admitted (nothing to check or document).
    pub fn is_any(&self) -> bool {
        *self == Range::ANY
    }

    /// The rule in words, for a number, or for each component of a vector (`vector`).
    pub fn rule(&self, vector: bool) -> String {
        let bounds = match (self.lo, self.hi) {
            (Limit::Open, Limit::Open) => None,
            (Limit::Excl(l), Limit::Open) => Some(format!("greater than {}", short(l))),
            (Limit::Incl(l), Limit::Open) => Some(format!("at least {}", short(l))),
            (Limit::Open, Limit::Excl(h)) => Some(format!("less than {}", short(h))),
            (Limit::Open, Limit::Incl(h)) => Some(format!("at most {}", short(h))),
            (Limit::Incl(l), Limit::Incl(h)) => Some(format!("between {} and {}", short(l), short(h))),
            (Limit::Excl(l), Limit::Excl(h)) => Some(format!("between {} and {} (exclusive)", short(l), short(h))),
            (Limit::Excl(l), Limit::Incl(h)) => Some(format!("greater than {} and at most {}", short(l), short(h))),
            (Limit::Incl(l), Limit::Excl(h)) => Some(format!("at least {} and less than {}", short(l), short(h))),
        };
        let bounds = match (bounds, self.also) {
            (Some(b), Some(x)) => Some(format!("{} or {b}", short(x))),
            (b, _) => b,
        };
        let bounds = match (bounds, self.whole, vector) {
            (Some(b), true, true) => Some(format!("whole numbers {b}")),
            (Some(b), true, false) => Some(format!("a whole number {b}")),
            (None, true, _) => Some("whole".into()),
            (b, false, _) => b,
        };
        match (bounds, self.nonzero, vector) {
            (None, false, _) => "any value".into(),
            (None, true, true) => "a non-zero vector".into(),
            (None, true, false) => "other than 0".into(),
            (Some(b), false, _) => b,
            (Some(b), true, true) => format!("a non-zero vector, each component {b}"),
            (Some(b), true, false) => format!("{b}, other than 0"),
        }
    }
}

/// One parameter, as a builtin declares it.
#[derive(Clone, Copy, Debug)]
pub struct Param {
    /// Its name, for named arguments.
    pub name: &'static str,
    /// Its type.
    pub ty: Ty,
    /// Its default.
    pub default: Default,
    /// The values it takes.
    pub range: Range,
    /// What it is, one phrase for hover and docs.
    pub doc: &'static str,
}

impl Param {
    /// `name: type = default`, as in a signature.
    pub fn describe(&self) -> String {
        let default = match self.default {
            Default::Required => String::new(),
            Default::Num(x) => format!(" = {}", num(x)),
            Default::Vec3(v) => format!(" = {}", vec(v.into())),
            Default::Bool(b) => format!(" = {b}"),
            Default::Color(c) => format!(" = rgb({}, {}, {})", c[0], c[1], c[2]),
            Default::Str(s) => format!(" = \"{s}\""),
            Default::Derived => " = …".into(),
        };
        format!("{}: {}{default}", self.name, self.ty)
    }

    /// Whether the range applies to each component of a vector.
    pub fn is_vector(&self) -> bool {
        matches!(self.ty, Ty::Vec3 | Ty::Size | Ty::Color)
    }

    /// The parameter's doc with its range: `radius; greater than 0`.
    pub fn explain(&self) -> String {
        if self.range.is_any() {
            self.doc.to_string()
        } else {
            format!("{}; {}", self.doc, self.range.rule(self.is_vector()))
        }
    }
}

/// Formats a number with at most 12 decimals, trailing zeros trimmed and `-0` as `0`,
/// so dumps do not change with the last bits of a rotation matrix; from 1e16 on (where
/// f64 no longer holds every whole number) in exponent form, not 300 digits.
pub fn num(x: f64) -> String {
    if x.is_finite() && x.abs() >= 1e16 {
        return format!("{x:e}");
    }
    let s = format!("{x:.12}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// A number as a rule states it: in exponent form when it is very large or small
/// (`1e-6`, `1e15`), else as [`num`] writes it.
pub fn short(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        num(x)
    }
}

/// A vector as `[x, y, z]`, each number as [`num`] writes it.
pub fn vec(v: DVec3) -> String {
    format!("[{}, {}, {}]", num(v.x), num(v.y), num(v.z))
}

/// Where a declared struct's fields come from: bound arguments (or their defaults) by
/// slot, in the order the parameters are declared. The checker's bound arguments are
/// one source; tests make others.
pub trait Args {
    /// The number in slot `i` (a whole number for an `int`).
    fn num(&self, i: usize) -> f64;
    /// The vector in slot `i` (a size's number as `[k, k, k]`, a colour's channels).
    fn vec3(&self, i: usize) -> DVec3;
    /// The boolean in slot `i`.
    fn flag(&self, i: usize) -> bool;
    /// The string in slot `i`.
    fn text(&self, i: usize) -> String;
    /// Whether slot `i` was given (not its default).
    fn given(&self, i: usize) -> bool;
}

/// A field type of a declared struct, read from slot `i` of an argument source `A`.
/// The plain types read any [`Args`]; the checker adds shapes, paints and the rest for
/// its own arguments.
pub trait FromArg<A: ?Sized>: Sized {
    /// The value of slot `i`.
    fn from_arg(a: &A, i: usize) -> Self;
}

impl<A: Args + ?Sized> FromArg<A> for f64 {
    fn from_arg(a: &A, i: usize) -> f64 {
        a.num(i)
    }
}

/// An `int` parameter: its declared range keeps it within `u32` (tested for every
/// declaration in `every_int_parameter_fits_its_field`).
impl<A: Args + ?Sized> FromArg<A> for u32 {
    fn from_arg(a: &A, i: usize) -> u32 {
        a.num(i) as u32
    }
}

impl<A: Args + ?Sized> FromArg<A> for DVec3 {
    fn from_arg(a: &A, i: usize) -> DVec3 {
        a.vec3(i)
    }
}

impl<A: Args + ?Sized> FromArg<A> for bool {
    fn from_arg(a: &A, i: usize) -> bool {
        a.flag(i)
    }
}

impl<A: Args + ?Sized> FromArg<A> for String {
    fn from_arg(a: &A, i: usize) -> String {
        a.text(i)
    }
}

/// A parameter whose absence means something ([`Default::Derived`]): `None` when not given.
impl<A: Args + ?Sized, T: FromArg<A>> FromArg<A> for Option<T> {
    fn from_arg(a: &A, i: usize) -> Option<T> {
        a.given(i).then(|| T::from_arg(a, i))
    }
}

/// A field's value shown in an IR dump, as [`num`] and [`vec()`] write numbers.
pub trait Show {
    /// The value as dumps show it.
    fn show(&self) -> String;
}

impl Show for f64 {
    fn show(&self) -> String {
        num(*self)
    }
}

impl Show for u32 {
    fn show(&self) -> String {
        self.to_string()
    }
}

impl Show for DVec3 {
    fn show(&self) -> String {
        vec(*self)
    }
}

impl Show for bool {
    fn show(&self) -> String {
        self.to_string()
    }
}

/// [`Show`] for a type, asked through a type parameter so that a declared struct can
/// offer [`shown`](crate::params) whatever its fields are: the method exists for every
/// struct, and compiles where it is called only when every field has a `Show`.
pub trait ShowVia<Via: ?Sized> {
    /// The value as dumps show it.
    fn show_via(&self) -> String;
}

impl<T: Show, Via: ?Sized> ShowVia<Via> for T {
    fn show_via(&self) -> String {
        self.show()
    }
}

/// The [`Default`] of a parameter of type `$ty` written `$d` in a [`params!`](crate::params)
/// declaration: `required`, `derived`, or a value.
#[doc(hidden)]
#[macro_export]
macro_rules! param_default {
    ($ty:ident, required) => {
        $crate::sig::Default::Required
    };
    ($ty:ident, derived) => {
        $crate::sig::Default::Derived
    };
    (Bool, $d:tt) => {
        $crate::sig::Default::Bool($d)
    };
    (Str, $d:tt) => {
        $crate::sig::Default::Str($d)
    };
    (Vec3, $d:tt) => {
        $crate::sig::Default::Vec3($d)
    };
    (Color, $d:tt) => {
        $crate::sig::Default::Color($d)
    };
    (Paint, $d:tt) => {
        $crate::sig::Default::Color($d)
    };
    ($ty:ident, $d:tt) => {
        $crate::sig::Default::Num($d as f64)
    };
}

/// Declares a builtin's parameters once: a struct with one typed field per parameter,
/// its `PARAMS` (name, type, default, range and doc, in positional order) and
/// `from_args`, which reads the fields from bound arguments.
///
/// ```ignore
/// params! {
///     /// A sphere centred at the origin.
///     #[derive(Clone, Debug, PartialEq)]
///     pub struct Sphere {
///         /// the radius
///         r: f64 as Num = required, Range::POSITIVE;
///     }
/// }
/// ```
///
/// A default is `required`, `derived` (the field is an `Option`, `None` when not given)
/// or a value (negative numbers in parentheses); the range is optional.
#[macro_export]
macro_rules! params {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $(
                $(#[doc = $doc:literal])+
                $field:ident : $rty:ty as $ty:ident = $default:tt $(, $range:expr)?;
            )*
        }
    ) => {
        $(#[$meta])*
        $vis struct $name {
            $(
                $(#[doc = $doc])+
                pub $field: $rty,
            )*
        }

        #[allow(dead_code, reason = "not every declaration is read, listed and dumped")]
        impl $name {
            /// The parameters, in positional order.
            pub const PARAMS: &'static [$crate::sig::Param] = &[
                $(
                    $crate::sig::Param {
                        name: stringify!($field),
                        ty: $crate::sig::Ty::$ty,
                        default: $crate::param_default!($ty, $default),
                        range: $crate::params!(@range $($range)?),
                        doc: concat!($($doc),+).trim_ascii(),
                    },
                )*
            ];

            /// The fields from bound arguments, slot by slot in declaration order.
            #[allow(unused_variables, reason = "a builtin without parameters reads nothing")]
            pub fn from_args<A: ?Sized>(a: &A) -> Self
            where
                $($rty: $crate::sig::FromArg<A>,)*
            {
                #[allow(non_camel_case_types, dead_code, reason = "one slot number per field, named by it")]
                enum Slot { $($field,)* }
                $name {
                    $(
                        $field: <$rty as $crate::sig::FromArg<A>>::from_arg(a, Slot::$field as usize),
                    )*
                }
            }

            /// The fields as the IR dump shows them, `(name, value)` in declaration order;
            /// call it as `shown::<()>()` (`Via` only defers the check that every field
            /// has a [`Show`](crate::sig::Show)).
            pub fn shown<Via: ?Sized>(&self) -> Vec<(&'static str, String)>
            where
                $($rty: $crate::sig::ShowVia<Via>,)*
            {
                vec![$((stringify!($field), <$rty as $crate::sig::ShowVia<Via>>::show_via(&self.$field)),)*]
            }
        }
    };
    (@range) => { $crate::sig::Range::ANY };
    (@range $range:expr) => { $range };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_admit_what_they_say() {
        assert!(Range::POSITIVE.admits(1e-300) && !Range::POSITIVE.admits(0.0) && !Range::POSITIVE.admits(f64::NAN));
        assert!(Range::NONNEG.admits(0.0) && !Range::NONNEG.admits(-1e-300));
        let spec = Range::NONNEG.or(-1.0);
        assert!(spec.admits(-1.0) && spec.admits(0.0) && !spec.admits(-0.5));
        assert_eq!(spec.rule(false), "-1 or at least 0");
        assert!(Range::ge_lt(1e-6, 1.0).admits(1e-6) && !Range::ge_lt(1e-6, 1.0).admits(1.0));
        assert_eq!(Range::ge_lt(1e-6, 1.0).rule(false), "at least 1e-6 and less than 1");
        assert!(Range::NONZERO.admits_vec(DVec3::X) && !Range::NONZERO.admits_vec(DVec3::ZERO));
        assert_eq!(Range::NONZERO.rule(true), "a non-zero vector");
        assert_eq!(Range::open(0.0, 180.0).rule(false), "between 0 and 180 (exclusive)");
        assert_eq!(Range::gt_le(0.0, 1e15).rule(false), "greater than 0 and at most 1e15");
        let counts = Range::closed(1.0, 1000.0).whole();
        assert!(counts.admits_vec(DVec3::new(1.0, 2.0, 1000.0)) && !counts.admits_vec(DVec3::new(1.5, 2.0, 3.0)));
        assert_eq!(counts.rule(true), "whole numbers between 1 and 1000");
    }

    #[test]
    fn numbers_are_written_stably() {
        assert_eq!(num(0.1 + 0.2), "0.3");
        assert_eq!(num(-0.0), "0");
        assert_eq!(short(1e-7), "1e-7");
        assert_eq!(short(0.001), "0.001");
        assert_eq!(num(2.5), "2.5");
        assert_eq!(vec(DVec3::new(1.0, -2.0, 0.5)), "[1, -2, 0.5]");
    }

    struct Given(Vec<f64>);

    impl Args for Given {
        fn num(&self, i: usize) -> f64 {
            self.0[i]
        }
        fn vec3(&self, i: usize) -> DVec3 {
            DVec3::splat(self.0[i])
        }
        fn flag(&self, i: usize) -> bool {
            self.0[i] != 0.0
        }
        fn text(&self, _: usize) -> String {
            String::new()
        }
        fn given(&self, i: usize) -> bool {
            !self.0[i].is_nan()
        }
    }

    crate::params! {
        /// A declaration to test the macro with.
        #[derive(Debug, PartialEq)]
        struct Example {
            /// a length
            r: f64 as Num = required, Range::POSITIVE;
            /// how many
            n: u32 as Int = 3, Range::closed(1.0, 10.0);
            /// derived from `n`
            m: Option<u32> as Int = derived;
            /// a direction
            axis: DVec3 as Vec3 = [0.0, 1.0, 0.0], Range::NONZERO;
            /// a switch
            on: bool as Bool = false;
        }
    }

    #[test]
    fn declarations_make_typed_fields_and_params() {
        let e = Example::from_args(&Given(vec![0.5, 4.0, f64::NAN, 2.0, 1.0]));
        assert_eq!(e, Example { r: 0.5, n: 4, m: None, axis: DVec3::splat(2.0), on: true });
        let names: Vec<&str> = Example::PARAMS.iter().map(|p| p.name).collect();
        assert_eq!(names, ["r", "n", "m", "axis", "on"]);
        assert_eq!(Example::PARAMS[0].doc, "a length");
        assert_eq!(Example::PARAMS[1].default, Default::Num(3.0));
        assert_eq!(Example::PARAMS[3].explain(), "a direction; a non-zero vector");
        assert_eq!(Example::PARAMS[0].describe(), "r: num");
        let shown = Example { r: 0.5, n: 4, m: None, axis: DVec3::Y, on: true };
        assert_eq!(shown.r.show(), "0.5");
        assert_eq!(Example::PARAMS[4].describe(), "on: bool = false");
    }
}
