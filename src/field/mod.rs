//! Evaluating field bodies: a body ([`crate::ir::field::FieldExpr`]) is compiled once to a
//! [`Tape`], which every scalar type runs: `f32` to march, [`Dual`] for a hit's value
//! and gradient, [`Interval`] to rule out a stretch of a ray, and [`Slope`] for the
//! bound of a body's slope over a box ([`lipschitz()`]), which the checker states and the
//! march divides by.
//!
//! Every operation's meaning is [`Unary::apply`] / [`Binary::apply`] in f64; each scalar
//! type follows it (tested against it at random points).

mod cost;
mod flat;
mod interval;
mod lipschitz;
mod support;
mod tape;

pub use cost::{evaluation_cost, Cost, MAX_WORK, WARN_WORK};
pub use flat::Flat;
pub use interval::{Dir, Interval, Jet, JetBox, Slope};
pub use lipschitz::{lipschitz, Estimate, SlopeDistances};
pub use support::{support_planes, support_radius};
pub use tape::{Distances, NoDistances, Op, Reg, Scalar, Tape};

use glam::Vec3A;

use crate::geom::outline::Outline;
use crate::ir::field::{Binary, Unary};

/// Degrees to radians, in f32.
const RAD: f32 = std::f32::consts::PI / 180.0;

impl Scalar for f32 {
    type Point = Vec3A;

    #[inline]
    fn input(p: &Vec3A, axis: u8) -> f32 {
        p[axis as usize]
    }

    #[inline]
    fn constant(x: f64) -> f32 {
        x as f32
    }

    #[inline(always)]
    fn unary(f: Unary, x: f32) -> f32 {
        match f {
            Unary::Neg => -x,
            Unary::Not => f32::from(x == 0.0),
            Unary::Sin => sin_deg(x),
            Unary::Cos => cos_deg(x),
            Unary::Tan => (x * RAD).tan(),
            Unary::Asin => x.clamp(-1.0, 1.0).asin() / RAD,
            Unary::Acos => x.clamp(-1.0, 1.0).acos() / RAD,
            Unary::Atan => x.atan() / RAD,
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
            Unary::Log => x.max(f32::MIN_POSITIVE).ln(),
            Unary::Length | Unary::Normalize => f32::NAN,
        }
    }

    #[inline]
    fn binary(f: Binary, a: f32, b: f32) -> f32 {
        match f {
            Binary::Add => a + b,
            Binary::Sub => a - b,
            Binary::Mul => a * b,
            Binary::Div => a / b,
            Binary::Rem => a % b,
            Binary::Lt => f32::from(a < b),
            Binary::Le => f32::from(a <= b),
            Binary::Gt => f32::from(a > b),
            Binary::Ge => f32::from(a >= b),
            Binary::Eq => f32::from(a == b),
            Binary::Ne => f32::from(a != b),
            Binary::And => f32::from(a != 0.0 && b != 0.0),
            Binary::Or => f32::from(a != 0.0 || b != 0.0),
            Binary::Min => a.min(b),
            Binary::Max => a.max(b),
            Binary::Pow => {
                if a < 0.0 && b.fract() != 0.0 {
                    a.abs().powf(b)
                } else {
                    a.powf(b)
                }
            }
            Binary::Atan2 => (a + 0.0).atan2(b) / RAD,
            Binary::Dot | Binary::Cross => f32::NAN,
        }
    }

    #[inline]
    fn select(c: f32, a: f32, b: f32) -> f32 {
        if c != 0.0 {
            a
        } else {
            b
        }
    }

    #[inline]
    fn length(v: [f32; 3]) -> f32 {
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    }

    fn noise(q: [f32; 3], seed: u32) -> f32 {
        crate::geom::noise(glam::DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64), seed) as f32
    }

    fn outline(o: &Outline, u: f32, v: f32) -> f32 {
        o.nearest(glam::DVec2::new(f64::from(u), f64::from(v))).d as f32
    }
}

