//! One compile of an open document, and the questions an editor asks of it: hover,
//! definition, references, completion, symbols and quick-fixes. Offsets here are
//! global byte offsets of the compile's [`SourceMap`]; the root document starts at 0.

use std::path::Path;

use crate::builtins::{self, Builtin, Kind};
use crate::check;
use crate::check::index::{Def, DefKind, Index};
use crate::diag::Diagnostic;
use crate::source::Loader;
use crate::source::{FileId, SourceMap};
use crate::span::Span;
use crate::syntax::{self, ast, Token};

/// A compiled document.
#[derive(Debug)]
pub struct Analysis {
    /// Every file of the compile; the document is file 0, at offset 0.
    pub map: SourceMap,
    /// Every diagnostic, as `scnc check` reports them.
    pub diagnostics: Vec<Diagnostic>,
    /// Names and types.
    pub index: Index,
}

/// What completion offers.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// The text inserted.
    pub label: String,
    /// What kind of thing it is.
    pub kind: CandidateKind,
    /// A type or signature.
    pub detail: String,
    /// A one-line description.
    pub doc: Option<String>,
}

/// The signature of the builtin whose call is being typed, for signature help.
#[derive(Clone, Debug, PartialEq)]
pub struct SignatureHelp {
    /// The signature, such as `sphere(r: num)`.
    pub label: String,
    /// The builtin's doc.
    pub doc: String,
    /// Each parameter: its text within `label` (as `describe` writes it) and its doc with
    /// its range.
    pub params: Vec<(String, String)>,
    /// The parameter the cursor is at: the one named before it, or the next positional one.
    pub active: Option<usize>,
}

/// Kinds of completion candidates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CandidateKind {
    /// A named argument of the call being typed.
    Argument,
    /// A `let` value, parameter or loop variable.
    Variable,
    /// A function defined with `let`.
    Function,
    /// A builtin function or mesh generator.
    Builtin,
    /// A constant such as `pi`.
    Constant,
    /// A statement keyword.
    Keyword,
}

/// A symbol of the document outline.
#[derive(Clone, Debug, PartialEq)]
pub struct Symbol {
    /// What the outline shows.
    pub name: String,
    /// What it is.
    pub kind: SymbolKind,
    /// The whole statement.
    pub span: Span,
    /// The part to select (the name, or the statement).
    pub name_span: Span,
    /// Statements inside a `for` loop.
    pub children: Vec<Symbol>,
}

/// Kinds of outline symbols.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SymbolKind {
    /// `let name = value` or `param name = value`.
    Value,
    /// `let name(params) = body`.
    Function,
    /// `object …`.
    Object,
    /// `light …`.
    Light,
    /// `camera(…)` or `render(…)`.
    Setting,
    /// `for …`.
    Loop,
    /// `if …`.
    Conditional,
}

const STATEMENT_KEYWORDS: [&str; 8] = ["let", "param", "object", "light", "camera", "render", "for", "include"];

impl Analysis {
    /// Compiles `text` as the file at `path` (includes resolve relative to it); `None`
    /// when `cancel` said the result is no longer wanted before it was complete.
    pub fn new(
        path: &Path,
        text: String,
        loader: &(dyn Loader + Sync),
        cancel: &(dyn Fn() -> bool + Sync),
    ) -> Option<Analysis> {
        let name = path.display().to_string();
        let analysed = crate::with_big_stack_on(text, |text| {
            let mut map = SourceMap::new();
            // Too large a document gets `compile_source`'s error, as the same file on disk
            // would (it used to be analysed as if empty).
            if text.len() > crate::source::MAX_FILE_BYTES {
                let compiled = crate::compile_source(&name, path, text, loader);
                return Some(Analysis {
                    map: compiled.map,
                    diagnostics: compiled.diagnostics,
                    index: Index::default(),
                });
            }
            let Some(root) = map.add(&name, path, text) else {
                let compiled = crate::compile_source(&name, path, String::new(), loader);
                return Some(Analysis {
                    map: compiled.map,
                    diagnostics: compiled.diagnostics,
                    index: Index::default(),
                });
            };
            let (_, diagnostics, index) = check::check_indexed(&mut map, root, loader, cancel)?;
            Some(Analysis { map, diagnostics, index })
        });
        analysed.unwrap_or_else(|(e, text)| {
            let (map, d) = e.in_file(&name, path, text);
            Some(Analysis { map, diagnostics: vec![d], index: Index::default() })
        })
    }

