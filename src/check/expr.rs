//! Expressions: literals, names, operators, indexing and calls (transforms are in
//! [`super::transform`]).

use std::rc::Rc;

use glam::DVec3;

use super::{Bound, Ctx, Value, MAX_EXPR_DEPTH, MAX_LIST};
use crate::builtins::{self, Kind};
use crate::diag::{codes, suggest, Diagnostic};
use crate::ir::dump_num;
use crate::ir::field::FieldTy as FTy;
use crate::span::Span;
use crate::syntax::ast::{self, BinOp, ExprKind};

/// An evaluated call argument.
pub(super) struct ArgVal {
    pub name: Option<ast::Ident>,
    pub value: Value,
    pub span: Span,
}

/// Words users reach for that scnc spells differently.
pub(super) const SYNONYMS: &[(&str, &str)] = &[
    ("radius", "r"),
    ("height", "half_height"),
    ("colour", "color"),
    ("reflect", "reflective"),
    ("reflectivity", "reflective"),
    ("shininess", "specular"),
    ("direction", "towards"),
];

impl Ctx<'_> {
    pub(super) fn expr(&mut self, e: &ast::Expr) -> Value {
        if !self.burn(1, e.span) {
            return Value::Error;
        }
        if self.expr_depth >= MAX_EXPR_DEPTH {
            if std::mem::replace(&mut self.too_deep, true) {
                return Value::Error;
            }
            self.report(
                Diagnostic::error(
                    codes::TOO_DEEP,
                    e.span,
                    "expression nests too deeply",
                    format!("nesting depth {MAX_EXPR_DEPTH} is exceeded here"),
                )
                .with_note(format!(
                    "expressions may nest at most {MAX_EXPR_DEPTH} operators, calls and transforms deep"
                )),
            );
            return Value::Error;
        }
        self.expr_depth += 1;
        let v = self.expr_inner(e);
        self.expr_depth -= 1;
        if let Some(ix) = &mut self.index {
            ix.typed(e.span, (!v.is_error()).then(|| v.ty_name()));
        }
        v
    }

    fn expr_inner(&mut self, e: &ast::Expr) -> Value {
        match &e.kind {
            ExprKind::Error => Value::Error,
            // Malformed numbers were reported by the lexer and arrive as `None`.
            ExprKind::Number(None) => Value::Error,
            ExprKind::Number(Some(x)) => match *x {
                x if x.is_finite() => Value::Num(x),
                _ => {
                    self.report(
                        Diagnostic::error(
                            codes::NOT_FINITE,
                            e.span,
                            "number is too large",
                            "this does not fit a 64-bit float",
                        )
                        .with_note("the largest number is about 1.8e308"),
                    );
                    Value::Error
                }
            },
            ExprKind::Bool(b) => Value::Bool(*b),
            ExprKind::Str(s) => Value::Str(Rc::from(s.as_str())),
            ExprKind::HexColor(c) => Value::Color(DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)),
            ExprKind::Ident(id) => self.ident(id),
            ExprKind::List(items) => self.list(items, e.span),
            ExprKind::Index { base, index } => {
                let b = self.expr(base);
                let i = self.expr(index);
                self.index(b, base.span, i, index.span)
            }
            ExprKind::Component { base, axis } => {
                let b = self.expr(base);
                self.component(b, base.span, axis)
            }
            ExprKind::Field { param, body } => self.field_literal(param, body),
            ExprKind::Neg(inner) => match self.expr(inner) {
                Value::Num(x) => Value::Num(-x),
                Value::Vec3(v) => Value::Vec3(-v),
                Value::Sym(s) => self.symbolic_neg(s, e.span),
                Value::Error => Value::Error,
                other => {
                    self.report(
                        Diagnostic::error(
                            codes::BAD_OPERANDS,
                            e.span,
                            format!("cannot negate a `{}`", other.ty_name()),
                            other.this_is(),
                        )
                        .with_note("`-` applies to numbers and vectors"),
                    );
                    Value::Error
                }
            },
            ExprKind::Binary { op: op @ (BinOp::And | BinOp::Or), lhs, rhs } => self.logic(*op, lhs, rhs),
            ExprKind::Binary { .. } => self.binary_chain(e),
            ExprKind::Not(inner) => {
                let v = self.expr(inner);
                if let Value::Sym(s) = v {
                    return self.symbolic_not(s, e.span);
                }
                match self.condition(&v, inner.span, "the operand of `not`") {
                    Some(b) => Value::Bool(!b),
                    None => Value::Error,
                }
            }
            ExprKind::If { cond, then, otherwise } => self.if_expr(cond, then, otherwise),
            ExprKind::Comprehension { generators, filter, body } => {
                self.comprehension(generators, filter.as_deref(), body, e.span)
            }
            ExprKind::Call { callee, args } => self.call(callee, args, e.span),
            ExprKind::Mesh { generator, args } => self.mesh_call(generator, args, e.span),
            ExprKind::Transform { op, op_span, target, arg } => {
                let t = self.expr(target);
                let a = self.expr(arg);
                self.transform(*op, *op_span, t, target.span, a, arg.span, e.span)
            }
        }
    }

    fn ident(&mut self, id: &ast::Ident) -> Value {
        if let Some(b) = self.lookup(id) {
            return match &b.bound {
                Bound::Value(v) => v.clone(),
                Bound::Func(f) => {
                    self.report(
                        Diagnostic::error(
                            codes::NOT_A_VALUE,
                            id.span,
                            format!("`{}` is a function, not a value", id.name),
                            "used as a value here",
                        )
                        .with_label(b.span, "defined here")
                        .with_hint(format!(
                            "try calling it: `{}({})`",
                            id.name,
                            f.params.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
                        )),
                    );
                    Value::Error
                }
            };
        }
        if let Some(c) = builtins::constant(&id.name) {
            if let Some(ix) = &mut self.index {
                ix.constants.insert(id.span, c);
            }
            return Value::Num(match c.value {
                builtins::ConstValue::Num(x) => x,
                builtins::ConstValue::Clock => self.time.clock,
                builtins::ConstValue::Frame => f64::from(self.time.frame),
            });
        }
        if let Some(b) = builtins::lookup(&id.name, Kind::Function) {
            let example = if b.params.iter().any(|p| p.default == builtins::Default::Required) || b.variadic.is_some() {
                "…"
            } else {
                ""
            };
            self.report(
                Diagnostic::error(
                    codes::NOT_A_VALUE,
                    id.span,
                    format!("`{}` is a builtin function, not a value", id.name),
                    "used as a value here",
                )
                .with_hint(format!("try calling it: `{}({example})`", id.name))
                .with_note(format!("signature: {}", b.signature())),
            );
            return Value::Error;
        }
        let mut candidates = self.names_in_scope(false);
        candidates.extend(builtins::CONSTANTS.iter().map(|c| c.name.to_string()));
        let mut d = Diagnostic::error(
            codes::UNKNOWN_NAME,
            id.span,
            format!("unknown name `{}`", id.name),
            "not found in this scope",
        );
        if let Some(g) = crate::diag::guesses::guess(&id.name) {
            d = d.with_hint(g.hint);
        } else if let Some(s) = suggest(&id.name, candidates.iter().map(String::as_str)) {
            d = d.with_replacement(id.span, s);
        } else if builtins::lookup(&id.name, Kind::MeshGenerator).is_some() {
            d = d.with_hint(format!("`{}` is a mesh generator: try `mesh {}(…)`", id.name, id.name));
        }
        self.report(d);
        Value::Error
    }

    fn list(&mut self, items: &[ast::Expr], span: Span) -> Value {
        if items.len() > MAX_LIST {
            self.host().list_too_long(span, format!("this list has {} elements", items.len()));
            return Value::Error;
        }
        let values: Vec<(Value, Span)> = items.iter().map(|e| (self.expr(e), e.span)).collect();
        if values.iter().any(|(v, _)| v.is_error()) {
            return Value::Error;
        }
        if values.len() == 3 && values.iter().all(|(v, _)| matches!(v, Value::Num(_))) {
            let n = |i: usize| if let Value::Num(x) = values[i].0 { x } else { 0.0 };
            return Value::Vec3(DVec3::new(n(0), n(1), n(2)));
        }
        // Three numbers, some depending on a field's point: a vector that does too.
        let num = |v: &Value| matches!(v, Value::Num(_)) || matches!(v, Value::Sym(e) if e.ty == FTy::Num);
        if values.len() == 3 && values.iter().all(|(v, _)| num(v)) {
            let c = |i: usize| values[i].0.as_field().unwrap_or_else(|| crate::ir::field::FieldExpr::num(0.0));
            return Value::Sym(crate::ir::field::FieldExpr::vector([c(0), c(1), c(2)]));
        }
        self.uniform_list(values).unwrap_or(Value::Error)
    }

    /// A list of `values` if they share one type, else `None` after reporting the first
    /// element that differs.
    pub(super) fn uniform_list(&mut self, values: Vec<(Value, Span)>) -> Option<Value> {
        // Judged against the first element that is not an empty list, which fits any.
        let typed = values.iter().find(|(v, _)| !matches!(v, Value::List(l) if l.is_empty())).or(values.first());
        if let Some((first, first_span)) = typed {
            let name = |v: &Value| v.ty_name();
            for (v, s) in &values {
                if !v.same_type(first) {
                    self.report(
                        Diagnostic::error(
                            codes::TYPE_MISMATCH,
                            *s,
                            format!(
                                "list elements must have one type: expected `{}`, found `{}`",
                                name(first),
                                name(v)
                            ),
                            format!("this is a `{}`", name(v)),
                        )
                        .with_label(*first_span, format!("the first element is a `{}`", name(first))),
                    );
                    return None;
                }
            }
        }
        Some(Value::List(Rc::new(values.into_iter().map(|(v, _)| v).collect())))
    }

    fn index(&mut self, base: Value, base_span: Span, index: Value, index_span: Span) -> Value {
        if matches!(index, Value::Sym(_)) {
            self.depends_on_point(index_span, "an index");
            return Value::Error;
        }
        if let Value::Sym(e) = &base {
            if e.ty == FTy::Vec3 {
                if let Value::Num(i) = index {
                    if i.fract() == 0.0 && (0.0..3.0).contains(&i) {
                        let axis = ["x", "y", "z"][i as usize];
                        return self.component(base, base_span, &ast::Ident { name: axis.into(), span: index_span });
                    }
                }
            }
        }
        let len = match &base {
            Value::List(items) => items.len(),
            Value::Vec3(_) => 3,
            Value::Error => return Value::Error,
            other => {
                self.report(
                    Diagnostic::error(
                        codes::TYPE_MISMATCH,
                        base_span,
                        format!("cannot index into a `{}`", other.ty_name()),
                        other.this_is(),
                    )
                    .with_note("only lists and vectors can be indexed"),
                );
                return Value::Error;
            }
        };
        let i = match index {
            Value::Num(x) if x.fract() == 0.0 => x,
            Value::Num(x) => {
                self.report(
                    Diagnostic::error(
                        codes::NOT_INTEGER,
                        index_span,
                        "index must be a whole number",
                        format!("this is {}", dump_num(x)),
                    )
                    .with_hint("try `floor(…)`"),
                );
                return Value::Error;
            }
            Value::Error => return Value::Error,
            other => {
                self.report(Diagnostic::error(
                    codes::TYPE_MISMATCH,
                    index_span,
                    format!("expected `int`, found `{}`", other.ty_name()),
                    "index must be a whole number",
                ));
                return Value::Error;
            }
        };
        if i < 0.0 || i >= len as f64 {
            self.report(
                Diagnostic::error(
                    codes::INDEX_OUT_OF_BOUNDS,
                    index_span,
                    format!("index {} is out of bounds", dump_num(i)),
                    format!("the length is {len}"),
                )
                .with_note(format!("valid indices are 0 to {}", len.saturating_sub(1))),
            );
            return Value::Error;
        }
        match base {
            Value::List(items) => items[i as usize].clone(),
            Value::Vec3(v) => Value::Num(v[i as usize]),
            _ => Value::Error,
        }
    }

    /// A binary operation and the ones down its left operand (`a + b + c + …`, which
    /// parses as `((a + b) + c) + …`), evaluated in a loop: a long flat expression is
    /// not a deep one, and only its operands count towards [`MAX_EXPR_DEPTH`].
    fn binary_chain(&mut self, e: &ast::Expr) -> Value {
        // The links from the outermost down, and the operand below the last. `and` and
        // `or` decide whether their right side is evaluated: they stay nodes of their
        // own (reached through `expr`), never links.
        let (mut links, mut first) = (Vec::new(), e);
        while let ExprKind::Binary { op, lhs, rhs } = &first.kind {
            if matches!(op, BinOp::And | BinOp::Or) {
                break;
            }
            links.push((*op, &**rhs, first.span));
            first = lhs;
        }
        let mut acc = self.expr(first);
        let mut acc_span = first.span;
        for (i, &(op, rhs, span)) in links.iter().enumerate().rev() {
            // Each inner link costs fuel and is typed for the editor, as `expr` does for `e`.
            if i > 0 && !self.burn(1, span) {
                return Value::Error;
            }
            let b = self.expr(rhs);
            acc = self.binary(op, acc, acc_span, b, rhs.span, span);
            acc_span = span;
            if let (Some(ix), true) = (&mut self.index, i > 0) {
                ix.typed(span, (!acc.is_error()).then(|| acc.ty_name()));
            }
        }
        acc
    }

    /// `a op b` on values. Long because it is one match over the operators and the
    /// operands' kinds.
    fn binary(&mut self, op: BinOp, a: Value, a_span: Span, b: Value, b_span: Span, span: Span) -> Value {
        use Value::{Num, Vec3};
        if a.is_error() || b.is_error() {
            return Value::Error;
        }
        if matches!(op, BinOp::Div | BinOp::Rem) && matches!(a, Value::Sym(_)) {
            // A constant zero divisor is still refused below; a varying one is the field's.
        } else if let Some(v) = self.symbolic_binary(op, (&a, a_span), (&b, b_span), span) {
            return v;
        }
        match op {
            BinOp::Eq | BinOp::Ne => return self.equality(op, &a, a_span, &b, b_span, span),
            BinOp::Lt => return self.ordering(op, |x, y| x < y, &a, a_span, &b, b_span, span),
            BinOp::Le => return self.ordering(op, |x, y| x <= y, &a, a_span, &b, b_span, span),
            BinOp::Gt => return self.ordering(op, |x, y| x > y, &a, a_span, &b, b_span, span),
            BinOp::Ge => return self.ordering(op, |x, y| x >= y, &a, a_span, &b, b_span, span),
            BinOp::And | BinOp::Or => {
                let what = format!("an operand of `{}`", op.symbol());
                let (x, y) = (self.condition(&a, a_span, &what), self.condition(&b, b_span, &what));
                return match (x, y) {
                    (Some(x), Some(y)) => Value::Bool(if op == BinOp::And { x && y } else { x || y }),
                    _ => Value::Error,
                };
            }
            BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div | BinOp::Rem => {}
        }
        if matches!(op, BinOp::Div | BinOp::Rem) {
            let zero = match &b {
                Num(x) => *x == 0.0,
                Vec3(v) => v.x == 0.0 || v.y == 0.0 || v.z == 0.0,
                _ => false,
            };
            if zero {
                let what = if op == BinOp::Div { "division" } else { "remainder" };
                self.report(
                    Diagnostic::error(codes::NOT_FINITE, b_span, format!("{what} by zero"), "this is zero")
                        .with_label(span, "in this expression"),
                );
                return Value::Error;
            }
            if let Some(v) = self.symbolic_binary(op, (&a, a_span), (&b, b_span), span) {
                return v;
            }
        }
        let f = |x: f64, y: f64| match op {
            BinOp::Add => x + y,
            BinOp::Sub => x - y,
            BinOp::Mul => x * y,
            BinOp::Div => x / y,
            BinOp::Rem => x % y,
            // Not arithmetic: answered above. NaN would be reported as an overflow.
            BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge | BinOp::And | BinOp::Or => f64::NAN,
        };
        let v3 = |x: DVec3, y: DVec3| DVec3::new(f(x.x, y.x), f(x.y, y.y), f(x.z, y.z));
        let result = match (&a, &b) {
            (Num(x), Num(y)) => Num(f(*x, *y)),
            (Vec3(x), Vec3(y)) => Vec3(v3(*x, *y)),
            (Vec3(x), Num(y)) if matches!(op, BinOp::Mul | BinOp::Div | BinOp::Rem) => Vec3(v3(*x, DVec3::splat(*y))),
            (Num(x), Vec3(y)) if op == BinOp::Mul => Vec3(v3(DVec3::splat(*x), *y)),
            (Value::Color(x), Num(y)) if matches!(op, BinOp::Mul | BinOp::Div) => {
                Value::Color(v3(*x, DVec3::splat(*y)))
            }
            (Value::Color(x), Value::Color(y)) if matches!(op, BinOp::Add | BinOp::Sub) => Value::Color(v3(*x, *y)),
            (Value::List(x), Value::List(y)) if op == BinOp::Add => {
                if x.len() + y.len() > MAX_LIST {
                    self.report(Diagnostic::error(
                        codes::TOO_LARGE,
                        span,
                        "list is too long",
                        format!("the result would have {} elements", x.len() + y.len()),
                    ));
                    return Value::Error;
                }
                // Lists are values: joining copies both, so a list grown in a loop costs
                // its length every step, and that is what it burns.
                if !self.burn((x.len() + y.len()) as u64, span) {
                    return Value::Error;
                }
                Value::List(Rc::new(x.iter().chain(y.iter()).cloned().collect()))
            }
            _ => {
                let mut d = bad_operands(op, (&a, a_span), (&b, b_span), span);
                if matches!((&a, &b), (Value::Shape(_), Value::Shape(_))) {
                    let hint = match op {
                        BinOp::Add => "try `union(a, b)` to combine shapes",
                        BinOp::Sub => "try `subtract(a, b)` to cut one shape from another",
                        _ => "try `union`, `intersect` or `subtract`",
                    };
                    d = d.with_hint(hint);
                }
                self.report(d);
                return Value::Error;
            }
        };
        self.host().finite(result, span, || "arithmetic overflowed".into())
    }
}

