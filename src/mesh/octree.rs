//! Where a surface can pass: an octree over a shape's padded bounds, refined only in
//! cells that the surface may cross, down to the finest cell.
//!
//! The distance functions scnc builds are bounds: `|f(p)|` never exceeds the distance
//! from `p` to the surface. So a cube whose centre has `|f| > ` its half-diagonal holds
//! no surface, and neither does any cube inside it; every other cube is split. The cells
//! left at the finest level are a thin shell around the surface: their number grows
//! with the surface's area over the cell's, not with the bounding volume over it, which
//! is what lets a shape of many small parts be meshed at a cell that sees every part.

use glam::{DVec3, Vec3A};
use rayon::prelude::*;

/// Bits of each coordinate in a key: a grid may be 2^20 cells on a side (its points,
/// one more than its cells, still fit).
const BITS: u32 = 21;

/// The most levels of refinement, so that grid points fit in a key (21 bits a coordinate).
pub const MAX_LEVELS: u32 = BITS - 1;

/// Nodes expanded between two checks of the cell limit: the limit is overshot by at
/// most eight times this many cells before it is noticed.
const CHUNK: usize = 1 << 15;

/// A cell or grid point by its integer coordinates, packed x-major, so that keys sort
/// by x, then y, then z.
pub fn key([i, j, k]: [u64; 3]) -> u64 {
    (i << (2 * BITS)) | (j << BITS) | k
}

/// The coordinates of a key.
pub fn unkey(key: u64) -> [u64; 3] {
    let mask = (1 << BITS) - 1;
    [key >> (2 * BITS), (key >> BITS) & mask, key & mask]
}

/// The finest grid of a mesh: points `lo + (i, j, k)·cell` for `0 ≤ i, j, k ≤ 2^levels`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// The lowest point.
    pub lo: DVec3,
    /// The side of a finest cell.
    pub cell: f64,
    /// Levels of refinement: the root cube is `2^levels` cells on a side.
    pub levels: u32,
}

impl Grid {
    /// The grid of cells of side `cell` over `[min, max]` padded by a cell on every side
    /// (so that the surface crosses no edge on the grid's boundary); `Err` with the cells
    /// a side would need when that is more than a key can hold.
    pub fn new(min: DVec3, max: DVec3, cell: f64) -> Result<Grid, f64> {
        let lo = min - cell;
        let across = ((max + cell - lo) / cell).max_element().ceil().max(1.0);
        if !across.is_finite() || across > (1u64 << MAX_LEVELS) as f64 {
            return Err(across);
        }
        let levels = (across as u64).next_power_of_two().trailing_zeros();
        Ok(Grid { lo, cell, levels })
    }

    /// The grid point at integer coordinates.
    pub fn point(&self, [i, j, k]: [u64; 3]) -> DVec3 {
        self.lo + DVec3::new(i as f64, j as f64, k as f64) * self.cell
    }

    /// The finest cells whose cube the surface of `f` may cross, sorted by key, found by
    /// refining in parallel (the same cells for any thread count). `Err` with the number
    /// of cells the finest level is projected to have, once more than `max` are found.
    pub fn surface_cells(&self, f: &(dyn Fn(Vec3A) -> f32 + Sync), max: usize) -> Result<Vec<u64>, f64> {
        // Nodes of the current level by coordinates in units of that level's cube.
        let mut nodes = vec![[0u64; 3]];
        for level in (0..self.levels).rev() {
            let size = self.cell * (1u64 << level) as f64;
            let keep = |c: [u64; 3]| {
                let centre = self.lo + (DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) + 0.5) * size;
                let half_diagonal = size * 0.5 * 3f64.sqrt();
                // f is evaluated in f32: a margin for its rounding at this distance from
                // the origin, so that no cube holding a crossing is dropped.
                let margin = 1e-3 * half_diagonal + 1e-5 * (centre.length() + half_diagonal);
                (f(centre.as_vec3a()).abs() as f64) <= half_diagonal + margin
            };
            let mut next = Vec::with_capacity(nodes.len() * 4);
            let mut done = 0;
            for chunk in nodes.chunks(CHUNK) {
                let children: Vec<[u64; 3]> = chunk
                    .par_iter()
                    .flat_map_iter(|&[i, j, k]| {
                        (0..8u64)
                            .map(move |c| [2 * i + (c & 1), 2 * j + ((c >> 1) & 1), 2 * k + (c >> 2)])
                            .filter(|&c| keep(c))
                    })
                    .collect();
                next.extend(children);
                done += chunk.len();
                if next.len() > max {
                    // A surface's cells multiply by four a level.
                    let at_this_level = next.len() as f64 * nodes.len() as f64 / done as f64;
                    return Err(at_this_level * 4f64.powi(level as i32));
                }
            }
            nodes = next;
        }
        let mut cells: Vec<u64> = nodes.into_iter().map(key).collect();
        cells.par_sort_unstable();
        Ok(cells)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Keys round-trip and sort x-major.
    #[test]
    fn keys_round_trip_and_sort() {
        let c = [(1 << 20) + 3, 7, (1 << 20) - 1];
        assert_eq!(unkey(key(c)), c);
        assert!(key([1, 0, 0]) > key([0, (1 << 20) + 1, (1 << 20) + 1]));
    }

    /// The refined cells are exactly the finest cells a dense scan keeps (the pruning
    /// drops only cubes with no surface), and they form a shell around a sphere.
    #[test]
    fn refinement_keeps_every_cell_the_surface_may_cross() {
        let f = |p: Vec3A| p.length() - 0.7;
        let grid = Grid::new(DVec3::splat(-0.7), DVec3::splat(0.7), 0.05).unwrap();
        assert_eq!(grid.levels, 5);
        let cells = grid.surface_cells(&f, usize::MAX).unwrap();
        let n = 1u64 << grid.levels;
        let mut dense = Vec::new();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let centre = grid.point([i, j, k]) + grid.cell * 0.5;
                    if ((centre.length() - 0.7).abs()) <= grid.cell * 0.5 * 3f64.sqrt() {
                        dense.push(key([i, j, k]));
                    }
                }
            }
        }
        for d in &dense {
            assert!(cells.binary_search(d).is_ok(), "cell {:?} crossing the surface was pruned", unkey(*d));
        }
        assert!(cells.len() < dense.len() * 2, "{} cells kept for {} near the surface", cells.len(), dense.len());
        assert!(grid.surface_cells(&f, 100).is_err(), "the limit holds");
    }
}
