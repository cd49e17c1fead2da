//! The back-end-independent part of a lowered scene: camera, lights, materials, settings.

use glam::{DVec3, Vec3A};

use crate::ir;

/// A material ready for shading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadeMaterial {
    /// Colour, 0–255 per channel.
    pub color: Vec3A,
    /// Phong exponent, `None` for no highlight.
    pub specular: Option<f32>,
    /// Reflectivity in [0, 1].
    pub reflective: f32,
}

/// Materials by index; index 0 is the default light grey.
#[derive(Clone, Debug)]
pub struct MaterialTable {
    /// The materials.
    pub materials: Vec<ShadeMaterial>,
}

impl Default for MaterialTable {
    fn default() -> MaterialTable {
        let mut t = MaterialTable { materials: Vec::new() };
        t.intern(&ir::Material::default_grey());
        t
    }
}

impl MaterialTable {
    /// The index of this material, adding it if new.
    pub fn intern(&mut self, m: &ir::Material) -> u32 {
        let sm = ShadeMaterial {
            color: m.color.as_vec3a(),
            specular: m.specular.map(|s| s as f32),
            reflective: m.reflective as f32,
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

/// A light in render space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadeLight {
    /// Ambient intensity.
    Ambient(f32),
    /// A point light.
    Point {
        /// Position.
        position: Vec3A,
        /// Intensity.
        intensity: f32,
        /// Casts shadows.
        shadows: bool,
    },
    /// A light at infinity.
    Directional {
        /// Direction towards the light, unit length.
        towards: Vec3A,
        /// Intensity.
        intensity: f32,
        /// Casts shadows.
        shadows: bool,
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
    /// Lights.
    pub lights: Vec<ShadeLight>,
    /// Materials.
    pub materials: MaterialTable,
    /// Background colour, 0–255.
    pub background: Vec3A,
    /// Reflection recursion depth.
    pub depth: u32,
    /// Samples per pixel.
    pub samples: u32,
    /// Far limit of rays.
    pub max_distance: f32,
    /// The world position of the render-space origin (the camera), in f64.
    pub origin: DVec3,
}

impl Frame {
    /// Builds the frame for a scene; materials are filled in by the back-end's lowering.
    pub fn new(scene: &ir::Scene) -> Frame {
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
        let lights = scene
            .lights
            .iter()
            .map(|l| match &l.kind {
                ir::LightKind::Ambient => ShadeLight::Ambient(l.intensity as f32),
                ir::LightKind::Point { position } => ShadeLight::Point {
                    position: (*position - origin).as_vec3a(),
                    intensity: l.intensity as f32,
                    shadows: l.shadows,
                },
                ir::LightKind::Directional { towards } => ShadeLight::Directional {
                    towards: towards.normalize().as_vec3a(),
                    intensity: l.intensity as f32,
                    shadows: l.shadows,
                },
            })
            .collect();
        Frame {
            width: s.width,
            height: s.height,
            forward: forward.as_vec3a(),
            right: (right * half_w).as_vec3a(),
            up: (up * half_h).as_vec3a(),
            lights,
            materials: MaterialTable::default(),
            background: s.background.as_vec3a(),
            depth: s.depth,
            samples: s.samples,
            max_distance: s.max_distance as f32,
            origin,
        }
    }

    /// The unit direction through image coordinates `(px, py)` (pixels, y down, may be fractional).
    pub fn direction(&self, px: f32, py: f32) -> Vec3A {
        let sx = px * (2.0 / self.width as f32) - 1.0;
        let sy = 1.0 - py * (2.0 / self.height as f32);
        (self.forward + self.right * sx + self.up * sy).normalize()
    }
}
