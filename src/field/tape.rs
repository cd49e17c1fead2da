//! A field expression compiled to a tape: a straight-line program over scalar
//! registers, vector operations split into their components, common subexpressions
//! computed once, and registers reused once their value is dead (as fidget's and
//! libfive's tapes are). One tape is evaluated by every [`Scalar`] type.

use std::collections::HashMap;
use std::sync::Arc;

use crate::geom::outline::Outline;
use crate::ir::field::{Binary, FieldExpr, FieldKind, FieldTy, Unary};
use crate::ir::Shape;

/// A register index.
pub type Reg = u32;

/// One instruction: what it computes from which registers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    /// The point's x, y or z.
    Input(u8),
    /// A constant.
    Const(f64),
    /// A function of one number (never `Length` or `Normalize`, which are split).
    Unary(Unary, Reg),
    /// A function of two numbers (never `Dot` or `Cross`, which are split).
    Binary(Binary, Reg, Reg),
    /// `f(a, c)` with the constant `c` carried in the instruction.
    BinaryRc(Binary, Reg, f64),
    /// `f(c, b)` with the constant `c` carried in the instruction.
    BinaryLc(Binary, f64, Reg),
    /// `if c then a else b`.
    Select(Reg, Reg, Reg),
    /// The length of the vector of three registers.
    Length([Reg; 3]),
    /// `dist` of the tape's `i`-th shape at the point of three registers.
    Dist(u32, [Reg; 3]),
    /// Gradient noise at the point of three registers (already divided by the size).
    Noise(u32, [Reg; 3]),
    /// The signed distance of the tape's `i`-th outline at the `[u, v]` of two registers.
    Outline(u32, [Reg; 2]),
}

/// What a [`Tape`] is evaluated over: f32 for marching, dual numbers for normals,
/// intervals for pruning and the Lipschitz analysis. Truth values are 1 and 0.
pub trait Scalar: Copy {
    /// The point's coordinates as this type sees them.
    type Point: Copy;
    /// The component `axis` of the point.
    fn input(p: &Self::Point, axis: u8) -> Self;
    /// A constant.
    fn constant(x: f64) -> Self;
    /// `f(x)`.
    fn unary(f: Unary, x: Self) -> Self;
    /// `f(a, b)`.
    fn binary(f: Binary, a: Self, b: Self) -> Self;
    /// `if c then a else b`.
    fn select(c: Self, a: Self, b: Self) -> Self;
    /// The length of `(a, b, c)`.
    fn length(v: [Self; 3]) -> Self;
    /// Gradient noise at `q`.
    fn noise(q: [Self; 3], seed: u32) -> Self;
    /// The signed distance of `o` at `[u, v]` (exact, so its slope is 1).
    fn outline(o: &Outline, u: Self, v: Self) -> Self;
}

/// How a tape's `dist` instructions are answered for one scalar type.
pub trait Distances<S: Scalar> {
    /// The `i`-th shape's distance at `q`.
    fn dist(&self, i: u32, q: [S; 3]) -> S;
}

/// A tape with no `dist`: any scalar type.
pub struct NoDistances;

impl<S: Scalar> Distances<S> for NoDistances {
    fn dist(&self, _: u32, _: [S; 3]) -> S {
        S::constant(f64::INFINITY)
    }
}

/// A compiled field body.
#[derive(Clone, Debug)]
pub struct Tape {
    /// Instructions with the register each writes, in order.
    pub ops: Vec<(Op, Reg)>,
    /// Registers used (the scratch an evaluation needs).
    pub regs: usize,
    /// The result: one register for a number, three for a vector.
    pub out: Vec<Reg>,
    /// The shapes `dist` reads, by index.
    pub shapes: Vec<Arc<Shape>>,
    /// The outlines read, by index.
    pub outlines: Vec<Arc<Outline>>,
}

/// Value numbering: an SSA value per distinct instruction.
struct Builder {
    ssa: Vec<Op>,
    seen: HashMap<OpKey, u32>,
    memo: HashMap<*const FieldExpr, Vec<u32>>,
    shapes: Vec<Arc<Shape>>,
    outlines: Vec<Arc<Outline>>,
}

/// An instruction as a hash key (constants by their bits).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum OpKey {
    Input(u8),
    Const(u64),
    Unary(Unary, u32),
    Binary(Binary, u32, u32),
    BinaryRc(Binary, u32, u64),
    BinaryLc(Binary, u64, u32),
    Select(u32, u32, u32),
    Length([u32; 3]),
    Dist(u32, [u32; 3]),
    Noise(u32, [u32; 3]),
    Outline(u32, [u32; 2]),
}

