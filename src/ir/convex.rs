//! Which field bodies are convex functions of the point, by the composition rules of
//! disciplined convex programming (Grant, Boyd and Ye, "Disciplined Convex
//! Programming", 2006): an affine map is convex and concave; a sum of convex terms, a
//! positive multiple, a maximum, a norm of affine terms and a nondecreasing convex
//! function of a convex term are convex. The rules are sound, not complete: a body
//! they do not cover (a norm written as `pow(…, 0.25)`, anything through `dist`,
//! `if` or noise) is "not known convex", never wrongly convex.
//!
//! A convex body's set `{f < 0}` is a convex solid, so a ray leaving its surface
//! outward never meets it again; and `f` along a ray is a convex function of the
//! distance, so a secant through two points outside the solid, extended, never crosses
//! the surface before the function does (`sdf::field` steps by it).

use std::collections::HashMap;
use std::sync::Arc;

use super::field::{Binary, FieldExpr, FieldKind, FieldTy, Unary};

/// How a value bends as the point moves along any line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Curv {
    /// Straight: both convex and concave (constants too).
    Affine,
    /// Convex.
    Convex,
    /// Concave.
    Concave,
    /// Not known to be either.
    Other,
}

/// What is known of a value's sign.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Sign {
    /// ≥ 0 everywhere.
    Nonneg,
    /// ≤ 0 everywhere.
    Nonpos,
    /// Either.
    Any,
}

/// What is known of one number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Fact {
    curv: Curv,
    sign: Sign,
}

const OTHER: Fact = Fact { curv: Curv::Other, sign: Sign::Any };

impl Fact {
    fn constant(c: f64) -> Fact {
        let sign = if c >= 0.0 {
            Sign::Nonneg
        } else if c <= 0.0 {
            Sign::Nonpos
        } else {
            Sign::Any
        };
        Fact { curv: Curv::Affine, sign }
    }

    fn convexish(self) -> bool {
        matches!(self.curv, Curv::Affine | Curv::Convex)
    }

    fn concaveish(self) -> bool {
        matches!(self.curv, Curv::Affine | Curv::Concave)
    }

    fn neg(self) -> Fact {
        let curv = match self.curv {
            Curv::Convex => Curv::Concave,
            Curv::Concave => Curv::Convex,
            c => c,
        };
        let sign = match self.sign {
            Sign::Nonneg => Sign::Nonpos,
            Sign::Nonpos => Sign::Nonneg,
            Sign::Any => Sign::Any,
        };
        Fact { curv, sign }
    }

    fn add(self, o: Fact) -> Fact {
        let curv = if self.curv == Curv::Affine && o.curv == Curv::Affine {
            Curv::Affine
        } else if self.convexish() && o.convexish() {
            Curv::Convex
        } else if self.concaveish() && o.concaveish() {
            Curv::Concave
        } else {
            Curv::Other
        };
        let sign = match (self.sign, o.sign) {
            (Sign::Nonneg, Sign::Nonneg) => Sign::Nonneg,
            (Sign::Nonpos, Sign::Nonpos) => Sign::Nonpos,
            _ => Sign::Any,
        };
        Fact { curv, sign }
    }

    fn scale(self, c: f64) -> Fact {
        if c > 0.0 {
            self
        } else if c < 0.0 {
            self.neg()
        } else if c == 0.0 {
            Fact::constant(0.0)
        } else {
            OTHER
        }
    }

    /// `|x|`: convex when `x` is affine, or convex and never negative, or concave and
    /// never positive.
    fn abs(self) -> Fact {
        let curv = match (self.curv, self.sign) {
            (Curv::Affine, _) => Curv::Convex,
            (c, Sign::Nonneg) => c,
            (c, Sign::Nonpos) => Fact { curv: c, sign: Sign::Nonpos }.neg().curv,
            _ => Curv::Other,
        };
        Fact { curv, sign: Sign::Nonneg }
    }

    fn max(self, o: Fact) -> Fact {
        let curv = if self.convexish() && o.convexish() { Curv::Convex } else { Curv::Other };
        let sign = match (self.sign, o.sign) {
            (Sign::Nonneg, _) | (_, Sign::Nonneg) => Sign::Nonneg,
            (Sign::Nonpos, Sign::Nonpos) => Sign::Nonpos,
            _ => Sign::Any,
        };
        Fact { curv, sign }
    }

    fn min(self, o: Fact) -> Fact {
        self.neg().max(o.neg()).neg()
    }

    /// A nondecreasing convex function of this: convex when this is.
    fn raised(self, sign: Sign) -> Fact {
        Fact { curv: if self.convexish() { Curv::Convex } else { Curv::Other }, sign }
    }
}

/// Whether the number `body` is a convex function of the point by the rules above.
pub fn is_convex(body: &Arc<FieldExpr>) -> bool {
    body.ty == FieldTy::Num && facts(body, &mut HashMap::new())[0].convexish()
}

