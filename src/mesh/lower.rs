//! Lowering IR geometry to mesh objects: explicit `mesh …` objects, and shape objects
//! tessellated at a detail level (primitives by their generators, anything else by
//! isosurface, a plane as a square reaching the far limit). Failures are diagnostics
//! that point at the source.

use glam::{DAffine3, DVec3};

use super::{isosurface, obj, tessellate, MeshJob, TriMesh};
use crate::check::Loader;
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, MeshSource, Shape, ShapeKind};
use crate::sdf::Builder;
use crate::span::Span;
use crate::world::Detail;

/// Tessellates a shape object at `detail`.
pub fn tessellate(
    shape: &Shape,
    xf: DAffine3,
    detail: Detail,
    max_distance: f64,
    budget: &mut u64,
    builder: &mut Builder<'_>,
) -> Result<MeshJob, Diagnostic> {
    // Walk down through transforms and materials to a primitive that has a generator.
    let (mut node, mut xf, mut material) = (shape, xf, 0u32);
    loop {
        match &node.kind {
            ShapeKind::Transform { child, xf: inner } => {
                xf *= *inner;
                node = child;
            }
            ShapeKind::Paint { child, material: m } => {
                material = builder.materials.intern(m);
                node = child;
            }
            _ => break,
        }
    }
    let (rings, circle) = (detail.rings(), detail.circle());
    let (r, c) = (rings as u64, circle as u64);
    let expected = match node.kind {
        ShapeKind::Sphere { .. } => 4 * r * (r - 1),
        ShapeKind::Cylinder { .. } => 4 * c,
        ShapeKind::Cone { .. } => 2 * c,
        ShapeKind::Torus { .. } => 2 * c * r,
        _ => 12,
    };
    spend(budget, expected, shape.span)?;
    let generated = match node.kind {
        ShapeKind::Sphere { radius } => Some(tessellate::uvsphere(radius, rings, 2 * rings)),
        ShapeKind::Box { half } => Some(tessellate::cuboid(half)),
        ShapeKind::Cylinder { radius, half_height } => Some(tessellate::cylinder(radius, half_height, circle)),
        ShapeKind::Cone { radius, half_height } => Some(tessellate::cone(radius, half_height, circle)),
        ShapeKind::Torus { major, minor } => Some(tessellate::torus(major, minor, circle, rings)),
        ShapeKind::Plane { normal, offset } => {
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
            return Ok(MeshJob {
                mesh: square,
                xf: xf * frame,
                material,
                per_triangle: None,
                smooth: false,
                convex: node.is_convex(),
            });
        }
        _ => None,
    };
    if let Some(mesh) = generated {
        // A generator's polytope is convex exactly when its shape is (tested for each);
        // isosurfaces (below) may dent even a convex shape, so they are never marked.
        return Ok(MeshJob { mesh, xf, material, per_triangle: None, smooth: false, convex: node.is_convex() });
    }
    // Everything else: an isosurface of the subtree in render space, at a cell size that
    // follows the detail (a 1/(4·rings) fraction of the bounding diameter).
    let bounds = ir::shape_bounds(node).ok_or_else(|| unbounded(node.span))?.transform(&xf);
    let cell = (bounds.max - bounds.min).length() / (4.0 * rings as f64);
    // Sampled in render space, so the vertices need no further placing.
    isosurface_object(node, xf, DAffine3::IDENTITY, material, cell, false, node.span, CellFrom::Detail, builder)
}

/// Most triangles all meshes of one scene may have together (about 2.4 GB with BVHs).
pub const MAX_SCENE_TRIANGLES: u64 = 50_000_000;

/// Takes `triangles` from the scene's remaining budget, or reports the object that would
/// exceed it, before anything is allocated.
pub fn spend(budget: &mut u64, triangles: u64, span: Span) -> Result<(), Diagnostic> {
    if triangles > *budget {
        return Err(Diagnostic::error(
            codes::LOWERING,
            span,
            "the scene's meshes would have too many triangles",
            format!("this object needs {triangles} more triangles"),
        )
        .with_note(format!("a scene may have at most {MAX_SCENE_TRIANGLES} triangles in all its meshes"))
        .with_hint("try a lower `--detail`, or fewer or coarser meshes"));
    }
    *budget -= triangles;
    Ok(())
}

fn unbounded(span: Span) -> Diagnostic {
    Diagnostic::error(codes::LOWERING, span, "cannot tessellate an unbounded shape", "this shape has no finite extent")
        .with_note("an isosurface needs finite bounds; only a bare `plane` is meshed as a large square")
        .with_hint("try intersecting it with a `box` to bound it")
}

