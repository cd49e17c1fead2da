//! The syntax tree: what was written, with spans; no names resolved, no types.

use crate::span::Span;

/// A name as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    /// The text.
    pub name: String,
    /// Where.
    pub span: Span,
}

/// A parsed file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct File {
    /// Top-level statements in order.
    pub stmts: Vec<Stmt>,
}

/// A statement with its span.
#[derive(Clone, Debug, PartialEq)]
pub struct Stmt {
    /// What kind.
    pub kind: StmtKind,
    /// The whole statement.
    pub span: Span,
}

/// The statements of the language.
#[derive(Clone, Debug, PartialEq)]
pub enum StmtKind {
    /// `camera(args)`
    Camera(Vec<Arg>),
    /// `render(args)`
    Render(Vec<Arg>),
    /// `light expr`
    Light(Expr),
    /// `object expr`
    Object(Expr),
    /// `let name = expr` or `let name(params) = expr`.
    Let {
        /// The bound name.
        name: Ident,
        /// `Some` for a function.
        params: Option<Vec<Ident>>,
        /// The value or function body.
        value: Expr,
    },
    /// `param name = default …`: a value the command line or the studio may set.
    Param(Box<ParamDecl>),
    /// `for var in start..end { body }` (end exclusive) or `for var in list { body }`.
    For {
        /// Loop variable and what it runs over.
        each: Generator,
        /// The statements repeated.
        body: Vec<Stmt>,
    },
    /// `if c { … } else if d { … } else { … }`.
    If {
        /// Each condition with the statements it guards, in order.
        branches: Vec<(Expr, Vec<Stmt>)>,
        /// The statements of the final `else`, if any.
        otherwise: Option<Vec<Stmt>>,
    },
    /// `include "path"`.
    Include {
        /// The path as written (unquoted).
        path: String,
        /// The string literal's span.
        path_span: Span,
    },
    /// A statement that failed to parse (already reported).
    Error,
}

/// `param name = default [in lo .. hi | in [choices]] [step s] ["description"] [group "name"]`.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamDecl {
    /// The parameter's name, read like a `let`'s.
    pub name: Ident,
    /// Its value unless overridden.
    pub default: Expr,
    /// The values it may take: `lo .. hi` (both included) or a list of choices.
    pub domain: Option<ParamDomain>,
    /// A slider's step.
    pub step: Option<Expr>,
    /// What it means, for people (the string literal, unquoted).
    pub description: Option<String>,
    /// The heading the customizer shows it under.
    pub group: Option<String>,
}

/// The values a parameter may take.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamDomain {
    /// `lo .. hi`, both ends included.
    Range(Expr, Expr),
    /// A list of the allowed values.
    Choices(Expr),
}

/// `var in start..end` or `var in list`: one loop variable and what it runs over.
#[derive(Clone, Debug, PartialEq)]
pub struct Generator {
    /// The variable.
    pub var: Ident,
    /// What it takes in turn.
    pub over: Iterable,
}

/// What a `for` runs over.
#[derive(Clone, Debug, PartialEq)]
pub enum Iterable {
    /// The whole numbers from `start` up to, not including, `end`.
    Range {
        /// First value.
        start: Expr,
        /// One past the last value.
        end: Expr,
    },
    /// The elements of a list.
    List(Expr),
}

/// A call argument, positional or named.
#[derive(Clone, Debug, PartialEq)]
pub struct Arg {
    /// `Some(name)` for `name = value`.
    pub name: Option<Ident>,
    /// The value.
    pub value: Expr,
}

/// An expression with its span.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// What kind.
    pub kind: ExprKind,
    /// Where.
    pub span: Span,
}

impl Drop for Expr {
    /// Takes the tree apart with a stack of its own: a chain without brackets (a sum of
    /// a million terms, `- - - 1`, `s at … at …`) is as deep as the input is long, and
    /// the compiler's recursive drop would overflow any thread's stack on it.
    fn drop(&mut self) {
        let mut pending = Vec::new();
        self.kind.move_children(&mut pending);
        while let Some(mut e) = pending.pop() {
            e.kind.move_children(&mut pending);
        }
    }
}

