//! Interval arithmetic over boxes of points (Moore 1966), and on top of it the
//! [`Slope`]: a body's value and gradient as intervals over a box, whose largest
//! gradient norm bounds the body's slope there.
//!
//! Intervals are in f64 and closed; an unknown or unbounded result is the whole line,
//! never NaN (`0 · ∞` is 0: a factor that is exactly zero stays zero).

use std::f64::consts::PI;
use std::ops::{Add, Div, Mul, Sub};

use super::tape::Scalar;
use crate::geom::noise::{NOISE_RANGE, NOISE_SLOPE};
use crate::geom::outline::Outline;
use crate::ir::field::{Binary, Unary};

/// A closed interval `[lo, hi]` (`lo ≤ hi`, either may be infinite).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Interval {
    /// The lower end.
    pub lo: f64,
    /// The upper end.
    pub hi: f64,
}

const DEG: f64 = PI / 180.0;

/// `x` rounded to the nearest whole number, without a libm call (`f64::round` is one on
/// baseline x86-64): adding and taking off 1.5·2⁵² rounds, for `|x|` below 2⁵¹.
fn round(x: f64) -> f64 {
    const MAGIC: f64 = 6_755_399_441_055_744.0;
    if x.abs() < 2e15 {
        (x + MAGIC) - MAGIC
    } else {
        x
    }
}

/// `a · b` where a zero factor wins over an infinite one.
fn mul0(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 {
        0.0
    } else {
        a * b
    }
}

impl Interval {
    /// The interval of one number.
    pub fn point(x: f64) -> Interval {
        Interval { lo: x, hi: x }
    }

    /// `[lo, hi]`, widened to the whole line if either end is NaN.
    pub fn new(lo: f64, hi: f64) -> Interval {
        if lo.is_nan() || hi.is_nan() {
            Interval::ALL
        } else {
            Interval { lo: lo.min(hi), hi: hi.max(lo) }
        }
    }

    /// Every number.
    pub const ALL: Interval = Interval { lo: f64::NEG_INFINITY, hi: f64::INFINITY };

    /// The truth values 0 and 1 both possible.
    const MAYBE: Interval = Interval { lo: 0.0, hi: 1.0 };

    /// Its middle (0 when an end is infinite).
    pub fn mid(self) -> f64 {
        if self.lo.is_finite() && self.hi.is_finite() {
            0.5 * (self.lo + self.hi)
        } else {
            0.0
        }
    }

    /// Half its width.
    pub fn radius(self) -> f64 {
        0.5 * (self.hi - self.lo)
    }

    /// The largest absolute value in it.
    pub fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// The smallest interval holding both.
    pub fn hull(self, o: Interval) -> Interval {
        Interval { lo: self.lo.min(o.lo), hi: self.hi.max(o.hi) }
    }

