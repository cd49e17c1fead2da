//! Expressions: literals, names, operators, indexing, calls and transforms.

use std::collections::HashMap;
use std::rc::Rc;
use std::sync::Arc;

use glam::{DAffine3, DMat3, DVec3};

use super::builtins::{self, Builtin, Kind, Ty};
use super::{Bound, Ctx, Func, Value, MAX_CALL_DEPTH, MAX_EXPR_DEPTH, MAX_LIST};
use crate::diag::{codes, suggest, Diagnostic};
use crate::ir::{self, dump_num};
use crate::span::Span;
use crate::syntax::ast::{self, BinOp, ExprKind, TransformOp};

/// An evaluated call argument.
pub(super) struct ArgVal {
    pub name: Option<ast::Ident>,
    pub value: Value,
    pub span: Span,
}

/// Arguments bound to a builtin's parameters, after arity, name and type checks.
pub(super) struct BoundArgs {
    /// One slot per parameter: the value and the span to blame for it.
    pub vals: Vec<Option<(Value, Span)>>,
    /// Variadic positional arguments.
    pub rest: Vec<(Value, Span)>,
    /// The whole call.
    pub call: Span,
}

/// Words users reach for that scnc spells differently.
const SYNONYMS: &[(&str, &str)] = &[
    ("radius", "r"),
    ("height", "half_height"),
    ("colour", "color"),
    ("reflect", "reflective"),
    ("reflectivity", "reflective"),
    ("shininess", "specular"),
    ("direction", "towards"),
];

fn vec3_of(v: &Value) -> Option<DVec3> {
    match v {
        Value::Vec3(v) => Some(*v),
        _ => None,
    }
}