/// Where an isosurface's cell size came from, so a failure can say what to change.
#[derive(Clone, Copy)]
enum CellFrom {
    /// `mesh isosurface(…, cell = …)`.
    Scene,
    /// `--detail` in mesh mode.
    Detail,
}

/// An isosurface of `shape` on a grid laid out in the frame `grid` (render from the
/// grid's frame), placed by `place` (render from the grid's frame, applied to the
/// vertices), each triangle taking the material of the shape's nearest part.
#[allow(clippy::too_many_arguments, reason = "shape, two frames, material, grid, shading and the span to blame")]
fn isosurface_object(
    shape: &Shape,
    grid: DAffine3,
    place: DAffine3,
    material: u32,
    cell: f64,
    smooth: bool,
    span: Span,
    from: CellFrom,
    builder: &mut Builder<'_>,
) -> Result<MeshJob, Diagnostic> {
    let bounds = ir::shape_bounds(shape).ok_or_else(|| unbounded(shape.span))?.transform(&grid);
    let (dist, mat) = builder.build(shape, grid, material);
    let mesh = isosurface::extract(&*dist, bounds.min, bounds.max, cell).map_err(|e| match e {
        isosurface::IsoError::TooManyCells { cells, min_cell } => {
            let d = Diagnostic::error(
                codes::LOWERING,
                span,
                "isosurface grid is too fine",
                format!("cell {} needs {cells} grid cells", ir::dump_num(cell)),
            )
            .with_note(format!("an isosurface may use at most {} cells", isosurface::MAX_CELLS));
            match from {
                CellFrom::Scene => {
                    d.with_hint(format!("try `cell = {}` or more", ir::dump_num((min_cell * 1.001 * 1e6).ceil() / 1e6)))
                }
                CellFrom::Detail => d.with_hint("try a lower `--detail`"),
            }
        }
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
    let per_triangle = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            mat(((a + b + c) / 3.0).as_vec3a()).1
        })
        .collect();
    Ok(MeshJob { mesh, xf: place, material, per_triangle: Some(per_triangle), smooth, convex: false })
}

/// Lowers an explicit `mesh …` object.
pub fn explicit(
    m: &ir::Mesh,
    to_render: DAffine3,
    budget: &mut u64,
    builder: &mut Builder<'_>,
    loader: &dyn Loader,
) -> Result<MeshJob, Diagnostic> {
    let xf = to_render * m.xf;
    let material = m.material.as_ref().map_or(0, |mat| builder.materials.intern(mat));
    let expected = match &m.source {
        MeshSource::UvSphere { rings, segments, .. } => 2 * *segments as u64 * (*rings as u64 - 1),
        MeshSource::IcoSphere { subdivisions, .. } => 20 * 4u64.pow(*subdivisions),
        MeshSource::Box { .. } => 12,
        MeshSource::Cylinder { segments, .. } => 4 * *segments as u64,
        MeshSource::Torus { segments, sides, .. } => 2 * *segments as u64 * *sides as u64,
        MeshSource::Plane { .. } => 2,
        // Bounded by the grid-cell and OBJ-size limits; counted once made, below.
        MeshSource::Isosurface { .. } | MeshSource::File { .. } => 0,
    };
    spend(budget, expected, m.span)?;
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
            return isosurface_object(
                shape,
                DAffine3::IDENTITY,
                xf,
                material,
                *cell,
                m.smooth,
                m.span,
                CellFrom::Scene,
                builder,
            );
        }
        MeshSource::File { path, written } => {
            let text = loader.read(path).map_err(|e| {
                Diagnostic::error(
                    codes::LOWERING,
                    m.span,
                    format!("cannot read mesh file `{written}`"),
                    crate::check::io_reason(&e),
                )
                .with_note(format!("looked for {}", path.display()))
            })?;
            obj::parse(&text).map_err(|e| {
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
    Ok(MeshJob { mesh: local, xf, material, per_triangle: None, smooth: m.smooth, convex: m.is_convex() })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The budget is spent before anything is allocated, and exceeding it is an error at
    /// the object's span, never a partial spend.
    #[test]
    fn triangle_budget_is_checked_before_spending() {
        let span = Span::new(3, 9);
        let mut budget = 10;
        assert!(spend(&mut budget, 4, span).is_ok());
        assert_eq!(budget, 6);
        let err = spend(&mut budget, 7, span).expect_err("over budget");
        assert_eq!((err.code, err.span()), (codes::LOWERING, span));
        assert_eq!(budget, 6, "a refused spend takes nothing");
        assert!(spend(&mut budget, 6, span).is_ok());
        assert_eq!(budget, 0);
    }
}
