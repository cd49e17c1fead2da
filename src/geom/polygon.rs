//! Polygons: triangulation by ear clipping, convex hulls and their clipping, and the
//! prism of a polygon (an extruded profile's exact mesh).

use glam::{DVec2, DVec3};

use super::TriMesh;

/// Most corners of a face that is not convex that [`triangulate_within`] is asked to
/// clip for a mesh file (a convex face of any size is a fan): ear clipping is
/// quadratic in the worst case, and 10,000 corners take milliseconds, a million hours.
pub const MAX_CLIPPED_CORNERS: usize = 10_000;

/// A polygon's triangles, wound as the polygon: a triangle as it is, a convex polygon
/// as a fan, a larger one by ear clipping in the plane of its Newell normal, so a
/// concave outline (an L, a notch) keeps its shape; a fan where clipping finds no ear (a
/// degenerate or self-crossing polygon, which has no right answer).
pub fn triangulate(v: &[u32], positions: &[DVec3]) -> Vec<[u32; 3]> {
    triangulate_within(v, positions, usize::MAX).unwrap_or_default()
}

/// [`triangulate`], or `None` for a polygon that is not convex and has more than
/// `max_clipped` corners (before any clipping, in time linear in the corners).
///
/// The clipper keeps the corners in a ring and tests a candidate ear only against the
/// reflex corners (only they can lie inside an ear of a simple polygon), walking on from
/// each ear it cuts: `O(n·r)` for `r` reflex corners, where the textbook loop that
/// rescans every corner for every ear is `O(n³)`.
pub fn triangulate_within(v: &[u32], positions: &[DVec3], max_clipped: usize) -> Option<Vec<[u32; 3]>> {
    let n = v.len();
    if n == 3 {
        return Some(vec![[v[0], v[1], v[2]]]);
    }
    let fan = || (1..n - 1).map(|k| [v[0], v[k], v[k + 1]]).collect::<Vec<_>>();
    let p: Vec<DVec3> = v.iter().map(|&i| positions[i as usize]).collect();
    let normal = (0..n).fold(DVec3::ZERO, |acc, i| {
        let (a, b) = (p[i], p[(i + 1) % n]);
        acc + DVec3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y))
    });
    let Some(normal) = normal.try_normalize() else { return Some(fan()) };
    // Any two axes across the normal; the polygon's winding is counter-clockwise there.
    let u = normal.any_orthonormal_vector();
    let w = normal.cross(u);
    let flat: Vec<(f64, f64)> = p.iter().map(|q| (q.dot(u), q.dot(w))).collect();
    let cross = |a: usize, b: usize, c: usize| {
        let (a, b, c) = (flat[a], flat[b], flat[c]);
        (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
    };
    let (mut prev, mut next): (Vec<usize>, Vec<usize>) =
        ((0..n).map(|i| (i + n - 1) % n).collect(), (0..n).map(|i| (i + 1) % n).collect());
    let mut reflex: Vec<bool> = (0..n).map(|i| cross(prev[i], i, next[i]) <= 0.0).collect();
    if !reflex.contains(&true) {
        return Some(fan());
    }
    if n > max_clipped {
        return None;
    }
    let mut reflexes: Vec<usize> = (0..n).filter(|&i| reflex[i]).collect();
    let mut out = Vec::with_capacity(n - 2);
    let (mut left, mut at, mut tried) = (n, 0, 0);
    while left > 3 {
        if tried > left {
            // A full lap without an ear: degenerate or self-crossing.
            return Some(fan());
        }
        let (a, b, c) = (prev[at], at, next[at]);
        let ear = !reflex[b]
            && reflexes.iter().all(|&o| {
                o == a || o == c || !reflex[o] || cross(a, b, o) < 0.0 || cross(b, c, o) < 0.0 || cross(c, a, o) < 0.0
            });
        if !ear {
            (at, tried) = (c, tried + 1);
            continue;
        }
        out.push([v[a], v[b], v[c]]);
        (next[a], prev[c], left, tried) = (c, a, left - 1, 0);
        reflex[b] = false;
        for k in [a, c] {
            reflex[k] = cross(prev[k], k, next[k]) <= 0.0;
        }
        // Corners only ever turn convex: drop those that have, now and then.
        if reflexes.len() > 32 && out.len().is_multiple_of(32) {
            reflexes.retain(|&o| reflex[o] && next[prev[o]] == o);
        }
        at = c;
    }
    out.push([v[prev[at]], v[at], v[next[at]]]);
    Some(out)
}