impl Builder {
    fn push(&mut self, op: Op) -> u32 {
        let key = match op {
            Op::Input(a) => OpKey::Input(a),
            Op::Const(c) => OpKey::Const((c + 0.0).to_bits()),
            Op::Unary(f, a) => OpKey::Unary(f, a),
            Op::Binary(f, a, b) => OpKey::Binary(f, a, b),
            Op::BinaryRc(f, a, c) => OpKey::BinaryRc(f, a, (c + 0.0).to_bits()),
            Op::BinaryLc(f, c, b) => OpKey::BinaryLc(f, (c + 0.0).to_bits(), b),
            Op::Select(c, a, b) => OpKey::Select(c, a, b),
            Op::Length(v) => OpKey::Length(v),
            Op::Dist(i, q) => OpKey::Dist(i, q),
            Op::Noise(s, q) => OpKey::Noise(s, q),
            Op::Outline(i, q) => OpKey::Outline(i, q),
        };
        if let Some(&id) = self.seen.get(&key) {
            return id;
        }
        let id = self.ssa.len() as u32;
        self.ssa.push(op);
        self.seen.insert(key, id);
        id
    }

    fn constant_of(&self, id: u32) -> Option<f64> {
        match self.ssa[id as usize] {
            Op::Const(c) => Some(c),
            _ => None,
        }
    }

    /// `f(a)`, folded when `a` is a constant.
    fn unary(&mut self, f: Unary, a: u32) -> u32 {
        match self.constant_of(a) {
            Some(x) => self.push(Op::Const(f.apply(x))),
            None => self.push(Op::Unary(f, a)),
        }
    }

    /// `f(a, b)`, folded when both are constants and simplified by identities that
    /// hold for every number (`x + 0`, `x * 1`, `x / 1`).
    fn binary(&mut self, f: Binary, a: u32, b: u32) -> u32 {
        match (self.constant_of(a), self.constant_of(b)) {
            (Some(x), Some(y)) => self.push(Op::Const(f.apply(x, y))),
            (_, Some(y)) if y == 0.0 && matches!(f, Binary::Add | Binary::Sub) => a,
            (Some(x), _) if x == 0.0 && f == Binary::Add => b,
            (_, Some(y)) if y == 1.0 && matches!(f, Binary::Mul | Binary::Div) => a,
            (Some(x), _) if x == 1.0 && f == Binary::Mul => b,
            // A constant operand rides in the instruction: no register, no load.
            (_, Some(y)) => self.push(Op::BinaryRc(f, a, y)),
            (Some(x), _) => self.push(Op::BinaryLc(f, x, b)),
            _ => self.push(Op::Binary(f, a, b)),
        }
    }

    /// The SSA values of `e`: one for a number or truth value, three for a vector.
    fn expr(&mut self, e: &Arc<FieldExpr>) -> Vec<u32> {
        if let Some(v) = self.memo.get(&Arc::as_ptr(e)) {
            return v.clone();
        }
        let out = self.expr_inner(e);
        self.memo.insert(Arc::as_ptr(e), out.clone());
        out
    }

