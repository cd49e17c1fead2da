//! Isosurface extraction: dual contouring on an adaptive octree, refined by the error
//! it measures.
//!
//! 1. The cells ([`super::tree`]): split where the surface may pass, down to the finest
//!    cell everywhere ([`Plan::Uniform`]) or only as far as the surface's shape needs
//!    under a tolerance ([`Plan::Within`]).
//! 2. The crossed edges of the subdivision with the leaves around each
//!    ([`super::dual`]), and the mesh on them ([`super::contour`]): a vertex per sheet of
//!    surface in a leaf, placed by a quadric error function on the tangent planes at its
//!    crossings (`mesh::qef`, so that a box keeps its edges and corners), a polygon per
//!    crossed edge. Closed and manifold by construction, at every tolerance.
//! 3. Under a tolerance, the mesh is measured against the field on every triangle
//!    ([`super::deviation`]); the leaves of triangles found farther than the tolerance
//!    are split, and steps 2–3 repeat ([`ROUNDS`] times at most).
//!
//! Memory grows with the leaves near the surface (what the error needs), not with the
//! box: what the field was found to be is kept once ([`super::samples`]) for every round.

use glam::Vec3A;
use rayon::prelude::*;

use super::deviation::{self, MeasuredDeviation};
use super::octree::Grid;
use super::samples::{IsoField, Samples, ENTRY_BYTES};
use super::tree::{Plan, TooMany, Tree};
use crate::geom::TriMesh;
use crate::sdf::Surf;

/// Bytes a leaf takes at the peak of extraction (its share of the tree, of the sampled
/// values and crossings, its edges' polygon records, its vertices and triangles): a
/// memory budget allows its bytes over this many leaves.
pub const CELL_BYTES: u64 = 400;

/// Most leaves one isosurface may refine when no budget says otherwise (about 1.6 GB of
/// working memory).
pub const MAX_CELLS: usize = 4_000_000;

/// The share of the tolerance the sampled points must meet: between them a triangle can
/// bulge a little farther where the surface bends or creases. On the gyroid sheet of
/// `benches/scenes/gyroid-sheet.scn` at tolerance 0.01, measured at 15 points a
/// triangle (`cargo run --release --example deviation`), a whole share let points reach
/// 1.29 of the tolerance and 0.8 kept them at 0.88 (on `e8ac92c`); 0.75 left the
/// farthest point at 0.002 where it was, for 5 % more triangles. The ladder on today's
/// mesher is `scripts/mesh-error-table.sh`'s, in docs/performance.md.
pub const SAMPLED_SHARE: f64 = 0.8;

/// Rounds of measuring and splitting under a tolerance.
pub const ROUNDS: usize = 8;

/// Why an isosurface could not be made.
#[derive(Clone, Debug, PartialEq)]
pub enum IsoError {
    /// The surface would refine more leaves than the limit.
    TooManyCells {
        /// Leaves it is expected to refine.
        cells: f64,
        /// The smallest finest cell expected to stay within the limit.
        min_cell: f64,
    },
    /// No sign change was found: the shape is thinner than a cell everywhere (or empty).
    NoSurface,
}

/// An extracted isosurface.
#[derive(Debug)]
pub struct Surface {
    /// The triangles, closed, manifold and wound outward.
    pub mesh: TriMesh,
    /// The leaves the mesh was made on.
    pub leaves: usize,
    /// The smallest and largest leaf that holds a vertex.
    pub cells: (f64, f64),
    /// The deviation from the surface, measured on every triangle (under a tolerance).
    pub deviation: Option<MeasuredDeviation>,
    /// Where the rounds ended with samples farther than the whole tolerance.
    pub unmet: Option<Unmet>,
}

/// Triangles and vertices left with a sample farther than the whole tolerance (not only
/// its sampled share) when the rounds ended or the leaves under them could not be split.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unmet {
    /// How many triangles and vertices.
    pub places: usize,
    /// The farthest sample's distance in tolerances (above 1).
    pub worst: f64,
}

