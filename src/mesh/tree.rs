//! The cells an isosurface is contoured on: an octree over the grid, split where the
//! surface may pass and, under a tolerance, only as far as the error needs.
//!
//! Every cube whose centre has `|f|` above its half-diagonal holds no surface (`f` is a
//! distance bound) and is left empty. The others are split down to the finest level
//! ([`Plan::Uniform`]), or ([`Plan::Within`]) until a cell passes two tests on the
//! 3×3×3 lattice of its children's corners:
//!
//! - **topology**: its children's surface is one disk that its own corners already show
//!   (Ju et al. 2002's safety conditions, checked directly: every child holds at most one
//!   sheet and no face of a child is ambiguous, the children's sheets join into one
//!   connected piece of Euler characteristic 1, each edge of the cell is crossed at most
//!   once, and the cell's own corners show one sheet);
//! - **geometry**: the tangent planes at the children's edge crossings pass within a
//!   fraction of the tolerance of the point their quadric puts the cell's vertex at
//!   (on a surface of curvature radius `R` a cell of side `h` deviates by about `h²/8R`,
//!   which is what this measures; at an edge or a corner the planes meet at the vertex).
//!
//! The two tests are `mesh::lattice`'s. Small solid parts force their cells down to half
//! their size, so a grid point lies in each; cells where the mesh was measured too far
//! from the surface are split on demand ([`Tree::split`]). The cells are kept level by
//! level; a node's eight children are consecutive in the next level's list (x + 2y + 4z
//! order).

use std::sync::Arc;

use glam::DVec3;
use rayon::prelude::*;

use super::lattice::{at, lattice_point, offsets, Lattice};
use super::octree::{key, unkey, Grid};
use super::samples::Samples;

/// The largest distance an isosurface's mesh may lie from the surface at a point `p` of
/// the grid's frame: `absolute + per_distance · |p − eye|` (a pixel's footprint grows
/// with the distance from the camera).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Deviation {
    /// The bound everywhere.
    pub absolute: f64,
    /// The bound's growth per unit of distance from `eye`.
    pub per_distance: f64,
    /// Where the bound is smallest.
    pub eye: DVec3,
}

impl Deviation {
    /// A bound of `t` everywhere.
    pub fn absolute(t: f64) -> Deviation {
        Deviation { absolute: t, per_distance: 0.0, eye: DVec3::ZERO }
    }

    /// The bound at `p`.
    pub fn at(&self, p: DVec3) -> f64 {
        self.absolute + self.per_distance * (p - self.eye).length()
    }

    /// The bound as people read it: a distance, or a pixel's footprint.
    pub fn label(&self) -> String {
        if self.per_distance > 0.0 {
            format!("a pixel's footprint ({:.3e} per unit of distance)", self.per_distance)
        } else {
            crate::ir::dump_num(self.absolute)
        }
    }

    /// The smallest bound over the box `[lo, hi]`.
    pub fn over(&self, lo: DVec3, hi: DVec3) -> f64 {
        self.absolute + self.per_distance * (self.eye.clamp(lo, hi) - self.eye).length()
    }
}

/// How far cells are split.
#[derive(Clone, Debug)]
pub enum Plan {
    /// Every cell the surface may cross, down to the finest level.
    Uniform,
    /// As coarse as keeps the mesh within `deviation`, with no cell above `coarsest`
    /// levels and none larger than half a `part`'s size that meets its box.
    Within {
        /// The bound on the distance from the surface.
        deviation: Deviation,
        /// The coarsest level a cell with surface may stay at.
        coarsest: u32,
        /// Boxes of solid parts (lowest and highest corner), each seen by a grid point.
        parts: Vec<(DVec3, DVec3)>,
    },
}

/// The share of a cell's tolerance its tangent planes may miss its vertex by. The mesh
/// is measured afterwards, and what this test lets through is split then; over the
/// gyroid sheet of `benches/scenes/gyroid.scn`'s kind (`scnc export … --tolerance
/// 0.001`), 0.25, 0.5, 1, 2 and 4 made 2.78, 1.40, 1.14, 1.02 and 1.06 M triangles in
/// 47, 22, 18, 16 and 16 s: the looser tests leave more to the rounds of splitting,
/// which cost a whole contouring each, so one tolerance is where both are small.
const PLANES_WITHIN: f64 = 1.0;

