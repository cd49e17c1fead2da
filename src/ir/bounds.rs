//! Conservative axis-aligned bounds of shapes and meshes, in world units.

use std::sync::Arc;

use glam::{DAffine3, DMat3, DVec3};

use super::{Body, CsgOp, Mesh, MeshSource, Shape, ShapeKind};
pub use crate::geom::hull::{max_stretch, transform_half_space};
use crate::geom::hull::{Hull, Round};
use crate::geom::DAabb;

/// Bounds of a shape tree; `None` when it is unbounded (it contains a half-space).
pub fn shape_bounds(shape: &Shape) -> Option<DAabb> {
    bounds_within(shape, 0.0)
}

/// Bounds of where the shape's field is at most `g`: the solid grown by `g` in the
/// field's own units. A transform's field is its child's scaled by the smallest
/// singular value `σ` of the map (the SDF back-end's bound), so at `g` it reaches
/// `g / σ` in the child's frame, and the map may stretch that by more than `σ`: a
/// `round` of a non-uniformly scaled part grows further than its radius.
fn bounds_within(shape: &Shape, g: f64) -> Option<DAabb> {
    let children =
        |kids: &[std::sync::Arc<Shape>], g: f64| kids.iter().map(|k| bounds_within(k, g)).collect::<Vec<_>>();
    match &shape.kind {
        // Primitives' fields are exact distances.
        ShapeKind::Primitive(p) => p.bounds().map(|b| b.grow(g)),
        // A smooth union's field is at least the plain minimum less `smooth` (the
        // nearest-first fold stops blending at a gap of `smooth`), so it reaches as far
        // as the parts grown by it.
        ShapeKind::Csg { op: CsgOp::Union, children: kids, smooth } => {
            let all: Option<Vec<DAabb>> = children(kids, g + smooth).into_iter().collect();
            all?.into_iter().reduce(DAabb::union)
        }
        ShapeKind::Csg { op: CsgOp::Intersect, children: kids, smooth } => {
            children(kids, g + smooth).into_iter().flatten().reduce(DAabb::intersect)
        }
        ShapeKind::Csg { op: CsgOp::Subtract, children: kids, smooth } => bounds_within(kids.first()?, g + smooth),
        ShapeKind::Round { child, radius } => bounds_within(child, g + radius),
        ShapeKind::Shell { child, thickness } => bounds_within(child, g + thickness * 0.5),
        ShapeKind::Repeat { child, period, count } => {
            let b = bounds_within(child, g)?;
            let reach = *period * (DVec3::new(count[0] as f64, count[1] as f64, count[2] as f64) - 1.0) * 0.5;
            Some(DAabb { min: b.min - reach, max: b.max + reach })
        }
        ShapeKind::Transform { child, xf } => bounds_within(child, within_child(g, xf)).map(|b| b.transform(xf)),
        ShapeKind::Paint { child, .. } => bounds_within(child, g),
        // A field cut to a box is at most `g` only within `g` of the box.
        ShapeKind::Field { bounds, .. } | ShapeKind::Warp { bounds, .. } => bounds.map(|b| b.grow(g)),
        // (child + d) / (1 + L) ≤ g where child ≤ g·(1 + L) − d ≤ g·(1 + L) + reach.
        ShapeKind::Displace { child, bounds, lipschitz, reach, .. } => match bounds {
            Some(b) => Some(b.grow(g)),
            None => bounds_within(child, g * (1.0 + lipschitz.value) + reach),
        },
    }
}

/// Bounds of a mesh in world space; `None` for a file, whose extent is known only once read.
pub fn mesh_bounds(mesh: &Mesh) -> Option<DAabb> {
    let local = match &mesh.source {
        MeshSource::UvSphere { radius, .. } | MeshSource::IcoSphere { radius, .. } => {
            DAabb::centred(DVec3::splat(*radius))
        }
        MeshSource::Box { half } => DAabb::centred(*half),
        MeshSource::Cylinder { radius, half_height, .. } => DAabb::centred(DVec3::new(*radius, *half_height, *radius)),
        MeshSource::Torus { major, minor, .. } => DAabb::centred(DVec3::new(major + minor, *minor, major + minor)),
        MeshSource::Plane { size } => DAabb::centred(DVec3::new(*size, 0.0, *size)),
        MeshSource::Isosurface { shape, .. } => shape_bounds(shape)?,
        MeshSource::File { .. } => return None,
    };
    Some(local.transform(&mesh.xf))
}

