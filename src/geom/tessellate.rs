//! Parametric mesh generators. Every closed generator is watertight (shared vertices,
//! each edge used by exactly two triangles) and wound counter-clockwise seen from
//! outside, so face normals point out.

use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

use glam::DVec3;
use rayon::prelude::*;

use super::TriMesh;

/// How many triangles each generator makes, so a budget can be charged before anything
/// is allocated (each checked against its generator in `counts_are_what_generators_make`).
pub mod count {
    /// [`uvsphere`](super::uvsphere).
    pub fn uvsphere(rings: u32, segments: u32) -> u64 {
        2 * segments.max(3) as u64 * (rings.max(2) as u64 - 1)
    }

    /// [`icosphere`](super::icosphere).
    pub fn icosphere(subdivisions: u32) -> u64 {
        20 * 4u64.pow(subdivisions)
    }

    /// [`cuboid`](super::cuboid).
    pub const CUBOID: u64 = 12;

    /// [`square`](super::square).
    pub const SQUARE: u64 = 2;

    /// [`cylinder`](super::cylinder).
    pub fn cylinder(segments: u32) -> u64 {
        4 * segments.max(3) as u64
    }

    /// [`cone`](super::cone).
    pub fn cone(segments: u32) -> u64 {
        2 * segments.max(3) as u64
    }

    /// [`frustum`](super::frustum): a side and a cap for each end that is a circle.
    pub fn frustum(r_bottom: f64, r_top: f64, segments: u32) -> u64 {
        let ends = (r_bottom > 0.0) as u64 + (r_top > 0.0) as u64;
        (ends * 2) * segments.max(3) as u64
    }

    /// [`torus`](super::torus).
    pub fn torus(segments: u32, sides: u32) -> u64 {
        2 * segments.max(3) as u64 * sides.max(3) as u64
    }
}

/// UV sphere: `rings` latitude bands (≥ 2) and `segments` longitudes (≥ 3), poles on ±y.
/// Made in parallel, each vertex and quad from its index (exact-length collects, the
/// same mesh for any thread count).
pub fn uvsphere(r: f64, rings: u32, segments: u32) -> TriMesh {
    let (rings, segments) = (rings.max(2), segments.max(3));
    let band = (rings - 1) * segments;
    let positions = (0..band + 2)
        .into_par_iter()
        .map(|k| match k {
            0 => DVec3::new(0.0, r, 0.0),
            k if k > band => DVec3::new(0.0, -r, 0.0),
            k => {
                let (i, j) = ((k - 1) / segments + 1, (k - 1) % segments);
                let theta = PI * i as f64 / rings as f64;
                let phi = TAU * j as f64 / segments as f64;
                DVec3::new(r * theta.sin() * phi.cos(), r * theta.cos(), r * theta.sin() * phi.sin())
            }
        })
        .collect();
    let south = band + 1;
    let ring = move |i: u32, j: u32| 1 + (i - 1) * segments + (j % segments);
    let caps = 2 * segments;
    let triangles = (0..2 * band)
        .into_par_iter()
        .map(|k| {
            if k < caps {
                let j = k / 2;
                return if k % 2 == 0 {
                    [0, ring(1, j + 1), ring(1, j)]
                } else {
                    [south, ring(rings - 1, j), ring(rings - 1, j + 1)]
                };
            }
            let q = (k - caps) / 2;
            let (i, j) = (q / segments + 1, q % segments);
            quad_half([ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)], k % 2)
        })
        .collect();
    TriMesh { positions, triangles }
}

/// Box with half-extents `h`: 8 vertices, 12 triangles.
pub fn cuboid(h: DVec3) -> TriMesh {
    let positions = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            )
        })
        .collect();
    // Each face as a quad (a, b, c, d) counter-clockwise seen from outside.
    let quads = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
    let triangles = quads.iter().flat_map(|&q| [quad_half(q, 0), quad_half(q, 1)]).collect();
    TriMesh { positions, triangles }
}

/// Triangle `half` (0 or 1) of the quad `q`, counter-clockwise seen from outside:
/// `q0 q1 q2`, then `q0 q2 q3`.
fn quad_half(q: [u32; 4], half: u32) -> [u32; 3] {
    if half == 0 {
        [q[0], q[1], q[2]]
    } else {
        [q[0], q[2], q[3]]
    }
}