impl ExprKind {
    /// Moves every child expression out into `out`, leaving [`ExprKind::Error`] in its
    /// place (what [`Expr`]'s drop walks).
    fn move_children(&mut self, out: &mut Vec<Expr>) {
        let mut take = |e: &mut Expr| out.push(std::mem::replace(e, Expr { kind: ExprKind::Error, span: e.span }));
        match self {
            ExprKind::Number(_)
            | ExprKind::Bool(_)
            | ExprKind::Str(_)
            | ExprKind::HexColor(_)
            | ExprKind::Ident(_)
            | ExprKind::Error => {}
            ExprKind::List(items) => items.iter_mut().for_each(take),
            ExprKind::Call { args, .. } | ExprKind::Mesh { args, .. } => {
                args.iter_mut().for_each(|a| take(&mut a.value))
            }
            ExprKind::Index { base, index } => {
                take(base);
                take(index);
            }
            ExprKind::Component { base: e, .. }
            | ExprKind::Field { body: e, .. }
            | ExprKind::Neg(e)
            | ExprKind::Not(e) => take(e),
            ExprKind::If { cond, then, otherwise } => {
                take(cond);
                take(then);
                take(otherwise);
            }
            ExprKind::Comprehension { generators, filter, body } => {
                for g in generators {
                    match &mut g.over {
                        Iterable::Range { start, end } => {
                            take(start);
                            take(end);
                        }
                        Iterable::List(e) => take(e),
                    }
                }
                if let Some(f) = filter {
                    take(f);
                }
                take(body);
            }
            ExprKind::Binary { lhs, rhs, .. } => {
                take(lhs);
                take(rhs);
            }
            ExprKind::Transform { target, arg, .. } => {
                take(target);
                take(arg);
            }
        }
    }
}

/// Binary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `%`
    Rem,
    /// `==`
    Eq,
    /// `!=`
    Ne,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
    /// `and` (the right operand is evaluated only when the left is `true`)
    And,
    /// `or` (the right operand is evaluated only when the left is `false`)
    Or,
}

impl BinOp {
    /// As written.
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Rem => "%",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::And => "and",
            BinOp::Or => "or",
        }
    }
}

/// Postfix transforms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransformOp {
    /// `at [x, y, z]`
    At,
    /// `rotate [rx, ry, rz]`
    Rotate,
    /// `scale k` or `scale [kx, ky, kz]`
    Scale,
    /// `with material`
    With,
}

impl TransformOp {
    /// As written.
    pub fn keyword(self) -> &'static str {
        match self {
            TransformOp::At => "at",
            TransformOp::Rotate => "rotate",
            TransformOp::Scale => "scale",
            TransformOp::With => "with",
        }
    }
}

/// The expressions of the language.
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A number literal, parsed once here (infinite when it overflows, which the
    /// checker reports); `None` when malformed (the lexer reported it).
    Number(Option<f64>),
    /// `true` / `false`.
    Bool(bool),
    /// A string literal, escapes resolved.
    Str(String),
    /// `#rrggbb`.
    HexColor([u8; 3]),
    /// A name.
    Ident(Ident),
    /// `[a, b, c]`: a `vec3` when it holds three numbers, else a list.
    List(Vec<Expr>),
    /// `name(args)`.
    Call {
        /// The function.
        callee: Ident,
        /// The arguments.
        args: Vec<Arg>,
    },
    /// `base[index]`.
    Index {
        /// The list or vector.
        base: Box<Expr>,
        /// The index.
        index: Box<Expr>,
    },
    /// `base.x`, `base.y` or `base.z`: one component of a vector.
    Component {
        /// The vector.
        base: Box<Expr>,
        /// The component's name, as written (the checker refuses any but `x`, `y`, `z`).
        axis: Ident,
    },
    /// `p => body`, a field literal: a function of the point `p`, written only as an
    /// argument of a builtin that takes one (`field`, `warp`, `displace`).
    Field {
        /// The point's name.
        param: Ident,
        /// The value at the point.
        body: Box<Expr>,
    },
    /// `-expr`.
    Neg(Box<Expr>),
    /// `not expr`.
    Not(Box<Expr>),
    /// `if cond then a else b`.
    If {
        /// The condition.
        cond: Box<Expr>,
        /// The value when it holds.
        then: Box<Expr>,
        /// The value when it does not.
        otherwise: Box<Expr>,
    },
    /// `[for i in 0..n, p in ps if cond => body]`.
    Comprehension {
        /// The loop variables, outermost first.
        generators: Vec<Generator>,
        /// Elements are made only where this holds.
        filter: Option<Box<Expr>>,
        /// Each element.
        body: Box<Expr>,
    },
    /// `lhs op rhs`.
    Binary {
        /// Operator.
        op: BinOp,
        /// Left operand.
        lhs: Box<Expr>,
        /// Right operand.
        rhs: Box<Expr>,
    },
    /// `target at|rotate|scale|with arg`.
    Transform {
        /// Which transform.
        op: TransformOp,
        /// The keyword's span.
        op_span: Span,
        /// What is transformed.
        target: Box<Expr>,
        /// The vector, factor or material.
        arg: Box<Expr>,
    },
    /// `mesh generator(args)`.
    Mesh {
        /// The generator name.
        generator: Ident,
        /// Its arguments.
        args: Vec<Arg>,
    },
    /// An expression that failed to parse (already reported).
    Error,
}