/// A bounding sphere (centre, radius) of an object's geometry, if bounded.
pub fn bounding_sphere(g: &Body) -> Option<(DVec3, f64)> {
    let b = match g {
        Body::Shape(s) => shape_bounds(s)?,
        Body::Mesh(m) => mesh_bounds(m)?,
    };
    (b.min.cmple(b.max).all()).then(|| (b.centre(), (b.max - b.min).length() * 0.5))
}

/// The growth `g` of a transform's field in its child's units: the field is the child's
/// scaled by the map's smallest singular value.
fn within_child(g: f64, xf: &DAffine3) -> f64 {
    if g == 0.0 {
        0.0
    } else {
        g / min_singular_value(xf.matrix3)
    }
}

/// A bounding sphere (centre, radius) of a shape tree, tight for primitives under
/// similarities (a sphere's bound is the sphere itself); `None` when unbounded.
pub fn shape_sphere(shape: &Shape) -> Option<(DVec3, f64)> {
    sphere_within(shape, 0.0, &mut |_, _, _| None)
}

/// A sphere holding where a field's body is at most `level` within a box, found by a
/// search `ir` cannot run (`world` hands it in, as for [`FieldPlanes`]); `None` for none
/// better than the box's own.
pub type FieldSphere<'a> = dyn FnMut(&Arc<super::field::FieldExpr>, DAabb, f64) -> Option<(DVec3, f64)> + 'a;

/// [`shape_sphere`] with a field's sphere from `fields` where it is smaller than its
/// box's.
pub fn shape_sphere_with(shape: &Shape, fields: &mut FieldSphere<'_>) -> Option<(DVec3, f64)> {
    sphere_within(shape, 0.0, fields)
}

/// A sphere around where the shape's field is at most `g` (see [`bounds_within`]).
fn sphere_within(shape: &Shape, g: f64, fields: &mut FieldSphere<'_>) -> Option<(DVec3, f64)> {
    let from_box = |b: DAabb| (b.centre(), (b.max - b.min).length() * 0.5);
    match &shape.kind {
        ShapeKind::Primitive(p) => p.sphere_radius().map(|r| (DVec3::ZERO, r + g)),
        ShapeKind::Csg { op: CsgOp::Union, children, smooth } => {
            let spheres: Option<Vec<(DVec3, f64)>> =
                children.iter().map(|c| sphere_within(c, g + smooth, fields)).collect();
            let spheres = spheres?;
            let boxes = spheres.iter().map(|(c, r)| DAabb { min: *c - *r, max: *c + *r });
            let centre = boxes.reduce(DAabb::union)?.centre();
            let radius = spheres.iter().map(|(c, r)| (*c - centre).length() + r).fold(0.0, f64::max);
            Some((centre, radius))
        }
        ShapeKind::Csg { op: CsgOp::Intersect, children, smooth } => {
            children.iter().filter_map(|c| sphere_within(c, g + smooth, fields)).min_by(|a, b| a.1.total_cmp(&b.1))
        }
        ShapeKind::Csg { op: CsgOp::Subtract, children, smooth } => {
            sphere_within(children.first()?, g + smooth, fields)
        }
        ShapeKind::Round { child, radius } => sphere_within(child, g + radius, fields),
        ShapeKind::Shell { child, thickness } => sphere_within(child, g + thickness * 0.5, fields),
        ShapeKind::Repeat { .. } => bounds_within(shape, g).map(from_box),
        ShapeKind::Transform { child, xf } => {
            let (c, r) = sphere_within(child, within_child(g, xf), fields)?;
            Some((xf.transform_point3(c), r * max_stretch(xf.matrix3)))
        }
        ShapeKind::Paint { child, .. } => sphere_within(child, g, fields),
        // As for its hull: where the field is at most `g`, the body is at most `g·L`
        // within the box grown by `g`.
        ShapeKind::Field { body, bounds: Some(b), sweep: None, lipschitz, .. } => {
            let grown = DAabb { min: b.min - g, max: b.max + g };
            let boxed = from_box(grown);
            Some(fields(body, grown, g * lipschitz.value).filter(|s| s.1 < boxed.1).unwrap_or(boxed))
        }
        ShapeKind::Field { .. } | ShapeKind::Warp { .. } | ShapeKind::Displace { .. } => {
            bounds_within(shape, g).map(from_box)
        }
    }
}