/// What a node is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Slot {
    /// Not decided yet.
    Pending,
    /// Holds no surface.
    Empty,
    /// A cell the mesh is made on (its index among the leaves).
    Leaf(u32),
    /// Split: its children are the eight nodes from this index on in the next level, and
    /// whether a leaf lies below it.
    Inner(u32, bool),
}

/// Why the cells could not be made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TooMany {
    /// More than the budget's cells, with the number expected at the finest level.
    Cells(f64),
}

/// The octree of one isosurface.
pub struct Tree {
    /// The finest grid.
    pub grid: Grid,
    /// Nodes by depth (depth 0 is the root, at level `grid.levels`).
    slots: Vec<Vec<Slot>>,
    /// Their lowest corners in finest-grid coordinates.
    origins: Vec<Vec<[u32; 3]>>,
    /// Where a leaf's corner values are in `corner_values` ([`NONE`] until known).
    corner_at: Vec<Vec<u32>>,
    /// The values at leaves' eight corners (by corner number).
    corner_values: Vec<[f32; 8]>,
    /// Each leaf's depth and index.
    leaves: Vec<(u8, u32)>,
}

/// No entry.
const NONE: u32 = u32::MAX;

/// Nodes decided between two checks of the cell budget: it is overshot by at most this
/// many leaves before it is noticed.
const CHUNK: usize = 1 << 15;

/// What a pending node already knows of its field: nothing, its corners (a finest
/// cell), or its 3×3×3 lattice (handed down by its parent).
#[derive(Clone)]
enum Known {
    Nothing,
    Corners(Box<[f32; 8]>),
    Lattice(Box<[f32; 27]>),
}

/// A node to decide: where it is, the parts that may still force it to split, and what
/// it knows. Its parent found it not empty.
struct Todo {
    index: u32,
    parts: Option<Arc<[u32]>>,
    known: Known,
}

/// What was decided for a node: a leaf with its corner values, or split, with the parts
/// its children must heed and each child's fate (empty, or what it knows).
enum Decided {
    Leaf([f32; 8]),
    Split { parts: Option<Arc<[u32]>>, children: [Option<Known>; 8] },
}

const UNKNOWN: [f32; 8] = [f32::NAN; 8];

impl Tree {
    /// The cells of `samples`' field on `grid` under `plan`, at most `max_cells` leaves.
    pub fn build(grid: Grid, samples: &Samples, plan: &Plan, max_cells: usize) -> Result<Tree, TooMany> {
        let depths = grid.levels as usize + 1;
        let mut tree = Tree {
            grid,
            slots: vec![Vec::new(); depths],
            origins: vec![Vec::new(); depths],
            corner_at: vec![Vec::new(); depths],
            corner_values: Vec::new(),
            leaves: Vec::new(),
        };
        tree.slots[0].push(Slot::Pending);
        tree.origins[0].push([0; 3]);
        tree.corner_at[0].push(NONE);
        let all = match plan {
            Plan::Within { parts, .. } if !parts.is_empty() => Some((0..parts.len() as u32).collect()),
            Plan::Within { .. } | Plan::Uniform => None,
        };
        let mut todo: Vec<Vec<Todo>> = (0..depths).map(|_| Vec::new()).collect();
        if empty(samples, [0; 3], grid.levels) {
            tree.slots[0][0] = Slot::Empty;
        } else {
            todo[0].push(Todo { index: 0, parts: all, known: Known::Nothing });
        }
        tree.expand(todo, samples, plan, max_cells)?;
        Ok(tree)
    }

