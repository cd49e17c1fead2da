//! What one distance evaluation of a shape costs, as an upper bound: the primitives
//! it evaluates and the tape instructions it runs, work counted where it is multiplied
//! (each `dist` a body reads runs its shape once per reading, a `repeat` evaluates up to
//! three copies per repeated axis, a `polar` whose parts cross their sectors is a body
//! reading every copy), not only where nodes are made. The checker refuses a shape past
//! [`MAX_WORK`] and warns past [`WARN_WORK`] (`docs/limits.md`).

use std::collections::HashMap;
use std::sync::Arc;

use super::{Op, Tape};
use crate::ir::{Shape, ShapeKind};

/// Work per distance evaluation past which a shape is refused (E0710).
pub const MAX_WORK: u64 = 1_000_000;

/// Work per distance evaluation past which a shape is warned about (W0011).
pub const WARN_WORK: u64 = 100_000;

/// An upper bound of what one evaluation of a shape's distance does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cost {
    /// Primitive evaluations (the SDF back-end's leaf closures, `--stats`'s leaf count):
    /// a primitive, a swept profile and a field's own value each count one.
    pub leaves: u64,
    /// Tape instructions of field, warp and displacement bodies.
    pub ops: u64,
}

impl Cost {
    /// The work the budgets are set in: a primitive and an instruction count one each.
    pub fn work(&self) -> u64 {
        self.leaves.saturating_add(self.ops)
    }

    fn plus(self, other: Cost, times: u64) -> Cost {
        Cost {
            leaves: self.leaves.saturating_add(other.leaves.saturating_mul(times)),
            ops: self.ops.saturating_add(other.ops.saturating_mul(times)),
        }
    }
}

/// The cost of one evaluation of `shape`'s distance, each distinct node costed once
/// (so a shape shared level on level costs one walk, whatever it multiplies into).
pub fn evaluation_cost(shape: &Arc<Shape>) -> Cost {
    Costs::default().of(shape)
}

/// Costs by node, kept across the walk.
#[derive(Default)]
struct Costs {
    memo: HashMap<*const Shape, Cost>,
}

impl Costs {
    fn of(&mut self, shape: &Arc<Shape>) -> Cost {
        let key = Arc::as_ptr(shape);
        if let Some(&c) = self.memo.get(&key) {
            return c;
        }
        let one = Cost { leaves: 1, ops: 0 };
        let cost = match &shape.kind {
            ShapeKind::Primitive(_) | ShapeKind::Field { sweep: Some(_), .. } => one,
            ShapeKind::Csg { children, .. } => {
                children.iter().fold(Cost::default(), |c, child| c.plus(self.of(child), 1))
            }
            ShapeKind::Round { child, .. }
            | ShapeKind::Shell { child, .. }
            | ShapeKind::Transform { child, .. }
            | ShapeKind::Paint { child, .. } => self.of(child),
            // The nearest cell and its neighbours on each repeated axis.
            ShapeKind::Repeat { child, count, .. } => {
                let cells = count.iter().map(|&n| u64::from(n.clamp(1, 3))).product::<u64>();
                Cost::default().plus(self.of(child), cells)
            }
            ShapeKind::Field { body, .. } => one.plus(self.tape(&Tape::new(body)), 1),
            ShapeKind::Warp { child, map, .. } => self.tape(&Tape::new(map)).plus(self.of(child), 1),
            ShapeKind::Displace { child, by, .. } => self.tape(&Tape::new(by)).plus(self.of(child), 1),
        };
        self.memo.insert(key, cost);
        cost
    }

    /// A tape's instructions, and each `dist` it runs at the cost of its shape.
    fn tape(&mut self, tape: &Tape) -> Cost {
        let mut cost = Cost { leaves: 0, ops: tape.ops.len() as u64 };
        for (op, _) in &tape.ops {
            if let Op::Dist(i, _) = op {
                cost = cost.plus(self.of(&tape.shapes[*i as usize]), 1);
            }
        }
        cost
    }
}
