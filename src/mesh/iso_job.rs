//! An isosurface made into a mesh job: the cell a detail level stands for, the
//! extraction within the memory budget, each triangle's material, and the warnings of
//! what the grid lost (parts, volume), each with the cell that keeps it.

use glam::{DAffine3, Vec3A};
use rayon::prelude::*;

use super::samples::IsoField;
use super::tree::{Deviation, Plan};
use super::{isosurface, octree, parts, IsoAccuracy, MeshJob, Normals};
use crate::diag::{codes, Diagnostic};
use crate::geom::TriMesh;
use crate::ir::{self, Shape, ShapeKind};
use crate::sdf::Builder;
use crate::span::Span;
use crate::trace::MaterialTable;

/// The cell of an isosurface made at `rings` of detail: a 1/(4·rings) fraction of the
/// shape's bounding diameter `across`.
pub(super) fn detail_cell(across: f64, rings: f64) -> f64 {
    across / (4.0 * rings)
}

/// The lowest detail whose cell ([`detail_cell`]) is at most `cell`.
fn detail_for(across: f64, cell: f64) -> f64 {
    (across / (4.0 * cell)).ceil()
}

/// A positive length to three significant digits, as people read it.
pub(crate) fn approx(x: f64) -> String {
    let scale = 10f64.powi((3 - x.abs().log10().ceil() as i32).clamp(0, 12));
    short((x * scale).round() / scale)
}

/// A byte count as people read it: GiB or MiB.
fn bytes_name(b: u64) -> String {
    if b >= 1 << 30 {
        format!("{:.1} GiB", b as f64 / (1u64 << 30) as f64)
    } else {
        format!("{} MiB", b >> 20)
    }
}

/// A count as people say it: millions above a million, powers of ten above a billion.
fn millions(n: f64) -> String {
    if n >= 1e9 {
        format!("{n:.1e}")
    } else if n >= 1e6 {
        format!("{:.1} million", n / 1e6)
    } else {
        format!("{}", n.round())
    }
}

/// A size as people write it: exponent form when it is huge.
fn short(x: f64) -> String {
    if x.abs() >= 1e6 {
        format!("{x:e}")
    } else {
        ir::dump_num(x)
    }
}

pub(super) fn unbounded(span: Span) -> Diagnostic {
    Diagnostic::error(codes::LOWERING, span, "cannot tessellate an unbounded shape", "this shape has no finite extent")
        .with_note("an isosurface needs finite bounds; only a bare `plane` is meshed as a large square")
        .with_hint("give a `field` its `bounds = [[x0, y0, z0], [x1, y1, z1]]`, or intersect the shape with a `box`")
}

/// Where an isosurface's cell size came from, so a failure can say what to change.
#[derive(Clone, Copy)]
pub(super) enum CellFrom {
    /// `mesh isosurface(…, cell = …)`.
    Scene,
    /// `--detail` in mesh mode.
    Detail,
    /// `--tolerance`: the cells follow the error.
    Tolerance,
}

/// How an isosurface is sampled and placed.
pub(super) struct Iso {
    /// Render from the grid's frame: where the grid is laid out.
    pub(super) grid: DAffine3,
    /// Render from the grid's frame, applied to the vertices.
    pub(super) place: DAffine3,
    /// Material of parts that have none.
    pub(super) material: u32,
    /// Cell size in the grid's units: every cell's, or under a tolerance the coarsest
    /// the detail's cell would have been (the finest then follows the tolerance).
    pub(super) cell: f64,
    /// The tolerance the mesh must meet, in the grid's frame: cells follow the error.
    pub(super) deviation: Option<Deviation>,
    /// Interpolated normals.
    pub(super) smooth: bool,
    /// What set `cell`, for the hint of a failure.
    pub(super) from: CellFrom,
    /// Most cells it may refine: what the memory budget has left, at
    /// [`isosurface::CELL_BYTES`] a cell.
    pub(super) max_cells: usize,
    /// Asked at every sample: once the lowering is not wanted, every sample reads as far
    /// outside, so the extraction runs out of cells and ends within one evaluation.
    pub(super) wanted: Option<super::Wanted>,
}

