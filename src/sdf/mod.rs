//! The SDF back-end: each object's shape tree becomes a closure-composed distance
//! function, sphere traced inside its bounding box. A BVH over the boxes decides most
//! misses without evaluating any distance; unbounded objects (planes) are marched always.
//!
//! Supported IR subset: every shape. Explicit `mesh …` objects belong to the mesh
//! back-end; lowering rejects them with their span until that back-end exists.

mod build;
pub mod march;
pub mod prim;

use glam::{DAffine3, Vec3A};

pub use build::{min_singular_value, MatSdf, Sdf};
pub use march::MarchParams;

use crate::bvh::{Aabb, Bvh};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, Geometry as IrGeometry};
use crate::render::{Counters, Frame, Geometry, Hit, Ray};
use crate::span::Span;

/// One object ready for marching.
pub struct SdfObject {
    /// Distance bound, for marching.
    pub dist: Sdf,
    /// Distance and material, evaluated once per hit.
    pub mat: MatSdf,
    /// Render-space bounds, if bounded.
    pub bounds: Option<Aabb>,
    /// Render-space bounding sphere (centre, radius), if bounded; tighter than the box for round shapes.
    pub sphere: Option<(Vec3A, f32)>,
    /// The `object` statement.
    pub span: Span,
}

/// A scene of SDF objects.
pub struct SdfScene {
    objects: Vec<SdfObject>,
    bvh: Bvh,
    bounded: Vec<u32>,
    unbounded: Vec<u32>,
    params: MarchParams,
    closure_bytes: usize,
}

/// Per-object memory, for `--stats`.
#[derive(Clone, Debug)]
pub struct SdfMemory {
    /// Bytes of closure state across all objects.
    pub closure_bytes: usize,
    /// Bytes of the top-level BVH.
    pub bvh_bytes: usize,
}

/// Lowers every shape object of the scene; materials are interned into `frame`.
pub fn lower(scene: &ir::Scene, frame: &mut Frame, params: MarchParams) -> Result<SdfScene, Diagnostic> {
    // Render space: world translated so the camera is at the origin, composed in f64.
    let to_render = DAffine3::from_translation(-frame.origin);
    let mut builder = build::Builder {
        materials: &mut frame.materials,
        bytes: 0,
    };
    let mut objects = Vec::with_capacity(scene.objects.len());
    for obj in &scene.objects {
        let shape = match &obj.geometry {
            IrGeometry::Shape(s) => s,
            IrGeometry::Mesh(m) => {
                return Err(Diagnostic::error(
                    codes::LOWERING,
                    m.span,
                    "mesh objects cannot be rendered yet",
                    "this is a mesh",
                )
                .with_note("the mesh back-end is not built yet; only shapes render")
                .with_hint("try the shape instead, e.g. `sphere(1)` for `mesh uvsphere()`"));
            }
        };
        let (dist, mat) = builder.build(shape, to_render, 0);
        let bounds = ir::shape_bounds(shape).map(|b| {
            let b = b.transform(&to_render);
            // Widen by a few ulps so the f32 box never clips the surface.
            let pad = b.max.abs().max(b.min.abs()).max_element() * 1e-6 + 1e-6;
            Aabb {
                min: (b.min - pad).as_vec3a(),
                max: (b.max + pad).as_vec3a(),
            }
        });
        let sphere = ir::shape_sphere(shape).map(|(c, r)| {
            let c = to_render.transform_point3(c);
            let pad = (c.abs().max_element() + r) * 1e-6 + 1e-6;
            (c.as_vec3a(), (r + pad) as f32)
        });
        objects.push(SdfObject {
            dist,
            mat,
            bounds,
            sphere,
            span: obj.span,
        });
    }
    let closure_bytes = builder.bytes;
    let bounded: Vec<u32> = (0..objects.len() as u32)
        .filter(|&i| objects[i as usize].bounds.is_some_and(|b| b.min.cmple(b.max).all()))
        .collect();
    let unbounded = (0..objects.len() as u32)
        .filter(|&i| objects[i as usize].bounds.is_none())
        .collect();
    let boxes: Vec<Aabb> = bounded
        .iter()
        .map(|&i| objects[i as usize].bounds.unwrap_or(Aabb::EMPTY))
        .collect();
    let bvh = Bvh::build(&boxes);
    debug_assert!(bvh.validate(&boxes).is_ok());
    Ok(SdfScene {
        objects,
        bvh,
        bounded,
        unbounded,
        params,
        closure_bytes,
    })
}