    fn expr_inner(&mut self, e: &Arc<FieldExpr>) -> Vec<u32> {
        match &e.kind {
            FieldKind::Point => (0..3).map(|a| self.push(Op::Input(a))).collect(),
            FieldKind::Num(x) => vec![self.push(Op::Const(*x))],
            FieldKind::Vec(v) => v.to_array().iter().map(|c| self.push(Op::Const(*c))).collect(),
            FieldKind::Component(v, i) => vec![self.expr(v)[*i]],
            FieldKind::Vector(xs) => xs.iter().map(|x| self.expr(x)[0]).collect(),
            FieldKind::Unary(Unary::Length, v) => {
                let v = self.expr(v);
                vec![self.push(Op::Length([v[0], v[1], v[2]]))]
            }
            FieldKind::Unary(Unary::Normalize, v) => {
                // The zero vector stays zero: divided by a length of at least the tiniest.
                let v = self.expr(v);
                let len = self.push(Op::Length([v[0], v[1], v[2]]));
                let tiny = self.push(Op::Const(1e-30));
                let len = self.binary(Binary::Max, len, tiny);
                v.iter().map(|&c| self.binary(Binary::Div, c, len)).collect()
            }
            FieldKind::Unary(f, x) => self.expr(x).into_iter().map(|c| self.unary(*f, c)).collect(),
            FieldKind::Binary(Binary::Dot, a, b) => {
                let (a, b) = (self.expr(a), self.expr(b));
                let terms: Vec<u32> = (0..3).map(|i| self.binary(Binary::Mul, a[i], b[i])).collect();
                let ab = self.binary(Binary::Add, terms[0], terms[1]);
                vec![self.binary(Binary::Add, ab, terms[2])]
            }
            FieldKind::Binary(Binary::Cross, a, b) => {
                let (a, b) = (self.expr(a), self.expr(b));
                (0..3)
                    .map(|i| {
                        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                        let l = self.binary(Binary::Mul, a[j], b[k]);
                        let r = self.binary(Binary::Mul, a[k], b[j]);
                        self.binary(Binary::Sub, l, r)
                    })
                    .collect()
            }
            FieldKind::Binary(f, a, b) => {
                let (a, b) = (self.expr(a), self.expr(b));
                let n = a.len().max(b.len());
                // A number against a vector applies to each component.
                (0..n).map(|i| self.binary(*f, a[i.min(a.len() - 1)], b[i.min(b.len() - 1)])).collect()
            }
            FieldKind::Select(c, a, b) => {
                let c = self.expr(c)[0];
                let (a, b) = (self.expr(a), self.expr(b));
                match self.constant_of(c) {
                    Some(x) if x != 0.0 => a,
                    Some(_) => b,
                    None => a.iter().zip(&b).map(|(&x, &y)| self.push(Op::Select(c, x, y))).collect(),
                }
            }
            FieldKind::Dist(shape, q) => {
                let q = self.expr(q);
                let i = index_of(&mut self.shapes, shape);
                vec![self.push(Op::Dist(i, [q[0], q[1], q[2]]))]
            }
            FieldKind::Noise { at, size, seed } => {
                let q = self.expr(at);
                let inv = self.push(Op::Const(1.0 / size));
                let q: Vec<u32> = q.iter().map(|&c| self.binary(Binary::Mul, c, inv)).collect();
                vec![self.push(Op::Noise(*seed, [q[0], q[1], q[2]]))]
            }
            FieldKind::Outline(o, at) => {
                let q = self.expr(at);
                let i = index_of(&mut self.outlines, o);
                vec![self.push(Op::Outline(i, [q[0], q[1]]))]
            }
        }
    }
}

/// The index of `item` in `list` (the same `Arc`), added at the end when it is not there.
fn index_of<T>(list: &mut Vec<Arc<T>>, item: &Arc<T>) -> u32 {
    let i = list.iter().position(|s| Arc::ptr_eq(s, item)).unwrap_or_else(|| {
        list.push(item.clone());
        list.len() - 1
    });
    i as u32
}

impl Op {
    /// The SSA values (or registers) it reads.
    fn reads(&self) -> Vec<u32> {
        match *self {
            Op::Input(_) | Op::Const(_) => vec![],
            Op::Unary(_, a) | Op::BinaryRc(_, a, _) | Op::BinaryLc(_, _, a) => vec![a],
            Op::Binary(_, a, b) => vec![a, b],
            Op::Select(c, a, b) => vec![c, a, b],
            Op::Length(v) | Op::Dist(_, v) | Op::Noise(_, v) => v.to_vec(),
            Op::Outline(_, v) => v.to_vec(),
        }
    }

    /// The same instruction reading `map(r)` for each `r` it reads.
    fn renamed(&self, map: impl Fn(u32) -> u32) -> Op {
        match *self {
            Op::Input(_) | Op::Const(_) => *self,
            Op::Unary(f, a) => Op::Unary(f, map(a)),
            Op::Binary(f, a, b) => Op::Binary(f, map(a), map(b)),
            Op::BinaryRc(f, a, c) => Op::BinaryRc(f, map(a), c),
            Op::BinaryLc(f, c, b) => Op::BinaryLc(f, c, map(b)),
            Op::Select(c, a, b) => Op::Select(map(c), map(a), map(b)),
            Op::Length(v) => Op::Length(v.map(map)),
            Op::Dist(i, v) => Op::Dist(i, v.map(map)),
            Op::Noise(s, v) => Op::Noise(s, v.map(map)),
            Op::Outline(i, v) => Op::Outline(i, v.map(map)),
        }
    }
}

