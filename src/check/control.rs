//! Control flow: conditions, `if` (expression and statement), `for` over ranges and
//! lists, and list comprehensions.
//!
//! Only the branch taken is evaluated, as in every language with `if`. When the
//! condition is unknown (poison, as in a function body checked at its definition), both
//! branches are evaluated without emitting anything, so their mistakes are still
//! reported and an `if` expression's branch types are compared.
//!
//! A branch that does not run (and the right side of `and`/`or` the left side decided,
//! and a comprehension's body that its filter always rejects) is explored once: run
//! without emitting, on a small fuel budget, reporting only the mistakes that would be
//! mistakes whatever the values — misspelt names, arguments and parameters — because
//! the others are what the condition guards against (`if n != 0 { … 1 / n … }`). The
//! editor gets types and definitions inside it, its uses count as uses, and an `if`
//! expression's branch types are compared when both are known.

use std::rc::Rc;

use super::{index, Bound, Ctx, Value, MAX_ITERATIONS, MAX_LIST};
use crate::diag::{codes, Diagnostic};
use crate::span::Span;
use crate::syntax::ast::{self, Generator, Iterable};

/// Fuel one exploration of a branch that does not run may spend.
const EXPLORE_FUEL: u64 = 100_000;

/// Whether a mistake of this code is one in code that does not run, too: it does not
/// depend on any value.
pub(super) fn holds_in_dead_code(code: &str) -> bool {
    [
        codes::UNKNOWN_NAME,
        codes::UNKNOWN_FUNCTION,
        codes::DUPLICATE_PARAM,
        codes::NOT_A_VALUE,
        codes::UNKNOWN_ARG,
        codes::DUPLICATE_ARG,
        codes::NOT_A_MESH_GENERATOR,
        codes::UNUSED,
    ]
    .contains(&code)
}

/// What a `for` runs over, evaluated.
enum Items {
    /// Whole numbers `start..end`.
    Range(i64, i64),
    /// Elements of a list (a vector's three numbers count as a list).
    List(Rc<Vec<Value>>),
    /// Unknown (poison, or a mistake already reported): the body is checked once.
    Unknown,
}

impl Items {
    fn len(&self) -> u64 {
        match self {
            Items::Range(lo, hi) => hi.saturating_sub(*lo).max(0) as u64,
            Items::List(items) => items.len() as u64,
            Items::Unknown => 0,
        }
    }

    fn get(&self, i: u64) -> Value {
        match self {
            Items::Range(lo, _) => Value::Num((lo + i as i64) as f64),
            Items::List(items) => items.get(i as usize).cloned().unwrap_or(Value::Error),
            Items::Unknown => Value::Error,
        }
    }
}

