//! Field literals and the values that depend on their point.
//!
//! A literal's body is evaluated once, with the point an unknown: what the point flows
//! into becomes a [`Value::Sym`], an expression of it (`ir::field::FieldExpr`), and
//! everything else is computed as usual, so what does not depend on the point is
//! folded before rendering. Arithmetic, comparisons, `if`, `and`/`or`/`not`, indexing
//! and components, the maths builtins and user functions all take such values; what
//! must be known before rendering (a shape's size, a transform, a list index, a loop)
//! refuses them with E0313 at the span that depends on the point.

use std::rc::Rc;
use std::sync::Arc;

use super::expr::bad_operands;
use super::{index, Bound, Ctx, Value};
use crate::builtins::BoundArgs;
use crate::builtins::FieldLit;
use crate::builtins::{Builtin, Ctor, FieldForm, InFields, MathFn};
use crate::diag::{codes, Diagnostic};
use crate::ir::field::{Binary, FieldExpr, FieldKind, FieldTy, Unary};
use crate::span::Span;
use crate::syntax::ast::{self, BinOp};

impl Ctx<'_> {
    /// `param => body`: the body evaluated with `param` the point.
    pub(super) fn field_literal(&mut self, param: &ast::Ident, body: &ast::Expr) -> Value {
        self.env.push_scope();
        let ty = Some("vec3, the point the field is evaluated at".to_string());
        self.note_def(param, index::DefKind::Point, ty, body.span.start, body.span.end);
        self.bind(param, Bound::Value(Value::Sym(FieldExpr::point())));
        self.field_depth += 1;
        let v = self.expr(body);
        self.field_depth -= 1;
        self.env.pop_scope();
        match &v {
            Value::Error => Value::Error,
            Value::Num(_) | Value::Vec3(_) | Value::Sym(_) if v.ty() != Some(crate::builtins::Ty::Bool) => {
                match v.as_field() {
                    Some(body_expr) => Value::Field(Rc::new(FieldLit { body: body_expr, span: body.span })),
                    None => Value::Error,
                }
            }
            other => {
                self.report(
                    Diagnostic::error(
                        codes::TYPE_MISMATCH,
                        body.span,
                        format!("a field's body is a number or a vector, not a `{}`", other.ty_name()),
                        other.this_is(),
                    )
                    .with_note("`p => body` gives the body's value at every point `p`"),
                );
                Value::Error
            }
        }
    }

    /// Reports that what is at `span` depends on the point where `what` must be known
    /// before rendering.
    pub(super) fn depends_on_point(&mut self, span: Span, what: &str) {
        self.report(
            Diagnostic::error(
                codes::DEPENDS_ON_POINT,
                span,
                format!("{what} cannot depend on a field's point"),
                "this depends on the point",
            )
            .with_note(
                "inside `p => …` only numbers, vectors and truth values may vary with `p`; \
                 shapes, transforms, list indices and loops are fixed before rendering",
            ),
        );
    }

    /// `base.axis`: a vector's component.
    pub(super) fn component(&mut self, base: Value, base_span: Span, axis: &ast::Ident) -> Value {
        let i = match axis.name.as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => {
                self.report(
                    Diagnostic::error(
                        codes::UNKNOWN_NAME,
                        axis.span,
                        format!("a vector has no component `{}`", axis.name),
                        "not `x`, `y` or `z`",
                    )
                    .with_note("a vector's components are `.x`, `.y` and `.z`; a list's elements are `xs[i]`"),
                );
                return Value::Error;
            }
        };
        match base {
            Value::Vec3(v) => Value::Num(v[i]),
            Value::Sym(e) if e.ty == FieldTy::Vec3 => Value::Sym(component(&e, i)),
            Value::Error => Value::Error,
            other => {
                self.report(
                    Diagnostic::error(
                        codes::TYPE_MISMATCH,
                        base_span,
                        format!("`.{}` reads a vector's component, not a `{}`'s", axis.name, other.ty_name()),
                        other.this_is(),
                    )
                    .with_note("components are read from `vec3` values"),
                );
                Value::Error
            }
        }
    }

    /// `-x` of a value that depends on the point.
    pub(super) fn symbolic_neg(&mut self, e: Arc<FieldExpr>, span: Span) -> Value {
        self.sym(FieldExpr::unary(Unary::Neg, e), span, "`-`")
    }

    /// `not x` of a value that depends on the point.
    pub(super) fn symbolic_not(&mut self, e: Arc<FieldExpr>, span: Span) -> Value {
        self.sym(FieldExpr::unary(Unary::Not, e), span, "`not`")
    }

    /// The node `e`, or a report at `span` that `what` does not take these operands.
    fn sym(&mut self, e: Option<Arc<FieldExpr>>, span: Span, what: &str) -> Value {
        match e {
            Some(e) => Value::Sym(e),
            None => {
                self.report(Diagnostic::error(
                    codes::BAD_OPERANDS,
                    span,
                    format!("{what} is not defined for these operands"),
                    "in this expression",
                ));
                Value::Error
            }
        }
    }

    /// `a op b` where one side depends on the point; `None` when neither does.
    pub(super) fn symbolic_binary(
        &mut self,
        op: BinOp,
        (a, a_span): (&Value, Span),
        (b, b_span): (&Value, Span),
        span: Span,
    ) -> Option<Value> {
        if !matches!(a, Value::Sym(_)) && !matches!(b, Value::Sym(_)) {
            return None;
        }
        let f = match op {
            BinOp::Add => Binary::Add,
            BinOp::Sub => Binary::Sub,
            BinOp::Mul => Binary::Mul,
            BinOp::Div => Binary::Div,
            BinOp::Rem => Binary::Rem,
            BinOp::Eq => Binary::Eq,
            BinOp::Ne => Binary::Ne,
            BinOp::Lt => Binary::Lt,
            BinOp::Le => Binary::Le,
            BinOp::Gt => Binary::Gt,
            BinOp::Ge => Binary::Ge,
            BinOp::And => Binary::And,
            BinOp::Or => Binary::Or,
        };
        let (x, y) = (a.as_field(), b.as_field());
        let node = match (&x, &y) {
            (Some(x), Some(y)) => FieldExpr::binary(f, x.clone(), y.clone()),
            _ => None,
        };
        Some(match node {
            Some(e) => Value::Sym(e),
            None => {
                let mut d = bad_operands(op, (a, a_span), (b, b_span), span);
                if x.is_none() || y.is_none() {
                    d = d.with_note("only numbers, vectors and truth values can depend on a field's point");
                }
                self.report(d);
                Value::Error
            }
        })
    }

    /// `if c then a else b` where `c` depends on the point: both branches, chosen per point.
    pub(super) fn symbolic_if(&mut self, c: Arc<FieldExpr>, then: &ast::Expr, otherwise: &ast::Expr) -> Value {
        self.explored.extend([then.span, otherwise.span]);
        let a = self.expr(then);
        let b = self.expr(otherwise);
        if a.is_error() || b.is_error() {
            return Value::Error;
        }
        let (x, y) = (a.as_field(), b.as_field());
        match (x, y) {
            (Some(x), Some(y)) if x.ty == y.ty => Value::Sym(FieldExpr::new(FieldKind::Select(c, x.clone(), y), x.ty)),
            (Some(x), Some(y)) => {
                self.report(
                    Diagnostic::error(
                        codes::BRANCH_MISMATCH,
                        otherwise.span,
                        format!("`if` branches have different types: `{}` and `{}`", x.ty.name(), y.ty.name()),
                        b.this_is(),
                    )
                    .with_label(then.span, a.this_is())
                    .with_note("both branches must give the same type"),
                );
                Value::Error
            }
            (x, _) => {
                let bad = if x.is_none() { then.span } else { otherwise.span };
                self.report(
                    Diagnostic::error(
                        codes::DEPENDS_ON_POINT,
                        bad,
                        "an `if` whose condition depends on a field's point gives a number or a vector",
                        if x.is_none() { a.this_is() } else { b.this_is() },
                    )
                    .with_note("the branch is chosen at each point, so only numbers and vectors can be chosen"),
                );
                Value::Error
            }
        }
    }

    /// Whether `b` is a function of numbers, which may be given values that vary with
    /// a field's point (and then has a field form, or refuses them with its reason).
    pub(super) fn takes_symbolic(b: &Builtin) -> bool {
        !matches!(b.ctor.in_fields(), InFields::NotMaths)
    }

    /// A maths builtin with an argument that depends on the point.
    pub(super) fn symbolic_call(&mut self, b: &Builtin, a: &BoundArgs) -> Value {
        let form = match b.ctor.in_fields() {
            InFields::Yes(form) => form,
            InFields::No(why) => return self.not_in_fields(b, a, why),
            // Never called for these: `takes_symbolic` is false.
            InFields::NotMaths => return Value::Error,
        };
        let arg = |i: usize| a.vals.get(i).and_then(|s| s.as_ref()).and_then(|(v, _)| v.as_field());
        let un = |f: Unary| arg(0).and_then(|x| FieldExpr::unary(f, x));
        let bin = |f: Binary, i: usize, j: usize| arg(i).zip(arg(j)).and_then(|(x, y)| FieldExpr::binary(f, x, y));
        let node = match form {
            FieldForm::Unary(u) => un(u),
            FieldForm::Binary(f) => bin(f, 0, 1),
            FieldForm::Clamp => {
                let low = bin(Binary::Max, 0, 1);
                low.zip(arg(2)).and_then(|(l, hi)| FieldExpr::binary(Binary::Min, l, hi))
            }
            FieldForm::Mix => {
                // a + (b − a)·t: exactly `a` at 0 and `b` at 1, as `mix` of numbers is.
                let (x, y, t) = (arg(0), arg(1), arg(2));
                x.clone().zip(y).zip(t).and_then(|((x, y), t)| {
                    let d = FieldExpr::binary(Binary::Sub, y, x.clone())?;
                    FieldExpr::binary(Binary::Add, x, FieldExpr::binary(Binary::Mul, d, t)?)
                })
            }
            FieldForm::Sum => {
                let Some((Value::List(items), _)) = a.vals.first().and_then(|s| s.as_ref()) else {
                    return Value::Error;
                };
                let parts: Option<Vec<Arc<FieldExpr>>> = items.iter().map(Value::as_field).collect();
                parts.and_then(|ps| {
                    let mut ps = ps.into_iter();
                    let first = ps.next()?;
                    ps.try_fold(first, |acc, e| FieldExpr::binary(Binary::Add, acc, e))
                })
            }
            FieldForm::Fold(f) => {
                let mut parts = a.rest.iter().map(|(v, _)| v.as_field());
                let first = parts.next().flatten();
                parts.try_fold(first, |acc, x| Some(acc.zip(x).and_then(|(s, x)| FieldExpr::binary(f, s, x)))).flatten()
            }
            FieldForm::Dist => return self.host().dist(a),
            FieldForm::Noise3 => return self.host().noise3(a),
        };
        match node {
            Some(e) => Value::Sym(e),
            None => {
                self.report(
                    Diagnostic::error(
                        codes::DEPENDS_ON_POINT,
                        a.call,
                        format!("`{}` cannot take a value that depends on a field's point here", b.name),
                        "this depends on the point",
                    )
                    .with_note("inside `p => …`, maths builtins take numbers and vectors that vary with `p`"),
                );
                Value::Error
            }
        }
    }
}