/// `x` degrees reduced to (−180, 180]: whole turns taken off exactly (`k·360` and the
/// difference are exact in f32 for the angles a field meets), so the reduction loses
/// nothing and the angle keeps its f32 precision.
#[inline]
fn reduce_deg(x: f32) -> f32 {
    // Round to nearest by the 1.5·2²³ trick (`f32::round` is a libm call on baseline x86-64).
    const MAGIC: f32 = 12_582_912.0;
    let k = (x * (1.0 / 360.0) + MAGIC) - MAGIC;
    x - k * 360.0
}

/// The sine and cosine of `r` degrees in [−45, 45]: Taylor polynomials to the 9th
/// and 10th powers, whose errors at an eighth of a turn (below 2e-9) are far below
/// f32's resolution. No call into libm: a `sinf` call cost as much as the rest of a
/// gyroid's evaluation (`perf` on benches/scenes/gyroid.scn), and these inline.
#[inline]
fn octant(r: f32) -> (f32, f32) {
    let a = r * RAD;
    let a2 = a * a;
    let s = a + a * a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362_880.0))));
    let c = 1.0 + a2 * (-0.5 + a2 * (1.0 / 24.0 + a2 * (-1.0 / 720.0 + a2 * (1.0 / 40_320.0 - a2 / 3_628_800.0))));
    (s, c)
}

/// Sine and cosine of degrees from one reduction: the angle less its nearest quarter
/// turn, whose octant polynomials give both, swapped and signed by the quarter.
#[inline]
pub fn sincos_deg(x: f32) -> (f32, f32) {
    const MAGIC: f32 = 12_582_912.0;
    let r = reduce_deg(x);
    let q = (r * (1.0 / 90.0) + MAGIC) - MAGIC;
    let (s, c) = octant(r - 90.0 * q);
    // The quarter, 0 to 3 (−1 and −2 are 3 and 2).
    let j = (q as i32) & 3;
    let swap = f32::from(u8::from(j & 1 == 1));
    let (a, b) = (s + swap * (c - s), c + swap * (s - c));
    let sin_sign = if j >= 2 { -1.0 } else { 1.0 };
    let cos_sign = if j == 1 || j == 2 { -1.0 } else { 1.0 };
    (a * sin_sign, b * cos_sign)
}

/// Sine of degrees.
#[inline]
pub fn sin_deg(x: f32) -> f32 {
    sincos_deg(x).0
}

/// Cosine of degrees.
#[inline]
pub fn cos_deg(x: f32) -> f32 {
    sincos_deg(x).1
}

/// A number with its gradient with respect to the point: forward-mode differentiation,
/// so a field's normal is exact whatever the hit threshold.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dual {
    /// The value.
    pub v: f32,
    /// Its gradient.
    pub g: Vec3A,
}

impl Dual {
    /// A value whose gradient is `d` times `x`'s (the chain rule for a function of `x`
    /// whose derivative is `d`).
    #[inline]
    fn chain(v: f32, d: f32, x: Dual) -> Dual {
        Dual { v, g: x.g * d }
    }
}

impl Scalar for Dual {
    type Point = Vec3A;

    #[inline]
    fn input(p: &Vec3A, axis: u8) -> Dual {
        let mut g = Vec3A::ZERO;
        g[axis as usize] = 1.0;
        Dual { v: p[axis as usize], g }
    }

    #[inline]
    fn constant(x: f64) -> Dual {
        Dual { v: x as f32, g: Vec3A::ZERO }
    }

