//! The lowered scene: every object, SDF or mesh, under one top-level BVH, implementing
//! the tracer's [`Geometry`](crate::trace::Geometry) contract. Lowering picks each object's back-end: shapes go
//! to the SDF back-end, or are tessellated in mesh mode; explicit meshes are always meshes.
//!
//! **Invariant:** every object lies in render space (camera at the origin); each bounded
//! object's box and sphere contain its surface, so a ray outside them cannot hit it.
//!
//! - [`lower`](mod@lower): objects to their back-ends, meshes built in parallel.
//! - `query`: the [`Geometry`](crate::trace::Geometry) contract for single rays (closest and any hit).
//! - `packet`: camera rays four and sixteen at a time.
//! - `estimate`: soft shadows and ambient occlusion estimated from SDFs.

mod estimate;
pub mod lower;
mod packet;
mod query;

use glam::Vec3A;

pub use lower::{
    lower, lowering_steps, prepare, prepare_reusing, prepare_until, prepare_within, shape_hull, shape_sphere,
    FrameCache,
};

use crate::accel::{Aabb, Bvh};
use crate::mesh::{Detail, MeshMemory, MeshObject};
use crate::sdf::{MarchParams, SdfObject};
use crate::span::Span;

/// Which back-end renders shapes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mode {
    /// Sphere tracing.
    Sdf,
    /// Tessellation at the given detail.
    Mesh(Detail),
}

/// One object of the world.
#[derive(Clone)]
pub enum ObjectKind {
    /// Sphere traced.
    Sdf(SdfObject),
    /// Triangles, shared with the frames that reuse them.
    Mesh(std::sync::Arc<MeshObject>),
}

#[derive(Clone)]
pub(crate) struct Object {
    kind: ObjectKind,
    bounds: Option<Aabb>,
    sphere: Option<(Vec3A, f32)>,
    /// For an unbounded SDF object, a half-space `n·p ≤ offset` holding it, in render
    /// space: a ray from outside starts marching where it enters, which a grazing ray
    /// along a floor would otherwise spend its whole step budget reaching.
    half_space: Option<(Vec3A, f32)>,
    /// For a bounded SDF object, a convex set holding it in render space (planes, and
    /// cones or an ellipsoid about an axis: `world::shape_hull`): a ray is clipped to it,
    /// so a miss is found without a step and a hit starts at or near the surface.
    hull: Option<std::sync::Arc<query::Entry>>,
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
    /// a sharp union's parts, or a top-level tree with interior nodes). Sphere tracing is
    /// per ray anyway, and on a lone SDF object the packet set-up measured 10–20% slower
    /// than single rays (bench `primary rays/packets sdf/01-sphere` against
    /// `intersect sdf/01-sphere`).
    share_walks: bool,
    /// What lowering found wrong but survivable, in scene order (parts an isosurface lost).
    pub warnings: Vec<crate::diag::Diagnostic>,
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
        self.closure_bytes + self.top_bvh_bytes + self.mesh_bytes()
    }

    /// Bytes of every mesh: vertices, indices and BVHs.
    pub fn mesh_bytes(&self) -> usize {
        self.meshes.iter().map(|(_, m)| m.vertex_bytes + m.index_bytes + m.bvh_bytes).sum()
    }

    /// All triangles.
    pub fn triangles(&self) -> usize {
        self.meshes.iter().map(|(_, m)| m.triangles).sum()
    }
}

impl World {
    /// The `object` statement of the object a [`Hit`](crate::trace::Hit) names, if any
    /// (the studio's click on the preview selects it).
    pub fn span_of(&self, object: u32) -> Option<Span> {
        self.objects.get(object as usize).map(|o| o.span)
    }

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
}
