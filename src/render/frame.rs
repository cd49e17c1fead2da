//! The back-end-independent part of a lowered scene: camera, lights, materials, settings.

use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3A};

use super::pattern::{self, ShadePattern};
use crate::ir::{self, ColorSpace};
use crate::render::effects::Effects;

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
        let mut t = MaterialTable { materials: Vec::new(), space };
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
        };
        match self.materials.iter().position(|x| *x == sm) {
            Some(i) => i as u32,
            None => {
                self.materials.push(sm);
                self.materials.len() as u32 - 1
            }
        }
    }
}

/// A point or directional light in render space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadeLight {
    /// A point light.
    Point {
        /// Position.
        position: Vec3A,
        /// Intensity.
        intensity: f32,
    },
    /// A light at infinity.
    Directional {
        /// Direction towards the light, unit length.
        towards: Vec3A,
        /// Intensity.
        intensity: f32,
    },
}

/// Everything the tracer needs besides the geometry.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Camera basis in render space (the camera sits at the origin).
    pub forward: Vec3A,
    /// Right vector scaled to half the viewport width at distance 1.
    pub right: Vec3A,
    /// Up vector scaled to half the viewport height at distance 1.
    pub up: Vec3A,
    /// Total ambient intensity.
    pub ambient: f32,
    /// Reach of ambient occlusion in render units (0 when off).
    pub ao_reach: f32,
    /// Lights that cast hard shadows.
    pub casting: Vec<ShadeLight>,
    /// Point lights that cast soft shadows, with their radius.
    pub soft: Vec<(ShadeLight, f32)>,
    /// Lights that cast none (`shadows = false`).
    pub plain: Vec<ShadeLight>,
    /// The effect set the tracer is built for.
    pub effects: Effects,
    /// Materials.
    pub materials: MaterialTable,
    /// Background colour, linear, 0–255.
    pub background: Vec3A,
    /// Reflection recursion depth actually traced (the effect set's useful depth).
    pub depth: u32,
    /// Samples per pixel.
    pub samples: u32,
    /// Far limit of rays.
    pub max_distance: f32,
    /// The world position of the render-space origin (the camera), in f64.
    pub origin: DVec3,
    /// How pixels are encoded (`render(color = …)`).
    pub color: ColorSpace,
    /// Bits per channel of the image (`--bit-depth`).
    pub bit_depth: super::BitDepth,
}

impl Frame {
    /// Builds the frame with a given effect set (`Effects::all` for the general tracer);
    /// materials are filled in by the back-ends' lowering.
    pub fn with_effects(scene: &ir::Scene, effects: Effects) -> Frame {
        let cam = &scene.camera;
        let s = &scene.settings;
        let origin = cam.position;
        // The checker guarantees look_at ≠ position and up ∦ view.
        let forward = (cam.look_at - cam.position).normalize();
        let right = forward.cross(cam.up).normalize();
        // Left-handed like the study: x right, y up, z forward, so right = up × forward.
        let right = -right;
        let up = right.cross(forward).normalize() * -1.0;
        let half_h = (cam.fov.to_radians() * 0.5).tan();
        let half_w = half_h * s.width as f64 / s.height as f64;
        let light = |i: &usize| {
            let l = &scene.lights[*i];
            match &l.kind {
                ir::LightKind::Point { position } => {
                    ShadeLight::Point { position: (*position - origin).as_vec3a(), intensity: l.intensity as f32 }
                }
                ir::LightKind::Directional { towards } => {
                    ShadeLight::Directional { towards: towards.normalize().as_vec3a(), intensity: l.intensity as f32 }
                }
                // Ambient lights are summed into `ambient`, never listed.
                ir::LightKind::Ambient => ShadeLight::Directional { towards: Vec3A::Y, intensity: 0.0 },
            }
        };
        let is_soft = |i: &&usize| scene.lights[**i].radius > 0.0;
        let casting = effects.shadow_lights.iter().filter(|i| !is_soft(i)).map(light).collect();
        let soft =
            effects.shadow_lights.iter().filter(is_soft).map(|i| (light(i), scene.lights[*i].radius as f32)).collect();
        let plain = effects.unshadowed_lights.iter().map(light).collect();
        Frame {
            width: s.width,
            height: s.height,
            forward: forward.as_vec3a(),
            right: (right * half_w).as_vec3a(),
            up: (up * half_h).as_vec3a(),
            ambient: effects.ambient as f32,
            ao_reach: effects.ambient_occlusion.unwrap_or(0.0) as f32,
            casting,
            soft,
            plain,
            materials: MaterialTable::new(s.color),
            background: pattern::linear(s.background.as_vec3a(), s.color),
            depth: effects.useful_depth,
            samples: s.samples,
            max_distance: s.max_distance as f32,
            origin,
            color: s.color,
            bit_depth: super::BitDepth::Eight,
            effects,
        }
    }

    /// The unit direction through image coordinates `(px, py)` (pixels, y down, may be fractional).
    pub fn direction(&self, px: f32, py: f32) -> Vec3A {
        let sx = px * (2.0 / self.width as f32) - 1.0;
        let sy = 1.0 - py * (2.0 / self.height as f32);
        (self.forward + self.right * sx + self.up * sy).normalize()
    }
}