    /// Whether it holds `x`.
    pub fn contains(self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    fn truth(always: bool, never: bool) -> Interval {
        if always {
            Interval::point(1.0)
        } else if never {
            Interval::point(0.0)
        } else {
            Interval::MAYBE
        }
    }

    /// A monotone non-decreasing function applied to both ends.
    fn rising(self, f: impl Fn(f64) -> f64) -> Interval {
        Interval::new(f(self.lo), f(self.hi))
    }

    /// The square.
    pub fn sqr(self) -> Interval {
        if self.contains(0.0) {
            Interval::new(0.0, self.mag() * self.mag())
        } else {
            let (a, b) = (self.lo * self.lo, self.hi * self.hi);
            Interval::new(a.min(b), a.max(b))
        }
    }

    /// The sine of degrees: the ends' values, widened to ±1 where a crest lies within.
    fn sin_deg(self) -> Interval {
        let width = self.hi - self.lo;
        // (NaN-safe: an unbounded width counts as wide; so does a huge angle, whose
        // turns f64 cannot count.)
        if !(width < 360.0 && self.lo.abs() < 1e15) {
            return Interval::new(-1.0, 1.0);
        }
        // Whole turns off exactly, then crests at 90° and 450°, troughs at −90° and 270°.
        let lo = self.lo - 360.0 * round(self.lo / 360.0);
        let hi = lo + width;
        // The ends by the f32 polynomials, widened by more than their error (f32's
        // rounding of an angle up to 540°, about 1e-6).
        const PAD: f64 = 4e-6;
        let (a, b) = (crate::field::sin_deg(lo as f32) as f64, crate::field::sin_deg(hi as f32) as f64);
        let mut top = (a.max(b) + PAD).min(1.0);
        let mut bottom = (a.min(b) - PAD).max(-1.0);
        let within = |x: f64| lo <= x && x <= hi;
        if within(90.0) || within(450.0) {
            top = 1.0;
        }
        if within(-90.0) || within(270.0) {
            bottom = -1.0;
        }
        Interval { lo: bottom, hi: top }
    }

    /// The cosine of degrees.
    fn cos_deg(self) -> Interval {
        Interval::new(self.lo + 90.0, self.hi + 90.0).sin_deg()
    }

    fn unary(f: Unary, x: Interval) -> Interval {
        match f {
            Unary::Neg => Interval::new(-x.hi, -x.lo),
            Unary::Not => Interval::truth(x == Interval::point(0.0), !x.contains(0.0)),
            Unary::Sin => x.sin_deg(),
            Unary::Cos => x.cos_deg(),
            Unary::Tan => {
                // Rising between asymptotes at 90 + 180k.
                let k = ((x.lo - 90.0) / 180.0).floor();
                if x.hi - x.lo < 180.0 && x.hi < (k + 1.0) * 180.0 + 90.0 {
                    x.rising(|t| (t * DEG).tan())
                } else {
                    Interval::ALL
                }
            }
            Unary::Asin => x.rising(|t| t.clamp(-1.0, 1.0).asin() / DEG),
            Unary::Acos => Interval::new(x.hi.clamp(-1.0, 1.0).acos() / DEG, x.lo.clamp(-1.0, 1.0).acos() / DEG),
            Unary::Atan => x.rising(|t| t.atan() / DEG),
            Unary::Sqrt => x.rising(|t| t.max(0.0).sqrt()),
            Unary::Abs => {
                if x.contains(0.0) {
                    Interval::new(0.0, x.mag())
                } else {
                    Interval::new(x.lo.abs().min(x.hi.abs()), x.mag())
                }
            }
            Unary::Floor => x.rising(f64::floor),
            Unary::Fract => {
                let whole = x.lo.floor();
                if x.hi < whole + 1.0 {
                    Interval::new(x.lo - whole, x.hi - whole)
                } else {
                    Interval::new(0.0, 1.0)
                }
            }
            Unary::Ceil => x.rising(f64::ceil),
            Unary::Round => x.rising(f64::round),
            Unary::Sign => x.rising(|t| Unary::Sign.apply(t)),
            Unary::Exp => x.rising(f64::exp),
            Unary::Log => x.rising(|t| Unary::Log.apply(t)),
            Unary::Length | Unary::Normalize => Interval::ALL,
        }
    }

    fn binary(f: Binary, a: Interval, b: Interval) -> Interval {
        match f {
            Binary::Add => a.add(b),
            Binary::Sub => a.sub(b),
            Binary::Mul => a.mul(b),
            Binary::Div => a.div(b),
            Binary::Rem => {
                let m = b.mag();
                // Within one period of a constant positive divisor, a remainder is a shift.
                if b.lo == b.hi && m > 0.0 && m.is_finite() && a.lo.is_finite() && a.hi.is_finite() {
                    let k = (a.lo / m).trunc();
                    if k == (a.hi / m).trunc() && (a.lo >= 0.0) == (a.hi >= 0.0) {
                        return Interval::new(a.lo - k * m, a.hi - k * m);
                    }
                }
                let lo = if a.lo >= 0.0 { 0.0 } else { -m };
                let hi = if a.hi <= 0.0 { 0.0 } else { m };
                Interval::new(lo, hi)
            }
            Binary::Lt => Interval::truth(a.hi < b.lo, a.lo >= b.hi),
            Binary::Le => Interval::truth(a.hi <= b.lo, a.lo > b.hi),
            Binary::Gt => Interval::truth(a.lo > b.hi, a.hi <= b.lo),
            Binary::Ge => Interval::truth(a.lo >= b.hi, a.hi < b.lo),
            Binary::Eq => Interval::truth(a.lo == a.hi && a == b, a.hi < b.lo || b.hi < a.lo),
            Binary::Ne => Interval::truth(a.hi < b.lo || b.hi < a.lo, a.lo == a.hi && a == b),
            Binary::And => Interval::truth(
                !a.contains(0.0) && !b.contains(0.0),
                a == Interval::point(0.0) || b == Interval::point(0.0),
            ),
            Binary::Or => Interval::truth(
                !a.contains(0.0) || !b.contains(0.0),
                a == Interval::point(0.0) && b == Interval::point(0.0),
            ),
            Binary::Min => Interval::new(a.lo.min(b.lo), a.hi.min(b.hi)),
            Binary::Max => Interval::new(a.lo.max(b.lo), a.hi.max(b.hi)),
            Binary::Pow => pow(a, b),
            Binary::Atan2 => {
                // Continuous, and monotone along each edge of a box that misses the cut
                // (the negative x axis): the corners hold its extremes.
                if a.contains(0.0) && b.lo <= 0.0 {
                    return Interval::new(-180.0, 180.0);
                }
                let c =
                    [(a.lo, b.lo), (a.lo, b.hi), (a.hi, b.lo), (a.hi, b.hi)].map(|(y, x)| Binary::Atan2.apply(y, x));
                Interval::new(
                    c.iter().copied().fold(f64::INFINITY, f64::min),
                    c.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                )
            }
            Binary::Dot | Binary::Cross => Interval::ALL,
        }
    }
}

impl std::ops::Mul for Interval {
    type Output = Interval;