/// An isosurface of `shape` sampled and placed as `iso` says, each triangle taking the
/// material of the shape's nearest part. The distance closures are temporary: they are
/// not part of the world's memory.
///
/// Long because it is one extraction's sequence: the cell checks, the grid, the extraction,
/// each triangle's material and the warnings of what the grid lost.
pub(super) fn isosurface_object(
    shape: &Shape,
    iso: Iso,
    span: Span,
    materials: &mut MaterialTable,
) -> Result<MeshJob, Diagnostic> {
    let Iso { grid, place, material, cell, deviation, smooth, from, max_cells, wanted } = iso;
    let bounds = ir::shape_bounds(shape).ok_or_else(|| unbounded(shape.span))?.transform(&grid);
    // A cell as large as the shape samples a few points around it: the mesh would be a
    // sliver or nothing, so it is refused like a grid that finds no surface.
    let across = (bounds.max - bounds.min).length();
    if cell >= across || cell.is_nan() {
        let d = Diagnostic::error(
            codes::LOWERING,
            span,
            "isosurface cell is as large as the shape",
            format!("cell {} for a shape {} across", short(cell), short(across)),
        )
        .with_note("a cell must be smaller than the shape for the grid to see it");
        return Err(match from {
            CellFrom::Scene => d.with_hint(format!("try `cell = {}` or less", ir::dump_num(across / 20.0))),
            CellFrom::Detail => d.with_hint("try a higher `--detail`"),
            CellFrom::Tolerance => d.with_hint("try a smaller `--tolerance`"),
        });
    }
    let (dist, mat) = Builder::new(materials).build(shape, grid, material);
    let dist: crate::sdf::Sdf = match wanted {
        Some(wanted) => std::sync::Arc::new(move |p| if wanted() { dist(p) } else { f32::MAX }),
        None => dist,
    };
    let too_fine = |cells: f64, min_cell: f64| {
        let d = Diagnostic::error(
            codes::LOWERING,
            span,
            "isosurface grid is too fine",
            format!("cell {} would refine about {} cells near the surface", ir::dump_num(cell), millions(cells)),
        )
        .with_note(format!(
            "an isosurface may refine at most {} cells: the memory limit's {} at {} bytes a cell",
            millions(max_cells as f64),
            bytes_name(max_cells as u64 * isosurface::CELL_BYTES),
            isosurface::CELL_BYTES
        ));
        match from {
            CellFrom::Scene => {
                d.with_hint(format!("try `cell = {}` or more", ir::dump_num((min_cell * 1.001 * 1e6).ceil() / 1e6)))
            }
            CellFrom::Detail => d.with_hint("try a lower `--detail`"),
            CellFrom::Tolerance => d.with_hint("try a larger `--tolerance`, or a larger `--memory-limit`"),
        }
    };
    let mut solid = Vec::new();
    parts::solid_parts(shape, grid, &mut solid);
    // Under a tolerance the finest cell is half the smallest bound over the box, and a
    // leaf may stay as coarse as an eighth of the shape.
    let finest = match deviation {
        Some(d) => (0.5 * d.over(bounds.min, bounds.max)).max(across * 1e-6).min(cell),
        None => cell,
    };
    let lattice = octree::Grid::new(bounds.min, bounds.max, finest).map_err(|side| {
        // Too many cells on a side for a key: a closed surface across the grid crosses
        // about as many cells as a cube's six faces, so the cell must grow for both the
        // key and the cell limit.
        let cells = 6.0 * side * side;
        let for_keys = finest * side / (1u64 << octree::MAX_LEVELS) as f64;
        let for_limit = finest * (cells / max_cells as f64).sqrt();
        too_fine(cells, for_keys.max(for_limit))
    })?;
    let plan = match deviation {
        Some(deviation) => Plan::Within {
            deviation,
            coarsest: (across / 8.0 / finest).log2().floor().clamp(0.0, f64::from(lattice.levels)) as u32,
            parts: solid.iter().map(|p| (p.min, p.max)).collect(),
        },
        None => Plan::Uniform,
    };
    let field = IsoField { dist: &*dist, surf: &*mat };
    let surface = isosurface::extract_within(field, &lattice, &plan, max_cells).map_err(|e| match e {
        isosurface::IsoError::TooManyCells { cells, min_cell } => too_fine(cells, min_cell),
        isosurface::IsoError::NoSurface => no_surface(shape, &*dist, (&bounds, across), finest, span, from),
    })?;
    let mesh = surface.mesh;
    let centroid = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        ((a + b + c) / 3.0).as_vec3a()
    };
    // One material over the whole shape is the common case, and a material lookup at a
    // smooth union's point walks its parts as a distance does: asked once, not per triangle.
    let (material, per_triangle) = if one_material(shape) {
        (mesh.triangles.first().map_or(material, |t| mat(centroid(t)).mat), None)
    } else {
        (material, Some(mesh.triangles.par_iter().map(|t| mat(centroid(t)).mat).collect()))
    };
    let lost = parts::lost(&solid, &lattice, &*dist);
    let warnings = lost_parts(&lost, solid.len(), span, finest, across, from)
        .into_iter()
        .chain(if lost.is_empty() { lost_volume(&mesh, &*dist, &bounds, span, finest, across, from) } else { None })
        .chain(surface.unmet.map(|u| unmet_tolerance(u, span, surface.cells.0)))
        .collect();
    let farthest = mesh.positions.par_iter().map(|p| f64::from(dist(p.as_vec3a()).abs())).reduce(|| 0.0, f64::max);
    Ok(MeshJob {
        mesh,
        xf: place,
        material,
        per_triangle,
        normals: if smooth { Normals::Vertex } else { Normals::Flat },
        convex: false,
        warnings,
        isosurface: Some(IsoAccuracy {
            cell: surface.cells.0,
            coarsest: surface.cells.1,
            farthest,
            deviation: surface.deviation,
        }),
    })
}

