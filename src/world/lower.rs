//! Lowering: each object to its back-end, in scene order (materials and the triangle
//! budget are spent deterministically), then meshes built in parallel. In an animation,
//! objects that did not change since the previous frame are taken from it ([`FrameCache`]).

use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3A};
use rayon::prelude::*;

use super::{query, Mode, Object, ObjectKind, World};
use crate::accel::{padded_sphere, Aabb, Bvh};
use crate::diag::{codes, Diagnostic};
use crate::ir;
use crate::mesh;
use crate::render::Frame;
use crate::sdf::{self, MarchParams, SdfObject};
use crate::source::Loader;
use crate::span::Span;
use crate::trace::ShadeMaterial;

/// An object between lowering and building: an SDF object with its bounds, a mesh to
/// build, or an object an earlier frame lowered.
enum Lowered {
    Sdf(SdfObject, Reach),
    Mesh(mesh::MeshJob),
    Kept(Object),
}

/// Where an SDF object's surface can be, in render space: its box and sphere when
/// bounded, a half-space holding it when not (a floor plane, a plane cut by others).
struct Reach {
    bounds: Option<Aabb>,
    sphere: Option<(Vec3A, f32)>,
    half_space: Option<(Vec3A, f32)>,
    hull: Option<Arc<query::Entry>>,
}

impl Reach {
    fn of(shape: &ir::Shape, to_render: &DAffine3, known: &mut FieldHulls) -> Reach {
        let bounds = ir::shape_bounds(shape).map(|b| Aabb::padded(b.transform(to_render)));
        let sphere = known.sphere_of(shape).map(|(c, r)| padded_sphere(to_render.transform_point3(c), r));
        let half_space = match bounds {
            Some(_) => None,
            None => ir::shape_half_space(shape)
                .and_then(|h| ir::transform_half_space(h, to_render))
                .map(|(n, o)| (n.as_vec3a(), o as f32)),
        };
        let hull = bounds.and_then(|_| known.hull(shape));
        let solid = shape.hull_is_solid();
        let hull = hull.and_then(|h| h.transformed(to_render)).map(|h| query::Entry::new(h, solid));
        Reach { bounds, sphere, half_space, hull: hull.map(Arc::new) }
    }
}

/// The support planes of the fields lowered so far, by body, box and level: a scene's
/// many copies of one field (a loop placing it) search once. Only the last 64 are
/// looked through, so a scene of many different fields does not pay a square.
#[derive(Default)]
struct FieldHulls(Vec<KnownPlanes>);

/// A body, box and level with the planes found for them and the sphere holding its
/// solid.
struct KnownPlanes {
    body: Arc<ir::field::FieldExpr>,
    bounds: ir::DAabb,
    level: f64,
    planes: Option<Vec<(DVec3, f64)>>,
    sphere: Option<(DVec3, f64)>,
}

/// The fewest operations a field's body has for its rays to be clipped to its support
/// planes: below that a step costs less than the clip (`scnc render
/// benches/scenes/field-spheres-64.scn --width 1000 --height 1000 --stats`, spheres of
/// three operations each; docs/performance.md, "Measurements behind the code"). Their
/// sphere ([`FieldHulls::sphere`]) is clipped to at every size: it costs what a
/// native object's does.
const MIN_OPS: usize = 12;

/// The convex set an object of `shape`'s rays are clipped to: [`ir::shape_hull`] with
/// the support planes of the fields in it (of a dozen operations or more).
pub fn shape_hull(shape: &ir::Shape) -> Option<crate::geom::hull::Hull> {
    FieldHulls::default().hull(shape)
}

/// The sphere an object of `shape`'s rays are clipped to: [`ir::shape_sphere`] with
/// the ball each field's solid is found in (`field::support_radius`).
pub fn shape_sphere(shape: &ir::Shape) -> Option<(DVec3, f64)> {
    FieldHulls::default().sphere_of(shape)
}

impl FieldHulls {
    /// [`shape_hull`], searching each field's planes once per body, box and level.
    fn hull(&mut self, shape: &ir::Shape) -> Option<crate::geom::hull::Hull> {
        ir::shape_hull(shape, &mut |body, b, level| self.planes(body, b, level))
    }

