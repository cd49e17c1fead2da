//! The lowered scene: every object, SDF or mesh, under one top-level BVH, implementing
//! the tracer's [`Geometry`] contract. Lowering picks each object's back-end: shapes go
//! to the SDF back-end, or are tessellated in mesh mode; explicit meshes are always meshes.
//!
//! **Invariant:** every object lies in render space (camera at the origin); each bounded
//! object's box and sphere contain its surface, so a ray outside them cannot hit it.

use glam::{DAffine3, Vec3A, Vec4};
use rayon::prelude::*;

use crate::accel::bvh::splat3;
use crate::accel::{Aabb, Bvh, Rays4};
use crate::diag::Diagnostic;
use crate::ir;
use crate::mesh::triangle::PacketShear;
use crate::mesh::{self, Detail, MeshMemory, MeshObject};
use crate::render::{intersect_each, lanes, Counters, Frame, Geometry, Hit, Packet, Ray, NO_OBJECT};
use crate::sdf::{self, MarchParams, SdfObject};
use crate::source::Loader;
use crate::span::Span;

/// Which back-end renders shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Sphere tracing.
    Sdf,
    /// Tessellation at the given detail.
    Mesh(Detail),
}

/// One object of the world.
pub enum ObjectKind {
    /// Sphere traced.
    Sdf(SdfObject),
    /// Triangles.
    Mesh(MeshObject),
}

/// An object between lowering and building: an SDF object with its bounds, or a mesh to build.
enum Lowered {
    Sdf(SdfObject, Option<Aabb>, Option<(Vec3A, f32)>),
    Mesh(mesh::MeshJob),
}

struct Object {
    kind: ObjectKind,
    bounds: Option<Aabb>,
    sphere: Option<(Vec3A, f32)>,
    span: Span,
}

/// The lowered scene.
pub struct World {
    objects: Vec<Object>,
    bvh: Bvh,
    bounded: Vec<u32>,
    unbounded: Vec<u32>,
    params: MarchParams,
    closure_bytes: usize,
    /// Whether any object is a mesh: then soft shadows and occlusion need rays, not estimates.
    has_meshes: bool,
    /// Whether packets walk the BVHs together: only when there is a walk to share (a mesh,
    /// or a top-level tree with interior nodes). Sphere tracing is per ray anyway, and on
    /// a lone SDF object the packet set-up measured 10–20% slower than single rays.
    share_walks: bool,
}

/// Memory of the world by structure, for `--stats`.
#[derive(Clone, Debug, Default)]
pub struct Memory {
    /// Objects sphere traced.
    pub sdf_objects: usize,
    /// Bytes of SDF closure state.
    pub closure_bytes: usize,
    /// Per mesh object: its `object` statement and memory.
    pub meshes: Vec<(Span, MeshMemory)>,
    /// Bytes of the top-level BVH.
    pub top_bvh_bytes: usize,
}

impl Memory {
    /// Every byte of geometry.
    pub fn total(&self) -> usize {
        self.closure_bytes
            + self.top_bvh_bytes
            + self.meshes.iter().map(|(_, m)| m.vertex_bytes + m.index_bytes + m.bvh_bytes).sum::<usize>()
    }

    /// All triangles.
    pub fn triangles(&self) -> usize {
        self.meshes.iter().map(|(_, m)| m.triangles).sum()
    }
}

fn pad_box(b: ir::Aabb) -> Aabb {
    // Widen by a few ulps so the f32 box never clips the surface.
    let pad = b.max.abs().max(b.min.abs()).max_element() * 1e-6 + 1e-6;
    Aabb { min: (b.min - pad).as_vec3a(), max: (b.max + pad).as_vec3a() }
}

/// Builds the frame for `effects` and lowers the scene into a world, with the scene's
/// own sphere-tracing settings: the one call the CLI, tests and benchmarks use.
pub fn prepare(
    scene: &ir::Scene,
    effects: crate::effects::Effects,
    mode: Mode,
    loader: &dyn Loader,
) -> Result<(Frame, World), Diagnostic> {
    let mut frame = Frame::with_effects(scene, effects);
    let params = MarchParams { epsilon: scene.settings.epsilon as f32, max_steps: scene.settings.max_steps };
    let world = lower(scene, &mut frame, mode, params, loader)?;
    Ok((frame, world))
}

