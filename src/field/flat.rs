//! The f32 tape flattened for the march's inner loop: one instruction per operation,
//! a constant operand carried inline for the common arithmetic, registers in a fixed
//! array indexed through a mask (so no bounds check), one `match` to dispatch. It
//! computes exactly what [`Tape::run`] computes on `f32` (tested on every operation).
//!
//! Dispatch, not arithmetic, was much of an evaluation: the gyroid sheet ran 22
//! instructions, for 3 sines with their cosines and 8 operations. Inputs and copies
//! become register names, and the pairs bodies are made of become one instruction
//! each ([`fused`]): 9 instructions, the same bits (`cargo bench --bench render --
//! 'sdf eval/gyroid'`; the measurements are in docs/performance.md, "Measurements
//! behind the code").
//!
//! Every instruction runs over `W` lanes ([`Flat::eval_lanes`]): a block of camera
//! rays marching a field evaluates its points together, one dispatch for all of them
//! and the lanes' arithmetic in one loop (`benches/scenes/gyroid-primary.scn`, the
//! same image); a single point is one lane.

use glam::Vec3A;

use super::tape::{Distances, Op, Scalar, Tape};
use super::{cos_deg, sin_deg, sincos_deg, Dual};
use crate::ir::field::{Binary, Unary};

/// Registers of a flat tape; a tape needing more runs as a [`Tape`].
pub const FLAT_REGS: usize = 64;

/// Registers of a small flat tape (most bodies): less to clear per evaluation.
const SMALL_REGS: usize = 16;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Code {
    Const,
    Unary(Unary),
    Binary(Binary),
    AddC,
    SubC,
    CSub,
    MulC,
    DivC,
    CDiv,
    MinC,
    MaxC,
    Select,
    Length,
    Dist,
    Noise,
    /// Sine of `a·k` into `out` and its cosine into register `b` (`k` is 1 for an
    /// angle alone).
    SinCos,
    /// A copy of register `a`.
    Copy,
    /// `a·b + c`.
    MulAdd,
    /// `a·k + b`.
    MulCAdd,
    /// `|a| − k`.
    AbsSubC,
    /// `length(a, b, c) − k`.
    LengthSubC,
}

impl Code {
    /// Which of `a`, `b`, `c` it reads.
    fn reads(self) -> [bool; 3] {
        match self {
            Code::Const => [false; 3],
            Code::AddC
            | Code::SubC
            | Code::CSub
            | Code::MulC
            | Code::DivC
            | Code::CDiv
            | Code::MinC
            | Code::MaxC
            | Code::Unary(_)
            | Code::SinCos
            | Code::Copy
            | Code::AbsSubC => [true, false, false],
            Code::Binary(_) | Code::MulCAdd => [true, true, false],
            Code::Select | Code::Length | Code::Dist | Code::Noise | Code::MulAdd | Code::LengthSubC => [true; 3],
        }
    }
}

impl Ins {
    /// The registers it writes: `out`, and `b` for a sine–cosine pair.
    fn writes(&self) -> impl Iterator<Item = u16> {
        let pair = self.code == Code::SinCos;
        std::iter::once(self.out).chain(pair.then_some(self.b))
    }

    /// The registers it reads.
    fn operands(&self) -> impl Iterator<Item = u16> + '_ {
        [self.a, self.b, self.c].into_iter().zip(self.code.reads()).filter_map(|(r, read)| read.then_some(r))
    }

    /// Its operands renamed by `f`.
    fn renamed(mut self, f: impl Fn(u16) -> u16) -> Ins {
        let [ra, rb, rc] = self.code.reads();
        if ra {
            self.a = f(self.a);
        }
        if rb {
            self.b = f(self.b);
        }
        if rc {
            self.c = f(self.c);
        }
        self
    }
}

