//! A cube's corners, edges and faces, numbered once for the mesher: corner `n` is at
//! offsets `(n & 1, n >> 1 & 1, n >> 2)`; the edge along `axis` whose lower end is at
//! offsets `b1` along the next axis and `b2` along the one after is `4·axis + b1 + 2·b2`.

/// The offsets of corner `n` (x + 2y + 4z) from a cube's lowest corner.
pub const fn corner_offset(n: usize) -> [u32; 3] {
    [(n & 1) as u32, ((n >> 1) & 1) as u32, (n >> 2) as u32]
}

/// The corner at offsets `off` from a cube's lowest corner.
pub const fn corner_index(off: [u32; 3]) -> usize {
    (off[0] + 2 * off[1] + 4 * off[2]) as usize
}

/// Where local edge `e` starts (offsets of its lower end) and its axis.
pub const fn edge_start(e: usize) -> ([u32; 3], usize) {
    let axis = e / 4;
    let mut off = [0u32; 3];
    off[(axis + 1) % 3] = (e & 1) as u32;
    off[(axis + 2) % 3] = ((e >> 1) & 1) as u32;
    (off, axis)
}

/// The local number of the edge along `axis` whose lower end is at offsets `off`.
pub const fn edge_id(axis: usize, off: [u32; 3]) -> usize {
    4 * axis + (off[(axis + 1) % 3] + 2 * off[(axis + 2) % 3]) as usize
}

/// A face of a cube: its corners in cyclic order A, B, C, D (around the face), and the
/// local edges AB, BC, CD, DA.
pub struct Face {
    /// The corners A, B, C, D.
    pub corners: [usize; 4],
    /// The edges AB, BC, CD, DA.
    pub edges: [usize; 4],
}

/// The six faces of a cube: face `n` is across axis `n / 2`, on its high side when `n`
/// is odd; A is its lowest corner, B the next along the axis after, D along the one after.
pub const FACES: [Face; 6] = faces();

const fn faces() -> [Face; 6] {
    let mut out = [const { Face { corners: [0; 4], edges: [0; 4] } }; 6];
    let mut n = 0;
    while n < 6 {
        let (axis, side) = (n / 2, (n % 2) as u32);
        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
        let uw = [(0, 0), (1, 0), (1, 1), (0, 1)];
        let mut offs = [[0u32; 3]; 4];
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

/// Whether the bilinear interpolant of a face's corner values `A, B, C, D` (in cyclic
/// order, A and C of one sign, B and D of the other) joins A and C through the face's
/// middle: its saddle has their sign (the asymptotic decider). A flat saddle joins the
/// outside corners.
pub fn joins_a_and_c([a, b, c, d]: [f64; 4]) -> bool {
    let denominator = a + c - b - d;
    if denominator != 0.0 {
        let saddle = (a * c - b * d) / denominator;
        (saddle < 0.0) == (a < 0.0)
    } else {
        a >= 0.0
    }
}

/// How many sheets a cube with corner values `v` holds when each face pairs its two
/// crossed edges; `None` when a face has all four crossed (ambiguous).
pub fn corner_sheets(v: &[f32; 8]) -> Option<usize> {
    let crossed = |e: usize| {
        let (off, axis) = edge_start(e);
        let a = corner_index(off);
        (v[a] < 0.0) != (v[a + (1 << axis)] < 0.0)
    };
    let mut parent: [usize; 12] = std::array::from_fn(|e| e);
    for face in &FACES {
        let on: Vec<usize> = face.edges.iter().copied().filter(|&e| crossed(e)).collect();
        match on.len() {
            0 => {}
            2 => {
                let (a, b) = (root(&mut parent, on[0]), root(&mut parent, on[1]));
                parent[a] = b;
            }
            _ => return None,
        }
    }
    let mut roots: Vec<usize> = (0..12).filter(|&e| crossed(e)).map(|e| root(&mut parent, e)).collect();
    roots.sort_unstable();
    roots.dedup();
    Some(roots.len())
}

/// The root of `e` in a union-find over `parent`, halving the path on the way.
pub fn root(parent: &mut [usize], mut e: usize) -> usize {
    while parent[e] != e {
        parent[e] = parent[parent[e]];
        e = parent[e];
    }
    e
}

/// Joins the sets of `a` and `b`.
pub fn join(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (root(parent, a), root(parent, b));
    parent[ra] = rb;
}

#[cfg(test)]
mod tests {
    use super::*;

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

    /// One corner in: one sheet; two opposite corners: two; a face's diagonal: ambiguous.
    #[test]
    fn sheets_of_corner_configurations() {
        let with = |inside: &[usize]| std::array::from_fn(|n| if inside.contains(&n) { -1.0 } else { 1.0 });
        assert_eq!(corner_sheets(&with(&[])), Some(0));
        assert_eq!(corner_sheets(&with(&[0])), Some(1));
        assert_eq!(corner_sheets(&with(&[0, 1, 2, 3])), Some(1));
        assert_eq!(corner_sheets(&with(&[0, 7])), Some(2));
        assert_eq!(corner_sheets(&with(&[0, 3])), None);
    }
}
