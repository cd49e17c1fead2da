//! Field expressions: the bodies of `p => …` literals, functions of the point `p` with
//! everything that does not depend on it already folded to a number.
//!
//! An expression is a tree of `Arc`-shared nodes (a name used twice in a body is one
//! node reached twice); its meaning is fixed here, in f64, by [`FieldExpr::eval`], which the
//! back-ends' f32 evaluators (`crate::field`) are tested against.

use std::fmt::Write as _;
use std::sync::Arc;

use glam::DVec3;

use super::Shape;
use crate::sig::num;

/// What a field expression evaluates to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FieldTy {
    /// A number.
    Num,
    /// A vector.
    Vec3,
    /// A truth value (a comparison), only ever a condition.
    Bool,
}

impl FieldTy {
    /// The language's name for it.
    pub fn name(self) -> &'static str {
        match self {
            FieldTy::Num => "num",
            FieldTy::Vec3 => "vec3",
            FieldTy::Bool => "bool",
        }
    }
}

/// One node of a field expression.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldExpr {
    /// What it computes.
    pub kind: FieldKind,
    /// Its type, fixed by its operands'.
    pub ty: FieldTy,
}

/// Lists the functions of one operand once: each variant with its doc and its name (the
/// builtin's, or the operator), from which the enum, [`Unary::name`] and [`Unary::ALL`]
/// are made. What a function computes is [`Unary::apply`], matched exhaustively there
/// and in every evaluator, so a new line here fails to compile until each has it.
macro_rules! unaries {
    ($($(#[doc = $doc:literal])* $variant:ident => $name:literal,)*) => {
        /// Functions of one operand.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Unary {
            $($(#[doc = $doc])* $variant,)*
        }

        impl Unary {
            /// Every function, in the list's order (tests walk them all).
            pub const ALL: &[Unary] = &[$(Unary::$variant),*];

            /// The function's name (`-` and `not` as operators).
            pub fn name(self) -> &'static str {
                match self {
                    $(Unary::$variant => $name,)*
                }
            }
        }
    };
}

unaries! {
    /// `-x` of a number or vector.
    Neg => "-",
    /// `not b`.
    Not => "not",
    /// Sine of degrees.
    Sin => "sin",
    /// Cosine of degrees.
    Cos => "cos",
    /// Tangent of degrees.
    Tan => "tan",
    /// Arcsine in degrees; its operand is clamped to [−1, 1].
    Asin => "asin",
    /// Arccosine in degrees; its operand is clamped to [−1, 1].
    Acos => "acos",
    /// Arctangent in degrees.
    Atan => "atan",
    /// Square root; of 0 below 0.
    Sqrt => "sqrt",
    /// Absolute value.
    Abs => "abs",
    /// Largest whole number not above.
    Floor => "floor",
    /// Smallest whole number not below.
    Ceil => "ceil",
    /// Nearest whole number, halves away from zero.
    Round => "round",
    /// What is left above the largest whole number not above, in [0, 1).
    Fract => "fract",
    /// −1, 0 or 1.
    Sign => "sign",
    /// e to the power.
    Exp => "exp",
    /// Natural logarithm; of the smallest positive f32 at or below 0.
    Log => "log",
    /// Length of a vector.
    Length => "length",
    /// A vector scaled to length 1 (the zero vector stays zero).
    Normalize => "normalize",
}

/// Functions of two operands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Binary {
    /// `+` of numbers or vectors.
    Add,
    /// `-` of numbers or vectors.
    Sub,
    /// `*`: numbers, a vector and a number, or two vectors by component.
    Mul,
    /// `/`: as `*`.
    Div,
    /// `%`: as `/`, the remainder with the sign of the dividend.
    Rem,
    /// `<` of numbers.
    Lt,
    /// `<=` of numbers.
    Le,
    /// `>` of numbers.
    Gt,
    /// `>=` of numbers.
    Ge,
    /// `==` of numbers or truth values.
    Eq,
    /// `!=` of numbers or truth values.
    Ne,
    /// `and`.
    And,
    /// `or`.
    Or,
    /// The smaller number.
    Min,
    /// The larger number.
    Max,
    /// `pow(x, y)`; of `|x|` when `x` is negative and `y` not whole.
    Pow,
    /// `atan2(y, x)` in degrees.
    Atan2,
    /// Dot product.
    Dot,
    /// Cross product.
    Cross,
}

/// What a node computes.
#[derive(Clone, Debug, PartialEq)]
pub enum FieldKind {
    /// The point `p`.
    Point,
    /// A number known before rendering.
    Num(f64),
    /// A vector known before rendering.
    Vec(DVec3),
    /// One component (0, 1, 2 for x, y, z) of a vector.
    Component(Arc<FieldExpr>, usize),
    /// A vector of three numbers.
    Vector([Arc<FieldExpr>; 3]),
    /// A function of one operand.
    Unary(Unary, Arc<FieldExpr>),
    /// A function of two operands.
    Binary(Binary, Arc<FieldExpr>, Arc<FieldExpr>),
    /// `if c then a else b`, both of one type.
    Select(Arc<FieldExpr>, Arc<FieldExpr>, Arc<FieldExpr>),
    /// `dist(shape, q)`: the shape's signed distance bound at the point `q`.
    Dist(Arc<Shape>, Arc<FieldExpr>),
    /// `noise3(q, size, seed)`: the `noise` pattern's gradient noise at `q / size`.
    Noise {
        /// Where.
        at: Arc<FieldExpr>,
        /// The feature size, > 0.
        size: f64,
        /// The seed.
        seed: u32,
    },
    /// The signed distance of a 2D outline (`text`'s glyphs) at the `x` and `y` of a point.
    Outline(Arc<crate::geom::outline::Outline>, Arc<FieldExpr>),
}

impl Unary {
    /// The result's type for an operand of type `x`; `None` if it takes no such operand.
    pub fn ty(self, x: FieldTy) -> Option<FieldTy> {
        match (self, x) {
            (Unary::Neg, FieldTy::Num | FieldTy::Vec3) => Some(x),
            (Unary::Not, FieldTy::Bool) => Some(FieldTy::Bool),
            (Unary::Length, FieldTy::Vec3) => Some(FieldTy::Num),
            (Unary::Normalize, FieldTy::Vec3) => Some(FieldTy::Vec3),
            (Unary::Neg | Unary::Not | Unary::Length | Unary::Normalize, _) => None,
            (_, FieldTy::Num) => Some(FieldTy::Num),
            _ => None,
        }
    }

    /// The function at `x`, in f64 (the definition the evaluators follow).
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Unary::Neg => -x,
            Unary::Not => f64::from(x == 0.0),
            Unary::Sin => x.to_radians().sin(),
            Unary::Cos => x.to_radians().cos(),
            Unary::Tan => x.to_radians().tan(),
            Unary::Asin => x.clamp(-1.0, 1.0).asin().to_degrees(),
            Unary::Acos => x.clamp(-1.0, 1.0).acos().to_degrees(),
            Unary::Atan => x.atan().to_degrees(),
            Unary::Sqrt => x.max(0.0).sqrt(),
            Unary::Abs => x.abs(),
            Unary::Floor => x.floor(),
            Unary::Ceil => x.ceil(),
            Unary::Round => x.round(),
            Unary::Fract => x - x.floor(),
            Unary::Sign => {
                if x == 0.0 {
                    0.0
                } else {
                    x.signum()
                }
            }
            Unary::Exp => x.exp(),
            Unary::Log => x.max(f64::from(f32::MIN_POSITIVE)).ln(),
            // Vector functions are applied by `FieldExpr::eval`.
            Unary::Length | Unary::Normalize => f64::NAN,
        }
    }
}

