//! Conservative axis-aligned bounds of shapes and meshes, in world units.

use glam::{DAffine3, DVec3};

use super::{CsgOp, Geometry, Mesh, MeshSource, Shape, ShapeKind};

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// A box centred at the origin.
    pub fn centred(half: DVec3) -> Aabb {
        Aabb { min: -half, max: half }
    }

    /// Grown by `d` on every side.
    pub fn grow(self, d: f64) -> Aabb {
        Aabb { min: self.min - d, max: self.max + d }
    }

    /// The smallest box containing both.
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// The overlap of both (may be empty: `min > max` on some axis).
    pub fn intersect(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.max(o.min), max: self.max.min(o.max) }
    }

    /// The bounds of this box after an affine map.
    pub fn transform(self, xf: &DAffine3) -> Aabb {
        let centre = (self.min + self.max) * 0.5;
        let half = (self.max - self.min) * 0.5;
        let m = xf.matrix3;
        let abs = glam::DMat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        let c = xf.transform_point3(centre);
        let h = abs * half;
        Aabb { min: c - h, max: c + h }
    }

    /// Centre point.
    pub fn centre(self) -> DVec3 {
        (self.min + self.max) * 0.5
    }
}

/// Bounds of a shape tree; `None` when it is unbounded (it contains a half-space).
pub fn shape_bounds(shape: &Shape) -> Option<Aabb> {
    let children = |kids: &[std::sync::Arc<Shape>]| kids.iter().map(|k| shape_bounds(k)).collect::<Vec<_>>();
    match &shape.kind {
        ShapeKind::Primitive(p) => p.bounds(),
        ShapeKind::Csg { op: CsgOp::Union, children: kids, smooth } => {
            let all: Option<Vec<Aabb>> = children(kids).into_iter().collect();
            all?.into_iter().reduce(Aabb::union).map(|b| b.grow(*smooth))
        }
        ShapeKind::Csg { op: CsgOp::Intersect, children: kids, smooth } => {
            children(kids).into_iter().flatten().reduce(Aabb::intersect).map(|b| b.grow(*smooth))
        }
        ShapeKind::Csg { op: CsgOp::Subtract, children: kids, smooth } => {
            shape_bounds(kids.first()?).map(|b| b.grow(*smooth))
        }
        ShapeKind::Round { child, radius } => shape_bounds(child).map(|b| b.grow(*radius)),
        ShapeKind::Shell { child, thickness } => shape_bounds(child).map(|b| b.grow(thickness * 0.5)),
        ShapeKind::Repeat { child, period, count } => {
            let b = shape_bounds(child)?;
            let reach = *period * (DVec3::new(count[0] as f64, count[1] as f64, count[2] as f64) - 1.0) * 0.5;
            Some(Aabb { min: b.min - reach, max: b.max + reach })
        }
        ShapeKind::Transform { child, xf } => shape_bounds(child).map(|b| b.transform(xf)),
        ShapeKind::Paint { child, .. } => shape_bounds(child),
    }
}

/// Bounds of a mesh in world space; `None` for a file, whose extent is known only once read.
pub fn mesh_bounds(mesh: &Mesh) -> Option<Aabb> {
    let local = match &mesh.source {
        MeshSource::UvSphere { radius, .. } | MeshSource::IcoSphere { radius, .. } => {
            Aabb::centred(DVec3::splat(*radius))
        }
        MeshSource::Box { half } => Aabb::centred(*half),
        MeshSource::Cylinder { radius, half_height, .. } => Aabb::centred(DVec3::new(*radius, *half_height, *radius)),
        MeshSource::Torus { major, minor, .. } => Aabb::centred(DVec3::new(major + minor, *minor, major + minor)),
        MeshSource::Plane { size } => Aabb::centred(DVec3::new(*size, 0.0, *size)),
        MeshSource::Isosurface { shape, .. } => shape_bounds(shape)?,
        MeshSource::File { .. } => return None,
    };
    Some(local.transform(&mesh.xf))
}

/// A bounding sphere (centre, radius) of an object's geometry, if bounded.
pub fn bounding_sphere(g: &Geometry) -> Option<(DVec3, f64)> {
    let b = match g {
        Geometry::Shape(s) => shape_bounds(s)?,
        Geometry::Mesh(m) => mesh_bounds(m)?,
    };
    (b.min.cmple(b.max).all()).then(|| (b.centre(), (b.max - b.min).length() * 0.5))
}

/// A bounding sphere (centre, radius) of a shape tree, tight for primitives under
/// similarities (a sphere's bound is the sphere itself); `None` when unbounded.
pub fn shape_sphere(shape: &Shape) -> Option<(DVec3, f64)> {
    let from_box = |b: Aabb| (b.centre(), (b.max - b.min).length() * 0.5);
    match &shape.kind {
        ShapeKind::Primitive(p) => p.sphere_radius().map(|r| (DVec3::ZERO, r)),
        ShapeKind::Csg { op: CsgOp::Union, children, smooth } => {
            let spheres: Option<Vec<(DVec3, f64)>> = children.iter().map(|c| shape_sphere(c)).collect();
            let spheres = spheres?;
            let boxes = spheres.iter().map(|(c, r)| Aabb { min: *c - *r, max: *c + *r });
            let centre = boxes.reduce(Aabb::union)?.centre();
            let radius = spheres.iter().map(|(c, r)| (*c - centre).length() + r).fold(0.0, f64::max);
            Some((centre, radius + smooth))
        }
        ShapeKind::Csg { op: CsgOp::Intersect, children, smooth } => children
            .iter()
            .filter_map(|c| shape_sphere(c))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(c, r)| (c, r + smooth)),
        ShapeKind::Csg { op: CsgOp::Subtract, children, smooth } => {
            shape_sphere(children.first()?).map(|(c, r)| (c, r + smooth))
        }
        ShapeKind::Round { child, radius } => shape_sphere(child).map(|(c, r)| (c, r + radius)),
        ShapeKind::Shell { child, thickness } => shape_sphere(child).map(|(c, r)| (c, r + thickness * 0.5)),
        ShapeKind::Repeat { .. } => shape_bounds(shape).map(from_box),
        ShapeKind::Transform { child, xf } => {
            let (c, r) = shape_sphere(child)?;
            Some((xf.transform_point3(c), r * max_stretch(xf.matrix3)))
        }
        ShapeKind::Paint { child, .. } => shape_sphere(child),
    }
}

/// An upper bound of the largest singular value (how far the map can stretch a
/// vector): the largest column-norm sum bound, exact for rotations and scales.
pub fn max_stretch(m: glam::DMat3) -> f64 {
    let mtm = m.transpose() * m;
    // The largest eigenvalue of the symmetric mᵀm is at most its largest absolute row sum.
    let rows = [mtm.row(0), mtm.row(1), mtm.row(2)];
    let bound = rows.iter().map(|r| r.abs().element_sum()).fold(0.0, f64::max);
    bound.sqrt()
}