    /// The product.
    fn mul(self, o: Interval) -> Interval {
        let c = [mul0(self.lo, o.lo), mul0(self.lo, o.hi), mul0(self.hi, o.lo), mul0(self.hi, o.hi)];
        Interval::new(
            c.iter().copied().fold(f64::INFINITY, f64::min),
            c.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }
}

impl std::ops::Add for Interval {
    type Output = Interval;

    /// The sum.
    fn add(self, o: Interval) -> Interval {
        Interval::new(self.lo + o.lo, self.hi + o.hi)
    }
}

impl std::ops::Sub for Interval {
    type Output = Interval;

    /// The difference.
    fn sub(self, o: Interval) -> Interval {
        Interval::new(self.lo - o.hi, self.hi - o.lo)
    }
}

impl std::ops::Div for Interval {
    type Output = Interval;

    /// The quotient; the whole line when the divisor may be zero.
    fn div(self, o: Interval) -> Interval {
        if o.contains(0.0) {
            return if self == Interval::point(0.0) { self } else { Interval::ALL };
        }
        self.mul(Interval::new(1.0 / o.hi, 1.0 / o.lo))
    }
}

/// `pow(a, b)` over intervals: exact for a constant whole exponent and for a positive
/// base; the whole line otherwise.
fn pow(a: Interval, b: Interval) -> Interval {
    if b.lo == b.hi && b.lo.fract() == 0.0 && b.lo.abs() < 1e9 {
        let n = b.lo;
        if n == 0.0 {
            return Interval::point(1.0);
        }
        let p = |x: f64| Binary::Pow.apply(x, n);
        if n > 0.0 && n % 2.0 == 0.0 {
            return Interval::new(p(a.lo.abs().min(a.hi.abs()) * f64::from(!a.contains(0.0))), p(a.mag()));
        }
        if n > 0.0 {
            return a.rising(p);
        }
        if a.contains(0.0) {
            return Interval::ALL;
        }
        let (x, y) = (p(a.lo), p(a.hi));
        return Interval::new(x.min(y), x.max(y));
    }
    if a.lo > 0.0 {
        // x^y = e^(y ln x): monotone in each argument on each sign of ln x.
        let ln = Interval::new(a.lo.ln(), a.hi.ln());
        let e = ln.mul(b);
        return Interval::new(e.lo.exp(), e.hi.exp());
    }
    Interval::ALL
}

/// An outline's signed distance over the box `u × v`: its value at the middle, give or
/// take the half-diagonal; anything where the box is unbounded.
fn outline_over(o: &Outline, u: Interval, v: Interval) -> Interval {
    let (r, s) = (u.radius(), v.radius());
    if !(r.is_finite() && s.is_finite()) {
        return Interval::ALL;
    }
    let d = o.nearest(glam::DVec2::new(u.mid(), v.mid())).d;
    let reach = r.hypot(s);
    Interval::new(d - reach, d + reach)
}

impl Scalar for Interval {
    type Point = [Interval; 3];

    fn input(p: &[Interval; 3], axis: u8) -> Interval {
        p[axis as usize]
    }

    fn constant(x: f64) -> Interval {
        Interval::point(x)
    }

    #[inline]
    fn unary(f: Unary, x: Interval) -> Interval {
        Interval::unary(f, x)
    }

