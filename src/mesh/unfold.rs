//! Folds out of an isosurface. Dual contouring puts a cell's vertex where the surface's
//! tangent planes meet, which keeps sharp edges and corners but near them can fold a
//! triangle through a neighbour (a smooth union of a sphere and a box at cell 0.05 had
//! 4 crossing pairs): slicers repair such a mesh silently or refuse it. Every crossing pair is
//! found, and the corners of both triangles move to their cells' mass points (the mean
//! of the edge crossings, where Surface Nets would put them, which does not fold there);
//! a few rounds, since a move can make a new crossing.

use std::collections::HashMap;

use foldhash::fast::FixedState;
use rayon::prelude::*;

use glam::DVec3;

use crate::geom::TriMesh;

/// Rounds of moving corners to their mass points.
const ROUNDS: usize = 4;

/// How far (in cells) a vertex must sit from its mass point for its triangles to be
/// checked: a fold needs a vertex pulled out towards a sharp feature, and where every
/// vertex is near its mass point the surface is smooth at the cell's scale. Checking
/// only those keeps the cost down (`scnc export benches/scenes/gyroid.scn -o g.stl
/// --tolerance 0.01`; docs/performance.md, "Measurements behind the code").
const PULLED: f64 = 0.25;

/// Unfolds `mesh` (vertex `i`'s mass point is `mass[i]`, its cell `size[i]` across)
/// and returns the pairs still crossing.
pub fn unfold(mesh: &mut TriMesh, mass: &[DVec3], size: &[f64]) -> usize {
    let pulled: Vec<bool> = mesh
        .positions
        .iter()
        .zip(mass)
        .zip(size)
        .map(|((p, m), s)| p.distance_squared(*m) > (PULLED * s).powi(2))
        .collect();
    let near: Vec<usize> =
        (0..mesh.triangles.len()).filter(|&t| mesh.triangles[t].iter().any(|&v| pulled[v as usize])).collect();
    if near.is_empty() {
        return 0;
    }
    // Bins of the near triangles' typical cell.
    let mut near_sizes: Vec<f64> = near.iter().flat_map(|&t| mesh.triangles[t]).map(|v| size[v as usize]).collect();
    near_sizes.sort_unstable_by(f64::total_cmp);
    let cell = near_sizes[near_sizes.len() / 2];
    // Found once, over where the corners are and where they may move to.
    let candidates = candidates(mesh, mass, &near, cell);
    for _ in 0..ROUNDS {
        let pairs = crossing(mesh, &candidates);
        if pairs.is_empty() {
            return 0;
        }
        let mut moved = false;
        for &(a, b) in &pairs {
            for v in mesh.triangles[a].into_iter().chain(mesh.triangles[b]) {
                let p = &mut mesh.positions[v as usize];
                moved |= *p != mass[v as usize];
                *p = mass[v as usize];
            }
        }
        if !moved {
            return pairs.len();
        }
    }
    crossing(mesh, &candidates).len()
}

/// Pairs of triangles that share no corner and cross: an edge of one passes through the
/// other's interior.
pub fn crossing_pairs(mesh: &TriMesh, cell: f64) -> Vec<(usize, usize)> {
    let all: Vec<usize> = (0..mesh.triangles.len()).collect();
    crossing(mesh, &candidates(mesh, &mesh.positions, &all, cell))
}

/// The `candidates` that cross where the corners are now.
fn crossing(mesh: &TriMesh, candidates: &[(usize, usize)]) -> Vec<(usize, usize)> {
    let corners = |t: usize| mesh.triangles[t].map(|i| mesh.positions[i as usize]);
    candidates.iter().copied().filter(|&(a, b)| cross(corners(a), corners(b))).collect()
}

