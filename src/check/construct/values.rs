//! Plain-value builtins: materials, colours and lights.

use std::sync::Arc;

use glam::DVec3;

use super::{Range, NONNEG, POS};
use crate::check::builtins::{Builtin, LightFn, PatternFn};
use crate::check::expr::BoundArgs;
use crate::check::{direction, Ctx, Value};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, dump_vec, Material, Paint, Pattern, PatternKind};

/// Highest index of refraction (germanium's is about 4; nothing in nature reaches 10).
pub const MAX_IOR: f64 = 10.0;
/// Most patterns in one pattern, itself included: each is evaluated at every shaded
/// point, and a blend evaluates both of its paints.
pub const MAX_PATTERN_NODES: usize = 64;

/// A colour or pattern value as a material's paint (`None` for poison).
fn paint(v: &Value) -> Option<Paint> {
    match v {
        Value::Color(c) => Some(Paint::Solid(*c)),
        Value::Pattern(p) => Some(Paint::Pattern(p.clone())),
        _ => None,
    }
}

/// Patterns in a pattern, itself included.
fn pattern_nodes(p: &Pattern) -> usize {
    let inner = |paint: &Paint| match paint {
        Paint::Solid(_) => 0,
        Paint::Pattern(q) => pattern_nodes(q),
    };
    1 + inner(&p.a) + inner(&p.b)
}

impl Ctx<'_> {
    /// `material(color, specular, reflective, transparency, ior, absorption)`.
    pub(super) fn material(&mut self, b: &Builtin, a: &BoundArgs) -> Value {
        let spec = a.num(b, 1);
        let ok = [
            self.check_num(a, b, 1, |s| s == -1.0 || s >= 0.0, "-1 (no highlight) or at least 0"),
            self.check_num(a, b, 2, |r| (0.0..=1.0).contains(&r), "between 0 and 1"),
            self.check_num(a, b, 3, |t| (0.0..=1.0).contains(&t), "between 0 and 1"),
            self.check_num(a, b, 4, |n| n > 0.0 && n <= MAX_IOR, "greater than 0 and at most 10"),
            self.check_vec(a, b, 5, |x| x >= 0.0, NONNEG),
        ];
        if ok.contains(&false) {
            return Value::Error;
        }
        let Some(color) = paint(&a.value(b, 0)) else {
            return Value::Error;
        };
        let m = Material {
            color,
            specular: (spec >= 0.0).then_some(spec),
            reflective: a.num(b, 2),
            transparency: a.num(b, 3),
            ior: a.num(b, 4),
            absorption: a.vec(b, 5),
            span: a.call,
        };
        if !m.is_transparent() {
            let idle: Vec<usize> = [(4, m.ior != 1.0), (5, m.absorption != DVec3::ZERO)]
                .into_iter()
                .filter_map(|(i, set)| (set && a.vals[i].is_some()).then_some(i))
                .collect();
            if let Some(&first) = idle.first() {
                let names: Vec<String> = idle.iter().map(|&i| format!("`{}`", b.params[i].name)).collect();
                self.report(
                    Diagnostic::warning(
                        codes::NO_EFFECT,
                        a.span(first),
                        format!(
                            "{} {} no effect on an opaque material",
                            names.join(" and "),
                            if idle.len() > 1 { "have" } else { "has" }
                        ),
                        "the material has no `transparency`",
                    )
                    .with_hint("give it `transparency = 1` for clear glass, or less to mix in its surface colour"),
                );
            }
        }
        Value::Material(Arc::new(m))
    }

    /// `checker`, `stripes`, `gradient` and `noise`: two paints and where each goes.
    pub(super) fn pattern(&mut self, b: &Builtin, f: PatternFn, a: &BoundArgs) -> Value {
        let kind = match f {
            PatternFn::Checker => {
                self.check_num(a, b, 2, |x| x > 0.0, POS).then(|| PatternKind::Checker { size: a.num(b, 2) })
            }
            PatternFn::Stripes => {
                let ok_width = self.check_num(a, b, 2, |x| x > 0.0, POS);
                let axis = a.vec(b, 3);
                let ok_axis = direction(axis).is_some();
                if !ok_axis {
                    self.range_error(a.span(3), Range { name: "axis", rule: "a non-zero vector" }, dump_vec(axis));
                }
                (ok_width && ok_axis).then_some(PatternKind::Stripes { width: a.num(b, 2), axis })
            }
            PatternFn::Gradient => {
                let (from, to) = (a.vec(b, 2), a.vec(b, 3));
                if direction(to - from).is_none() {
                    self.range_error(a.span(3), Range { name: "to", rule: "a point other than `from`" }, dump_vec(to));
                    None
                } else {
                    Some(PatternKind::Gradient { from, to })
                }
            }
            PatternFn::Noise => {
                let ok_size = self.check_num(a, b, 2, |x| x > 0.0, POS);
                let seed = self.check_int(a, b, 3, 0, u32::MAX);
                match (ok_size, seed) {
                    (true, Some(seed)) => Some(PatternKind::Noise { size: a.num(b, 2), seed }),
                    _ => None,
                }
            }
        };
        let (Some(kind), Some(pa), Some(pb)) = (kind, paint(&a.value(b, 0)), paint(&a.value(b, 1))) else {
            return Value::Error;
        };
        let pattern = Pattern { kind, a: pa, b: pb, span: a.call };
        let nodes = pattern_nodes(&pattern);
        if nodes > MAX_PATTERN_NODES {
            self.report(
                Diagnostic::error(
                    codes::SHAPE_TOO_LARGE,
                    a.call,
                    "a pattern with too many patterns inside",
                    format!("this pattern holds {nodes} patterns"),
                )
                .with_note(format!(
                    "a pattern may hold at most {MAX_PATTERN_NODES}, itself included: every one is evaluated at each shaded point"
                )),
            );
            return Value::Error;
        }
        Value::Pattern(Arc::new(pattern))
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
