//! Lowering IR geometry to mesh objects: explicit `mesh …` objects, and shape objects
//! tessellated at a detail level (primitives by their generators, anything else by
//! isosurface, a plane as a square reaching the far limit). Failures are diagnostics
//! that point at the source.

use glam::{DAffine3, DVec3, Vec3A};
use rayon::prelude::*;

use super::{isosurface, obj, octree, parts, Detail, IsoAccuracy, MeshJob, Normals};
use crate::diag::{codes, Diagnostic};
use crate::geom::tessellate::count;
use crate::geom::{tessellate, TriMesh};
use crate::ir::{self, MeshSource, Shape, ShapeKind};
use crate::primitive::{Facets, Tessellation};
use crate::sdf::Builder;
use crate::source::Loader;
use crate::span::Span;
use crate::trace::MaterialTable;

/// Tessellates a shape object at `detail`: a primitive with a generator by it, a plane
/// as a square reaching the far limit, anything else as an isosurface.
pub fn tessellate(
    shape: &Shape,
    xf: DAffine3,
    detail: Detail,
    max_distance: f64,
    budget: &mut Budget,
    materials: &mut MaterialTable,
) -> Result<MeshJob, Diagnostic> {
    // Walk down through transforms and materials to what decides how it is made.
    let (mut node, mut xf, mut material) = (shape, xf, 0u32);
    loop {
        match &node.kind {
            ShapeKind::Transform { child, xf: inner } => {
                xf *= *inner;
                node = child;
            }
            ShapeKind::Paint { child, material: m } => {
                material = materials.intern(m, xf * child.placement());
                node = child;
            }
            ShapeKind::Primitive(_)
            | ShapeKind::Csg { .. }
            | ShapeKind::Round { .. }
            | ShapeKind::Shell { .. }
            | ShapeKind::Repeat { .. }
            | ShapeKind::Field { .. }
            | ShapeKind::Warp { .. }
            | ShapeKind::Displace { .. } => break,
        }
    }
    let made = match &node.kind {
        ShapeKind::Primitive(p) => p.tessellate(detail.resolution()),
        ShapeKind::Csg { .. }
        | ShapeKind::Round { .. }
        | ShapeKind::Shell { .. }
        | ShapeKind::Repeat { .. }
        | ShapeKind::Transform { .. }
        | ShapeKind::Paint { .. }
        | ShapeKind::Field { .. }
        | ShapeKind::Warp { .. }
        | ShapeKind::Displace { .. } => Tessellation::Isosurface,
    };
    match made {
        Tessellation::Triangles(triangles, make) => {
            budget.spend(triangles, shape.span)?;
            let mesh = make();
            // A curved primitive shades with its own normals: flat facets would bend
            // light facet by facet (glass magnifies a normal's error far beyond its
            // position's). A flat-faced one is exact as it is.
            let normals = match &node.kind {
                ShapeKind::Primitive(p) if matches!(p.facets(), Facets::Inscribed(_)) => {
                    Normals::Corners(p.corner_normals(&mesh))
                }
                _ => Normals::Flat,
            };
            // A generator's polytope is convex exactly when its shape is (tested for each);
            // isosurfaces (below) may dent even a convex shape, so they are never marked.
            Ok(MeshJob {
                mesh,
                xf,
                material,
                per_triangle: None,
                normals,
                convex: node.is_convex(),
                warnings: Vec::new(),
                isosurface: None,
            })
        }
        Tessellation::HalfSpace { normal, offset } => {
            budget.spend(tessellate::count::SQUARE, shape.span)?;
            // A square centred on the point of the plane nearest the camera, reaching the far limit.
            let inv = xf.inverse();
            let eye = inv.transform_point3(DVec3::ZERO);
            let foot = eye - normal * (normal.dot(eye) - offset);
            let up = if normal.y.abs() < 0.9 { DVec3::Y } else { DVec3::X };
            let u = normal.cross(up).normalize();
            let w = normal.cross(u);
            let frame = DAffine3::from_cols(u, normal, w, foot);
            // Scale by the inverse's stretch so the square reaches `max_distance` in render space.
            let reach = max_distance * inv.matrix3.to_cols_array().iter().fold(0.0f64, |a, x| a.max(x.abs())) * 2.0;
            let square = tessellate::square(reach.max(1.0));
            // Flat: a ray leaving its front never meets it again.
            Ok(MeshJob {
                mesh: square,
                xf: xf * frame,
                material,
                per_triangle: None,
                normals: Normals::Flat,
                convex: true,
                warnings: Vec::new(),
                isosurface: None,
            })
        }
        Tessellation::Isosurface => {
            // An isosurface of the subtree in render space, at a cell size that follows the
            // detail (a 1/(4·rings) fraction of the bounding diameter).
            let bounds = ir::shape_bounds(node).ok_or_else(|| unbounded(node.span))?.transform(&xf);
            let cell = detail_cell((bounds.max - bounds.min).length(), detail.rings() as f64);
            // Sampled in render space, so the vertices need no further placing.
            let iso = Iso {
                grid: xf,
                place: DAffine3::IDENTITY,
                material,
                cell,
                smooth: false,
                from: CellFrom::Detail,
                max_cells: budget.cells_allowed(),
            };
            let job = isosurface_object(node, iso, node.span, materials)?;
            budget.spend(job.mesh.triangles.len() as u64, shape.span)?;
            Ok(job)
        }
    }
}