impl Ctx<'_> {
    pub(super) fn expr(&mut self, e: &ast::Expr) -> Value {
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
            // Malformed numbers were reported by the lexer and arrive empty.
            ExprKind::Number(text) if text.is_empty() => Value::Error,
            ExprKind::Number(text) => match text.parse::<f64>() {
                Ok(x) if x.is_finite() => Value::Num(x),
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
            ExprKind::Neg(inner) => match self.expr(inner) {
                Value::Num(x) => Value::Num(-x),
                Value::Vec3(v) => Value::Vec3(-v),
                Value::Error => Value::Error,
                other => {
                    self.report(
                        Diagnostic::error(
                            codes::BAD_OPERANDS,
                            e.span,
                            format!("cannot negate a `{}`", other.ty_name()),
                            format!("this is a `{}`", other.ty_name()),
                        )
                        .with_note("`-` applies to numbers and vectors"),
                    );
                    Value::Error
                }
            },
            ExprKind::Binary { op, lhs, rhs } => {
                let a = self.expr(lhs);
                let b = self.expr(rhs);
                self.binary(*op, a, lhs.span, b, rhs.span, e.span)
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
        if let Some((_, x)) = builtins::CONSTANTS.iter().find(|(n, _)| *n == id.name) {
            return Value::Num(*x);
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
        candidates.extend(builtins::CONSTANTS.iter().map(|(n, _)| n.to_string()));
        let mut d = Diagnostic::error(
            codes::UNKNOWN_NAME,
            id.span,
            format!("unknown name `{}`", id.name),
            "not found in this scope",
        );
        if let Some(s) = suggest(&id.name, candidates.iter().map(String::as_str)) {
            d = d.with_replacement(id.span, s);
        } else if builtins::lookup(&id.name, Kind::MeshGenerator).is_some() {
            d = d.with_hint(format!("`{}` is a mesh generator: try `mesh {}(…)`", id.name, id.name));
        }
        self.report(d);
        Value::Error
    }

    fn list(&mut self, items: &[ast::Expr], span: Span) -> Value {
        if items.len() > MAX_LIST {
            self.report(
                Diagnostic::error(
                    codes::TOO_LARGE,
                    span,
                    "list is too long",
                    format!("this list has {} elements", items.len()),
                )
                .with_note(format!("lists may hold at most {MAX_LIST} elements")),
            );
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
        if let Some((first, first_span)) = values.first() {
            let name = |v: &Value| v.ty_name();
            for (v, s) in &values[1..] {
                if name(v) != name(first) {
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
                    return Value::Error;
                }
            }
        }
        Value::List(Rc::new(values.into_iter().map(|(v, _)| v).collect()))
    }

    fn index(&mut self, base: Value, base_span: Span, index: Value, index_span: Span) -> Value {
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
                        format!("this is a `{}`", other.ty_name()),
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

    fn binary(&mut self, op: BinOp, a: Value, a_span: Span, b: Value, b_span: Span, span: Span) -> Value {
        use Value::{Num, Vec3};
        if a.is_error() || b.is_error() {
            return Value::Error;
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
        }
        let f = |x: f64, y: f64| match op {
            BinOp::Add => x + y,
            BinOp::Sub => x - y,
            BinOp::Mul => x * y,
            BinOp::Div => x / y,
            BinOp::Rem => x % y,
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
                Value::List(Rc::new(x.iter().chain(y.iter()).cloned().collect()))
            }
            _ => {
                let mut d = Diagnostic::error(
                    codes::BAD_OPERANDS,
                    span,
                    format!("cannot apply `{}` to `{}` and `{}`", op.symbol(), a.ty_name(), b.ty_name()),
                    format!("`{}` {} `{}` is not defined", a.ty_name(), op.symbol(), b.ty_name()),
                )
                .with_label(a_span, format!("this is a `{}`", a.ty_name()))
                .with_label(b_span, format!("this is a `{}`", b.ty_name()));
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
        let finite = match &result {
            Num(x) => x.is_finite(),
            Vec3(v) | Value::Color(v) => v.is_finite(),
            _ => true,
        };
        if !finite {
            self.report(Diagnostic::error(
                codes::NOT_FINITE,
                span,
                "arithmetic overflowed",
                "the result is not a finite number",
            ));
            return Value::Error;
        }
        result
    }

    fn eval_args(&mut self, args: &[ast::Arg]) -> Vec<ArgVal> {
        args.iter()
            .map(|a| ArgVal {
                name: a.name.clone(),
                value: self.expr(&a.value),
                span: a.name.as_ref().map_or(a.value.span, |n| n.span.to(a.value.span)),
            })
            .collect()
    }

    fn call(&mut self, callee: &ast::Ident, args: &[ast::Arg], span: Span) -> Value {
        let binding = self.lookup(callee);
        if let Some(b) = &binding {
            match &b.bound {
                Bound::Func(f) => {
                    let f = f.clone();
                    let args = self.eval_args(args);
                    let Some(values) = self.bind_user(&f, args, span, callee.span) else {
                        return Value::Error;
                    };
                    return self.call_user(&f, values, span);
                }
                Bound::Value(v) => {
                    let ty = v.ty_name();
                    self.report(
                        Diagnostic::error(
                            codes::NOT_A_VALUE,
                            callee.span,
                            format!("`{}` is a `{ty}`, not a function", callee.name),
                            "called here",
                        )
                        .with_label(b.span, "defined here as a value"),
                    );
                    return Value::Error;
                }
            }
        }
        let Some(builtin) = builtins::lookup(&callee.name, Kind::Function) else {
            let mut candidates: Vec<String> = self.names_in_scope(true);
            candidates.extend(builtins::names(Kind::Function).map(str::to_string));
            let mut d = Diagnostic::error(
                codes::UNKNOWN_FUNCTION,
                callee.span,
                format!("unknown function `{}`", callee.name),
                "not a builtin or a function in scope",
            );
            if builtins::lookup(&callee.name, Kind::MeshGenerator).is_some() {
                d = d.with_hint(format!("`{}` is a mesh generator: try `mesh {}(…)`", callee.name, callee.name));
            } else if let Some(s) = suggest(&callee.name, candidates.iter().map(String::as_str)) {
                d = d.with_replacement(callee.span, s);
            } else if matches!(callee.name.as_str(), "camera" | "render") {
                d = d.with_note(format!("`{}(…)` is a statement, not an expression", callee.name));
            }
            self.report(d);
            // Still evaluate the arguments, to report their own mistakes.
            let _ = self.eval_args(args);
            return Value::Error;
        };
        self.note_builtin(callee.span, builtin);
        self.apply_builtin(builtin, args, span)
    }

    /// Records in the index that `span` names `builtin`.
    fn note_builtin(&mut self, span: Span, builtin: &'static Builtin) {
        if let Some(ix) = &mut self.index {
            ix.builtins.insert(span, super::index::BuiltinUse { span, builtin, param: None });
        }
    }

    /// Evaluates the arguments, binds them and builds the builtin's value.
    fn apply_builtin(&mut self, builtin: &'static Builtin, args: &[ast::Arg], span: Span) -> Value {
        let args = self.eval_args(args);
        match self.bind_builtin(builtin, args, span) {
            Some(bound) => self.construct(builtin, bound),
            None => Value::Error,
        }
    }

    fn mesh_call(&mut self, generator: &ast::Ident, args: &[ast::Arg], span: Span) -> Value {
        let Some(builtin) = builtins::lookup(&generator.name, Kind::MeshGenerator) else {
            let mut d = Diagnostic::error(
                codes::NOT_A_MESH_GENERATOR,
                generator.span,
                format!("unknown mesh generator `{}`", generator.name),
                "not a mesh generator",
            );
            if generator.name == "sphere" {
                d = d
                    .with_hint("did you mean `uvsphere` or `icosphere`?")
                    .with_fix(generator.span, "uvsphere")
                    .with_fix(generator.span, "icosphere");
            } else if let Some(s) = suggest(&generator.name, builtins::names(Kind::MeshGenerator)) {
                d = d.with_replacement(generator.span, s);
            } else {
                d = d.with_note(format!(
                    "mesh generators: {}",
                    builtins::names(Kind::MeshGenerator).collect::<Vec<_>>().join(", ")
                ));
                if builtins::lookup(&generator.name, Kind::Function).is_some() {
                    d = d.with_hint(format!("try `mesh isosurface({}(…))` to triangulate any shape", generator.name));
                }
            }
            self.report(d);
            let _ = self.eval_args(args);
            return Value::Error;
        };
        self.note_builtin(generator.span, builtin);
        self.apply_builtin(builtin, args, span)
    }

    /// Matches arguments to parameter slots: positional ones in order (or all into `rest`
    /// for a variadic callee), named ones by name. Reports too many arguments, unknown
    /// names (with a suggestion) and arguments given twice; returns the slots, the extra
    /// positional values, and whether all went well. `note` is the callee's signature.
    #[allow(clippy::type_complexity, reason = "slots and variadic values, both with the span to blame")]
    fn bind_slots(
        &mut self,
        callee: &str,
        params: &[&str],
        variadic: bool,
        args: Vec<ArgVal>,
        call: Span,
        note: Option<String>,
    ) -> (Vec<Option<(Value, Span)>>, Vec<(Value, Span)>, bool) {
        let recovered = args.iter().any(|a| a.value.is_error() && a.name.is_none());
        let with_note = |d: Diagnostic| match &note {
            Some(n) => d.with_note(n.clone()),
            None => d,
        };
        let mut ok = true;
        let mut vals: Vec<Option<(Value, Span)>> = vec![None; params.len()];
        let mut rest = Vec::new();
        let mut next = 0;
        for arg in args {
            let idx = match &arg.name {
                None if variadic => {
                    rest.push((arg.value, arg.span));
                    continue;
                }
                None if next >= params.len() => {
                    if !recovered {
                        let plural = if params.len() == 1 { "" } else { "s" };
                        let d = Diagnostic::error(
                            codes::ARITY,
                            arg.span,
                            format!("`{callee}` takes {} argument{plural}, but more were given", params.len()),
                            "unexpected argument",
                        )
                        .with_label(call, "in this call");
                        self.report(with_note(d));
                    }
                    ok = false;
                    continue;
                }
                None => {
                    next += 1;
                    next - 1
                }
                Some(name) => match params.iter().position(|p| *p == name.name) {
                    Some(i) => i,
                    None => {
                        let mut d = Diagnostic::error(
                            codes::UNKNOWN_ARG,
                            name.span,
                            format!("`{callee}` has no parameter named `{}`", name.name),
                            "unknown parameter",
                        );
                        // `radius` means `r`, and so does a misspelt `radus`.
                        let known = SYNONYMS.iter().filter(|(_, p)| params.contains(p));
                        let word = suggest(&name.name, known.clone().map(|(w, _)| *w));
                        let synonym = known.clone().find(|(w, _)| *w == name.name || Some(*w) == word).map(|(_, p)| *p);
                        if let Some(s) = synonym.or_else(|| suggest(&name.name, params.iter().copied())) {
                            d = d.with_replacement(name.span, s);
                        }
                        self.report(with_note(d));
                        ok = false;
                        continue;
                    }
                },
            };
            if let Some((_, prev)) = &vals[idx] {
                self.report(
                    Diagnostic::error(
                        codes::DUPLICATE_ARG,
                        arg.span,
                        format!("argument `{}` is given twice", params[idx]),
                        "given again here",
                    )
                    .with_label(*prev, "first given here"),
                );
                ok = false;
                continue;
            }
            vals[idx] = Some((arg.value, arg.span));
        }
        (vals, rest, ok && !recovered)
    }

    /// Binds arguments to a builtin's parameters; `None` after reporting (or on poison).
    pub(super) fn bind_builtin(&mut self, b: &'static Builtin, mut args: Vec<ArgVal>, call: Span) -> Option<BoundArgs> {
        if let Some(ix) = &mut self.index {
            for name in args.iter().filter_map(|a| a.name.as_ref()) {
                if let Some(param) = b.params.iter().find(|p| p.name == name.name) {
                    let span = name.span;
                    ix.builtins.insert(span, super::index::BuiltinUse { span, builtin: b, param: Some(param) });
                }
            }
        }
        let recovered = args.iter().any(|a| a.value.is_error() && a.name.is_none());
        // `box(x, y, z)`: three numbers are one size vector.
        if b.name == "box"
            && args.len() == 3
            && args.iter().all(|a| a.name.is_none() && matches!(a.value, Value::Num(_)))
        {
            let n = |a: &ArgVal| if let Value::Num(x) = a.value { x } else { 0.0 };
            let span = args[0].span.to(args[2].span);
            let v = DVec3::new(n(&args[0]), n(&args[1]), n(&args[2]));
            args = vec![ArgVal { name: None, value: Value::Vec3(v), span }];
        }
        let names: Vec<&str> = b.params.iter().map(|p| p.name).collect();
        // A misspelt name is one mistake: the parameter it meant is not also "missing".
        let misspelt = args.iter().any(|a| a.name.as_ref().is_some_and(|n| !names.contains(&n.name.as_str())));
        let note = Some(format!("signature: {}", b.signature()));
        let (mut vals, mut rest, mut ok) = self.bind_slots(b.name, &names, b.variadic.is_some(), args, call, note);
        if !recovered && !misspelt {
            for (p, v) in b.params.iter().zip(&vals) {
                if v.is_none() && p.default == builtins::Default::Required {
                    self.report(
                        Diagnostic::error(
                            codes::MISSING_ARG,
                            call,
                            format!("missing argument `{}` of `{}`", p.name, b.name),
                            format!("`{}` is required", p.name),
                        )
                        .with_note(format!("signature: {}", b.signature())),
                    );
                    ok = false;
                }
            }
        }
        // Type checks.
        for (p, slot) in b.params.iter().zip(vals.iter_mut()) {
            if let Some((v, span)) = slot {
                match self.coerce(v, p.ty, *span, &format!("parameter `{}` of `{}`", p.name, b.name)) {
                    Some(c) => *v = c,
                    None => ok = false,
                }
            }
        }
        if let Some(ty) = b.variadic {
            for (v, span) in rest.iter_mut() {
                match self.coerce(v, ty, *span, &format!("every positional argument of `{}`", b.name)) {
                    Some(c) => *v = c,
                    None => ok = false,
                }
            }
        }
        let poisoned = vals.iter().flatten().any(|(v, _)| v.is_error()) || rest.iter().any(|(v, _)| v.is_error());
        (ok && !poisoned && !recovered).then_some(BoundArgs { vals, rest, call })
    }

    /// Converts `v` to `ty` or reports a mismatch; poison passes through.
    fn coerce(&mut self, v: &Value, ty: Ty, span: Span, what: &str) -> Option<Value> {
        let ok = match (ty, v) {
            (_, Value::Error) => return Some(Value::Error),
            (Ty::Num, Value::Num(_)) => true,
            (Ty::Int, Value::Num(x)) => {
                if x.fract() != 0.0 {
                    self.report(
                        Diagnostic::error(
                            codes::NOT_INTEGER,
                            span,
                            format!("expected a whole number, found {}", dump_num(*x)),
                            "not a whole number",
                        )
                        .with_note(format!("{what} is an `int`"))
                        .with_hint("try `floor(…)`"),
                    );
                    return None;
                }
                true
            }
            (Ty::Size, Value::Num(x)) => return Some(Value::Vec3(DVec3::splat(*x))),
            (Ty::Size | Ty::Vec3, Value::Vec3(_)) => true,
            (Ty::Bool, Value::Bool(_)) | (Ty::Str, Value::Str(_)) | (Ty::Color, Value::Color(_)) => true,
            (Ty::Material, Value::Material(_)) | (Ty::Shape, Value::Shape(_)) | (Ty::Mesh, Value::Mesh(_)) => true,
            (Ty::Light, Value::Light(_)) | (Ty::List, Value::List(_)) => true,
            _ => false,
        };
        if ok {
            return Some(v.clone());
        }
        let mut d = Diagnostic::error(
            codes::TYPE_MISMATCH,
            span,
            format!("expected `{ty}`, found `{}`", v.ty_name()),
            format!("this is a `{}`", v.ty_name()),
        )
        .with_note(format!("{what} is a `{ty}`"));
        match (ty, v) {
            (Ty::Color, Value::Vec3(c)) => {
                d = d.with_hint(format!("try `rgb({}, {}, {})`", dump_num(c.x), dump_num(c.y), dump_num(c.z)))
            }
            (Ty::Shape, Value::Mesh(_)) => {
                d = d.with_note("meshes cannot take part in CSG; shapes can be meshed with `mesh isosurface(…)`")
            }
            (Ty::Vec3, Value::Num(x)) => d = d.with_hint(format!("try `[{0}, {0}, {0}]`", dump_num(*x))),
            (Ty::Vec3, Value::List(items)) => {
                d = d.with_note(format!("a vector has exactly 3 numbers; this list has {}", items.len()))
            }
            _ => {}
        }
        self.report(d);
        None
    }

    fn bind_user(&mut self, f: &Func, args: Vec<ArgVal>, call: Span, callee_span: Span) -> Option<Vec<Value>> {
        let recovered = args.iter().any(|a| a.value.is_error() && a.name.is_none());
        let names: Vec<&str> = f.params.iter().map(|p| p.name.as_str()).collect();
        if let Some(ix) = &mut self.index {
            for name in args.iter().filter_map(|a| a.name.as_ref()) {
                if let Some(p) = f.params.iter().find(|p| p.name == name.name) {
                    ix.refer(name.span, p.span);
                }
            }
        }
        let misspelt = args.iter().any(|a| a.name.as_ref().is_some_and(|n| !names.contains(&n.name.as_str())));
        let (vals, _, mut ok) = self.bind_slots(&f.name, &names, false, args, callee_span, None);
        if recovered || misspelt {
            return None;
        }
        for (p, v) in f.params.iter().zip(&vals) {
            if v.is_none() {
                self.report(
                    Diagnostic::error(
                        codes::MISSING_ARG,
                        call,
                        format!("missing argument `{}` of `{}`", p.name, f.name),
                        format!("`{}` is required", p.name),
                    )
                    .with_label(p.span, "parameter declared here"),
                );
                ok = false;
            }
        }
        ok.then(|| vals.into_iter().map(|v| v.map_or(Value::Error, |(v, _)| v)).collect())
    }

    pub(super) fn call_user(&mut self, f: &Func, args: Vec<Value>, call: Span) -> Value {
        if self.call_depth >= MAX_CALL_DEPTH {
            self.report(
                Diagnostic::error(
                    codes::CALL_DEPTH,
                    call,
                    "function calls nest too deeply",
                    format!("call depth {MAX_CALL_DEPTH} is exceeded here"),
                )
                .with_note(format!("functions may call each other at most {MAX_CALL_DEPTH} levels deep")),
            );
            return Value::Error;
        }
        let mut frame = Vec::with_capacity(f.params.len());
        let mut seen = HashMap::new();
        for (p, v) in f.params.iter().zip(args) {
            let ty = (!v.is_error()).then(|| v.ty_name());
            self.note_def(p, super::index::DefKind::Param, ty, f.body.span.start, f.body.span.end);
            if seen.insert(p.name.clone(), ()).is_none() {
                frame.push(Rc::new(super::Binding { name: p.name.clone(), span: p.span, bound: Bound::Value(v) }));
            }
        }
        let saved = std::mem::replace(&mut self.scopes, vec![f.env.clone(), frame]);
        let saved_dir = std::mem::replace(&mut self.dir, f.file_dir.clone());
        self.call_depth += 1;
        let v = self.expr(&f.body);
        self.call_depth -= 1;
        self.dir = saved_dir;
        self.scopes = saved;
        v
    }

    #[allow(clippy::too_many_arguments, reason = "each span blames a different part of `a op b`")]
    fn transform(
        &mut self,
        op: TransformOp,
        op_span: Span,
        target: Value,
        target_span: Span,
        arg: Value,
        arg_span: Span,
        span: Span,
    ) -> Value {
        if target.is_error() || arg.is_error() {
            return Value::Error;
        }
        let kw = op.keyword();
        let bad_target = |this: &mut Self, note: &str| {
            this.report(
                Diagnostic::error(
                    codes::BAD_TRANSFORM,
                    op_span,
                    format!("cannot apply `{kw}` to a `{}`", target.ty_name()),
                    format!("`{kw}` needs a shape or a mesh"),
                )
                .with_label(target_span, format!("this is a `{}`", target.ty_name()))
                .with_note(note.to_string()),
            );
            Value::Error
        };
        if let Value::Light(light) = &target {
            return match (op, &light.kind, &arg) {
                (TransformOp::At, ir::LightKind::Point { .. }, Value::Vec3(p)) => {
                    let mut l = (**light).clone();
                    l.kind = ir::LightKind::Point { position: *p };
                    l.span = span;
                    Value::Light(Arc::new(l))
                }
                (TransformOp::At, ir::LightKind::Point { .. }, other) => {
                    self.report(Diagnostic::error(
                        codes::TYPE_MISMATCH,
                        arg_span,
                        format!("expected `vec3`, found `{}`", other.ty_name()),
                        "a position is a `vec3`",
                    ));
                    Value::Error
                }
                _ => bad_target(
                    self,
                    "only point lights can be placed, with `at`; a directional light takes `towards = […]`",
                ),
            };
        }
        if !matches!(target, Value::Shape(_) | Value::Mesh(_)) {
            return bad_target(self, "transforms apply to shapes and meshes");
        }
        if op == TransformOp::With {
            let Value::Material(m) = arg else {
                let mut d = Diagnostic::error(
                    codes::TYPE_MISMATCH,
                    arg_span,
                    format!("expected `material`, found `{}`", arg.ty_name()),
                    format!("this is a `{}`", arg.ty_name()),
                )
                .with_note("`with` takes a material");
                if matches!(arg, Value::Color(_)) {
                    d = d.with_hint("try `with material(color = …)`");
                }
                self.report(d);
                return Value::Error;
            };
            return match target {
                Value::Shape(s) => {
                    Value::Shape(Arc::new(ir::Shape { kind: ir::ShapeKind::Paint { child: s, material: m }, span }))
                }
                Value::Mesh(mesh) => {
                    let mut mesh = (*mesh).clone();
                    // The innermost material wins, as for shapes.
                    mesh.material.get_or_insert(m);
                    Value::Mesh(Arc::new(mesh))
                }
                _ => Value::Error,
            };
        }
        let xf = match (op, &arg) {
            (TransformOp::At, Value::Vec3(v)) => DAffine3::from_translation(*v),
            (TransformOp::Rotate, Value::Vec3(deg)) => DAffine3::from_mat3(rotation(*deg)),
            (TransformOp::Scale, Value::Num(_) | Value::Vec3(_)) => {
                let k = match arg {
                    Value::Num(k) => DVec3::splat(k),
                    Value::Vec3(v) => v,
                    _ => DVec3::ONE,
                };
                if k.min_element() <= 0.0 {
                    self.report(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            arg_span,
                            "scale factors must be greater than 0",
                            format!("this is {}", ir::dump_vec(k)),
                        )
                        .with_note(
                            "a zero scale flattens the shape to nothing; mirroring (negative scale) is not supported",
                        ),
                    );
                    return Value::Error;
                }
                if k.max_element() / k.min_element() > 1e6 {
                    self.report(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            arg_span,
                            "scale factors differ too much",
                            "the largest is over a million times the smallest",
                        )
                        .with_note("such a stretch loses all precision in the distance bound"),
                    );
                    return Value::Error;
                }
                DAffine3::from_scale(k)
            }
            _ => {
                let expected = if op == TransformOp::Scale { "num` or `vec3" } else { "vec3" };
                let mut d = Diagnostic::error(
                    codes::TYPE_MISMATCH,
                    arg_span,
                    format!("expected `{expected}`, found `{}`", arg.ty_name()),
                    format!("this is a `{}`", arg.ty_name()),
                )
                .with_note(format!("`{kw}` takes a `{expected}`"));
                if let Value::Num(x) = arg {
                    d = d.with_hint(format!("try `{kw} [{}, 0, 0]`", dump_num(x)));
                }
                self.report(d);
                return Value::Error;
            }
        };
        match target {
            Value::Shape(s) => Value::Shape(apply_xf(s, xf, span)),
            Value::Mesh(m) => {
                let mut m = (*m).clone();
                m.xf = xf * m.xf;
                Value::Mesh(Arc::new(m))
            }
            _ => Value::Error,
        }
    }
}

/// The study's rotation: about X, then Y, then Z, angles in degrees.
pub(crate) fn rotation(deg: DVec3) -> DMat3 {
    let r = deg * (std::f64::consts::PI / 180.0);
    DMat3::from_rotation_z(r.z) * DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x)
}

/// Applies `xf` on top of `shape`, merging consecutive transforms and keeping materials outside them.
fn apply_xf(shape: Arc<ir::Shape>, xf: DAffine3, span: Span) -> Arc<ir::Shape> {
    match &shape.kind {
        ir::ShapeKind::Transform { child, xf: inner } => {
            Arc::new(ir::Shape { kind: ir::ShapeKind::Transform { child: child.clone(), xf: xf * *inner }, span })
        }
        ir::ShapeKind::Paint { child, material } => Arc::new(ir::Shape {
            kind: ir::ShapeKind::Paint { child: apply_xf(child.clone(), xf, span), material: material.clone() },
            span: shape.span,
        }),
        ir::ShapeKind::Primitive(_)
        | ir::ShapeKind::Csg { .. }
        | ir::ShapeKind::Round { .. }
        | ir::ShapeKind::Shell { .. }
        | ir::ShapeKind::Repeat { .. } => {
            Arc::new(ir::Shape { kind: ir::ShapeKind::Transform { child: shape, xf }, span })
        }
    }
}

pub(super) fn vec3(v: &Value) -> DVec3 {
    vec3_of(v).unwrap_or(DVec3::ZERO)
}
