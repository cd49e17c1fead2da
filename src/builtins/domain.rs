//! Domain operations: `twist`, `bend`, `elongate`, `symmetric` and `polar`. Each is a
//! warp (`ir::ShapeKind::Warp`) whose map is written here, so it is marched, meshed,
//! bounded and dumped as any warp is; its box is derived from the shape's, and its
//! Lipschitz bound is exact (1, for the maps that do not stretch) or estimated over
//! that box as a written warp's is (`twist`, `bend`).

use std::sync::Arc;

use glam::DVec3;

use super::BoundArgs;
use super::FieldFn;
use super::{Host, Value};
use crate::diag::{codes, Diagnostic};
use crate::geom::DAabb;
use crate::ir::field::{Binary, FieldExpr, FieldKind, FieldTy, Unary};
use crate::ir::{self, DomainOp, Lipschitz, Shape, ShapeKind};
use crate::sig::Range;
use crate::span::Span;

crate::params! {
    /// `twist(shape, degrees_per_unit)`.
    pub struct TwistArgs {
        /// the shape, twisted about the `y` axis
        shape: Value as Shape = required;
        /// the slice at height `y` is turned as `rotate [0, degrees_per_unit * y, 0]` turns it
        degrees_per_unit: f64 as Num = required, Range::closed(-36000.0, 36000.0);
    }
}

crate::params! {
    /// `bend(shape, degrees_per_unit)`.
    pub struct BendArgs {
        /// the shape, its `y` axis bent towards `+x` (in the `xy` plane)
        shape: Value as Shape = required;
        /// how far the axis turns per unit of height, towards `+x` when positive
        degrees_per_unit: f64 as Num = required, Range::closed(-36000.0, 36000.0);
    }
}

crate::params! {
    /// `elongate(shape, by)`.
    pub struct ElongateArgs {
        /// the shape, cut at its centre planes and pulled apart
        shape: Value as Shape = required;
        /// half the slab inserted along each axis (a sphere elongated along `y` is a capsule)
        by: DVec3 as Vec3 = required, Range::NONNEG;
    }
}

crate::params! {
    /// `symmetric(shape, axes)`.
    pub struct SymmetricArgs {
        /// the shape; its half on the positive side of each axis is kept and mirrored
        shape: Value as Shape = required;
        /// the axes mirrored across: any of "x", "y", "z", e.g. "xz"
        axes: String as Str = required;
    }
}

crate::params! {
    /// `polar(shape, count)`.
    pub struct PolarArgs {
        /// the shape, one copy (its sector is centred on the `+x` axis)
        shape: Value as Shape = required;
        /// copies about the `y` axis, 360 / count degrees apart
        count: u32 as Int = required, Range::closed(1.0, 10000.0);
    }
}

/// Most copies a `polar` measures one by one when its shape crosses its sector.
const MAX_EXACT_COPIES: u32 = 64;

/// Expression builders for maps and bodies written here (also by `profiles`); every use
/// is well typed, so a refusal would be a bug, shown as NaN rather than a panic.
pub(super) fn un(f: Unary, x: &Arc<FieldExpr>) -> Arc<FieldExpr> {
    FieldExpr::unary(f, x.clone()).unwrap_or_else(|| FieldExpr::num(f64::NAN))
}

/// `f(a, b)`, see [`un`].
pub(super) fn bin(f: Binary, a: &Arc<FieldExpr>, b: &Arc<FieldExpr>) -> Arc<FieldExpr> {
    FieldExpr::binary(f, a.clone(), b.clone()).unwrap_or_else(|| FieldExpr::num(f64::NAN))
}

/// `[a·cos θ − b·sin θ, a·sin θ + b·cos θ]`: `(a, b)` turned by `θ` degrees.
fn turn(a: &Arc<FieldExpr>, b: &Arc<FieldExpr>, theta: &Arc<FieldExpr>) -> (Arc<FieldExpr>, Arc<FieldExpr>) {
    let (c, s) = (un(Unary::Cos, theta), un(Unary::Sin, theta));
    let first = bin(Binary::Sub, &bin(Binary::Mul, a, &c), &bin(Binary::Mul, b, &s));
    let second = bin(Binary::Add, &bin(Binary::Mul, a, &s), &bin(Binary::Mul, b, &c));
    (first, second)
}