    /// [`shape_sphere`], searching each field's ball once per body, box and level.
    fn sphere_of(&mut self, shape: &ir::Shape) -> Option<(DVec3, f64)> {
        ir::shape_sphere_with(shape, &mut |body, b, level| self.sphere(body, b, level))
    }

    /// [`ir::FieldPlanes`]: the planes holding where `body` is at most `level` within
    /// `b` (`field::support_planes`), for a body of at least [`MIN_OPS`] operations.
    fn planes(&mut self, body: &Arc<ir::field::FieldExpr>, b: ir::DAabb, level: f64) -> Option<Vec<(DVec3, f64)>> {
        self.known(body, b, level).planes.clone()
    }

    /// [`ir::FieldSphere`]: a sphere holding the solid, for a body of any size: the
    /// smaller of the ball `field::support_radius` finds and the sphere about the
    /// support planes' polyhedron (within `b`) through its corners. A ray misses it, or
    /// enters it near the surface, for the cost of a native object's sphere test.
    fn sphere(&mut self, body: &Arc<ir::field::FieldExpr>, b: ir::DAabb, level: f64) -> Option<(DVec3, f64)> {
        self.known(body, b, level).sphere
    }

    /// What is known of `body` within `b` at `level`, searched once.
    fn known(&mut self, body: &Arc<ir::field::FieldExpr>, b: ir::DAabb, level: f64) -> &KnownPlanes {
        let same =
            |k: &KnownPlanes| k.bounds == b && k.level == level && (Arc::ptr_eq(&k.body, body) || k.body == *body);
        let n = self.0.len();
        if let Some(i) = (n.saturating_sub(64)..n).rev().find(|&i| same(&self.0[i])) {
            return &self.0[i];
        }
        let tape = crate::field::Tape::new(body);
        // Each `dist` as the values its shape's distance bound can take.
        let shapes =
            crate::field::SlopeDistances { spheres: tape.shapes.iter().map(|s| ir::shape_sphere(s)).collect() };
        // A body of a few operations steps more cheaply than a ray is clipped to twenty
        // planes (see MIN_OPS).
        let planes =
            (tape.ops.len() >= MIN_OPS).then(|| crate::field::support_planes(&tape, b, level, &shapes)).flatten();
        let hull = |p: &Vec<(DVec3, f64)>| {
            let mut all = p.clone();
            all.extend(crate::geom::hull::Hull::box_planes(b));
            corner_sphere(&crate::geom::hull::Hull::planes(all).corners())
        };
        let corners = planes.as_ref().and_then(hull);
        // The ball holding the solid, about the middle of its polyhedron or box (its
        // search's cost: `field::support_radius`). Every body
        // is searched, so an object's sphere depends on nothing but the object, as an
        // animation's reuse of objects needs (`FrameCache`).
        let centre = corners.map_or(b.centre(), |c| c.0);
        let radial = crate::field::support_radius(&tape, b, level, centre, &shapes);
        let sphere = match (corners, radial) {
            (Some((c, r)), Some(w)) => Some((c, r.min(w))),
            (Some(s), None) => Some(s),
            (None, Some(w)) => Some((centre, w)),
            (None, None) => None,
        };
        self.0.push(KnownPlanes { body: body.clone(), bounds: b, level, planes, sphere });
        &self.0[n]
    }
}

/// The sphere about the middle of `corners`' box through the farthest of them; `None`
/// for no corners.
fn corner_sphere(corners: &[DVec3]) -> Option<(DVec3, f64)> {
    let (lo, hi) = corners.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &c| (lo.min(c), hi.max(c)));
    let centre = (lo + hi) * 0.5;
    let radius = corners.iter().map(|c| (*c - centre).length()).fold(f64::NEG_INFINITY, f64::max);
    (radius.is_finite()).then_some((centre, radius))
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
    prepare_reusing(scene, effects, mode, loader, memory_limit, &mut FrameCache::default(), &|| {})
}

