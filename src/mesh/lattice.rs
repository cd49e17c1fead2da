//! A cell's 3×3×3 lattice of values (its children's corners) and the two tests that let
//! [`super::tree`] keep the cell a leaf under a tolerance: its surface is one disk its
//! own corners already show (Ju et al. 2002's safety conditions), and the tangent planes
//! at its children's crossings pass within a bound of the vertex their quadric places.

use glam::DVec3;

use super::cube::{corner_sheets, edge_start, join, root};
use super::qef::Qef;
use super::samples::Samples;

/// A cell's 3×3×3 lattice: its corners, its edges' and faces' midpoints and its centre,
/// the corners of its eight children.
pub(super) struct Lattice {
    origin: [u32; 3],
    half: u32,
    level: u32,
    /// Whether each lattice point is inside, at `i + 3j + 9k`.
    inside: [bool; 27],
    /// Its values, likewise.
    values: [f32; 27],
}

/// The lattice index of offsets `(i, j, k)` in half-cells.
pub(super) const fn at(i: usize, j: usize, k: usize) -> usize {
    i + 3 * j + 9 * k
}

/// The finest-grid coordinates of lattice point `p` (offsets in half-cells) of the cell
/// at `origin` whose half-cell is `half` finest cells.
pub(super) fn lattice_point(origin: [u32; 3], half: u32, p: [usize; 3]) -> [u32; 3] {
    std::array::from_fn(|a| origin[a] + half * p[a] as u32)
}

/// The offsets `(i, j, k)` of lattice index `n` ([`at`]'s inverse).
pub(super) const fn offsets(n: usize) -> [usize; 3] {
    [n % 3, n / 3 % 3, n / 9]
}

/// A fine edge of the lattice: along `axis`, from lattice point `start`.
#[derive(Clone, Copy)]
struct FineEdge {
    start: [usize; 3],
    axis: usize,
}

impl Lattice {
    /// The lattice of the cell at `origin`, `level` ≥ 1, from its values.
    pub(super) fn new(origin: [u32; 3], level: u32, values: [f32; 27]) -> Lattice {
        Lattice { origin, half: 1 << (level - 1), level, inside: values.map(super::samples::inside), values }
    }

    fn point_inside(&self, p: [usize; 3]) -> bool {
        self.inside[at(p[0], p[1], p[2])]
    }

    /// Whether the fine edge is crossed.
    fn crossed(&self, e: FineEdge) -> bool {
        let mut end = e.start;
        end[e.axis] += 1;
        self.point_inside(e.start) != self.point_inside(end)
    }

    /// Whether a sheet may pass between the lattice's points though none of them sees it
    /// (a field's plate or shell thinner than half the cell, which no CSG part names).
    /// Along a fine edge, the field falls from both ends towards a minimum between them
    /// where a sheet lies; the tangent lines at the two ends meet at about that minimum's
    /// value, and below zero they say the edge crosses a sheet twice. Scale-free, so a
    /// field whose bound is loose reads the same; a surface beside the cell, or on its
    /// lattice (a box's face on a grid plane), slopes one way along every edge.
    fn may_hide_a_sheet(&self, samples: &Samples) -> bool {
        let step = samples.cell() * f64::from(self.half);
        // Every point is on one side (the caller found no crossing): measured from it.
        let side = if self.inside[0] { -1.0 } else { 1.0 };
        let gradients: [DVec3; 27] = std::array::from_fn(|n| {
            let p = samples.point(lattice_point(self.origin, self.half, offsets(n)));
            (samples.field().surf)(p.as_vec3a()).g.as_dvec3() * side
        });
        (0..27).any(|n| {
            let start = offsets(n);
            (0..3).filter(|&axis| start[axis] < 2).any(|axis| {
                let mut end = start;
                end[axis] += 1;
                let m = at(end[0], end[1], end[2]);
                let (f0, f1) = (f64::from(self.values[n]) * side, f64::from(self.values[m]) * side);
                let (a, b) = (gradients[n][axis], gradients[m][axis]);
                if !(a < 0.0 && b > 0.0) {
                    return false;
                }
                // f0 + a·t = f1 + b·(t − step)
                let t = (f0 - f1 + b * step) / (b - a);
                t > 0.0 && t < step && f0 + a * t < 0.0
            })
        })
    }

