//! Pinched vertices: a vertex whose triangles form two or more fans that meet only
//! there is not manifold, even when every edge lies on two triangles, and slicers and
//! validators reject or repair such a mesh. The isosurface mesher makes none by
//! construction (`mesh::contour`); this finds them, for the tests that hold it to that.

use crate::geom::TriMesh;

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
    use glam::DVec3;

    /// Two tetrahedra touching at one corner: that corner is pinched, nothing else is.
    #[test]
    fn a_vertex_shared_by_two_closed_fans_is_pinched() {
        let tetra =
            |o: DVec3, s: f64| [o, o + DVec3::new(s, s, 0.0), o + DVec3::new(s, 0.0, s), o + DVec3::new(0.0, s, s)];
        let mut mesh = TriMesh::default();
        mesh.positions.extend(tetra(DVec3::ZERO, 1.0));
        mesh.positions.extend(tetra(DVec3::ZERO, -1.0)[1..].iter().copied());
        let faces = |a: u32, b: u32, c: u32, d: u32| [[a, b, c], [a, c, d], [a, d, b], [b, d, c]];
        mesh.triangles.extend(faces(0, 1, 2, 3));
        mesh.triangles.extend(faces(0, 4, 5, 6));
        let found = pinched(&mesh);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].0, 0);
        assert_eq!(found[0].1.len(), 2, "two fans");
        assert_eq!(mesh.open_edges(), (0, 0), "every edge on two triangles all the same");
        mesh.triangles.truncate(4);
        assert!(pinched(&mesh).is_empty());
    }
}