/// The gradient of a distance bound by central differences on a tetrahedron, for a
/// field that has no gradient of its own (tests, plain closures).
pub fn by_differences(dist: &(dyn Fn(Vec3A) -> f32 + Sync), h: f32) -> impl Fn(Vec3A) -> Surf + Sync + '_ {
    move |p: Vec3A| {
        let g: Vec3A =
            [Vec3A::new(1.0, -1.0, -1.0), Vec3A::new(-1.0, -1.0, 1.0), Vec3A::new(-1.0, 1.0, -1.0), Vec3A::ONE]
                .into_iter()
                .map(|k| k * dist(p + k * h))
                .sum();
        Surf { d: dist(p), g, mat: 0 }
    }
}

/// Extracts the zero set of `dist` on every cell of `grid` (its gradient by
/// differences), refining at most [`MAX_CELLS`] leaves.
pub fn extract(dist: &(dyn Fn(Vec3A) -> f32 + Sync), grid: &Grid) -> Result<Surface, IsoError> {
    let surf = by_differences(dist, (grid.cell * 0.01) as f32);
    extract_within(IsoField { dist, surf: &surf }, grid, &Plan::Uniform, MAX_CELLS)
}

/// Extracts the zero set of `field` on `grid` as `plan` says, refining at most
/// `max_cells` leaves.
///
/// Long because it is the one sequence of the extraction: the cells, their crossed
/// edges (mended where rounding left a cell empty), the mesh, and the rounds of
/// measuring and splitting.
pub fn extract_within(field: IsoField, grid: &Grid, plan: &Plan, max_cells: usize) -> Result<Surface, IsoError> {
    let too_many = |cells: f64| IsoError::TooManyCells {
        cells,
        // A surface's cell count goes with the inverse square of the cell.
        min_cell: grid.cell * (cells / max_cells as f64).sqrt(),
    };
    let samples = Samples::new(field, *grid, matches!(plan, Plan::Within { .. }));
    let mut tree = Tree::build(*grid, &samples, plan, max_cells).map_err(|TooMany::Cells(c)| too_many(c))?;
    let mut rounds = 0;
    loop {
        // Ask for the working memory's address space before using it: a cap (ulimit -v)
        // or a strict overcommit policy refuses here, as a too-fine grid, not by
        // aborting midway.
        if !crate::source::system_gives((tree.leaf_count() as u64).saturating_mul(CELL_BYTES)) {
            return Err(too_many(max_cells as f64 * 2.0));
        }
        let edges = loop {
            let found = super::dual::crossed(&tree, &samples);
            if found.empties.is_empty() {
                break found.edges;
            }
            for &(depth, index) in &found.empties {
                tree.fill(depth as usize, index);
            }
            tree.renumber(&samples);
        };
        if edges.is_empty() {
            return Err(IsoError::NoSurface);
        }
        let contoured = super::contour::contour(&tree, &samples, &edges);
        let mut mesh = contoured.mesh;
        let sizes: Vec<f64> =
            contoured.leaf_of.iter().map(|&l| grid.cell * f64::from(1u32 << tree.leaf(l).1)).collect();
        super::unfold::unfold(&mut mesh, &contoured.mass, &sizes);
        let cells = sizes.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &s| (lo.min(s), hi.max(s)));
        let done = |mesh: TriMesh, deviation: Option<MeasuredDeviation>, unmet: Option<Unmet>| Surface {
            mesh,
            leaves: tree.leaf_count(),
            cells,
            deviation,
            unmet,
        };
        let Plan::Within { deviation: bound, .. } = plan else {
            return Ok(done(mesh, None, None));
        };
        let found = deviation::measure(&mesh, field, &|p| SAMPLED_SHARE * bound.at(p));
        // The leaves of every vertex of a triangle found too far, and of every vertex
        // found too far: the finest ones cannot be split.
        let mut split: Vec<u32> = found
            .triangles
            .par_iter()
            .flat_map_iter(|&(t, _)| mesh.triangles[t as usize].map(|v| contoured.leaf_of[v as usize]))
            .chain(found.vertices.par_iter().map(|&(v, _)| contoured.leaf_of[v as usize]))
            .filter(|&l| tree.leaf(l).1 > 0)
            .collect();
        split.par_sort_unstable();
        split.dedup();
        if split.is_empty() || rounds == ROUNDS {
            return Ok(done(mesh, Some(found.measured), unmet(&found)));
        }
        tree.split(&split, &samples, plan, max_cells).map_err(|TooMany::Cells(c)| too_many(c))?;
        rounds += 1;
    }
}