/// [`prepare_within`] for a lowering that may stop being wanted (the studio's, once a
/// newer request comes): `Ok(None)` as soon as `wanted` says so. It is asked between
/// objects, at every isosurface sample and at every large subtree of a mesh's BVH, so an
/// abandoned lowering lets go of the workers at once rather than when its meshes are
/// done.
pub fn prepare_until(
    scene: &ir::Scene,
    effects: crate::render::effects::Effects,
    mode: Mode,
    loader: &dyn Loader,
    memory_limit: u64,
    wanted: mesh::Wanted,
) -> Result<Option<(Frame, World)>, Diagnostic> {
    let budget = mesh::lower::Budget::new(memory_limit).while_wanted(wanted.clone());
    let prepared = prepare_with(scene, effects, mode, loader, budget, &mut FrameCache::default(), &|| {});
    // Not wanted any more: whatever the lowering made or refused is moot.
    if !wanted() {
        return Ok(None);
    }
    prepared.map(Some)
}

/// [`prepare_within`] for one frame of an animation: objects equal to the previous
/// frame's, seen from the same place, are taken from `reuse` instead of lowered again
/// (their meshes are shared, not rebuilt), and this frame's objects are kept there for
/// the next. The world is the one [`prepare_within`] would make, bit for bit.
///
/// `step` is called twice per object, as it is lowered (in scene order: an isosurface is
/// extracted here) and as it is built (in parallel: vertices to render space and BVHs),
/// for a progress bar of [`lowering_steps`].
pub fn prepare_reusing(
    scene: &ir::Scene,
    effects: crate::render::effects::Effects,
    mode: Mode,
    loader: &dyn Loader,
    memory_limit: u64,
    reuse: &mut FrameCache,
    step: &(dyn Fn() + Sync),
) -> Result<(Frame, World), Diagnostic> {
    let budget = mesh::lower::Budget::new(memory_limit);
    prepare_with(scene, effects, mode, loader, budget, reuse, step)
}

/// The frame for `effects` and the scene lowered into a world within `budget`.
fn prepare_with(
    scene: &ir::Scene,
    effects: crate::render::effects::Effects,
    mode: Mode,
    loader: &dyn Loader,
    budget: mesh::lower::Budget,
    reuse: &mut FrameCache,
    step: &(dyn Fn() + Sync),
) -> Result<(Frame, World), Diagnostic> {
    let mut frame = Frame::with_effects(scene, effects);
    let params = MarchParams { epsilon: scene.settings.epsilon as f32, max_steps: scene.settings.max_steps };
    let world = lower_reusing(scene, &mut frame, mode, params, loader, budget, reuse, step)?;
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
    budget: mesh::lower::Budget,
) -> Result<World, Diagnostic> {
    lower_reusing(scene, frame, mode, params, loader, budget, &mut FrameCache::default(), &|| {})
}

/// How many times lowering `scene` calls [`prepare_reusing`]'s `step`.
pub fn lowering_steps(scene: &ir::Scene) -> u64 {
    2 * scene.objects.len() as u64
}

/// Objects one frame lowered, for the next frame to reuse.
///
/// Why a kept object is exactly what lowering would make again: lowering an object is a
/// function of the object, the render-space origin, the back-end and its detail, and the
/// material table it starts from (it interns its materials, and their ids depend on
/// what is in the table). The first three are compared whole; for the table, a kept
/// object remembers how long it was before and after the object, and is reused only when
/// this frame's table so far equals the last frame's up to that length, then takes the
/// entries the object added. Mesh files are read again each frame, as a changed file
/// should show (an object naming one is never kept).
#[derive(Default)]
pub struct FrameCache {
    /// Where render space was, how far rays reach (planes are meshed to there), and
    /// which back-end.
    origin: DVec3,
    max_distance: f32,
    mode: Option<Mode>,
    /// By object index; `None` for an object that is lowered afresh every frame.
    kept: Vec<Option<Kept>>,
    /// The material table the kept objects were lowered into, at its end.
    table: Vec<ShadeMaterial>,
    /// Objects reused by the last lowering, for `--stats`.
    pub reused: usize,
}

/// One object kept for the next frame.
struct Kept {
    source: ir::Object,
    object: Object,
    /// The material table's length before and after the object.
    table: (usize, usize),
    closure_bytes: usize,
    triangles: u64,
    warnings: Vec<Diagnostic>,
}

