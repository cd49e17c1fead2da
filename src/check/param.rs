//! `param` statements: a scene's parameters, the values they may take, and the values
//! the command line, a parameter set or the studio give them.

use super::{ast, index, Bound, Ctx, Value};
use crate::diag::{codes, suggest, Diagnostic};
use crate::ir::{self, ParamValue};
use crate::span::Span;

/// Values for a scene's parameters given from outside its file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Overrides(pub Vec<Override>);

/// One value for one parameter, as text, with where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// The parameter's name.
    pub name: String,
    /// The value as written (`30`, `false`, `round`, `#ff0000`).
    pub text: String,
    /// Where it was given, as messages quote it: ``-D width=30``, or
    /// ``"width": "30"` of set `large` in `sets.json``.
    pub origin: String,
}

impl Overrides {
    /// Reads `name=value` (the form of `-D`).
    pub fn parse_define(s: &str) -> Result<Override, String> {
        let (name, text) = s.split_once('=').ok_or_else(|| format!("`{s}` is not `name=value`"))?;
        let name = name.trim();
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(format!("`{name}` is not a parameter name"));
        }
        Ok(Override { name: name.to_string(), text: text.to_string(), origin: format!("`-D {name}={text}`") })
    }

    /// The value given for `name`: the last one, as on a command line the last flag wins.
    fn get(&self, name: &str) -> Option<&Override> {
        self.0.iter().rev().find(|o| o.name == name)
    }
}

