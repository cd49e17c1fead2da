//! The back-end-independent part of a lowered scene: camera, lights, materials, settings.

use glam::{DVec3, Vec3A};

use crate::ir::{self, ColorSpace};
use crate::render::effects::Effects;
use crate::trace::{pattern, MaterialTable};

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
    /// The lights, lens and exposure of light transport, when the effect set has it.
    pub transport: Option<super::path::Transport>,
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
                // Ambient lights are summed into `ambient`, area and environment lights
                // are light transport's (`path::Lights`): never listed here.
                ir::LightKind::Ambient | ir::LightKind::Area { .. } | ir::LightKind::Environment => {
                    ShadeLight::Directional { towards: Vec3A::Y, intensity: 0.0 }
                }
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
            transport: effects.light_transport.map(|bounces| super::path::Transport::new(scene, &effects, bounces)),
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