impl Binary {
    /// The operator as written, or the function's name.
    pub fn name(self) -> &'static str {
        match self {
            Binary::Add => "+",
            Binary::Sub => "-",
            Binary::Mul => "*",
            Binary::Div => "/",
            Binary::Rem => "%",
            Binary::Lt => "<",
            Binary::Le => "<=",
            Binary::Gt => ">",
            Binary::Ge => ">=",
            Binary::Eq => "==",
            Binary::Ne => "!=",
            Binary::And => "and",
            Binary::Or => "or",
            Binary::Min => "min",
            Binary::Max => "max",
            Binary::Pow => "pow",
            Binary::Atan2 => "atan2",
            Binary::Dot => "dot",
            Binary::Cross => "cross",
        }
    }

    /// Whether it is written as a function call rather than between its operands.
    pub fn is_call(self) -> bool {
        matches!(self, Binary::Min | Binary::Max | Binary::Pow | Binary::Atan2 | Binary::Dot | Binary::Cross)
    }

    /// The result's type for operands of types `a` and `b`; `None` if it takes no such pair.
    pub fn ty(self, a: FieldTy, b: FieldTy) -> Option<FieldTy> {
        use FieldTy::{Bool, Num, Vec3};
        match (self, a, b) {
            (Binary::Add | Binary::Sub, Num, Num) => Some(Num),
            (Binary::Add | Binary::Sub, Vec3, Vec3) => Some(Vec3),
            (Binary::Mul | Binary::Div | Binary::Rem, Num, Num) => Some(Num),
            (Binary::Mul | Binary::Div | Binary::Rem, Vec3, Vec3 | Num) => Some(Vec3),
            (Binary::Mul, Num, Vec3) => Some(Vec3),
            (Binary::Lt | Binary::Le | Binary::Gt | Binary::Ge, Num, Num) => Some(Bool),
            (Binary::Eq | Binary::Ne, Num, Num) | (Binary::Eq | Binary::Ne, Bool, Bool) => Some(Bool),
            (Binary::And | Binary::Or, Bool, Bool) => Some(Bool),
            (Binary::Min | Binary::Max | Binary::Pow | Binary::Atan2, Num, Num) => Some(Num),
            (Binary::Dot, Vec3, Vec3) => Some(Num),
            (Binary::Cross, Vec3, Vec3) => Some(Vec3),
            _ => None,
        }
    }

    /// The function of two numbers, in f64 (truth values are 1 and 0).
    pub fn apply(self, x: f64, y: f64) -> f64 {
        match self {
            Binary::Add => x + y,
            Binary::Sub => x - y,
            Binary::Mul => x * y,
            Binary::Div => x / y,
            Binary::Rem => x % y,
            Binary::Lt => f64::from(x < y),
            Binary::Le => f64::from(x <= y),
            Binary::Gt => f64::from(x > y),
            Binary::Ge => f64::from(x >= y),
            Binary::Eq => f64::from(x == y),
            Binary::Ne => f64::from(x != y),
            Binary::And => f64::from(x != 0.0 && y != 0.0),
            Binary::Or => f64::from(x != 0.0 || y != 0.0),
            Binary::Min => x.min(y),
            Binary::Max => x.max(y),
            Binary::Pow => {
                if x < 0.0 && y.fract() != 0.0 {
                    x.abs().powf(y)
                } else {
                    x.powf(y)
                }
            }
            // `atan2(y, x)`: the first operand is y.
            Binary::Atan2 => (x + 0.0).atan2(y).to_degrees(),
            // Vector functions are applied by `FieldExpr::eval`.
            Binary::Dot | Binary::Cross => f64::NAN,
        }
    }
}

