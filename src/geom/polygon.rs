//! Polygons: triangulation by ear clipping, and the prism of a polygon (an extruded
//! profile's exact mesh).

use glam::{DVec2, DVec3};

use super::TriMesh;

/// A polygon's triangles, wound as the polygon: a triangle as it is, a larger polygon by
/// ear clipping in the plane of its Newell normal, so a concave outline (an L, a notch)
/// keeps its shape; a fan where clipping finds no ear (a degenerate or self-crossing
/// polygon, which has no right answer).
pub fn triangulate(v: &[u32], positions: &[DVec3]) -> Vec<[u32; 3]> {
    if v.len() == 3 {
        return vec![[v[0], v[1], v[2]]];
    }
    let fan = || (1..v.len() - 1).map(|k| [v[0], v[k], v[k + 1]]).collect();
    let p: Vec<DVec3> = v.iter().map(|&i| positions[i as usize]).collect();
    let normal = (0..p.len()).fold(DVec3::ZERO, |n, i| {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        n + DVec3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y))
    });
    let Some(n) = normal.try_normalize() else { return fan() };
    // Any two axes across the normal; the polygon's winding is counter-clockwise there.
    let u = n.any_orthonormal_vector();
    let w = n.cross(u);
    let flat: Vec<(f64, f64)> = p.iter().map(|q| (q.dot(u), q.dot(w))).collect();
    let cross = |a: (f64, f64), b: (f64, f64), c: (f64, f64)| (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
    let mut left: Vec<usize> = (0..v.len()).collect();
    let mut out = Vec::with_capacity(v.len() - 2);
    while left.len() > 3 {
        let m = left.len();
        let ear = (0..m).find(|&k| {
            let (a, b, c) = (left[(k + m - 1) % m], left[k], left[(k + 1) % m]);
            let (fa, fb, fc) = (flat[a], flat[b], flat[c]);
            cross(fa, fb, fc) > 0.0
                && left.iter().all(|&o| {
                    o == a
                        || o == b
                        || o == c
                        || cross(fa, fb, flat[o]) < 0.0
                        || cross(fb, fc, flat[o]) < 0.0
                        || cross(fc, fa, flat[o]) < 0.0
                })
        });
        let Some(k) = ear else { return fan() };
        out.push([v[left[(k + m - 1) % m]], v[left[k]], v[left[(k + 1) % m]]]);
        left.remove(k);
    }
    out.push([v[left[0]], v[left[1]], v[left[2]]]);
    out
}

/// The prism of the simple polygon `corners` (`[u, v]`, either winding) as the solid's
/// `x` and `z`, from `y = -half_height` to `half_height`: its two caps, ear-clipped, and a
/// quad per edge, corners shared, wound outward. Exact: the solid's own flat faces.
pub fn prism(corners: &[DVec2], half_height: f64) -> TriMesh {
    let n = corners.len() as u32;
    let mut m = TriMesh::default();
    for y in [-half_height, half_height] {
        m.positions.extend(corners.iter().map(|c| DVec3::new(c.x, y, c.y)));
    }
    let bottom: Vec<u32> = (0..n).collect();
    let top: Vec<u32> = (n..2 * n).collect();
    for [a, b, c] in triangulate(&bottom, &m.positions) {
        m.triangles.push([a, b, c]);
    }
    for [a, b, c] in triangulate(&top, &m.positions) {
        m.triangles.push([a, c, b]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        m.triangles.push([i, n + j, j]);
        m.triangles.push([i, n + i, n + j]);
    }
    // Built for one winding of the outline; the other comes out inside out.
    if m.signed_volume() < 0.0 {
        m.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_l_prism_is_closed_outward_and_holds_the_ls_volume() {
        let l = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]].map(DVec2::from);
        for corners in [l.to_vec(), l.iter().rev().copied().collect()] {
            let m = prism(&corners, 0.5);
            assert_eq!(m.open_edges(), (0, 0));
            assert!((m.signed_volume() - 3.0).abs() < 1e-12, "{}", m.signed_volume());
            assert_eq!(m.triangles.len(), 2 * 4 + 2 * 6);
        }
    }
}
