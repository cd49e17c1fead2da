//! Name resolution: the bindings in scope, found by hashing rather than by scanning,
//! and what a function captures, resolved once where it is defined.
//!
//! A scene may hold hundreds of thousands of names and function definitions; looking a
//! name up by scanning the scopes, or copying the scopes into every function's
//! environment, makes such a file quadratic in time and memory. Here a lookup is one
//! hash probe (two inside a call) and a definition costs what its body mentions.

use std::cell::Cell;
use std::collections::HashMap;
use std::rc::Rc;

use foldhash::fast::FixedState;

use super::{Bound, Value};
use crate::span::Span;
use crate::syntax::ast::{self, ExprKind};

/// A name bound to a value or a function.
#[derive(Debug)]
pub(super) struct Binding {
    pub name: Rc<str>,
    pub span: Span,
    pub bound: Bound,
    /// Set on the first lookup, so the table of unused `let`s is updated once per
    /// binding rather than on every use.
    pub used: Cell<bool>,
}

/// What a name in a function body refers to.
#[derive(Debug)]
enum Slot {
    /// The parameter at this index, declared at this span.
    Param(usize, Span),
    /// A binding in scope where the function was defined.
    Outer(Rc<Binding>),
}

/// The names a function body can see besides builtins: its parameters, and the
/// bindings that its free names referred to where it was defined.
#[derive(Debug, Default)]
pub(super) struct Captured {
    slots: Vec<(Rc<str>, Slot)>,
    /// Positions in `slots` by name, for bodies that mention many names; a short list
    /// is faster to scan than a name is to hash.
    index: Option<NameMap<usize>>,
}

/// Above this many slots, names are found through a hash map.
const SCAN_LIMIT: usize = 8;

/// A map keyed by names. Hashed with a fast fixed-seed hasher: a lookup is made for
/// every name a scene evaluates, and SipHash was a visible share of evaluating
/// generated scenes (`valgrind --tool=callgrind scnc check
/// benches/scenes/union-10000.scn`); a fixed seed keeps any order derived from it the
/// same from run to run.
type NameMap<V> = HashMap<Rc<str>, V, FixedState>;

impl Captured {
    /// Resolves the free names of `body` in `env`; `params` shadow them (the first of
    /// a repeated name binds). Costs what the body mentions, not what is in scope.
    pub fn new(env: &Env, params: &[ast::Ident], body: &ast::Expr) -> Captured {
        let mut slots: NameMap<Slot> = NameMap::default();
        for (i, p) in params.iter().enumerate() {
            slots.entry(Rc::from(p.name.as_str())).or_insert(Slot::Param(i, p.span));
        }
        let mut stack = vec![body];
        while let Some(e) = stack.pop() {
            let mention = |name: &str, slots: &mut NameMap<Slot>| {
                if !slots.contains_key(name) {
                    if let Some(b) = env.binding(name) {
                        slots.insert(b.name.clone(), Slot::Outer(b));
                    }
                }
            };
            match &e.kind {
                ExprKind::Number(_)
                | ExprKind::Bool(_)
                | ExprKind::Str(_)
                | ExprKind::HexColor(_)
                | ExprKind::Error => {}
                ExprKind::Ident(id) => mention(&id.name, &mut slots),
                ExprKind::List(items) => stack.extend(items),
                ExprKind::Call { callee, args } => {
                    mention(&callee.name, &mut slots);
                    stack.extend(args.iter().map(|a| &a.value));
                }
                ExprKind::Mesh { generator: _, args } => stack.extend(args.iter().map(|a| &a.value)),
                ExprKind::Index { base, index } => stack.extend([&**base, &**index]),
                ExprKind::Neg(inner) | ExprKind::Not(inner) | ExprKind::Component { base: inner, axis: _ } => {
                    stack.push(inner)
                }
                // The point is local, like a comprehension's variable.
                ExprKind::Field { param: _, body } => stack.push(body),
                ExprKind::If { cond, then, otherwise } => stack.extend([&**cond, &**then, &**otherwise]),
                // A comprehension's variables are local, so capturing an outer binding of
                // the same name is harmless: the local one is found first.
                ExprKind::Comprehension { generators, filter, body } => {
                    for g in generators {
                        match &g.over {
                            ast::Iterable::Range { start, end } => stack.extend([start, end]),
                            ast::Iterable::List(e) => stack.push(e),
                        }
                    }
                    stack.extend(filter.as_deref());
                    stack.push(body);
                }
                ExprKind::Binary { op: _, lhs, rhs } => stack.extend([&**lhs, &**rhs]),
                ExprKind::Transform { op: _, op_span: _, target, arg } => stack.extend([&**target, &**arg]),
            }
        }
        // In a stable order, so suggestions and their ties do not depend on hashing.
        let mut slots: Vec<(Rc<str>, Slot)> = slots.into_iter().collect();
        slots.sort_unstable_by(|a, b| a.0.cmp(&b.0));
        let index =
            (slots.len() > SCAN_LIMIT).then(|| slots.iter().enumerate().map(|(i, (n, _))| (n.clone(), i)).collect());
        Captured { slots, index }
    }

