//! Isosurface extraction by dual contouring on the cells an octree keeps
//! ([`octree`](super::octree)): every finest cell the surface crosses gets one vertex per
//! sheet of surface inside it, placed by a quadric error function
//! (`mesh::qef`) on the tangent planes at its edge crossings, so that a box keeps
//! its edges and corners; every grid edge the surface crosses gets a quad joining the
//! vertices of the four cells around it.
//!
//! **Closed and manifold.** A cell's sheets are the cycles its crossed edges form when
//! each face pairs the crossed edges on it (two crossings pair up; four, on a face whose
//! diagonal corners agree, pair by the asymptotic decider of the face's bilinear
//! interpolant). A face's pairing depends on its four corner values only, which both
//! cells sharing it read from one table, so both see the same pairs. Then a mesh edge
//! between two sheets across a face lies on exactly the two quads of that face's paired
//! grid edges, and the quads around a sheet's vertex form one fan: every edge has two
//! triangles and every vertex one disk — except where one sheet crosses a face twice
//! from both sides (a part thinner than a cell), which `split_doubled_faces` mends
//! where it can and counts where it cannot. A crossed edge's four cells all hold a crossing,
//! so the octree keeps them; should rounding drop one, it is added and the step repeated.
//! Quads are wound outward (from the inside end of their grid edge).

use glam::{DVec3, Vec3A};
use rayon::prelude::*;

use super::octree::{key, unkey, Grid};
use super::qef::Qef;
use crate::geom::TriMesh;

/// Bytes a finest cell takes at the peak of extraction (its key, its share of corner
/// values and crossings, its sheets and their triangles): a memory budget allows its
/// bytes over this many cells.
pub const CELL_BYTES: u64 = 200;

/// Most finest cells one isosurface may refine when no budget says otherwise (about 1 GB
/// of working memory).
pub const MAX_CELLS: usize = 4_000_000;

/// Why an isosurface could not be made.
#[derive(Clone, Debug, PartialEq)]
pub enum IsoError {
    /// The surface would refine more cells than [`MAX_CELLS`].
    TooManyCells {
        /// Cells it is expected to refine.
        cells: f64,
        /// The smallest cell size expected to stay within the limit.
        min_cell: f64,
    },
    /// No sign change was found: the shape is thinner than a cell everywhere (or empty).
    NoSurface,
}

/// A grid edge by the key of its lower end and its axis.
type EdgeKey = (u64, u8);

/// A crossed grid edge: where the surface crosses it and the surface's normal there.
#[derive(Clone, Copy)]
struct Crossing {
    point: DVec3,
    normal: DVec3,
}

/// A cell's sheets: which sheet each of its twelve edges belongs to ([`NO_SHEET`] when
/// the edge is not crossed), the index of its first sheet's vertex, and the faces one
/// sheet crosses twice (bit `n` for face `n`).
#[derive(Clone, Copy)]
struct Sheets {
    of_edge: [u8; 12],
    first: u32,
    doubled: u8,
}

const NO_SHEET: u8 = u8::MAX;

/// An extracted isosurface.
#[derive(Debug)]
pub struct Surface {
    /// The triangles, closed and wound outward.
    pub mesh: TriMesh,
    /// Edges left on four triangles: where a part thinner than a cell crosses a cell
    /// face twice from both sides and the sheets could not be split (0 otherwise).
    pub pinched: usize,
    /// Pairs of triangles that still cross each other after [`super::unfold`].
    pub crossing_pairs: usize,
}

/// Extracts the zero set of `f` on `grid`, refining at most [`MAX_CELLS`] cells.
pub fn extract(f: &(dyn Fn(Vec3A) -> f32 + Sync), grid: &Grid) -> Result<Surface, IsoError> {
    extract_within(f, grid, MAX_CELLS)
}