/// Whether lowering `obj` reads a file (which may change between frames).
fn reads_files(obj: &ir::Object) -> bool {
    matches!(&obj.geometry, ir::Body::Mesh(m) if matches!(m.source, ir::MeshSource::File { .. }))
}

/// Long because it is the one pass that interns materials, spends the triangle budget and
/// takes reused objects in scene order, so ids and errors do not depend on timing; split,
/// that order would be spread over several functions.
#[allow(clippy::too_many_arguments, reason = "prepare_reusing's arguments, and the frame it fills")]
fn lower_reusing(
    scene: &ir::Scene,
    frame: &mut Frame,
    mode: Mode,
    params: MarchParams,
    loader: &dyn Loader,
    mut budget: mesh::lower::Budget,
    reuse: &mut FrameCache,
    step: &(dyn Fn() + Sync),
) -> Result<World, Diagnostic> {
    // Render space: world translated so the camera is at the origin, composed in f64.
    let to_render = DAffine3::from_translation(-frame.origin);
    let max_distance = frame.max_distance as f64;
    if (reuse.origin, reuse.max_distance, reuse.mode) != (frame.origin, frame.max_distance, Some(mode)) {
        reuse.kept.clear();
    }
    // What changed is let go before anything is built, so a mesh that changes every frame
    // is not held twice.
    reuse.kept.truncate(scene.objects.len());
    for (kept, obj) in reuse.kept.iter_mut().zip(&scene.objects) {
        if kept.as_ref().is_some_and(|k| k.source != *obj) {
            *kept = None;
        }
    }
    let mut builder = sdf::Builder::new(&mut frame.materials);
    // How much of this frame's material table equals the last frame's so far.
    let mut agree = 0;
    let mut reused = 0;
    // In scene order: materials are interned and the triangle budget spent as objects
    // come, so ids and errors do not depend on timing. Meshes are built afterwards.
    let mut lowered = Vec::with_capacity(scene.objects.len());
    let mut field_hulls = FieldHulls::default();
    let mut kept = Vec::with_capacity(scene.objects.len());
    for (i, obj) in scene.objects.iter().enumerate() {
        if budget.abandoned() {
            return Err(abandoned(obj.span));
        }
        let table = &mut builder.materials.materials;
        while agree < table.len().min(reuse.table.len()) && table[agree] == reuse.table[agree] {
            agree += 1;
        }
        let before = (table.len(), builder.bytes, budget.triangles_left());
        let old = reuse.kept.get(i).and_then(Option::as_ref);
        let old = old.filter(|k| k.table.0 == before.0 && agree >= before.0);
        let part = match old {
            Some(k) => {
                table.extend_from_slice(&reuse.table[k.table.0..k.table.1]);
                builder.bytes += k.closure_bytes;
                if k.triangles > 0 {
                    budget.spend(k.triangles, obj.span)?;
                }
                reused += 1;
                Lowered::Kept(k.object.clone())
            }
            None => match (&obj.geometry, mode) {
                (ir::Body::Shape(shape), Mode::Sdf) => {
                    let reach = Reach::of(shape, &to_render, &mut field_hulls);
                    Lowered::Sdf(SdfObject::new(shape, to_render, &mut builder), reach)
                }
                (ir::Body::Shape(shape), Mode::Mesh(detail)) => Lowered::Mesh(mesh::lower::tessellate(
                    shape,
                    to_render,
                    detail.in_frame(&to_render),
                    max_distance,
                    &mut budget,
                    builder.materials,
                )?),
                (ir::Body::Mesh(m), _) => {
                    Lowered::Mesh(mesh::lower::explicit(m, to_render, &mut budget, builder.materials, loader)?)
                }
            },
        };
        let after = (builder.materials.materials.len(), builder.bytes, budget.triangles_left());
        let warnings = match &part {
            Lowered::Mesh(job) => job.warnings.clone(),
            Lowered::Kept(_) => old.map_or_else(Vec::new, |k| k.warnings.clone()),
            Lowered::Sdf(..) => Vec::new(),
        };
        let (closure_bytes, triangles) = (after.1 - before.1, before.2 - after.2);
        kept.push((obj, (before.0, after.0), closure_bytes, triangles, warnings.clone()));
        lowered.push((part, warnings, obj.span));
        step();
    }
    budget.confirm()?;
    if let (true, Some(last)) = (budget.abandoned(), scene.objects.last()) {
        return Err(abandoned(last.span));
    }
    let warnings: Vec<Diagnostic> = lowered.iter().flat_map(|(_, w, _)| w.iter().cloned()).collect();
    // Building the meshes (vertices to render space, BVHs) is most of the lowering time
    // of a scene of many meshes; they are independent, so they are built in parallel.
    // Under light transport nearly every ray is a lone, incoherent one: meshes get the
    // four-wide BVH and the corners in place those walk faster (`MeshObject::widen`,
    // `docs/light.md` against Embree).
    let incoherent = frame.transport.is_some();
    let objects: Vec<Object> = lowered
        .into_par_iter()
        .map(|(part, _, span)| {
            let object = match part {
                Lowered::Sdf(s, Reach { bounds, sphere, half_space, hull }) => {
                    Object { kind: ObjectKind::Sdf(s), bounds, sphere, half_space, hull, span }
                }
                Lowered::Mesh(job) => {
                    let mut m = job.build_until(&|| budget.abandoned());
                    if incoherent {
                        m.widen();
                    }
                    let (bounds, sphere) = (Some(m.bounds()), m.sphere());
                    Object { bounds, sphere, half_space: None, hull: None, kind: ObjectKind::Mesh(Arc::new(m)), span }
                }
                Lowered::Kept(object) => object,
            };
            step();
            object
        })
        .collect();
    let closure_bytes = builder.bytes;
    reuse.kept = kept
        .into_iter()
        .zip(&objects)
        .map(|((obj, table, closure_bytes, triangles, warnings), object)| {
            let source = (!reads_files(obj)).then(|| obj.clone())?;
            Some(Kept { source, object: object.clone(), table, closure_bytes, triangles, warnings })
        })
        .collect();
    reuse.origin = frame.origin;
    reuse.max_distance = frame.max_distance;
    reuse.mode = Some(mode);
    reuse.table = frame.materials.materials.clone();
    reuse.reused = reused;
    Ok(world_of(objects, params, closure_bytes, warnings))
}