/// The prism of the simple polygon `corners` (`[u, v]`, either winding) as the solid's
/// `x` and `z`, from `y = -half_height` to `half_height`: its two caps, ear-clipped, and a
/// quad per edge, corners shared, wound outward. Exact: the solid's own flat faces.
pub fn prism(corners: &[DVec2], half_height: f64) -> TriMesh {
    let outline: Vec<u32> = (0..corners.len() as u32).collect();
    let flat: Vec<DVec3> = corners.iter().map(|c| DVec3::new(c.x, 0.0, c.y)).collect();
    prism_of_caps(corners, &triangulate(&outline, &flat), half_height)
}

/// A prism from a triangulated cap (`[u, v]` points, triangles of either winding): the
/// cap at both heights and a quad on every edge of the cap's rim, so the walls meet the
/// caps at the very same corners whatever the triangulation made of the outline.
pub fn prism_of_caps(points: &[DVec2], triangles: &[[u32; 3]], half_height: f64) -> TriMesh {
    let n = points.len() as u32;
    let mut m = TriMesh::default();
    for y in [-half_height, half_height] {
        m.positions.extend(points.iter().map(|c| DVec3::new(c.x, y, c.y)));
    }
    // Counter-clockwise in `[u, v]` is clockwise seen from +y (`v` is `z`): so wound,
    // a triangle faces down, as the bottom cap should.
    let ccw: Vec<[u32; 3]> = triangles
        .iter()
        .filter_map(|&[a, b, c]| {
            let [pa, pb, pc] = [a, b, c].map(|i| points[i as usize]);
            let area = (pb - pa).perp_dot(pc - pa);
            (area != 0.0).then_some(if area > 0.0 { [a, b, c] } else { [a, c, b] })
        })
        .collect();
    let mut rim: std::collections::HashSet<(u32, u32)> = std::collections::HashSet::new();
    for t in &ccw {
        m.triangles.push(*t);
        m.triangles.push([t[0] + n, t[2] + n, t[1] + n]);
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            if !rim.remove(&(b, a)) {
                rim.insert((a, b));
            }
        }
    }
    // A rim edge a→b of the bottom cap: its wall runs up from it, wound against it.
    let mut rim: Vec<(u32, u32)> = rim.into_iter().collect();
    rim.sort_unstable();
    for (a, b) in rim {
        m.triangles.push([b, a, a + n]);
        m.triangles.push([b, a + n, b + n]);
    }
    m
}

/// Whether `corners` (`[radius, height]`) revolve into a closed, manifold lathe: none at
/// a negative radius, and those on the axis (at most two) next to each other, so the
/// surface meets the axis in one point or along one edge.
pub fn lathe_ok(corners: &[DVec2]) -> bool {
    let n = corners.len();
    let axis: Vec<usize> = (0..n).filter(|&i| corners[i].x == 0.0).collect();
    corners.iter().all(|c| c.x >= 0.0)
        && match axis[..] {
            [] | [_] => true,
            [a, b] => b == a + 1 || (a == 0 && b == n - 1),
            _ => false,
        }
}

