//! What light transport samples light from: the scene's lights and glowing objects in
//! render space, one *source* each, and the density with which next-event estimation
//! picks a direction towards any of them.
//!
//! Light sampling is one mixture: a source is chosen uniformly, then a direction
//! towards it — a rectangle by area, a sphere of light or a glowing object's bounding
//! sphere uniformly within its cone, the environment cosine-weighted. Whatever a
//! direction then meets (which may be another source than the one chosen) is counted
//! with the mixture's density [`Transport::pdf`], so multiple importance sampling
//! weighs every emitter, fields included, against BSDF sampling consistently. A
//! glowing object needs no surface sampler: every point of it lies inside its bounding
//! sphere, so every direction to it lies in the cone.

use glam::{DVec3, Vec3A};

use super::super::ShadeLight;
use crate::ir::{self, LightKind};
use crate::render::effects::Effects;

/// A rectangle of light.
#[derive(Clone, Debug, PartialEq)]
pub struct Rect {
    /// Its centre, render space.
    pub centre: Vec3A,
    /// Half its sides, as vectors along it.
    pub u: Vec3A,
    /// See `u`.
    pub v: Vec3A,
    /// The unit normal of its emitting side (`u × v`).
    pub normal: Vec3A,
    /// Its area.
    pub area: f32,
    /// Radiance from its front.
    pub radiance: f32,
}

/// A sphere: of light, or bounding a glowing object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    /// Centre, render space.
    pub centre: Vec3A,
    /// Radius.
    pub radius: f32,
    /// Radiance from its surface (a sphere of light's; 0 for a glowing object's bound).
    pub radiance: f32,
}

/// A point or directional light under light transport: a delta light, sampled by next-
/// event estimation alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Delta {
    /// The light: a point's intensity is its radiant intensity (irradiance `I / d²` facing
    /// it), a directional light's its irradiance facing it.
    pub light: ShadeLight,
    /// Whether it casts shadows.
    pub shadows: bool,
}

/// One source of the light-sampling mixture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Source {
    /// `deltas[i]`.
    Delta(usize),
    /// `rects[i]`.
    Rect(usize),
    /// `balls[i]` (spheres of light, then glowing objects' bounds).
    Ball(usize),
    /// The environment.
    Environment,
}

/// The scene as light transport sees it, beyond geometry and materials.
#[derive(Clone, Debug, PartialEq)]
pub struct Transport {
    /// Surface interactions after the camera ray.
    pub bounces: u32,
    /// Radiance arriving from every direction where rays escape.
    pub environment: f32,
    /// Point and directional lights.
    pub deltas: Vec<Delta>,
    /// Rectangles of light (none of zero area).
    pub rects: Vec<Rect>,
    /// Spheres of light (the first `lamps`), then bounding spheres of glowing objects.
    pub balls: Vec<Ball>,
    /// How many of `balls` are spheres of light.
    pub lamps: usize,
    /// Whether any object glows (bounded or not): only then can a light ray's first
    /// surface send light back.
    pub glowing: bool,
    /// Every source, in the order a uniform pick indexes.
    pub sources: Vec<Source>,
    /// The thin lens's radius (0: a pinhole).
    pub lens_radius: f32,
    /// The distance along the view at which the lens focuses.
    pub focus: f32,
    /// Pixels are radiance × this × 255 before the tone map (`2^exposure`).
    pub exposure: f32,
    /// The relative error adaptive sampling stops at, if it is on.
    pub noise: Option<f32>,
    /// The most radiance a sample brings in any channel, if clamped.
    pub clamp: Option<f32>,
    /// The index of a pixel's first sample: a render of samples `first_sample ..
    /// first_sample + samples` continues one of the samples before (the studio's
    /// accumulation).
    pub first_sample: u32,
}

