//! What the checker learns about names and types while it evaluates, kept for editor
//! tooling (`scnc lsp`): definitions, the uses that resolved to them, the type each
//! expression evaluated to, and the builtins named at each place.
//!
//! The index is filled only when asked for ([`check_indexed`](super::check_indexed)); a
//! plain compile pays nothing for it.

use std::collections::HashMap;

use crate::builtins::{Builtin, Constant, Param};
use crate::span::Span;

/// What kind of name a definition binds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DefKind {
    /// `let name = value`.
    Value,
    /// `let name(params) = body`.
    Function,
    /// A function parameter.
    Param,
    /// A `for` loop variable.
    LoopVar,
    /// A field literal's point (`p` in `p => …`).
    Point,
}

/// One definition.
#[derive(Clone, Debug)]
pub struct Def {
    /// The name.
    pub name: String,
    /// The name's span at the definition.
    pub span: Span,
    /// What it binds.
    pub kind: DefKind,
    /// The type of the value (the first one seen that was not poison), or for a
    /// function its signature, such as `ring(n, r) -> shape`.
    pub ty: Option<String>,
    /// A function's parameter names (empty for other kinds).
    pub params: Vec<String>,
    /// Global offsets in the root file between which the name is in scope; `None`
    /// when it is never in scope there (a loop variable of an included file).
    pub visible: Option<(u32, u32)>,
}

/// A builtin named in the source: a function, mesh generator, or a named argument.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinUse {
    /// Where it is named.
    pub span: Span,
    /// The builtin.
    pub builtin: &'static Builtin,
    /// For a named argument, its parameter.
    pub param: Option<&'static Param>,
}

/// Names and types of one compile.
#[derive(Debug, Default)]
pub struct Index {
    defs: Vec<Def>,
    by_span: HashMap<Span, usize>,
    /// Each use of a name (and each definition itself) and the definition's span.
    pub refs: HashMap<Span, Span>,
    /// The type each expression evaluated to (the first that was not poison).
    pub types: HashMap<Span, String>,
    /// Builtins named in the source.
    pub builtins: HashMap<Span, BuiltinUse>,
    /// Constants (`pi`, `clock`, `frame`) named in the source.
    pub constants: HashMap<Span, &'static Constant>,
}

impl Index {
    /// Every definition, in the order first seen.
    pub fn defs(&self) -> &[Def] {
        &self.defs
    }

    /// The definition whose name is at `span`.
    pub fn def(&self, span: Span) -> Option<&Def> {
        self.by_span.get(&span).map(|&i| &self.defs[i])
    }

    /// Records a definition (again: a loop body or function body runs many times); the
    /// first non-poison type wins.
    pub(super) fn define(&mut self, def: Def) {
        self.refs.insert(def.span, def.span);
        match self.by_span.get(&def.span) {
            Some(&i) => {
                let old = &mut self.defs[i];
                if old.ty.is_none() {
                    old.ty = def.ty;
                }
            }
            None => {
                self.by_span.insert(def.span, self.defs.len());
                self.defs.push(def);
            }
        }
    }

    /// Sets the parameter names of the function defined at `span`.
    pub(super) fn set_params(&mut self, span: Span, params: Vec<String>) {
        if let Some(&i) = self.by_span.get(&span) {
            self.defs[i].params = params;
        }
    }

    /// Records that the name at `use_span` refers to the definition at `def`.
    pub(super) fn refer(&mut self, use_span: Span, def: Span) {
        self.refs.insert(use_span, def);
    }

    /// Records the type of the expression at `span`, unless one is known already.
    pub(super) fn typed(&mut self, span: Span, ty: Option<String>) {
        if let Some(ty) = ty {
            self.types.entry(span).or_insert(ty);
        }
    }

    /// Every use of the definition at `def`, the definition included, in source order.
    pub fn references(&self, def: Span) -> Vec<Span> {
        let mut out: Vec<Span> = self.refs.iter().filter(|(_, d)| **d == def).map(|(u, _)| *u).collect();
        out.sort();
        out
    }

    /// Definitions in scope at global offset `at` of the root file, the innermost (latest)
    /// first for each name.
    pub fn in_scope(&self, at: u32) -> Vec<&Def> {
        let mut seen = std::collections::HashSet::new();
        let mut visible: Vec<&Def> =
            self.defs.iter().filter(|d| d.visible.is_some_and(|(from, to)| from <= at && at <= to)).collect();
        visible.sort_by_key(|d| std::cmp::Reverse(d.visible.map(|v| v.0)));
        visible.retain(|d| seen.insert(d.name.clone()));
        visible
    }
}