    /// Splits the leaves `which` (finest ones stay) and decides their children as the
    /// plan says.
    pub fn split(&mut self, which: &[u32], samples: &Samples, plan: &Plan, max_cells: usize) -> Result<(), TooMany> {
        let mut todo: Vec<Vec<Todo>> = (0..self.slots.len()).map(|_| Vec::new()).collect();
        let levels = self.grid.levels;
        for &leaf in which {
            let (depth, index) = self.leaves[leaf as usize];
            let depth = depth as usize;
            if depth + 1 >= self.slots.len() || !matches!(self.slots[depth][index as usize], Slot::Leaf(_)) {
                continue;
            }
            let origin = self.origins[depth][index as usize];
            let children: [Option<Known>; 8] = std::array::from_fn(|k| {
                let o = child_origin(origin, 1 << (levels - depth as u32 - 1), k);
                (!empty(samples, o, levels - depth as u32 - 1)).then_some(Known::Nothing)
            });
            self.push_children(depth, index, children, None, &mut todo[depth + 1]);
        }
        self.expand(todo, samples, plan, max_cells)
    }

    /// Replaces node `index` at `depth` by eight children, the empty ones decided, the
    /// finest ones leaves, and the others pending in `todo`; returns the leaves made.
    fn push_children(
        &mut self,
        depth: usize,
        index: u32,
        children: [Option<Known>; 8],
        parts: Option<Arc<[u32]>>,
        todo: &mut Vec<Todo>,
    ) -> usize {
        let first = self.slots[depth + 1].len() as u32;
        let origin = self.origins[depth][index as usize];
        let half = 1u32 << (self.grid.levels as usize - depth - 1);
        let finest = depth + 2 == self.slots.len();
        self.slots[depth][index as usize] = Slot::Inner(first, false);
        let mut leaves = 0;
        for (k, child) in children.into_iter().enumerate() {
            self.origins[depth + 1].push(child_origin(origin, half, k));
            let (slot, corners) = match child {
                None => (Slot::Empty, NONE),
                // A finest cell that is not empty is a leaf (numbered later).
                Some(known) if finest => {
                    leaves += 1;
                    let at = match known {
                        Known::Corners(c) => {
                            self.corner_values.push(*c);
                            self.corner_values.len() as u32 - 1
                        }
                        Known::Nothing | Known::Lattice(_) => NONE,
                    };
                    (Slot::Leaf(0), at)
                }
                Some(known) => {
                    todo.push(Todo { index: first + k as u32, parts: parts.clone(), known });
                    (Slot::Pending, NONE)
                }
            };
            self.slots[depth + 1].push(slot);
            self.corner_at[depth + 1].push(corners);
        }
        leaves
    }

    /// Decides the pending nodes level by level, then numbers the leaves and finds the
    /// corner values no lattice gave.
    fn expand(
        &mut self,
        mut todo: Vec<Vec<Todo>>,
        samples: &Samples,
        plan: &Plan,
        max_cells: usize,
    ) -> Result<(), TooMany> {
        let mut leaves = self.leaves.len();
        for depth in 0..self.slots.len() {
            let level = self.grid.levels - depth as u32;
            let now = std::mem::take(&mut todo[depth]);
            let mut next = Vec::new();
            let (total, before) = (now.len(), leaves);
            let mut done = 0;
            let mut rest = now.into_iter();
            loop {
                let chunk: Vec<Todo> = rest.by_ref().take(CHUNK).collect();
                if chunk.is_empty() {
                    break;
                }
                done += chunk.len();
                let origins = &self.origins[depth];
                let decided: Vec<Decided> =
                    chunk.par_iter().map(|t| decide(samples, plan, origins[t.index as usize], level, t)).collect();
                for (t, d) in chunk.into_iter().zip(decided) {
                    match d {
                        // Numbered below.
                        Decided::Leaf(corners) => {
                            leaves += 1;
                            let i = t.index as usize;
                            self.slots[depth][i] = Slot::Leaf(0);
                            if !corners[0].is_nan() {
                                self.corner_at[depth][i] = self.corner_values.len() as u32;
                                self.corner_values.push(corners);
                            }
                        }
                        Decided::Split { parts, children } => {
                            leaves += self.push_children(depth, t.index, children, parts, &mut next);
                        }
                    }
                }
                // Every pending node is not empty, so it ends in a leaf at least.
                if leaves + next.len() > max_cells {
                    // What this depth has made so far, for all of it, then each pending
                    // node's leaves: a surface's cells multiply by four a level.
                    let here = (leaves - before) as f64 + next.len() as f64 * 4f64.powi(level as i32 - 1);
                    return Err(TooMany::Cells(before as f64 + here * total as f64 / done as f64));
                }
            }
            if depth + 1 < self.slots.len() {
                todo[depth + 1].append(&mut next);
            }
        }
        self.number(samples);
        Ok(())
    }

