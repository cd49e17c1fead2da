//! Calls: arguments bound to parameters (positional, named, defaults, coercions), then
//! a builtin's constructor or a user function's body.

use glam::DVec3;

use super::expr::{ArgVal, SYNONYMS};
use super::field::has_sym;
use super::{Bound, Ctx, Env, Func, Value, MAX_CALL_DEPTH};
use crate::builtins::BoundArgs;
use crate::builtins::{self, Builtin, Ctor, Kind, Ty};
use crate::diag::guesses::guess;
use crate::diag::{codes, suggest, Diagnostic};
use crate::ir::dump_num;
use crate::span::Span;
use crate::syntax::ast;

impl Ctx<'_> {
    fn eval_args(&mut self, args: &[ast::Arg]) -> Vec<ArgVal> {
        args.iter()
            .map(|a| ArgVal {
                name: a.name.clone(),
                value: self.expr(&a.value),
                span: a.name.as_ref().map_or(a.value.span, |n| n.span.to(a.value.span)),
            })
            .collect()
    }

    pub(super) fn call(&mut self, callee: &ast::Ident, args: &[ast::Arg], span: Span) -> Value {
        let binding = self.lookup(callee);
        if let Some(b) = &binding {
            match &b.bound {
                Bound::Func(f) => {
                    let f = f.clone();
                    // The common call, positional arguments one per parameter, skips the
                    // general binding (and its allocations): this is the evaluator's
                    // inner loop for generated scenes.
                    if args.len() == f.params.len() && args.iter().all(|a| a.name.is_none()) {
                        let mut values = Vec::with_capacity(args.len());
                        for a in args {
                            values.push(self.expr(&a.value));
                        }
                        for (v, a) in values.iter_mut().zip(args) {
                            self.no_field_literal(v, a.value.span, &f.name);
                        }
                        if values.iter().any(Value::is_error) {
                            return Value::Error;
                        }
                        return self.call_user(&f, values, span, false);
                    }
                    let mut args = self.eval_args(args);
                    for a in &mut args {
                        self.no_field_literal(&mut a.value, a.span, &f.name);
                    }
                    let Some(values) = self.bind_user(&f, args, span, callee.span) else {
                        return Value::Error;
                    };
                    return self.call_user(&f, values, span, false);
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
        let all = builtins::overloads(&callee.name, Kind::Function);
        if all.is_empty() {
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
            } else if let Some(g) = guess(&callee.name) {
                // A call of `translate(…)` is OpenSCAD's form, not a misspelling of `at`.
                match g.replacement.filter(|r| *r != "at") {
                    Some(r) => d = d.with_replacement(callee.span, r).with_note(g.hint),
                    None => d = d.with_hint(g.hint),
                }
            } else if let Some(s) = suggest(&callee.name, candidates.iter().map(String::as_str)) {
                d = d.with_replacement(callee.span, s);
            } else if matches!(callee.name.as_str(), "camera" | "render") {
                d = d.with_note(format!("`{}(…)` is a statement, not an expression", callee.name));
            }
            self.report(d);
            // Still evaluate the arguments, to report their own mistakes.
            let _ = self.eval_args(args);
            return Value::Error;
        }
        self.apply_builtin(all, callee.span, args, span)
    }

    /// Turns a field literal passed to the user function `name` into poison, reported.
    fn no_field_literal(&mut self, v: &mut Value, span: Span, name: &str) {
        if matches!(v, Value::Field(_)) {
            self.report(
                Diagnostic::error(
                    codes::MISPLACED_FIELD,
                    span,
                    format!("a field literal cannot be passed to `{name}`"),
                    "a field literal",
                )
                .with_note("`p => …` is an argument of `field`, `warp` or `displace` only")
                .with_hint(format!("call `field(…)` inside `{name}` and pass what it needs instead")),
            );
            *v = Value::Error;
        }
    }

    /// Among a builtin's overloads `all` (`round(x)`, `round(shape, r)`; never empty),
    /// the one whose first parameter takes the first argument. The first when there is
    /// one, or when no argument decides (its binding reports what is missing); `None`
    /// after reporting a first argument that fits none of them.
    fn overload(&mut self, all: &'static [&'static Builtin], args: &[ArgVal]) -> Option<&'static Builtin> {
        let b = all[0];
        if all.len() == 1 {
            return Some(b);
        }
        let mut decider = None;
        for o in all {
            if let Some(arg) = first_arg(o, args) {
                if arg.value.is_error() || admits_part(o, &arg.value) {
                    return Some(o);
                }
                decider = decider.or(Some(arg));
            }
        }
        let Some(arg) = decider else {
            return Some(b);
        };
        let found = arg.value.ty_name();
        let expected: Vec<String> = all.iter().map(|o| format!("`{}`", deciding_ty(o))).collect();
        // `a or b`, `a, b or c`.
        let listed = match expected.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => expected.join(""),
        };
        let mut d = Diagnostic::error(
            codes::TYPE_MISMATCH,
            arg.span,
            format!("expected {listed}, found `{found}`"),
            format!("this is a `{found}`"),
        );
        for o in all {
            d = d.with_note(format!("{}: {}", o.signature(), o.doc));
        }
        self.report(d);
        None
    }

    /// Records in the index that `span` names `builtin`.
    fn note_builtin(&mut self, span: Span, builtin: &'static Builtin) {
        if let Some(ix) = &mut self.index {
            ix.builtins.insert(span, super::index::BuiltinUse { span, builtin, param: None });
        }
    }

    /// Evaluates the arguments, picks the overload of `all` they fit, binds them and
    /// builds the builtin's value; `name` is the callee's span, for the editor's index.
    fn apply_builtin(&mut self, all: &'static [&'static Builtin], name: Span, args: &[ast::Arg], span: Span) -> Value {
        // `floor(x)`, `random(i)`: a number in, a number out. The inner loop of generated
        // scenes, so a number argument skips binding and its allocations (what binding
        // would check of it holds: one positional argument, of the one type taken).
        let args = match (all, args) {
            ([b @ Builtin { ctor: Ctor::Math(f), .. }], [ast::Arg { name: None, value }]) if b.params.len() == 1 => {
                let x = self.expr(value);
                if let Value::Num(x) = x {
                    self.note_builtin(name, b);
                    return self.host().math(b, *f, x, value.span, span);
                }
                vec![ArgVal { name: None, value: x, span: value.span }]
            }
            _ => self.eval_args(args),
        };
        let Some(builtin) = self.overload(all, &args) else {
            return Value::Error;
        };
        self.note_builtin(name, builtin);
        // The maths builtins take values that depend on a field's point, and give one.
        let symbolic = Self::takes_symbolic(builtin);
        let outer = std::mem::replace(&mut self.symbolic_args, symbolic);
        let bound = self.bind_builtin(builtin, args, span);
        self.symbolic_args = outer;
        match bound {
            Some(bound) if symbolic && bound.vals.iter().flatten().chain(&bound.rest).any(|(v, _)| has_sym(v)) => {
                self.symbolic_call(builtin, &bound)
            }
            Some(bound) => self.host().construct(builtin, bound),
            None => Value::Error,
        }
    }

    pub(super) fn mesh_call(&mut self, generator: &ast::Ident, args: &[ast::Arg], span: Span) -> Value {
        let all = builtins::overloads(&generator.name, Kind::MeshGenerator);
        if all.is_empty() {
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
        }
        self.apply_builtin(all, generator.span, args, span)
    }

    /// Matches arguments to parameter slots: positional ones in order (or all into `rest`
    /// for a variadic callee), named ones by name. Reports too many arguments, unknown
    /// names (with a suggestion) and arguments given twice; returns the slots, the extra
    /// positional values, and whether all went well. `note` is the builtin whose signature
    /// a report shows.
    ///
    /// Long because positional, named and variadic arguments are matched in one pass, with
    /// their errors in the order they are reported.
    #[allow(clippy::type_complexity, reason = "slots and variadic values, both with the span to blame")]
    fn bind_slots(
        &mut self,
        callee: &str,
        params: &[&str],
        variadic: bool,
        args: Vec<ArgVal>,
        call: Span,
        note: Option<&'static Builtin>,
    ) -> (Vec<Option<(Value, Span)>>, Vec<(Value, Span)>, bool) {
        let recovered = args.iter().any(|a| a.value.is_error() && a.name.is_none());
        // The signature is formatted only when a mistake is reported.
        let with_note = |d: Diagnostic| match note {
            Some(b) => d.with_note(format!("signature: {}", b.signature())),
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
    ///
    /// Long because it binds in the order its errors are reported: slots, required
    /// arguments, types, ranges.
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
        let (mut vals, mut rest, mut ok, misspelt) =
            if b.variadic.is_none() && args.len() <= b.params.len() && args.iter().all(|a| a.name.is_none()) {
                // The common call, `floor(x)` or `sphere(r)`: the arguments fill the first
                // slots in order, with nothing to report; no names to match (nor the
                // allocations that takes).
                let mut vals = Vec::with_capacity(b.params.len());
                vals.extend(args.into_iter().map(|a| Some((a.value, a.span))));
                vals.resize(b.params.len(), None);
                (vals, Vec::new(), true, false)
            } else {
                let names: Vec<&str> = b.params.iter().map(|p| p.name).collect();
                // A misspelt name is one mistake: the parameter it meant is not also "missing".
                let misspelt = args.iter().any(|a| a.name.as_ref().is_some_and(|n| !names.contains(&n.name.as_str())));
                let (vals, rest, ok) = self.bind_slots(b.name, &names, b.variadic.is_some(), args, call, Some(b));
                (vals, rest, ok, misspelt)
            };
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
                match self.coerce(v, p.ty, *span, &|| format!("parameter `{}` of `{}`", p.name, b.name)) {
                    Some(c) => *v = c,
                    None => ok = false,
                }
            }
        }
        if let Some(ty) = b.variadic {
            // `union(a, xs, b)`: a list among the shapes (or numbers) stands for its
            // elements, in order, so generated parts combine like written ones.
            if rest.iter().any(|(v, _)| matches!(v, Value::List(_))) {
                rest = rest
                    .into_iter()
                    .flat_map(|(v, span)| match v {
                        Value::List(items) => items.iter().map(|x| (x.clone(), span)).collect::<Vec<_>>(),
                        v => vec![(v, span)],
                    })
                    .collect();
                if rest.is_empty() {
                    self.report(
                        Diagnostic::error(
                            codes::ARITY,
                            call,
                            format!("`{}` of nothing: every list given is empty", b.name),
                            "no elements",
                        )
                        .with_note(format!("`{}` needs at least one element", b.name)),
                    );
                    return None;
                }
            }
            for (v, span) in rest.iter_mut() {
                match self.coerce(v, ty, *span, &|| format!("every positional argument of `{}`", b.name)) {
                    Some(c) => *v = c,
                    None => ok = false,
                }
            }
        }
        let poisoned = vals.iter().flatten().any(|(v, _)| v.is_error()) || rest.iter().any(|(v, _)| v.is_error());
        // Ranges, from the declaration: defaults are in range (tested for every one).
        if ok && !poisoned {
            for (p, slot) in b.params.iter().zip(&vals) {
                if let Some((v, span)) = slot {
                    ok &= self.host().in_range(p, v, *span);
                }
            }
        }
        (ok && !poisoned && !recovered).then_some(BoundArgs { params: b.params, vals, rest, call })
    }

    /// Converts `v` to `ty` or reports a mismatch; poison passes through. `what` names
    /// the slot, formatted only for a report.
    fn coerce(&mut self, v: &Value, ty: Ty, span: Span, what: &dyn Fn() -> String) -> Option<Value> {
        let ok = match (ty, v) {
            (_, Value::Error) => return Some(Value::Error),
            (Ty::Num | Ty::Int | Ty::Vec3 | Ty::Size | Ty::Linear | Ty::List, Value::Sym(e)) => {
                if self.symbolic_args && point_value_fits(ty, e) {
                    return Some(v.clone());
                }
                self.depends_on_point(span, &what());
                return None;
            }
            (Ty::Int, Value::Num(x)) => {
                if x.fract() != 0.0 {
                    self.report(
                        Diagnostic::error(
                            codes::NOT_INTEGER,
                            span,
                            format!("expected a whole number, found {}", dump_num(*x)),
                            "not a whole number",
                        )
                        .with_note(format!("{} is an `int`", what()))
                        .with_hint("try `floor(…)`"),
                    );
                    return None;
                }
                true
            }
            (Ty::Size, Value::Num(x)) => return Some(Value::Vec3(DVec3::splat(*x))),
            // `[1, 2, 3]` reads as a vector, but is a list of numbers too, as in `for`.
            (Ty::List, Value::Vec3(v)) => return Some(Value::List(Value::numbers(*v))),
            _ => admits(ty, v),
        };
        if ok {
            return Some(v.clone());
        }
        let mut d = Diagnostic::error(
            codes::TYPE_MISMATCH,
            span,
            format!("expected `{ty}`, found `{}`", v.ty_name()),
            v.this_is(),
        )
        .with_note(format!("{} is a `{ty}`", what()));
        match (ty, v) {
            (Ty::Color | Ty::Paint, Value::Vec3(c)) => {
                d = d.with_hint(format!("try `rgb({}, {}, {})`", dump_num(c.x), dump_num(c.y), dump_num(c.z)))
            }
            (Ty::Color | Ty::Paint, Value::Str(name)) => {
                d = match named_colour(name) {
                    Some(hex) => d.with_replacement(span, hex),
                    None => d.with_hint("a colour is written `#rrggbb` or `rgb(r, g, b)`, not as a string"),
                }
            }
            (Ty::Color, Value::Pattern(_)) => {
                d = d.with_note("a pattern paints the surface of the object its material is on; this needs one colour")
            }
            (Ty::Shape, Value::Mesh(_)) => {
                d = d.with_note("meshes cannot take part in CSG; shapes can be meshed with `mesh isosurface(…)`")
            }
            (Ty::Vec3, Value::Num(x)) => d = d.with_hint(format!("try `[{0}, {0}, {0}]`", dump_num(*x))),
            (Ty::Vec3, Value::List(items)) => {
                d = d.with_note(format!("a vector has exactly 3 numbers; this list has {}", items.len()))
            }
            (_, Value::Field(_)) => {
                d = d.with_note("a field literal `p => …` is an argument of `field`, `warp` or `displace`")
            }
            (Ty::FieldNum | Ty::FieldVec, _) => d = d.with_hint("try a field literal, such as `p => length(p) - 1`"),
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

    /// Evaluates `f`'s body with `args`; `defining` for the evaluation at its definition.
    pub(super) fn call_user(&mut self, f: &Func, args: Vec<Value>, call: Span, defining: bool) -> Value {
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
        f.calls.set(f.calls.get() + 1);
        if self.index.is_some() {
            for (p, v) in f.params.iter().zip(&args) {
                let ty = (!v.is_error()).then(|| v.ty_name());
                self.note_def(p, super::index::DefKind::Param, ty, f.body.span.start, f.body.span.end);
            }
        }
        let env = Env::call(f.captured.clone(), args, defining);
        let caller = std::mem::replace(&mut self.env, env);
        self.outer.push(caller);
        let saved_dir = std::mem::replace(&mut self.dir, f.file_dir.clone());
        self.call_depth += 1;
        let v = self.expr(&f.body);
        self.call_depth -= 1;
        self.dir = saved_dir;
        if let Some(caller) = self.outer.pop() {
            self.env = caller;
        }
        v
    }
}

/// Whether a value of `v`'s type fills a parameter of type `ty` (an `int` must also be
/// whole; `coerce` checks that).
fn admits(ty: Ty, v: &Value) -> bool {
    match ty {
        Ty::Num | Ty::Int => matches!(v, Value::Num(_)),
        Ty::Size => matches!(v, Value::Num(_) | Value::Vec3(_)),
        Ty::Vec3 => matches!(v, Value::Vec3(_)),
        Ty::Linear => matches!(v, Value::Num(_) | Value::Vec3(_) | Value::Color(_)),
        Ty::Bool => matches!(v, Value::Bool(_)),
        Ty::Str => matches!(v, Value::Str(_)),
        Ty::Color => matches!(v, Value::Color(_)),
        Ty::Material => matches!(v, Value::Material(_)),
        Ty::Pattern => matches!(v, Value::Pattern(_)),
        Ty::Paint => matches!(v, Value::Color(_) | Value::Pattern(_)),
        Ty::Shape => matches!(v, Value::Shape(_)),
        Ty::Mesh => matches!(v, Value::Mesh(_)),
        Ty::Light => matches!(v, Value::Light(_)),
        Ty::List => matches!(v, Value::List(_) | Value::Vec3(_)),
        Ty::FieldNum => matches!(v, Value::Field(f) if f.body.ty == crate::ir::field::FieldTy::Num),
        Ty::FieldVec => matches!(v, Value::Field(f) if f.body.ty == crate::ir::field::FieldTy::Vec3),
        // Its two corners are checked by the builtin, which can say which is wrong.
        Ty::Bounds => matches!(v, Value::List(_)),
        Ty::Profile => matches!(v, Value::Profile(_)),
    }
}

/// The type of the argument that picks overload `o`: its shapes' (or profiles') for a
/// variadic one, else its first parameter's.
fn deciding_ty(o: &Builtin) -> Ty {
    o.variadic.unwrap_or(o.params[0].ty)
}

/// Whether `v` may be what picks overload `o`: a value of its type, or for a variadic
/// one also a list of them (spread into its parts; an empty list picks the first overload).
fn admits_part(o: &Builtin, v: &Value) -> bool {
    match (o.variadic, v) {
        (Some(_), Value::List(items)) => items.first().is_none_or(|x| admits_part(o, x)),
        // A value that varies with a field's point picks the function of numbers it fits
        // (`round(p.x)` is the number's `round`, not the shape modifier's).
        (_, Value::Sym(e)) => Ctx::takes_symbolic(o) && point_value_fits(deciding_ty(o), e),
        _ => admits(deciding_ty(o), v),
    }
}

/// Whether a value that varies with a field's point may stand for a parameter of type `ty`
/// of a function of numbers.
fn point_value_fits(ty: Ty, e: &crate::ir::field::FieldExpr) -> bool {
    use crate::ir::field::FieldTy as F;
    match ty {
        Ty::Num => e.ty == F::Num,
        Ty::Vec3 => e.ty == F::Vec3,
        Ty::Linear => e.ty != F::Bool,
        _ => false,
    }
}

/// The argument that picks overload `o`: the first positional one of a variadic builtin,
/// else the one its first parameter binds.
fn first_arg<'a>(o: &Builtin, args: &'a [ArgVal]) -> Option<&'a ArgVal> {
    if o.variadic.is_some() {
        return args.iter().find(|a| a.name.is_none());
    }
    let first = o.params[0].name;
    args.iter()
        .find(|a| a.name.as_ref().is_some_and(|n| n.name == first))
        .or_else(|| args.iter().find(|a| a.name.is_none()))
}