/// A half-space `(n, offset)`, `n` unit, holding an unbounded shape tree: the set of
/// points `p` with `n·p ≤ offset`; `None` when the tree has no such bound that is
/// cheap to find (a union of half-spaces, a repeat) or is bounded.
pub fn shape_half_space(shape: &Shape) -> Option<(DVec3, f64)> {
    half_space_within(shape, 0.0)
}

/// A half-space holding where the shape's field is at most `g` (see [`bounds_within`]).
fn half_space_within(shape: &Shape, g: f64) -> Option<(DVec3, f64)> {
    match &shape.kind {
        ShapeKind::Primitive(p) => p.half_space().map(|(n, o)| (n, o + g)),
        // Any operand's half-space holds an intersection, and the first operand's holds
        // a subtraction; a smooth one reaches `smooth` further (as for boxes).
        ShapeKind::Csg { op: CsgOp::Intersect, children, smooth } => {
            children.iter().find_map(|c| half_space_within(c, g + smooth))
        }
        ShapeKind::Csg { op: CsgOp::Subtract, children, smooth } => half_space_within(children.first()?, g + smooth),
        ShapeKind::Csg { op: CsgOp::Union, .. } | ShapeKind::Repeat { .. } => None,
        ShapeKind::Round { child, radius } => half_space_within(child, g + radius),
        ShapeKind::Shell { child, thickness } => half_space_within(child, g + thickness * 0.5),
        ShapeKind::Transform { child, xf } => {
            let (n, o) = half_space_within(child, within_child(g, xf))?;
            transform_half_space((n, o), xf)
        }
        ShapeKind::Paint { child, .. } => half_space_within(child, g),
        ShapeKind::Field { .. } | ShapeKind::Warp { .. } | ShapeKind::Displace { .. } => None,
    }
}

/// Planes `n·p ≤ offset` holding where a field's body is at most `level` within a box,
/// for the directions where that is nearer than the box's face (`field::support_planes`,
/// which `ir` cannot call: its caller hands the search in); `None` for none.
pub type FieldPlanes<'a> = dyn FnMut(&Arc<super::field::FieldExpr>, DAabb, f64) -> Option<Vec<(DVec3, f64)>> + 'a;

/// A convex set holding the shape ([`Solid::hull`](crate::primitive::Solid::hull)):
/// exactly the solid for a convex polyhedron, a cylinder, a capped cone or an
/// ellipsoid under any affine map, and for intersections of them; for a field, wherever
/// it is in the tree (under transforms, intersections, rounding, a twist), the planes
/// `fields` finds; `None` where there is none that is cheap to find (a union, a repeat).
pub fn shape_hull(shape: &Shape, fields: &mut FieldPlanes<'_>) -> Option<Hull> {
    hull_within(shape, 0.0, fields)
}

