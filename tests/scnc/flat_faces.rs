//! Flat-faced primitives measured against their own meshes: where a distance is exact
//! and the mesh is the solid's own faces, the two are independent descriptions of one
//! solid, so each checks the other (the samples come from `derived.rs`).

use glam::DVec3;
use scnc::primitive::{Facets, Resolution, Tessellation};

use super::derived::{primitives, Functions};
use super::support::Rng;

/// The nearest point of triangle `abc` to `p` (Ericson, *Real-Time Collision Detection*,
/// 5.1.5).
fn nearest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Where a primitive's distance is exact and its mesh is its own flat faces, the two are
/// independent descriptions of one solid: at random points the distance's magnitude is
/// the distance to the nearest triangle, and its sign says whether the point is inside.
#[test]
fn every_exact_flat_faced_primitive_measures_as_its_mesh() {
    let mut rng = Rng(0x51de);
    let mut failures = Vec::new();
    let mut measured = 0;
    for (call, p) in primitives(&mut rng) {
        let (f, _, exact) = p.visit(Functions);
        if !exact || p.facets() != Facets::Exact {
            continue;
        }
        let Tessellation::Triangles(_, make) = p.tessellate(Resolution { rings: 8, circle: 16 }) else { continue };
        let mesh = make();
        let size = p.sphere_radius().unwrap_or(1.0);
        for _ in 0..2000 {
            let x = DVec3::new(rng.f32() as f64 - 0.5, rng.f32() as f64 - 0.5, rng.f32() as f64 - 0.5) * (3.0 * size);
            let brute = mesh
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                    nearest_on_triangle(x, a, b, c).distance(x)
                })
                .fold(f64::INFINITY, f64::min);
            let d = f(x.as_vec3a()) as f64;
            if (d.abs() - brute).abs() > 1e-3 * size.max(1.0) {
                failures.push(format!("{call}: at {x} the distance is {d}, the mesh is {brute} away"));
                break;
            }
        }
        measured += 1;
    }
    assert!(measured >= 4 * 6, "only {measured} flat-faced primitives measured");
    crate::support::finish(failures);
}