    /// Numbers the leaves level by level (the same numbers for any thread count), marks
    /// the inner nodes with a leaf below, and looks up the corner values of leaves that
    /// have none yet.
    fn number(&mut self, samples: &Samples) {
        self.leaves.clear();
        for depth in 0..self.slots.len() {
            for (i, s) in self.slots[depth].iter_mut().enumerate() {
                if let Slot::Leaf(id) = s {
                    *id = self.leaves.len() as u32;
                    self.leaves.push((depth as u8, i as u32));
                }
            }
        }
        for depth in (0..self.slots.len().saturating_sub(1)).rev() {
            let (upper, lower) = self.slots.split_at_mut(depth + 1);
            for s in upper[depth].iter_mut() {
                if let Slot::Inner(first, any) = s {
                    *any = lower[0][*first as usize..*first as usize + 8]
                        .iter()
                        .any(|c| matches!(c, Slot::Leaf(_) | Slot::Inner(_, true)));
                }
            }
        }
        let levels = self.grid.levels;
        let missing: Vec<(u8, u32)> =
            self.leaves.iter().copied().filter(|&(d, i)| self.corner_at[d as usize][i as usize] == NONE).collect();
        // Their corners, each grid point evaluated once: sorted, then looked up.
        let corner = |&(d, i): &(u8, u32), n: usize| {
            let (o, size) = (self.origins[d as usize][i as usize], 1u32 << (levels - u32::from(d)));
            let off = super::cube::corner_offset(n);
            key([o[0] + size * off[0], o[1] + size * off[1], o[2] + size * off[2]].map(u64::from))
        };
        let mut keys: Vec<u64> = missing.par_iter().flat_map_iter(|l| (0..8).map(move |n| corner(l, n))).collect();
        keys.par_sort_unstable();
        keys.dedup();
        let values: Vec<f32> = keys.par_iter().map(|&k| samples.evaluate(unkey(k).map(|c| c as u32))).collect();
        let found: Vec<[f32; 8]> = missing
            .par_iter()
            .map(|l| {
                std::array::from_fn(|n| match keys.binary_search(&corner(l, n)) {
                    Ok(k) => values[k],
                    Err(_) => f32::INFINITY,
                })
            })
            .collect();
        for (&(d, i), c) in missing.iter().zip(found) {
            self.corner_at[d as usize][i as usize] = self.corner_values.len() as u32;
            self.corner_values.push(c);
        }
    }

    /// Makes the empty node at `depth`, `index` a leaf (a crossing its centre's bound
    /// ruled out, by rounding); call [`renumber`](Self::renumber) after the last.
    pub fn fill(&mut self, depth: usize, index: u32) {
        if self.slots[depth][index as usize] == Slot::Empty {
            self.slots[depth][index as usize] = Slot::Leaf(0);
            self.corner_at[depth][index as usize] = NONE;
        }
    }

    /// Numbers the leaves again after [`fill`](Self::fill).
    pub fn renumber(&mut self, samples: &Samples) {
        self.number(samples);
    }

    /// The node at `depth`, `index`.
    pub fn slot(&self, depth: usize, index: u32) -> Slot {
        self.slots[depth][index as usize]
    }

    /// The values at the corners of the leaf at `depth`, `index`.
    pub fn corner_values(&self, depth: usize, index: u32) -> [f32; 8] {
        self.corner_values[self.corner_at[depth][index as usize] as usize]
    }