/// Lowers every object of the scene. Materials are interned into `frame`; mesh files
/// are read through `loader`.
pub fn lower(
    scene: &ir::Scene,
    frame: &mut Frame,
    mode: Mode,
    params: MarchParams,
    loader: &dyn Loader,
) -> Result<World, Diagnostic> {
    // Render space: world translated so the camera is at the origin, composed in f64.
    let to_render = DAffine3::from_translation(-frame.origin);
    let max_distance = frame.max_distance as f64;
    let mut builder = sdf::Builder { materials: &mut frame.materials, bytes: 0 };
    let mut budget = mesh::lower::MAX_SCENE_TRIANGLES;
    // In scene order: materials are interned and the triangle budget spent as objects
    // come, so ids and errors do not depend on timing. Meshes are built afterwards.
    let mut lowered = Vec::with_capacity(scene.objects.len());
    for obj in &scene.objects {
        let part = match (&obj.geometry, mode) {
            (ir::Geometry::Shape(shape), Mode::Sdf) => {
                let bounds = ir::shape_bounds(shape).map(|b| pad_box(b.transform(&to_render)));
                let sphere = ir::shape_sphere(shape).map(|(c, r)| {
                    let c = to_render.transform_point3(c);
                    let pad = (c.abs().max_element() + r) * 1e-6 + 1e-6;
                    (c.as_vec3a(), (r + pad) as f32)
                });
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
    Ok(World { objects, bvh, bounded, unbounded, params, closure_bytes, has_meshes, share_walks })
}

impl World {
    /// Memory by structure.
    pub fn memory(&self) -> Memory {
        let mut m = Memory { closure_bytes: self.closure_bytes, top_bvh_bytes: self.bvh.bytes(), ..Memory::default() };
        for o in &self.objects {
            match &o.kind {
                ObjectKind::Sdf(_) => m.sdf_objects += 1,
                ObjectKind::Mesh(mesh) => m.meshes.push((o.span, mesh.memory())),
            }
        }
        m
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether there are no objects.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// The SDF of object `i` at a render-space point, if it is an SDF object (for tests).
    pub fn sdf_eval(&self, i: usize, p: Vec3A) -> Option<f32> {
        match &self.objects.get(i)?.kind {
            ObjectKind::Sdf(o) => Some(o.eval(p)),
            ObjectKind::Mesh(_) => None,
        }
    }

    /// The interval of the ray inside object `i`'s bounds, clipped to `[ray.t_min, t_max]`.
    #[inline]
    fn interval(&self, o: &Object, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        let (t0, t1) = match o.bounds {
            Some(b) => b.slab(ray.origin, ray.inv_dir, ray.t_min, t_max)?,
            None => (ray.t_min, t_max),
        };
        clip_to_sphere(o, ray, (t0, t1))
    }

    /// Whether the ray can reach mesh object `o` before `t_max`. Only its sphere is
    /// tested: its box is the root of the mesh's own BVH, whose walk tests it anyway.
    #[inline]
    fn may_reach_mesh(&self, o: &Object, ray: &Ray, t_max: f32) -> bool {
        clip_to_sphere(o, ray, (ray.t_min, t_max)).is_some()
    }

    /// The closest surface of object `i` before `t_max`, without its shading data.
    fn find(&self, i: u32, q: &mut Query<'_>, t_max: f32, c: &mut Counters) -> Option<Found> {
        if i == q.ray.skip {
            return None;
        }
        let o = &self.objects[i as usize];
        match &o.kind {
            ObjectKind::Sdf(s) => s
                .closest(q.ray, self.interval(o, q.ray, t_max)?, self.params, c, &mut q.evals)
                .map(|(t, error)| Found::Sdf { object: i, t, error }),
            // Triangles are tested exactly; the sphere only decides whether to look.
            ObjectKind::Mesh(m) if self.may_reach_mesh(o, q.ray, t_max) => {
                m.closest(q.ray, q.shear(), t_max, c).map(|(tri, hit)| Found::Mesh { object: i, tri, hit })
            }
            ObjectKind::Mesh(_) => None,
        }
    }

    /// Normal, material and error of the winning surface, computed once per ray.
    fn surface(&self, found: Found, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        match found {
            Found::Sdf { object, t, error } => match &self.objects[object as usize].kind {
                ObjectKind::Sdf(s) => Some(s.surface(ray, t, error, object, c)),
                ObjectKind::Mesh(_) => None,
            },
            Found::Mesh { object, tri, hit } => match &self.objects[object as usize].kind {
                ObjectKind::Mesh(m) => Some(m.surface(tri, hit, object)),
                ObjectKind::Sdf(_) => None,
            },
        }
    }

    /// Completes a ray's closest-hit query: the unbounded objects (outside the top-level
    /// tree) are tried up to the tree's closest hit, then the counters are settled and the
    /// winner's surface is computed.
    #[inline(always)]
    fn finish(&self, q: &mut Query<'_>, mut best: Option<Found>, c: &mut Counters) -> Option<Hit> {
        for &i in &self.unbounded {
            let limit = best.map_or(q.ray.t_max, |f| f.t());
            if let Some(found) = self.find(i, q, limit, c) {
                best = Some(found);
            }
        }
        q.settle(c);
        self.surface(best?, q.ray, c)
    }

    fn blocks(&self, i: u32, q: &mut Query<'_>, t_max: f32, c: &mut Counters) -> bool {
        if i == q.ray.skip {
            return false;
        }
        let o = &self.objects[i as usize];
        match &o.kind {
            ObjectKind::Sdf(s) => self
                .interval(o, q.ray, t_max)
                .is_some_and(|interval| s.closest(q.ray, interval, self.params, c, &mut q.evals).is_some()),
            ObjectKind::Mesh(m) => self.may_reach_mesh(o, q.ray, t_max) && m.occluded(q.ray, q.shear(), t_max, c),
        }
    }

    /// [`Geometry::intersect4`] for `N` packets of four traced together: one walk of the
    /// top-level tree and of each mesh's tree for all of their rays.
    #[inline]
    fn intersect_packet<const N: usize>(&self, quads: &[Packet; N], c: &mut Counters) -> [[Option<Hit>; 4]; N] {
        // The shared walk knows no skips; packets of camera rays never have one.
        if !self.share_walks || quads.iter().any(|q| q.rays.iter().any(|r| r.skip != NO_OBJECT)) {
            return self.each_quad(quads, c);
        }
        let mut mask = 0;
        let mut rays4 = [Rays4 { origin: [Vec4::ZERO; 3], inv_dir: [Vec4::ZERO; 3], t_min: Vec4::ZERO }; N];
        let mut dirs = [[Vec4::ZERO; 3]; N];
        let mut t_max = [Vec4::ZERO; N];
        for (g, quad) in quads.iter().enumerate() {
            rays4[g] = Rays4 {
                origin: quad.across(|r| r.origin),
                inv_dir: quad.across(|r| r.inv_dir),
                t_min: quad.each(|r| r.t_min),
            };
            dirs[g] = quad.across(|r| r.dir);
            t_max[g] = quad.each(|r| r.t_max);
            mask |= (quad.mask & 0b1111) << (4 * g);
        }
        // Only the 4-wide triangle test needs the rays to share their origin and shear
        // axes; without (directions too far apart) meshes are tested lane by lane like
        // SDF objects.
        let origin = quads[0].rays[0].origin;
        let shared = || quads.iter().all(|q| q.rays.iter().all(|r| r.origin == origin));
        let shear = (self.has_meshes && shared()).then(|| PacketShear::new(origin, &dirs)).flatten();
        let mut best: [[Option<Found>; 4]; N] = [[None; 4]; N];
        // SDF evaluations per lane; a lane's query is made only for an object tested lane by lane.
        let mut evals = [[0u64; 4]; N];
        let mut visits = 0u64;
        self.bvh.each_packet(&rays4, mask, &mut t_max, &mut visits, |k, lanes, t_max| {
            let i = self.bounded[k as usize];
            let o = &self.objects[i as usize];
            if let (ObjectKind::Mesh(m), Some(shear)) = (&o.kind, &shear) {
                let mut reach = 0;
                for g in 0..N {
                    reach |= sphere_lanes(o, &rays4[g], &dirs[g], t_max[g]) << (4 * g);
                }
                let reach = lanes & reach;
                if reach == 0 {
                    return;
                }
                m.closest_packet(&rays4, shear, reach, t_max, c, |g, l, tri, hit| {
                    best[g][l] = Some(Found::Mesh { object: i, tri, hit });
                });
                return;
            }
            self.find_each(i, quads, lanes, t_max, &mut best, &mut evals, c);
        });
        c.node_visits += visits;
        // A loop, not `array::from_fn` (see `intersect_each`).
        let mut hits = [[None; 4]; N];
        for lane in lanes(mask) {
            let (g, l) = (lane / 4, lane % 4);
            let ray = &quads[g].rays[l];
            hits[g][l] = if self.unbounded.is_empty() && evals[g][l] == 0 {
                // No object left to try and no work to settle: only the winner's surface.
                best[g][l].and_then(|found| self.surface(found, ray, c))
            } else {
                self.finish(&mut Query { evals: evals[g][l], ..Query::new(ray) }, best[g][l], c)
            };
        }
        hits
    }

    /// Each packet's rays traced alone: out of line, like [`World::find_each`].
    #[inline(never)]
    fn each_quad<const N: usize>(&self, quads: &[Packet; N], c: &mut Counters) -> [[Option<Hit>; 4]; N] {
        let mut hits = [[None; 4]; N];
        for (hits, quad) in hits.iter_mut().zip(quads) {
            *hits = intersect_each(self, quad, c);
        }
        hits
    }

    /// Object `i` tested for each lane of `lanes` alone, as the packet walk does for SDF
    /// objects: out of line, so the walk's loop stays small enough for the instruction
    /// cache (inlined, the march loop made it four times larger).
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn find_each<const N: usize>(
        &self,
        i: u32,
        quads: &[Packet; N],
        lanes: u32,
        t_max: &mut [Vec4; N],
        best: &mut [[Option<Found>; 4]; N],
        evals: &mut [[u64; 4]; N],
        c: &mut Counters,
    ) {
        for lane in crate::render::lanes(lanes) {
            let (g, l) = (lane / 4, lane % 4);
            let mut q = Query { evals: evals[g][l], ..Query::new(&quads[g].rays[l]) };
            if let Some(found) = self.find(i, &mut q, t_max[g][l], c) {
                t_max[g][l] = found.t();
                best[g][l] = Some(found);
            }
            evals[g][l] = q.evals;
        }
    }
}

/// A surface found along a ray, before its shading data is computed.
#[derive(Clone, Copy)]
enum Found {
    /// An SDF hit: distance and the threshold there.
    Sdf { object: u32, t: f32, error: f32 },
    /// A triangle hit.
    Mesh { object: u32, tri: u32, hit: mesh::triangle::TriHit },
}

impl Found {
    fn t(&self) -> f32 {
        match self {
            Found::Sdf { t, .. } => *t,
            Found::Mesh { hit, .. } => hit.t,
        }
    }
}

/// Per-ray state shared by the objects one query visits.
struct Query<'a> {
    ray: &'a Ray,
    /// The triangle test's shear, computed the first time a mesh is visited.
    shear: Option<mesh::triangle::Shear>,
    /// SDF evaluations so far.
    evals: u64,
    /// Top-level BVH nodes visited.
    visits: u64,
}

impl<'a> Query<'a> {
    fn new(ray: &'a Ray) -> Query<'a> {
        Query { ray, shear: None, evals: 0, visits: 0 }
    }

    /// Adds this query's work to the counters.
    fn settle(&self, c: &mut Counters) {
        c.node_visits += self.visits;
        c.sdf_evals += self.evals;
        c.max_evals_per_ray = c.max_evals_per_ray.max(self.evals);
    }

    fn shear(&mut self) -> &mesh::triangle::Shear {
        let dir = self.ray.dir;
        self.shear.get_or_insert_with(|| mesh::triangle::Shear::new(dir))
    }
}

/// `(t0, t1)` narrowed to where the ray is inside the object's bounding sphere, if it has one.
#[inline]
fn clip_to_sphere(o: &Object, ray: &Ray, (t0, t1): (f32, f32)) -> Option<(f32, f32)> {
    let (t0, t1) = match o.sphere {
        Some((centre, radius)) => {
            let (s0, s1) = sphere_interval(ray, centre, radius)?;
            (t0.max(s0), t1.min(s1))
        }
        None => (t0, t1),
    };
    (t0 <= t1).then_some((t0, t1))
}

/// The lanes of a packet that may reach object `o` before their `t_max`: its bounding
/// sphere tested for four rays at once, lane by lane the arithmetic of
/// [`sphere_interval`] and [`clip_to_sphere`] (a mesh object's box is its BVH's root,
/// which the walk tests anyway).
#[inline]
fn sphere_lanes(o: &Object, rays: &Rays4, dir: &[Vec4; 3], t_max: Vec4) -> u32 {
    let Some((centre, radius)) = o.sphere else { return 0b1111 };
    let centre = splat3(centre);
    let oc = [rays.origin[0] - centre[0], rays.origin[1] - centre[1], rays.origin[2] - centre[2]];
    let b = oc[0] * dir[0] + oc[1] * dir[1] + oc[2] * dir[2];
    let perp = [oc[0] - dir[0] * b, oc[1] - dir[1] * b, oc[2] - dir[2] * b];
    let disc = Vec4::splat(radius * radius) - (perp[0] * perp[0] + perp[1] * perp[1] + perp[2] * perp[2]);
    let s = disc.sqrt();
    let (t0, t1) = (rays.t_min.max(-b - s), t_max.min(-b + s));
    (disc.cmpge(Vec4::ZERO) & t0.cmple(t1)).bitmask()
}

/// Where the ray is inside the sphere, or `None`. The discriminant is computed from the
/// perpendicular distance to the centre (Haines et al., *Ray Tracing Gems* ch. 7), which
/// stays accurate for distant spheres where `b² − c` would cancel catastrophically.
#[inline]
pub fn sphere_interval(ray: &Ray, centre: Vec3A, radius: f32) -> Option<(f32, f32)> {
    let oc = ray.origin - centre;
    let b = oc.dot(ray.dir);
    let perp = oc - ray.dir * b;
    let disc = radius * radius - perp.length_squared();
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    Some((-b - s, -b + s))
}

impl Geometry for World {
    fn intersect(&self, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        let mut q = Query::new(ray);
        let mut visits = 0u64;
        let mut best: Option<Found> = None;
        self.bvh.closest(ray.origin, ray.inv_dir, ray.t_min, ray.t_max, &mut visits, |k, t_max| {
            let found = self.find(self.bounded[k as usize], &mut q, t_max, c)?;
            best = Some(found);
            Some(found.t())
        });
        q.visits = visits;
        self.finish(&mut q, best, c)
    }

    fn intersect4(&self, packet: &Packet, c: &mut Counters) -> [Option<Hit>; 4] {
        let [hits] = self.intersect_packet(std::array::from_ref(packet), c);
        hits
    }

    fn intersect16(&self, quads: &[Packet; 4], c: &mut Counters) -> [[Option<Hit>; 4]; 4] {
        self.intersect_packet(quads, c)
    }

    fn occluded(&self, ray: &Ray, c: &mut Counters) -> bool {
        let mut q = Query::new(ray);
        let mut visits = 0u64;
        let hit = self.bvh.any(ray.origin, ray.inv_dir, ray.t_min, ray.t_max, &mut visits, |k, t_max| {
            self.blocks(self.bounded[k as usize], &mut q, t_max, c)
        }) || self.unbounded.iter().any(|&i| self.blocks(i, &mut q, ray.t_max, c));
        q.visits = visits;
        q.settle(c);
        hit
    }

    fn soft_visibility(&self, ray: &Ray, cone: f32, c: &mut Counters) -> Option<f32> {
        if self.has_meshes {
            return None;
        }
        // The penumbra reaches `cone·t` beyond an object, so each object's bounding sphere
        // is widened by the cone's radius at the far end before it is skipped.
        let widen = cone * ray.t_max.min(1e6);
        let mut q = Query::new(ray);
        let mut visibility = 1.0f32;
        for o in &self.objects {
            let ObjectKind::Sdf(s) = &o.kind else { continue };
            let (t0, t1) = match o.sphere {
                Some((centre, radius)) => match sphere_interval(ray, centre, radius + widen) {
                    Some((a, b)) => (a.max(ray.t_min), b.min(ray.t_max)),
                    None => continue,
                },
                None => (ray.t_min, ray.t_max),
            };
            if t0 > t1 {
                continue;
            }
            visibility = visibility.min(s.penumbra(ray, (t0, t1), cone, self.params, c, &mut q.evals));
            if visibility <= 0.0 {
                break;
            }
        }
        q.settle(c);
        Some(visibility)
    }

    fn occlusion(&self, point: Vec3A, normal: Vec3A, reach: f32, c: &mut Counters) -> Option<f32> {
        if self.has_meshes {
            return None;
        }
        // Five taps along the normal (Quilez): where the field is below the distance
        // travelled, something is near; nearer taps weigh more.
        let mut shortfall = 0.0f32;
        let mut weight = 1.0f32;
        let mut evals = 0u64;
        for i in 1..=5 {
            let h = reach * i as f32 / 5.0;
            let p = point + normal * h;
            let d = self
                .objects
                .iter()
                .filter_map(|o| match &o.kind {
                    ObjectKind::Sdf(s) => {
                        let near = o.sphere.is_none_or(|(centre, r)| (p - centre).length() - r < reach);
                        near.then(|| {
                            evals += 1;
                            s.eval(p)
                        })
                    }
                    ObjectKind::Mesh(_) => None,
                })
                .fold(f32::INFINITY, f32::min);
            shortfall += weight * (h - d.min(h)).max(0.0) / reach;
            weight *= 0.5;
        }
        c.sdf_shading_evals += evals;
        Some((1.0 - shortfall * 1.5).clamp(0.0, 1.0))
    }

    fn bytes(&self) -> usize {
        self.memory().total()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The perpendicular-distance form stays accurate where `b² − c` cancels: a unit
    /// sphere 1e4 and 1e5 away, hit near its silhouette, against the same maths in f64.
    #[test]
    fn sphere_interval_is_stable_far_away() {
        for dist in [10.0f64, 1e4, 1e5] {
            for offset in [0.0f64, 0.5, 0.9, 0.999] {
                let centre = glam::DVec3::new(offset, 0.0, dist);
                let dir = glam::DVec3::Z;
                let b = centre.dot(dir);
                let perp = (centre - dir * b).length_squared();
                let s = (1.0 - perp).sqrt();
                let (t0, t1) = (b - s, b + s);
                let ray = Ray::new(Vec3A::ZERO, Vec3A::Z, f32::MAX);
                let (a0, a1) = sphere_interval(&ray, centre.as_vec3a(), 1.0).expect("the ray hits the sphere");
                // Within a few f32 ulps of the distance, not the much larger cancellation error.
                let tol = dist * 4.0 * f32::EPSILON as f64;
                assert!(
                    (a0 as f64 - t0).abs() <= tol && (a1 as f64 - t1).abs() <= tol,
                    "at {dist}, offset {offset}: ({a0}, {a1}) vs ({t0}, {t1})"
                );
                // The naive form b² − c loses the chord entirely this far away.
                if dist >= 1e4 && offset > 0.9 {
                    let c32 = centre.as_vec3().length_squared() - 1.0;
                    let b32 = b as f32;
                    let naive = b32 * b32 - c32;
                    let truth = 1.0 - perp;
                    assert!(
                        (naive as f64 - truth).abs() > 0.5 * truth,
                        "this case should defeat the naive form ({naive} vs {truth})"
                    );
                }
            }
        }
    }
}