/// Pairs that share no corner, one of them among `near`, whose reach (the bounds of
/// their corners and of the corners' mass points `mass`) overlaps: the only pairs that
/// can cross, before or after corners move. The near triangles are binned in a grid of
/// bins as large as the largest near reach (so each lies in at most eight); every
/// triangle looks for them in the bins its reach overlaps, or among the occupied bins
/// when it overlaps more than those.
fn candidates(mesh: &TriMesh, mass: &[DVec3], near: &[usize], _cell: f64) -> Vec<(usize, usize)> {
    let reach = |t: usize| {
        let v = mesh.triangles[t].map(|i| i as usize);
        let ps = v.iter().flat_map(|&i| [mesh.positions[i], mass[i]]);
        ps.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
    };
    let near_reach: Vec<(DVec3, DVec3)> = near.iter().map(|&t| reach(t)).collect();
    let size = near_reach.iter().map(|(lo, hi)| (*hi - *lo).max_element()).fold(0.0f64, f64::max);
    if size.is_nan() || size <= 0.0 || !size.is_finite() {
        return Vec::new();
    }
    let bin = |p: DVec3| (p / size).floor().as_i64vec3().to_array();
    let mut bins: HashMap<[i64; 3], Vec<u32>, FixedState> = HashMap::default();
    for (k, &(lo, hi)) in near_reach.iter().enumerate() {
        let ([x0, y0, z0], [x1, y1, z1]) = (bin(lo), bin(hi));
        for x in x0..=x1 {
            for y in y0..=y1 {
                for z in z0..=z1 {
                    bins.entry([x, y, z]).or_default().push(k as u32);
                }
            }
        }
    }
    let occupied: Vec<([i64; 3], &Vec<u32>)> = bins.iter().map(|(b, l)| (*b, l)).collect();
    let overlaps = |(la, ha): (DVec3, DVec3), (lb, hb): (DVec3, DVec3)| !(la.cmpgt(hb).any() || lb.cmpgt(ha).any());
    let mut pairs: Vec<(usize, usize)> = (0..mesh.triangles.len())
        .into_par_iter()
        .fold(Vec::new, |mut found, t| {
            let r = reach(t);
            let ([x0, y0, z0], [x1, y1, z1]) = (bin(r.0), bin(r.1));
            let tt = mesh.triangles[t];
            let mut check = |list: &[u32]| {
                for &k in list {
                    let u = near[k as usize];
                    if u != t
                        && !mesh.triangles[u].iter().any(|v| tt.contains(v))
                        && overlaps(r, near_reach[k as usize])
                    {
                        found.push((t.min(u), t.max(u)));
                    }
                }
            };
            let count = (x1 - x0 + 1).saturating_mul(y1 - y0 + 1).saturating_mul(z1 - z0 + 1);
            if count <= occupied.len() as i64 {
                for x in x0..=x1 {
                    for y in y0..=y1 {
                        for z in z0..=z1 {
                            if let Some(list) = bins.get(&[x, y, z]) {
                                check(list);
                            }
                        }
                    }
                }
            } else {
                for (b, list) in &occupied {
                    if (x0..=x1).contains(&b[0]) && (y0..=y1).contains(&b[1]) && (z0..=z1).contains(&b[2]) {
                        check(list);
                    }
                }
            }
            found
        })
        .flatten()
        .collect();
    pairs.par_sort_unstable();
    pairs.dedup();
    pairs
}

/// Whether an edge of either triangle passes through the other (touching at a corner
/// or lying in its plane is not crossing).
fn cross(a: [DVec3; 3], b: [DVec3; 3]) -> bool {
    (0..3).any(|k| through(a[k], a[(k + 1) % 3], b)) || (0..3).any(|k| through(b[k], b[(k + 1) % 3], a))
}

/// Whether the open segment `p`–`q` passes through triangle `t` (Möller–Trumbore).
fn through(p: DVec3, q: DVec3, [a, b, c]: [DVec3; 3]) -> bool {
    let (e1, e2, d) = (b - a, c - a, q - p);
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det.abs() <= 1e-12 * e1.length() * e2.length() * d.length() {
        return false;
    }
    let s = p - a;
    let u = s.dot(h) / det;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let r = s.cross(e1);
    let v = d.dot(r) / det;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = e2.dot(r) / det;
    t > 1e-9 && t < 1.0 - 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle, one through its interior, and one above it, apart.
    fn three() -> TriMesh {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.2, 0.2, -0.5], [0.2, 0.2, 0.5]];
        let q = [[0.3, 0.4, 0.5], [0.2, 0.2, 1.5], [0.8, 0.2, 1.5], [0.2, 0.8, 1.5]];
        TriMesh {
            positions: p.iter().chain(&q).map(|&c| DVec3::from(c)).collect(),
            triangles: vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]],
        }
    }

    #[test]
    fn crossing_triangles_are_found_and_apart_ones_are_not() {
        assert_eq!(crossing_pairs(&three(), 0.5), [(0, 1)]);
    }

    #[test]
    fn a_fold_is_undone_at_the_mass_points() {
        let mut mesh = three();
        let mut mass = mesh.positions.clone();
        // The second triangle's mass points lie above the first.
        mass[3].z = 0.1;
        assert_eq!(unfold(&mut mesh, &mass, &[0.5; 9]), 0);
        assert_eq!(mesh.positions[3].z, 0.1);
    }
}
