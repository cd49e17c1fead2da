//! Materials ready for shading, interned by the back-ends as they lower objects and
//! read by the tracer at every hit.

use std::sync::Arc;

use glam::{DAffine3, Vec3A};

use super::pattern::{self, ShadePattern};
use crate::ir::{self, ColorSpace};

/// A material ready for shading.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadeMaterial {
    /// Colour, linear, 0–255 per channel (a pattern's average where there is one).
    pub color: Vec3A,
    /// The pattern that paints it instead of `color`, with its object's space.
    pub pattern: Option<Arc<ShadePattern>>,
    /// Phong exponent, `None` for no highlight.
    pub specular: Option<f32>,
    /// Reflectivity in [0, 1].
    pub reflective: f32,
    /// The share of light passing into the surface, in [0, 1].
    pub transparency: f32,
    /// Index of refraction inside.
    pub ior: f32,
    /// Absorption inside, per unit of distance, per channel.
    pub absorption: Vec3A,
    /// Emitted radiance, linear, 0–255 per channel (255 is radiance 1).
    pub emission: Vec3A,
}

impl ShadeMaterial {
    /// The colour at a render-space point of the surface (just inside it, so a face lying
    /// on a pattern's cell boundary takes one side's colour, not both in speckles).
    #[inline]
    pub fn color_at(&self, inside: Vec3A) -> Vec3A {
        match &self.pattern {
            None => self.color,
            Some(p) => p.color_at(inside),
        }
    }
}

/// Materials by index; index 0 is the default light grey.
#[derive(Clone, Debug)]
pub struct MaterialTable {
    /// The materials.
    pub materials: Vec<ShadeMaterial>,
    /// The `material(…)` call each was first interned from (the default grey's is empty).
    pub spans: Vec<crate::span::Span>,
    /// How the scene's colours are read.
    space: ColorSpace,
}

impl Default for MaterialTable {
    fn default() -> MaterialTable {
        MaterialTable::new(ColorSpace::Linear)
    }
}

impl MaterialTable {
    /// An empty table but for the default grey, reading colours in `space`.
    pub fn new(space: ColorSpace) -> MaterialTable {
        let mut t = MaterialTable { materials: Vec::new(), spans: Vec::new(), space };
        t.intern(&ir::Material::default_grey(), DAffine3::IDENTITY);
        t
    }

    /// The index of this material painting an object whose space is `render_from_local`
    /// of render space, adding it if new. Only a patterned material depends on where it
    /// is; plain ones are shared by every object.
    pub fn intern(&mut self, m: &ir::Material, render_from_local: DAffine3) -> u32 {
        let pattern = pattern::of_material(m, render_from_local, self.space).map(Arc::new);
        let sm = ShadeMaterial {
            color: pattern::linear(m.color.mean().as_vec3a(), self.space),
            pattern,
            specular: m.specular.map(|s| s as f32),
            reflective: m.reflective as f32,
            transparency: m.transparency as f32,
            ior: m.ior as f32,
            absorption: m.absorption.as_vec3a(),
            // The colour read as every colour is, then scaled: decoding is not linear.
            emission: if m.emits() {
                pattern::linear(m.emission.as_vec3a(), self.space) * m.emission_strength as f32
            } else {
                Vec3A::ZERO
            },
        };
        match self.materials.iter().position(|x| *x == sm) {
            Some(i) => i as u32,
            None => {
                self.materials.push(sm);
                self.spans.push(m.span);
                self.materials.len() as u32 - 1
            }
        }
    }
}