    /// The number of leaves.
    pub fn leaf_count(&self) -> usize {
        self.leaves.len()
    }

    /// Leaf `id`'s lowest corner and level.
    pub fn leaf(&self, id: u32) -> ([u32; 3], u32) {
        let (depth, index) = self.leaves[id as usize];
        (self.origins[depth as usize][index as usize], self.grid.levels - u32::from(depth))
    }

    /// The node count (for the memory the tree takes).
    pub fn nodes(&self) -> usize {
        self.slots.iter().map(Vec::len).sum()
    }
}

/// The lowest corner of child `k` (x + 2y + 4z) of a node at `origin` whose children
/// are `half` finest cells wide.
pub fn child_origin(origin: [u32; 3], half: u32, k: usize) -> [u32; 3] {
    [origin[0] + half * (k as u32 & 1), origin[1] + half * ((k as u32 >> 1) & 1), origin[2] + half * (k as u32 >> 2)]
}

/// Whether the node at `origin` of `2^level` finest cells holds no surface: its centre's
/// `|f|` is above its half-diagonal (`value`, when known, is that `f`).
fn empty(samples: &Samples, origin: [u32; 3], level: u32) -> bool {
    is_empty(samples, origin, level, centre_value(samples, origin, level))
}

/// The value at the centre of the node at `origin` of `2^level` finest cells. No other
/// node's lattice holds it (its children's take it from their parent's), so it is not
/// kept.
fn centre_value(samples: &Samples, origin: [u32; 3], level: u32) -> f64 {
    if level == 0 {
        samples.field().at(samples.point(origin) + samples.cell() * 0.5)
    } else {
        let h = 1 << (level - 1);
        f64::from(samples.evaluate([origin[0] + h, origin[1] + h, origin[2] + h]))
    }
}

/// Whether a node whose centre has the value `value` holds no surface.
fn is_empty(samples: &Samples, origin: [u32; 3], level: u32, value: f64) -> bool {
    let size = samples.cell() * f64::from(1u32 << level);
    let centre = samples.point(origin) + size * 0.5;
    let half_diagonal = size * 0.5 * 3f64.sqrt();
    // f is evaluated in f32: a margin for its rounding at this distance from the origin,
    // so that no cube holding a crossing is dropped.
    let margin = 1e-3 * half_diagonal + 1e-5 * (centre.length() + half_diagonal);
    value.abs() > half_diagonal + margin
}

/// What a node at `origin` of `2^level` finest cells, not empty, becomes.
fn decide(samples: &Samples, plan: &Plan, origin: [u32; 3], level: u32, todo: &Todo) -> Decided {
    let corners_of = |l: &[f32; 27]| -> [f32; 8] {
        std::array::from_fn(|n| {
            let off = super::cube::corner_offset(n);
            l[at(2 * off[0] as usize, 2 * off[1] as usize, 2 * off[2] as usize)]
        })
    };
    if level == 0 {
        return Decided::Leaf(match &todo.known {
            Known::Corners(c) => **c,
            Known::Lattice(l) => corners_of(l),
            Known::Nothing => UNKNOWN,
        });
    }
    // Each child empty, or what it knows.
    let unknown_children = |samples: &Samples| -> [Option<Known>; 8] {
        std::array::from_fn(|k| {
            let o = child_origin(origin, 1 << (level - 1), k);
            (!empty(samples, o, level - 1)).then_some(Known::Nothing)
        })
    };
    let Plan::Within { deviation, coarsest, parts: boxes } = plan else {
        return Decided::Split { parts: None, children: unknown_children(samples) };
    };
    let size = samples.cell() * f64::from(1u32 << level);
    let lo = samples.point(origin);
    let hi = lo + size;
    // The parts whose box this cell meets and that are smaller than the cell: a cell no
    // larger than a part has lattice points at most half the part apart, so one lies
    // inside it, and the test below sees it. Until those and the coarsest level allow a
    // leaf, no lattice is read, unless the children will read theirs: then it is handed
    // down.
    let near: Vec<u32> = todo
        .parts
        .iter()
        .flat_map(|p| p.iter().copied())
        .filter(|&i| {
            let (a, b) = boxes[i as usize];
            a.cmple(hi).all() && b.cmpge(lo).all() && (b - a).min_element() < size
        })
        .collect();
    if !near.is_empty() || level > *coarsest {
        let children_tested = level - 1 <= *coarsest
            && near.iter().all(|&i| (boxes[i as usize].1 - boxes[i as usize].0).min_element() >= 0.5 * size);
        let children = if children_tested && level >= 2 {
            children_known(samples, origin, level, &known_lattice(samples, todo, origin, level))
        } else {
            unknown_children(samples)
        };
        let parts = (!near.is_empty()).then(|| near.into());
        return Decided::Split { parts, children };
    }
    let values = known_lattice(samples, todo, origin, level);
    let lattice = Lattice::new(origin, level, values);
    if lattice.simple(samples, deviation.over(lo, hi) * PLANES_WITHIN) {
        Decided::Leaf(corners_of(&values))
    } else {
        Decided::Split { parts: None, children: children_known(samples, origin, level, &values) }
    }
}

