//! Dual contouring on an octree's crossed edges ([`super::dual`]): every leaf gets one
//! vertex per sheet of surface through it, every crossed edge a polygon joining the
//! vertices of the leaves around it.
//!
//! **Closed and manifold by construction.** Where two leaves meet, the face between them
//! is the smaller one's face, its sides split wherever a smaller leaf touches them. The
//! crossed edges on its border pair up into segments by one rule that reads only what both
//! leaves see alike (which edges are crossed, the corner values), so both pair them the
//! same way: two crossings pair with each other; four, one on each side, by the asymptotic
//! decider of the face's corners; any other number by cutting off each run of inside
//! points along the border. A leaf's sheets are the cycles its segments form. This is
//! marching cubes' surface on the subdivision (a disk per cycle, glued along segments,
//! with a disk of polygons around every crossing), and the mesh is its dual: a vertex per
//! disk, a polygon per crossing, an edge per segment, so every edge lies on two polygons
//! and every vertex has one fan — except where two sheets share two segments of one face
//! (a part thinner than the cell there), whose mesh edge would then lie on four triangles.
//! There each segment gets a vertex of its own on the face, which makes the two edges
//! distinct. A quad is split along the diagonal through its smallest leaf (whose
//! diagonal neighbour touches it along that edge only, so no other polygon has that
//! diagonal); a polygon with face vertices is fanned about its crossing.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU16, AtomicU32, Ordering};

use foldhash::fast::FixedState;
use glam::DVec3;
use rayon::prelude::*;

use super::cube::{join, joins_a_and_c, root};
use super::dual::MinEdge;
use super::qef::Qef;
use super::samples::{Crossing, Samples};
use super::tree::Tree;
use crate::geom::TriMesh;

/// Leaves contoured by one task.
const LEAVES_A_TASK: usize = 2048;

/// The contoured mesh and what the refinement and the passes after it need.
pub struct Contoured {
    /// The triangles, closed and wound outward.
    pub mesh: TriMesh,
    /// Each vertex's mass point (the mean of its crossings), where an unfolding moves it.
    pub mass: Vec<DVec3>,
    /// The leaf each vertex was made in.
    pub leaf_of: Vec<u32>,
}

/// One leaf's crossings on its border, by the neighbour whose face they lie on: what
/// each leaf around each crossed edge contributes twice (its neighbours before and after
/// it in the winding).
struct Incidences {
    /// Where each leaf's entries start (one more than the leaves).
    start: Vec<usize>,
    /// (neighbour, edge), sorted within a leaf.
    entries: Vec<(u32, u32)>,
}

/// Segments of one face: their two edges, and the sheet of the leaf asking.
type Segments = Vec<(u32, u32, u16)>;

/// Faces where two segments of a leaf lie on one sheet of it: the leaf, its neighbour,
/// and the segments.
type Twice = (u32, u32, Segments);

/// What one task of leaves contributes: their vertices with mass points, each leaf's
/// count of them, and their faces crossed twice.
type LeafChunk = (Vec<[DVec3; 2]>, Vec<u32>, Vec<Twice>);

/// A face crossed twice from both sides: its leaves (lower number first) and the
/// segments (two edges each) that get a vertex of their own.
type Doubled = (u32, u32, Vec<(u32, u32)>);

