//! `--tolerance`: the cheapest setting expected to keep geometric error under a bound,
//! from the same error model the sweep measures.
//!
//! - **SDF**: a hit is accepted where `d < epsilon · t`, so for an exact SDF the error at a
//!   primary hit is below `epsilon · t`. For an absolute bound `T`, `epsilon = T / t_far`
//!   with `t_far` the farthest point of any bounded object from the camera (the far limit
//!   when something is unbounded). For `pixel`, `epsilon` is the angular size of a pixel,
//!   `2·tan(fov/2) / height`, so the error is below a pixel's footprint at every depth.
//! - **Mesh**: a polygon of `N` sides inscribed in a circle of radius `r` deviates from it by
//!   at most `r·(1 − cos(π/N))`; every curved primitive is tessellated with at least
//!   `rings` sides per turn, so the detail is the smallest `rings` that keeps
//!   `r·(1 − cos(π/rings))` under the bound for every object (for `pixel`, the bound at the
//!   object's nearest distance). Boxes are exact. Isosurfaces (CSG and modifiers) are
//!   given the bound itself (for `pixel`, a pixel's footprint at each point's distance
//!   from the camera): their cells are split until the mesh, measured on every triangle,
//!   lies within it (`mesh::isosurface`).
//! - **Normals**: a curved primitive's mesh shades with its analytic normals, exact at
//!   the vertices, so a pixel's colour errs mostly by where the facet put the hit. That
//!   is all a matte surface shows; glass and mirrors also show what lies behind or in
//!   front of them, moved by the normal's error times the distance to it. The normal at a
//!   point of a facet `δ` inside a surface of radius `r`, met at a slant, errs by about
//!   `2δ/r`, so for a transparent or reflective object the bound is scaled by
//!   `r / (2·D)`, with `D` the extent of the scene's bounded objects (what can be seen
//!   through it), at least its own diameter: `tests/data/ladder/sphere.scn`, a glass
//!   sphere over a floor, is then within 1.5 % of the SDF sphere's pixels at `pixel`.

use crate::ir::{self, Body, DomainOp, ExactMesh, Facets, Scene, Shape, ShapeKind};
use crate::mesh::tree::Deviation;
use crate::mesh::Detail;

/// A geometric error bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tolerance {
    /// World units.
    Absolute(f64),
    /// A pixel's footprint at the surface's depth.
    Pixel,
}

impl std::str::FromStr for Tolerance {
    type Err = String;

    fn from_str(s: &str) -> Result<Tolerance, String> {
        if s == "pixel" {
            return Ok(Tolerance::Pixel);
        }
        match s.parse::<f64>() {
            Ok(t) if t > 0.0 && t.is_finite() => Ok(Tolerance::Absolute(t)),
            _ => Err("expected `pixel` or a distance greater than 0".into()),
        }
    }
}

impl std::fmt::Display for Tolerance {
    /// As written on the command line: `pixel`, or the distance.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Tolerance::Absolute(t) => write!(f, "{t}"),
            Tolerance::Pixel => f.write_str("pixel"),
        }
    }
}

/// The angular size of one pixel (radians per pixel at distance 1).
pub fn pixel_angle(scene: &Scene) -> f64 {
    2.0 * (scene.camera.fov.to_radians() * 0.5).tan() / scene.settings.height as f64
}

/// Nearest and farthest distance of an object's bounds from the camera, if bounded.
fn depth_range(scene: &Scene, g: &Body) -> Option<(f64, f64)> {
    let (c, r) = ir::bounding_sphere(g)?;
    let d = (c - scene.camera.position).length();
    Some(((d - r).max(0.0), d + r))
}

/// The SDF hit threshold for `tol`.
pub fn sdf_epsilon(scene: &Scene, tol: Tolerance) -> f64 {
    let eps = match tol {
        Tolerance::Pixel => pixel_angle(scene),
        Tolerance::Absolute(t) => {
            let far = scene
                .objects
                .iter()
                .map(|o| depth_range(scene, &o.geometry).map_or(scene.settings.max_distance, |(_, f)| f))
                .fold(0.0, f64::max);
            t / far.max(f64::MIN_POSITIVE)
        }
    };
    eps.clamp(crate::builtins::MIN_EPSILON, 0.5)
}