/// Capped cylinder along y with `segments` points per cap circle.
pub fn cylinder(r: f64, h: f64, segments: u32) -> TriMesh {
    let n = segments.max(3);
    let mut m = TriMesh::default();
    for y in [h, -h] {
        for j in 0..n {
            let phi = TAU * j as f64 / n as f64;
            m.positions.push(DVec3::new(r * phi.cos(), y, r * phi.sin()));
        }
    }
    let (top, bottom) = (m.positions.len() as u32, m.positions.len() as u32 + 1);
    m.positions.push(DVec3::new(0.0, h, 0.0));
    m.positions.push(DVec3::new(0.0, -h, 0.0));
    for j in 0..n {
        let k = (j + 1) % n;
        m.triangles.push([top, k, j]);
        m.triangles.push([bottom, n + j, n + k]);
        m.triangles.push([j, k, n + k]);
        m.triangles.push([j, n + k, n + j]);
    }
    m
}

/// Cone along y: base radius `r` at `−h`, apex at `h`, `segments` points on the base.
pub fn cone(r: f64, h: f64, segments: u32) -> TriMesh {
    let n = segments.max(3);
    let mut m = TriMesh::default();
    for j in 0..n {
        let phi = TAU * j as f64 / n as f64;
        m.positions.push(DVec3::new(r * phi.cos(), -h, r * phi.sin()));
    }
    let (apex, base) = (n, n + 1);
    m.positions.push(DVec3::new(0.0, h, 0.0));
    m.positions.push(DVec3::new(0.0, -h, 0.0));
    for j in 0..n {
        let k = (j + 1) % n;
        m.triangles.push([apex, k, j]);
        m.triangles.push([base, j, k]);
    }
    m
}

/// Frustum along y: radius `r_bottom` at `−h`, `r_top` at `h` (at least one of them
/// positive; an end of radius 0 is an apex, one vertex), `segments` points per circle.
pub fn frustum(r_bottom: f64, r_top: f64, h: f64, segments: u32) -> TriMesh {
    let n = segments.max(3);
    let mut m = TriMesh::default();
    // Each end: its first vertex, and whether it is a circle of `n` points (else an apex).
    let mut end = |r: f64, y: f64| {
        let first = m.positions.len() as u32;
        if r > 0.0 {
            for j in 0..n {
                let phi = TAU * j as f64 / n as f64;
                m.positions.push(DVec3::new(r * phi.cos(), y, r * phi.sin()));
            }
        } else {
            m.positions.push(DVec3::new(0.0, y, 0.0));
        }
        (first, r > 0.0)
    };
    let (top, top_ring) = end(r_top, h);
    let (bottom, bottom_ring) = end(r_bottom, -h);
    let at = |(first, ring): (u32, bool), j: u32| if ring { first + j % n } else { first };
    for j in 0..n {
        let (tj, tk) = (at((top, top_ring), j), at((top, top_ring), j + 1));
        let (bj, bk) = (at((bottom, bottom_ring), j), at((bottom, bottom_ring), j + 1));
        // The side quad (tj, tk, bk, bj), one triangle dropped where an apex folds it.
        if top_ring {
            m.triangles.push([tj, tk, bk]);
        }
        if bottom_ring {
            m.triangles.push([tj, bk, bj]);
        }
    }
    for (first, ring, y, flip) in [(top, top_ring, h, false), (bottom, bottom_ring, -h, true)] {
        if ring {
            let centre = m.positions.len() as u32;
            m.positions.push(DVec3::new(0.0, y, 0.0));
            for j in 0..n {
                let (a, b) = (first + j, first + (j + 1) % n);
                m.triangles.push(if flip { [centre, a, b] } else { [centre, b, a] });
            }
        }
    }
    m
}

/// Torus in the xz plane: `segments` around the major circle, `sides` around the tube.
/// Made in parallel like [`uvsphere`].
pub fn torus(major: f64, minor: f64, segments: u32, sides: u32) -> TriMesh {
    let (n, s) = (segments.max(3), sides.max(3));
    let positions = (0..n * s)
        .into_par_iter()
        .map(|k| {
            let phi = TAU * (k / s) as f64 / n as f64;
            let theta = TAU * (k % s) as f64 / s as f64;
            let dir = DVec3::new(phi.cos(), 0.0, phi.sin());
            dir * (major + minor * theta.cos()) + DVec3::Y * (minor * theta.sin())
        })
        .collect();
    let idx = move |i: u32, j: u32| (i % n) * s + (j % s);
    let triangles = (0..2 * n * s)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k / 2 / s, k / 2 % s);
            quad_half([idx(i, j), idx(i, j + 1), idx(i + 1, j + 1), idx(i + 1, j)], k % 2)
        })
        .collect();
    TriMesh { positions, triangles }
}

