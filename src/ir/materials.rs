//! Materials: what a surface is made of, and what materials an object can show (every
//! `with` in its tree, and the default grey where some part has none: what the effect set
//! and the checker's lints read).

use glam::DVec3;

use super::{Body, MeshSource, Paint, Shape, ShapeKind};
use crate::span::Span;

/// A surface material: the study's Phong terms, and a transparent medium behind the
/// surface when `transparency` > 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Colour, 0–255 per channel, or a pattern.
    pub color: Paint,
    /// Phong exponent; `None` for no highlight (the study's −1).
    pub specular: Option<f64>,
    /// Reflectivity in [0, 1].
    pub reflective: f64,
    /// The share of light passing into the surface, in [0, 1] (0 = opaque).
    pub transparency: f64,
    /// Index of refraction of the medium inside, in [1, 10] (1 = air: no bending).
    pub ior: f64,
    /// Beer–Lambert absorption inside, per unit of distance, per channel, ≥ 0.
    pub absorption: DVec3,
    /// The colour a surface glows with, 0–255 per channel: under light transport it
    /// emits this (255 is radiance 1) times `emission_strength`.
    pub emission: DVec3,
    /// What the emission colour is multiplied by.
    pub emission_strength: f64,
    /// Mass per unit volume (`scnc measure`), > 0; 1 when not given.
    pub density: f64,
    /// The `material(…)` call.
    pub span: Span,
}

impl Material {
    /// The colour of an object with no material anywhere above it: light grey, matte.
    pub fn default_grey() -> Material {
        Material {
            color: Paint::Solid(DVec3::splat(200.0)),
            specular: None,
            reflective: 0.0,
            transparency: 0.0,
            ior: 1.0,
            absorption: DVec3::ZERO,
            emission: DVec3::ZERO,
            emission_strength: 1.0,
            density: 1.0,
            span: Span::default(),
        }
    }

    /// Whether light passes through the surface (refraction rays are traced).
    pub fn is_transparent(&self) -> bool {
        self.transparency > 0.0
    }

    /// Whether the surface glows (and so is a light under light transport).
    pub fn emits(&self) -> bool {
        self.emission.max_element() > 0.0 && self.emission_strength > 0.0
    }
}

fn materials_of_shape(shape: &Shape, out: &mut Vec<Material>) {
    if let ShapeKind::Paint { material, .. } = &shape.kind {
        out.push((**material).clone());
    }
    shape.children().iter().for_each(|c| materials_of_shape(c, out));
}

/// Every material an object can show, plus the default grey when some part has none.
pub fn materials_of(geometry: &Body) -> Vec<Material> {
    let mut out = Vec::new();
    match geometry {
        Body::Shape(s) => {
            materials_of_shape(s, &mut out);
            if !painted_everywhere(s) {
                out.push(Material::default_grey());
            }
        }
        Body::Mesh(m) => {
            out.push(m.material.as_deref().cloned().unwrap_or_else(Material::default_grey));
            if let MeshSource::Isosurface { shape, .. } = &m.source {
                materials_of_shape(shape, &mut out);
            }
        }
    }
    out
}

/// Whether every leaf of the tree has a material above it.
fn painted_everywhere(shape: &Shape) -> bool {
    match &shape.kind {
        ShapeKind::Paint { .. } => true,
        // A field's surface is its own: the shapes its body measures paint nothing.
        ShapeKind::Primitive(_) | ShapeKind::Field { .. } => false,
        ShapeKind::Warp { .. }
        | ShapeKind::Displace { .. }
        | ShapeKind::Csg { .. }
        | ShapeKind::Round { .. }
        | ShapeKind::Shell { .. }
        | ShapeKind::Repeat { .. }
        | ShapeKind::Transform { .. } => shape.children().iter().all(|c| painted_everywhere(c)),
    }
}