/// Drops the copies of a register written at most once (the point's coordinates, which
/// sit in registers of their own from the start and are never written; a cosine's spare
/// register): their readers, and `out`, read the original instead.
fn forward(ins: Vec<Ins>, regs: usize, out: &mut [u16; 3]) -> Vec<Ins> {
    let mut writes = vec![0u32; regs];
    for i in &ins {
        for w in i.writes() {
            writes[w as usize] += 1;
        }
    }
    // What each register's reader reads instead, until the register is written again.
    let mut alias: Vec<u16> = (0..regs as u16).collect();
    let mut kept = Vec::with_capacity(ins.len());
    for i in ins {
        let i = i.renamed(|r| alias[r as usize]);
        match i.code {
            Code::Copy if writes[i.a as usize] <= 1 => alias[i.out as usize] = i.a,
            _ => {
                for w in i.writes() {
                    alias[w as usize] = w;
                }
                kept.push(i);
            }
        }
    }
    for o in out.iter_mut() {
        *o = alias[*o as usize];
    }
    kept
}

/// How many readers each instruction's result has (`out` counts as one).
fn readers(ins: &[Ins], regs: usize, out: &[u16; 3]) -> Vec<u32> {
    let mut last = vec![usize::MAX; regs];
    let mut n = vec![0u32; ins.len()];
    let mut read = |last: &[usize], r: u16| {
        if let Some(d) = last.get(r as usize).copied().filter(|&d| d != usize::MAX) {
            n[d] += 1;
        }
    };
    for (j, i) in ins.iter().enumerate() {
        for r in i.operands() {
            read(&last, r);
        }
        for w in i.writes() {
            last[w as usize] = j;
        }
    }
    for &o in out {
        read(&last, o);
    }
    n
}

/// One instruction doing the work of `p` and the `q` right after it that alone reads
/// `p`'s result, where the pair is common in bodies (a gyroid's `sin(k·x)`, its sums of
/// products; a distance less a radius). Each computes in the same order as the pair,
/// so the result is the same to the bit.
fn fused(p: &Ins, q: &Ins) -> Option<Ins> {
    let other = |q: &Ins| match (q.a == p.out, q.b == p.out) {
        (true, false) => Some(q.b),
        (false, true) => Some(q.a),
        _ => None,
    };
    let ins = |code, a, b, c, k| Some(Ins { code, out: q.out, a, b, c, k });
    match (p.code, q.code) {
        (Code::MulC, Code::SinCos) if q.a == p.out && q.k == 1.0 => {
            Some(Ins { code: Code::SinCos, out: q.out, a: p.a, b: q.b, c: 0, k: p.k })
        }
        (Code::Binary(Binary::Mul), Code::Binary(Binary::Add)) => ins(Code::MulAdd, p.a, p.b, other(q)?, 0.0),
        (Code::MulC, Code::Binary(Binary::Add)) => ins(Code::MulCAdd, p.a, other(q)?, 0, p.k),
        (Code::Unary(Unary::Abs), Code::SubC) if q.a == p.out => ins(Code::AbsSubC, p.a, 0, 0, q.k),
        (Code::Length, Code::SubC) if q.a == p.out => ins(Code::LengthSubC, p.a, p.b, p.c, q.k),
        _ => None,
    }
}

/// Fuses the pairs [`fused`] knows.
fn fuse(ins: Vec<Ins>, regs: usize, out: &[u16; 3]) -> Vec<Ins> {
    let n = readers(&ins, regs, out);
    let mut kept = Vec::with_capacity(ins.len());
    let mut i = 0;
    while i < ins.len() {
        if let Some(f) = ins.get(i + 1).filter(|_| n[i] == 1).and_then(|q| fused(&ins[i], q)) {
            kept.push(f);
            i += 2;
        } else {
            kept.push(ins[i]);
            i += 1;
        }
    }
    kept
}

/// One instruction: `out = code(a, b, c)`, or with the constant `k`.
#[derive(Clone, Copy, Debug)]
struct Ins {
    code: Code,
    out: u16,
    a: u16,
    b: u16,
    c: u16,
    k: f32,
}

