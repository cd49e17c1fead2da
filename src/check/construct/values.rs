//! Plain-value builtins: materials, colours and lights.

use std::sync::Arc;

use glam::DVec3;

use super::{Range, NONNEG};
use crate::check::builtins::{Builtin, LightFn};
use crate::check::expr::BoundArgs;
use crate::check::{direction, Ctx, Value};
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
}