/// Whether every point of `shape` shows one material: it has no `with material` below
/// its top, where transforms and at most one material may stand.
fn one_material(shape: &Shape) -> bool {
    fn unpainted(s: &Shape) -> bool {
        !matches!(s.kind, ShapeKind::Paint { .. }) && s.children().iter().all(|c| unpainted(c))
    }
    match &shape.kind {
        ShapeKind::Transform { child, .. } => one_material(child),
        ShapeKind::Paint { child, .. } => unpainted(child),
        _ => unpainted(shape),
    }
}

/// The warning for parts an isosurface at `cell` lost, of `total` solid parts of a
/// shape `across` wide; `None` when none was.
/// Why an isosurface found no sign change, and what to do: a distance divided by so
/// steep a stated or estimated slope that f32 cannot tell its sign apart from zero, a
/// box grown level by level by nested domain operations (each takes the box of the
/// turned shape), or a shape thinner than a cell.
fn no_surface(
    shape: &Shape,
    dist: &dyn Fn(Vec3A) -> f32,
    (bounds, across): (&crate::geom::DAabb, f64),
    cell: f64,
    span: Span,
    from: CellFrom,
) -> Diagnostic {
    let (steepest, nesting) = steepness(shape);
    // The largest value over a coarse grid of the box: a distance divided away reads 0.
    let largest = (0..16 * 16 * 16)
        .map(|i| {
            let f = glam::DVec3::new((i % 16) as f64, (i / 16 % 16) as f64, (i / 256) as f64) / 15.0;
            dist((bounds.min + (bounds.max - bounds.min) * f).as_vec3a()).abs()
        })
        .fold(0.0f32, f32::max);
    let d = Diagnostic::error(
        codes::LOWERING,
        span,
        "isosurface found no surface",
        format!("no sign change on a grid of cell {} over a box {} across", short(cell), rounded(across)),
    );
    if largest < 1e-30 || steepest > 1e12 {
        return d
            .with_note(format!(
                "its distance is divided by a slope bound of {} (stated or estimated), which leaves f32 \
                 nothing to tell inside from outside: the largest value sampled is {largest:e}",
                short(steepest)
            ))
            .with_hint(
                "state a `lipschitz` near the field's true slope (a distance has 1); an estimate this large comes \
                 from a box grown by nesting: nest fewer levels",
            );
    }
    let d = if nesting >= 3 {
        d.with_note(format!(
            "{nesting} nested `twist`, `bend` and `polar` each take the box of the turned shape, so the box grows \
             level by level and the shape is much smaller than it; or the shape is thinner than a cell everywhere"
        ))
    } else {
        d.with_note(
            "the shape is thinner than a cell everywhere, or much smaller than its box, so the mesh would be empty",
        )
    };
    let (scene, detail, tolerance) = if nesting >= 3 {
        (
            "try a smaller `cell`, or nest fewer levels",
            "try a higher `--detail`, or nest fewer levels",
            "try a smaller `--tolerance`, or nest fewer levels",
        )
    } else {
        ("try a smaller `cell`", "try a higher `--detail`", "try a smaller `--tolerance`")
    };
    d.with_hint(match from {
        CellFrom::Scene => scene,
        CellFrom::Detail => detail,
        CellFrom::Tolerance => tolerance,
    })
}