/// Makes a sine and a cosine of one angle one instruction: the sine's computes both,
/// the cosine into a register of its own that the cosine's place then copies from
/// (the angle's register must hold the same value at both).
fn fuse_sincos(ins: &mut [Ins], extra: &mut usize) {
    for i in 0..ins.len() {
        let (code, a) = (ins[i].code, ins[i].a);
        let partner = match code {
            Code::Unary(Unary::Sin) => Code::Unary(Unary::Cos),
            Code::Unary(Unary::Cos) => Code::Unary(Unary::Sin),
            _ => continue,
        };
        // The first partner reading the angle before anything overwrites it.
        let mut found = None;
        for (j, next) in ins.iter().enumerate().skip(i) {
            if j > i && next.code == partner && next.a == a {
                found = Some(j);
                break;
            }
            if next.out == a {
                break;
            }
        }
        let Some(j) = found else { continue };
        let spare = *extra as u16;
        *extra += 1;
        let mine = ins[i].out;
        ins[i] = if code == Code::Unary(Unary::Sin) {
            Ins { code: Code::SinCos, out: mine, a, b: spare, c: 0, k: 1.0 }
        } else {
            Ins { code: Code::SinCos, out: spare, a, b: mine, c: 0, k: 1.0 }
        };
        ins[j] = Ins { code: Code::Copy, out: ins[j].out, a: spare, b: 0, c: 0, k: 0.0 };
    }
}

/// Lane `l` of `W` is `f(l)`.
#[inline(always)]
fn each<const W: usize>(f: impl Fn(usize) -> f32) -> [f32; W] {
    std::array::from_fn(f)
}

/// A tape flattened for f32.
#[derive(Clone, Debug)]
pub struct Flat {
    ins: Vec<Ins>,
    out: [u16; 3],
    /// The first of the three registers holding the point.
    inputs: u16,
    /// Whether its registers fit [`SMALL_REGS`].
    small: bool,
}

impl Flat {
    /// `tape` flattened, or `None` if it needs more than `FLAT_REGS` registers or reads an outline.
    pub fn new(tape: &Tape) -> Option<Flat> {
        // The point's coordinates first, in registers no instruction writes.
        let inputs = tape.regs as u16;
        let mut extra = tape.regs + 3;
        let mut ins = Vec::with_capacity(tape.ops.len());
        let mut constant = |ins: &mut Vec<Ins>, k: f64| {
            let r = extra as u16;
            extra += 1;
            ins.push(Ins { code: Code::Const, out: r, a: 0, b: 0, c: 0, k: k as f32 });
            r
        };
        for &(op, out) in &tape.ops {
            let out = out as u16;
            let i = |code, a: u32, b: u32, c: u32, k: f64| Ins {
                code,
                out,
                a: a as u16,
                b: b as u16,
                c: c as u16,
                k: k as f32,
            };
            let next = match op {
                Op::Input(a) => i(Code::Copy, u32::from(inputs) + u32::from(a), 0, 0, 0.0),
                Op::Const(k) => i(Code::Const, 0, 0, 0, k),
                Op::Unary(f, a) => i(Code::Unary(f), a, 0, 0, 0.0),
                Op::Binary(f, a, b) => i(Code::Binary(f), a, b, 0, 0.0),
                Op::BinaryRc(f, a, k) => match f {
                    Binary::Add => i(Code::AddC, a, 0, 0, k),
                    Binary::Sub => i(Code::SubC, a, 0, 0, k),
                    Binary::Mul => i(Code::MulC, a, 0, 0, k),
                    Binary::Div => i(Code::DivC, a, 0, 0, k),
                    Binary::Min => i(Code::MinC, a, 0, 0, k),
                    Binary::Max => i(Code::MaxC, a, 0, 0, k),
                    _ => {
                        let r = constant(&mut ins, k);
                        i(Code::Binary(f), a, r as u32, 0, 0.0)
                    }
                },
                Op::BinaryLc(f, k, b) => match f {
                    Binary::Add => i(Code::AddC, b, 0, 0, k),
                    Binary::Sub => i(Code::CSub, b, 0, 0, k),
                    Binary::Mul => i(Code::MulC, b, 0, 0, k),
                    Binary::Div => i(Code::CDiv, b, 0, 0, k),
                    Binary::Min => i(Code::MinC, b, 0, 0, k),
                    Binary::Max => i(Code::MaxC, b, 0, 0, k),
                    _ => {
                        let r = constant(&mut ins, k);
                        i(Code::Binary(f), r as u32, b, 0, 0.0)
                    }
                },
                Op::Select(c, a, b) => i(Code::Select, a, b, c, 0.0),
                Op::Length(v) => i(Code::Length, v[0], v[1], v[2], 0.0),
                Op::Dist(s, q) => {
                    Ins { code: Code::Dist, out, a: q[0] as u16, b: q[1] as u16, c: q[2] as u16, k: f32::from_bits(s) }
                }
                Op::Noise(s, q) => {
                    Ins { code: Code::Noise, out, a: q[0] as u16, b: q[1] as u16, c: q[2] as u16, k: f32::from_bits(s) }
                }
                // An outline's distance is a search over its segments in f64, not an
                // instruction: such a body runs on the tape.
                Op::Outline(..) => return None,
            };
            ins.push(next);
        }
        fuse_sincos(&mut ins, &mut extra);
        if extra > FLAT_REGS {
            return None;
        }
        let o = |i: usize| tape.out[i.min(tape.out.len() - 1)] as u16;
        let mut out = [o(0), o(1), o(2)];
        let ins = forward(ins, extra, &mut out);
        let ins = fuse(ins, extra, &out);
        Some(Flat { ins, out, inputs, small: extra <= SMALL_REGS })
    }