    /// The document's text.
    pub fn text(&self) -> &str {
        &self.map.file(FileId(0)).text
    }

    /// The smallest name span at `at` that the index knows (a use, a definition, a
    /// builtin or a constant).
    fn name_at(&self, at: u32) -> Option<Span> {
        let hit = |s: &Span| s.start <= at && at <= s.end;
        self.index
            .refs
            .keys()
            .chain(self.index.builtins.keys())
            .chain(self.index.constants.keys())
            .filter(|s| hit(s))
            .min_by_key(|s| (s.end - s.start, s.start))
            .copied()
    }

    /// Markdown for the thing at `at`: a builtin's signature and doc, a name's kind and
    /// type, or else the type of the innermost expression. Also returns the span described.
    pub fn hover(&self, at: u32) -> Option<(Span, String)> {
        if let Some(span) = self.name_at(at) {
            if let Some(b) = self.index.builtins.get(&span) {
                let text = match b.param {
                    Some(p) => format!(
                        "```scn\n{}\n```\n{}\n\nparameter of `{}`",
                        p.describe(),
                        p.explain(),
                        b.builtin.signature()
                    ),
                    None => format!("```scn\n{}\n```\n{}", b.builtin.signature(), b.builtin.explained()),
                };
                return Some((span, text));
            }
            if let Some(c) = self.index.constants.get(&span) {
                return Some((span, format!("```scn\n{}: {}\n```\n{}", c.name, c.ty, c.doc)));
            }
            if let Some(def) = self.index.refs.get(&span).and_then(|d| self.index.def(*d)) {
                return Some((span, describe_def(def)));
            }
        }
        let (span, ty) = self
            .index
            .types
            .iter()
            .filter(|(s, _)| s.start <= at && at < s.end)
            .min_by_key(|(s, _)| (s.end - s.start, s.start))?;
        Some((*span, format!("```scn\n{ty}\n```")))
    }

    /// The definition of the name at `at`.
    pub fn definition(&self, at: u32) -> Option<Span> {
        self.index.refs.get(&self.name_at(at)?).copied()
    }

    /// Every use of the name at `at` (its definition first when `with_definition`).
    pub fn references(&self, at: u32, with_definition: bool) -> Vec<Span> {
        let Some(def) = self.definition(at) else {
            return Vec::new();
        };
        let mut spans = self.index.references(def);
        spans.retain(|s| with_definition || *s != def);
        spans
    }