/// `x` to four significant digits, in exponent form when large.
fn rounded(x: f64) -> String {
    if x.abs() >= 1e4 {
        format!("{x:.3e}")
    } else {
        ir::dump_num((x * 1e3).round() / 1e3)
    }
}

/// The steepest slope bound in `shape`'s tree, and the most domain operations that
/// turn it (`twist`, `bend`, `polar`) nested on one path.
fn steepness(shape: &Shape) -> (f64, usize) {
    use ir::{DomainOp, ShapeKind};
    let (own, turns) = match &shape.kind {
        ShapeKind::Field { lipschitz, .. } | ShapeKind::Displace { lipschitz, .. } => (lipschitz.value, 0),
        ShapeKind::Warp { lipschitz, domain_op, .. } => {
            let turns = matches!(domain_op, Some(DomainOp::Twist(_) | DomainOp::Bend(_) | DomainOp::Polar(_)));
            (lipschitz.value, usize::from(turns))
        }
        _ => (1.0, 0),
    };
    let (below, nested) =
        shape.children().iter().map(|c| steepness(c)).fold((1.0f64, 0), |a, b| (a.0.max(b.0), a.1.max(b.1)));
    (own.max(below), turns + nested)
}

fn lost_parts(
    lost: &[&parts::SolidPart],
    total: usize,
    span: Span,
    cell: f64,
    across: f64,
    from: CellFrom,
) -> Option<Diagnostic> {
    let smallest = lost.iter().min_by(|a, b| a.across().total_cmp(&b.across()))?;
    let plural = if lost.len() == 1 { "part was" } else { "parts were" };
    // A grid point lies inside any part at least twice the cell across.
    let needed = smallest.across() / 2.0;
    let d = Diagnostic::warning(
        codes::LOST_PARTS,
        span,
        format!("{} of {total} {plural} not meshed: smaller than the isosurface cell", lost.len()),
        format!("meshed at cell {}", approx(cell)),
    )
    .with_label(smallest.span, format!("the smallest lost part, {} across, is made here", approx(smallest.across())))
    .with_note("no grid point lies inside these parts, so the mesh has no surface there");
    Some(match from {
        CellFrom::Scene => d.with_hint(format!("try `cell = {}` or less", approx(needed))),
        CellFrom::Detail => {
            let rings = detail_for(across, needed);
            d.with_hint(format!("try `--detail {}` or a `--tolerance` below {}", short(rings), approx(needed / 2.0)))
        }
        CellFrom::Tolerance => d.with_hint(format!("try a `--tolerance` below {}", approx(needed / 2.0))),
    })
}