/// The value of an expression at a point, in f64: a number (truth values as 1 and 0)
/// or a vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Val {
    /// A number or truth value.
    Num(f64),
    /// A vector.
    Vec(DVec3),
}

impl Val {
    /// The number (a vector's x).
    pub fn num(self) -> f64 {
        match self {
            Val::Num(x) => x,
            Val::Vec(v) => v.x,
        }
    }

    /// The vector (a number splatted).
    pub fn vec(self) -> DVec3 {
        match self {
            Val::Num(x) => DVec3::splat(x),
            Val::Vec(v) => v,
        }
    }
}

impl FieldExpr {
    /// A node of `kind` whose type is `ty`.
    pub fn new(kind: FieldKind, ty: FieldTy) -> Arc<FieldExpr> {
        Arc::new(FieldExpr { kind, ty })
    }

    /// The point `p`.
    pub fn point() -> Arc<FieldExpr> {
        FieldExpr::new(FieldKind::Point, FieldTy::Vec3)
    }

    /// A number.
    pub fn num(x: f64) -> Arc<FieldExpr> {
        FieldExpr::new(FieldKind::Num(x), FieldTy::Num)
    }

    /// A vector.
    pub fn vec(v: DVec3) -> Arc<FieldExpr> {
        FieldExpr::new(FieldKind::Vec(v), FieldTy::Vec3)
    }

