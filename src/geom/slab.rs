//! Meshes of `elongate` and `symmetric` made from their child's own mesh by cutting it
//! at a coordinate plane through the origin. The cut splits every triangle that crosses
//! the plane at the crossing points (shared by neighbours, so the halves stay closed
//! against each other), and the halves are then either moved apart with a band of
//! quads between their rims (`elongate`: the slab `p − clamp(p, −h, h)` inserts is the
//! cut extruded, so the band is exact on the child's mesh) or the positive half is kept
//! and mirrored onto the other side (`symmetric`). Where the isosurface mesher rounded
//! the capsule of an elongated sphere with millions of cells, this is the sphere's own
//! mesh and one ring of quads.

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use crate::geom::TriMesh;

/// Which side of the plane a triangle of a cut mesh lies on.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Side {
    Below,
    Above,
    /// In the plane, all three corners on it.
    On,
}

/// A mesh cut at `x[axis] = 0`: its vertices (those on the plane exactly there), and its
/// triangles, each wholly on one side or in the plane.
struct Cut {
    positions: Vec<DVec3>,
    triangles: Vec<([u32; 3], Side)>,
}

/// A vertex whose distance to the plane is within this fraction of the mesh's extent is
/// put on it: a generator's ring "at the equator" has `cos 90°` there, 6e-17, not 0.
const SNAP: f64 = 1e-9;

/// Cuts `mesh` at the plane `x[axis] = 0`.
fn cut(mesh: &TriMesh, axis: usize) -> Cut {
    let extent = mesh.positions.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let eps = SNAP * extent.max(f64::MIN_POSITIVE);
    let mut positions = mesh.positions.clone();
    let side: Vec<i8> = positions
        .iter_mut()
        .map(|p| {
            if p[axis].abs() <= eps {
                p[axis] = 0.0;
                0
            } else if p[axis] > 0.0 {
                1
            } else {
                -1
            }
        })
        .collect();
    // One crossing point per edge, shared by the two triangles on it.
    let mut crossing: HashMap<(u32, u32), u32> = HashMap::new();
    let mut cross = |positions: &mut Vec<DVec3>, a: u32, b: u32| -> u32 {
        *crossing.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (pa, pb) = (positions[a as usize], positions[b as usize]);
            let t = pa[axis] / (pa[axis] - pb[axis]);
            let mut p = pa + (pb - pa) * t;
            p[axis] = 0.0;
            positions.push(p);
            positions.len() as u32 - 1
        })
    };
    let mut triangles = Vec::with_capacity(mesh.triangles.len() + mesh.triangles.len() / 8);
    let of = |s: i8| if s > 0 { Side::Above } else { Side::Below };
    for &t in &mesh.triangles {
        let s = t.map(|i| side[i as usize]);
        if s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0) {
            let sum: i8 = s.iter().sum();
            triangles.push((t, if sum == 0 { Side::On } else { of(sum.signum()) }));
            continue;
        }
        // Both sides are touched. Turn the triangle so that `a` is alone on its side
        // (or, with a corner on the plane, so that the plane's corner is `c`).
        if let Some(r) = (0..3).find(|&r| s[r] == 0) {
            let [a, b, c] = [t[(r + 1) % 3], t[(r + 2) % 3], t[r]];
            let m = cross(&mut positions, a, b);
            triangles.push(([a, m, c], of(side[a as usize])));
            triangles.push(([m, b, c], of(side[b as usize])));
        } else {
            let r = (0..3).find(|&r| s[r] != s[(r + 1) % 3] && s[r] != s[(r + 2) % 3]).unwrap_or(0);
            let [a, b, c] = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
            let (ab, ca) = (cross(&mut positions, a, b), cross(&mut positions, c, a));
            triangles.push(([a, ab, ca], of(s[r])));
            // The quad `ab b c ca` on the other side, split along its shorter diagonal.
            let p = |i: u32| positions[i as usize];
            let other = of(-s[r]);
            if p(ab).distance_squared(p(c)) <= p(b).distance_squared(p(ca)) {
                triangles.extend([([ab, b, c], other), ([ab, c, ca], other)]);
            } else {
                triangles.extend([([ab, b, ca], other), ([b, c, ca], other)]);
            }
        }
    }
    Cut { positions, triangles }
}

/// Directed edges of the triangles on `side`.
fn edges(cut: &Cut, side: Side) -> HashSet<(u32, u32)> {
    cut.triangles
        .iter()
        .filter(|(_, s)| *s == side)
        .flat_map(|(t, _)| (0..3).map(move |e| (t[e], t[(e + 1) % 3])))
        .collect()
}