/// Contours `edges` (crossed, in a fixed order) of `tree`.
///
/// Long because it is the one sequence of the contouring: crossings, each leaf's faces
/// and sheets, the vertices, the faces crossed twice, and the polygons, each pass over
/// arrays sized once.
pub fn contour(tree: &Tree, samples: &Samples, edges: &[MinEdge]) -> Contoured {
    let crossings: Vec<Crossing> =
        edges.par_iter().map(|e| samples.crossing(e.start, e.axis as usize, u32::from(e.level), e.values)).collect();
    let incidences = incidences(tree.leaf_count(), edges);
    // Each leaf's sheet for each position around each edge.
    let sheet_at: Vec<AtomicU16> = (0..4 * edges.len()).map(|_| AtomicU16::new(u16::MAX)).collect();
    let chunks: Vec<LeafChunk> = (0..tree.leaf_count())
        .into_par_iter()
        .step_by(LEAVES_A_TASK)
        .map(|first| {
            let mut vertices = Vec::new();
            let mut counts = Vec::with_capacity(LEAVES_A_TASK);
            let mut twice = Vec::new();
            for leaf in first..(first + LEAVES_A_TASK).min(tree.leaf_count()) {
                let group = &incidences.entries[incidences.start[leaf]..incidences.start[leaf + 1]];
                let before = vertices.len();
                if !group.is_empty() {
                    sheets(tree, samples, leaf as u32, group, edges, &crossings, &sheet_at, &mut vertices, &mut twice);
                }
                counts.push((vertices.len() - before) as u32);
            }
            (vertices, counts, twice)
        })
        .collect();

    // Vertices, leaf by leaf.
    let mut mesh = TriMesh::default();
    let mut mass = Vec::new();
    let mut leaf_of = Vec::new();
    let mut first = Vec::with_capacity(tree.leaf_count());
    let mut twice = Vec::new();
    for (k, (vertices, counts, t)) in chunks.into_iter().enumerate() {
        let mut at = mesh.positions.len() as u32;
        for (leaf, c) in ((k * LEAVES_A_TASK) as u32..).zip(counts) {
            first.push(at);
            at += c;
            leaf_of.extend(std::iter::repeat_n(leaf, c as usize));
        }
        for v in vertices {
            mesh.positions.push(v[0]);
            mass.push(v[1]);
        }
        twice.extend(t);
    }
    let vertex = |i: usize, pos: usize| -> u32 {
        let leaf = edges[i].around[pos];
        first[leaf as usize] + u32::from(sheet_at[4 * i + pos].load(Ordering::Relaxed))
    };

    // Faces two sheets cross twice: a vertex on the face for each of their segments.
    let doubled_faces = doubled(twice, edges, &vertex);
    let mut split: HashMap<(u32, u32, u32), u32, FixedState> = HashMap::default();
    for (a, b, segments) in &doubled_faces {
        for &(x, y) in segments {
            let (p, q) = (crossings[x as usize].point, crossings[y as usize].point);
            let at = mesh.positions.len() as u32;
            mesh.positions.push((p + q) * 0.5);
            mass.push((p + q) * 0.5);
            leaf_of.push(*a);
            split.insert((x, *a, *b), at);
            split.insert((y, *a, *b), at);
        }
    }

    // One polygon per crossed edge: a triangle, a quad split in two, or (with face
    // vertices) a fan about a new vertex at the crossing, made after the others.
    let fans = AtomicU32::new(0);
    let polygons: Vec<([[u32; 3]; 2], u8)> = edges
        .par_iter()
        .enumerate()
        .map(|(i, e)| {
            let ring = ring(&e.around, e.inside);
            let corners: Vec<u32> = ring.iter().map(|&(_, pos)| vertex(i, pos)).collect();
            let with_face = !split.is_empty()
                && (0..ring.len()).any(|j| {
                    let (a, b) = (ring[j].0, ring[(j + 1) % ring.len()].0);
                    split.contains_key(&(i as u32, a.min(b), a.max(b)))
                });
            if with_face {
                fans.fetch_add(1, Ordering::Relaxed);
                return ([[0; 3]; 2], 0);
            }
            if corners.len() == 3 {
                return ([[corners[0], corners[1], corners[2]], [0; 3]], 1);
            }
            // The diagonal through the smallest leaf (0–2 when both have one).
            let levels: Vec<u32> = ring.iter().map(|&(leaf, _)| tree.leaf(leaf).1).collect();
            let smallest = *levels.iter().min().unwrap_or(&0);
            let c = &corners;
            if levels[0] == smallest || levels[2] == smallest {
                ([[c[0], c[1], c[2]], [c[0], c[2], c[3]]], 2)
            } else {
                ([[c[1], c[2], c[3]], [c[1], c[3], c[0]]], 2)
            }
        })
        .collect();
    mesh.triangles.reserve(polygons.iter().map(|p| p.1 as usize).sum::<usize>() + 8 * fans.into_inner() as usize);
    for (i, (tris, n)) in polygons.into_iter().enumerate() {
        if n > 0 {
            mesh.triangles.extend_from_slice(&tris[..n as usize]);
            continue;
        }
        let ring = ring(&edges[i].around, edges[i].inside);
        let mut corners = Vec::with_capacity(8);
        for j in 0..ring.len() {
            let (leaf, pos) = ring[j];
            corners.push(vertex(i, pos));
            let next = ring[(j + 1) % ring.len()].0;
            if let Some(&f) = split.get(&(i as u32, leaf.min(next), leaf.max(next))) {
                corners.push(f);
            }
        }
        let centre = mesh.positions.len() as u32;
        let p = crossings[i].point;
        mesh.positions.push(p);
        mass.push(p);
        leaf_of.push(leaf_of[corners[0] as usize]);
        for k in 0..corners.len() {
            mesh.triangles.push([centre, corners[k], corners[(k + 1) % corners.len()]]);
        }
    }
    Contoured { mesh, mass, leaf_of }
}