/// Most triangles all meshes of one scene may have together (about 2.4 GB with BVHs).
pub const MAX_SCENE_TRIANGLES: u64 = 50_000_000;

/// Bytes one triangle may take at the peak of lowering, an upper estimate: the mesh in
/// f64 as generated, its camera-relative f32 copy with smooth normals and indices, the
/// BVH build's boxes with their order, and the BVH. Measured: a 10 M-triangle smooth
/// UV sphere peaks at 109 bytes per triangle of the whole process (`/usr/bin/time -f %M
/// scnc render` of `uvsphere(rings = 2237, segments = 2237, smooth = true)`), 101 flat;
/// what meshes keep afterwards is checked in `tests/scnc/mesh.rs`
/// (`memory_estimate_bounds_what_meshes_keep`).
pub const BYTES_PER_TRIANGLE: u64 = 144;

/// Bytes spent between two confirmations with the system ([`Budget::confirm`]).
const CONFIRM_FROM: u64 = 64 << 20;

/// The default memory limit for meshes: 4 GiB, room on a laptop and on the test machine.
pub const DEFAULT_MEMORY_LIMIT: u64 = 4 << 30;

/// What the scene's meshes may still use: triangles, and bytes at the estimate above.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    triangles: u64,
    bytes: u64,
    limit: u64,
    /// Bytes spent since the system was last asked for them ([`Budget::confirm`]), and
    /// the object that took the most of them, to name if it will not give them.
    unconfirmed: u64,
    largest: Option<(u64, Span)>,
}

impl Budget {
    /// The whole budget, for a memory limit in bytes.
    pub fn new(memory_limit: u64) -> Budget {
        Budget {
            triangles: MAX_SCENE_TRIANGLES,
            bytes: memory_limit,
            limit: memory_limit,
            unconfirmed: 0,
            largest: None,
        }
    }

    /// Cells an isosurface may refine now: the bytes left at
    /// [`isosurface::CELL_BYTES`] a cell. Its working memory is freed once its mesh is
    /// made, so only the mesh is spent from the budget.
    pub fn cells_allowed(&self) -> usize {
        usize::try_from(self.bytes / isosurface::CELL_BYTES).unwrap_or(usize::MAX).max(1)
    }

    /// Asks the system for the bytes spent since the last question, and gives them back:
    /// an address-space cap or a strict overcommit policy then refuses here, with an
    /// error, rather than aborting the process halfway through building. Only address
    /// space is taken (no page is touched), so a question costs a map and an unmap; it is
    /// asked when 64 MiB have been spent, before they are allocated, and at the end.
    pub fn confirm(&mut self) -> Result<(), Diagnostic> {
        let planned = std::mem::take(&mut self.unconfirmed);
        let Some((_, span)) = self.largest.take() else { return Ok(()) };
        let mut probe: Vec<u8> = Vec::new();
        if probe.try_reserve_exact(planned as usize).is_ok() {
            return Ok(());
        }
        Err(Diagnostic::error(
            codes::LOWERING,
            span,
            "the system would not give the memory the scene's meshes need",
            format!("the meshes need about {} more here, most of it for this object", crate::diag::bytes(planned)),
        )
        .with_note("the memory limit allowed it, but the process may not have that much (see `ulimit -v`)")
        .with_hint("try a lower `--detail`, coarser meshes, or a lower `--memory-limit`"))
    }

    /// Triangles the scene's meshes may still have.
    pub fn triangles_left(&self) -> u64 {
        self.triangles
    }