/// "cannot apply `op` to `A` and `B`", each operand labelled with its type.
pub(super) fn bad_operands(
    op: BinOp,
    (a, a_span): (&Value, Span),
    (b, b_span): (&Value, Span),
    span: Span,
) -> Diagnostic {
    Diagnostic::error(
        codes::BAD_OPERANDS,
        span,
        format!("cannot apply `{}` to `{}` and `{}`", op.symbol(), a.ty_name(), b.ty_name()),
        format!("`{}` {} `{}` is not defined", a.ty_name(), op.symbol(), b.ty_name()),
    )
    .with_label(a_span, a.this_is())
    .with_label(b_span, b.this_is())
}

/// Equality of values that `==` compares; `None` for values it does not. Each pair of
/// values looked at costs a step of `steps`; past `limit` it stops with `Err` (a list
/// that shares itself, `[a, a]` forty levels deep, has 2⁴⁰ elements). A list compared
/// with itself is equal without a look inside (values are immutable, and never NaN).
fn equal(a: &Value, b: &Value, steps: &mut u64, limit: u64) -> Result<Option<bool>, ()> {
    *steps += 1;
    if *steps > limit {
        return Err(());
    }
    Ok(Some(match (a, b) {
        (Value::Num(x), Value::Num(y)) => x == y,
        (Value::Bool(x), Value::Bool(y)) => x == y,
        (Value::Str(x), Value::Str(y)) => x == y,
        (Value::Vec3(x), Value::Vec3(y)) | (Value::Color(x), Value::Color(y)) => x == y,
        (Value::List(x), Value::List(y)) => {
            if Rc::ptr_eq(x, y) {
                return Ok(Some(true));
            }
            if x.len() != y.len() {
                return Ok(Some(false));
            }
            for (p, q) in x.iter().zip(y.iter()) {
                match equal(p, q, steps, limit)? {
                    Some(true) => {}
                    other => return Ok(other.map(|_| false)),
                }
            }
            true
        }
        _ => return Ok(None),
    }))
}