    /// The vector `[x, y, z]` of three number expressions.
    pub fn vector(xs: [Arc<FieldExpr>; 3]) -> Arc<FieldExpr> {
        FieldExpr::new(FieldKind::Vector(xs), FieldTy::Vec3)
    }

    /// Component `k` (0, 1, 2 for x, y, z) of a vector expression.
    pub fn component(v: &Arc<FieldExpr>, k: usize) -> Arc<FieldExpr> {
        FieldExpr::new(FieldKind::Component(v.clone(), k), FieldTy::Num)
    }

    /// `f(x)`; `None` if `f` takes no operand of `x`'s type.
    pub fn unary(f: Unary, x: Arc<FieldExpr>) -> Option<Arc<FieldExpr>> {
        let ty = f.ty(x.ty)?;
        Some(FieldExpr::new(FieldKind::Unary(f, x), ty))
    }

    /// `f(a, b)`; `None` if `f` takes no operands of these types.
    pub fn binary(f: Binary, a: Arc<FieldExpr>, b: Arc<FieldExpr>) -> Option<Arc<FieldExpr>> {
        let ty = f.ty(a.ty, b.ty)?;
        Some(FieldExpr::new(FieldKind::Binary(f, a, b), ty))
    }

    /// The operands, in order.
    pub fn operands(&self) -> Vec<&Arc<FieldExpr>> {
        match &self.kind {
            FieldKind::Point | FieldKind::Num(_) | FieldKind::Vec(_) => vec![],
            FieldKind::Component(x, _)
            | FieldKind::Unary(_, x)
            | FieldKind::Dist(_, x)
            | FieldKind::Noise { at: x, .. }
            | FieldKind::Outline(_, x) => vec![x],
            FieldKind::Vector(xs) => xs.iter().collect(),
            FieldKind::Binary(_, a, b) => vec![a, b],
            FieldKind::Select(c, a, b) => vec![c, a, b],
        }
    }

    /// Whether the value depends on the point (else it is a constant the checker folded).
    pub fn uses_point(&self) -> bool {
        match &self.kind {
            FieldKind::Point => true,
            FieldKind::Num(_) | FieldKind::Vec(_) => false,
            _ => self.operands().iter().any(|x| x.uses_point()),
        }
    }

    /// Distinct nodes (shared ones once): the work of one evaluation.
    pub fn size(self: &Arc<FieldExpr>) -> usize {
        let mut seen = std::collections::HashSet::new();
        let mut stack = vec![self];
        while let Some(e) = stack.pop() {
            if seen.insert(Arc::as_ptr(e)) {
                stack.extend(e.operands());
            }
        }
        seen.len()
    }