/// What is known of each of the value's components (a number's in the first; nothing
/// reads the other two).
fn facts(e: &Arc<FieldExpr>, memo: &mut HashMap<*const FieldExpr, [Fact; 3]>) -> [Fact; 3] {
    if let Some(f) = memo.get(&Arc::as_ptr(e)) {
        return *f;
    }
    let mut f = |x: &Arc<FieldExpr>| facts(x, memo);
    let num = |x: Fact| [x, OTHER, OTHER];
    let per = |a: [Fact; 3], g: &dyn Fn(Fact) -> Fact| a.map(g);
    let both = |a: [Fact; 3], b: [Fact; 3], g: &dyn Fn(Fact, Fact) -> Fact| [0, 1, 2].map(|i| g(a[i], b[i]));
    let out = match &e.kind {
        FieldKind::Point => [Fact { curv: Curv::Affine, sign: Sign::Any }; 3],
        FieldKind::Num(c) => num(Fact::constant(*c)),
        FieldKind::Vec(c) => c.to_array().map(Fact::constant),
        FieldKind::Component(x, i) => num(f(x)[*i]),
        FieldKind::Vector(xs) => [f(&xs[0])[0], f(&xs[1])[0], f(&xs[2])[0]],
        FieldKind::Unary(op, x) => {
            let a = f(x);
            match op {
                Unary::Neg => per(a, &Fact::neg),
                Unary::Abs => per(a, &Fact::abs),
                Unary::Exp => per(a, &|x| x.raised(Sign::Nonneg)),
                // A norm is convex, and nondecreasing in each component's size: convex
                // of affine components, and of convex ones that keep one sign.
                Unary::Length => {
                    let ok = a.iter().all(|c| c.abs().convexish());
                    num(Fact { curv: if ok { Curv::Convex } else { Curv::Other }, sign: Sign::Nonneg })
                }
                _ => [OTHER; 3],
            }
        }
        FieldKind::Binary(op, x, y) => {
            let (a, b) = (f(x), f(y));
            // A finite constant operand (a product with an infinite one is no function).
            let constant = |e: &Arc<FieldExpr>| {
                let c = match &e.kind {
                    FieldKind::Num(c) => [*c; 3],
                    FieldKind::Vec(c) => c.to_array(),
                    _ => return None,
                };
                c.iter().all(|x| x.is_finite()).then_some(c)
            };
            let scaled = |a: [Fact; 3], c: [f64; 3]| [0, 1, 2].map(|i| a[i].scale(c[i]));
            match (op, constant(x), constant(y)) {
                (Binary::Add, ..) => both(a, b, &Fact::add),
                (Binary::Sub, ..) => both(a, b, &|a, b| a.add(b.neg())),
                (Binary::Mul, Some(c), _) => scaled(b, c),
                (Binary::Mul, _, Some(c)) => scaled(a, c),
                (Binary::Div, _, Some(c)) if c.iter().all(|&x| x != 0.0) => scaled(a, c.map(f64::recip)),
                (Binary::Max, ..) => both(a, b, &Fact::max),
                (Binary::Min, ..) => both(a, b, &Fact::min),
                (Binary::Dot, Some(c), _) | (Binary::Dot, _, Some(c)) => {
                    let v = if constant(x).is_some() { b } else { a };
                    let s = scaled(v, c);
                    num(s[0].add(s[1]).add(s[2]))
                }
                // `pow(x, c)`, c ≥ 1: `|x|^c` for a fractional or even `c`, which is
                // convex where `|x|` is; `x^c` for an odd `c`, convex of a convex `x ≥ 0`.
                (Binary::Pow, _, Some([1.0, ..])) => a,
                (Binary::Pow, _, Some([c, ..])) if c > 1.0 => {
                    let odd = c.fract() == 0.0 && c % 2.0 == 1.0;
                    let base = if odd {
                        if a[0].sign == Sign::Nonneg {
                            a[0]
                        } else {
                            OTHER
                        }
                    } else {
                        a[0].abs()
                    };
                    num(base.raised(Sign::Nonneg))
                }
                _ => [OTHER; 3],
            }
        }
        FieldKind::Select(..) | FieldKind::Dist(..) | FieldKind::Noise { .. } | FieldKind::Outline(..) => [OTHER; 3],
    };
    memo.insert(Arc::as_ptr(e), out);
    out
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;

    fn p() -> Arc<FieldExpr> {
        FieldExpr::point()
    }
    fn c(x: f64) -> Arc<FieldExpr> {
        FieldExpr::num(x)
    }
    #[track_caller]
    fn un(f: Unary, x: Arc<FieldExpr>) -> Arc<FieldExpr> {
        FieldExpr::unary(f, x).unwrap()
    }
    #[track_caller]
    fn bin(f: Binary, a: Arc<FieldExpr>, b: Arc<FieldExpr>) -> Arc<FieldExpr> {
        FieldExpr::binary(f, a, b).unwrap()
    }
    fn x(i: usize) -> Arc<FieldExpr> {
        FieldExpr::component(&p(), i)
    }

    /// Bodies, whether the rules must call them convex, and whether they are.
    fn cases() -> Vec<(&'static str, Arc<FieldExpr>, bool, bool)> {
        let sphere = bin(Binary::Sub, un(Unary::Length, p()), c(1.0));
        // The box's exact distance, written as the catalogue writes it.
        let half = [1.0, 0.5, 0.25];
        let q: Vec<_> = (0..3).map(|i| bin(Binary::Sub, un(Unary::Abs, x(i)), c(half[i]))).collect();
        let outside = un(Unary::Length, FieldExpr::vector([0, 1, 2].map(|i| bin(Binary::Max, q[i].clone(), c(0.0)))));
        let inside =
            bin(Binary::Min, bin(Binary::Max, q[0].clone(), bin(Binary::Max, q[1].clone(), q[2].clone())), c(0.0));
        let cube = bin(Binary::Add, outside, inside.clone());
        let slabs = bin(Binary::Max, q[0].clone(), bin(Binary::Max, q[1].clone(), q[2].clone()));
        let slab = bin(Binary::Sub, un(Unary::Abs, x(1)), c(0.5));
        let quartic = bin(
            Binary::Sub,
            bin(Binary::Add, bin(Binary::Pow, x(0), c(4.0)), bin(Binary::Pow, un(Unary::Abs, x(2)), c(2.5))),
            c(1.0),
        );
        let plane = bin(Binary::Dot, p(), FieldExpr::vec(DVec3::new(0.0, 1.0, 0.0)));
        let steep = bin(Binary::Mul, c(4.0), sphere.clone());
        let scaled = un(Unary::Length, bin(Binary::Mul, p(), FieldExpr::vec(DVec3::new(1.0, 2.0, -3.0))));
        let hole = bin(Binary::Sub, c(1.0), un(Unary::Length, p()));
        let torus = bin(
            Binary::Sub,
            un(
                Unary::Length,
                FieldExpr::vector([
                    bin(Binary::Sub, un(Unary::Length, FieldExpr::vector([x(0), c(0.0), x(2)])), c(1.0)),
                    x(1),
                    c(0.0),
                ]),
            ),
            c(0.25),
        );
        let cubic = bin(Binary::Pow, x(0), c(3.0));
        let wave = bin(Binary::Sub, un(Unary::Sin, x(0)), x(1));
        let product = bin(Binary::Mul, x(0), x(1));
        let by_zero = bin(Binary::Div, un(Unary::Length, p()), c(0.0));
        vec![
            ("sphere", sphere.clone(), true, true),
            ("box as slabs", slabs, true, true),
            // Convex, but `min(…, 0)` of a convex term is beyond the rules.
            ("exact box", cube, false, true),
            ("slab", slab, true, true),
            ("quartic", quartic, true, true),
            ("plane", plane, true, true),
            ("steep", steep, true, true),
            ("stretched", scaled, true, true),
            ("intersection", bin(Binary::Max, sphere.clone(), x(0)), true, true),
            ("negated", un(Unary::Neg, sphere.clone()), false, false),
            ("hole", hole, false, false),
            ("torus", torus, false, false),
            ("union", bin(Binary::Min, sphere, x(0)), false, false),
            ("inside part", bin(Binary::Mul, c(-1.0), inside), false, false),
            ("cubic", cubic, false, false),
            ("wave", wave, false, false),
            ("product", product, false, false),
            // Infinite everywhere: no line bends the wrong way, but it is no function to march.
            ("over zero", by_zero, false, true),
        ]
    }

    #[test]
    fn convex_bodies_are_told_from_others() {
        for (name, body, called, _) in cases() {
            assert_eq!(is_convex(&body), called, "{name}");
        }
    }

    /// What the rules call convex is: along lines through the cube [-2, 2]³, the
    /// midpoint's value is at most the mean of the ends' (and the check fails for the
    /// cases that are not).
    #[test]
    fn bodies_called_convex_are_convex_along_lines() {
        // Points spread over [-2, 2]³ by the fractional parts of irrational multiples.
        let at = |k: f64, s: [f64; 3]| DVec3::from_array(s.map(|s| ((k * s).fract() - 0.5) * 4.0));
        let no_dist = |_: &Arc<crate::ir::Shape>, _: DVec3| f64::NAN;
        for (name, body, _, convex) in cases() {
            let mut broken = 0;
            for k in 1..2000 {
                let k = f64::from(k);
                let (a, b) =
                    (at(k, [2f64.sqrt(), 3f64.sqrt(), 5f64.sqrt()]), at(k, [7f64.sqrt(), 11f64.sqrt(), 13f64.sqrt()]));
                let v = |q: DVec3| body.eval(q, &no_dist).num();
                if v((a + b) / 2.0) > (v(a) + v(b)) / 2.0 + 1e-9 {
                    broken += 1;
                }
            }
            assert_eq!(broken == 0, convex, "{name}: {broken} lines bend the wrong way");
        }
    }
}
