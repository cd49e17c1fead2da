//! Field builtins: `field`, `warp` and `displace` (shapes from field literals), and
//! `dist` and `noise3` (numbers inside their bodies). Each shape states the bound of its
//! body's slope that the march divides by: given with `lipschitz`, or estimated here
//! (`crate::field::lipschitz`), so `scnc ir` shows it and a steep field is reported
//! where it is written.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use glam::DVec3;

use super::BoundArgs;
use super::FieldFn;
use super::{Host, Value};
use crate::diag::{codes, Diagnostic};
use crate::field::{lipschitz, Estimate, SlopeDistances, Tape};
use crate::geom::DAabb;
use crate::ir::field::{FieldExpr, FieldKind, FieldTy, Unary, Val};
use crate::ir::{self, Lipschitz, ShapeKind};
use crate::sig::Range;
use crate::span::Span;

crate::params! {
    /// `field(f, bounds, lipschitz)`.
    pub struct FieldArgs {
        /// the field, `p => …` of the point `p`: inside where it is negative
        f: Value as FieldNum = required;
        /// the box the shape is cut to, `[[x0, y0, z0], [x1, y1, z1]]`; absent: all of space, like a plane
        bounds: Option<Value> as Bounds = derived;
        /// a bound of the body's slope; absent: estimated over `bounds`
        lipschitz: Option<f64> as Num = derived, Range::POSITIVE;
    }
}

crate::params! {
    /// `warp(shape, f, bounds, lipschitz)`.
    pub struct WarpArgs {
        /// the shape to deform
        shape: Value as Shape = required;
        /// where each point `p` looks in the shape, `p => …` giving a point
        f: Value as FieldVec = required;
        /// the box the result is cut to; absent: all of space
        bounds: Option<Value> as Bounds = derived;
        /// a bound of how much the map stretches a distance; absent: estimated over `bounds`
        lipschitz: Option<f64> as Num = derived, Range::POSITIVE;
    }
}

crate::params! {
    /// `displace(shape, f, bounds, lipschitz)`.
    pub struct DisplaceArgs {
        /// the shape whose surface moves
        shape: Value as Shape = required;
        /// what is added to its distance at `p`, `p => …` (negative pushes the surface out)
        f: Value as FieldNum = required;
        /// the box the result is cut to; absent: the shape's box grown by how far the surface can move
        bounds: Option<Value> as Bounds = derived;
        /// a bound of the displacement's slope; absent: estimated where the shape can reach
        lipschitz: Option<f64> as Num = derived, Range::POSITIVE;
    }
}

crate::params! {
    /// `dist(shape, q)`.
    pub struct DistArgs {
        /// the shape
        shape: Value as Shape = required;
        /// the point, inside a field's body
        q: Value as Vec3 = required;
    }
}

crate::params! {
    /// `noise3(q, size, seed)`.
    pub struct Noise3Args {
        /// the point
        q: Value as Vec3 = required;
        /// the feature size
        size: f64 as Num = 1.0, Range::POSITIVE;
        /// which noise; the same seed gives the same field on every machine
        seed: u32 as Int = 0, Range::closed(0.0, u32::MAX as f64);
    }
}

/// `x` rounded up to four significant digits.
fn round_up(x: f64) -> f64 {
    let unit = 10f64.powf(x.log10().floor() - 3.0);
    let r = (x / unit).ceil() * unit;
    // The product may round below `x` in the last bit.
    if r < x {
        r.next_up()
    } else {
        r
    }
}

/// Slope bounds above this or below its inverse are reported (W0007).
const STEEP: f64 = 2.5;

/// Slope estimates of the bodies analysed so far, by their instructions (constants to
/// the bit), box and the spheres their `dist` shapes are known by. The analysis is a
/// deterministic function of those, and up to a 32³ grid of interval evaluations: the
/// studio compiles on every keystroke and would analyse every unchanged body again.
static ESTIMATES: Mutex<Option<HashMap<String, Estimate>>> = Mutex::new(None);

/// Most estimates kept; past it the memo starts again.
const MAX_ESTIMATES: usize = 256;

/// Trigonometry in a body whose argument turns by less than this many degrees over the
/// body's domain was most likely written in radians (W0010).
const SMALL_TURN: f64 = 45.0;