impl Ctx<'_> {
    /// The truth of a condition; `None` for poison, or after reporting a non-boolean.
    pub(super) fn condition(&mut self, v: &Value, span: Span, what: &str) -> Option<bool> {
        match v {
            Value::Bool(b) => Some(*b),
            Value::Error => None,
            Value::Sym(e) if e.ty == crate::ir::field::FieldTy::Bool => {
                self.depends_on_point(span, what);
                None
            }
            other => {
                let mut d = Diagnostic::error(
                    codes::NOT_A_BOOL,
                    span,
                    format!("expected `bool`, found `{}`", other.ty_name()),
                    other.this_is(),
                )
                .with_note(format!("{what} must be `true` or `false`"));
                if matches!(other, Value::Num(_)) {
                    d = d.with_hint("try a comparison, such as `x != 0` or `x > 0`");
                }
                self.report(d);
                None
            }
        }
    }

    /// Runs `run` over code that does not run, the first time only (see the module doc);
    /// its result, or `None` when it was explored before.
    pub(super) fn explore<R>(&mut self, key: Span, run: impl FnOnce(&mut Self) -> R) -> Option<R> {
        if self.halted || !self.explored.insert(key) {
            return None;
        }
        let fuel = self.fuel;
        let budget = fuel.min(EXPLORE_FUEL);
        self.fuel = budget;
        self.quiet += 1;
        self.dry += 1;
        let r = run(self);
        self.dry -= 1;
        self.quiet -= 1;
        self.fuel = fuel - (budget - self.fuel);
        // Running out of the budget stops the exploration, not the compile.
        if self.halted && !self.cancelled && self.error_reports < super::MAX_ERROR_REPORTS {
            self.halted = false;
        }
        Some(r)
    }

    /// `if cond then a else b`.
    pub(super) fn if_expr(&mut self, cond: &ast::Expr, then: &ast::Expr, otherwise: &ast::Expr) -> Value {
        let c = self.expr(cond);
        if let Value::Sym(s) = &c {
            if s.ty == crate::ir::field::FieldTy::Bool {
                return self.symbolic_if(s.clone(), then, otherwise);
            }
        }
        let taken = self.condition(&c, cond.span, "the condition of `if`");
        let (ran, other) = match taken {
            Some(true) => (then, otherwise),
            Some(false) => (otherwise, then),
            None => {
                // Both are checked here, so neither needs exploring later.
                self.explored.extend([then.span, otherwise.span]);
                self.dry += 1;
                let a = self.expr(then);
                let b = self.expr(otherwise);
                self.dry -= 1;
                self.branches_agree((then, &a), (otherwise, &b));
                return Value::Error;
            }
        };
        let v = self.expr(ran);
        if let Some(w) = self.explore(other.span, |this| this.expr(other)) {
            let (a, b) =
                if taken == Some(true) { ((then, &v), (otherwise, &w)) } else { ((then, &w), (otherwise, &v)) };
            if self.branches_agree(a, b) {
                return Value::Error;
            }
        }
        v
    }

    /// Reports branches of known, different types; `true` if it did.
    fn branches_agree(&mut self, (then, a): (&ast::Expr, &Value), (otherwise, b): (&ast::Expr, &Value)) -> bool {
        if a.is_error() || b.is_error() || a.same_type(b) {
            return false;
        }
        self.report(
            Diagnostic::error(
                codes::BRANCH_MISMATCH,
                otherwise.span,
                format!("`if` branches have different types: `{}` and `{}`", a.ty_name(), b.ty_name()),
                b.this_is(),
            )
            .with_label(then.span, a.this_is())
            .with_note("both branches must give the same type"),
        );
        true
    }

    /// `if c { … } else if d { … } else { … }`: the first branch whose condition holds.
    pub(super) fn if_stmt(&mut self, branches: &[(ast::Expr, Vec<ast::Stmt>)], otherwise: Option<&[ast::Stmt]>) {
        for (i, (cond, body)) in branches.iter().enumerate() {
            let c = self.expr(cond);
            match self.condition(&c, cond.span, "the condition of `if`") {
                Some(true) => {
                    self.block(body);
                    for (cond, body) in &branches[i + 1..] {
                        let _ = self.explore(cond.span, |this| {
                            let _ = this.expr(cond);
                            this.block(body);
                        });
                    }
                    if let Some(body) = otherwise.filter(|b| !b.is_empty()) {
                        let _ = self.explore(body[0].span, |this| this.block(body));
                    }
                    return;
                }
                Some(false) => {
                    let _ = self.explore(cond.span, |this| this.block(body));
                }
                None => {
                    // Which branch runs is unknown: check the rest without emitting.
                    self.explored.extend(branches[i..].iter().map(|(c, _)| c.span));
                    self.explored.extend(otherwise.and_then(|b| b.first()).map(|s| s.span));
                    self.dry += 1;
                    self.block(body);
                    for (cond, body) in &branches[i + 1..] {
                        let _ = self.expr(cond);
                        self.block(body);
                    }
                    if let Some(body) = otherwise {
                        self.block(body);
                    }
                    self.dry -= 1;
                    return;
                }
            }
        }
        if let Some(body) = otherwise {
            self.block(body);
        }
    }

    /// Statements in a scope of their own.
    fn block(&mut self, body: &[ast::Stmt]) {
        self.env.push_scope();
        self.stmts(body);
        self.env.pop_scope();
    }

    /// Evaluates what `each` runs over, or reports why it cannot be run over.
    fn items(&mut self, each: &Generator) -> Items {
        match &each.over {
            Iterable::Range { start, end } => {
                let lo = self.expr(start);
                let hi = self.expr(end);
                let lo = self.int_operand(&lo, start.span, "the loop start");
                let hi = self.int_operand(&hi, end.span, "the loop end");
                match (lo, hi) {
                    (Some(lo), Some(hi)) => Items::Range(lo, hi.max(lo)),
                    _ => Items::Unknown,
                }
            }
            Iterable::List(e) => match self.expr(e) {
                Value::List(items) => Items::List(items),
                Value::Vec3(v) => Items::List(Value::numbers(v)),
                Value::Error => Items::Unknown,
                other => {
                    self.report(
                        Diagnostic::error(
                            codes::NOT_ITERABLE,
                            e.span,
                            format!("cannot run `for` over a `{}`", other.ty_name()),
                            other.this_is(),
                        )
                        .with_note("`for` runs over a range `a..b` or a list")
                        .with_hint("for whole numbers, try `for i in 0..n`"),
                    );
                    Items::Unknown
                }
            },
        }
    }

    /// Counts `n` more iterations against [`MAX_ITERATIONS`]; `false` after reporting.
    fn take_iterations(&mut self, n: u64, span: Span, what: &str) -> bool {
        if self.iterations.saturating_add(n) <= MAX_ITERATIONS {
            self.iterations += n;
            return true;
        }
        self.report(
            Diagnostic::error(
                codes::TOO_MANY_ITERATIONS,
                span,
                "too many loop iterations",
                format!("{what} {n} times"),
            )
            .with_note(format!("a scene may run at most {MAX_ITERATIONS} loop iterations in total")),
        );
        false
    }

    /// Binds the loop variable of `each` to `value` in a new scope, runs `f`, closes it.
    fn with_var<T>(&mut self, each: &Generator, scope_end: u32, value: Value, f: impl FnOnce(&mut Self) -> T) -> T {
        self.env.push_scope();
        let ty = (!value.is_error()).then(|| value.ty_name());
        let from = match &each.over {
            Iterable::Range { end, .. } => end.span.end,
            Iterable::List(e) => e.span.end,
        };
        self.note_def(&each.var, index::DefKind::LoopVar, ty, from, scope_end);
        self.bind(&each.var, Bound::Value(value));
        let out = f(self);
        self.env.pop_scope();
        out
    }

    /// `for var in range-or-list { body }`.
    pub(super) fn for_loop(&mut self, each: &Generator, body: &[ast::Stmt], span: Span) {
        let run = |this: &mut Self, value: Value| {
            this.with_var(each, span.end, value, |this| {
                let outer = std::mem::replace(&mut this.block_end, span.end);
                this.stmts(body);
                this.block_end = outer;
            })
        };
        let items = self.items(each);
        let count = items.len();
        // A loop that runs no times, or over an unknown range, still has its body checked.
        if count == 0 || !self.take_iterations(count, span, "this loop would run") {
            self.dry += 1;
            run(self, Value::Error);
            self.dry -= 1;
            return;
        }
        for i in 0..count {
            run(self, items.get(i));
            if self.too_many_objects || self.halted {
                break;
            }
        }
    }

    /// `[for g1, g2 if filter => body]`: the elements, in the order of the generators
    /// (the last varies fastest), where the filter holds.
    pub(super) fn comprehension(
        &mut self,
        generators: &[Generator],
        filter: Option<&ast::Expr>,
        body: &ast::Expr,
        span: Span,
    ) -> Value {
        let mut out = Vec::new();
        let complete = self.generate(generators, filter, body, span, &mut out);
        if !complete || out.iter().any(|(v, _): &(Value, Span)| v.is_error()) {
            return Value::Error;
        }
        self.uniform_list(out).unwrap_or(Value::Error)
    }

    /// Adds the elements of the generators from the first on to `out`; `false` when the
    /// result is unknown (poison, a limit, a mistake).
    fn generate(
        &mut self,
        generators: &[Generator],
        filter: Option<&ast::Expr>,
        body: &ast::Expr,
        span: Span,
        out: &mut Vec<(Value, Span)>,
    ) -> bool {
        let Some((each, rest)) = generators.split_first() else {
            if let Some(f) = filter {
                let c = self.expr(f);
                match self.condition(&c, f.span, "a comprehension's filter") {
                    Some(true) => {}
                    Some(false) => {
                        let _ = self.explore(body.span, |this| this.expr(body));
                        return true;
                    }
                    None => {
                        let _ = self.expr(body);
                        return false;
                    }
                }
            }
            if out.len() >= MAX_LIST {
                self.host().list_too_long(span, "this comprehension makes too many elements".into());
                return false;
            }
            let v = self.expr(body);
            out.push((v, body.span));
            return !self.halted;
        };
        let items = self.items(each);
        let count = items.len();
        let known = !matches!(items, Items::Unknown);
        if count == 0 || !self.take_iterations(count, span, "this comprehension would run") {
            // Nothing to take: the rest is checked once with the variable unknown.
            self.dry += 1;
            let mut scratch = Vec::new();
            let _ = self
                .with_var(each, span.end, Value::Error, |this| this.generate(rest, filter, body, span, &mut scratch));
            self.dry -= 1;
            return known && count == 0;
        }
        for i in 0..count {
            let value = items.get(i);
            if !self.with_var(each, span.end, value, |this| this.generate(rest, filter, body, span, out)) {
                return false;
            }
        }
        true
    }
}
