//! Plain-value builtins: materials, colours, lights and numbers.

use std::sync::Arc;

use glam::DVec3;

use super::{Range, NONNEG};
use crate::check::builtins::{Builtin, Extreme, LightFn, MathFn};
use crate::check::expr::BoundArgs;
use crate::check::{direction, Ctx, Value};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, dump_vec, Material};

impl Ctx<'_> {
    /// `material(color, specular, reflective)`.
    pub(super) fn material(&mut self, b: &Builtin, a: &BoundArgs) -> Value {
        let spec = a.num(b, 1);
        let ok_spec = self.check_num(a, b, 1, |s| s == -1.0 || s >= 0.0, "-1 (no highlight) or at least 0");
        let ok_refl = self.check_num(a, b, 2, |r| (0.0..=1.0).contains(&r), "between 0 and 1");
        if !(ok_spec && ok_refl) {
            return Value::Error;
        }
        let Value::Color(color) = a.value(b, 0) else {
            return Value::Error;
        };
        Value::Material(Arc::new(Material {
            color,
            specular: (spec >= 0.0).then_some(spec),
            reflective: a.num(b, 2),
            span: a.call,
        }))
    }

    /// `rgb(r, g, b)` in 0–255.
    pub(super) fn rgb(&mut self, b: &Builtin, a: &BoundArgs) -> Value {
        let mut ok = true;
        for i in 0..3 {
            ok &= self.check_num(a, b, i, |x| (0.0..=255.0).contains(&x), "between 0 and 255");
        }
        if !ok {
            return Value::Error;
        }
        Value::Color(DVec3::new(a.num(b, 0), a.num(b, 1), a.num(b, 2)))
    }

    /// A light (placed later by `at`).
    pub(super) fn light(&mut self, b: &Builtin, l: LightFn, a: &BoundArgs) -> Value {
        if !self.check_num(a, b, 0, |x| x >= 0.0, NONNEG) {
            return Value::Error;
        }
        let (kind, shadows, radius) = match l {
            LightFn::Ambient => (ir::LightKind::Ambient, false, 0.0),
            LightFn::Point => {
                if !self.check_num(a, b, 2, |x| x >= 0.0, NONNEG) {
                    return Value::Error;
                }
                (ir::LightKind::Point { position: DVec3::ZERO }, a.flag(b, 1), a.num(b, 2))
            }
            LightFn::Directional => {
                let towards = a.vec(b, 1);
                if direction(towards).is_none() {
                    self.range_error(
                        a.span(1),
                        Range { name: "towards", rule: "a non-zero vector" },
                        dump_vec(towards),
                    );
                    return Value::Error;
                }
                (ir::LightKind::Directional { towards }, a.flag(b, 2), 0.0)
            }
        };
        Value::Light(Arc::new(ir::Light { kind, intensity: a.num(b, 0), shadows, radius, span: a.call }))
    }

    /// A function of one number (angles in degrees).
    pub(super) fn math(&mut self, b: &Builtin, f: MathFn, a: &BoundArgs) -> Value {
        let x = a.num(b, 0);
        let r = x.to_radians();
        Value::Num(match f {
            MathFn::Sin => r.sin(),
            MathFn::Cos => r.cos(),
            MathFn::Tan => r.tan(),
            MathFn::Sqrt => {
                if !self.check_num(a, b, 0, |x| x >= 0.0, NONNEG) {
                    return Value::Error;
                }
                x.sqrt()
            }
            MathFn::Abs => x.abs(),
            MathFn::Floor => x.floor(),
            MathFn::Ceil => x.ceil(),
            MathFn::Sign => {
                if x == 0.0 {
                    0.0
                } else {
                    x.signum()
                }
            }
            MathFn::Random => random(x),
        })
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