    /// This expression with the point replaced by `q` (an expression of the new point):
    /// `f(p)` becomes `f(q(p))`. Shared nodes stay shared.
    pub fn substitute(self: &Arc<FieldExpr>, q: &Arc<FieldExpr>) -> Arc<FieldExpr> {
        fn walk(
            e: &Arc<FieldExpr>,
            q: &Arc<FieldExpr>,
            memo: &mut std::collections::HashMap<*const FieldExpr, Arc<FieldExpr>>,
        ) -> Arc<FieldExpr> {
            if !e.uses_point() {
                return e.clone();
            }
            if let Some(done) = memo.get(&Arc::as_ptr(e)) {
                return done.clone();
            }
            let mut w = |x: &Arc<FieldExpr>| walk(x, q, memo);
            let kind = match &e.kind {
                FieldKind::Point => return q.clone(),
                FieldKind::Num(_) | FieldKind::Vec(_) => return e.clone(),
                FieldKind::Component(x, k) => FieldKind::Component(w(x), *k),
                FieldKind::Vector([a, b, c]) => FieldKind::Vector([w(a), w(b), w(c)]),
                FieldKind::Unary(f, x) => FieldKind::Unary(*f, w(x)),
                FieldKind::Binary(f, a, b) => FieldKind::Binary(*f, w(a), w(b)),
                FieldKind::Select(c, a, b) => FieldKind::Select(w(c), w(a), w(b)),
                FieldKind::Dist(s, at) => FieldKind::Dist(s.clone(), w(at)),
                FieldKind::Noise { at, size, seed } => FieldKind::Noise { at: w(at), size: *size, seed: *seed },
                FieldKind::Outline(o, at) => FieldKind::Outline(o.clone(), w(at)),
            };
            let out = FieldExpr::new(kind, e.ty);
            memo.insert(Arc::as_ptr(e), out.clone());
            out
        }
        walk(self, q, &mut std::collections::HashMap::new())
    }

    /// The shapes `dist` reads, in first-use order, each once.
    pub fn shapes(self: &Arc<FieldExpr>) -> Vec<Arc<Shape>> {
        let mut out: Vec<Arc<Shape>> = Vec::new();
        let mut seen = std::collections::HashSet::new();
        let mut stack = vec![self];
        while let Some(e) = stack.pop() {
            if !seen.insert(Arc::as_ptr(e)) {
                continue;
            }
            if let FieldKind::Dist(s, _) = &e.kind {
                if !out.iter().any(|o| Arc::ptr_eq(o, s)) {
                    out.push(s.clone());
                }
            }
            // Reversed, so operands are visited left to right.
            stack.extend(e.operands().into_iter().rev());
        }
        out
    }

    /// The value at `p`, in f64, with `dist(shape, q)` given by `dist` (by the shape's
    /// index in [`shapes`](Self::shapes)).
    pub fn eval(&self, p: DVec3, dist: &dyn Fn(&Arc<Shape>, DVec3) -> f64) -> Val {
        let n = |e: &Arc<FieldExpr>| e.eval(p, dist).num();
        let v = |e: &Arc<FieldExpr>| e.eval(p, dist).vec();
        match &self.kind {
            FieldKind::Point => Val::Vec(p),
            FieldKind::Num(x) => Val::Num(*x),
            FieldKind::Vec(x) => Val::Vec(*x),
            FieldKind::Component(x, i) => Val::Num(v(x)[*i]),
            FieldKind::Vector(xs) => Val::Vec(DVec3::new(n(&xs[0]), n(&xs[1]), n(&xs[2]))),
            FieldKind::Unary(Unary::Length, x) => Val::Num(v(x).length()),
            FieldKind::Unary(Unary::Normalize, x) => Val::Vec(v(x).normalize_or_zero()),
            FieldKind::Unary(f, x) if x.ty == FieldTy::Vec3 => Val::Vec(v(x).to_array().map(|c| f.apply(c)).into()),
            FieldKind::Unary(f, x) => Val::Num(f.apply(n(x))),
            FieldKind::Binary(Binary::Dot, a, b) => Val::Num(v(a).dot(v(b))),
            FieldKind::Binary(Binary::Cross, a, b) => Val::Vec(v(a).cross(v(b))),
            FieldKind::Binary(f, a, b) if self.ty == FieldTy::Vec3 => {
                let (a, b) = (v(a), v(b));
                Val::Vec(DVec3::new(f.apply(a.x, b.x), f.apply(a.y, b.y), f.apply(a.z, b.z)))
            }
            FieldKind::Binary(f, a, b) => Val::Num(f.apply(n(a), n(b))),
            FieldKind::Select(c, a, b) => {
                if n(c) != 0.0 {
                    a.eval(p, dist)
                } else {
                    b.eval(p, dist)
                }
            }
            FieldKind::Dist(s, q) => Val::Num(dist(s, v(q))),
            FieldKind::Noise { at, size, seed } => Val::Num(crate::geom::noise(v(at) / *size, *seed)),
            FieldKind::Outline(o, at) => {
                let q = v(at);
                Val::Num(o.nearest(glam::DVec2::new(q.x, q.y)).d)
            }
        }
    }