impl Ctx<'_> {
    /// Declares the parameter of a `param` statement and binds its value.
    pub(super) fn param(&mut self, p: &ast::ParamDecl, span: Span) {
        let default = self.expr(&p.default);
        let top_level = self.include_stack.len() <= 1 && self.env.depth() == Some(0);
        if !top_level {
            self.report(
                Diagnostic::error(
                    codes::BAD_PARAM,
                    span,
                    "a `param` inside a block or an included file",
                    "declared here",
                )
                .with_note(
                    "parameters belong to the top level of the scene's own file, where `-D` and the studio find them",
                )
                .with_hint("try a `let` here, or move the `param` to the top of the scene"),
            );
            self.bind(&p.name, Bound::Value(default));
            return;
        }
        let declared = self.declare(p, &default, span);
        let value = match declared {
            Some(mut param) => {
                let value = self.given(&param, p).unwrap_or_else(|| param.default.clone());
                param.value = value.clone();
                if self.dry == 0 {
                    self.params.push(param);
                }
                to_value(&value)
            }
            None => Value::Error,
        };
        if !value.is_error() {
            self.lets.entry(p.name.span).or_insert_with(|| (p.name.name.clone(), false));
        }
        let ty = (!value.is_error()).then(|| value.ty_name());
        self.note_def(&p.name, index::DefKind::Value, ty, span.end, self.block_end);
        self.bind(&p.name, Bound::Value(value));
    }

    /// The parameter as declared, its value still the default; `None` after an error.
    fn declare(&mut self, p: &ast::ParamDecl, default: &Value, span: Span) -> Option<ir::SceneParam> {
        if let Some(first) = self.params.iter().find(|q| q.name == p.name.name) {
            let first = first.span;
            self.report(
                Diagnostic::error(
                    codes::BAD_PARAM,
                    p.name.span,
                    format!("`{}` is declared twice", p.name.name),
                    "again here",
                )
                .with_label(first, "first declared here"),
            );
            return None;
        }
        let default_value = match from_value(default) {
            Some(v) => v,
            None if default.is_error() => return None,
            None => {
                self.report(
                    Diagnostic::error(
                        codes::BAD_PARAM,
                        p.default.span,
                        "a parameter is a number, truth value, string or colour",
                        default.this_is(),
                    )
                    .with_hint("try `param width = 20 in 1 .. 100` or `param lid = true`"),
                );
                return None;
            }
        };
        let mut param = ir::SceneParam {
            name: p.name.name.clone(),
            default: default_value.clone(),
            value: default_value.clone(),
            range: None,
            choices: Vec::new(),
            step: None,
            description: p.description.clone(),
            group: p.group.clone(),
            span,
            default_span: p.default.span,
        };
        match &p.domain {
            None => {}
            Some(ast::ParamDomain::Range(lo, hi)) => {
                param.range = Some(self.range(lo, hi, &default_value, p.default.span)?)
            }
            Some(ast::ParamDomain::Choices(list)) => {
                param.choices = self.choices(list, &default_value, p.default.span)?
            }
        }
        if let Some(step) = &p.step {
            match (self.expr(step), &default_value) {
                (Value::Num(s), ParamValue::Num(_)) if s > 0.0 && s.is_finite() => param.step = Some(s),
                (Value::Error, _) => return None,
                (v, ParamValue::Num(_)) => {
                    let label = if let Value::Num(_) = v { "not above 0".to_string() } else { v.this_is() };
                    self.report(Diagnostic::error(codes::BAD_PARAM, step.span, "a step is a number above 0", label));
                    return None;
                }
                (_, other) => {
                    let label = format!("this parameter is a `{}`", other.ty());
                    self.report(Diagnostic::error(codes::BAD_PARAM, step.span, "only a number has a step", label));
                    return None;
                }
            }
        }
        Some(param)
    }

    /// `lo .. hi` of a number parameter, with its default inside.
    fn range(&mut self, lo: &ast::Expr, hi: &ast::Expr, default: &ParamValue, at: Span) -> Option<(f64, f64)> {
        let ends = (self.expr(lo), self.expr(hi));
        let (lo_v, hi_v) = match ends {
            (Value::Num(a), Value::Num(b)) => (a, b),
            (Value::Error, _) | (_, Value::Error) => return None,
            (a, b) => {
                let (bad, span) = if matches!(a, Value::Num(_)) { (b, hi.span) } else { (a, lo.span) };
                self.report(Diagnostic::error(codes::BAD_PARAM, span, "a range's ends are numbers", bad.this_is()));
                return None;
            }
        };
        let whole = lo.span.to(hi.span);
        if lo_v >= hi_v {
            let label = format!("{} is not below {}", ir::dump_num(lo_v), ir::dump_num(hi_v));
            self.report(Diagnostic::error(codes::BAD_PARAM, whole, "a parameter's range is empty", label));
            return None;
        }
        match default {
            ParamValue::Num(d) if (lo_v..=hi_v).contains(d) => Some((lo_v, hi_v)),
            ParamValue::Num(d) => {
                let label = format!("{} is outside {} .. {}", ir::dump_num(*d), ir::dump_num(lo_v), ir::dump_num(hi_v));
                self.report(
                    Diagnostic::error(codes::BAD_PARAM, at, "the default is outside the parameter's range", label)
                        .with_label(whole, "the range"),
                );
                None
            }
            other => {
                let label = format!("this parameter is a `{}`", other.ty());
                self.report(
                    Diagnostic::error(codes::BAD_PARAM, whole, "only a number has a range", label)
                        .with_hint("for a choice of values, try `in [\"a\", \"b\"]`"),
                );
                None
            }
        }
    }

    /// `in [a, b, …]`: the choices, of the default's type, the default among them.
    fn choices(&mut self, list: &ast::Expr, default: &ParamValue, at: Span) -> Option<Vec<ParamValue>> {
        let items = match self.expr(list) {
            Value::List(items) if !items.is_empty() => items,
            Value::Error => return None,
            v => {
                let label = if let Value::List(_) = v { "an empty list".to_string() } else { v.this_is() };
                self.report(
                    Diagnostic::error(
                        codes::BAD_PARAM,
                        list.span,
                        "the values a parameter may take are a list or a range",
                        label,
                    )
                    .with_hint("try `in 1 .. 100` or `in [\"round\", \"square\"]`"),
                );
                return None;
            }
        };
        let mut choices = Vec::with_capacity(items.len());
        for item in items.iter() {
            match from_value(item).filter(|v| v.ty() == default.ty()) {
                Some(v) => choices.push(v),
                None => {
                    let label =
                        format!("this parameter is a `{}`; the list holds a `{}`", default.ty(), item.ty_name());
                    self.report(Diagnostic::error(codes::BAD_PARAM, list.span, "a choice of another type", label));
                    return None;
                }
            }
        }
        if !choices.contains(default) {
            let label = format!("{} is not one of the choices", default.source());
            self.report(
                Diagnostic::error(codes::BAD_PARAM, at, "the default is not one of the parameter's choices", label)
                    .with_label(list.span, "the choices"),
            );
            return None;
        }
        Some(choices)
    }

    /// The value given from outside for `param`, checked against its type and domain;
    /// `None` when none was given or it was wrong (then reported, and the default used
    /// so that the rest of the scene is still checked).
    fn given(&mut self, param: &ir::SceneParam, p: &ast::ParamDecl) -> Option<ParamValue> {
        let given = self.overrides.get(&param.name)?.clone();
        let wrong = |msg: String, label: String| Diagnostic::error(codes::BAD_PARAM_VALUE, p.name.span, msg, label);
        let value = match ParamValue::parse(&given.text, &param.default) {
            Ok(v) => v,
            Err(why) => {
                let label = format!("`{}` is a `{}`", param.name, param.default.ty());
                self.report(wrong(format!("{}: {why}", given.origin), label));
                return None;
            }
        };
        if let (Some((lo, hi)), ParamValue::Num(x)) = (param.range, &value) {
            if !(lo..=hi).contains(x) {
                let (lo, hi) = (ir::dump_num(lo), ir::dump_num(hi));
                self.report(wrong(
                    format!("{} is outside {lo} .. {hi}", given.origin),
                    format!("`{}` takes {lo} .. {hi}", param.name),
                ));
                return None;
            }
        }
        if !param.choices.is_empty() && !param.choices.contains(&value) {
            let list: Vec<String> = param.choices.iter().map(ParamValue::source).collect();
            let label = format!("`{}` takes one of {}", param.name, list.join(", "));
            self.report(wrong(format!("{} is not one of the choices", given.origin), label));
            return None;
        }
        Some(value)
    }

    /// Reports every value given for a parameter the scene does not declare.
    pub(super) fn unknown_overrides(&mut self) {
        let names: Vec<String> = self.params.iter().map(|p| p.name.clone()).collect();
        let unknown: Vec<_> = self.overrides.0.iter().filter(|o| !names.contains(&o.name)).cloned().collect();
        let start = self.file_start();
        for o in unknown {
            let mut d = Diagnostic::error(
                codes::BAD_PARAM_VALUE,
                start,
                format!("{} sets no parameter of the scene", o.origin),
                format!("the scene has no `param {}`", o.name),
            );
            d = match suggest(&o.name, names.iter().map(String::as_str)) {
                Some(near) => d.with_hint(format!("did you mean `{near}`?")),
                None if names.is_empty() => d.with_note("the scene declares no parameters"),
                None => d.with_note(format!("its parameters are {}", names.join(", "))),
            };
            self.report(d);
        }
    }
}

/// A checked value as a parameter's, when it is of a type a parameter may have.
fn from_value(v: &Value) -> Option<ParamValue> {
    Some(match v {
        Value::Num(x) => ParamValue::Num(*x),
        Value::Bool(b) => ParamValue::Bool(*b),
        Value::Str(s) => ParamValue::Str(s.to_string()),
        Value::Color(c) => ParamValue::Color([c.x, c.y, c.z]),
        _ => return None,
    })
}

fn to_value(v: &ParamValue) -> Value {
    match v {
        ParamValue::Num(x) => Value::Num(*x),
        ParamValue::Bool(b) => Value::Bool(*b),
        ParamValue::Str(s) => Value::Str(s.as_str().into()),
        ParamValue::Color(c) => Value::Color(glam::DVec3::from_array(*c)),
    }
}