impl Ctx<'_> {
    /// `and` / `or`: the right operand is evaluated only when the left does not decide.
    fn logic(&mut self, op: BinOp, lhs: &ast::Expr, rhs: &ast::Expr) -> Value {
        let what = format!("an operand of `{}`", op.symbol());
        let a = self.expr(lhs);
        if matches!(a, Value::Sym(_)) {
            // Decided per point: both sides, whatever the left is at any one point.
            let b = self.expr(rhs);
            let span = lhs.span.to(rhs.span);
            if b.is_error() {
                return Value::Error;
            }
            return self.symbolic_binary(op, (&a, lhs.span), (&b, rhs.span), span).unwrap_or(Value::Error);
        }
        match (op, self.condition(&a, lhs.span, &what)) {
            (BinOp::And, Some(false)) | (BinOp::Or, Some(true)) => {
                let _ = self.explore(rhs.span, |this| this.expr(rhs));
                Value::Bool(op == BinOp::Or)
            }
            (_, Some(_)) => {
                let b = self.expr(rhs);
                // `true and c` is `c`, also where `c` depends on a field's point.
                if matches!(&b, Value::Sym(s) if s.ty == FTy::Bool) {
                    return b;
                }
                self.condition(&b, rhs.span, &what).map_or(Value::Error, Value::Bool)
            }
            (_, None) => {
                // The left is unknown: the right is checked, as an untaken branch is.
                self.dry += 1;
                let b = self.expr(rhs);
                let _ = self.condition(&b, rhs.span, &what);
                self.dry -= 1;
                Value::Error
            }
        }
    }

    fn equality(&mut self, op: BinOp, a: &Value, a_span: Span, b: &Value, b_span: Span, span: Span) -> Value {
        let same = if a.same_type(b) || matches!((a, b), (Value::List(_), Value::List(_))) {
            // Counted against the fuel like every other step of evaluation.
            let mut steps = 0;
            let limit = self.fuel.min(u64::MAX - 1);
            match equal(a, b, &mut steps, limit) {
                Ok(eq) => {
                    if !self.burn(steps, span) {
                        return Value::Error;
                    }
                    eq
                }
                Err(()) => {
                    self.burn(limit + 1, span);
                    return Value::Error;
                }
            }
        } else {
            None
        };
        match same {
            Some(eq) => Value::Bool(eq == (op == BinOp::Eq)),
            None => {
                self.report(
                    Diagnostic::error(
                        codes::BAD_OPERANDS,
                        span,
                        format!("cannot compare `{}` with `{}`", a.ty_name(), b.ty_name()),
                        format!("`{}` {} `{}` is not defined", a.ty_name(), op.symbol(), b.ty_name()),
                    )
                    .with_label(a_span, a.this_is())
                    .with_label(b_span, b.this_is())
                    .with_note(
                        "`==` and `!=` compare two numbers, booleans, strings, vectors, colours or lists of them",
                    ),
                );
                Value::Error
            }
        }
    }

    /// `<`, `<=`, `>`, `>=` (`op`, which `holds` computes) on two numbers.
    #[allow(clippy::too_many_arguments, reason = "both operands with their spans, and the whole")]
    fn ordering(
        &mut self,
        op: BinOp,
        holds: fn(f64, f64) -> bool,
        a: &Value,
        a_span: Span,
        b: &Value,
        b_span: Span,
        span: Span,
    ) -> Value {
        if let (Value::Num(x), Value::Num(y)) = (a, b) {
            return Value::Bool(holds(*x, *y));
        }
        let (bad, bad_span) = if matches!(a, Value::Num(_)) { (b, b_span) } else { (a, a_span) };
        self.report(
            Diagnostic::error(
                codes::BAD_OPERANDS,
                bad_span,
                format!("`{}` orders numbers, not `{}`", op.symbol(), bad.ty_name()),
                bad.this_is(),
            )
            .with_label(span, "in this comparison"),
        );
        Value::Error
    }
}