/// Extracts the zero set of `f` on `grid`, refining at most `max_cells` cells.
pub fn extract_within(f: &(dyn Fn(Vec3A) -> f32 + Sync), grid: &Grid, max_cells: usize) -> Result<Surface, IsoError> {
    let too_many = |cells: f64| IsoError::TooManyCells {
        cells,
        // A surface's cell count goes with the inverse square of the cell.
        min_cell: grid.cell * (cells / max_cells as f64).sqrt(),
    };
    let mut cells = grid.surface_cells(f, max_cells).map_err(too_many)?;
    // Ask for the working memory's address space before using it: a cap (ulimit -v) or a
    // strict overcommit policy refuses here, as a too-fine grid, not by aborting midway.
    if !crate::source::system_gives((cells.len() as u64).saturating_mul(CELL_BYTES)) {
        return Err(too_many(max_cells as f64 * 2.0));
    }
    let (corners, values, edges, rings) = loop {
        let corners = corner_values(f, grid, &cells);
        // Each cell's eight corners, looked up once (the table is large: lookups miss
        // the cache, and every later step reads a cell's corners).
        let values: Vec<[f32; 8]> = cells.par_iter().map(|&c| cell_values(&corners, c)).collect();
        let edges = crossed_edges(&cells, &values);
        // The cells around each crossed edge, by index: found once, for the check here
        // and for the quads.
        let rings: Vec<[Option<usize>; 4]> =
            edges.par_iter().map(|&e| around(e).map(|c| cells.binary_search(&c?).ok())).collect();
        let mut missing: Vec<u64> = edges
            .par_iter()
            .zip(&rings)
            .flat_map_iter(|(&e, ring)| around(e).into_iter().zip(ring).filter_map(|(c, i)| i.is_none().then_some(c?)))
            .collect();
        if missing.is_empty() {
            break (corners, values, edges, rings);
        }
        missing.par_sort_unstable();
        missing.dedup();
        cells.extend(missing);
        cells.par_sort_unstable();
        if cells.len() > max_cells {
            return Err(too_many(cells.len() as f64));
        }
    };
    if edges.is_empty() {
        return Err(IsoError::NoSurface);
    }
    let crossings: Vec<Crossing> = edges.par_iter().map(|&e| crossing(f, grid, &corners, e)).collect();

    // One vertex per sheet of every cell, in cell order.
    let mut per_cell: Vec<(Sheets, Vec<[DVec3; 2]>)> =
        cells.par_iter().zip(&values).map(|(&c, v)| sheets::<4>(grid, c, v, &edges, &crossings, 0)).collect();
    // Where a part is thinner than a cell, one sheet can cross an ambiguous face twice,
    // in both cells of the face: the two vertices would then share four quads' edge.
    let pinched = split_doubled_faces(grid, &cells, &values, &edges, &crossings, &mut per_cell);
    let mut mesh = TriMesh::default();
    let mut mass = Vec::new();
    let mut sheets_of = Vec::with_capacity(per_cell.len());
    for (mut s, vertices) in per_cell {
        s.first = mesh.positions.len() as u32;
        mesh.positions.extend(vertices.iter().map(|v| v[0]));
        mass.extend(vertices.iter().map(|v| v[1]));
        sheets_of.push(s);
    }
    let quads: Vec<[[u32; 3]; 2]> = edges
        .par_iter()
        .zip(&rings)
        .filter_map(|(&(corner, axis), ring)| {
            let mut v = [0u32; 4];
            for (n, i) in ring.iter().enumerate() {
                let s = &sheets_of[(*i)?];
                let sheet = s.of_edge[local_edge(axis as usize, corner, cells[(*i)?])];
                v[n] = s.first + u32::from((sheet != NO_SHEET).then_some(sheet)?);
            }
            let [a, b, c, d] = v;
            Some(if inside(corner_value(&corners, corner)) { [[a, b, c], [a, c, d]] } else { [[a, c, b], [a, d, c]] })
        })
        .collect();
    mesh.triangles = quads.into_iter().flatten().collect();
    let crossing_pairs = super::unfold::unfold(&mut mesh, &mass, grid.cell);
    super::pinch::split(&mut mesh, grid.cell);
    Ok(Surface { mesh, pinched, crossing_pairs })
}