/// Every leaf's incidences, grouped by a counting sort on the leaf (numbers are dense).
fn incidences(leaves: usize, edges: &[MinEdge]) -> Incidences {
    let count: Vec<AtomicU32> = (0..leaves).map(|_| AtomicU32::new(0)).collect();
    edges.par_iter().for_each(|e| {
        for (leaf, _) in ring(&e.around, true) {
            count[leaf as usize].fetch_add(2, Ordering::Relaxed);
        }
    });
    let mut start = Vec::with_capacity(leaves + 1);
    let mut sum = 0usize;
    for c in &count {
        start.push(sum);
        sum += c.load(Ordering::Relaxed) as usize;
    }
    start.push(sum);
    let cursor: Vec<AtomicU32> = (0..leaves).map(|_| AtomicU32::new(0)).collect();
    let entries: Vec<AtomicU32> = (0..2 * sum).map(|_| AtomicU32::new(0)).collect();
    edges.par_iter().enumerate().for_each(|(i, e)| {
        let ring = ring(&e.around, true);
        let n = ring.len();
        for j in 0..n {
            let (leaf, pred, succ) = (ring[j].0, ring[(j + n - 1) % n].0, ring[(j + 1) % n].0);
            let at = start[leaf as usize] + cursor[leaf as usize].fetch_add(2, Ordering::Relaxed) as usize;
            for (k, neighbour) in [pred, succ].into_iter().enumerate() {
                entries[2 * (at + k)].store(neighbour, Ordering::Relaxed);
                entries[2 * (at + k) + 1].store(i as u32, Ordering::Relaxed);
            }
        }
    });
    let mut entries: Vec<(u32, u32)> =
        entries.chunks(2).map(|p| (p[0].load(Ordering::Relaxed), p[1].load(Ordering::Relaxed))).collect();
    // In a fixed order within each leaf, whichever thread filled it.
    let mut groups: Vec<&mut [(u32, u32)]> = Vec::with_capacity(leaves);
    let mut rest = entries.as_mut_slice();
    for l in 0..leaves {
        let (group, tail) = rest.split_at_mut(start[l + 1] - start[l]);
        groups.push(group);
        rest = tail;
    }
    groups.par_iter_mut().for_each(|g| g.sort_unstable());
    Incidences { start, entries }
}

/// The distinct leaves around an edge in winding order (reversed when its lower end is
/// outside, so that every polygon is wound outward), each with its first position.
fn ring(around: &[u32; 4], inside: bool) -> Vec<(u32, usize)> {
    let mut ring: Vec<(u32, usize)> = Vec::with_capacity(4);
    for (k, &leaf) in around.iter().enumerate() {
        if ring.last().map(|&(l, _)| l) != Some(leaf) {
            ring.push((leaf, k));
        }
    }
    if ring.len() > 1 && ring[0].0 == ring[ring.len() - 1].0 {
        ring.pop();
    }
    if !inside {
        ring.reverse();
    }
    ring
}

