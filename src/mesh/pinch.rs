//! Pinched vertices out of an isosurface. Where a part is thinner than a cell, a sheet's
//! vertex can be the corner of two fans of triangles that meet only there (a gyroid
//! sheet meshed at cell 0.099 had 12 such vertices in 34,560 triangles, every edge still
//! on two triangles): a non-manifold vertex, which slicers and validators reject or
//! repair. Each fan after the first gets a vertex of its own, and every copy moves a
//! hundredth of a cell towards its own fan, so the fans stay apart when the file's f32
//! corners are welded again.

use glam::DVec3;

use crate::geom::TriMesh;

/// How far (in cells) each copy of a pinched vertex moves towards its fan.
const NUDGE: f64 = 0.01;

/// Splits every vertex of `mesh` whose triangles form more than one fan; returns how many
/// were split.
pub fn split(mesh: &mut TriMesh, cell: f64) -> usize {
    let pinched = pinched(mesh);
    for (v, fans) in &pinched {
        let p = mesh.positions[*v as usize];
        for (k, members) in fans.iter().enumerate() {
            let centre = members
                .iter()
                .map(|&t| mesh.triangles[t as usize].iter().map(|&w| mesh.positions[w as usize]).sum::<DVec3>() / 3.0)
                .sum::<DVec3>()
                / members.len() as f64;
            let moved = p + (centre - p).normalize_or_zero() * NUDGE * cell;
            let copy = if k == 0 {
                *v
            } else {
                mesh.positions.push(moved);
                (mesh.positions.len() - 1) as u32
            };
            mesh.positions[copy as usize] = moved;
            for &t in members {
                for w in &mut mesh.triangles[t as usize] {
                    if w == v {
                        *w = copy;
                    }
                }
            }
        }
    }
    pinched.len()
}

/// The vertices of `mesh` whose triangles form more than one fan (triangles joined
/// through the edges they share at the vertex), each with its fans' triangles.
pub fn pinched(mesh: &TriMesh) -> Vec<(u32, Vec<Vec<u32>>)> {
    // Each vertex's triangles, in one array: `around[start[v]..start[v + 1]]`.
    let n = mesh.positions.len();
    let mut start = vec![0usize; n + 1];
    for t in &mesh.triangles {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut around = vec![0u32; start[n]];
    for (i, t) in mesh.triangles.iter().enumerate() {
        for &v in t {
            around[fill[v as usize]] = i as u32;
            fill[v as usize] += 1;
        }
    }
    fn root(fan: &mut [usize], mut a: usize) -> usize {
        while fan[a] != a {
            fan[a] = fan[fan[a]];
            a = fan[a];
        }
        a
    }
    let mut out = Vec::new();
    let mut fan: Vec<usize> = Vec::new();
    for v in 0..n as u32 {
        let tris = &around[start[v as usize]..start[v as usize + 1]];
        // Union-find over the vertex's triangles, joined where two share an edge at it.
        fan.clear();
        fan.extend(0..tris.len());
        for a in 0..tris.len() {
            for b in a + 1..tris.len() {
                let (ta, tb) = (mesh.triangles[tris[a] as usize], mesh.triangles[tris[b] as usize]);
                if ta.iter().any(|&w| w != v && tb.contains(&w)) {
                    let (ra, rb) = (root(&mut fan, a), root(&mut fan, b));
                    fan[ra] = rb;
                }
            }
        }
        let roots: Vec<usize> = (0..tris.len()).map(|a| root(&mut fan, a)).collect();
        let mut distinct = roots.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() > 1 {
            let fans = distinct
                .iter()
                .map(|&r| (0..tris.len()).filter(|&a| roots[a] == r).map(|a| tris[a]).collect())
                .collect();
            out.push((v, fans));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two tetrahedra touching at one corner: the corner is split in two, each copy moved
    /// towards its own tetrahedron, and every other vertex stays.
    #[test]
    fn a_vertex_shared_by_two_closed_fans_is_split() {
        let tetra =
            |o: DVec3, s: f64| [o, o + DVec3::new(s, s, 0.0), o + DVec3::new(s, 0.0, s), o + DVec3::new(0.0, s, s)];
        let mut mesh = TriMesh::default();
        mesh.positions.extend(tetra(DVec3::ZERO, 1.0));
        mesh.positions.extend(tetra(DVec3::ZERO, -1.0)[1..].iter().copied());
        let faces = |a: u32, b: u32, c: u32, d: u32| [[a, b, c], [a, c, d], [a, d, b], [b, d, c]];
        mesh.triangles.extend(faces(0, 1, 2, 3));
        mesh.triangles.extend(faces(0, 4, 5, 6));
        assert_eq!(split(&mut mesh, 1.0), 1);
        assert_eq!(mesh.positions.len(), 8);
        assert_eq!(split(&mut mesh, 1.0), 0, "nothing is left to split");
        let corner = |t: usize| mesh.triangles[t][0];
        assert_ne!(corner(0), corner(4), "each tetrahedron has a corner of its own");
        assert!(mesh.positions[corner(0) as usize].element_sum() > 0.0);
        assert!(mesh.positions[corner(4) as usize].element_sum() < 0.0);
        assert!((mesh.positions[corner(0) as usize].length() - NUDGE).abs() < 1e-12);
        assert_eq!(mesh.open_edges(), (0, 0));
    }
}