    /// Takes `triangles` from what is left, or reports the object that would exceed the
    /// triangle count or the memory limit, before anything is allocated.
    pub fn spend(&mut self, triangles: u64, span: Span) -> Result<(), Diagnostic> {
        if triangles > self.triangles {
            return Err(Diagnostic::error(
                codes::LOWERING,
                span,
                "the scene's meshes would have too many triangles",
                format!("this object needs {triangles} more triangles"),
            )
            .with_note(format!("a scene may have at most {MAX_SCENE_TRIANGLES} triangles in all its meshes"))
            .with_hint("try a lower `--detail`, or fewer or coarser meshes"));
        }
        let bytes = triangles.saturating_mul(BYTES_PER_TRIANGLE);
        if bytes > self.bytes {
            return Err(Diagnostic::error(
                codes::LOWERING,
                span,
                "the scene's meshes would need more memory than the limit",
                format!("this object needs about {} ({triangles} triangles)", crate::diag::bytes(bytes)),
            )
            .with_note(format!(
                "the memory limit is {}, of which {} is left; a triangle takes up to {BYTES_PER_TRIANGLE} bytes while it is built",
                crate::diag::bytes(self.limit),
                crate::diag::bytes(self.bytes)
            ))
            .with_hint("try a lower `--detail`, coarser meshes, or a higher `--memory-limit`"));
        }
        self.triangles -= triangles;
        self.bytes -= bytes;
        self.unconfirmed += bytes;
        if self.largest.is_none_or(|(most, _)| bytes > most) {
            self.largest = Some((bytes, span));
        }
        if self.unconfirmed >= CONFIRM_FROM {
            self.confirm()?;
        }
        Ok(())
    }
}

/// The cell of an isosurface made at `rings` of detail: a 1/(4·rings) fraction of the
/// shape's bounding diameter `across`.
fn detail_cell(across: f64, rings: f64) -> f64 {
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

fn unbounded(span: Span) -> Diagnostic {
    Diagnostic::error(codes::LOWERING, span, "cannot tessellate an unbounded shape", "this shape has no finite extent")
        .with_note("an isosurface needs finite bounds; only a bare `plane` is meshed as a large square")
        .with_hint("give a `field` its `bounds = [[x0, y0, z0], [x1, y1, z1]]`, or intersect the shape with a `box`")
}

/// Where an isosurface's cell size came from, so a failure can say what to change.
#[derive(Clone, Copy)]
enum CellFrom {
    /// `mesh isosurface(…, cell = …)`.
    Scene,
    /// `--detail` in mesh mode.
    Detail,
}

/// How an isosurface is sampled and placed.
struct Iso {
    /// Render from the grid's frame: where the grid is laid out.
    grid: DAffine3,
    /// Render from the grid's frame, applied to the vertices.
    place: DAffine3,
    /// Material of parts that have none.
    material: u32,
    /// Cell size in the grid's units.
    cell: f64,
    /// Interpolated normals.
    smooth: bool,
    /// What set `cell`, for the hint of a failure.
    from: CellFrom,
    /// Most cells it may refine: what the memory budget has left, at
    /// [`isosurface::CELL_BYTES`] a cell.
    max_cells: usize,
}

/// An isosurface of `shape` sampled and placed as `iso` says, each triangle taking the
/// material of the shape's nearest part. The distance closures are temporary: they are
/// not part of the world's memory.
fn isosurface_object(
    shape: &Shape,
    iso: Iso,
    span: Span,
    materials: &mut MaterialTable,
) -> Result<MeshJob, Diagnostic> {
    let Iso { grid, place, material, cell, smooth, from, max_cells } = iso;
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
        });
    }
    let (dist, mat) = Builder::new(materials).build(shape, grid, material);
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
        }
    };
    let lattice = octree::Grid::new(bounds.min, bounds.max, cell).map_err(|side| {
        // Too many cells on a side for a key: a closed surface across the grid crosses
        // about as many cells as a cube's six faces, so the cell must grow for both the
        // key and the cell limit.
        let cells = 6.0 * side * side;
        let for_keys = cell * side / (1u64 << octree::MAX_LEVELS) as f64;
        let for_limit = cell * (cells / max_cells as f64).sqrt();
        too_fine(cells, for_keys.max(for_limit))
    })?;
    let surface = isosurface::extract_within(&*dist, &lattice, max_cells).map_err(|e| match e {
        isosurface::IsoError::TooManyCells { cells, min_cell } => too_fine(cells, min_cell),
        isosurface::IsoError::NoSurface => {
            let d = Diagnostic::error(
                codes::LOWERING,
                span,
                "isosurface found no surface",
                format!("no sign change on a grid of cell {}", ir::dump_num(cell)),
            )
            .with_note("the shape is thinner than a cell everywhere, so the mesh would be empty");
            match from {
                CellFrom::Scene => d.with_hint("try a smaller `cell`"),
                CellFrom::Detail => d.with_hint("try a higher `--detail`"),
            }
        }
    })?;
    let mesh = surface.mesh;
    let per_triangle = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            mat(((a + b + c) / 3.0).as_vec3a()).mat
        })
        .collect();
    let mut solid = Vec::new();
    parts::solid_parts(shape, grid, &mut solid);
    let lost = parts::lost(&solid, &lattice, &*dist);
    let warnings = lost_parts(&lost, solid.len(), span, cell, across, from)
        .into_iter()
        .chain(pinched(surface.pinched, span, cell, across, from))
        .chain(if lost.is_empty() { lost_volume(&mesh, &*dist, &bounds, span, cell, across, from) } else { None })
        .collect();
    let farthest = mesh.positions.par_iter().map(|p| f64::from(dist(p.as_vec3a()).abs())).reduce(|| 0.0, f64::max);
    Ok(MeshJob {
        mesh,
        xf: place,
        material,
        per_triangle: Some(per_triangle),
        normals: if smooth { Normals::Vertex } else { Normals::Flat },
        convex: false,
        warnings,
        isosurface: Some(IsoAccuracy { cell, farthest }),
    })
}

