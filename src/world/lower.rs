//! Lowering: each object to its back-end, in scene order (materials and the triangle
//! budget are spent deterministically), then meshes built in parallel.

use glam::{DAffine3, Vec3A};
use rayon::prelude::*;

use super::{Mode, Object, ObjectKind, World};
use crate::accel::{padded_sphere, Aabb, Bvh};
use crate::diag::Diagnostic;
use crate::ir;
use crate::mesh;
use crate::render::Frame;
use crate::sdf::{self, MarchParams, SdfObject};
use crate::source::Loader;

/// An object between lowering and building: an SDF object with its bounds, or a mesh to build.
enum Lowered {
    Sdf(SdfObject, Option<Aabb>, Option<(Vec3A, f32)>),
    Mesh(mesh::MeshJob),
}

/// Builds the frame for `effects` and lowers the scene into a world, with the scene's
/// own sphere-tracing settings and the default memory limit: the one call the CLI,
/// tests and benchmarks use.
pub fn prepare(
    scene: &ir::Scene,
    effects: crate::render::effects::Effects,
    mode: Mode,
    loader: &dyn Loader,
) -> Result<(Frame, World), Diagnostic> {
    prepare_within(scene, effects, mode, loader, mesh::lower::DEFAULT_MEMORY_LIMIT)
}

/// [`prepare`] with meshes limited to `memory_limit` bytes (at
/// [`mesh::lower::BYTES_PER_TRIANGLE`] each), refused before anything is allocated.
pub fn prepare_within(
    scene: &ir::Scene,
    effects: crate::render::effects::Effects,
    mode: Mode,
    loader: &dyn Loader,
    memory_limit: u64,
) -> Result<(Frame, World), Diagnostic> {
    let mut frame = Frame::with_effects(scene, effects);
    let params = MarchParams { epsilon: scene.settings.epsilon as f32, max_steps: scene.settings.max_steps };
    let budget = mesh::lower::Budget::new(memory_limit);
    let world = lower(scene, &mut frame, mode, params, loader, budget)?;
    Ok((frame, world))
}

/// Lowers every object of the scene within `budget`. Materials are interned into
/// `frame`; mesh files are read through `loader`.
pub fn lower(
    scene: &ir::Scene,
    frame: &mut Frame,
    mode: Mode,
    params: MarchParams,
    loader: &dyn Loader,
    mut budget: mesh::lower::Budget,
) -> Result<World, Diagnostic> {
    // Render space: world translated so the camera is at the origin, composed in f64.
    let to_render = DAffine3::from_translation(-frame.origin);
    let max_distance = frame.max_distance as f64;
    let mut builder = sdf::Builder::new(&mut frame.materials);
    // In scene order: materials are interned and the triangle budget spent as objects
    // come, so ids and errors do not depend on timing. Meshes are built afterwards.
    let mut lowered = Vec::with_capacity(scene.objects.len());
    for obj in &scene.objects {
        let part = match (&obj.geometry, mode) {
            (ir::Geometry::Shape(shape), Mode::Sdf) => {
                let bounds = ir::shape_bounds(shape).map(|b| Aabb::padded(b.transform(&to_render)));
                let sphere = ir::shape_sphere(shape).map(|(c, r)| padded_sphere(to_render.transform_point3(c), r));
                Lowered::Sdf(SdfObject::new(shape, to_render, &mut builder), bounds, sphere)
            }
            (ir::Geometry::Shape(shape), Mode::Mesh(detail)) => Lowered::Mesh(mesh::lower::tessellate(
                shape,
                to_render,
                detail,
                max_distance,
                &mut budget,
                builder.materials,
            )?),
            (ir::Geometry::Mesh(m), _) => {
                Lowered::Mesh(mesh::lower::explicit(m, to_render, &mut budget, builder.materials, loader)?)
            }
        };
        lowered.push((part, obj.span));
    }
    budget.confirm()?;
    let warnings = lowered
        .iter_mut()
        .flat_map(|(part, _)| match part {
            Lowered::Mesh(job) => std::mem::take(&mut job.warnings),
            Lowered::Sdf(..) => Vec::new(),
        })
        .collect();
    // Building the meshes (vertices to render space, BVHs) is most of the lowering time
    // of a scene of many meshes; they are independent, so they are built in parallel.
    let objects: Vec<Object> = lowered
        .into_par_iter()
        .map(|(part, span)| match part {
            Lowered::Sdf(s, bounds, sphere) => Object { kind: ObjectKind::Sdf(s), bounds, sphere, span },
            Lowered::Mesh(job) => {
                let m = job.build();
                Object { bounds: Some(m.bounds()), sphere: m.sphere(), kind: ObjectKind::Mesh(m), span }
            }
        })
        .collect();
    // The checker's renderable range (check::range) keeps camera-relative f32 finite.
    debug_assert!(
        objects.iter().all(|o| o.bounds.is_none_or(|b| b.min.is_finite() && b.max.is_finite())
            && o.sphere.is_none_or(|(c, r)| c.is_finite() && r.is_finite())),
        "lowering made a non-finite bound"
    );
    let closure_bytes = builder.bytes;
    let bounded: Vec<u32> = (0..objects.len() as u32)
        .filter(|&i| objects[i as usize].bounds.is_some_and(|b| b.min.cmple(b.max).all()))
        .collect();
    let unbounded = (0..objects.len() as u32).filter(|&i| objects[i as usize].bounds.is_none()).collect();
    let boxes: Vec<Aabb> = bounded.iter().map(|&i| objects[i as usize].bounds.unwrap_or(Aabb::EMPTY)).collect();
    let bvh = Bvh::build(&boxes, 2);
    debug_assert!(bvh.validate(&boxes).is_ok());
    let has_meshes = objects.iter().any(|o| matches!(o.kind, ObjectKind::Mesh(_)));
    let share_walks = has_meshes || bvh.node_count() > 1;
    Ok(World { objects, bvh, bounded, unbounded, params, closure_bytes, has_meshes, share_walks, warnings })
}