/// A convex set holding where the shape's field is at most `g`, by the rules of
/// [`half_space_within`]: every operand's hull holds an intersection (all planes are
/// kept), the first operand's a subtraction.
fn hull_within(shape: &Shape, g: f64, fields: &mut FieldPlanes<'_>) -> Option<Hull> {
    match &shape.kind {
        ShapeKind::Primitive(p) => p.hull().map(|h| h.grown(g)),
        ShapeKind::Csg { op: CsgOp::Intersect, children, smooth } => {
            children.iter().filter_map(|c| hull_within(c, g + smooth, fields)).reduce(Hull::meet)
        }
        ShapeKind::Csg { op: CsgOp::Subtract, children, smooth } => hull_within(children.first()?, g + smooth, fields),
        ShapeKind::Csg { op: CsgOp::Union, .. } | ShapeKind::Repeat { .. } => None,
        ShapeKind::Round { child, radius } => hull_within(child, g + radius, fields),
        ShapeKind::Shell { child, thickness } => hull_within(child, g + thickness * 0.5, fields),
        ShapeKind::Transform { child, xf } => hull_within(child, within_child(g, xf), fields)?.transformed(xf),
        ShapeKind::Paint { child, .. } => hull_within(child, g, fields),
        // An extrusion lies within its slab and its profile's convex hull.
        ShapeKind::Field { sweep: Some(crate::ir::Sweep::Extrude { region, half_height }), .. } => {
            let lines = region.hull_lines();
            let sides = lines.into_iter().map(|(n, d)| (DVec3::new(n.x, 0.0, n.y), d));
            let caps = [(DVec3::Y, *half_height), (-DVec3::Y, *half_height)];
            Some(Hull::planes(sides.chain(caps).collect()).grown(g))
        }
        // A revolved profile lies within the revolved hull of the profile and its mirror.
        ShapeKind::Field { sweep: Some(crate::ir::Sweep::Revolve { region, .. }), .. } => {
            let lines = region.revolved_hull_lines();
            Some(Hull::about_y(lines.into_iter().map(|(n, d)| (n.x, n.y, d)))?.grown(g))
        }
        // A twisted shape stays within its child's cones about y, or else the cylinder
        // about y that holds its child's corners (or box), between the same heights. Its field is the child's divided
        // by the map's stretch, at most `g` where the child's is at most `g·L`.
        ShapeKind::Warp { child, domain_op: Some(crate::ir::DomainOp::Twist(_)), lipschitz, .. } => {
            let g = g * lipschitz.value.max(1.0);
            let hull = hull_within(child, g, fields);
            // Cones about the axis and planes across it are turned into themselves.
            if let Some(Hull { planes, round: Some(round) }) = &hull {
                if round.turns_with_y() {
                    let across = planes.iter().filter(|(n, _)| n.x == 0.0 && n.z == 0.0).copied().collect();
                    return Some(Hull { planes: across, round: Some(round.clone()) });
                }
            }
            let (radius, low, high) = extent_about(&corners_within(child, hull, g)?, |c| (c.x.hypot(c.z), c.y));
            let round = Round::about_y([(1.0, 0.0, radius)])?;
            Some(Hull { planes: vec![(DVec3::Y, high), (-DVec3::Y, -low)], round: Some(round) })
        }
        // A bend turns the point about z by an angle its height fixes: the bent shape
        // stays within what `Hull::bent` finds from its child's corners (or box).
        ShapeKind::Warp { child, domain_op: Some(crate::ir::DomainOp::Bend(k)), lipschitz, .. } => {
            let g = g * lipschitz.value.max(1.0);
            Hull::bent(&corners_within(child, hull_within(child, g, fields), g)?, k.to_radians())
        }
        // A field is its body over its bound `L`, cut to its box: where it is at most
        // `g`, the body is at most `g·L` within the box grown by `g`.
        ShapeKind::Field { body, bounds: Some(b), sweep: None, lipschitz, .. } => {
            let grown = DAabb { min: b.min - g, max: b.max + g };
            let mut planes = fields(body, grown, g * lipschitz.value).filter(|p| !p.is_empty())?;
            // The box's own faces, so the polyhedron is bounded (a twist takes its corners).
            planes.extend(Hull::box_planes(grown));
            Some(Hull::planes(planes))
        }
        ShapeKind::Field { .. } | ShapeKind::Warp { .. } | ShapeKind::Displace { .. } => None,
    }
}

/// Points whose convex hull holds where `shape`'s field is at most `g`: the corners of
/// its planes' polyhedron when its `hull` (at `g`) is one, else its box's corners.
fn corners_within(shape: &Shape, hull: Option<Hull>, g: f64) -> Option<Vec<DVec3>> {
    let corners = hull.filter(|h| h.round.is_none()).map(|h| h.corners());
    match corners.filter(|c| !c.is_empty()) {
        Some(c) => Some(c),
        None => {
            let b = bounds_within(shape, g)?;
            let corner = |i: i32| DVec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), b.max, b.min);
            Some((0..8).map(corner).collect())
        }
    }
}

/// The largest distance from an axis and the range along it of `corners`; `about(p)` is
/// a point's distance from the axis and its place along it.
fn extent_about(corners: &[DVec3], about: impl Fn(DVec3) -> (f64, f64)) -> (f64, f64, f64) {
    corners
        .iter()
        .map(|&c| about(c))
        .fold((0.0_f64, f64::INFINITY, f64::NEG_INFINITY), |acc, (r, t)| (acc.0.max(r), acc.1.min(t), acc.2.max(t)))
}