/// `mesh` (closed, wound outward) elongated by `h` along `axis`: its halves moved to
/// `±h` and joined by a band of quads along the cut. A triangle in the plane goes with
/// the side its solid is on (the side its normal points away from).
fn elongated_along(mesh: &TriMesh, axis: usize, h: f64) -> TriMesh {
    let mut cut = cut(mesh, axis);
    let normal_up = |t: [u32; 3], p: &[DVec3]| {
        (p[t[1] as usize] - p[t[0] as usize]).cross(p[t[2] as usize] - p[t[0] as usize])[axis] > 0.0
    };
    for i in 0..cut.triangles.len() {
        let (t, side) = cut.triangles[i];
        if side == Side::On {
            cut.triangles[i].1 = if normal_up(t, &cut.positions) { Side::Below } else { Side::Above };
        }
    }
    let above = edges(&cut, Side::Above);
    // A vertex on the plane is the upper half's; the lower half gets a copy of it.
    let n = cut.positions.len();
    let mut copy: Vec<u32> = vec![u32::MAX; n];
    let mut positions = cut.positions.clone();
    let mut lower = |i: u32, positions: &mut Vec<DVec3>| -> u32 {
        if cut.positions[i as usize][axis] != 0.0 {
            return i;
        }
        if copy[i as usize] == u32::MAX {
            copy[i as usize] = positions.len() as u32;
            positions.push(cut.positions[i as usize]);
        }
        copy[i as usize]
    };
    let mut triangles = Vec::with_capacity(cut.triangles.len());
    for &(t, side) in &cut.triangles {
        triangles.push(match side {
            Side::Below => t.map(|i| lower(i, &mut positions)),
            _ => t,
        });
    }
    // The rim: an upper edge on the plane whose twin is not upper. Its quad runs from the
    // edge moved up to the edge moved down, wound against both halves' edges. Sorted, so
    // an export is the same file every run (a set's order is not).
    let on = |i: u32| cut.positions[i as usize][axis] == 0.0;
    let mut rim: Vec<(u32, u32)> =
        above.iter().copied().filter(|&(a, b)| on(a) && on(b) && !above.contains(&(b, a))).collect();
    rim.sort_unstable();
    for (a, b) in rim {
        let (la, lb) = (lower(a, &mut positions), lower(b, &mut positions));
        triangles.extend([[b, a, la], [b, la, lb]]);
    }
    // Copies (past `n`) are the lower half's, originals on the plane the upper's.
    for (i, p) in positions.iter_mut().enumerate() {
        p[axis] += if i >= n || p[axis] < 0.0 { -h } else { h };
    }
    TriMesh { positions, triangles }
}

/// `mesh` elongated as `elongate(s, h)` elongates its shape: along each axis where `h`
/// is positive, in turn (the slab's clamp is separable, so the order does not matter).
pub fn elongated(mut mesh: TriMesh, h: DVec3) -> TriMesh {
    for axis in 0..3 {
        if h[axis] > 0.0 {
            mesh = elongated_along(&mesh, axis, h[axis]);
        }
    }
    mesh
}

/// `mesh` mirrored as `symmetric(s, axes)` mirrors its shape: along each chosen axis in
/// turn, the half at positive coordinates kept and reflected onto the negative side;
/// the two meet on the plane at the same vertices. Triangles in the plane go (they are
/// either inside the mirrored whole or not on the kept half).
pub fn mirrored(mut mesh: TriMesh, axes: [bool; 3]) -> TriMesh {
    for axis in (0..3).filter(|&k| axes[k]) {
        let cut = cut(&mesh, axis);
        let n = cut.positions.len() as u32;
        let mut positions = cut.positions;
        let kept: Vec<[u32; 3]> = cut.triangles.iter().filter(|(_, s)| *s == Side::Above).map(|&(t, _)| t).collect();
        // A mirror image of each vertex off the plane; those on it are shared.
        let mut image: Vec<u32> = (0..n).collect();
        for i in 0..n as usize {
            if positions[i][axis] != 0.0 {
                let mut p = positions[i];
                p[axis] = -p[axis];
                image[i] = positions.len() as u32;
                positions.push(p);
            }
        }
        let mut triangles = kept.clone();
        // A reflection turns the winding: swap two corners to keep it outward.
        triangles.extend(kept.iter().map(|t| [image[t[0] as usize], image[t[2] as usize], image[t[1] as usize]]));
        mesh = compacted(TriMesh { positions, triangles });
    }
    mesh
}