/// Samples of the shape's box that measure its volume for [`lost_volume`].
const VOLUME_SAMPLES: u32 = 1 << 16;

/// The warning for an isosurface that lost (or gained) much of its shape's volume; `None`
/// when the mesh's volume is within a tenth, plus four standard errors, of the volume
/// measured by sampling the shape at stratified points of its box. This is what finds a
/// field's sheet thinner than the cell, which no CSG part names: the grid misses it, so
/// the mesh has no surface there and the part-based check has nothing to point at.
fn lost_volume(
    mesh: &TriMesh,
    dist: &(dyn Fn(Vec3A) -> f32 + Sync),
    bounds: &ir::DAabb,
    span: Span,
    cell: f64,
    across: f64,
    from: CellFrom,
) -> Option<Diagnostic> {
    let size = bounds.max - bounds.min;
    let box_volume = size.x * size.y * size.z;
    if box_volume.is_nan() || box_volume <= 0.0 || box_volume.is_infinite() {
        return None;
    }
    // Jittered points of a 2^16-point lattice along a Weyl sequence: the same on every run.
    let inside = (0..VOLUME_SAMPLES)
        .into_par_iter()
        .filter(|&i| {
            let i = f64::from(i) + 0.5;
            let u = glam::DVec3::new(
                i * 0.754_877_666_246_692_7,
                i * 0.569_840_290_998_053_3,
                i / f64::from(VOLUME_SAMPLES),
            );
            let u = u - u.floor();
            dist((bounds.min + u * size).as_vec3a()) < 0.0
        })
        .count() as f64;
    let n = f64::from(VOLUME_SAMPLES);
    let fraction = inside / n;
    let sampled = fraction * box_volume;
    let error = (fraction * (1.0 - fraction) / n).sqrt() * box_volume;
    let meshed = mesh.signed_volume();
    if (meshed - sampled).abs() <= 0.1 * sampled + 4.0 * error {
        return None;
    }
    let d = Diagnostic::warning(
        codes::LOST_VOLUME,
        span,
        format!("the mesh holds {} of the shape's volume", percent(meshed / sampled)),
        format!(
            "meshed at cell {}: volume {} where samples of the shape find {}",
            approx(cell),
            approx(meshed),
            approx(sampled)
        ),
    )
    .with_note(
        "parts thinner than the cell (a thin shell, a field's sheet) fall between the grid's points and are left out",
    );
    Some(match from {
        CellFrom::Scene => d.with_hint(format!("try `cell = {}` or less", approx(cell / 2.0))),
        CellFrom::Detail => d.with_hint(format!(
            "try `--detail {}` or more, or a `--tolerance` below {}",
            short(detail_for(across, cell / 2.0)),
            approx(cell / 4.0)
        )),
        CellFrom::Tolerance => d.with_hint(format!("try a `--tolerance` below {}", approx(cell))),
    })
}

/// The warning for a mesh left farther than its tolerance in places when the rounds of
/// refinement ended (`isosurface::ROUNDS`) or the leaves there were the finest.
fn unmet_tolerance(u: isosurface::Unmet, span: Span, cell: f64) -> Diagnostic {
    let places = if u.places == 1 { "one place".to_string() } else { format!("{} places", u.places) };
    Diagnostic::warning(
        codes::TOLERANCE_UNMET,
        span,
        format!("the mesh lies up to {:.2}× the tolerance from the shape in {places}", u.worst),
        format!("meshed down to cell {}", approx(cell)),
    )
    .with_note(format!(
        "the leaves there were split for {} rounds or are the finest (half the tolerance): the surface bends or creases faster than they follow",
        isosurface::ROUNDS
    ))
    .with_hint("`--stats` gives the measured deviation; a smaller `--tolerance` meets this one there")
}

/// A ratio as a percentage people read: whole percents, or one decimal below 10 %.
fn percent(r: f64) -> String {
    let p = r * 100.0;
    if p.abs() < 10.0 {
        format!("{p:.1} %")
    } else {
        format!("{p:.0} %")
    }
}