    #[inline]
    fn binary(f: Binary, a: Interval, b: Interval) -> Interval {
        Interval::binary(f, a, b)
    }

    fn select(c: Interval, a: Interval, b: Interval) -> Interval {
        if !c.contains(0.0) {
            a
        } else if c == Interval::point(0.0) {
            b
        } else {
            a.hull(b)
        }
    }

    fn length(v: [Interval; 3]) -> Interval {
        let s = v[0].sqr().add(v[1].sqr()).add(v[2].sqr());
        Interval::new(s.lo.max(0.0).sqrt(), s.hi.max(0.0).sqrt())
    }

    fn noise(_: [Interval; 3], _: u32) -> Interval {
        Interval::new(-NOISE_RANGE, NOISE_RANGE)
    }

    /// Within the box's half-diagonal of the distance at its middle: an exact distance
    /// changes no faster than the point moves.
    fn outline(o: &Outline, u: Interval, v: Interval) -> Interval {
        outline_over(o, u, v)
    }
}

/// A body's value and gradient over a box, as intervals, and `n`, a bound of the
/// gradient's norm by the rules of Lipschitz constants (a sum's slope is at most the
/// sum of the slopes, a length's at most its vector's stretch, …). The gradient
/// intervals alone lose the correlation between components (`length(p)` would get
/// √3 instead of 1); the rules alone lose where a slope is small; each node keeps the
/// smaller of the two bounds.
///
/// Generic over how many derivatives it carries: [`Slope`] the gradient (three), for the
/// bound of a body's slope over a box; [`Dir`] the derivative along one direction, for
/// the bound along a stretch of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jet<const N: usize> {
    /// The value.
    pub v: Interval,
    /// The derivatives, by seed direction.
    pub g: [Interval; N],
    /// A bound of the derivatives' norm.
    pub n: f64,
}

/// Value and gradient.
pub type Slope = Jet<3>;

/// Value and derivative along a direction.
pub type Dir = Jet<1>;

impl<const N: usize> Default for Jet<N> {
    fn default() -> Jet<N> {
        Jet { v: Interval::default(), g: [Interval::default(); N], n: 0.0 }
    }
}

/// Where a [`Jet`] is evaluated: a box, and the derivatives of the point's coordinates
/// with respect to the seeds (the identity for a gradient, a ray's direction for `Dir`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JetBox<const N: usize> {
    /// The box.
    pub at: [Interval; 3],
    /// `seed[axis][j]`: how coordinate `axis` moves along seed `j`.
    pub seed: [[f64; N]; 3],
}

impl JetBox<3> {
    /// A box, for the gradient.
    pub fn gradient(at: [Interval; 3]) -> JetBox<3> {
        JetBox { at, seed: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] }
    }
}

impl<const N: usize> Jet<N> {
    /// A value with derivatives `g`, its norm bound the smaller of `n` and `g`'s.
    fn new(v: Interval, g: [Interval; N], n: f64) -> Jet<N> {
        let by_g = g.iter().map(|d| d.mag().powi(2)).sum::<f64>().sqrt();
        let n = if n.is_nan() { by_g } else { n.min(by_g) };
        Jet { v, g, n: if n.is_nan() { f64::INFINITY } else { n } }
    }

    /// The bound of the gradient's norm.
    pub fn norm(&self) -> f64 {
        self.n
    }

    /// `f(x)` where `f`'s derivative lies in `d` over `x`.
    fn chain(v: Interval, d: Interval, x: Jet<N>) -> Jet<N> {
        Jet::new(v, x.g.map(|g| g.mul(d)), mul0(d.mag(), x.n))
    }

    /// Column `i` of the Jacobian of three jets, its norm as a bound.
    fn column(v: &[Jet<N>; 3], i: usize) -> f64 {
        (0..3).map(|k| v[k].g[i].mag().powi(2)).sum::<f64>().sqrt()
    }

