//! Shape builtins: primitives (declared in [`crate::primitive`]), CSG operators and
//! modifiers.

use glam::DVec3;

use super::BoundArgs;
use super::MAX_REPEAT;
use super::{Builtin, Modifier};
use super::{Host, Value, MAX_OBJECTS};
use crate::diag::{codes, Diagnostic};
use std::sync::Arc;

use crate::ir::{self, CsgOp, Primitive, ShapeKind};
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

impl dyn Host + '_ {
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
        let children: Vec<_> =
            a.rest.iter().filter_map(|(v, _)| if let Value::Shape(s) = v { Some(s.clone()) } else { None }).collect();
        if op == CsgOp::Intersect || smooth > 0.0 {
            if let Some(crowd) = crowded(&children, smooth) {
                let why = "an `intersect`, or a smooth `union` or `subtract`, cannot skip a part that reaches the \
                           point";
                let hint = "combine fewer parts, spread them apart, or use a sharp `union` (pruned by a hierarchy)";
                let (name, label) = (b.name, "every step of a ray there evaluates all of them");
                let refused = crowd > MAX_CROWD;
                self.report(
                    if refused {
                        Diagnostic::error(
                            codes::TOO_LARGE,
                            a.call,
                            format!("{crowd} parts of this `{name}` overlap one place"),
                            label,
                        )
                        .with_note(format!("{why}; at most {MAX_CROWD} parts may overlap one place"))
                    } else {
                        Diagnostic::warning(
                            codes::CROWDED_CSG,
                            a.call,
                            format!("{crowd} parts of this `{name}` overlap one place"),
                            label,
                        )
                        .with_note(format!("{why}; {crowd} distances a step make a large image take minutes"))
                    }
                    .with_hint(hint),
                );
                if refused {
                    return None;
                }
            }
        }
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

/// Parts of a combination overlapping one place from which [`crowded`] warns.
pub const CROWDED_PARTS: usize = 1_000;

/// The most parts of a combination that may overlap one place: each is evaluated at
/// every step there (what that costs at 10,000 and 100,000: docs/limits.md).
pub const MAX_CROWD: usize = 10_000;

/// The most parts whose boxes (grown by the blend `smooth`) hold one point, sampled at up
/// to 64 parts' centres, when it is at least [`CROWDED_PARTS`]; an unbounded part holds
/// every point.
fn crowded(children: &[Arc<ir::Shape>], smooth: f64) -> Option<usize> {
    if children.len() < CROWDED_PARTS {
        return None;
    }
    let boxes: Vec<Option<crate::geom::DAabb>> =
        children.iter().map(|c| ir::shape_bounds(c).map(|b| b.grow(smooth))).collect();
    let step = (children.len() / 64).max(1);
    let most = (0..children.len())
        .step_by(step)
        .filter_map(|i| boxes[i].map(|b| b.centre()))
        .map(|p| boxes.iter().filter(|b| b.is_none_or(|b| p.cmpge(b.min).all() && p.cmple(b.max).all())).count())
        .max()
        .unwrap_or(children.len());
    (most >= CROWDED_PARTS).then_some(most)
}