/// What a lowering that stopped being wanted ends with ([`prepare_until`] drops it).
fn abandoned(span: Span) -> Diagnostic {
    Diagnostic::error(codes::LOWERING, span, "lowering abandoned", "a newer request took its place")
}

/// The world of lowered objects: the top-level BVH over the bounded ones.
fn world_of(objects: Vec<Object>, params: MarchParams, closure_bytes: usize, warnings: Vec<Diagnostic>) -> World {
    // The checker's renderable range (check::range) keeps camera-relative f32 finite.
    debug_assert!(
        objects.iter().all(|o| o.bounds.is_none_or(|b| b.min.is_finite() && b.max.is_finite())
            && o.sphere.is_none_or(|(c, r)| c.is_finite() && r.is_finite())),
        "lowering made a non-finite bound"
    );
    let bounded: Vec<u32> = (0..objects.len() as u32)
        .filter(|&i| objects[i as usize].bounds.is_some_and(|b| b.min.cmple(b.max).all()))
        .collect();
    let unbounded = (0..objects.len() as u32).filter(|&i| objects[i as usize].bounds.is_none()).collect();
    let boxes: Vec<Aabb> = bounded.iter().map(|&i| objects[i as usize].bounds.unwrap_or(Aabb::EMPTY)).collect();
    let bvh = Bvh::build(&boxes, 2);
    debug_assert!(bvh.validate(&boxes).is_ok());
    let has_meshes = objects.iter().any(|o| matches!(o.kind, ObjectKind::Mesh(_)));
    let packs = |o: &Object| matches!(&o.kind, ObjectKind::Sdf(s) if s.walks_packets());
    let share_walks = has_meshes || bvh.node_count() > 1 || objects.iter().any(packs);
    World { objects, bvh, bounded, unbounded, params, closure_bytes, has_meshes, share_walks, warnings }
}
