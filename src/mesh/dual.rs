//! The crossed edges of an octree's subdivision, each with the leaves around it: what
//! dual contouring makes one polygon of. Found by the recursion of Ju et al. 2002
//! (cells, the faces between two nodes, the edges between four), which visits every
//! edge of the subdivision once, at the size of the smallest leaf it borders, and needs no
//! lookups.
//!
//! Around an edge along `axis`, position `i` holds the node at `(du, dw) = POSITIONS[i]`
//! along the next two axes (0: below the edge on that axis): the order that winds its
//! polygon about the axis.

use rayon::prelude::*;

use super::cube::corner_index;
use super::samples::Samples;
use super::tree::{child_origin, Slot, Tree};

/// The four positions around an edge, in winding order.
pub const POSITIONS: [(u32, u32); 4] = [(0, 0), (1, 0), (1, 1), (0, 1)];

/// A node that is no leaf (empty), where a leaf's number would be.
pub const EMPTY: u32 = u32::MAX;

/// Tasks nested this deep or less are run in parallel.
const PARALLEL_DEPTH: u32 = 3;

/// A crossed edge of the subdivision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MinEdge {
    /// Its lower end, in finest-grid coordinates.
    pub start: [u32; 3],
    /// Its axis.
    pub axis: u8,
    /// Its level: it is `2^level` finest cells long.
    pub level: u8,
    /// The leaves around it by position ([`EMPTY`] for an empty node).
    pub around: [u32; 4],
    /// Whether its lower end is inside (its polygon is wound from that end).
    pub inside: bool,
    /// The values at its ends.
    pub values: [f32; 2],
}

/// The subdivision's crossed edges in the order of the walk (the same for any thread
/// count), and the empty nodes found beside one.
pub struct Crossed {
    /// The crossed edges.
    pub edges: Vec<MinEdge>,
    /// Empty nodes (depth, index) next to a crossed edge: their bound ruled a crossing
    /// out by rounding, and they must become leaves.
    pub empties: Vec<(u8, u32)>,
}

/// A node in the recursion.
#[derive(Clone, Copy)]
struct Node {
    depth: u8,
    index: u32,
    origin: [u32; 3],
}

/// What the recursion visits: a node, the face between two, the edge between four.
enum Task {
    Cell(Node),
    Face([Node; 2], usize),
    Edge([Node; 4], usize),
}

/// Every crossed edge of `tree`'s subdivision.
pub fn crossed(tree: &Tree, samples: &Samples) -> Crossed {
    let walk = Walk { tree, samples };
    let mut found = walk.parallel(Task::Cell(Node { depth: 0, index: 0, origin: [0; 3] }), 0);
    found.empties.sort_unstable();
    found.empties.dedup();
    found
}

struct Walk<'a> {
    tree: &'a Tree,
    samples: &'a Samples<'a>,
}