impl dyn Host + '_ {
    /// A domain operation, or `None` after reporting.
    ///
    /// Long because it is one match over the domain operations, each arm its checks and its
    /// map written as a field expression.
    pub(crate) fn domain_shape(&mut self, f: FieldFn, a: &BoundArgs, span: Span) -> Option<ShapeKind> {
        let p = FieldExpr::point();
        let (x, y, z) = (FieldExpr::component(&p, 0), FieldExpr::component(&p, 1), FieldExpr::component(&p, 2));
        let exact = Lipschitz { value: 1.0, given: false };
        match f {
            FieldFn::Twist => {
                let TwistArgs { shape: Value::Shape(child), degrees_per_unit: k } = TwistArgs::from_args(a) else {
                    return None;
                };
                let b = self.bounded(&child, "twist", span)?;
                // The slice at height y is the shape's turned by k·y: it is seen at p
                // turned back (rotate [0, a, 0] takes (x, z) to (x cos a + z sin a,
                // −x sin a + z cos a), so back is the other way).
                let theta = bin(Binary::Mul, &FieldExpr::num(k), &y);
                let (qx, qz) = turn(&x, &z, &theta);
                let map = FieldExpr::vector([qx, y.clone(), qz]);
                let r = radius_about_y(&child, &b);
                let bounds = DAabb { min: DVec3::new(-r, b.min.y, -r), max: DVec3::new(r, b.max.y, r) };
                self.warp(child, map, bounds, span, "this twist", Some(DomainOp::Twist(k)))
            }
            FieldFn::Bend => {
                let BendArgs { shape: Value::Shape(child), degrees_per_unit: k } = BendArgs::from_args(a) else {
                    return None;
                };
                let b = self.bounded(&child, "bend", span)?;
                // The point at height y is turned about z by k·y degrees, so the shape's
                // y axis, seen where q.x = 0, lies at x = y·tan(k·y): towards +x.
                let theta = bin(Binary::Mul, &FieldExpr::num(k), &y);
                let (qx, qy) = turn(&x, &y, &theta);
                let map = FieldExpr::vector([qx, qy, z.clone()]);
                // A turn about the origin keeps the distance from it.
                let r = radius_from_origin(&child, &b);
                let bounds = DAabb { min: DVec3::splat(-r), max: DVec3::splat(r) };
                self.warp(child, map, bounds, span, "this bend", Some(DomainOp::Bend(k)))
            }
            FieldFn::Elongate => {
                let ElongateArgs { shape: Value::Shape(child), by: h } = ElongateArgs::from_args(a) else {
                    return None;
                };
                // q = p − clamp(p, −h, h): the shape's halves moved apart by the slab,
                // exact outside (Quilez's elongation) and 1-Lipschitz everywhere.
                let q = [0, 1, 2].map(|k| {
                    let c = FieldExpr::component(&p, k);
                    let clamped =
                        bin(Binary::Max, &bin(Binary::Min, &c, &FieldExpr::num(h[k])), &FieldExpr::num(-h[k]));
                    bin(Binary::Sub, &c, &clamped)
                });
                let bounds = ir::shape_bounds(&child).map(|b| DAabb { min: b.min - h, max: b.max + h });
                let domain_op = Some(DomainOp::Elongate(h));
                Some(ShapeKind::Warp { child, map: FieldExpr::vector(q), bounds, lipschitz: exact, domain_op })
            }
            FieldFn::Symmetric => {
                let SymmetricArgs { shape: Value::Shape(child), axes } = SymmetricArgs::from_args(a) else {
                    return None;
                };
                let mirrored = self.axes(&axes, a.span_of("axes"))?;
                let q = [0, 1, 2].map(|k| {
                    let c = FieldExpr::component(&p, k);
                    if mirrored[k] {
                        un(Unary::Abs, &c)
                    } else {
                        c
                    }
                });
                let bounds = ir::shape_bounds(&child).map(|b| {
                    let (mut lo, mut hi) = (b.min, b.max);
                    for k in (0..3).filter(|&k| mirrored[k]) {
                        let m = hi[k].max(0.0);
                        (lo[k], hi[k]) = (-m, m);
                    }
                    DAabb { min: lo, max: hi }
                });
                let domain_op = Some(DomainOp::Mirror(mirrored));
                Some(ShapeKind::Warp { child, map: FieldExpr::vector(q), bounds, lipschitz: exact, domain_op })
            }
            FieldFn::Polar => {
                let PolarArgs { shape: Value::Shape(child), count } = PolarArgs::from_args(a) else {
                    return None;
                };
                let b = self.bounded(&child, "polar", span)?;
                let w = 360.0 / f64::from(count);
                let r = radius_about_y(&child, &b);
                let bounds = DAabb { min: DVec3::new(-r, b.min.y, -r), max: DVec3::new(r, b.max.y, r) };
                if self.crosses_sector(&b, w) {
                    if count <= MAX_EXACT_COPIES {
                        // Every copy measured, the nearest taken: exact, `count` times the work.
                        let copies = (0..count).map(|j| {
                            let (qx, qz) = turn(&x, &z, &FieldExpr::num(-w * f64::from(j)));
                            FieldExpr::new(
                                FieldKind::Dist(child.clone(), FieldExpr::vector([qx, y.clone(), qz])),
                                FieldTy::Num,
                            )
                        });
                        let body =
                            copies.reduce(|a, b| bin(Binary::Min, &a, &b)).unwrap_or_else(|| FieldExpr::num(1.0));
                        return Some(ShapeKind::Field {
                            body,
                            bounds: Some(bounds),
                            lipschitz: exact,
                            exact: None,
                            sweep: None,
                        });
                    }
                    self.report(
                        Diagnostic::warning(
                            codes::CROSSES_SECTOR,
                            span,
                            format!("the shape reaches out of its sector of {w:.3}° and {count} copies are too many to measure each"),
                            "its copies meet at the sectors' edges",
                        )
                        .with_note(format!(
                            "up to {MAX_EXACT_COPIES} copies every copy is measured; beyond, each point sees only its own \
                             sector's copy, so where a part crosses its sector the part is cut and the distance \
                             can overestimate"
                        ))
                        .with_hint("move the shape out along +x, or make it smaller, so each copy stays within its sector"),
                    );
                }
                // The sector of p (its angle about y, from +x towards +z, in steps of w),
                // and p turned back by that many steps into the first sector: within a
                // sector a rotation, so a part within its sector keeps an exact distance.
                let angle = bin(Binary::Atan2, &z, &x);
                let step = un(Unary::Round, &bin(Binary::Div, &angle, &FieldExpr::num(w)));
                let back = bin(Binary::Mul, &step, &FieldExpr::num(-w));
                let (qx, qz) = turn(&x, &z, &back);
                let map = FieldExpr::vector([qx, y.clone(), qz]);
                // Within its sector, a part's copies are apart: their mesh is the part's, copied.
                let domain_op = (!self.crosses_sector(&b, w)).then_some(DomainOp::Polar(count));
                Some(ShapeKind::Warp { child, map, bounds: Some(bounds), lipschitz: exact, domain_op })
            }
            FieldFn::Field | FieldFn::Warp | FieldFn::Displace => None,
        }
    }

    /// A warp by `map` cut to `bounds`, its slope estimated there.
    fn warp(
        &mut self,
        child: Arc<Shape>,
        map: Arc<FieldExpr>,
        bounds: DAabb,
        span: Span,
        what: &str,
        domain_op: Option<DomainOp>,
    ) -> Option<ShapeKind> {
        let tape = self.field_tape(&map, span)?;
        let lipschitz = self.field_slope(&tape, Some(bounds), None, span, what)?;
        Some(ShapeKind::Warp { child, map, bounds: Some(bounds), lipschitz, domain_op })
    }

    /// The shape's box, or `None` after reporting that `op` needs one.
    fn bounded(&mut self, child: &Shape, op: &str, span: Span) -> Option<DAabb> {
        let b = ir::shape_bounds(child);
        if b.is_none() {
            self.report(
                Diagnostic::error(
                    codes::NEEDS_BOUNDED,
                    span,
                    format!("`{op}` needs a bounded shape"),
                    "this shape has no finite extent",
                )
                .with_note(format!(
                    "`{op}` moves points by how far they are from an axis: its box comes from the shape's"
                ))
                .with_hint("intersect the shape with a `box` first"),
            );
        }
        b
    }

    /// Which axes `text` names (`"x"`, `"xz"`, …), or `None` after reporting.
    fn axes(&mut self, text: &str, span: Span) -> Option<[bool; 3]> {
        let mut out = [false; 3];
        for c in text.chars() {
            match c {
                'x' => out[0] = true,
                'y' => out[1] = true,
                'z' => out[2] = true,
                _ => {
                    self.report(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            span,
                            format!("`{c}` is not an axis"),
                            "axes are any of \"x\", \"y\" and \"z\"",
                        )
                        .with_hint("try \"x\", \"xz\" or \"xyz\""),
                    );
                    return None;
                }
            }
        }
        if out == [false; 3] {
            self.report(
                Diagnostic::error(codes::OUT_OF_RANGE, span, "no axis given", "this names no axis")
                    .with_hint("try \"x\""),
            );
            return None;
        }
        Some(out)
    }

    /// Whether a shape with box `b` may reach out of its sector of `w` degrees about
    /// `+x`: a corner of its box in the `xz` plane, or the axis itself, lies outside it.
    fn crosses_sector(&self, b: &DAabb, w: f64) -> bool {
        if b.min.x <= 0.0 {
            return w < 360.0 || b.min.z < 0.0 && b.max.z > 0.0;
        }
        let corners = [(b.min.x, b.min.z), (b.min.x, b.max.z), (b.max.x, b.min.z), (b.max.x, b.max.z)];
        corners.iter().any(|&(x, z)| z.atan2(x).to_degrees().abs() > w / 2.0 + 1e-9)
    }
}