impl Transport {
    /// The lights of `scene` in render space, for a scene whose effect set has light
    /// transport with `bounces`.
    ///
    /// Long because it is one match over the light kinds, each converted to render space
    /// and to radiance, then the glowing objects' bounding spheres and the source list.
    pub fn new(scene: &ir::Scene, effects: &Effects, bounces: u32) -> Transport {
        let origin = scene.camera.position;
        let at = |p: DVec3| (p - origin).as_vec3a();
        let mut t = Transport {
            bounces,
            environment: 0.0,
            deltas: Vec::new(),
            rects: Vec::new(),
            balls: Vec::new(),
            lamps: 0,
            glowing: !effects.glowing.is_empty(),
            sources: Vec::new(),
            lens_radius: (scene.camera.aperture * 0.5) as f32,
            focus: scene.camera.focus_distance.unwrap_or_else(|| (scene.camera.look_at - origin).length()) as f32,
            exposure: 2f64.powf(scene.settings.exposure) as f32,
            noise: scene.settings.noise.map(|e| e as f32),
            clamp: scene.settings.clamp.map(|c| c as f32),
            first_sample: 0,
        };
        let mut glowing = Vec::new();
        for l in &scene.lights {
            let intensity = l.intensity as f32;
            if intensity <= 0.0 {
                continue;
            }
            match &l.kind {
                // Light transport has no ambient term (an environment light is its
                // counterpart); the effects line shows ambient off.
                LightKind::Ambient => {}
                LightKind::Environment => t.environment += intensity,
                LightKind::Point { position } if l.radius > 0.0 => {
                    // The same radiant intensity as the point: I = L·πr².
                    let r = l.radius as f32;
                    t.balls.push(Ball {
                        centre: at(*position),
                        radius: r,
                        radiance: intensity / (std::f32::consts::PI * r * r),
                    });
                }
                LightKind::Point { position } => t.deltas.push(Delta {
                    light: ShadeLight::Point { position: at(*position), intensity },
                    shadows: l.shadows,
                }),
                LightKind::Directional { towards } => t.deltas.push(Delta {
                    light: ShadeLight::Directional { towards: towards.normalize().as_vec3a(), intensity },
                    shadows: l.shadows,
                }),
                LightKind::Area { centre, u, v } => {
                    let cross = u.cross(*v);
                    let area = 4.0 * cross.length();
                    if area > 0.0 && area.is_finite() {
                        t.rects.push(Rect {
                            centre: at(*centre),
                            u: u.as_vec3a(),
                            v: v.as_vec3a(),
                            normal: cross.normalize().as_vec3a(),
                            area: area as f32,
                            radiance: intensity,
                        });
                    }
                }
            }
        }
        for &i in &effects.glowing {
            let sphere = match &scene.objects[i].geometry {
                ir::Body::Shape(s) => ir::shape_sphere(s),
                body @ ir::Body::Mesh(_) => ir::bounding_sphere(body),
            };
            // An unbounded glowing object has no cone to aim at: bounces find it alone.
            if let Some((c, r)) = sphere.filter(|(c, r)| c.is_finite() && r.is_finite()) {
                glowing.push(Ball { centre: at(c), radius: r as f32, radiance: 0.0 });
            }
        }
        t.lamps = t.balls.len();
        t.balls.extend(glowing);
        t.sources.extend((0..t.deltas.len()).map(Source::Delta));
        t.sources.extend((0..t.rects.len()).map(Source::Rect));
        t.sources.extend((0..t.balls.len()).map(Source::Ball));
        if t.environment > 0.0 {
            t.sources.push(Source::Environment);
        }
        t
    }

    /// The density (per steradian) with which light sampling from `x` with shading
    /// normal `n` picks the direction `w` (unit), over every source but the delta ones.
    pub fn pdf(&self, x: Vec3A, n: Vec3A, w: Vec3A) -> f32 {
        if self.sources.is_empty() {
            return 0.0;
        }
        let mut p = 0.0;
        for r in &self.rects {
            if let Some(t) = rect_hit(r, x, w) {
                let cos = r.normal.dot(w).abs();
                if cos > 0.0 {
                    p += t * t / (r.area * cos);
                }
            }
        }
        for b in &self.balls {
            p += cone_pdf(b, x, w);
        }
        if self.environment > 0.0 {
            p += n.dot(w).max(0.0) * std::f32::consts::FRAC_1_PI;
        }
        p / self.sources.len() as f32
    }
}

/// Where the ray from `x` along `w` meets the rectangle, if it does (distance > 0).
pub fn rect_hit(r: &Rect, x: Vec3A, w: Vec3A) -> Option<f32> {
    let denom = r.normal.dot(w);
    if denom == 0.0 {
        return None;
    }
    let t = r.normal.dot(r.centre - x) / denom;
    if t.is_nan() || t <= 0.0 {
        return None;
    }
    let d = x + w * t - r.centre;
    let inside = d.dot(r.u).abs() <= r.u.length_squared() && d.dot(r.v).abs() <= r.v.length_squared();
    inside.then_some(t)
}

/// The cone of `b` seen from `x`: the cosine of its half-angle, and the unit axis
/// (`None` when `x` is inside the sphere: every direction).
pub fn cone(b: &Ball, x: Vec3A) -> Option<(f32, Vec3A)> {
    let to = b.centre - x;
    let d2 = to.length_squared();
    let r2 = b.radius * b.radius;
    if d2 <= r2 * 1.000_01 {
        return None;
    }
    let d = d2.sqrt();
    Some(((1.0 - r2 / d2).max(0.0).sqrt(), to / d))
}

/// The solid angle of the cone with half-angle cosine `cos_max`, never 0 for a ball of
/// any size (a far sphere's `1 − cos` loses every digit in f32).
pub fn cone_solid_angle(b: &Ball, x: Vec3A, cos_max: f32) -> f32 {
    let d2 = (b.centre - x).length_squared();
    let s2 = b.radius * b.radius / d2;
    // 1 − √(1 − s²) = s² / (1 + √(1 − s²)), exact where the difference cancels.
    let one_minus = s2 / (1.0 + cos_max);
    std::f32::consts::TAU * one_minus
}

/// The density of a direction drawn uniformly in `b`'s cone from `x` (uniformly over
/// the sphere of directions when `x` is inside it).
fn cone_pdf(b: &Ball, x: Vec3A, w: Vec3A) -> f32 {
    match cone(b, x) {
        None => 1.0 / (4.0 * std::f32::consts::PI),
        Some((cos_max, axis)) if w.dot(axis) >= cos_max => 1.0 / cone_solid_angle(b, x, cos_max),
        Some(_) => 0.0,
    }
}

/// Where the ray from `x` along `w` first meets the sphere's surface (distance > 0),
/// and whether from outside.
pub fn ball_hit(b: &Ball, x: Vec3A, w: Vec3A) -> Option<(f32, bool)> {
    let oc = x - b.centre;
    let half_b = oc.dot(w);
    let c = oc.length_squared() - b.radius * b.radius;
    let disc = half_b * half_b - c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let near = -half_b - s;
    if near > 0.0 {
        return Some((near, true));
    }
    let far = -half_b + s;
    (far > 0.0).then_some((far, false))
}