    fn get(&self, name: &str) -> Option<&Slot> {
        match &self.index {
            Some(index) => index.get(name).map(|&i| &self.slots[i].1),
            None => self.slots.iter().find(|(n, _)| **n == *name).map(|(_, s)| s),
        }
    }
}

/// A function call in progress: what its body can see.
struct Frame {
    captured: Rc<Captured>,
    args: Vec<Value>,
    /// Set for the evaluation at the definition (with poisoned arguments), when the
    /// environment outside is the one the function was defined in.
    defining: bool,
}

/// The bindings visible where evaluation is.
#[derive(Default)]
pub(super) struct Env {
    /// Inside a function call: the callee's parameters and captured names.
    frame: Option<Frame>,
    /// Bindings made here; boxed and made on first use so that entering a call, which
    /// usually binds nothing, moves a small value.
    scopes: Option<Box<Scopes>>,
}

/// Bindings in nested scopes, by name.
#[derive(Default)]
struct Scopes {
    /// Each name's bindings, innermost last.
    table: NameMap<Vec<Rc<Binding>>>,
    /// Names bound, in order, so a scope can be closed.
    log: Vec<Rc<str>>,
    /// Where each open scope starts in `log`.
    marks: Vec<usize>,
}

/// A name found in scope: what it is bound to, where, and the binding to mark used
/// (parameters have none).
pub(super) struct Found {
    pub bound: Bound,
    pub span: Span,
    pub binding: Option<Rc<Binding>>,
}

impl Env {
    /// The environment of a call to a function that captured `captured`.
    pub fn call(captured: Rc<Captured>, args: Vec<Value>, defining: bool) -> Env {
        Env { frame: Some(Frame { captured, args, defining }), scopes: None }
    }

    /// Opens a scope (a loop body).
    pub fn push_scope(&mut self) {
        let s = self.scopes.get_or_insert_default();
        s.marks.push(s.log.len());
    }

    /// Closes the innermost scope: its bindings go out of sight.
    pub fn pop_scope(&mut self) {
        let Some(s) = self.scopes.as_deref_mut() else { return };
        let start = s.marks.pop().unwrap_or(0);
        for name in s.log.drain(start..) {
            if let Some(stack) = s.table.get_mut(&name) {
                stack.pop();
            }
        }
    }

    /// Binds a name in the innermost scope, shadowing any outer binding of it.
    pub fn bind(&mut self, b: Binding) {
        let s = self.scopes.get_or_insert_default();
        let b = Rc::new(b);
        s.log.push(b.name.clone());
        s.table.entry(b.name.clone()).or_default().push(b);
    }

    /// The innermost binding of `name` made in this environment's own scopes.
    fn local(&self, name: &str) -> Option<&Rc<Binding>> {
        self.scopes.as_ref()?.table.get(name)?.last()
    }

    /// The binding `name` refers to here, unless it is a parameter.
    fn binding(&self, name: &str) -> Option<Rc<Binding>> {
        if let Some(b) = self.local(name) {
            return Some(b.clone());
        }
        match self.frame.as_ref()?.captured.get(name)? {
            Slot::Outer(b) => Some(b.clone()),
            Slot::Param(..) => None,
        }
    }