/// The faces whose two sides both put two segments on one sheet: the leaves (lower
/// number first) and those segments' edges.
fn doubled(twice: Vec<Twice>, edges: &[MinEdge], vertex: &dyn Fn(usize, usize) -> u32) -> Vec<Doubled> {
    let mut halves: HashMap<(u32, u32), Segments, FixedState> = HashMap::default();
    for (leaf, n, segs) in twice {
        halves.insert((leaf, n), segs);
    }
    // The vertex of leaf `b`'s sheet through edge `x`.
    let of = |b: u32, x: u32| {
        let pos = edges[x as usize].around.iter().position(|&l| l == b).expect("a leaf around its edge");
        vertex(x as usize, pos)
    };
    let mut out = Vec::new();
    for (&(a, b), segs) in &halves {
        if a > b || !halves.contains_key(&(b, a)) {
            continue;
        }
        // Segments on one sheet of `a` whose other ends lie on one sheet of `b` too.
        let mut chosen: Vec<(u32, u32)> = Vec::new();
        for (k, &(x, y, s)) in segs.iter().enumerate() {
            for &(x2, y2, s2) in &segs[k + 1..] {
                if s == s2 && of(b, x) == of(b, x2) {
                    for seg in [(x, y), (x2, y2)] {
                        if !chosen.contains(&seg) {
                            chosen.push(seg);
                        }
                    }
                }
            }
        }
        if !chosen.is_empty() {
            chosen.sort_unstable();
            out.push((a, b, chosen));
        }
    }
    out.sort_unstable_by_key(|(a, b, _)| (*a, *b));
    out
}

/// One leaf's sheets from its faces' crossings (`group`: its incidences, sorted by
/// neighbour then edge): each sheet's vertex and mass point pushed to `vertices`, the
/// sheet of each of its positions around its edges stored in `sheet_at`, and its faces
/// that one sheet crosses twice pushed to `twice`.
#[allow(clippy::too_many_arguments, reason = "one leaf's share of the contouring's arrays")]
fn sheets(
    tree: &Tree,
    samples: &Samples,
    leaf: u32,
    group: &[(u32, u32)],
    edges: &[MinEdge],
    crossings: &[Crossing],
    sheet_at: &[AtomicU16],
    vertices: &mut Vec<[DVec3; 2]>,
    twice: &mut Vec<Twice>,
) {
    let mut own: Vec<u32> = group.iter().map(|&(_, e)| e).collect();
    own.sort_unstable();
    own.dedup();
    let local = |e: u32| own.binary_search(&e).expect("an edge of this leaf");
    let mut parent: Vec<usize> = (0..own.len()).collect();
    let mut faces: Vec<(u32, Vec<(u32, u32)>)> = Vec::new();
    let mut k = 0;
    while k < group.len() {
        let n = group[k].0;
        let end = k + group[k..].iter().take_while(|&&(m, _)| m == n).count();
        let on: Vec<u32> = group[k..end].iter().map(|&(_, e)| e).collect();
        let segs = pair(tree, samples, leaf, n, &on, edges);
        for &(x, y) in &segs {
            join(&mut parent, local(x), local(y));
        }
        faces.push((n, segs));
        k = end;
    }
    // Sheets numbered in the order of their lowest edge.
    let mut sheet_of_root = vec![u16::MAX; own.len()];
    let mut count = 0u16;
    let mut sheet = vec![0u16; own.len()];
    for (j, s) in sheet.iter_mut().enumerate() {
        let r = root(&mut parent, j);
        if sheet_of_root[r] == u16::MAX {
            sheet_of_root[r] = count;
            count += 1;
        }
        *s = sheet_of_root[r];
    }
    let mut qefs = vec![Qef::default(); count as usize];
    for (j, &e) in own.iter().enumerate() {
        let x = crossings[e as usize];
        qefs[sheet[j] as usize].add(x.point, x.normal);
        for (pos, &l) in edges[e as usize].around.iter().enumerate() {
            if l == leaf {
                sheet_at[4 * e as usize + pos].store(sheet[j], Ordering::Relaxed);
            }
        }
    }
    let (origin, level) = tree.leaf(leaf);
    let lo = samples.point(origin);
    let hi = lo + samples.cell() * f64::from(1u32 << level);
    vertices.extend(qefs.iter().map(|q| [q.solve().clamp(lo, hi), q.mass_point()]));
    for (n, segs) in faces {
        if segs.len() < 2 {
            continue;
        }
        let tagged: Vec<(u32, u32, u16)> = segs.iter().map(|&(x, y)| (x, y, sheet[local(x)])).collect();
        if tagged.iter().enumerate().any(|(k, a)| tagged[k + 1..].iter().any(|b| b.2 == a.2)) {
            twice.push((leaf, n, tagged));
        }
    }
}

