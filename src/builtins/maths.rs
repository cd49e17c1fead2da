//! Numeric builtins: functions of numbers and vectors, `min`/`max`, `range`, `sum`,
//! `hsv` and `random`. Angles are in degrees, in and out, like `sin`.

use std::rc::Rc;

use glam::DVec3;

use super::BoundArgs;
use super::{direction, Host, Value, MAX_LIST};
use super::{Builtin, Extreme, MathFn, NumFn, VecFn};
use crate::diag::{codes, Diagnostic};
use crate::ir::dump_num;
use crate::sig::{Default, Param, Range, Ty};
use crate::span::Span;

crate::params! {
    /// A function of one number: its one argument, whatever its name.
    pub struct OneNumber {
        /// a number
        x: f64 as Num = required;
    }
}

/// The parameter lists of functions of one number `x`, each with the function's domain
/// as its range (the checker checks it, the docs print it).
pub struct NumberArgs;

/// One required number named `name`, of the values in `range`.
const fn number(name: &'static str, range: Range, doc: &'static str) -> [Param; 1] {
    [Param { name, ty: Ty::Num, default: Default::Required, range, doc }]
}

impl NumberArgs {
    /// Any number.
    pub const ANY: &'static [Param] = &number("x", Range::ANY, "a number");
    /// `sqrt`'s domain.
    pub const NONNEG: &'static [Param] = &number("x", Range::NONNEG, "a number");
    /// `log`'s domain.
    pub const POSITIVE: &'static [Param] = &number("x", Range::POSITIVE, "a number");
    /// `asin`'s and `acos`'s domain.
    pub const UNIT: &'static [Param] = &number("x", Range::closed(-1.0, 1.0), "a sine or cosine");
    /// `random`'s seed.
    pub const SEED: &'static [Param] = &number("seed", Range::ANY, "any number; the same seed gives the same result");
}

crate::params! {
    /// A function of one vector: its one argument.
    pub struct OneVector {
        /// a vector
        v: DVec3 as Vec3 = required;
    }
}

/// The parameter lists of functions of one vector `v`.
pub struct VectorArgs;

/// One required vector named `v`, of the values in `range`.
const fn vector(range: Range) -> [Param; 1] {
    [Param { name: "v", ty: Ty::Vec3, default: Default::Required, range, doc: "a vector" }]
}

impl VectorArgs {
    /// Any vector.
    pub const ANY: &'static [Param] = &vector(Range::ANY);
    /// A vector that has a direction.
    pub const NONZERO: &'static [Param] = &vector(Range::NONZERO);
}

crate::params! {
    /// `pow(x, y)`.
    pub struct PowArgs {
        /// the base
        x: f64 as Num = required;
        /// the exponent (whole when `x` is negative)
        y: f64 as Num = required;
    }
}

crate::params! {
    /// `atan2(y, x)`.
    pub struct Atan2Args {
        /// the point's y
        y: f64 as Num = required;
        /// the point's x
        x: f64 as Num = required;
    }
}

crate::params! {
    /// `clamp(x, lo, hi)`.
    pub struct ClampArgs {
        /// the number to limit
        x: f64 as Num = required;
        /// the lowest result
        lo: f64 as Num = required;
        /// the highest result, at least `lo`
        hi: f64 as Num = required;
    }
}

crate::params! {
    /// `mix(a, b, t)`.
    pub struct MixArgs {
        /// the value at `t = 0`
        a: Value as Linear = required;
        /// the value at `t = 1`, of `a`'s type
        b: Value as Linear = required;
        /// how far from `a` to `b`
        t: f64 as Num = required;
    }
}

crate::params! {
    /// `hsv(h, s, v)`.
    pub struct HsvArgs {
        /// the hue in degrees (0 red, 120 green, 240 blue; it wraps)
        h: f64 as Num = required;
        /// the saturation
        s: f64 as Num = required, Range::UNIT;
        /// the value (brightness)
        v: f64 as Num = required, Range::UNIT;
    }
}

crate::params! {
    /// `range(from, to, step)`.
    pub struct RangeArgs {
        /// the first element
        from: f64 as Num = required;
        /// the bound the elements stay before
        to: f64 as Num = required;
        /// the distance between elements
        step: f64 as Num = 1.0, Range::NONZERO;
    }
}

crate::params! {
    /// `sum(list)` and `len(list)`.
    pub struct ListArgs {
        /// a list
        list: Value as List = required;
    }
}

crate::params! {
    /// `dot(a, b)` and `cross(a, b)`.
    pub struct PairArgs {
        /// the first vector
        a: DVec3 as Vec3 = required;
        /// the second vector
        b: DVec3 as Vec3 = required;
    }
}