/// The polygon `corners` (`[radius, height]`, see [`lathe_ok`]) revolved about `y` in
/// `segments` steps, every vertex on the surface of revolution: closed and outward for
/// either winding. A corner on the axis is one vertex; an edge along the axis makes no
/// triangles.
pub fn lathe(corners: &[DVec2], segments: u32) -> TriMesh {
    let n = corners.len();
    let mut m = TriMesh::default();
    let mut first = Vec::with_capacity(n);
    for c in corners {
        first.push(m.positions.len() as u32);
        if c.x == 0.0 {
            m.positions.push(DVec3::new(0.0, c.y, 0.0));
        } else {
            m.positions.extend((0..segments).map(|j| {
                let a = std::f64::consts::TAU * f64::from(j) / f64::from(segments);
                DVec3::new(c.x * a.cos(), c.y, c.x * a.sin())
            }));
        }
    }
    let at = |i: usize, j: u32| if corners[i].x == 0.0 { first[i] } else { first[i] + j % segments };
    for i in 0..n {
        let k = (i + 1) % n;
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(k, j), at(k, j + 1), at(i, j + 1));
            // Next to the axis a quad is one triangle: the other has two corners in one.
            for t in [[a, b, c], [a, c, d]] {
                if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                    m.triangles.push(t);
                }
            }
        }
    }
    // Built for one winding of the outline; the other comes out inside out.
    if m.signed_volume() < 0.0 {
        m.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
    m
}

/// Corner normals for a [`lathe`]: each triangle's facet normal split into its
/// meridian's radial and `y` parts and turned to each corner's angle, so the surface
/// shades smooth around the axis and keeps the profile's creases.
pub fn lathe_normals(m: &TriMesh) -> Vec<[DVec3; 3]> {
    let angle = |p: DVec3| p.z.atan2(p.x);
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let n = (b - a).cross(c - a).normalize_or_zero();
            let mid = angle(a + b + c);
            let radial = n.x * mid.cos() + n.z * mid.sin();
            [a, b, c].map(|p| {
                // A corner on the axis has no angle of its own: the facet's.
                let at = if p.x == 0.0 && p.z == 0.0 { mid } else { angle(p) };
                DVec3::new(radial * at.cos(), n.y, radial * at.sin()).normalize_or(n)
            })
        })
        .collect()
}

/// Corner normals for a prism's walls (an extrusion): each corner's normal is the
/// mean of the planes of the facets meeting at its point whose normals are within
/// `crease` (radians) of its own facet's, as Blender's auto smooth does, so the walls
/// round a circle shade smooth while the caps' rims and a polygon's corners sharper
/// than `crease` stay creased.
pub fn smooth_within(m: &TriMesh, crease: f64) -> Vec<[DVec3; 3]> {
    use std::collections::HashMap;
    let facets: Vec<DVec3> = m
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            (b - a).cross(c - a)
        })
        .collect();
    // The facets at each point (by position: a wall and a cap may not share indices).
    let key = |p: DVec3| p.to_array().map(f64::to_bits);
    let mut at: HashMap<[u64; 3], Vec<usize>> = HashMap::new();
    for (f, t) in m.triangles.iter().enumerate() {
        for &i in t {
            at.entry(key(m.positions[i as usize])).or_default().push(f);
        }
    }
    let cos = crease.cos();
    m.triangles
        .iter()
        .enumerate()
        .map(|(f, t)| {
            let own = facets[f].normalize_or_zero();
            t.map(|i| {
                // Each plane once (a wall's quad is two triangles of one plane), so the
                // corner between two walls is normal to neither more than the other.
                let mut planes: Vec<DVec3> = Vec::new();
                for &g in &at[&key(m.positions[i as usize])] {
                    let n = facets[g].normalize_or_zero();
                    if n.dot(own) >= cos && !planes.iter().any(|q| q.abs_diff_eq(n, 1e-9)) {
                        planes.push(n);
                    }
                }
                planes.iter().sum::<DVec3>().normalize_or(own)
            })
        })
        .collect()
}

/// Whether segments `a0 a1` and `b0 b1` cross or touch.
pub fn segments_meet(a0: DVec2, a1: DVec2, b0: DVec2, b1: DVec2) -> bool {
    let side = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let on = |p: DVec2, q: DVec2, r: DVec2| r.cmpge(p.min(q)).all() && r.cmple(p.max(q)).all();
    let (d1, d2) = (side(b0, b1, a0), side(b0, b1, a1));
    let (d3, d4) = (side(a0, a1, b0), side(a0, a1, b1));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        return true;
    }
    (d1 == 0.0 && on(b0, b1, a0))
        || (d2 == 0.0 && on(b0, b1, a1))
        || (d3 == 0.0 && on(a0, a1, b0))
        || (d4 == 0.0 && on(a0, a1, b1))
}