/// `mesh` without the vertices no triangle uses, the rest in their order.
fn compacted(mut mesh: TriMesh) -> TriMesh {
    let mut index = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::new();
    for t in &mut mesh.triangles {
        for i in t.iter_mut() {
            if index[*i as usize] == u32::MAX {
                index[*i as usize] = positions.len() as u32;
                positions.push(mesh.positions[*i as usize]);
            }
            *i = index[*i as usize];
        }
    }
    mesh.positions = positions;
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::tessellate::{cuboid, icosphere, torus, uvsphere};

    fn moved(mut m: TriMesh, by: DVec3) -> TriMesh {
        m.positions.iter_mut().for_each(|p| *p += by);
        m
    }

    /// A box elongated along one axis and along all three is the longer box: closed,
    /// outward, its volume exact, whether the cut meets its corners or its faces' middles.
    #[test]
    fn an_elongated_box_is_the_longer_box() {
        for (offset, h) in [(DVec3::ZERO, DVec3::new(0.25, 0.0, 0.0)), (DVec3::new(0.2, -0.1, 0.3), DVec3::splat(0.5))]
        {
            let m = elongated(moved(cuboid(DVec3::splat(0.5)), offset), h);
            assert_eq!(m.open_edges(), (0, 0));
            let want = (1.0 + 2.0 * h.x) * (1.0 + 2.0 * h.y) * (1.0 + 2.0 * h.z);
            assert!((m.signed_volume() - want).abs() < 1e-12, "{} not {want}", m.signed_volume());
        }
    }

    /// A sphere elongated along `y` is a capsule: closed, with no vertex inside the slab
    /// but on its rims, and the sphere's volume plus its equator's area times the slab,
    /// whether rings lie on the plane (even) or cross it (odd, or an icosphere's).
    #[test]
    fn an_elongated_sphere_is_a_capsule() {
        for sphere in [uvsphere(1.0, 16, 24), uvsphere(1.0, 15, 24), icosphere(1.0, 3)] {
            let h = 0.7;
            let m = elongated(sphere.clone(), DVec3::new(0.0, h, 0.0));
            assert_eq!(m.open_edges(), (0, 0));
            assert!(m.positions.iter().all(|p| p.y.abs() >= h - 1e-12));
            // The rim at y = h is the sphere's cut at y = 0: its area by the shoelace.
            let rim: Vec<DVec3> = m.positions.iter().copied().filter(|p| (p.y - h).abs() < 1e-12).collect();
            assert!(rim.len() >= 8);
            let grown = m.signed_volume() - sphere.signed_volume();
            let r = rim.iter().map(|p| p.length_squared().sqrt()).fold(0.0f64, f64::max);
            // Between the inscribed rim and its circle.
            assert!(grown <= std::f64::consts::PI * (r * r - h * h) * 2.0 * h + 1e-9, "{grown}");
            assert!(grown >= 0.9 * std::f64::consts::PI * (r * r - h * h) * 2.0 * h, "{grown}");
        }
    }

    /// A torus on its side (cut into two rings of the plane, one a hole) elongated across
    /// the hole stays closed and grows by the cut's area times the slab.
    #[test]
    fn an_elongated_torus_is_closed_around_its_hole() {
        let m = torus(1.0, 0.3, 32, 16);
        for axis in 0..3 {
            let mut h = DVec3::ZERO;
            h[axis] = 0.4;
            let e = elongated(m.clone(), h);
            assert_eq!(e.open_edges(), (0, 0), "along {axis}");
            assert!(e.signed_volume() > m.signed_volume());
        }
    }

    /// A box half across the plane mirrored is the box twice as wide on that side; a
    /// sphere off the plane mirrored is two spheres; a box wholly below leaves nothing.
    #[test]
    fn mirrored_meshes_are_closed_and_double_the_kept_half() {
        let m = mirrored(moved(cuboid(DVec3::splat(0.5)), DVec3::new(0.25, 0.0, 0.0)), [true, false, false]);
        assert_eq!(m.open_edges(), (0, 0));
        assert!((m.signed_volume() - 1.5).abs() < 1e-12, "{}", m.signed_volume());
        let b = m.positions.iter().fold(DVec3::ZERO, |a, p| a.max(p.abs()));
        assert_eq!(b, DVec3::new(0.75, 0.5, 0.5));
        let s = moved(uvsphere(0.5, 8, 12), DVec3::new(1.0, 0.0, 1.0));
        let two = mirrored(s.clone(), [true, false, true]);
        assert_eq!(two.open_edges(), (0, 0));
        assert!((two.signed_volume() - 4.0 * s.signed_volume()).abs() < 1e-12);
        let none = mirrored(moved(cuboid(DVec3::splat(0.5)), DVec3::new(-2.0, 0.0, 0.0)), [true, false, false]);
        assert!(none.triangles.is_empty() && none.positions.is_empty());
    }
}
