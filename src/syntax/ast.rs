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
    /// `for var in start..end { body }` (end exclusive).
    For {
        /// Loop variable.
        var: Ident,
        /// First value.
        start: Expr,
        /// One past the last value.
        end: Expr,
        /// The statements repeated.
        body: Vec<Stmt>,
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
    /// A number literal (its text, parsed by the checker).
    Number(String),
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
    /// `-expr`.
    Neg(Box<Expr>),
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