    /// The tape run for `W` points at once in as many registers as it needs, `live` of
    /// the lanes wanted: the lanes of its three results (a number's in the first).
    #[inline(always)]
    fn outs<const W: usize>(&self, p: &[Vec3A; W], live: usize, dist: &dyn Distances<f32>) -> [[f32; W]; 3] {
        if self.small {
            self.run_n::<SMALL_REGS, W>(p, live, dist)
        } else {
            self.run_n::<FLAT_REGS, W>(p, live, dist)
        }
    }

    /// The tape with `N` registers (a power of two the tape fits) run for `W` points at
    /// once, lane by lane in each instruction: one dispatch serves every lane, and the
    /// lanes' arithmetic is one vector loop. The first `live` lanes are wanted; the
    /// others repeat a point (so a shape's distance is asked only for the live ones).
    /// It gives only the three result registers' lanes: returning all `N` would copy
    /// them.
    ///
    /// Long because it is the interpreter's loop, one arm per instruction, kept in one
    /// function so each arm's lane loop is a single vector loop.
    #[inline(always)]
    fn run_n<const N: usize, const W: usize>(
        &self,
        p: &[Vec3A; W],
        live: usize,
        dist: &dyn Distances<f32>,
    ) -> [[f32; W]; 3] {
        let mask = N as u16 - 1;
        let mut r = [[0.0f32; W]; N];
        for axis in 0..3u16 {
            let reg = &mut r[(self.inputs + axis) as usize & (N - 1)];
            for (x, p) in reg.iter_mut().zip(p) {
                *x = p[axis as usize];
            }
        }
        for ins in &self.ins {
            let x = |i: u16| r[(i & mask) as usize];
            let (a, k) = (x(ins.a), ins.k);
            let v: [f32; W] = match ins.code {
                Code::Const => [k; W],
                Code::AddC => a.map(|a| a + k),
                Code::SubC => a.map(|a| a - k),
                Code::CSub => a.map(|a| k - a),
                Code::MulC => a.map(|a| a * k),
                Code::DivC => a.map(|a| a / k),
                Code::CDiv => a.map(|a| k / a),
                Code::MinC => a.map(|a| a.min(k)),
                Code::MaxC => a.map(|a| a.max(k)),
                Code::Unary(Unary::Sin) => a.map(sin_deg),
                Code::Unary(Unary::Cos) => a.map(cos_deg),
                Code::SinCos => {
                    let (mut s, mut c) = ([0.0; W], [0.0; W]);
                    for l in 0..W {
                        (s[l], c[l]) = sincos_deg(a[l] * k);
                    }
                    r[(ins.b & mask) as usize] = c;
                    s
                }
                Code::Copy => a,
                Code::MulAdd => {
                    let (b, c) = (x(ins.b), x(ins.c));
                    each(|l| a[l] * b[l] + c[l])
                }
                Code::MulCAdd => {
                    let b = x(ins.b);
                    each(|l| a[l] * k + b[l])
                }
                Code::AbsSubC => a.map(|a| a.abs() - k),
                Code::Unary(Unary::Abs) => a.map(f32::abs),
                Code::Unary(Unary::Neg) => a.map(|a| -a),
                Code::Unary(f) => a.map(|a| <f32 as Scalar>::unary(f, a)),
                Code::Binary(f) => {
                    let b = x(ins.b);
                    match f {
                        Binary::Add => each(|l| a[l] + b[l]),
                        Binary::Sub => each(|l| a[l] - b[l]),
                        Binary::Mul => each(|l| a[l] * b[l]),
                        Binary::Min => each(|l| a[l].min(b[l])),
                        Binary::Max => each(|l| a[l].max(b[l])),
                        f => each(|l| <f32 as Scalar>::binary(f, a[l], b[l])),
                    }
                }
                Code::Select => {
                    let (b, c) = (x(ins.b), x(ins.c));
                    each(|l| if c[l] != 0.0 { a[l] } else { b[l] })
                }
                // A length alone carries `k` = 0, which subtracts to the same bits.
                Code::Length | Code::LengthSubC => {
                    let (b, c) = (x(ins.b), x(ins.c));
                    each(|l| (a[l] * a[l] + b[l] * b[l] + c[l] * c[l]).sqrt() - k)
                }
                Code::Dist | Code::Noise => {
                    let (b, c) = (x(ins.b), x(ins.c));
                    let mut v = [0.0; W];
                    for l in 0..live {
                        let q = [a[l], b[l], c[l]];
                        v[l] = if ins.code == Code::Dist {
                            dist.dist(k.to_bits(), q)
                        } else {
                            <f32 as Scalar>::noise(q, k.to_bits())
                        };
                    }
                    v
                }
            };
            r[(ins.out & mask) as usize] = v;
        }
        self.out.map(|o| r[(o & mask) as usize])
    }