/// The 3×3×3 lattice of the node at `origin`, `level` ≥ 1: handed down by its parent,
/// or looked up.
fn known_lattice(samples: &Samples, todo: &Todo, origin: [u32; 3], level: u32) -> [f32; 27] {
    match &todo.known {
        Known::Lattice(l) => **l,
        Known::Nothing | Known::Corners(_) => lattice_values(samples, origin, level),
    }
}

/// The 3×3×3 lattice of the node at `origin`, `level` ≥ 1, looked up.
fn lattice_values(samples: &Samples, origin: [u32; 3], level: u32) -> [f32; 27] {
    let half = 1u32 << (level - 1);
    std::array::from_fn(|n| samples.value(lattice_point(origin, half, offsets(n))))
}

/// Each child of the node at `origin`, `level` (≥ 1): empty, or what it knows from its
/// parent's `lattice` — its corners when it is a finest cell, else its own lattice (the
/// parent's 5×5×5, of which the parent's lattice is every other point), whose centre
/// tells whether it is empty.
fn children_known(samples: &Samples, origin: [u32; 3], level: u32, lattice: &[f32; 27]) -> [Option<Known>; 8] {
    if level == 1 {
        return std::array::from_fn(|k| {
            let c = super::cube::corner_offset(k);
            let o = child_origin(origin, 1, k);
            (!empty(samples, o, 0)).then(|| {
                Known::Corners(Box::new(std::array::from_fn(|n| {
                    let off = super::cube::corner_offset(n);
                    lattice[at((c[0] + off[0]) as usize, (c[1] + off[1]) as usize, (c[2] + off[2]) as usize)]
                })))
            })
        });
    }
    let quarter = 1u32 << (level - 2);
    let fine: [f32; 125] = std::array::from_fn(|n| {
        let (i, j, k) = (n % 5, n / 5 % 5, n / 25);
        let c = [origin[0] + quarter * i as u32, origin[1] + quarter * j as u32, origin[2] + quarter * k as u32];
        if i % 2 == 0 && j % 2 == 0 && k % 2 == 0 {
            lattice[at(i / 2, j / 2, k / 2)]
        } else if [i, j, k].iter().all(|&x| (1..4).contains(&x)) {
            // Inside the parent: no other cell's lattice holds it.
            samples.evaluate(c)
        } else {
            samples.value(c)
        }
    });
    std::array::from_fn(|k| {
        let c = super::cube::corner_offset(k).map(|x| 2 * x as usize);
        let child: [f32; 27] = std::array::from_fn(|n| {
            let [i, j, l] = offsets(n);
            fine[(c[0] + i) + 5 * (c[1] + j) + 25 * (c[2] + l)]
        });
        let o = child_origin(origin, 2 * quarter, k);
        (!is_empty(samples, o, level - 1, f64::from(child[13]))).then(|| Known::Lattice(Box::new(child)))
    })
}