/// The triangles and vertices `found` over the sampled share of the tolerance that lie
/// farther than the whole tolerance, if any do.
fn unmet(found: &deviation::Found) -> Option<Unmet> {
    let (places, worst) = found
        .triangles
        .iter()
        .chain(&found.vertices)
        .map(|&(_, r)| r * SAMPLED_SHARE)
        .filter(|&r| r > 1.0)
        .fold((0, 1.0f64), |(n, worst), r| (n + 1, worst.max(r)));
    (places > 0).then_some(Unmet { places, worst })
}

/// The memory a mesh of `leaves` leaves takes while it is made, by [`CELL_BYTES`]; the
/// samples' tables are counted in it.
pub fn working_bytes(leaves: usize) -> u64 {
    (leaves as u64).saturating_mul(CELL_BYTES).max(ENTRY_BYTES)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tree::Deviation;
    use glam::DVec3;

    fn grid(r: f64, cell: f64) -> Grid {
        Grid::new(DVec3::splat(-r), DVec3::splat(r), cell).unwrap()
    }

    #[test]
    fn sphere_isosurface_is_closed_outward_and_accurate() {
        let f = |p: Vec3A| p.length() - 1.0;
        let m = extract(&f, &grid(1.0, 0.05)).expect("surface").mesh;
        assert_eq!(m.open_edges(), (0, 0), "open edges");
        let v = m.signed_volume();
        assert!((v - 4.0 / 3.0 * std::f64::consts::PI).abs() < 0.01, "volume {v}");
        for p in &m.positions {
            assert!((p.length() - 1.0).abs() < 0.005, "vertex off the surface: {p}");
        }
    }

    /// A box keeps its corners and edges: every vertex lies on the box's surface, and
    /// the eight corners are vertices.
    #[test]
    fn box_keeps_edges_and_corners() {
        let half = DVec3::new(0.6, 0.4, 0.5);
        let f = move |p: Vec3A| {
            let q = p.as_dvec3().abs() - half;
            (q.max(DVec3::ZERO).length() + q.max_element().min(0.0)) as f32
        };
        let m = extract(&f, &Grid::new(-half, half, 0.07).unwrap()).expect("surface").mesh;
        assert_eq!(m.open_edges(), (0, 0), "open edges");
        for p in &m.positions {
            let q = p.abs() - half;
            let d = q.max(DVec3::ZERO).length() + q.max_element().min(0.0);
            assert!(d.abs() < 1e-4, "vertex {p} is {d} off the box");
        }
        for n in 0..8 {
            let corner = half * DVec3::new([-1.0, 1.0][n & 1], [-1.0, 1.0][(n >> 1) & 1], [-1.0, 1.0][n >> 2]);
            let nearest = m.positions.iter().map(|p| (*p - corner).length()).fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-4, "corner {corner} is {nearest} from the nearest vertex");
        }
        let v = m.signed_volume();
        assert!((v - 8.0 * half.x * half.y * half.z).abs() < 1e-3, "volume {v}");
    }

    /// Two spheres touching at a point, and a thin neck: the ambiguous faces there still
    /// give a closed, manifold mesh.
    #[test]
    fn ambiguous_faces_stay_manifold() {
        for gap in [0.0, 0.01, -0.01, 0.031] {
            let f = move |p: Vec3A| {
                let a = (p - Vec3A::new(-0.5 - gap, 0.0, 0.0)).length() - 0.5;
                let b = (p - Vec3A::new(0.5, 0.0, 0.0)).length() - 0.5;
                a.min(b)
            };
            let g = Grid::new(DVec3::new(-1.1, -0.6, -0.6), DVec3::new(1.1, 0.6, 0.6), 0.0625).unwrap();
            let m = extract(&f, &g).expect("surface").mesh;
            assert_eq!(m.open_edges(), (0, 0), "gap {gap}: open or doubled edges");
        }
    }

    /// Connected components of a mesh, by shared vertices.
    fn components(m: &TriMesh) -> usize {
        let mut parent: Vec<usize> = (0..m.positions.len()).collect();
        for t in &m.triangles {
            for k in 1..3 {
                crate::mesh::cube::join(&mut parent, t[0] as usize, t[k] as usize);
            }
        }
        let used: std::collections::BTreeSet<usize> =
            m.triangles.iter().flatten().map(|&v| crate::mesh::cube::root(&mut parent, v as usize)).collect();
        used.len()
    }

    /// Many small disjoint parts (a 5×5×5 lattice of spheres 2.5 cells across, spread
    /// over a box 80 cells wide) each come out as their own closed piece.
    #[test]
    fn many_small_parts_are_all_kept() {
        let centre = |i: usize| DVec3::new((i % 5) as f64, ((i / 5) % 5) as f64, (i / 25) as f64) * 0.4 - 0.8;
        let f = move |p: Vec3A| {
            let p = p.as_dvec3();
            (0..125).map(|i| (p - centre(i)).length() - 0.025).fold(f64::INFINITY, f64::min) as f32
        };
        let m = extract(&f, &Grid::new(DVec3::splat(-0.83), DVec3::splat(0.83), 0.02).unwrap()).expect("surface").mesh;
        assert_eq!(m.open_edges(), (0, 0), "open or doubled edges");
        assert_eq!(components(&m), 125, "every sphere is its own piece");
        assert!(m.signed_volume() > 0.0, "wound outward");
    }

    #[test]
    fn limits_are_reported() {
        let f = |p: Vec3A| p.length() - 1.0;
        assert!(matches!(extract(&f, &grid(1.0, 2e-4)), Err(IsoError::TooManyCells { .. })));
        let thin = |p: Vec3A| p.length() - 1e-4;
        assert_eq!(extract(&thin, &grid(1.0, 0.3)).err(), Some(IsoError::NoSurface));
    }

    /// Only what lies beyond the whole tolerance, not its sampled share, is unmet: a
    /// triangle at 1.1 shares is within it, one at 1.3 and a vertex at 1.5 are not.
    #[test]
    fn unmet_counts_what_passes_the_whole_tolerance() {
        let found = |triangles: Vec<(u32, f64)>, vertices: Vec<(u32, f64)>| deviation::Found {
            measured: MeasuredDeviation::default(),
            triangles,
            vertices,
        };
        let u = unmet(&found(vec![(0, 1.1), (1, 1.3)], vec![(2, 1.5)])).expect("unmet");
        assert_eq!(u.places, 2);
        assert!((u.worst - 1.5 * SAMPLED_SHARE).abs() < 1e-12, "{u:?}");
        assert_eq!(unmet(&found(vec![(0, 1.1)], vec![(1, 1.2)])), None);
    }

    /// Under a tolerance a sphere is meshed with cells far coarser than the finest, and
    /// every sample of every triangle lies within the tolerance of the surface (checked
    /// here again with the exact distance, at 66 points a triangle).
    #[test]
    fn a_tolerance_is_met_with_coarse_cells() {
        let dist = |p: Vec3A| p.length() - 1.0;
        let surf = |p: Vec3A| Surf { d: p.length() - 1.0, g: p.normalize_or_zero(), mat: 0 };
        for t in [1e-2, 1e-3] {
            let g = grid(1.0, t / 2.0);
            let plan =
                Plan::Within { deviation: Deviation::absolute(t), coarsest: g.levels.saturating_sub(2), parts: vec![] };
            let s = extract_within(IsoField { dist: &dist, surf: &surf }, &g, &plan, MAX_CELLS).expect("surface");
            assert_eq!(s.mesh.open_edges(), (0, 0), "t {t}");
            let d = s.deviation.expect("measured");
            assert_eq!(d.over, 0, "t {t}: {d:?}");
            assert!(s.cells.1 > 8.0 * g.cell, "t {t}: leaves {:?} against the finest {}", s.cells, g.cell);
            let worst = s
                .mesh
                .triangles
                .iter()
                .flat_map(|tri| {
                    let [a, b, c] = tri.map(|i| s.mesh.positions[i as usize]);
                    (0..=10).flat_map(move |i| {
                        (0..=10 - i).map(move |j| {
                            let (u, v) = (i as f64 / 10.0, j as f64 / 10.0);
                            (a + (b - a) * u + (c - a) * v).length() - 1.0
                        })
                    })
                })
                .fold(0.0f64, |m, d| m.max(d.abs()));
            assert!(worst <= t, "t {t}: a point of the mesh is {worst} from the sphere");
        }
    }
}