    /// The number at each of up to 16 points, into `out`: [`eval`](Self::eval) point by
    /// point, to the bit, for less than a quarter of the dispatch.
    pub fn eval_lanes(&self, p: &[Vec3A], dist: &dyn Distances<f32>, out: &mut [f32]) {
        match p.len() {
            0 => {}
            1..=4 => self.lanes::<4>(p, dist, out),
            5..=8 => self.lanes::<8>(p, dist, out),
            _ => {
                for (p, out) in p.chunks(16).zip(out.chunks_mut(16)) {
                    self.lanes::<16>(p, dist, out);
                }
            }
        }
    }

    /// [`eval_lanes`](Self::eval_lanes) in `W` lanes, `p.len()` ≤ `W` of them live.
    fn lanes<const W: usize>(&self, p: &[Vec3A], dist: &dyn Distances<f32>, out: &mut [f32]) {
        let live = p.len();
        let pts: [Vec3A; W] = std::array::from_fn(|l| p[l.min(live - 1)]);
        let [v, ..] = self.outs::<W>(&pts, live, dist);
        out[..live].copy_from_slice(&v[..live]);
    }

    /// The tape with `N` registers run on dual numbers at `p`: what [`Tape::run`] gives
    /// for [`Dual`], to the bit, each fused instruction differentiated as the pair it
    /// stands for (so a sphere's normal is one instruction, not five).
    fn run_dual<const N: usize>(&self, p: Vec3A, dist: &dyn Distances<Dual>) -> [Dual; 3] {
        let mask = N as u16 - 1;
        let mut r = [Dual::default(); N];
        for axis in 0..3u8 {
            r[(self.inputs + u16::from(axis)) as usize & (N - 1)] = Dual::input(&p, axis);
        }
        let k = |k: f32| Dual { v: k, g: Vec3A::ZERO };
        for ins in &self.ins {
            let x = |i: u16| r[(i & mask) as usize];
            let (a, c) = (x(ins.a), k(ins.k));
            let v = match ins.code {
                Code::Const => c,
                Code::AddC => Dual::binary(Binary::Add, a, c),
                Code::SubC => Dual::binary(Binary::Sub, a, c),
                Code::CSub => Dual::binary(Binary::Sub, c, a),
                Code::MulC => Dual::binary(Binary::Mul, a, c),
                Code::DivC => Dual::binary(Binary::Div, a, c),
                Code::CDiv => Dual::binary(Binary::Div, c, a),
                Code::MinC => Dual::binary(Binary::Min, a, c),
                Code::MaxC => Dual::binary(Binary::Max, a, c),
                Code::Unary(f) => Dual::unary(f, a),
                Code::Binary(f) => Dual::binary(f, a, x(ins.b)),
                Code::Select => Dual::select(x(ins.c), a, x(ins.b)),
                Code::Length => Dual::length([a, x(ins.b), x(ins.c)]),
                Code::LengthSubC => Dual::binary(Binary::Sub, Dual::length([a, x(ins.b), x(ins.c)]), c),
                Code::Dist => dist.dist(ins.k.to_bits(), [a, x(ins.b), x(ins.c)]),
                Code::Noise => Dual::noise([a, x(ins.b), x(ins.c)], ins.k.to_bits()),
                Code::SinCos => {
                    // `k` is 1 where no multiply was fused in.
                    let angle = if ins.k == 1.0 { a } else { Dual::binary(Binary::Mul, a, c) };
                    r[(ins.b & mask) as usize] = Dual::unary(Unary::Cos, angle);
                    Dual::unary(Unary::Sin, angle)
                }
                Code::Copy => a,
                Code::MulAdd => Dual::binary(Binary::Add, Dual::binary(Binary::Mul, a, x(ins.b)), x(ins.c)),
                Code::MulCAdd => Dual::binary(Binary::Add, Dual::binary(Binary::Mul, a, c), x(ins.b)),
                Code::AbsSubC => Dual::binary(Binary::Sub, Dual::unary(Unary::Abs, a), c),
            };
            r[(ins.out & mask) as usize] = v;
        }
        self.out.map(|o| r[(o & mask) as usize])
    }