    /// The Jacobian's stretch bound for a vector of three slopes: its spectral norm is
    /// at most the midpoint matrix's plus the radius matrix's Frobenius norm.
    /// (With one seed the Jacobian is a column, whose norm is its spectral norm.)
    pub fn stretch(v: &[Jet<N>; 3]) -> f64 {
        let by_g = if N == 3 {
            let mid = |i: Interval| if i.lo.is_finite() && i.hi.is_finite() { 0.5 * (i.lo + i.hi) } else { 0.0 };
            let rad =
                |i: Interval| if i.lo.is_finite() && i.hi.is_finite() { 0.5 * (i.hi - i.lo) } else { f64::INFINITY };
            let row = |s: &Jet<N>| glam::DVec3::new(mid(s.g[0]), mid(s.g[1]), mid(s.g[2]));
            let m = glam::DMat3::from_cols(row(&v[0]), row(&v[1]), row(&v[2])).transpose();
            let r2: f64 = v.iter().flat_map(|s| s.g.iter()).map(|&i| rad(i).powi(2)).sum();
            crate::ir::max_stretch(m) + r2.sqrt()
        } else {
            (0..N).map(|i| Jet::column(v, i).powi(2)).sum::<f64>().sqrt()
        };
        // Each row's norm bound gives a Frobenius bound too.
        let by_n = (v[0].n.powi(2) + v[1].n.powi(2) + v[2].n.powi(2)).sqrt();
        by_g.min(by_n)
    }
}

impl<const N: usize> Scalar for Jet<N> {
    type Point = JetBox<N>;

    fn input(p: &JetBox<N>, axis: u8) -> Jet<N> {
        let seed = p.seed[axis as usize];
        let n = seed.iter().map(|x| x * x).sum::<f64>().sqrt();
        Jet { v: p.at[axis as usize], g: seed.map(Interval::point), n }
    }

    fn constant(x: f64) -> Jet<N> {
        Jet { v: Interval::point(x), g: [Interval::point(0.0); N], n: 0.0 }
    }

    #[inline]
    fn unary(f: Unary, x: Jet<N>) -> Jet<N> {
        let v = Interval::unary(f, x.v);
        let one = Interval::point(1.0);
        let d = match f {
            Unary::Neg => Interval::point(-1.0),
            Unary::Sin => x.v.cos_deg().mul(Interval::point(DEG)),
            Unary::Cos => x.v.sin_deg().mul(Interval::point(-DEG)),
            Unary::Tan => Interval::point(DEG).div(x.v.cos_deg().sqr()),
            Unary::Asin => Interval::point(1.0 / DEG).div(Interval::unary(Unary::Sqrt, one.sub(x.v.sqr()))),
            Unary::Acos => Interval::point(-1.0 / DEG).div(Interval::unary(Unary::Sqrt, one.sub(x.v.sqr()))),
            Unary::Atan => Interval::point(1.0 / DEG).div(one.add(x.v.sqr())),
            Unary::Sqrt => Interval::point(0.5).div(v),
            Unary::Abs => {
                if x.v.lo >= 0.0 {
                    one
                } else if x.v.hi <= 0.0 {
                    Interval::point(-1.0)
                } else {
                    Interval::new(-1.0, 1.0)
                }
            }
            Unary::Exp => v,
            Unary::Log => one.div(x.v),
            // A step's slope is zero between its jumps; a jump has no bound at all, and
            // is marched as if it were not there (docs/fields.md says so).
            Unary::Not | Unary::Floor | Unary::Ceil | Unary::Round | Unary::Sign => Interval::point(0.0),
            // Slope 1 between its jumps, which count as `floor`'s do.
            Unary::Fract => one,
            Unary::Length | Unary::Normalize => Interval::ALL,
        };
        Jet::chain(v, d, x)
    }