/// Largest radius of curvature among the curved parts of a shape, in world units, and
/// whether it needs an isosurface (its diameter then matters instead).
fn curvature_radius(shape: &Shape, scale: f64) -> (f64, Option<f64>) {
    let isosurface = || {
        let diameter = ir::shape_bounds(shape).map_or(0.0, |b| (b.max - b.min).length()) * scale;
        (0.0, Some(diameter))
    };
    match &shape.kind {
        ShapeKind::Primitive(p) => match p.facets() {
            Facets::Inscribed(radius) => (radius * scale, None),
            Facets::Exact => (0.0, None),
            Facets::Isosurface => isosurface(),
        },
        ShapeKind::Transform { child, xf } => {
            let k = xf.matrix3.to_cols_array().iter().fold(0.0f64, |a, x| a.max(x.abs())) * 3f64.sqrt();
            curvature_radius(child, scale * k)
        }
        ShapeKind::Paint { child, .. } => curvature_radius(child, scale),
        // An extruded polygon's prism: its own flat faces.
        ShapeKind::Field { exact: Some(ExactMesh::Faces(_)), .. } => (0.0, None),
        // An extruded region's flat faces are exact; its circles are inscribed polygons.
        ShapeKind::Field { exact: Some(ExactMesh::Extrusion { region, .. }), .. } => {
            (region.largest_radius() * scale, None)
        }
        // A revolved region: circles about `y` up to its widest point, its own circles.
        ShapeKind::Field { exact: Some(ExactMesh::Revolution { region, radius }), .. } => {
            (radius.max(region.largest_radius()) * scale, None)
        }
        // A lathe is inscribed in circles of up to its widest corner's radius.
        ShapeKind::Field { exact: Some(ExactMesh::Lathe(corners)), .. } => {
            (corners.iter().fold(0.0f64, |r, c| r.max(c.x)) * scale, None)
        }
        // A twist of a shape with a mesh of its own splits that mesh's edges by a
        // circle's step (`mesh::twist`): a circle about `y` through its farthest point.
        ShapeKind::Warp { child, domain_op: Some(DomainOp::Twist(_)), .. } => {
            match (curvature_radius(child, scale), ir::shape_bounds(child)) {
                ((r, None), Some(b)) => (r.max(b.radius_about_y() * scale), None),
                _ => isosurface(),
            }
        }
        // Copies of a part, its halves moved apart or mirrored: the part's.
        ShapeKind::Warp {
            child,
            domain_op: Some(DomainOp::Polar(_) | DomainOp::Elongate(_) | DomainOp::Mirror(_)),
            ..
        } => curvature_radius(child, scale),
        ShapeKind::Csg { .. }
        | ShapeKind::Round { .. }
        | ShapeKind::Shell { .. }
        | ShapeKind::Repeat { .. }
        | ShapeKind::Field { .. }
        | ShapeKind::Warp { .. }
        | ShapeKind::Displace { .. } => isosurface(),
    }
}

/// Whether light bends or mirrors at the shape's surface: a transparent or reflective
/// material anywhere in it.
fn bends_light(shape: &Shape) -> bool {
    let here = match &shape.kind {
        ShapeKind::Paint { material, .. } => material.is_transparent() || material.reflective > 0.0,
        _ => false,
    };
    here || shape.children().iter().any(|c| bends_light(c))
}

/// The diameter of the smallest sphere around every bounded object: how far what a
/// glass or mirror object shows can lie from it.
fn scene_extent(scene: &Scene) -> f64 {
    let spheres: Vec<_> = scene.objects.iter().filter_map(|o| ir::bounding_sphere(&o.geometry)).collect();
    let Some(&(first, _)) = spheres.first() else { return 0.0 };
    let centre = spheres.iter().fold(glam::DVec3::ZERO, |a, (c, _)| a + *c) / spheres.len() as f64;
    let centre = if centre.is_finite() { centre } else { first };
    2.0 * spheres.iter().map(|(c, r)| (*c - centre).length() + r).fold(0.0, f64::max)
}

/// The mesh detail for `tol`: the rings its curved primitives need, and for isosurfaces
/// the bound itself (their cells follow the error: `mesh::tree`).
pub fn mesh_detail(scene: &Scene, tol: Tolerance) -> Detail {
    let mut rings = 3u32;
    let extent = scene_extent(scene);
    for o in &scene.objects {
        let Body::Shape(shape) = &o.geometry else { continue };
        let bound = match tol {
            Tolerance::Absolute(t) => t,
            Tolerance::Pixel => {
                pixel_angle(scene) * depth_range(scene, &o.geometry).map_or(1.0, |(near, _)| near.max(1e-6))
            }
        };
        let (radius, _) = curvature_radius(shape, 1.0);
        // What a glass or mirror object shows moves by its normals' error times the
        // distance to it (see the module's doc).
        let bound = if radius > 0.0 && bends_light(shape) {
            bound * (radius / (2.0 * extent.max(2.0 * radius))).min(1.0)
        } else {
            bound
        };
        if radius > 0.0 {
            // r·(1 − cos(π/N)) ≤ bound  ⇔  N ≥ π / acos(1 − bound/r).
            let ratio = (1.0 - bound / radius).clamp(-1.0, 1.0);
            let n = (std::f64::consts::PI / ratio.acos().max(1e-9)).ceil();
            rings = rings.max(n.min(2048.0) as u32);
        }
    }
    let deviation = match tol {
        Tolerance::Absolute(t) => Deviation::absolute(t),
        Tolerance::Pixel => Deviation { absolute: 0.0, per_distance: pixel_angle(scene), eye: scene.camera.position },
    };
    Detail::Within { rings: rings.clamp(3, 2048), deviation }
}