/// Splits sheets that cross a face twice from both sides. Leaving the face's pairing
/// out of one cell cuts its sheet into arcs, each joining one end of each of the face's
/// segments. Where the arcs join ends that are neighbours around the face (as the
/// face's other resolution would) every quad edge at the face is shared by two quads
/// again, consistently wound, provided the cell across keeps its one sheet there: so a
/// cell is either split (at one or more faces, each checked) or a partner, never both.
/// A cell split at two faces usually leaves four arcs each joining the two faces, which
/// no check accepts, so along a thin tube of doubled cells about every third face stays
/// as it was (closed, its edge on four triangles). On the random CSG trees of the
/// mesher's tests this removes 86–100 % of the four-triangle edges (eight shapes, at a
/// sixtieth of their bounds). Returns the number of faces still crossed twice from
/// both sides, each an edge on four triangles.
fn split_doubled_faces(
    grid: &Grid,
    cells: &[u64],
    values: &[[f32; 8]],
    edges: &[EdgeKey],
    crossings: &[Crossing],
    per_cell: &mut [(Sheets, Vec<[DVec3; 2]>)],
) -> usize {
    let doubled = |per_cell: &[(Sheets, Vec<[DVec3; 2]>)], i: usize, n: u8| per_cell[i].0.doubled & (1 << n) != 0;
    // Each face doubled on both sides, once, from its lower cell.
    let faces: Vec<(usize, u8, usize)> = (0..cells.len())
        .into_par_iter()
        .filter(|&i| per_cell[i].0.doubled != 0)
        .flat_map_iter(|i| {
            let per_cell = &*per_cell;
            (0..6u8).filter_map(move |n| {
                let j = neighbour(cells[i], n).and_then(|k| cells.binary_search(&k).ok())?;
                (i < j && doubled(per_cell, i, n) && doubled(per_cell, j, n ^ 1)).then_some((i, n, j))
            })
        })
        .collect();
    // The cell's sheets with the faces of `mask` left out, if every one comes apart
    // into two arcs joining neighbouring ends.
    let split = |i: usize, mask: u8| {
        let s = sheets::<12>(grid, cells[i], &values[i], edges, crossings, mask);
        let apart = (0..6).filter(|n| mask & (1 << n) != 0).all(|n| {
            let o = FACES[n].edges.map(|e| s.0.of_edge[e]);
            o[0] != o[2] && ((o[0] == o[1] && o[2] == o[3]) || (o[0] == o[3] && o[1] == o[2]))
        });
        apart.then_some(s)
    };
    // Per cell: absent when not involved, `None` for a partner, the faces it is split at.
    let mut state: std::collections::HashMap<usize, Option<u8>> = std::collections::HashMap::new();
    for &(i, n, j) in &faces {
        for (c, face, partner) in [(i, n, j), (j, n ^ 1, i)] {
            let now = match state.get(&c) {
                None => 0,
                Some(Some(faces)) => *faces,
                Some(None) => continue,
            };
            if matches!(state.get(&partner), Some(Some(_))) {
                continue;
            }
            if let Some(s) = split(c, now | 1 << face) {
                per_cell[c] = s;
                state.insert(c, Some(now | 1 << face));
                state.insert(partner, None);
                break;
            }
        }
    }
    // A face stays pinched while it is still doubled on both sides (a split elsewhere
    // in a cell can also part its segments).
    faces.iter().filter(|&&(i, n, j)| doubled(per_cell, i, n) && doubled(per_cell, j, n ^ 1)).count()
}

/// The values of `f` at every corner of `cells`, sorted by key.
fn corner_values(f: &(dyn Fn(Vec3A) -> f32 + Sync), grid: &Grid, cells: &[u64]) -> Vec<(u64, f32)> {
    let mut keys: Vec<u64> = cells
        .par_iter()
        .flat_map_iter(|&c| {
            let c = unkey(c);
            (0..8).map(move |n| shifted(c, corner_offset(n)))
        })
        .collect();
    keys.par_sort_unstable();
    keys.dedup();
    keys.into_par_iter().map(|k| (k, f(grid.point(unkey(k)).as_vec3a()))).collect()
}

/// The value at a grid point of the table.
fn corner_value(corners: &[(u64, f32)], at: u64) -> f32 {
    match corners.binary_search_by_key(&at, |&(k, _)| k) {
        Ok(i) => corners[i].1,
        // Every corner of every cell is in the table.
        Err(_) => f32::INFINITY,
    }
}

/// The values at a cell's corners, by corner index.
fn cell_values(corners: &[(u64, f32)], cell: u64) -> [f32; 8] {
    let c = unkey(cell);
    std::array::from_fn(|n| corner_value(corners, shifted(c, corner_offset(n))))
}