    #[inline]
    fn binary(f: Binary, a: Jet<N>, b: Jet<N>) -> Jet<N> {
        let v = Interval::binary(f, a.v, b.v);
        let zero = [Interval::point(0.0); N];
        // Plain loops rather than `array::from_fn`, whose closure wrapper the compiler
        // does not always inline: this runs for every instruction of every segment bound.
        let comb = |ka: Interval, kb: Interval| {
            let mut g = zero;
            for (gi, (x, y)) in g.iter_mut().zip(a.g.iter().zip(&b.g)) {
                *gi = x.mul(ka).add(y.mul(kb));
            }
            Jet::new(v, g, mul0(ka.mag(), a.n) + mul0(kb.mag(), b.n))
        };
        let one = Interval::point(1.0);
        match f {
            Binary::Add => comb(one, one),
            Binary::Sub => comb(one, Interval::point(-1.0)),
            Binary::Mul => comb(b.v, a.v),
            Binary::Div => {
                let inv = one.div(b.v);
                comb(inv, a.v.mul(inv.sqr()).mul(Interval::point(-1.0)))
            }
            // Between jumps a remainder is its dividend shifted by whole divisors.
            Binary::Rem if b.n == 0.0 => comb(one, Interval::point(0.0)),
            Binary::Rem => Jet::new(v, [Interval::ALL; N], f64::INFINITY),
            Binary::Min | Binary::Max => {
                let a_wins = if f == Binary::Min { a.v.hi <= b.v.lo } else { a.v.lo >= b.v.hi };
                let b_wins = if f == Binary::Min { b.v.hi <= a.v.lo } else { b.v.lo >= a.v.hi };
                if a_wins {
                    Jet { v, ..a }
                } else if b_wins {
                    Jet { v, ..b }
                } else {
                    let mut g = zero;
                    for (gi, (x, y)) in g.iter_mut().zip(a.g.iter().zip(&b.g)) {
                        *gi = x.hull(*y);
                    }
                    Jet::new(v, g, a.n.max(b.n))
                }
            }
            Binary::Pow => {
                // d/da = b·a^(b−1); d/db = a^b·ln a (a > 0 only).
                let da = b.v.mul(pow(a.v, b.v.sub(one)));
                let db = if b.n == 0.0 {
                    Interval::point(0.0)
                } else if a.v.lo > 0.0 {
                    v.mul(Interval::new(a.v.lo.ln(), a.v.hi.ln()))
                } else {
                    Interval::ALL
                };
                comb(da, db)
            }
            Binary::Atan2 => {
                // atan2(y, x): ∂y = x / r², ∂x = −y / r², in degrees.
                let r2 = a.v.sqr().add(b.v.sqr());
                let k = Interval::point(1.0 / DEG).div(r2);
                comb(b.v.mul(k), a.v.mul(k).mul(Interval::point(-1.0)))
            }
            Binary::Lt | Binary::Le | Binary::Gt | Binary::Ge | Binary::Eq | Binary::Ne | Binary::And | Binary::Or => {
                Jet { v, g: zero, n: 0.0 }
            }
            Binary::Dot | Binary::Cross => Jet::new(Interval::ALL, [Interval::ALL; N], f64::INFINITY),
        }
    }

    fn select(c: Jet<N>, a: Jet<N>, b: Jet<N>) -> Jet<N> {
        if !c.v.contains(0.0) {
            a
        } else if c.v == Interval::point(0.0) {
            b
        } else {
            let g = std::array::from_fn(|i| a.g[i].hull(b.g[i]));
            Jet::new(a.v.hull(b.v), g, a.n.max(b.n))
        }
    }

    fn length(v: [Jet<N>; 3]) -> Jet<N> {
        let value = Interval::length([v[0].v, v[1].v, v[2].v]);
        // ∇|u| = Jᵀu/|u|: each component is at most its Jacobian column's norm.
        let g = if value.lo > 0.0 {
            let inv = Interval::point(1.0).div(value);
            std::array::from_fn(|i| {
                let dot = v[0].v.mul(v[0].g[i]).add(v[1].v.mul(v[1].g[i])).add(v[2].v.mul(v[2].g[i]));
                let g = dot.mul(inv);
                let c = Jet::column(&v, i);
                Interval::new(g.lo.max(-c), g.hi.min(c))
            })
        } else {
            std::array::from_fn(|i| {
                let c = Jet::column(&v, i);
                Interval::new(-c, c)
            })
        };
        Jet::new(value, g, Jet::stretch(&v))
    }

    fn noise(q: [Jet<N>; 3], _: u32) -> Jet<N> {
        let s = NOISE_SLOPE * Jet::stretch(&q);
        let g = std::array::from_fn(|i| {
            let c = NOISE_SLOPE * Jet::column(&q, i);
            Interval::new(-c, c)
        });
        Jet::new(Interval::new(-NOISE_RANGE, NOISE_RANGE), g, s)
    }

    /// Its value as [`Interval`]'s, its gradient a unit vector in `[u, v]` carried
    /// through the chain rule, as `length` of a vector of two.
    fn outline(o: &Outline, u: Jet<N>, v: Jet<N>) -> Jet<N> {
        let zero = <Jet<N> as Scalar>::constant(0.0);
        let q = [u, v, zero];
        let g = std::array::from_fn(|i| {
            let c = Jet::column(&q, i);
            Interval::new(-c, c)
        });
        Jet::new(outline_over(o, u.v, v.v), g, Jet::stretch(&q))
    }
}