    /// The expression as scn source, with `p` for the point and `shape#i` for the
    /// `i`-th shape `dist` reads ([`shapes`](Self::shapes)); cut short past `limit` bytes.
    pub fn source(self: &Arc<FieldExpr>, limit: usize) -> String {
        let shapes = self.shapes();
        let mut out = String::new();
        write_expr(&mut out, self, 0, &shapes, limit);
        if out.len() > limit {
            let mut cut = limit;
            while !out.is_char_boundary(cut) {
                cut -= 1;
            }
            out.truncate(cut);
            out.push('…');
        }
        out
    }
}

/// Binding strength of a node as written: higher binds tighter.
fn precedence(e: &FieldExpr) -> u8 {
    match &e.kind {
        FieldKind::Select(..) => 1,
        FieldKind::Binary(Binary::Or, ..) => 2,
        FieldKind::Binary(Binary::And, ..) => 3,
        FieldKind::Unary(Unary::Not, _) => 4,
        FieldKind::Binary(Binary::Lt | Binary::Le | Binary::Gt | Binary::Ge | Binary::Eq | Binary::Ne, ..) => 5,
        FieldKind::Binary(Binary::Add | Binary::Sub, ..) => 6,
        FieldKind::Binary(Binary::Mul | Binary::Div | Binary::Rem, ..) => 7,
        FieldKind::Unary(Unary::Neg, _) => 8,
        FieldKind::Num(x) if *x < 0.0 => 8,
        _ => 10,
    }
}