impl Tape {
    /// Compiles `e` (a number, vector or truth value).
    pub fn new(e: &Arc<FieldExpr>) -> Tape {
        let mut b = Builder {
            ssa: Vec::new(),
            seen: HashMap::new(),
            memo: HashMap::new(),
            shapes: Vec::new(),
            outlines: Vec::new(),
        };
        let outs = b.expr(e);
        // Only what the result needs, in order: dead values (an unused branch's parts
        // after folding) are dropped.
        let mut live = vec![false; b.ssa.len()];
        for &o in &outs {
            live[o as usize] = true;
        }
        for i in (0..b.ssa.len()).rev() {
            if live[i] {
                for r in b.ssa[i].reads() {
                    live[r as usize] = true;
                }
            }
        }
        let mut last_use = vec![0usize; b.ssa.len()];
        for (i, op) in b.ssa.iter().enumerate() {
            if live[i] {
                for r in op.reads() {
                    last_use[r as usize] = i;
                }
            }
        }
        for &o in &outs {
            last_use[o as usize] = usize::MAX;
        }
        // Linear-scan register allocation: a value's register is free after its last read.
        let mut reg_of = vec![Reg::MAX; b.ssa.len()];
        let mut free: Vec<Reg> = Vec::new();
        let mut regs = 0usize;
        let mut ops = Vec::new();
        for (i, op) in b.ssa.iter().enumerate() {
            if !live[i] {
                continue;
            }
            let renamed = op.renamed(|r| reg_of[r as usize]);
            // Operands that die here free their registers before the result takes one.
            for r in op.reads() {
                if last_use[r as usize] == i && !free.contains(&reg_of[r as usize]) {
                    free.push(reg_of[r as usize]);
                }
            }
            let out = free.pop().unwrap_or_else(|| {
                regs += 1;
                (regs - 1) as Reg
            });
            reg_of[i] = out;
            ops.push((renamed, out));
        }
        let out = outs.iter().map(|&o| reg_of[o as usize]).collect();
        Tape { ops, regs: regs.max(1), out, shapes: b.shapes, outlines: b.outlines }
    }

    /// The type of value the tape computes.
    pub fn ty(&self) -> FieldTy {
        if self.out.len() == 3 {
            FieldTy::Vec3
        } else {
            FieldTy::Num
        }
    }

    /// Runs the tape at `p` with `regs` as scratch (at least [`regs`](Self::regs) long);
    /// the result is in `regs` at [`out`](Self::out).
    #[inline]
    pub fn run<S: Scalar>(&self, p: &S::Point, regs: &mut [S], dist: &dyn Distances<S>) {
        for &(op, out) in &self.ops {
            let r = |i: Reg| regs[i as usize];
            let v = match op {
                Op::Input(a) => S::input(p, a),
                Op::Const(c) => S::constant(c),
                Op::Unary(f, a) => S::unary(f, r(a)),
                Op::Binary(f, a, b) => S::binary(f, r(a), r(b)),
                Op::BinaryRc(f, a, c) => S::binary(f, r(a), S::constant(c)),
                Op::BinaryLc(f, c, b) => S::binary(f, S::constant(c), r(b)),
                Op::Select(c, a, b) => S::select(r(c), r(a), r(b)),
                Op::Length(v) => S::length(v.map(r)),
                Op::Dist(i, q) => dist.dist(i, q.map(r)),
                Op::Noise(seed, q) => S::noise(q.map(r), seed),
                Op::Outline(i, [u, v]) => S::outline(&self.outlines[i as usize], r(u), r(v)),
            };
            regs[out as usize] = v;
        }
    }

    /// The number the tape computes at `p` (a vector's x).
    pub fn eval<S: Scalar + Default>(&self, p: &S::Point, dist: &dyn Distances<S>) -> S {
        with_scratch(self.regs, |regs| {
            self.run(p, regs, dist);
            regs[self.out[0] as usize]
        })
    }

    /// The vector the tape computes at `p`.
    pub fn eval3<S: Scalar + Default>(&self, p: &S::Point, dist: &dyn Distances<S>) -> [S; 3] {
        with_scratch(self.regs, |regs| {
            self.run(p, regs, dist);
            let o = |i: usize| regs[self.out[i.min(self.out.len() - 1)] as usize];
            [o(0), o(1), o(2)]
        })
    }
}

/// Registers on the stack for a small tape, on the heap for a large one. The smallest
/// tapes (a sphere's five registers) get a smaller array: clearing 48 dual numbers
/// took longer than running them.
#[inline]
fn with_scratch<S: Copy + Default, R>(n: usize, f: impl FnOnce(&mut [S]) -> R) -> R {
    const SMALL: usize = 8;
    const STACK: usize = 48;
    if n <= SMALL {
        let mut regs = [S::default(); SMALL];
        f(&mut regs[..n])
    } else if n <= STACK {
        let mut regs = [S::default(); STACK];
        f(&mut regs[..n])
    } else {
        let mut regs = vec![S::default(); n];
        f(&mut regs)
    }
}