    /// The number at `p` with its gradient: `Tape::eval::<Dual>`, to the bit.
    #[inline]
    pub fn dual(&self, p: Vec3A, dist: &dyn Distances<Dual>) -> Dual {
        self.dual3(p, dist)[0]
    }

    /// The vector at `p`, each component with its gradient: `Tape::eval3::<Dual>`, to
    /// the bit.
    #[inline]
    pub fn dual3(&self, p: Vec3A, dist: &dyn Distances<Dual>) -> [Dual; 3] {
        if self.small {
            self.run_dual::<SMALL_REGS>(p, dist)
        } else {
            self.run_dual::<FLAT_REGS>(p, dist)
        }
    }

    /// How many instructions an evaluation runs.
    pub fn instructions(&self) -> usize {
        self.ins.len()
    }

    /// The number at `p`.
    #[inline]
    pub fn eval(&self, p: Vec3A, dist: &dyn Distances<f32>) -> f32 {
        self.outs::<1>(&[p], 1, dist)[0][0]
    }

    /// The vector at `p`.
    #[inline]
    pub fn eval3(&self, p: Vec3A, dist: &dyn Distances<f32>) -> Vec3A {
        let [x, y, z] = self.outs::<1>(&[p], 1, dist);
        Vec3A::new(x[0], y[0], z[0])
    }
}