impl Ctx<'_> {
    /// The error for a function of numbers given a value that varies with the point,
    /// which it has no field form for (`why`, as [`Ctor::in_fields`] declares it).
    fn not_in_fields(&mut self, b: &Builtin, a: &BoundArgs, why: &str) -> Value {
        let span = a.vals.iter().flatten().chain(&a.rest).find(|(v, _)| has_sym(v)).map_or(a.call, |(_, s)| *s);
        let mut d = Diagnostic::error(codes::DEPENDS_ON_POINT, span, why.to_string(), "this depends on the point");
        if matches!(b.ctor, Ctor::Math(MathFn::Random)) {
            d = d.with_hint("for a field that varies at random, try `noise3(p, size, seed)`");
        }
        self.report(d);
        Value::Error
    }
}

/// Whether the value, or an element of the list it is, depends on the point.
pub(super) fn has_sym(v: &Value) -> bool {
    match v {
        Value::Sym(_) => true,
        Value::List(items) => items.iter().any(has_sym),
        _ => false,
    }
}

/// Component `i` of a vector expression, folded through vectors built of components.
fn component(e: &Arc<FieldExpr>, i: usize) -> Arc<FieldExpr> {
    match &e.kind {
        FieldKind::Vector(xs) => xs[i].clone(),
        FieldKind::Vec(v) => FieldExpr::num(v[i]),
        _ => FieldExpr::new(FieldKind::Component(e.clone(), i), FieldTy::Num),
    }
}