impl Walk<'_> {
    fn slot(&self, n: Node) -> Slot {
        self.tree.slot(n.depth as usize, n.index)
    }

    fn level(&self, n: Node) -> u32 {
        self.tree.grid.levels - u32::from(n.depth)
    }

    /// Whether a leaf lies at or below `n`.
    fn has_leaf(&self, n: Node) -> bool {
        matches!(self.slot(n), Slot::Leaf(_) | Slot::Inner(_, true))
    }

    /// Child `k` of `n` if it is split, else `n` itself.
    fn sub(&self, n: Node, k: usize) -> Node {
        match self.slot(n) {
            Slot::Inner(first, _) => {
                let half = 1 << (self.level(n) - 1);
                Node { depth: n.depth + 1, index: first + k as u32, origin: child_origin(n.origin, half, k) }
            }
            _ => n,
        }
    }

    fn inner(&self, n: Node) -> bool {
        matches!(self.slot(n), Slot::Inner(..))
    }

    /// Calls `each` on the tasks `t` splits into; a minimal edge ends there, recorded in
    /// `out` if crossed.
    fn split(&self, t: &Task, out: &mut Crossed, each: &mut dyn FnMut(Task, &mut Crossed)) {
        match *t {
            Task::Cell(c) => {
                if !matches!(self.slot(c), Slot::Inner(_, true)) {
                    return;
                }
                let kids: [Node; 8] = std::array::from_fn(|k| self.sub(c, k));
                for &k in &kids {
                    each(Task::Cell(k), out);
                }
                for a in 0..3 {
                    for k in (0..8).filter(|k| k & (1 << a) == 0) {
                        each(Task::Face([kids[k], kids[k | 1 << a]], a), out);
                    }
                }
                for a in 0..3 {
                    let (u, w) = ((a + 1) % 3, (a + 2) % 3);
                    for h in 0..2 {
                        let around =
                            POSITIONS.map(|(du, dw)| kids[(h << a) | ((du as usize) << u) | ((dw as usize) << w)]);
                        each(Task::Edge(around, a), out);
                    }
                }
            }
            Task::Face([c1, c2], a) => {
                if !(self.inner(c1) || self.inner(c2)) || !(self.has_leaf(c1) || self.has_leaf(c2)) {
                    return;
                }
                let (u, w) = ((a + 1) % 3, (a + 2) % 3);
                for dw in 0..2 {
                    for du in 0..2 {
                        let k = (du << u) | (dw << w);
                        each(Task::Face([self.sub(c1, k | 1 << a), self.sub(c2, k)], a), out);
                    }
                }
                // The two lines across the face, each in two halves.
                for (e, o) in [(u, w), (w, u)] {
                    for h in 0..2 {
                        let around = POSITIONS.map(|(p1, p2)| {
                            let (da, d_o) = if (e + 1) % 3 == a { (p1, p2) } else { (p2, p1) };
                            let k = ((d_o as usize) << o) | (h << e);
                            if da == 0 {
                                self.sub(c1, k | 1 << a)
                            } else {
                                self.sub(c2, k)
                            }
                        });
                        each(Task::Edge(around, e), out);
                    }
                }
            }
            Task::Edge(around, a) => {
                if !around.iter().any(|&n| self.has_leaf(n)) {
                    return;
                }
                if !around.iter().any(|&n| self.inner(n)) {
                    self.minimal(around, a, out);
                    return;
                }
                let (u, w) = ((a + 1) % 3, (a + 2) % 3);
                for h in 0..2 {
                    let subs: [Node; 4] = std::array::from_fn(|i| {
                        let (du, dw) = POSITIONS[i];
                        self.sub(around[i], (h << a) | (((1 - du) as usize) << u) | (((1 - dw) as usize) << w))
                    });
                    each(Task::Edge(subs, a), out);
                }
            }
        }
    }

    fn run(&self, t: Task, out: &mut Crossed) {
        self.split(&t, out, &mut |s, out| self.run(s, out));
    }

    /// The walk of `t`, its first levels of tasks in parallel, the results in task order.
    fn parallel(&self, t: Task, nesting: u32) -> Crossed {
        let mut out = Crossed { edges: Vec::new(), empties: Vec::new() };
        if nesting >= PARALLEL_DEPTH {
            self.run(t, &mut out);
            return out;
        }
        let mut subs = Vec::new();
        self.split(&t, &mut out, &mut |s, _| subs.push(s));
        let found: Vec<Crossed> = subs.into_par_iter().map(|s| self.parallel(s, nesting + 1)).collect();
        for f in found {
            out.edges.extend(f.edges);
            out.empties.extend(f.empties);
        }
        out
    }

    /// A minimal edge: recorded when the surface crosses it.
    fn minimal(&self, around: [Node; 4], a: usize, out: &mut Crossed) {
        let (u, w) = ((a + 1) % 3, (a + 2) % 3);
        // The smallest node's edge is the edge; a leaf of that size knows its ends' values.
        let deepest = around.iter().map(|n| n.depth).max().unwrap_or(0);
        let i = (0..4)
            .find(|&i| around[i].depth == deepest && matches!(self.slot(around[i]), Slot::Leaf(_)))
            .or_else(|| (0..4).find(|&i| around[i].depth == deepest))
            .unwrap_or(0);
        let (n, (du, dw)) = (around[i], POSITIONS[i]);
        let level = self.level(n);
        let mut start = n.origin;
        start[u] += (1 - du) << level;
        start[w] += (1 - dw) << level;
        let (v0, v1) = match self.slot(n) {
            Slot::Leaf(_) => {
                let c = self.tree.corner_values(n.depth as usize, n.index);
                let mut off = [0u32; 3];
                off[u] = 1 - du;
                off[w] = 1 - dw;
                let first = corner_index(off);
                (c[first], c[first + (1 << a)])
            }
            _ => {
                let mut end = start;
                end[a] += 1 << level;
                (self.samples.value(start), self.samples.value(end))
            }
        };
        let inside = super::samples::inside(v0);
        if inside == super::samples::inside(v1) {
            return;
        }
        let ids = around.map(|n| match self.slot(n) {
            Slot::Leaf(id) => id,
            _ => EMPTY,
        });
        for (k, &id) in ids.iter().enumerate() {
            if id == EMPTY {
                out.empties.push((around[k].depth, around[k].index));
            }
        }
        out.edges.push(MinEdge { start, axis: a as u8, level: level as u8, around: ids, inside, values: [v0, v1] });
    }
}
