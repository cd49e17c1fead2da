//! Lowering IR geometry to mesh objects: explicit `mesh …` objects, and shape objects
//! tessellated at a detail level (primitives by their generators, anything else by
//! isosurface, a plane as a square reaching the far limit). Failures are diagnostics
//! that point at the source.

use glam::{DAffine3, DVec3};

use super::iso_job::{detail_cell, isosurface_object, unbounded, CellFrom, Iso};
use super::Wanted;
use super::{isosurface, Detail, MeshJob, Normals};
use crate::diag::{codes, Diagnostic};
use crate::geom::tessellate::count;
use crate::geom::{tessellate, TriMesh};
use crate::ir::{self, ExactMesh, MeshSource, Shape, ShapeKind};
use crate::meshfile::{Format, Reader};
use crate::primitive::{Facets, Tessellation};
use crate::source::Loader;
use crate::span::Span;
use crate::trace::MaterialTable;

/// Tessellates a shape object at `detail`: a primitive with a generator by it, a plane
/// as a square reaching the far limit, anything else as an isosurface.
///
/// Long because it is one match over how each kind of shape is made a mesh (generator,
/// plane, sweep, isosurface).
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
        ShapeKind::Warp { child, domain_op: Some(op), .. } => from_child(child, *op, detail),
        _ => own_tessellation(node, detail),
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
                ShapeKind::Field { exact: Some(ExactMesh::Lathe(_) | ExactMesh::Revolution { .. }), .. } => {
                    Normals::Corners(crate::geom::polygon::lathe_normals(&mesh))
                }
                // A circle's walls meet at its step's angle; a sharper corner is a crease.
                ShapeKind::Field { exact: Some(ExactMesh::Extrusion { .. }), .. } => {
                    let step = std::f64::consts::TAU / f64::from(detail.circle());
                    let crease = (1.01 * step).min(std::f64::consts::FRAC_PI_4);
                    Normals::Corners(crate::geom::polygon::smooth_within(&mesh, crease))
                }
                _ => Normals::Flat,
            };
            // A generator's polytope is convex exactly when its shape is (tested for each);
            // isosurfaces (below) may dent even a convex shape, so they are never marked,
            // nor is a field's exact mesh (a lathe's rings are not tested to be convex).
            Ok(MeshJob {
                mesh,
                xf,
                material,
                per_triangle: None,
                normals,
                convex: !matches!(node.kind, ShapeKind::Field { .. }) && node.is_convex(),
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
                deviation: detail.deviation(),
                smooth: false,
                from: if detail.deviation().is_some() { CellFrom::Tolerance } else { CellFrom::Detail },
                max_cells: budget.cells_allowed(),
                wanted: budget.wanted.clone(),
            };
            let job = isosurface_object(node, iso, node.span, materials)?;
            budget.spend(job.mesh.triangles.len() as u64, shape.span)?;
            Ok(job)
        }
    }
}

/// A shape's own mesh at `detail`, where it has one: a primitive's generator, the mesh
/// a sweep knows; otherwise the isosurface. (A domain operation's is made from its
/// child's own, [`from_child`].)
fn own_tessellation(node: &Shape, detail: Detail) -> Tessellation {
    match &node.kind {
        ShapeKind::Primitive(p) => p.tessellate(detail.resolution()),
        ShapeKind::Field { exact: Some(exact), .. } => exact_tessellation(exact, detail),
        ShapeKind::Csg { .. }
        | ShapeKind::Round { .. }
        | ShapeKind::Shell { .. }
        | ShapeKind::Repeat { .. }
        | ShapeKind::Transform { .. }
        | ShapeKind::Paint { .. }
        | ShapeKind::Field { .. }
        | ShapeKind::Warp { .. }
        | ShapeKind::Displace { .. } => Tessellation::Isosurface,
    }
}

/// The mesh a sweep knows for itself, at `detail`.
fn exact_tessellation(exact: &ExactMesh, detail: Detail) -> Tessellation {
    match exact {
        ExactMesh::Faces(mesh) => {
            let mesh = mesh.clone();
            Tessellation::Triangles(mesh.triangles.len() as u64, Box::new(move || (*mesh).clone()))
        }
        ExactMesh::Lathe(corners) => {
            // As many segments as a circle has at this detail; two triangles a segment
            // per edge, at most.
            let (corners, n) = (corners.clone(), detail.circle());
            let triangles = 2 * corners.len() as u64 * u64::from(n);
            Tessellation::Triangles(triangles, Box::new(move || crate::geom::polygon::lathe(&corners, n)))
        }
        // Made here: its count depends on what the booleans leave. A region cut away
        // wholly, or too far out for the overlay, is left to the isosurface mesher.
        ExactMesh::Revolution { region, .. } => {
            crate::geom::region::revolution(region, detail.circle()).map_or(Tessellation::Isosurface, made)
        }
        ExactMesh::Extrusion { region, half_height } => {
            crate::geom::region::extrusion(region, *half_height, detail.circle()).map_or(Tessellation::Isosurface, made)
        }
    }
}