    #[inline]
    fn unary(f: Unary, x: Dual) -> Dual {
        let v = f32::unary(f, x.v);
        let d = match f {
            Unary::Neg => -1.0,
            Unary::Sin => RAD * cos_deg(x.v),
            Unary::Cos => -RAD * sin_deg(x.v),
            Unary::Tan => {
                let c = (x.v * RAD).cos();
                RAD / (c * c)
            }
            Unary::Asin | Unary::Acos if x.v.abs() >= 1.0 => 0.0,
            Unary::Asin => 1.0 / (RAD * (1.0 - x.v * x.v).sqrt()),
            Unary::Acos => -1.0 / (RAD * (1.0 - x.v * x.v).sqrt()),
            Unary::Atan => 1.0 / (RAD * (1.0 + x.v * x.v)),
            Unary::Sqrt if x.v > 0.0 => 0.5 / v,
            Unary::Abs => {
                if x.v < 0.0 {
                    -1.0
                } else {
                    1.0
                }
            }
            // Rising at slope 1 between its jumps, which are steps like `floor`'s.
            Unary::Fract => 1.0,
            Unary::Exp => v,
            Unary::Log if x.v > 0.0 => 1.0 / x.v,
            // Steps are flat between their jumps; below their domain the total forms are constant.
            Unary::Sqrt
            | Unary::Log
            | Unary::Not
            | Unary::Floor
            | Unary::Ceil
            | Unary::Round
            | Unary::Sign
            | Unary::Length
            | Unary::Normalize => 0.0,
        };
        Dual::chain(v, d, x)
    }

    #[inline]
    fn binary(f: Binary, a: Dual, b: Dual) -> Dual {
        let v = f32::binary(f, a.v, b.v);
        let g = match f {
            Binary::Add => a.g + b.g,
            Binary::Sub => a.g - b.g,
            Binary::Mul => a.g * b.v + b.g * a.v,
            Binary::Div => (a.g * b.v - b.g * a.v) / (b.v * b.v),
            Binary::Rem => a.g - b.g * (a.v / b.v).trunc(),
            Binary::Min => {
                if b.v < a.v {
                    b.g
                } else {
                    a.g
                }
            }
            Binary::Max => {
                if b.v > a.v {
                    b.g
                } else {
                    a.g
                }
            }
            Binary::Pow => {
                let base = a.v.abs().max(f32::MIN_POSITIVE);
                // |a|^b for a negative base and a fractional exponent: its slope turns with a.
                let turn = if a.v < 0.0 && b.v.fract() != 0.0 { -1.0 } else { 1.0 };
                let da =
                    if a.v == 0.0 && b.v < 1.0 { 0.0 } else { turn * b.v * f32::binary(Binary::Pow, a.v, b.v - 1.0) };
                a.g * da + b.g * (v * base.ln())
            }
            Binary::Atan2 => {
                // atan2(y, x): d = (x·dy − y·dx) / (x² + y²), in degrees.
                let r2 = (a.v * a.v + b.v * b.v).max(f32::MIN_POSITIVE);
                (a.g * b.v - b.g * a.v) / (r2 * RAD)
            }
            Binary::Lt
            | Binary::Le
            | Binary::Gt
            | Binary::Ge
            | Binary::Eq
            | Binary::Ne
            | Binary::And
            | Binary::Or
            | Binary::Dot
            | Binary::Cross => Vec3A::ZERO,
        };
        Dual { v, g }
    }

    #[inline]
    fn select(c: Dual, a: Dual, b: Dual) -> Dual {
        if c.v != 0.0 {
            a
        } else {
            b
        }
    }

    fn length(v: [Dual; 3]) -> Dual {
        let len = f32::length([v[0].v, v[1].v, v[2].v]);
        if len == 0.0 {
            return Dual { v: 0.0, g: Vec3A::ZERO };
        }
        Dual { v: len, g: (v[0].g * v[0].v + v[1].g * v[1].v + v[2].g * v[2].v) / len }
    }

    fn noise(q: [Dual; 3], seed: u32) -> Dual {
        let p = glam::DVec3::new(q[0].v as f64, q[1].v as f64, q[2].v as f64);
        let (n, g) = crate::geom::noise::noise_gradient(p, seed);
        Dual { v: n as f32, g: q[0].g * g.x as f32 + q[1].g * g.y as f32 + q[2].g * g.z as f32 }
    }

    fn outline(o: &Outline, u: Dual, v: Dual) -> Dual {
        let n = o.nearest(glam::DVec2::new(f64::from(u.v), f64::from(v.v)));
        Dual { v: n.d as f32, g: u.g * n.g.x as f32 + v.g * n.g.y as f32 }
    }
}

#[cfg(test)]
mod tests;