/// How far `shape` (whose box is `b`) reaches from the `y` axis: through the turns
/// about `y` below it (a twist, a `polar` of parts within their sectors), which keep
/// every point's distance from the axis, to the box of what they turn. The box alone
/// would do, but the box of a turned shape is the square around its circle, √2 wider
/// each level: fifty nested twists grew a unit sphere's box 2²⁵ times, and its mesh
/// found no surface.
fn radius_about_y(shape: &Shape, b: &DAabb) -> f64 {
    let mut node = shape;
    while let ShapeKind::Warp { child, domain_op: Some(DomainOp::Twist(_) | DomainOp::Polar(_)), .. } = &node.kind {
        node = child;
    }
    ir::shape_bounds(node).map_or(b.radius_about_y(), |inner| inner.radius_about_y().min(b.radius_about_y()))
}

/// How far `shape` (whose box is `b`) reaches from the origin: through the turns below
/// it (twists, bends, `polar`), which keep every point's distance from the origin, to
/// the box of what they turn (see [`radius_about_y`]).
fn radius_from_origin(shape: &Shape, b: &DAabb) -> f64 {
    let corner = |b: &DAabb| b.min.abs().max(b.max.abs()).length();
    let mut node = shape;
    while let ShapeKind::Warp {
        child,
        domain_op: Some(DomainOp::Twist(_) | DomainOp::Bend(_) | DomainOp::Polar(_)),
        ..
    } = &node.kind
    {
        node = child;
    }
    ir::shape_bounds(node).map_or(corner(b), |inner| corner(&inner).min(corner(b)))
}
