//! Shape builtins: primitives (declared in [`crate::primitive`]), CSG operators and
//! modifiers.

use glam::DVec3;

use super::MAX_REPEAT;
use crate::check::builtins::{Builtin, Modifier};
use crate::check::expr::BoundArgs;
use crate::check::{Ctx, Value, MAX_OBJECTS};
use crate::diag::{codes, Diagnostic};
use crate::ir::{CsgOp, Primitive, ShapeKind};
use crate::primitive::Entry;
use crate::sig::Range;

crate::params! {
    /// `union`, `intersect` and `subtract`, after their shapes.
    pub struct CsgArgs {
        /// how far the seams are blended (0: sharp)
        smooth: f64 as Num = 0.0, Range::NONNEG;
    }
}

crate::params! {
    /// `round(shape, r)`.
    pub struct RoundArgs {
        /// the shape to round
        shape: Value as Shape = required;
        /// how far the shape grows, rounding its edges by as much
        r: f64 as Num = required, Range::NONNEG;
    }
}

crate::params! {
    /// `shell(shape, thickness)`.
    pub struct ShellArgs {
        /// the shape to hollow
        shape: Value as Shape = required;
        /// the wall's thickness, centred on the surface
        thickness: f64 as Num = required, Range::POSITIVE;
    }
}

crate::params! {
    /// `repeat(shape, period, count)`.
    pub struct RepeatArgs {
        /// the shape to copy
        shape: Value as Shape = required;
        /// the spacing of the copies along each axis
        period: DVec3 as Size = required, Range::POSITIVE;
        /// copies along each axis
        count: DVec3 as Size = required, Range::closed(1.0, MAX_REPEAT as f64).whole();
    }
}

impl Ctx<'_> {
    /// A primitive from its definition, or `None` after reporting a rule between its
    /// parameters that the arguments break.
    pub(super) fn primitive(&mut self, e: &Entry, a: &BoundArgs) -> Option<Primitive> {
        match (e.build)(a) {
            Ok(p) => Some(p),
            Err(refusal) => {
                let shown = match a.slot(refusal.param).map(|i| a.value(i)) {
                    Some(Value::Num(x)) => crate::ir::dump_num(x),
                    Some(Value::Vec3(v)) => crate::ir::dump_vec(v),
                    _ => "given".into(),
                };
                self.range_error(a.span_of(refusal.param), refusal.param, &refusal.rule, shown);
                None
            }
        }
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
        let CsgArgs { smooth } = CsgArgs::from_args(a);
        let children =
            a.rest.iter().filter_map(|(v, _)| if let Value::Shape(s) = v { Some(s.clone()) } else { None }).collect();
        Some(ShapeKind::Csg { op, children, smooth })
    }

    /// A modifier node, or `None` for poison.
    pub(super) fn modifier(&mut self, m: Modifier, a: &BoundArgs) -> Option<ShapeKind> {
        Some(match m {
            Modifier::Round => {
                let RoundArgs { shape: Value::Shape(child), r } = RoundArgs::from_args(a) else { return None };
                ShapeKind::Round { child, radius: r }
            }
            Modifier::Shell => {
                let ShellArgs { shape: Value::Shape(child), thickness } = ShellArgs::from_args(a) else { return None };
                ShapeKind::Shell { child, thickness }
            }
            Modifier::Repeat => {
                let RepeatArgs { shape: Value::Shape(child), period, count } = RepeatArgs::from_args(a) else {
                    return None;
                };
                ShapeKind::Repeat { child, period, count: [count.x as u32, count.y as u32, count.z as u32] }
            }
        })
    }
}