/// The key of the grid point at offsets `off` from `c`.
fn shifted(c: [u64; 3], off: [u64; 3]) -> u64 {
    key([c[0] + off[0], c[1] + off[1], c[2] + off[2]])
}

/// The cell across face `n` (axis `n / 2`, the high side when `n` is odd) of `cell`,
/// unless that is below the grid.
fn neighbour(cell: u64, n: u8) -> Option<u64> {
    let mut c = unkey(cell);
    let axis = (n / 2) as usize;
    c[axis] = if n % 2 == 1 { c[axis] + 1 } else { c[axis].checked_sub(1)? };
    Some(key(c))
}

/// The offsets of corner `n` (x + 2y + 4z) from a cell's lowest corner.
const fn corner_offset(n: usize) -> [u64; 3] {
    [(n & 1) as u64, ((n >> 1) & 1) as u64, (n >> 2) as u64]
}

/// Whether local edge `e` of a cell with corner values `v` is crossed.
fn crossed(v: &[f32; 8], e: usize) -> bool {
    let (off, axis) = edge_start(e);
    let start = corner_index(off);
    inside(v[start]) != inside(v[start + (1 << axis)])
}

/// Whether a value is inside the shape. NaN counts as outside.
pub(super) fn inside(v: f32) -> bool {
    v < 0.0
}

/// The corner index (x + 2y + 4z) at offsets `off` from a cell's lowest corner.
const fn corner_index(off: [u64; 3]) -> usize {
    (off[0] + 2 * off[1] + 4 * off[2]) as usize
}

/// A cell's local edge numbering: the edge along `axis` whose lower end is at offsets
/// `b1` along the next axis and `b2` along the one after is `4·axis + b1 + 2·b2`.
const fn edge_start(e: usize) -> ([u64; 3], usize) {
    let axis = e / 4;
    let mut off = [0u64; 3];
    off[(axis + 1) % 3] = (e & 1) as u64;
    off[(axis + 2) % 3] = ((e >> 1) & 1) as u64;
    (off, axis)
}

/// The local number of the grid edge along `axis` from grid point `corner`, in `cell`.
fn local_edge(axis: usize, corner: u64, cell: u64) -> usize {
    let (p, c) = (unkey(corner), unkey(cell));
    edge_id(axis, [p[0] - c[0], p[1] - c[1], p[2] - c[2]])
}

/// The four cells around a grid edge, in the order that winds its quad about the
/// edge's axis (`None` beyond the grid's low boundary).
fn around((corner, axis): EdgeKey) -> [Option<u64>; 4] {
    let p = unkey(corner);
    let (u, w) = ((axis as usize + 1) % 3, (axis as usize + 2) % 3);
    [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(du, dw)| {
        let mut c = p;
        c[u] = (p[u] + du).checked_sub(1)?;
        c[w] = (p[w] + dw).checked_sub(1)?;
        Some(key(c))
    })
}

/// Every grid edge of `cells` whose ends lie on opposite sides, sorted.
fn crossed_edges(cells: &[u64], values: &[[f32; 8]]) -> Vec<EdgeKey> {
    let mut edges: Vec<EdgeKey> = cells
        .par_iter()
        .zip(values)
        .flat_map_iter(|(&cell, v)| {
            let c = unkey(cell);
            (0..12).filter(|&e| crossed(v, e)).map(move |e| {
                let (off, axis) = edge_start(e);
                (shifted(c, off), axis as u8)
            })
        })
        .collect();
    edges.par_sort_unstable();
    edges.dedup();
    edges
}