/// The corners of the convex hull of `pts`, counter-clockwise, by Andrew's monotone
/// chain; fewer than three when the points span no area.
pub fn convex_hull(mut pts: Vec<DVec2>) -> Vec<DVec2> {
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    // Lower then upper hull, turning left throughout.
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> =
            if pass == 0 { Box::new(pts.iter()) } else { Box::new(pts.iter().rev()) };
        for &p in iter {
            while hull.len() >= start + 2 {
                let (a, b) = (hull[hull.len() - 2], hull[hull.len() - 1]);
                if (b - a).perp_dot(p - a) > 0.0 {
                    break;
                }
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The part of the convex polygon `poly` (corners in order) where `n·p ≤ d`
/// (Sutherland–Hodgman against one line).
pub fn clip_convex(poly: &[DVec2], n: DVec2, d: f64) -> Vec<DVec2> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (da, db) = (n.dot(a) - d, n.dot(b) - d);
        if da <= 0.0 {
            out.push(a);
        }
        if (da < 0.0) != (db < 0.0) && da != db {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A star-shaped polygon of `n` corners in the plane `z = 0.3`, its radii 0.4 to 1
    /// from a fixed hash (every other corner pulled in: about half are reflex).
    fn star(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40;
                let r = if i % 2 == 0 { 1.0 } else { 0.4 + 0.5 * (h as f64 / (1u64 << 24) as f64) };
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                DVec3::new(r * a.cos(), r * a.sin(), 0.3)
            })
            .collect()
    }

    /// Ear clipping cuts a simple polygon into `n − 2` triangles, each wound as the
    /// polygon, whose areas add up to the polygon's (shoelace), at every size up to the
    /// corner limit, concave or convex; a concave polygon past the limit is refused at
    /// once and a convex one of a million corners is a fan.
    #[test]
    fn ear_clipping_covers_the_polygon_and_refuses_past_the_limit() {
        for n in [4, 5, 7, 16, 101, 1000, MAX_CLIPPED_CORNERS] {
            let p = star(n);
            let v: Vec<u32> = (0..n as u32).collect();
            let t = triangulate_within(&v, &p, MAX_CLIPPED_CORNERS).expect("within the limit");
            assert_eq!(t.len(), n - 2, "{n} corners");
            let area = |a: DVec3, b: DVec3, c: DVec3| 0.5 * (b - a).cross(c - a).z;
            let shoelace: f64 = (0..n).map(|i| 0.5 * p[i].truncate().perp_dot(p[(i + 1) % n].truncate())).sum();
            let cut: f64 = t.iter().map(|&[a, b, c]| area(p[a as usize], p[b as usize], p[c as usize])).sum();
            assert!(
                t.iter().all(|&[a, b, c]| area(p[a as usize], p[b as usize], p[c as usize]) > 0.0),
                "{n}: a triangle wound back"
            );
            assert!((cut - shoelace).abs() < 1e-9 * shoelace, "{n} corners: triangles {cut}, polygon {shoelace}");
        }
        let v: Vec<u32> = (0..1_000_000).collect();
        assert_eq!(triangulate_within(&v, &star(1_000_000), MAX_CLIPPED_CORNERS), None);
        let circle: Vec<DVec3> = (0..1_000_000)
            .map(|i| {
                let a = std::f64::consts::TAU * f64::from(i) / 1e6;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        assert_eq!(triangulate_within(&v, &circle, MAX_CLIPPED_CORNERS).map(|t| t.len()), Some(999_998));
    }

    /// Smoothed within a circle's step, an extruded disc's walls take the radial
    /// direction at their corners (a facet's own normal is half a step off) and its
    /// caps stay flat; a triangle prism's corners are sharper than the crease and keep their
    /// facets' normals.
    #[test]
    fn extruded_circles_shade_smooth_and_polygons_keep_their_creases() {
        use crate::geom::region::{extrusion, Region};
        let n = 32;
        let step = std::f64::consts::TAU / f64::from(n);
        let disc = extrusion(&Region::Circle { centre: DVec2::ZERO, r: 1.0 }, 0.5, n).expect("a prism");
        let normals = smooth_within(&disc, 1.01 * step);
        let (mut walls, mut caps) = (0, 0);
        for (t, corners) in disc.triangles.iter().zip(&normals) {
            let [a, b, c] = t.map(|i| disc.positions[i as usize]);
            let facet = (b - a).cross(c - a).normalize();
            for (&i, normal) in t.iter().zip(corners) {
                let p = disc.positions[i as usize];
                if facet.y.abs() > 0.99 {
                    caps += 1;
                    assert!(normal.abs_diff_eq(facet, 1e-12), "a cap corner {normal} against {facet}");
                } else {
                    walls += 1;
                    let radial = DVec3::new(p.x, 0.0, p.z).normalize();
                    assert!(normal.angle_between(radial) < 1e-6, "a wall corner at {p}: {normal}");
                }
            }
        }
        assert!(walls >= 6 * n as usize && caps > 0, "{walls} wall and {caps} cap corners");
        let triangle = [[-0.8, -0.5], [0.9, -0.3], [0.1, 0.8]].map(DVec2::from);
        let prism = prism(&triangle, 0.4);
        for (t, corners) in prism.triangles.iter().zip(smooth_within(&prism, 1.01 * step)) {
            let [a, b, c] = t.map(|i| prism.positions[i as usize]);
            let facet = (b - a).cross(c - a).normalize();
            assert!(corners.iter().all(|n| n.abs_diff_eq(facet, 1e-12)), "{corners:?} against {facet}");
        }
    }

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

    /// A tube (a rectangle off the axis) and a cone (a triangle with an edge on the axis)
    /// revolved: closed, outward for either winding, and holding the volume of the
    /// inscribed polygonal solid exactly (`n/2 · sin(2π/n)` of the circle's area).
    #[test]
    fn lathes_are_closed_outward_and_inscribed() {
        let n = 48u32;
        let inscribed = f64::from(n) / 2.0 * (std::f64::consts::TAU / f64::from(n)).sin();
        let tube = [[1.0, -0.5], [2.0, -0.5], [2.0, 0.5], [1.0, 0.5]].map(DVec2::from);
        let cone = [[0.0, 0.0], [1.0, 0.0], [0.0, 2.0]].map(DVec2::from);
        for (corners, volume) in [(&tube[..], inscribed * 3.0), (&cone[..], inscribed * 2.0 / 3.0)] {
            assert!(lathe_ok(corners));
            for corners in [corners.to_vec(), corners.iter().rev().copied().collect()] {
                let m = lathe(&corners, n);
                assert_eq!(m.open_edges(), (0, 0));
                // Each corner's normal points out of its facet's side and has no part
                // along the circle.
                for (t, normals) in m.triangles.iter().zip(lathe_normals(&m)) {
                    let [a, b, c] = t.map(|i| m.positions[i as usize]);
                    let facet = (b - a).cross(c - a).normalize();
                    for (p, n) in [a, b, c].into_iter().zip(normals) {
                        assert!(n.dot(facet) > 0.9 && (n.length() - 1.0).abs() < 1e-12);
                        let tangent = DVec3::new(-p.z, 0.0, p.x);
                        assert!(n.dot(tangent).abs() < 1e-9 * tangent.length().max(1.0));
                    }
                }
                assert!((m.signed_volume() - volume).abs() < 1e-9, "{} against {volume}", m.signed_volume());
            }
        }
        // Across the axis, or touching it at two corners apart: not a lathe.
        assert!(!lathe_ok(&[[-1.0, 0.0], [1.0, 0.0], [0.0, 1.0]].map(DVec2::from)));
        assert!(!lathe_ok(&[[0.0, 0.0], [1.0, 1.0], [0.0, 2.0], [2.0, 1.0]].map(DVec2::from)));
    }
}