    /// Completion candidates at `at`: named arguments of the call being typed, then names
    /// in scope, builtins and keywords (only mesh generators after `mesh`).
    pub fn complete(&self, at: u32) -> Vec<Candidate> {
        let text = self.text();
        let at = (at as usize).min(text.len());
        let tokens: Vec<(Token<'_>, Span)> = syntax::lex(text, 0)
            .into_iter()
            .filter(|(t, s)| !matches!(t, Token::LineComment | Token::BlockComment(_)) && (s.end as usize) <= at)
            .collect();
        // The word being typed is replaced by the candidate; context comes from before it.
        let before = match tokens.last() {
            Some((t, s)) if s.end as usize == at && is_word(t) => &tokens[..tokens.len() - 1],
            _ => &tokens[..],
        };
        let mut out = Vec::new();
        if matches!(before.last(), Some((Token::Mesh, _))) {
            out.extend(builtins::BUILTINS.iter().filter(|b| b.kind() == Kind::MeshGenerator).map(builtin_candidate));
            return out;
        }
        let call = enclosing_call(before);
        if let Some((callee, after_mesh, given)) = &call {
            let arg_start = matches!(before.last(), Some((Token::LParen | Token::Comma, _)));
            if arg_start {
                out.extend(self.named_arguments(callee, *after_mesh, at as u32, given));
            }
        }
        for def in self.index.in_scope(at as u32) {
            let kind = if def.kind == DefKind::Function { CandidateKind::Function } else { CandidateKind::Variable };
            out.push(Candidate {
                label: def.name.clone(),
                kind,
                detail: def.ty.clone().unwrap_or_else(|| "?".into()),
                doc: None,
            });
        }
        out.extend(builtins::BUILTINS.iter().filter(|b| b.kind() == Kind::Function).map(builtin_candidate));
        out.extend(builtins::CONSTANTS.iter().map(|c| Candidate {
            label: c.name.to_string(),
            kind: CandidateKind::Constant,
            detail: c.ty.to_string(),
            doc: Some(c.doc.to_string()),
        }));
        let depth: i32 = before.iter().map(|(t, _)| bracket_delta(t)).sum();
        if call.is_none() && depth == 0 {
            out.extend(STATEMENT_KEYWORDS.iter().map(|k| Candidate {
                label: k.to_string(),
                kind: CandidateKind::Keyword,
                detail: "statement".into(),
                doc: None,
            }));
        }
        out
    }

    /// The builtin whose call the cursor is in, with the parameter it is at; `None` outside
    /// a builtin's call (a user function's call, or no call).
    pub fn signature_help(&self, at: u32) -> Option<SignatureHelp> {
        let text = self.text();
        let at = (at as usize).min(text.len());
        let tokens: Vec<(Token<'_>, Span)> = syntax::lex(text, 0)
            .into_iter()
            .filter(|(t, s)| !matches!(t, Token::LineComment | Token::BlockComment(_)) && (s.end as usize) <= at)
            .collect();
        let (callee, after_mesh, _) = enclosing_call(&tokens)?;
        let b = self.builtin_called(&callee, after_mesh, at as u32)?;
        // The current argument: its position among the call's commas, or its name.
        let (mut depth, mut commas, mut named) = (0i32, 0usize, None);
        for (i, (t, _)) in tokens.iter().enumerate().rev() {
            match t {
                Token::RParen | Token::RBracket => depth += 1,
                Token::LParen | Token::LBracket if depth > 0 => depth -= 1,
                Token::LParen => break,
                Token::Comma if depth == 0 => commas += 1,
                Token::Eq if depth == 0 && commas == 0 => {
                    if let Some((Token::Ident(name), _)) = i.checked_sub(1).map(|j| &tokens[j]) {
                        named = Some(name.to_string());
                    }
                }
                _ => {}
            }
        }
        let skip = usize::from(b.variadic.is_some()).min(commas);
        let active = match named {
            Some(name) => b.params.iter().position(|p| p.name == name),
            None if b.variadic.is_some() => None,
            None => (commas - skip < b.params.len()).then_some(commas - skip),
        };
        Some(SignatureHelp {
            label: b.signature(),
            doc: b.doc.to_string(),
            params: b.params.iter().map(|p| (p.describe(), p.explain())).collect(),
            active,
        })
    }

    /// The builtin a call of `callee` names at `at`: a statement's argument list, a mesh
    /// generator after `mesh`, or a function no name in scope hides.
    fn builtin_called(&self, callee: &str, after_mesh: bool, at: u32) -> Option<&'static Builtin> {
        let builtin = match callee {
            "camera" => builtins::lookup(callee, Kind::Camera),
            "render" => builtins::lookup(callee, Kind::Render),
            _ if after_mesh => builtins::lookup(callee, Kind::MeshGenerator),
            _ => None,
        };
        let user = self.index.in_scope(at).into_iter().any(|d| d.name == callee && d.kind == DefKind::Function);
        builtin.or_else(|| (!user).then(|| builtins::lookup(callee, Kind::Function)).flatten())
    }

    fn named_arguments(&self, callee: &str, after_mesh: bool, at: u32, given: &[String]) -> Vec<Candidate> {
        let builtin = self.builtin_called(callee, after_mesh, at);
        // A name in scope hides a builtin of the same name.
        let user = self.index.in_scope(at).into_iter().find(|d| d.name == callee && d.kind == DefKind::Function);
        let fresh = |name: &str| !given.iter().any(|g| g == name);
        match (builtin, user) {
            (Some(b), _) => b
                .params
                .iter()
                .filter(|p| fresh(p.name))
                .map(|p| Candidate {
                    label: p.name.to_string(),
                    kind: CandidateKind::Argument,
                    detail: p.describe(),
                    doc: Some(format!("{}; parameter of `{}`", p.explain(), b.signature())),
                })
                .collect(),
            (None, Some(def)) => def
                .params
                .iter()
                .filter(|p| fresh(p))
                .map(|p| Candidate {
                    label: p.clone(),
                    kind: CandidateKind::Argument,
                    detail: "parameter".into(),
                    doc: def.ty.as_ref().map(|t| format!("parameter of `{t}`")),
                })
                .collect(),
            (None, None) => Vec::new(),
        }
    }

    /// The outline of the document: lets, functions, objects, lights, settings, loops.
    pub fn symbols(&self) -> Vec<Symbol> {
        let (file, _) = syntax::parse(self.text(), 0);
        symbols_of(&file.stmts, &self.map)
    }

    /// Diagnostics in the document that have fixes, and overlap `range`.
    pub fn fixable(&self, range: std::ops::Range<u32>) -> Vec<&Diagnostic> {
        let end = self.text().len() as u32;
        self.diagnostics
            .iter()
            .filter(|d| !d.fixes.is_empty())
            .filter(|d| d.span().end <= end && d.span().start <= range.end && range.start <= d.span().end)
            .collect()
    }
}

fn describe_def(def: &Def) -> String {
    let ty = def.ty.as_deref().unwrap_or("?");
    let line = match def.kind {
        DefKind::Value => format!("let {}: {ty}", def.name),
        DefKind::Function => format!("let {ty}"),
        DefKind::Param => format!("{}: {ty}", def.name),
        DefKind::LoopVar => format!("for {}: {ty}", def.name),
        DefKind::Point => format!("{} => …", def.name),
    };
    let what = match def.kind {
        DefKind::Value => "value",
        DefKind::Function => "function",
        DefKind::Param => "parameter",
        DefKind::LoopVar => "loop variable",
        DefKind::Point => "the point: a `vec3`, where the field is evaluated (`.x`, `.y`, `.z` are its coordinates)",
    };
    format!("```scn\n{line}\n```\n{what}")
}

fn builtin_candidate(b: &Builtin) -> Candidate {
    Candidate {
        label: b.name.to_string(),
        kind: CandidateKind::Builtin,
        detail: b.signature(),
        doc: Some(b.explained()),
    }
}

/// Identifiers and keywords: what a user may be in the middle of typing.
fn is_word(t: &Token<'_>) -> bool {
    matches!(t, Token::Ident(_)) || Token::KEYWORDS.contains(&t.to_string().as_str())
}

fn bracket_delta(t: &Token<'_>) -> i32 {
    match t {
        Token::LParen | Token::LBracket => 1,
        Token::RParen | Token::RBracket => -1,
        _ => 0,
    }
}

/// The call whose argument list is open at the end of `tokens`: its name, whether it
/// follows `mesh`, and the named arguments already given.
fn enclosing_call(tokens: &[(Token<'_>, Span)]) -> Option<(String, bool, Vec<String>)> {
    let mut depth = 0i32;
    let mut given = Vec::new();
    for (i, (t, _)) in tokens.iter().enumerate().rev() {
        match t {
            Token::RParen | Token::RBracket => depth += 1,
            Token::LBracket if depth > 0 => depth -= 1,
            Token::LParen if depth > 0 => depth -= 1,
            Token::LBracket | Token::LBrace | Token::RBrace => return None,
            Token::LParen => {
                let name = match i.checked_sub(1).map(|j| &tokens[j].0) {
                    Some(Token::Ident(name)) => name.to_string(),
                    Some(Token::Camera) => "camera".to_string(),
                    Some(Token::Render) => "render".to_string(),
                    _ => return None,
                };
                let after_mesh = i >= 2 && matches!(tokens[i - 2].0, Token::Mesh);
                return Some((name, after_mesh, given));
            }
            Token::Eq if depth == 0 => {
                if let Some((Token::Ident(name), _)) = i.checked_sub(1).map(|j| &tokens[j]) {
                    given.push(name.to_string());
                }
            }
            _ => {}
        }
    }
    None
}

fn head(e: &ast::Expr, map: &SourceMap) -> String {
    match &e.kind {
        ast::ExprKind::Call { callee, .. } => format!("{}(…)", callee.name),
        ast::ExprKind::Mesh { generator, .. } => format!("mesh {}(…)", generator.name),
        ast::ExprKind::Transform { target, .. } => head(target, map),
        ast::ExprKind::Ident(id) => id.name.clone(),
        _ => {
            let text = map.snippet(e.span);
            let short: String = text.chars().take(24).collect();
            if short.len() < text.len() {
                format!("{short}…")
            } else {
                short
            }
        }
    }
}

fn symbols_of(stmts: &[ast::Stmt], map: &SourceMap) -> Vec<Symbol> {
    let symbol = |name: String, kind, span, name_span| Symbol { name, kind, span, name_span, children: Vec::new() };
    stmts
        .iter()
        .filter_map(|s| {
            Some(match &s.kind {
                ast::StmtKind::Let { name, params: None, .. } => {
                    symbol(name.name.clone(), SymbolKind::Value, s.span, name.span)
                }
                ast::StmtKind::Let { name, params: Some(params), .. } => {
                    let list: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
                    symbol(format!("{}({})", name.name, list.join(", ")), SymbolKind::Function, s.span, name.span)
                }
                ast::StmtKind::Param(p) => symbol(p.name.name.clone(), SymbolKind::Value, s.span, p.name.span),
                ast::StmtKind::Object(e) => {
                    symbol(format!("object {}", head(e, map)), SymbolKind::Object, s.span, e.span)
                }
                ast::StmtKind::Light(e) => symbol(format!("light {}", head(e, map)), SymbolKind::Light, s.span, e.span),
                ast::StmtKind::Camera(_) => symbol("camera".into(), SymbolKind::Setting, s.span, s.span),
                ast::StmtKind::Render(_) => symbol("render".into(), SymbolKind::Setting, s.span, s.span),
                ast::StmtKind::For { each, body } => {
                    let over = match &each.over {
                        ast::Iterable::Range { start, end } => {
                            format!("{}..{}", map.snippet(start.span), map.snippet(end.span))
                        }
                        ast::Iterable::List(e) => map.snippet(e.span).to_string(),
                    };
                    Symbol {
                        name: format!("for {} in {over}", each.var.name),
                        kind: SymbolKind::Loop,
                        span: s.span,
                        name_span: each.var.span,
                        children: symbols_of(body, map),
                    }
                }
                ast::StmtKind::If { branches, otherwise } => {
                    let (cond, _) = branches.first()?;
                    let mut children: Vec<Symbol> = branches.iter().flat_map(|(_, b)| symbols_of(b, map)).collect();
                    children.extend(otherwise.iter().flat_map(|b| symbols_of(b, map)));
                    Symbol {
                        name: format!("if {}", map.snippet(cond.span)),
                        kind: SymbolKind::Conditional,
                        span: s.span,
                        name_span: cond.span,
                        children,
                    }
                }
                ast::StmtKind::Include { .. } | ast::StmtKind::Error => return None,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parameter signature help marks, with the cursor at the end of `text`.
    fn active(text: &str) -> Option<(String, Option<usize>)> {
        let a = Analysis::new(Path::new("t.scn"), text.to_string(), &crate::source::FsLoader, &|| false)?;
        a.signature_help(text.len() as u32).map(|h| (h.label, h.active))
    }

    #[test]
    fn signature_help_follows_the_argument_being_typed() {
        let at = |text: &str| active(text).and_then(|(_, i)| i);
        assert_eq!(at("object cylinder("), Some(0));
        assert_eq!(at("object cylinder(1, "), Some(1));
        assert_eq!(at("object cylinder(max(1, 2), "), Some(1), "a nested call's comma is not the call's");
        assert_eq!(at("let m = material(ior = "), Some(4));
        assert_eq!(at("object union(sphere(1), box(1), smooth = "), Some(0));
        assert_eq!(at("object union(sphere(1), "), None, "a variadic shape is no parameter");
        assert_eq!(at("render(width = 10, "), Some(1));
        assert_eq!(at("object mesh uvsphere(1, "), Some(1));
        assert_eq!(active("object sphere(1) at [0, 0, 5]"), None, "outside any call");
        let user = "let f(a, b) = sphere(a + b)\nobject f(";
        assert_eq!(active(user), None, "a user function's call");
    }
}
