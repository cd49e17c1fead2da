//! Isosurface extraction by surface nets: one vertex per grid cell that the surface
//! crosses (the mean of the crossings on its edges), one quad per grid edge with a sign
//! change, joining the four cells around it. Every grid edge is shared by exactly the
//! cells that emit its quad, so the result is closed when the grid encloses the surface
//! (it is padded by a cell on every side). Sharp features are rounded to about a cell,
//! no worse than marching cubes.

use glam::{DVec3, Vec3A};
use rayon::prelude::*;

use super::TriMesh;

/// Most grid cells one isosurface may sample.
pub const MAX_CELLS: u64 = 16_000_000;

/// Why an isosurface could not be made.
#[derive(Clone, Debug, PartialEq)]
pub enum IsoError {
    /// The grid would need more cells than [`MAX_CELLS`].
    TooManyCells {
        /// Cells needed.
        cells: u64,
        /// The smallest cell size within the limit.
        min_cell: f64,
    },
    /// No sign change was found: the shape is thinner than a cell everywhere (or empty).
    NoSurface,
}

/// Extracts the zero set of `f` inside `[min, max]` on a grid of cubes of side `cell`.
pub fn extract(f: &(dyn Fn(Vec3A) -> f32 + Sync), min: DVec3, max: DVec3, cell: f64) -> Result<TriMesh, IsoError> {
    let lo = min - cell;
    let size = (max + cell) - lo;
    let dims = (size / cell).ceil().max(DVec3::ONE);
    let cells = dims.x * dims.y * dims.z;
    if !cells.is_finite() || cells > MAX_CELLS as f64 {
        let min_cell = (size.x * size.y * size.z / MAX_CELLS as f64).cbrt();
        return Err(IsoError::TooManyCells { cells: cells.min(u64::MAX as f64) as u64, min_cell });
    }
    let (nx, ny, nz) = (dims.x as usize, dims.y as usize, dims.z as usize);
    let (px, py) = (nx + 1, ny + 1);
    let point = |i: usize, j: usize, k: usize| lo + DVec3::new(i as f64, j as f64, k as f64) * cell;
    // Samples at grid points, one z-slice per task (deterministic order).
    let values: Vec<f32> = (0..=nz)
        .into_par_iter()
        .flat_map_iter(|k| {
            (0..py)
                .flat_map(move |j| (0..px).map(move |i| (i, j, k)))
                .map(|(i, j, k)| f(point(i, j, k).as_vec3a()))
                .collect::<Vec<_>>()
        })
        .collect();
    let at = |i: usize, j: usize, k: usize| values[i + px * (j + py * k)];

    const NONE: u32 = u32::MAX;
    let mut cell_vertex = vec![NONE; nx * ny * nz];
    let mut mesh = TriMesh::default();
    const CORNERS: [(usize, usize, usize); 8] =
        [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 1)];
    const EDGES: [(usize, usize); 12] =
        [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let v: [f32; 8] = CORNERS.map(|(a, b, c)| at(i + a, j + b, k + c));
                let inside = v.iter().filter(|x| **x < 0.0).count();
                if inside == 0 || inside == 8 {
                    continue;
                }
                let mut sum = DVec3::ZERO;
                let mut n = 0;
                for (a, b) in EDGES {
                    if (v[a] < 0.0) != (v[b] < 0.0) {
                        let t = (v[a] / (v[a] - v[b])) as f64;
                        let (ca, cb) = (CORNERS[a], CORNERS[b]);
                        let pa = DVec3::new(ca.0 as f64, ca.1 as f64, ca.2 as f64);
                        let pb = DVec3::new(cb.0 as f64, cb.1 as f64, cb.2 as f64);
                        sum += pa + (pb - pa) * t.clamp(0.0, 1.0);
                        n += 1;
                    }
                }
                cell_vertex[i + nx * (j + ny * k)] = mesh.positions.len() as u32;
                mesh.positions.push(point(i, j, k) + sum / n as f64 * cell);
            }
        }
    }
    let cv = |i: usize, j: usize, k: usize| cell_vertex[i + nx * (j + ny * k)];
    // Each interior grid edge with a sign change gets a quad of the four cells around it,
    // ordered counter-clockwise about the edge's axis when the inside is at the low end.
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let here = at(i, j, k) < 0.0;
                for axis in 0..3 {
                    let (di, dj, dk) = [(1, 0, 0), (0, 1, 0), (0, 0, 1)][axis];
                    if i + di > nx || j + dj > ny || k + dk > nz {
                        continue;
                    }
                    if here == (at(i + di, j + dj, k + dk) < 0.0) {
                        continue;
                    }
                    // The two other axes in cyclic order (u, v) = (axis+1, axis+2).
                    let idx = [i, j, k];
                    let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
                    if idx[u] == 0 || idx[w] == 0 {
                        continue;
                    }
                    let cell = |du: usize, dw: usize| {
                        let mut c = idx;
                        c[u] = idx[u] - 1 + du;
                        c[w] = idx[w] - 1 + dw;
                        (c[0] < nx && c[1] < ny && c[2] < nz).then(|| cv(c[0], c[1], c[2]))
                    };
                    let (Some(a), Some(b), Some(c), Some(d)) = (cell(0, 0), cell(1, 0), cell(1, 1), cell(0, 1)) else {
                        continue;
                    };
                    if [a, b, c, d].contains(&NONE) {
                        continue;
                    }
                    if here {
                        mesh.triangles.push([a, b, c]);
                        mesh.triangles.push([a, c, d]);
                    } else {
                        mesh.triangles.push([a, c, b]);
                        mesh.triangles.push([a, d, c]);
                    }
                }
            }
        }
    }
    if mesh.triangles.is_empty() {
        return Err(IsoError::NoSurface);
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_isosurface_is_closed_outward_and_accurate() {
        let f = |p: Vec3A| p.length() - 1.0;
        let m = extract(&f, DVec3::splat(-1.0), DVec3::splat(1.0), 0.05).expect("surface");
        assert_eq!(m.open_edges().0, 0, "open edges");
        let v = m.signed_volume();
        assert!((v - 4.0 / 3.0 * std::f64::consts::PI).abs() < 0.05, "volume {v}");
        for p in &m.positions {
            assert!((p.length() - 1.0).abs() < 0.05, "vertex off the surface: {p}");
        }
    }

    #[test]
    fn limits_are_reported() {
        let f = |p: Vec3A| p.length() - 1.0;
        assert!(matches!(extract(&f, DVec3::splat(-1.0), DVec3::splat(1.0), 1e-4), Err(IsoError::TooManyCells { .. })));
        let thin = |p: Vec3A| p.length() - 1e-4;
        assert_eq!(extract(&thin, DVec3::splat(-1.0), DVec3::splat(1.0), 0.3), Err(IsoError::NoSurface));
    }
}