/// The first `sin`, `cos` or `tan` in `body` whose argument depends on the point but
/// turns by less than [`SMALL_TURN`] over `domain` (the cube from −1 to 1 without one):
/// the function, its argument and the turn, sampled on a 5×5×5 grid. Arguments that
/// read `dist` are left alone: their turn depends on shapes, not on how the author wrote
/// angles.
fn radians_for_degrees(body: &Arc<FieldExpr>, domain: Option<DAabb>) -> Option<(Unary, Arc<FieldExpr>, f64)> {
    let (lo, hi) = domain.map_or((DVec3::splat(-1.0), DVec3::splat(1.0)), |b| (b.min, b.max));
    let mut stack = vec![body];
    while let Some(e) = stack.pop() {
        if let FieldKind::Unary(f @ (Unary::Sin | Unary::Cos | Unary::Tan), x) = &e.kind {
            if x.uses_point() && x.shapes().is_empty() {
                let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
                for i in 0..125 {
                    let t = DVec3::new((i % 5) as f64, (i / 5 % 5) as f64, (i / 25) as f64) / 4.0;
                    let (a, b) = match x.eval(lo + (hi - lo) * t, &|_, _| 0.0) {
                        Val::Num(v) => (v, v),
                        Val::Vec(v) => (v.min_element(), v.max_element()),
                    };
                    (min, max) = (min.min(a), max.max(b));
                }
                let turn = max - min;
                if turn.is_finite() && turn > 0.0 && turn < SMALL_TURN {
                    return Some((*f, x.clone(), turn));
                }
            }
        }
        stack.extend(e.operands());
    }
    None
}

/// Most operations one field body may have after folding (shared ones once).
pub const MAX_FIELD_OPS: usize = 100_000;