/// The `#rrggbb` of a colour named as CSS names it, for a colour written as a string.
fn named_colour(name: &str) -> Option<&'static str> {
    const NAMES: &[(&str, &str)] = &[
        ("black", "#000000"),
        ("white", "#ffffff"),
        ("red", "#ff0000"),
        ("green", "#008000"),
        ("lime", "#00ff00"),
        ("blue", "#0000ff"),
        ("yellow", "#ffff00"),
        ("cyan", "#00ffff"),
        ("magenta", "#ff00ff"),
        ("orange", "#ffa500"),
        ("purple", "#800080"),
        ("pink", "#ffc0cb"),
        ("brown", "#a52a2a"),
        ("gray", "#808080"),
        ("grey", "#808080"),
        ("silver", "#c0c0c0"),
        ("gold", "#ffd700"),
    ];
    let name = name.trim().to_ascii_lowercase();
    NAMES.iter().find(|(n, _)| *n == name).map(|(_, hex)| *hex)
}

#[cfg(test)]
mod guess_tests {
    use crate::builtins::{self, Kind};
    use crate::diag::guesses::GUESSES;

    /// Advice for a word scnc itself defines would hide the real thing; no guess is one,
    /// and every replacement offered is a word scnc knows.
    #[test]
    fn no_guess_is_a_builtin_and_every_replacement_is() {
        for g in GUESSES {
            assert!(builtins::overloads(g.word, Kind::Function).is_empty(), "{} is a builtin", g.word);
            if let Some(r) = g.replacement {
                assert!(r == "at" || !builtins::overloads(r, Kind::Function).is_empty(), "{} → {r}", g.word);
            }
        }
    }
}