    /// Whether the cell may be a leaf: its surface one disk its corners show, its tangent
    /// planes within `planes` of its vertex. Long because it is the one sequence of
    /// checks over the lattice's arrays, kept on the stack.
    pub(super) fn simple(&self, samples: &Samples, planes: f64) -> bool {
        // Each edge of the cell crossed at most once: the midpoint's sign is one of the ends'.
        for axis in 0..3 {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            for (a, b) in [(0, 0), (2, 0), (0, 2), (2, 2)] {
                let p = |s: usize| {
                    let mut c = [0; 3];
                    c[axis] = s;
                    c[u] = a;
                    c[w] = b;
                    self.point_inside(c)
                };
                if p(0) == p(2) && p(1) != p(0) {
                    return false;
                }
            }
        }
        // The 54 fine edges, numbered as they come; a crossed one's union-find slot.
        let mut edges: Vec<FineEdge> = Vec::with_capacity(54);
        let mut index = [[usize::MAX; 27]; 3];
        for (axis, of_axis) in index.iter_mut().enumerate() {
            for (n, slot) in of_axis.iter_mut().enumerate() {
                let start = offsets(n);
                if start[axis] == 2 {
                    continue;
                }
                let e = FineEdge { start, axis };
                if self.crossed(e) {
                    *slot = edges.len();
                    edges.push(e);
                }
            }
        }
        if edges.is_empty() {
            // No sign change on the lattice: nothing to contour here, unless a sheet
            // thinner than the lattice's step passes between its points.
            return !self.may_hide_a_sheet(samples);
        }
        let edge_of = |start: [usize; 3], axis: usize| index[axis][at(start[0], start[1], start[2])];
        let mut parent: Vec<usize> = (0..edges.len()).collect();
        let mut segments = 0usize;
        // Each child's own union-find, to count its sheets.
        let mut child_parent: [[usize; 12]; 8] = [std::array::from_fn(|e| e); 8];
        // The 36 fine faces: perpendicular to `axis` at lattice plane `p`, quadrant (a, b).
        for axis in 0..3 {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            for p in 0..3 {
                for b in 0..2 {
                    for a in 0..2 {
                        let corner = |du: usize, dw: usize| {
                            let mut c = [0; 3];
                            c[axis] = p;
                            c[u] = a + du;
                            c[w] = b + dw;
                            c
                        };
                        // A, B, C, D around the face; the sides AB (along u), BC (w), CD (u
                        // from D), DA (w from A).
                        let sides = [(corner(0, 0), u), (corner(1, 0), w), (corner(0, 1), u), (corner(0, 0), w)];
                        let crossed: Vec<usize> = (0..4)
                            .filter(|&s| self.crossed(FineEdge { start: sides[s].0, axis: sides[s].1 }))
                            .collect();
                        match crossed.len() {
                            0 => continue,
                            2 => {}
                            // An ambiguous fine face: not a simple cell.
                            _ => return false,
                        }
                        let (x, y) = (
                            edge_of(sides[crossed[0]].0, sides[crossed[0]].1),
                            edge_of(sides[crossed[1]].0, sides[crossed[1]].1),
                        );
                        join(&mut parent, x, y);
                        segments += 1;
                        // The children this face belongs to: the one below it along `axis`
                        // and the one above, where they lie inside the cell.
                        for side in [p.checked_sub(1), (p < 2).then_some(p)].into_iter().flatten() {
                            let mut c = [0; 3];
                            c[axis] = side;
                            c[u] = a;
                            c[w] = b;
                            let child = c[0] + 2 * c[1] + 4 * c[2];
                            let local = |s: usize| child_edge(sides[s].0, sides[s].1, c);
                            let cp = &mut child_parent[child];
                            join(cp, local(crossed[0]), local(crossed[1]));
                        }
                    }
                }
            }
        }
        // Every child holds at most one sheet.
        let mut sheets_in_children = 0;
        for (child, cp) in child_parent.iter_mut().enumerate() {
            let c = [child & 1, (child >> 1) & 1, child >> 2];
            let mut roots = Vec::new();
            for e in 0..12 {
                let (off, axis) = edge_start(e);
                let start = [c[0] + off[0] as usize, c[1] + off[1] as usize, c[2] + off[2] as usize];
                if self.crossed(FineEdge { start, axis }) {
                    let r = root(cp, e);
                    if !roots.contains(&r) {
                        roots.push(r);
                    }
                }
            }
            if roots.len() > 1 {
                return false;
            }
            sheets_in_children += roots.len();
        }
        // One connected piece, a disk: V − E + F = 1.
        let first = root(&mut parent, 0);
        if (1..edges.len()).any(|e| root(&mut parent, e) != first) {
            return false;
        }
        if edges.len() as i64 - segments as i64 + sheets_in_children as i64 != 1 {
            return false;
        }
        // The cell's own corners show one sheet, on no ambiguous face.
        if !self.one_coarse_sheet() {
            return false;
        }
        // The children's tangent planes meet near one point inside the cell.
        let mut qef = Qef::default();
        let crossings: Vec<_> = edges
            .iter()
            .map(|e| {
                let start = lattice_point(self.origin, self.half, e.start);
                let mut end = e.start;
                end[e.axis] += 1;
                let ends =
                    [self.values[at(e.start[0], e.start[1], e.start[2])], self.values[at(end[0], end[1], end[2])]];
                samples.crossing(start, e.axis, self.level - 1, ends)
            })
            .collect();
        for x in &crossings {
            qef.add(x.point, x.normal);
        }
        let v = qef.solve();
        let lo = samples.point(self.origin);
        let size = samples.cell() * f64::from(2 * self.half);
        let slack = 0.01 * size;
        if (v - lo).cmplt(DVec3::splat(-slack)).any() || (v - lo).cmpgt(DVec3::splat(size + slack)).any() {
            return false;
        }
        crossings.iter().all(|x| x.normal.dot(v - x.point).abs() <= planes)
    }

    /// Whether the cell's eight corners alone show exactly one sheet, and no face of the
    /// cell has all four of its edges crossed.
    fn one_coarse_sheet(&self) -> bool {
        let corner = |n: usize| self.values[at(2 * (n & 1), 2 * ((n >> 1) & 1), 2 * (n >> 2))];
        let v: [f32; 8] = std::array::from_fn(corner);
        corner_sheets(&v) == Some(1)
    }
}

/// The number of a child's local edge (as `isosurface::edge_start` numbers them) for the
/// fine edge from lattice point `start` along `axis`, in the child at lattice offsets `c`.
fn child_edge(start: [usize; 3], axis: usize, c: [usize; 3]) -> usize {
    let off = [start[0] - c[0], start[1] - c[1], start[2] - c[2]];
    4 * axis + off[(axis + 1) % 3] + 2 * off[(axis + 2) % 3]
}