impl dyn Host + '_ {
    /// `field`, `warp` or `displace`, or `None` after reporting.
    pub(crate) fn field_shape(&mut self, f: FieldFn, a: &BoundArgs) -> Option<ShapeKind> {
        match f {
            FieldFn::Field => {
                let FieldArgs { f: Value::Field(lit), bounds, lipschitz: given } = FieldArgs::from_args(a) else {
                    return None;
                };
                let bounds = self.bounds(bounds, a.span_of("bounds"))?;
                let tape = self.field_tape(&lit.body, lit.span)?;
                let l = self.field_slope(&tape, bounds, given, lit.span, "this field")?;
                self.check_angles(&lit.body, bounds, lit.span);
                Some(ShapeKind::Field { body: lit.body.clone(), bounds, lipschitz: l, exact: None, sweep: None })
            }
            FieldFn::Warp => {
                let WarpArgs { shape: Value::Shape(child), f: Value::Field(lit), bounds, lipschitz: given } =
                    WarpArgs::from_args(a)
                else {
                    return None;
                };
                let bounds = self.bounds(bounds, a.span_of("bounds"))?;
                let tape = self.field_tape(&lit.body, lit.span)?;
                let l = self.field_slope(&tape, bounds, given, lit.span, "this warp")?;
                self.check_angles(&lit.body, bounds, lit.span);
                Some(ShapeKind::Warp { child, map: lit.body.clone(), bounds, lipschitz: l, domain_op: None })
            }
            FieldFn::Twist | FieldFn::Bend | FieldFn::Elongate | FieldFn::Symmetric | FieldFn::Polar => None,
            FieldFn::Displace => {
                let DisplaceArgs { shape: Value::Shape(child), f: Value::Field(lit), bounds, lipschitz: given } =
                    DisplaceArgs::from_args(a)
                else {
                    return None;
                };
                let bounds = self.bounds(bounds, a.span_of("bounds"))?;
                let tape = self.field_tape(&lit.body, lit.span)?;
                let (region, reach) = self.reach(&tape, &child, bounds, lit.span)?;
                let l = self.field_slope(&tape, region, given, lit.span, "this displacement")?;
                self.check_angles(&lit.body, region, lit.span);
                // A displacement's slope adds to the shape's 1: only the sum is far from 1.
                Some(ShapeKind::Displace { child, by: lit.body.clone(), bounds, lipschitz: l, reach })
            }
        }
    }

    /// `dist(shape, q)`: only inside a field's body, where there is a point to measure at.
    pub(crate) fn dist(&mut self, a: &BoundArgs) -> Value {
        let DistArgs { shape: Value::Shape(shape), q } = DistArgs::from_args(a) else {
            return Value::Error;
        };
        if !self.in_field_body() {
            self.report(
                Diagnostic::error(
                    codes::DEPENDS_ON_POINT,
                    a.call,
                    "`dist` measures a shape inside a field's body",
                    "not inside `p => …`",
                )
                .with_note("`dist(shape, q)` is the shape's signed distance at `q`, evaluated at every point `p`"),
            );
            return Value::Error;
        }
        match q.as_field() {
            Some(q) => Value::Sym(FieldExpr::new(FieldKind::Dist(shape, q), FieldTy::Num)),
            None => Value::Error,
        }
    }

    /// `noise3(q, size, seed)`: folded when `q` is known.
    pub(crate) fn noise3(&mut self, a: &BoundArgs) -> Value {
        let Noise3Args { q, size, seed } = Noise3Args::from_args(a);
        match q {
            Value::Vec3(v) => Value::Num(crate::geom::noise(v / size, seed)),
            Value::Sym(q) => Value::Sym(FieldExpr::new(FieldKind::Noise { at: q, size, seed }, FieldTy::Num)),
            _ => Value::Error,
        }
    }

    /// A `bounds` argument as a box, `Some(None)` when absent, `None` after reporting.
    fn bounds(&mut self, v: Option<Value>, span: Span) -> Option<Option<DAabb>> {
        let Some(v) = v else { return Some(None) };
        let corners: Option<Vec<DVec3>> = match &v {
            Value::List(items) if items.len() == 2 => {
                items.iter().map(|c| if let Value::Vec3(c) = c { Some(*c) } else { None }).collect()
            }
            _ => None,
        };
        match corners.as_deref() {
            Some(&[lo, hi]) if lo.cmplt(hi).all() => Some(Some(DAabb { min: lo, max: hi })),
            Some(&[lo, hi]) => {
                let shown = format!("from {} to {}", ir::dump_vec(lo), ir::dump_vec(hi));
                self.range_error(span, "bounds", "a box whose first corner is below its second on every axis", shown);
                None
            }
            _ => {
                self.report(
                    Diagnostic::error(
                        codes::TYPE_MISMATCH,
                        span,
                        format!("expected `[vec3, vec3]`, found `{}`", v.ty_name()),
                        v.this_is(),
                    )
                    .with_note("`bounds` is a box, its lowest and highest corners: `[[x0, y0, z0], [x1, y1, z1]]`"),
                );
                None
            }
        }
    }

    /// The body compiled, or `None` after reporting one too large.
    pub(crate) fn field_tape(&mut self, body: &Arc<FieldExpr>, span: Span) -> Option<Tape> {
        let tape = Tape::new(body);
        if tape.ops.len() > MAX_FIELD_OPS {
            self.report(
                Diagnostic::error(
                    codes::SHAPE_TOO_LARGE,
                    span,
                    "this field's body is too large",
                    format!("it takes {} operations", tape.ops.len()),
                )
                .with_note(format!("a field's body may take at most {MAX_FIELD_OPS} operations")),
            );
            return None;
        }
        Some(tape)
    }

    /// Warns (W0010) when the body's trigonometry barely turns over `domain`.
    fn check_angles(&mut self, body: &Arc<FieldExpr>, domain: Option<DAabb>, span: Span) {
        let Some((f, arg, turn)) = radians_for_degrees(body, domain) else { return };
        let (name, arg) = (f.name(), arg.source(60));
        let over = if domain.is_some() { "its `bounds`" } else { "the cube from -1 to 1" };
        self.report(
            Diagnostic::warning(
                codes::SMALL_TURN,
                span,
                format!(
                    "`{name}({arg})` turns by only {}° over {over}: `{name}` takes degrees",
                    crate::sig::short(turn)
                ),
                "in this body",
            )
            .with_note("trigonometry in scnc takes degrees, as in OpenSCAD and POV-Ray; shaders take radians")
            .with_hint(format!(
                "for radians write `{name}(({arg}) * 180 / pi)`; for a wave of period T, `{name}(360 * … / T)`"
            )),
        );
    }

    /// What the body's slope is bounded by: `given`, or estimated over `domain`;
    /// `None` after reporting that no bound was found. `what` names the field.
    pub(crate) fn field_slope(
        &mut self,
        tape: &Tape,
        domain: Option<DAabb>,
        given: Option<f64>,
        span: Span,
        what: &str,
    ) -> Option<Lipschitz> {
        if let Some(value) = given {
            return Some(Lipschitz { value, given: true });
        }
        let est = self.estimate(tape, domain);
        if !est.bound.is_finite() {
            let where_ = if domain.is_some() { "within its `bounds`" } else { "over all of space" };
            self.report(
                Diagnostic::error(
                    codes::UNBOUNDED_SLOPE,
                    span,
                    format!("{what} has no bound on its slope {where_}"),
                    "its slope cannot be bounded",
                )
                .with_note("a field is marched in steps of its value over its largest slope")
                .with_hint(if domain.is_some() {
                    "state one with `lipschitz = …`, or keep `bounds` away from where it is infinitely steep"
                } else {
                    "give `bounds = [[x0, y0, z0], [x1, y1, z1]]`, or state the bound with `lipschitz = …`"
                }),
            );
            return None;
        }
        // A constant has no slope; any positive bound marches it. Four significant
        // digits, rounded up, keep it a bound and the dump readable.
        let value = if est.bound > 0.0 { round_up(est.bound) } else { 1.0 };
        if !(1.0 / STEEP..=STEEP).contains(&value) {
            let shown = crate::sig::short(value);
            self.report(
                Diagnostic::warning(
                    codes::STEEP_FIELD,
                    span,
                    format!("{what}'s slope is up to {shown}, far from a distance's 1"),
                    format!("marched in steps of its value / {shown}"),
                )
                .with_note(
                    "a field whose slope varies takes more steps than a distance; one that is a distance \
                     scaled by k is exact divided by k",
                )
                .with_hint(format!("divide the body by {shown}, or state a bound you know with `lipschitz = …`")),
            );
        }
        Some(Lipschitz { value, given: false })
    }

    /// The bound of the slope of `tape` over `domain`, analysed once per distinct body.
    fn estimate(&self, tape: &Tape, domain: Option<DAabb>) -> Estimate {
        let spheres: Vec<_> = tape.shapes.iter().map(|s| ir::shape_sphere(s)).collect();
        // An outline is known by its address only, which a later one may reuse.
        let key = tape.outlines.is_empty().then(|| format!("{:?}{:?}{domain:?}{spheres:?}", tape.ops, tape.out));
        let memo = || ESTIMATES.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(found) = key.as_ref().and_then(|k| memo().as_ref().and_then(|m| m.get(k).cloned())) {
            return found;
        }
        let e = lipschitz(tape, domain, &SlopeDistances { spheres });
        if let Some(k) = key {
            let mut m = memo();
            let m = m.get_or_insert_with(HashMap::new);
            if m.len() >= MAX_ESTIMATES {
                m.clear();
            }
            m.insert(k, e.clone());
        }
        e
    }

    /// Where a displaced shape can reach and how far out its surface can move: the
    /// shape's box grown until the displacement's least value there pushes no further
    /// (`bounds`, when given, settles both). `None` after reporting no such box.
    fn reach(
        &mut self,
        tape: &Tape,
        child: &ir::Shape,
        bounds: Option<DAabb>,
        span: Span,
    ) -> Option<(Option<DAabb>, f64)> {
        if let Some(b) = bounds {
            return Some((Some(b), 0.0));
        }
        let Some(base) = ir::shape_bounds(child) else {
            // An unbounded shape stays unbounded; the displacement is bounded everywhere or not at all.
            return Some((None, 0.0));
        };
        let mut reach = 0.0f64;
        for _ in 0..8 {
            let region = base.grow(reach);
            let out = (-self.estimate(tape, Some(region)).range.lo).max(0.0);
            if !out.is_finite() {
                break;
            }
            if out <= reach * (1.0 + 1e-9) {
                return Some((Some(region), reach));
            }
            reach = out * 1.05;
        }
        self.report(
            Diagnostic::error(
                codes::UNBOUNDED_SLOPE,
                span,
                "how far this displacement moves the surface has no bound",
                "its least value keeps growing",
            )
            .with_hint("give `bounds = [[x0, y0, z0], [x1, y1, z1]]`"),
        );
        None
    }
}