/// A square of half-side `size` in the xz plane facing +y (two triangles; not closed).
pub fn square(size: f64) -> TriMesh {
    let positions = vec![
        DVec3::new(-size, 0.0, -size),
        DVec3::new(size, 0.0, -size),
        DVec3::new(size, 0.0, size),
        DVec3::new(-size, 0.0, size),
    ];
    TriMesh { positions, triangles: vec![[0, 2, 1], [0, 3, 2]] }
}

/// Icosphere: an icosahedron subdivided `subdivisions` times, projected onto the sphere.
pub fn icosphere(r: f64, subdivisions: u32) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| DVec3::from(*p).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<DVec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push(((positions[a as usize] + positions[b as usize]) * 0.5).normalize());
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let (ab, bc, ca) =
                (midpoint(a, b, &mut positions), midpoint(b, c, &mut positions), midpoint(c, a, &mut positions));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    TriMesh { positions: positions.into_iter().map(|p| p * r).collect(), triangles }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closed_and_outward(name: &str, m: &TriMesh, volume: f64, tol: f64) {
        assert_eq!(m.open_edges(), (0, 0), "{name}: open or inconsistently wound edges");
        let v = m.signed_volume();
        assert!(v > 0.0, "{name}: wound inward (volume {v})");
        assert!((v - volume).abs() <= tol * volume, "{name}: volume {v}, expected about {volume}");
    }

    #[test]
    fn generators_are_closed_and_outward() {
        closed_and_outward("uvsphere", &uvsphere(1.0, 14, 28), 4.0 / 3.0 * PI, 0.05);
        closed_and_outward("uvsphere low", &uvsphere(1.0, 7, 10), 4.0 / 3.0 * PI, 0.3);
        closed_and_outward("icosphere", &icosphere(1.0, 3), 4.0 / 3.0 * PI, 0.05);
        closed_and_outward("box", &cuboid(DVec3::new(1.0, 2.0, 3.0)), 48.0, 1e-9);
        closed_and_outward("cylinder", &cylinder(1.0, 1.0, 64), 2.0 * PI, 0.01);
        closed_and_outward("cone", &cone(1.0, 1.0, 64), 2.0 * PI / 3.0, 0.01);
        closed_and_outward("torus", &torus(1.0, 0.25, 64, 32), 2.0 * PI * PI * 0.0625, 0.01);
        // A frustum of height 2h holds πh·2(r₁² + r₁r₂ + r₂²)/3.
        let frustum_volume = |r1: f64, r2: f64| PI * 2.0 * (r1 * r1 + r1 * r2 + r2 * r2) / 3.0;
        for (r1, r2) in [(1.0, 0.5), (0.5, 1.0), (1.0, 0.0), (0.0, 1.0), (0.7, 0.7)] {
            closed_and_outward(&format!("frustum {r1} {r2}"), &frustum(r1, r2, 1.0, 64), frustum_volume(r1, r2), 0.01);
        }
    }

    #[test]
    fn counts_are_what_generators_make() {
        let n = |m: TriMesh| m.triangles.len() as u64;
        for a in [0, 2, 3, 7, 14, 31] {
            for b in [0, 3, 5, 50] {
                assert_eq!(count::uvsphere(a, b), n(uvsphere(1.0, a, b)), "uvsphere({a}, {b})");
                assert_eq!(count::torus(a, b), n(torus(1.0, 0.2, a, b)), "torus({a}, {b})");
            }
            assert_eq!(count::cylinder(a), n(cylinder(1.0, 1.0, a)), "cylinder({a})");
            assert_eq!(count::cone(a), n(cone(1.0, 1.0, a)), "cone({a})");
            for (r1, r2) in [(1.0, 0.5), (0.0, 1.0), (1.0, 0.0)] {
                assert_eq!(count::frustum(r1, r2, a), n(frustum(r1, r2, 1.0, a)), "frustum({r1}, {r2}, {a})");
            }
        }
        for s in 0..4 {
            assert_eq!(count::icosphere(s), n(icosphere(1.0, s)), "icosphere({s})");
        }
        assert_eq!(count::CUBOID, n(cuboid(DVec3::ONE)));
        assert_eq!(count::SQUARE, n(square(1.0)));
    }

    #[test]
    fn counts_match_the_study() {
        assert_eq!(cuboid(DVec3::ONE).triangles.len(), 12);
        assert_eq!(uvsphere(1.0, 7, 14).triangles.len(), 2 * 7 * 14 - 2 * 14);
        assert_eq!(cylinder(1.0, 1.0, 10).triangles.len(), 40);
    }
}