impl SdfScene {
    /// Memory use by structure.
    pub fn memory(&self) -> SdfMemory {
        SdfMemory {
            closure_bytes: self.closure_bytes + self.objects.len() * std::mem::size_of::<SdfObject>(),
            bvh_bytes: self.bvh.bytes(),
        }
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether there are no objects.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    fn march_object(&self, i: u32, ray: &Ray, t_max: f32, c: &mut Counters, evals: &mut u64) -> Option<(f32, f32)> {
        let obj = &self.objects[i as usize];
        let (mut t0, mut t1) = match obj.bounds {
            Some(b) => b.slab(ray.origin, ray.inv_dir, ray.t_min, t_max)?,
            None => (ray.t_min, t_max),
        };
        if let Some((centre, radius)) = obj.sphere {
            let (s0, s1) = sphere_interval(ray, centre, radius)?;
            t0 = t0.max(s0);
            t1 = t1.min(s1);
            if t0 > t1 {
                return None;
            }
        }
        march::march(&*obj.dist, ray, t0, t1, self.params, c, evals)
    }
}

impl Geometry for SdfScene {
    fn intersect(&self, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        let mut evals = 0u64;
        let mut visits = 0u64;
        let mut best = self
            .bvh
            .closest(
                ray.origin,
                ray.inv_dir,
                ray.t_min,
                ray.t_max,
                &mut visits,
                |k, t_max| {
                    let i = self.bounded[k as usize];
                    self.march_object(i, ray, t_max, c, &mut evals).map(|(t, _)| t)
                },
            )
            .map(|(k, t)| (self.bounded[k as usize], t));
        for &i in &self.unbounded {
            let limit = best.map_or(ray.t_max, |(_, t)| t);
            if let Some((t, _)) = self.march_object(i, ray, limit, c, &mut evals) {
                best = Some((i, t));
            }
        }
        c.node_visits += visits;
        c.sdf_evals += evals;
        c.max_evals_per_ray = c.max_evals_per_ray.max(evals);
        let (i, t) = best?;
        let obj = &self.objects[i as usize];
        let point = ray.at(t);
        let error = self.params.epsilon * (ray.origin.length() + t);
        let h = error.max(point.abs().max_element() * 8.0 * f32::EPSILON);
        let normal = march::normal(&*obj.dist, point, h);
        let (_, material) = (obj.mat)(point);
        c.sdf_shading_evals += 5;
        Some(Hit {
            t,
            point,
            normal,
            material,
            error,
        })
    }

    fn occluded(&self, ray: &Ray, c: &mut Counters) -> bool {
        let mut evals = 0u64;
        let mut visits = 0u64;
        let hit = self.bvh.any(
            ray.origin,
            ray.inv_dir,
            ray.t_min,
            ray.t_max,
            &mut visits,
            |k, t_max| {
                let i = self.bounded[k as usize];
                self.march_object(i, ray, t_max, c, &mut evals).is_some()
            },
        ) || self
            .unbounded
            .iter()
            .any(|&i| self.march_object(i, ray, ray.t_max, c, &mut evals).is_some());
        c.node_visits += visits;
        c.sdf_evals += evals;
        c.max_evals_per_ray = c.max_evals_per_ray.max(evals);
        hit
    }

    fn bytes(&self) -> usize {
        let m = self.memory();
        m.closure_bytes + m.bvh_bytes
    }
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

/// Evaluates the distance bound of object `i` at a render-space point (for tests).
pub fn eval(scene: &SdfScene, i: usize, p: Vec3A) -> f32 {
    (scene.objects[i].dist)(p)
}