fn write_expr(out: &mut String, e: &Arc<FieldExpr>, outer: u8, shapes: &[Arc<Shape>], limit: usize) {
    if out.len() > limit {
        return;
    }
    let prec = precedence(e);
    let paren = prec < outer;
    if paren {
        out.push('(');
    }
    let args = |out: &mut String, xs: &[&Arc<FieldExpr>]| {
        for (i, x) in xs.iter().enumerate() {
            if i > 0 {
                out.push_str(", ");
            }
            write_expr(out, x, 0, shapes, limit);
        }
    };
    match &e.kind {
        FieldKind::Point => out.push('p'),
        FieldKind::Num(x) => out.push_str(&num(*x)),
        FieldKind::Vec(v) => out.push_str(&crate::sig::vec(*v)),
        FieldKind::Component(x, i) => {
            write_expr(out, x, 10, shapes, limit);
            out.push_str([".x", ".y", ".z"][*i]);
            // (A negative number's component needs its parentheses: `(-1).x`.)
        }
        FieldKind::Vector(xs) => {
            out.push('[');
            args(out, &[&xs[0], &xs[1], &xs[2]]);
            out.push(']');
        }
        FieldKind::Unary(Unary::Neg, x) => {
            out.push('-');
            write_expr(out, x, 8, shapes, limit);
        }
        FieldKind::Unary(Unary::Not, x) => {
            out.push_str("not ");
            write_expr(out, x, 5, shapes, limit);
        }
        FieldKind::Unary(f, x) => {
            let _ = write!(out, "{}(", f.name());
            args(out, &[x]);
            out.push(')');
        }
        FieldKind::Binary(f, a, b) if f.is_call() => {
            let _ = write!(out, "{}(", f.name());
            args(out, &[a, b]);
            out.push(')');
        }
        FieldKind::Binary(f, a, b) => {
            // Left-associative: the right operand of an equal-precedence operator needs parentheses.
            write_expr(out, a, prec, shapes, limit);
            let _ = write!(out, " {} ", f.name());
            write_expr(out, b, prec + 1, shapes, limit);
        }
        FieldKind::Select(c, a, b) => {
            out.push_str("if ");
            write_expr(out, c, 0, shapes, limit);
            out.push_str(" then ");
            write_expr(out, a, 0, shapes, limit);
            out.push_str(" else ");
            write_expr(out, b, 1, shapes, limit);
        }
        FieldKind::Dist(s, q) => {
            let i = shapes.iter().position(|o| Arc::ptr_eq(o, s)).unwrap_or(0);
            let _ = write!(out, "dist(shape#{i}, ");
            write_expr(out, q, 0, shapes, limit);
            out.push(')');
        }
        FieldKind::Noise { at, size, seed } => {
            out.push_str("noise3(");
            write_expr(out, at, 0, shapes, limit);
            let _ = write!(out, ", {}, {seed})", num(*size));
        }
        FieldKind::Outline(o, at) => {
            let _ = write!(out, "outline({:?}, ", o.label);
            write_expr(out, at, 0, shapes, limit);
            out.push(')');
        }
    }
    if paren {
        out.push(')');
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn x() -> Arc<FieldExpr> {
        FieldExpr::new(FieldKind::Component(FieldExpr::point(), 0), FieldTy::Num)
    }

    #[test]
    fn source_is_readable_and_parenthesised_where_needed() {
        let sum = FieldExpr::binary(Binary::Add, x(), FieldExpr::num(1.0)).unwrap();
        let prod = FieldExpr::binary(Binary::Mul, sum.clone(), FieldExpr::num(2.0)).unwrap();
        assert_eq!(prod.source(100), "(p.x + 1) * 2");
        let diff =
            FieldExpr::binary(Binary::Sub, x(), FieldExpr::binary(Binary::Sub, x(), FieldExpr::num(1.0)).unwrap())
                .unwrap();
        assert_eq!(diff.source(100), "p.x - (p.x - 1)");
        let s = FieldExpr::unary(Unary::Sin, prod).unwrap();
        assert_eq!(s.source(100), "sin((p.x + 1) * 2)");
        assert_eq!(s.source(5), "sin((…");
    }

    #[test]
    fn eval_follows_the_language() {
        let p = DVec3::new(3.0, 4.0, 0.0);
        let len = FieldExpr::unary(Unary::Length, FieldExpr::point()).unwrap();
        let none = |_: &Arc<Shape>, _: DVec3| 0.0;
        assert_eq!(len.eval(p, &none), Val::Num(5.0));
        let s = FieldExpr::unary(Unary::Sin, FieldExpr::num(90.0)).unwrap();
        assert_eq!(s.eval(p, &none), Val::Num(1.0), "degrees");
        let root = FieldExpr::unary(Unary::Sqrt, FieldExpr::num(-4.0)).unwrap();
        assert_eq!(root.eval(p, &none), Val::Num(0.0), "total: sqrt of a negative is 0");
        let shared = FieldExpr::binary(Binary::Mul, len.clone(), len.clone()).unwrap();
        assert_eq!(shared.size(), 3, "a shared node counts once");
    }
}