/// The segments the crossed edges `on` on the border of the face between `leaf` and
/// `neighbour` form (the same for both, whichever asks).
fn pair(tree: &Tree, samples: &Samples, leaf: u32, neighbour: u32, on: &[u32], edges: &[MinEdge]) -> Vec<(u32, u32)> {
    if on.len() == 2 {
        return vec![(on[0], on[1])];
    }
    if on.len() < 2 {
        return Vec::new();
    }
    // The face: the smaller leaf's side towards the other.
    let (a, b) = (tree.leaf(leaf), tree.leaf(neighbour));
    let ((so, sl), (oo, ol)) = if b.1 < a.1 || (b.1 == a.1 && neighbour < leaf) { (b, a) } else { (a, b) };
    let (ss, os) = (1u32 << sl, 1u32 << ol);
    let axis = (0..3)
        .find(|&k| so[k] + ss == oo[k] || oo[k] + os == so[k])
        .expect("face-adjacent leaves touch across one axis");
    let plane = if so[axis] + ss == oo[axis] { so[axis] + ss } else { so[axis] };
    let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
    let corner = |du: u32, dw: u32| {
        let mut c = [0u32; 3];
        c[axis] = plane;
        c[u] = so[u] + du * ss;
        c[w] = so[w] + dw * ss;
        samples.value(c)
    };
    // Each crossing's place along the border, in half finest cells from corner A.
    let s2 = 2 * u64::from(ss);
    let place = |e: u32| {
        let m = &edges[e as usize];
        let mid = |k: usize| {
            let along = if k == m.axis as usize { 1u64 << m.level } else { 0 };
            (2 * u64::from(m.start[k]) + along).saturating_sub(2 * u64::from(so[k]))
        };
        let (du, dw) = (mid(u), mid(w));
        if dw == 0 {
            du
        } else if du == s2 {
            s2 + dw
        } else if dw == s2 {
            3 * s2 - du
        } else {
            4 * s2 - dw
        }
    };
    let mut sorted: Vec<(u64, u32)> = on.iter().map(|&e| (place(e), e)).collect();
    sorted.sort_unstable();
    let n = sorted.len();
    let at_a = super::samples::inside(corner(0, 0));
    let one_a_side = n == 4 && (0..4).all(|k| sorted[k].0 / s2 == k as u64);
    // The sign whose runs along the border are cut off.
    let cut_inside = if one_a_side {
        let v = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)].map(f64::from);
        // Joined A and C (through the middle) cut off B's sign.
        if joins_a_and_c(v) {
            !at_a
        } else {
            at_a
        }
    } else {
        true
    };
    // Run 0 (around corner A) has A's sign; the runs alternate after each crossing.
    let first = usize::from(cut_inside != at_a);
    (0..n / 2)
        .map(|k| {
            let (x, y) = ((first + 2 * k + n - 1) % n, (first + 2 * k) % n);
            (sorted[x].1, sorted[y].1)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::dual::POSITIONS;

    #[test]
    fn rings_drop_repeated_leaves() {
        let leaves = |r: Vec<(u32, usize)>| r.iter().map(|r| r.0).collect::<Vec<_>>();
        assert_eq!(leaves(ring(&[1, 2, 3, 4], true)), [1, 2, 3, 4]);
        assert_eq!(leaves(ring(&[1, 1, 3, 4], true)), [1, 3, 4]);
        assert_eq!(leaves(ring(&[1, 2, 3, 1], true)), [1, 2, 3]);
        assert_eq!(leaves(ring(&[1, 2, 3, 1], false)), [3, 2, 1]);
    }

    #[test]
    fn positions_wind_about_the_axis() {
        // Consecutive positions differ on exactly one axis: they share a face.
        for k in 0..4 {
            let (a, b) = (POSITIONS[k], POSITIONS[(k + 1) % 4]);
            assert_eq!((a.0 != b.0) as u32 + (a.1 != b.1) as u32, 1);
        }
    }
}
