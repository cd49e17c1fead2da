//! Shape builtins: primitives, CSG operators and modifiers.

use super::{Range, MAX_REPEAT, NONNEG, POS};
use crate::check::builtins::{Builtin, Modifier, Prim};
use crate::check::expr::BoundArgs;
use crate::check::{direction, Ctx, Value, MAX_OBJECTS};
use crate::diag::{codes, Diagnostic};
use crate::ir::{dump_vec, CsgOp, Primitive, ShapeKind};

impl Ctx<'_> {
    /// A primitive, or `None` after reporting a value out of range.
    pub(super) fn primitive(&mut self, b: &Builtin, p: Prim, a: &BoundArgs) -> Option<Primitive> {
        let pos = |x: f64| x > 0.0;
        // Every primitive but the plane takes two positive sizes, or a positive `size`.
        let mut two = || {
            let ok = self.check_num(a, b, 0, pos, POS) & self.check_num(a, b, 1, pos, POS);
            ok.then(|| (a.num(b, 0), a.num(b, 1)))
        };
        Some(match p {
            Prim::Sphere => {
                self.check_num(a, b, 0, pos, POS).then_some(())?;
                Primitive::Sphere { radius: a.num(b, 0) }
            }
            Prim::Box => {
                self.check_vec(a, b, 0, pos, POS).then_some(())?;
                Primitive::Box { half: a.vec(b, 0) }
            }
            Prim::Cylinder => two().map(|(radius, half_height)| Primitive::Cylinder { radius, half_height })?,
            Prim::Capsule => two().map(|(radius, half_height)| Primitive::Capsule { radius, half_height })?,
            Prim::Cone => two().map(|(radius, half_height)| Primitive::Cone { radius, half_height })?,
            Prim::Torus => two().map(|(major, minor)| Primitive::Torus { major, minor })?,
            Prim::Plane => {
                let Some(normal) = direction(a.vec(b, 0)) else {
                    self.range_error(
                        a.span(0),
                        Range { name: "normal", rule: "a non-zero vector" },
                        dump_vec(a.vec(b, 0)),
                    );
                    return None;
                };
                Primitive::Plane { normal, offset: a.num(b, 1) }
            }
        })
    }

    /// A CSG node, or `None` after reporting.
    pub(super) fn csg(&mut self, b: &Builtin, op: CsgOp, a: &BoundArgs) -> Option<ShapeKind> {
        if a.rest.is_empty() {
            self.report(
                Diagnostic::error(
                    codes::ARITY,
                    a.call,
                    format!("`{}` needs at least one shape", b.name),
                    "no shapes given",
                )
                .with_hint(format!("try `{}(sphere(1), box(1))`", b.name)),
            );
            return None;
        }
        // As many parts as a scene may have objects: the same parts as separate objects
        // would be refused at that count, and a list could join two full lists here.
        if a.rest.len() > MAX_OBJECTS {
            self.report(
                Diagnostic::error(
                    codes::TOO_LARGE,
                    a.call,
                    format!("`{}` of too many parts", b.name),
                    format!("this combines {} shapes", a.rest.len()),
                )
                .with_note(format!(
                    "one CSG operation may combine at most {MAX_OBJECTS} shapes, as many as a scene's objects"
                )),
            );
            return None;
        }
        self.check_num(a, b, 0, |x| x >= 0.0, NONNEG).then_some(())?;
        let children =
            a.rest.iter().filter_map(|(v, _)| if let Value::Shape(s) = v { Some(s.clone()) } else { None }).collect();
        Some(ShapeKind::Csg { op, children, smooth: a.num(b, 0) })
    }

    /// A modifier node, or `None` after reporting.
    pub(super) fn modifier(&mut self, b: &Builtin, m: Modifier, a: &BoundArgs) -> Option<ShapeKind> {
        let Value::Shape(child) = a.value(b, 0) else {
            return None;
        };
        match m {
            Modifier::Round => {
                self.check_num(a, b, 1, |x| x >= 0.0, NONNEG).then_some(())?;
                Some(ShapeKind::Round { child, radius: a.num(b, 1) })
            }
            Modifier::Shell => {
                self.check_num(a, b, 1, |x| x > 0.0, POS).then_some(())?;
                Some(ShapeKind::Shell { child, thickness: a.num(b, 1) })
            }
            Modifier::Repeat => {
                let ok_period = self.check_vec(a, b, 1, |x| x > 0.0, POS);
                let rule = format!("whole numbers between 1 and {MAX_REPEAT}");
                let ok_count =
                    self.check_vec(a, b, 2, |x| x.fract() == 0.0 && (1.0..=MAX_REPEAT as f64).contains(&x), &rule);
                (ok_period && ok_count).then_some(())?;
                let c = a.vec(b, 2);
                let count = [c.x as u32, c.y as u32, c.z as u32];
                Some(ShapeKind::Repeat { child, period: a.vec(b, 1), count })
            }
        }
    }
}