impl dyn Host + '_ {
    /// A function of one number, `x` given at `arg` in the call at `call`.
    pub(crate) fn math(&mut self, b: &Builtin, f: MathFn, x: f64, arg: Span, call: Span) -> Value {
        // The domain is the declared range (the fast path of a call reaches here unbound).
        if let Some(p) = b.params.first() {
            if !self.in_range(p, &Value::Num(x), arg) {
                return Value::Error;
            }
        }
        // Within the declared domain `apply` is the function itself (its clamps for
        // fields never act), so a number means the same here and in a field's body.
        let y = match f {
            MathFn::Unary(u) => u.apply(x),
            MathFn::Random => random(x),
        };
        self.finite(Value::Num(y), call, || format!("`{}` overflowed", b.name))
    }

    /// A function of several numbers, or one giving a list or a colour.
    pub(super) fn numeric(&mut self, b: &Builtin, f: NumFn, a: &BoundArgs) -> Value {
        let v = match f {
            NumFn::Pow => {
                let PowArgs { x, y } = PowArgs::from_args(a);
                if x < 0.0 && y.fract() != 0.0 {
                    self.range_error(a.span_of("y"), "y", "a whole number when `x` is negative", dump_num(y));
                    return Value::Error;
                }
                Value::Num(x.powf(y))
            }
            NumFn::Atan2 => {
                let Atan2Args { y, x } = Atan2Args::from_args(a);
                // `+ 0.0` reads -0 as 0, so the angle stays in (-180, 180] as documented.
                Value::Num((y + 0.0).atan2(x).to_degrees())
            }
            NumFn::Clamp => {
                let ClampArgs { x, lo, hi } = ClampArgs::from_args(a);
                if lo > hi {
                    let rule = format!("at least `lo` ({})", dump_num(lo));
                    self.range_error(a.span_of("hi"), "hi", &rule, dump_num(hi));
                    return Value::Error;
                }
                Value::Num(x.clamp(lo, hi))
            }
            NumFn::Mix => return self.mix(b, a),
            NumFn::Hsv => {
                let HsvArgs { h, s, v } = HsvArgs::from_args(a);
                Value::Color(hsv(h, s, v) * 255.0)
            }
            NumFn::Range => return self.range(a),
            NumFn::Sum => return self.sum(b, a),
        };
        self.finite(v, a.call, || format!("`{}` overflowed", b.name))
    }

    /// `mix(a, b, t)`: `a·(1 − t) + b·t`, which is exactly `a` at 0 and `b` at 1.
    fn mix(&mut self, b: &Builtin, a: &BoundArgs) -> Value {
        let MixArgs { a: from, b: to, t } = MixArgs::from_args(a);
        let lerp = |x: DVec3, y: DVec3| x * (1.0 - t) + y * t;
        let v = match (&from, &to) {
            (Value::Num(x), Value::Num(y)) => Value::Num(x * (1.0 - t) + y * t),
            (Value::Vec3(x), Value::Vec3(y)) => Value::Vec3(lerp(*x, *y)),
            (Value::Color(x), Value::Color(y)) => Value::Color(lerp(*x, *y)),
            _ => {
                self.report(
                    Diagnostic::error(
                        codes::TYPE_MISMATCH,
                        a.span_of("b"),
                        format!("expected `{}`, found `{}`", from.ty_name(), to.ty_name()),
                        to.this_is(),
                    )
                    .with_label(a.span_of("a"), from.this_is())
                    .with_note("`mix` blends two values of one type"),
                );
                return Value::Error;
            }
        };
        self.finite(v, a.call, || format!("`{}` overflowed", b.name))
    }

    /// `range(from, to, step)`: every `from + i·step` before `to`. Each element is
    /// computed from `i`, not by adding steps, so `range(0, 1, 0.1)` has no drift.
    fn range(&mut self, a: &BoundArgs) -> Value {
        let RangeArgs { from, to, step } = RangeArgs::from_args(a);
        let at = |i: f64| from + i * step;
        let before = |x: f64| if step > 0.0 { x < to } else { x > to };
        let estimate = ((to - from) / step).ceil();
        if estimate > MAX_LIST as f64 || !estimate.is_finite() {
            self.list_too_long(a.call, format!("this range has about {} elements", dump_num(estimate)));
            return Value::Error;
        }
        // The estimate is off by one at most where rounding puts an element on `to`.
        let mut n = estimate.max(0.0) as usize;
        while n > 0 && !before(at((n - 1) as f64)) {
            n -= 1;
        }
        while n < MAX_LIST && before(at(n as f64)) {
            n += 1;
        }
        if !self.burn(n as u64, a.call) {
            return Value::Error;
        }
        Value::List(Rc::new((0..n).map(|i| Value::Num(at(i as f64))).collect()))
    }

    /// `sum(list)` of numbers, vectors or colours, all of one type; 0 when empty.
    fn sum(&mut self, b: &Builtin, a: &BoundArgs) -> Value {
        let ListArgs { list: Value::List(items) } = ListArgs::from_args(a) else {
            return Value::Error;
        };
        if !self.burn(items.len() as u64, a.call) {
            return Value::Error;
        }
        let Some(first) = items.first() else {
            return Value::Num(0.0);
        };
        if !matches!(first, Value::Num(_) | Value::Vec3(_) | Value::Color(_)) {
            let ty = Value::List(items.clone()).ty_name();
            let mut d = Diagnostic::error(
                codes::TYPE_MISMATCH,
                a.span_of("list"),
                format!("cannot `sum` a `{ty}`"),
                format!("this is a `{ty}`"),
            )
            .with_note("`sum` adds numbers, vectors or colours");
            if matches!(first, Value::Shape(_)) {
                d = d.with_hint("try `union(…)` to combine shapes");
            }
            self.report(d);
            return Value::Error;
        }
        // Lists hold one type (E0300), so every element is of `first`'s type or poison.
        let mut total = DVec3::ZERO;
        for item in items.iter() {
            match item {
                Value::Num(x) => total.x += x,
                Value::Vec3(v) | Value::Color(v) => total += *v,
                _ => return Value::Error,
            }
        }
        let v = match first {
            Value::Num(_) => Value::Num(total.x),
            Value::Color(_) => Value::Color(total),
            _ => Value::Vec3(total),
        };
        self.finite(v, a.call, || format!("`{}` overflowed", b.name))
    }

    /// A function of vectors.
    pub(super) fn vector(&mut self, b: &Builtin, f: VecFn, a: &BoundArgs) -> Value {
        let v = match f {
            VecFn::Dot | VecFn::Cross => {
                let PairArgs { a: u, b: w } = PairArgs::from_args(a);
                if f == VecFn::Dot {
                    Value::Num(u.dot(w))
                } else {
                    Value::Vec3(u.cross(w))
                }
            }
            VecFn::Length => Value::Num(super::length(OneVector::from_args(a).v)),
            // The range refused zero; one too small to scale is refused the same way.
            VecFn::Normalize => match direction(OneVector::from_args(a).v) {
                Some(n) => Value::Vec3(n),
                None => {
                    let v = OneVector::from_args(a).v;
                    self.range_error(a.span_of("v"), "v", "a non-zero vector", crate::ir::dump_vec(v));
                    return Value::Error;
                }
            },
        };
        self.finite(v, a.call, || format!("`{}` overflowed", b.name))
    }

    /// `min` or `max` of at least one number.
    pub(super) fn extreme(&mut self, b: &Builtin, e: Extreme, a: &BoundArgs) -> Value {
        if a.rest.is_empty() {
            self.report(Diagnostic::error(
                codes::ARITY,
                a.call,
                format!("`{}` needs at least one number", b.name),
                "no numbers given",
            ));
            return Value::Error;
        }
        let nums = a.rest.iter().map(|(v, _)| if let Value::Num(x) = v { *x } else { 0.0 });
        Value::Num(match e {
            Extreme::Min => nums.fold(f64::INFINITY, f64::min),
            Extreme::Max => nums.fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

/// Hue (degrees, any value: it wraps), saturation and value in [0, 1] to RGB in [0, 1]:
/// the hexcone model (Smith, 1978), as in every colour picker.
fn hsv(h: f64, s: f64, v: f64) -> DVec3 {
    let sector = h.rem_euclid(360.0) / 60.0;
    let c = v * s;
    let x = c * (1.0 - (sector % 2.0 - 1.0).abs());
    let (r, g, b) = match sector as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    DVec3::new(r, g, b) + (v - c)
}
/// `random(seed)`: a number in [0, 1) that depends only on `seed`, the same on every
/// machine and thread count. The seed's f64 bits (with -0 read as 0) go through
/// SplitMix64's finaliser (Steele, Lea and Flood, 2014), whose output passes BigCrush
/// for consecutive inputs; the top 53 bits make the fraction.
pub(crate) fn random(seed: f64) -> f64 {
    let mut z = (seed + 0.0).to_bits().wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

#[cfg(test)]
mod tests {
    /// `random` is a fixed function: these values are part of the language (scenes
    /// jittered with it must look the same everywhere, for ever).
    #[test]
    fn random_is_a_fixed_function() {
        let got: Vec<String> =
            [0.0, -0.0, 1.0, 2.0, 3.5, 1e9, -7.0].iter().map(|&s| format!("{:.12}", super::random(s))).collect();
        // Checked against an independent Python transcription of the same steps.
        let want = [
            "0.883310808214",
            "0.883310808214",
            "0.534542283913",
            "0.002598817124",
            "0.035474898268",
            "0.553695854510",
            "0.158411744012",
        ];
        assert_eq!(got, want);
        assert_eq!(super::random(0.0), super::random(-0.0), "-0 is 0");
        assert!((0..10_000).map(|i| super::random(i as f64)).all(|r| (0.0..1.0).contains(&r)));
    }
}