/// The warning for parts an isosurface at `cell` lost, of `total` solid parts of a
/// shape `across` wide; `None` when none was.
fn lost_parts(
    lost: &[&parts::Part],
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
    bounds: &ir::Aabb,
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
    })
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

/// The warning for `edges` of an isosurface at `cell` left on four triangles; `None`
/// when there are none.
fn pinched(edges: usize, span: Span, cell: f64, across: f64, from: CellFrom) -> Option<Diagnostic> {
    if edges == 0 {
        return None;
    }
    let plural = if edges == 1 { "edge lies" } else { "edges lie" };
    let d = Diagnostic::warning(
        codes::PINCHED_EDGES,
        span,
        format!("{edges} isosurface {plural} on four triangles: parts are thinner than the cell"),
        format!("meshed at cell {}", approx(cell)),
    )
    .with_note(
        "the mesh is closed, but not manifold at those edges; tools that need a manifold (slicers) may refuse it",
    );
    Some(match from {
        CellFrom::Scene => d.with_hint(format!("try `cell = {}` or less", approx(cell / 2.0))),
        CellFrom::Detail => d.with_hint(format!("try `--detail {}` or more", short(detail_for(across, cell / 2.0)))),
    })
}

/// Lowers an explicit `mesh …` object.
pub fn explicit(
    m: &ir::Mesh,
    to_render: DAffine3,
    budget: &mut Budget,
    materials: &mut MaterialTable,
    loader: &dyn Loader,
) -> Result<MeshJob, Diagnostic> {
    let xf = to_render * m.xf;
    let material = m.material.as_ref().map_or(0, |mat| materials.intern(mat, xf));
    // Generators are charged before anything is allocated; isosurfaces and files once
    // made (their grid-cell and file-size limits bound them until then).
    let expected = match &m.source {
        MeshSource::UvSphere { rings, segments, .. } => Some(count::uvsphere(*rings, *segments)),
        MeshSource::IcoSphere { subdivisions, .. } => Some(count::icosphere(*subdivisions)),
        MeshSource::Box { .. } => Some(count::CUBOID),
        MeshSource::Cylinder { segments, .. } => Some(count::cylinder(*segments)),
        MeshSource::Torus { segments, sides, .. } => Some(count::torus(*segments, *sides)),
        MeshSource::Plane { .. } => Some(count::SQUARE),
        MeshSource::Isosurface { .. } | MeshSource::File { .. } => None,
    };
    if let Some(n) = expected {
        budget.spend(n, m.span)?;
    }
    let local: TriMesh = match &m.source {
        MeshSource::UvSphere { radius, rings, segments } => tessellate::uvsphere(*radius, *rings, *segments),
        MeshSource::IcoSphere { radius, subdivisions } => tessellate::icosphere(*radius, *subdivisions),
        MeshSource::Box { half } => tessellate::cuboid(*half),
        MeshSource::Cylinder { radius, half_height, segments } => {
            tessellate::cylinder(*radius, *half_height, *segments)
        }
        MeshSource::Torus { major, minor, segments, sides } => tessellate::torus(*major, *minor, *segments, *sides),
        MeshSource::Plane { size } => tessellate::square(*size),
        MeshSource::Isosurface { shape, cell } => {
            // The grid is laid in the shape's own frame, so `cell` is in its units.
            let iso = Iso {
                grid: DAffine3::IDENTITY,
                place: xf,
                material,
                cell: *cell,
                smooth: m.smooth,
                from: CellFrom::Scene,
                max_cells: budget.cells_allowed(),
            };
            let job = isosurface_object(shape, iso, m.span, materials)?;
            budget.spend(job.mesh.triangles.len() as u64, m.span)?;
            return Ok(job);
        }
        MeshSource::File { path, written } => {
            let bytes = loader.read_bytes(path, crate::source::MAX_MESH_FILE_BYTES).map_err(|e| {
                Diagnostic::error(
                    codes::LOWERING,
                    m.span,
                    format!("cannot read mesh file `{written}`"),
                    crate::source::io_reason(&e),
                )
                .with_note(format!("looked for {}", path.display()))
            })?;
            obj::parse(&bytes).map_err(|e| {
                let place = if e.line > 0 { format!("{written}:{}", e.line) } else { written.clone() };
                Diagnostic::error(
                    codes::LOWERING,
                    m.span,
                    format!("bad mesh file `{written}`"),
                    format!("{place}: {}", e.message),
                )
                .with_note("scnc reads OBJ files: `v x y z` and `f a b c …` records")
            })?
        }
    };
    if expected.is_none() {
        budget.spend(local.triangles.len() as u64, m.span)?;
    }
    Ok(MeshJob {
        mesh: local,
        xf,
        material,
        per_triangle: None,
        normals: if m.smooth { Normals::Vertex } else { Normals::Flat },
        warnings: Vec::new(),
        convex: m.is_convex(),
        isosurface: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::{Facets, Primitive};

    /// Every primitive of `tests/data/primitives.scn`.
    fn primitives() -> Vec<Primitive> {
        fn walk(shape: &Shape, out: &mut Vec<Primitive>) {
            if let ShapeKind::Primitive(p) = &shape.kind {
                out.push(p.clone());
            }
            shape.children().iter().for_each(|c| walk(c, out));
        }
        let text = include_str!("../../tests/data/primitives.scn").to_string();
        let path = std::path::Path::new("tests/data/primitives.scn");
        let compiled = crate::compile_source("primitives.scn", path, text, &crate::source::FsLoader);
        let scene = compiled.scene.expect("the primitives list compiles");
        let mut out = Vec::new();
        for o in &scene.objects {
            match &o.geometry {
                ir::Geometry::Shape(s) => walk(s, &mut out),
                ir::Geometry::Mesh(m) => {
                    if let MeshSource::Isosurface { shape, .. } = &m.source {
                        walk(shape, &mut out);
                    }
                }
            }
        }
        out
    }

    /// What `Primitive::facets` tells the accuracy model is what the mesh back-end does,
    /// and the triangles charged are the triangles made.
    #[test]
    fn generators_agree_with_facets() {
        let all = primitives();
        for entry in crate::primitive::PRIMITIVES {
            assert!(all.iter().any(|p| p.name() == entry.name), "no {} in tests/data/primitives.scn", entry.name);
        }
        for p in &all {
            for detail in [Detail::Low, Detail::High, Detail::N(3), Detail::N(40)] {
                match (p.tessellate(detail.resolution()), p.facets()) {
                    (Tessellation::Triangles(n, make), Facets::Inscribed(_) | Facets::Exact) => {
                        assert_eq!(make().triangles.len() as u64, n, "{} at {detail:?}", p.name());
                    }
                    (Tessellation::HalfSpace { .. }, Facets::Exact)
                    | (Tessellation::Isosurface, Facets::Isosurface) => {}
                    (_, facets) => panic!("{}: the generator does not match {facets:?}", p.name()),
                }
            }
        }
    }

    /// The budget is spent before anything is allocated, and exceeding it (in triangles
    /// or in bytes) is an error at the object's span, never a partial spend.
    #[test]
    fn budget_is_checked_before_spending() {
        let span = Span::new(3, 9);
        let mut budget = Budget::new(10 * BYTES_PER_TRIANGLE);
        assert!(budget.spend(4, span).is_ok());
        let err = budget.spend(7, span).expect_err("over the memory limit");
        assert_eq!((err.code, err.span()), (codes::LOWERING, span));
        assert!(err.message.contains("memory"), "{}", err.message);
        assert!(budget.spend(6, span).is_ok(), "a refused spend takes nothing");
        assert!(budget.spend(1, span).is_err());
        let mut roomy = Budget::new(u64::MAX);
        assert!(roomy.spend(MAX_SCENE_TRIANGLES, span).is_ok());
        assert!(roomy.spend(1, span).expect_err("over the triangle count").message.contains("triangles"));
    }
}