/// A domain operation's mesh made from its child's own mesh (through its transforms):
/// `twist` splits the mesh's edges until none turns by more than a circle's step at
/// `detail`, then twists it (`mesh::twist`); `polar` copies it about `y`; `elongate`
/// and `symmetric` cut it at the axes' planes (`geom::slab`). The
/// isosurface where the child has no mesh of its own. A twist is charged the most the
/// splitting can make (each round splits a triangle into four at most).
fn from_child(child: &Shape, op: ir::DomainOp, detail: Detail) -> Tessellation {
    let (mut node, mut xf) = (child, DAffine3::IDENTITY);
    while let ShapeKind::Transform { child, xf: inner } = &node.kind {
        xf *= *inner;
        node = child;
    }
    let (Tessellation::Triangles(count, make), Some(b)) = (own_tessellation(node, detail), ir::shape_bounds(child))
    else {
        return Tessellation::Isosurface;
    };
    let placed = move || {
        let mut mesh = make();
        mesh.positions.iter_mut().for_each(|p| *p = xf.transform_point3(*p));
        if xf.matrix3.determinant() < 0.0 {
            mesh.triangles.iter_mut().for_each(|t| t.swap(1, 2));
        }
        mesh
    };
    match op {
        // Its inverse map has no closed form to move the child's vertices by.
        ir::DomainOp::Bend(_) => Tessellation::Isosurface,
        ir::DomainOp::Twist(k) => {
            let step = 360.0 / f64::from(detail.circle());
            let rounds = super::twist::rounds(b.max.y - b.min.y, k, step);
            let most = count.saturating_mul(4u64.saturating_pow(rounds));
            // The bound grows four times a round where the splitting mostly doubles: past
            // a few million, leave a steep twist to the isosurface rather than refuse it.
            if most > 1 << 22 {
                return Tessellation::Isosurface;
            }
            Tessellation::Triangles(most, Box::new(move || super::twist::twisted(placed(), k, step, rounds)))
        }
        ir::DomainOp::Polar(copies) => Tessellation::Triangles(
            count.saturating_mul(u64::from(copies)),
            Box::new(move || super::twist::copies_about_y(&placed(), copies)),
        ),
        // What a cut makes depends on where the plane meets the mesh, so the mesh is made
        // here (in linear time) and charged what it has; past a few million triangles in
        // the child, the isosurface instead, as for a twist.
        ir::DomainOp::Elongate(_) | ir::DomainOp::Mirror(_) if count > 1 << 22 => Tessellation::Isosurface,
        ir::DomainOp::Elongate(h) => made(crate::geom::slab::elongated(placed(), h)),
        ir::DomainOp::Mirror(axes) => made(crate::geom::slab::mirrored(placed(), axes)),
    }
}

/// A mesh already made, as a tessellation charged what it has.
fn made(mesh: crate::geom::TriMesh) -> Tessellation {
    Tessellation::Triangles(mesh.triangles.len() as u64, Box::new(move || mesh))
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
#[derive(Clone)]
pub struct Budget {
    triangles: u64,
    bytes: u64,
    limit: u64,
    /// Bytes spent since the system was last asked for them ([`Budget::confirm`]), and
    /// the object that took the most of them, to name if it will not give them.
    unconfirmed: u64,
    largest: Option<(u64, Span)>,
    /// Asked as isosurfaces are sampled; `None`: always wanted.
    wanted: Option<Wanted>,
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
            wanted: None,
        }
    }

    /// The same budget for a lowering that ends early once `wanted` says it is not.
    pub fn while_wanted(self, wanted: Wanted) -> Budget {
        Budget { wanted: Some(wanted), ..self }
    }

    /// Whether the lowering is no longer wanted.
    pub fn abandoned(&self) -> bool {
        self.wanted.as_ref().is_some_and(|w| !w())
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
        if crate::source::system_gives(planned) {
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

    /// Bytes the scene's meshes may still take.
    pub fn bytes_left(&self) -> u64 {
        self.bytes
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

/// Lowers an explicit `mesh …` object.
///
/// Long because it is one match over the mesh sources (generators, isosurface, file), each
/// charged to the budget before it is made.
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
                deviation: None,
                smooth: m.smooth,
                from: CellFrom::Scene,
                max_cells: budget.cells_allowed(),
                wanted: budget.wanted.clone(),
            };
            let job = isosurface_object(shape, iso, m.span, materials)?;
            budget.spend(job.mesh.triangles.len() as u64, m.span)?;
            return Ok(job);
        }
        MeshSource::File { path, written } => {
            let cannot = |e: std::io::Error| {
                Diagnostic::error(
                    codes::LOWERING,
                    m.span,
                    format!("cannot read mesh file `{written}`"),
                    crate::source::io_reason(&e),
                )
                .with_note(format!("looked for {}", path.display()))
            };
            let bad = |place: String, message: String| {
                Diagnostic::error(
                    codes::LOWERING,
                    m.span,
                    format!("bad mesh file `{written}`"),
                    format!("{place}: {message}"),
                )
                .with_note(reads_note())
            };
            let limit = crate::source::MAX_MESH_FILE_BYTES;
            match Format::for_reading(path).reader() {
                Reader::Whole(read) => {
                    let file = loader.read_bytes(path, limit).map_err(cannot)?;
                    read(&file, budget.bytes_left()).map_err(|e| bad(written.clone(), e))?
                }
                Reader::Lines(read) => read(&mut loader.open_bytes(path, limit).map_err(cannot)?).map_err(|e| {
                    let place = if e.line > 0 { format!("{written}:{}", e.line) } else { written.clone() };
                    bad(place, e.message)
                })?,
            }
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

/// What `mesh file(…)` reads, for the note on a bad file: every format, OBJ first (any
/// other name is read as OBJ).
fn reads_note() -> String {
    let mut formats: Vec<&str> = Format::ALL.iter().map(|f| f.reads()).collect();
    formats.sort_by_key(|r| !r.starts_with("OBJ"));
    let (last, rest) = formats.split_last().expect("formats! lists formats");
    format!("scnc reads {} and {last}", rest.join(", "))
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
                ir::Body::Shape(s) => walk(s, &mut out),
                ir::Body::Mesh(m) => {
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