/// `Some(k)` when `m` is a rotation times a uniform scale `k`.
pub fn similarity(m: DMat3) -> Option<f64> {
    let mtm = m.transpose() * m;
    let k2 = mtm.x_axis.x;
    let eye = DMat3::from_diagonal(DVec3::splat(k2));
    let close = (mtm - eye).to_cols_array().iter().all(|x| x.abs() <= 1e-12 * k2.max(1.0));
    (close && k2 > 0.0).then(|| k2.sqrt())
}

/// The smallest singular value of `m`: the square root of the smallest eigenvalue of
/// the symmetric `mᵀm`, by the closed-form trigonometric method (Smith 1961).
pub fn min_singular_value(m: DMat3) -> f64 {
    if let Some(k) = similarity(m) {
        return k;
    }
    let a = m.transpose() * m;
    let (a11, a22, a33) = (a.x_axis.x, a.y_axis.y, a.z_axis.z);
    let (a12, a13, a23) = (a.y_axis.x, a.z_axis.x, a.z_axis.y);
    let p1 = a12 * a12 + a13 * a13 + a23 * a23;
    let smallest = if p1 == 0.0 {
        a11.min(a22).min(a33)
    } else {
        let q = (a11 + a22 + a33) / 3.0;
        let p2 = (a11 - q).powi(2) + (a22 - q).powi(2) + (a33 - q).powi(2) + 2.0 * p1;
        let p = (p2 / 6.0).sqrt();
        let b = (a - DMat3::from_diagonal(DVec3::splat(q))) * (1.0 / p);
        let r = (b.determinant() / 2.0).clamp(-1.0, 1.0);
        let phi = r.acos() / 3.0;
        // Eigenvalues q + 2p·cos(phi + 2πk/3); the smallest has k = 1.
        q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos()
    };
    // Shave a hair so rounding never makes the bound overstep.
    smallest.max(0.0).sqrt() * (1.0 - 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_singular_value_matches_known_cases() {
        let s = DMat3::from_diagonal(glam::DVec3::new(2.0, 0.5, 3.0));
        assert!((min_singular_value(s) - 0.5).abs() < 1e-9);
        let r = DMat3::from_rotation_x(0.3) * DMat3::from_rotation_y(1.1);
        assert!((min_singular_value(r * 4.0) - 4.0).abs() < 1e-9);
        // Rotation does not change singular values.
        let m = r * s * DMat3::from_rotation_z(0.7);
        assert!((min_singular_value(m) - 0.5).abs() < 1e-9);
        // Never above the true value (it is used as a bound).
        let shear = DMat3::from_cols_array(&[1.0, 0.0, 0.0, 0.9, 1.0, 0.0, 0.0, 0.0, 1.0]);
        let k = min_singular_value(shear);
        for i in 0..1000 {
            let a = i as f64 * 0.01;
            let v = glam::DVec3::new(a.cos(), a.sin(), 0.0);
            assert!((shear * v).length() >= k - 1e-12);
        }
    }

    /// A mapped half-space holds exactly the mapped points of the original: points on
    /// its plane map onto the new plane, and points either side stay on their side.
    #[test]
    fn transformed_half_spaces_hold_the_mapped_points() {
        let n = glam::DVec3::new(0.3, -0.8, 0.5).normalize();
        let xf = DAffine3::from_translation(glam::DVec3::new(1.0, -2.0, 3.0))
            * DAffine3::from_mat3(DMat3::from_cols_array(&[2.0, 0.0, 0.0, 0.7, 0.5, 0.0, 0.0, 0.3, 1.5]))
            * DAffine3::from_rotation_y(0.9);
        let (m, o) = transform_half_space((n, 0.4), &xf).expect("an invertible map");
        assert!((m.length() - 1.0).abs() < 1e-12);
        for i in 0..1000 {
            let f = i as f64;
            let p = glam::DVec3::new((f * 0.37).sin(), (f * 0.71).cos(), (f * 0.13).sin()) * 3.0;
            let before = n.dot(p) - 0.4;
            let after = m.dot(xf.transform_point3(p)) - o;
            assert_eq!(before > 1e-9, after > 1e-9, "{p}: {before} before, {after} after");
            let on = p - n * before;
            assert!((m.dot(xf.transform_point3(on)) - o).abs() < 1e-12, "{on} left the plane");
        }
        assert!(transform_half_space((n, 0.4), &DAffine3::from_mat3(DMat3::ZERO)).is_none());
    }
}