    /// Resolves `name`.
    pub fn find(&self, name: &str) -> Option<Found> {
        if let Some(b) = self.local(name) {
            return Some(Found { bound: b.bound.clone(), span: b.span, binding: Some(b.clone()) });
        }
        let frame = self.frame.as_ref()?;
        match frame.captured.get(name)? {
            Slot::Param(i, span) => {
                let v = frame.args.get(*i).cloned().unwrap_or(Value::Error);
                Some(Found { bound: Bound::Value(v), span: *span, binding: None })
            }
            Slot::Outer(b) => Some(Found { bound: b.bound.clone(), span: b.span, binding: Some(b.clone()) }),
        }
    }

    /// The scope depth outside calls (0 at a file's top level); `None` inside a call.
    pub fn depth(&self) -> Option<usize> {
        self.frame.is_none().then_some(self.scopes.as_ref().map_or(0, |s| s.marks.len()))
    }

    /// True while evaluating a function at its definition.
    pub fn defining(&self) -> bool {
        self.frame.as_ref().is_some_and(|f| f.defining)
    }

    /// Every name visible here (each once), with whether it is bound to a function.
    pub fn names(&self) -> impl Iterator<Item = (&str, bool)> {
        let table = self.scopes.iter().flat_map(|s| s.table.values());
        let table = table.filter_map(|s| s.last()).map(|b| (&*b.name, matches!(b.bound, Bound::Func(_))));
        let frame = self.frame.iter().flat_map(|f| {
            f.captured
                .slots
                .iter()
                .filter(|(name, _)| self.local(name).is_none())
                .map(|(name, slot)| (&**name, matches!(slot, Slot::Outer(b) if matches!(b.bound, Bound::Func(_)))))
        });
        table.chain(frame)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::ast::{Arg, Expr, Ident};

    fn ident(name: &str) -> Ident {
        Ident { name: name.into(), span: Span::default() }
    }

    fn expr(kind: ExprKind) -> Expr {
        Expr { kind, span: Span::default() }
    }

    fn binding(name: &str, x: f64) -> Binding {
        Binding { name: name.into(), span: Span::default(), bound: Bound::Value(Value::Num(x)), used: Cell::new(false) }
    }

    /// A function captures what its body mentions, not everything in scope: copying
    /// the scope into each function made memory and time grow with the number of
    /// functions times the names in scope.
    #[test]
    fn a_function_captures_only_the_names_its_body_mentions() {
        let mut env = Env::default();
        for i in 0..10_000 {
            env.bind(binding(&format!("a{i}"), i as f64));
        }
        // f(x) = g(a7, x) + a7 + nowhere
        let call = ExprKind::Call {
            callee: ident("g"),
            args: vec![
                Arg { name: None, value: expr(ExprKind::Ident(ident("a7"))) },
                Arg { name: None, value: expr(ExprKind::Ident(ident("x"))) },
            ],
        };
        let sum = ExprKind::Binary {
            op: ast::BinOp::Add,
            lhs: Box::new(expr(call)),
            rhs: Box::new(expr(ExprKind::Ident(ident("a7")))),
        };
        let body = expr(ExprKind::Binary {
            op: ast::BinOp::Add,
            lhs: Box::new(expr(sum)),
            rhs: Box::new(expr(ExprKind::Ident(ident("nowhere")))),
        });
        let captured = Captured::new(&env, &[ident("x")], &body);
        let names: Vec<&str> = captured.slots.iter().map(|(n, _)| &**n).collect();
        assert_eq!(names, ["a7", "x"], "unknown names (`g`, `nowhere`) are not captured");

        let call = Env::call(Rc::new(captured), vec![Value::Num(2.0)], false);
        assert!(matches!(call.find("x").map(|f| f.bound), Some(Bound::Value(Value::Num(2.0)))));
        assert!(matches!(call.find("a7").map(|f| f.bound), Some(Bound::Value(Value::Num(7.0)))));
        assert!(call.find("a8").is_none(), "a name the body does not mention is not visible in the call");
    }

    /// Scopes shadow and unshadow; the depth counts open scopes.
    #[test]
    fn scopes_shadow_and_close() {
        let mut env = Env::default();
        env.bind(binding("x", 1.0));
        env.push_scope();
        env.bind(binding("x", 2.0));
        assert_eq!(env.depth(), Some(1));
        assert!(matches!(env.find("x").map(|f| f.bound), Some(Bound::Value(Value::Num(2.0)))));
        env.pop_scope();
        assert!(matches!(env.find("x").map(|f| f.bound), Some(Bound::Value(Value::Num(1.0)))));
        assert_eq!(env.depth(), Some(0));
    }
}