/// Where the surface crosses a grid edge, by false position on `f` (Illinois variant,
/// from the linear estimate until `f` is within a ten-thousandth of a cell of zero:
/// along a cell's edge a distance field is nearly linear and that takes a step or two,
/// more where the edge passes a kink of a CSG field), and its normal there from four
/// samples on a tetrahedron (the crossings are most of an isosurface's evaluations of
/// a large CSG tree).
fn crossing(
    f: &(dyn Fn(Vec3A) -> f32 + Sync),
    grid: &Grid,
    corners: &[(u64, f32)],
    (corner, axis): EdgeKey,
) -> Crossing {
    let start = unkey(corner);
    let mut end = start;
    end[axis as usize] += 1;
    let (p0, p1) = (grid.point(start), grid.point(end));
    let at = |t: f64| f((p0 + (p1 - p0) * t).as_vec3a()) as f64;
    let (mut a, mut fa) = (0.0, corner_value(corners, corner) as f64);
    let (mut b, mut fb) = (1.0, corner_value(corners, key(end)) as f64);
    let mut side = 0;
    for _ in 0..12 {
        let t = (a - fa * (b - a) / (fb - fa)).clamp(a, b);
        let ft = at(t);
        if ft.abs() < 1e-4 * grid.cell || !ft.is_finite() {
            a = t;
            b = t;
            break;
        }
        if (ft < 0.0) == (fa < 0.0) {
            (a, fa) = (t, ft);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            (b, fb) = (t, ft);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    let point = p0 + (p1 - p0) * ((a + b) * 0.5);
    let h = grid.cell * 0.01;
    let g: DVec3 = [DVec3::new(1.0, -1.0, -1.0), DVec3::new(-1.0, -1.0, 1.0), DVec3::new(-1.0, 1.0, -1.0), DVec3::ONE]
        .into_iter()
        .map(|k| k * f((point + k * h).as_vec3a()) as f64)
        .sum();
    // A flat spot of f (no gradient at this step): the edge's own direction, outward.
    let along = (p1 - p0).normalize() * if fa < 0.0 { 1.0 } else { -1.0 };
    let normal = g.try_normalize().unwrap_or(along);
    Crossing { point, normal }
}

/// A face of a cell: its corners in cyclic order A, B, C, D (around the face), and the
/// local edges AB, BC, CD, DA.
struct Face {
    corners: [usize; 4],
    edges: [usize; 4],
}

/// The six faces of a cell.
const FACES: [Face; 6] = faces();

const fn faces() -> [Face; 6] {
    let mut out = [const { Face { corners: [0; 4], edges: [0; 4] } }; 6];
    let mut n = 0;
    while n < 6 {
        let (axis, side) = (n / 2, (n % 2) as u64);
        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
        // Corners at (u, w) = (0,0), (1,0), (1,1), (0,1) on this face.
        let uw = [(0, 0), (1, 0), (1, 1), (0, 1)];
        let mut offs = [[0u64; 3]; 4];
        let mut corners = [0; 4];
        let mut m = 0;
        while m < 4 {
            offs[m][axis] = side;
            offs[m][u] = uw[m].0;
            offs[m][w] = uw[m].1;
            corners[m] = corner_index(offs[m]);
            m += 1;
        }
        // AB runs along u from A, BC along w from B, CD along u from D, DA along w from A.
        let edges = [edge_id(u, offs[0]), edge_id(w, offs[1]), edge_id(u, offs[3]), edge_id(w, offs[0])];
        out[n] = Face { corners, edges };
        n += 1;
    }
    out
}

/// The local number of the edge along `axis` whose lower end is at offsets `off`.
const fn edge_id(axis: usize, off: [u64; 3]) -> usize {
    4 * axis + (off[(axis + 1) % 3] + 2 * off[(axis + 2) % 3]) as usize
}

/// A cell's sheets and their vertices: the cycles its crossed edges form under each
/// face's pairing, each placed by the QEF of its crossings and kept inside the cell.
/// The faces in `skip` join nothing, which cuts a cycle crossing one twice into two
/// arcs; `N` bounds the sheets (four cycles of three or more of the twelve edges when
/// nothing is skipped, at most twelve pieces otherwise).
///
/// Long because it traces a cell's cycles and places their vertices over arrays kept on the
/// stack for the cell; split, they would be passed around or allocated per cell.
fn sheets<const N: usize>(
    grid: &Grid,
    cell: u64,
    v: &[f32; 8],
    edges: &[EdgeKey],
    crossings: &[Crossing],
    skip: u8,
) -> (Sheets, Vec<[DVec3; 2]>) {
    let c = unkey(cell);
    let crossed: [bool; 12] = std::array::from_fn(|e| crossed(v, e));
    // Union-find over the twelve edges, joined by each face's pairs.
    let mut parent: [usize; 12] = std::array::from_fn(|e| e);
    fn root(parent: &mut [usize; 12], mut e: usize) -> usize {
        while parent[e] != e {
            parent[e] = parent[parent[e]];
            e = parent[e];
        }
        e
    }
    for (n, face) in FACES.iter().enumerate() {
        if skip & (1 << n) != 0 {
            continue;
        }
        let mut on = [0; 4];
        let mut count = 0;
        for m in (0..4).filter(|&m| crossed[face.edges[m]]) {
            on[count] = m;
            count += 1;
        }
        let pairs: [(usize, usize); 2] = match count {
            2 => [(on[0], on[1]); 2],
            4 => {
                let [a, b, cc, d] = face.corners.map(|k| v[k] as f64);
                // The bilinear interpolant's saddle: A and C (same sign) connect through
                // the face's middle when it has their sign. A flat saddle counts as
                // separating the inside corners.
                let denominator = a + cc - b - d;
                let connected = if denominator != 0.0 {
                    let saddle = (a * cc - b * d) / denominator;
                    (saddle < 0.0) == (a < 0.0)
                } else {
                    a >= 0.0
                };
                // Connected A–C cut off B (between AB and BC) and D (CD, DA).
                if connected {
                    [(0, 1), (2, 3)]
                } else {
                    [(1, 2), (3, 0)]
                }
            }
            _ => continue,
        };
        for (x, y) in pairs {
            let (rx, ry) = (root(&mut parent, face.edges[x]), root(&mut parent, face.edges[y]));
            parent[rx] = ry;
        }
    }
    // A face whose four crossed edges all end up in one sheet: its two segments are
    // joined through the rest of the cell.
    let doubled = FACES.iter().enumerate().fold(0u8, |mask, (n, face)| {
        let four = face.edges.iter().all(|&e| crossed[e]);
        let one = four && root(&mut parent, face.edges[0]) == root(&mut parent, face.edges[2]);
        mask | (u8::from(one && skip & (1 << n) == 0) << n)
    });
    // Sheets numbered in the order of their lowest edge; one QEF each.
    let mut of_edge = [NO_SHEET; 12];
    let mut qefs = [Qef::default(); N];
    let mut count = 0;
    let mut sheet_of_root = [NO_SHEET; 12];
    for e in (0..12).filter(|&e| crossed[e]) {
        let r = root(&mut parent, e);
        if sheet_of_root[r] == NO_SHEET {
            sheet_of_root[r] = count as u8;
            count += 1;
        }
        of_edge[e] = sheet_of_root[r];
        let (off, axis) = edge_start(e);
        if let Ok(i) = edges.binary_search(&(shifted(c, off), axis as u8)) {
            let x = crossings[i];
            qefs[of_edge[e] as usize].add(x.point, x.normal);
        }
    }
    let lo = grid.point(c);
    let hi = lo + grid.cell;
    // Each vertex with its mass point, where an unfolding moves it (`unfold`).
    let vertices = qefs[..count].iter().map(|q| [q.solve().clamp(lo, hi), q.mass_point()]).collect();
    (Sheets { of_edge, first: 0, doubled }, vertices)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(r: f64, cell: f64) -> Grid {
        Grid::new(DVec3::splat(-r), DVec3::splat(r), cell).unwrap()
    }

    /// The face table: each face's edges join its corners in cycle.
    #[test]
    fn face_edges_join_their_corners() {
        for face in &FACES {
            for m in 0..4 {
                let (off, axis) = edge_start(face.edges[m]);
                let a = corner_index(off);
                let ends = [a, a + (1 << axis)];
                let (x, y) = (face.corners[m], face.corners[(m + 1) % 4]);
                assert!(ends.contains(&x) && ends.contains(&y), "edge {} does not join {x} and {y}", face.edges[m]);
            }
        }
    }

    #[test]
    fn sphere_isosurface_is_closed_outward_and_accurate() {
        let f = |p: Vec3A| p.length() - 1.0;
        let m = extract(&f, &grid(1.0, 0.05)).expect("surface").mesh;
        assert_eq!(m.open_edges(), (0, 0), "open edges");
        let v = m.signed_volume();
        assert!((v - 4.0 / 3.0 * std::f64::consts::PI).abs() < 0.01, "volume {v}");
        for p in &m.positions {
            assert!((p.length() - 1.0).abs() < 0.005, "vertex off the surface: {p}");
        }
    }

    /// A box keeps its corners and edges: every vertex lies on the box's surface, and
    /// the eight corners are vertices.
    #[test]
    fn box_keeps_edges_and_corners() {
        let half = DVec3::new(0.6, 0.4, 0.5);
        let f = move |p: Vec3A| {
            let q = p.as_dvec3().abs() - half;
            (q.max(DVec3::ZERO).length() + q.max_element().min(0.0)) as f32
        };
        let m = extract(&f, &Grid::new(-half, half, 0.07).unwrap()).expect("surface").mesh;
        assert_eq!(m.open_edges(), (0, 0), "open edges");
        for p in &m.positions {
            let q = p.abs() - half;
            let d = q.max(DVec3::ZERO).length() + q.max_element().min(0.0);
            assert!(d.abs() < 1e-4, "vertex {p} is {d} off the box");
        }
        for n in 0..8 {
            let corner = half * DVec3::new([-1.0, 1.0][n & 1], [-1.0, 1.0][(n >> 1) & 1], [-1.0, 1.0][n >> 2]);
            let nearest = m.positions.iter().map(|p| (*p - corner).length()).fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-4, "corner {corner} is {nearest} from the nearest vertex");
        }
        let v = m.signed_volume();
        assert!((v - 8.0 * half.x * half.y * half.z).abs() < 1e-3, "volume {v}");
    }

    /// Two spheres touching at a point, and a thin neck: the ambiguous faces there still
    /// give a closed, manifold mesh.
    #[test]
    fn ambiguous_faces_stay_manifold() {
        for gap in [0.0, 0.01, -0.01, 0.031] {
            let f = move |p: Vec3A| {
                let a = (p - Vec3A::new(-0.5 - gap, 0.0, 0.0)).length() - 0.5;
                let b = (p - Vec3A::new(0.5, 0.0, 0.0)).length() - 0.5;
                a.min(b)
            };
            let g = Grid::new(DVec3::new(-1.1, -0.6, -0.6), DVec3::new(1.1, 0.6, 0.6), 0.0625).unwrap();
            let m = extract(&f, &g).expect("surface").mesh;
            assert_eq!(m.open_edges(), (0, 0), "gap {gap}: open or doubled edges");
        }
    }

    /// Connected components of a mesh, by shared vertices.
    fn components(m: &TriMesh) -> usize {
        let mut parent: Vec<usize> = (0..m.positions.len()).collect();
        fn root(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for t in &m.triangles {
            for k in 1..3 {
                let (a, b) = (root(&mut parent, t[0] as usize), root(&mut parent, t[k] as usize));
                parent[a] = b;
            }
        }
        let used: std::collections::BTreeSet<usize> =
            m.triangles.iter().flatten().map(|&v| root(&mut parent, v as usize)).collect();
        used.len()
    }

    /// Many small disjoint parts (a 5×5×5 lattice of spheres 2.5 cells across, spread
    /// over a box 80 cells wide) each come out as their own closed piece.
    #[test]
    fn many_small_parts_are_all_kept() {
        let centre = |i: usize| DVec3::new((i % 5) as f64, ((i / 5) % 5) as f64, (i / 25) as f64) * 0.4 - 0.8;
        let f = move |p: Vec3A| {
            let p = p.as_dvec3();
            (0..125).map(|i| (p - centre(i)).length() - 0.025).fold(f64::INFINITY, f64::min) as f32
        };
        let m = extract(&f, &Grid::new(DVec3::splat(-0.83), DVec3::splat(0.83), 0.02).unwrap()).expect("surface").mesh;
        assert_eq!(m.open_edges(), (0, 0), "open or doubled edges");
        assert_eq!(components(&m), 125, "every sphere is its own piece");
        assert!(m.signed_volume() > 0.0, "wound outward");
    }

    #[test]
    fn limits_are_reported() {
        let f = |p: Vec3A| p.length() - 1.0;
        assert!(matches!(extract(&f, &grid(1.0, 2e-4)), Err(IsoError::TooManyCells { .. })));
        let thin = |p: Vec3A| p.length() - 1e-4;
        assert_eq!(extract(&thin, &grid(1.0, 0.3)).err(), Some(IsoError::NoSurface));
    }
}
