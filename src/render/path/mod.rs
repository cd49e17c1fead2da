//! Light transport: unidirectional path tracing with next-event estimation and multiple
//! importance sampling, for scenes whose effect set has it (something glows, an area or
//! environment light, `render(bounces = …)`). Every other scene never reaches this
//! module and renders as the Whitted tracer always did.
//!
//! A path starts at the camera (a thin lens when `aperture > 0`) through a point drawn
//! uniformly in its pixel, and its radiance is splatted into the pixels whose tent
//! filter reaches that point (`film.rs`). It meets at most `bounces` surfaces that
//! scatter it. At each it adds light sampled towards one source of the
//! light mixture ([`lights`]) and continues in a direction its BSDF ([`bsdf`]) chooses;
//! emission found either way is weighted by the power heuristic, so every emitter is
//! sampled both ways and neither technique's weakness shows. Delta lobes (mirror,
//! glass) and delta lights (points of radius 0, directional lights) take the one
//! technique that can reach them. Russian roulette ends paths after the third surface
//! with a chance of survival equal to their throughput's largest channel (at most
//! 0.95), dividing survivors by it, so it adds noise but no bias. Nothing is clamped.
//!
//! Approximations, stated: the η² scaling of radiance across a refracting surface is
//! left out (it cancels for every path that leaves the glass it entered); light rays
//! do not pass through glass (a glass-covered light is reached by bounces, as caustics
//! are); an emitting surface emits from its outside only; a sphere light is opaque and
//! dark from within.
//!
//! Units: radiance 1 is a white surface at full light, written as 255 before the tone
//! map, which scales by `2^exposure` and clamps to the image's range.

pub mod bsdf;
mod film;
pub mod lights;
pub mod sampler;

use glam::Vec3A;

use self::bsdf::{Bsdf, Lobe};
pub(super) use self::film::rows;
use self::film::Patch;
pub use self::film::{PathPixel, MOST_SAMPLE_RADIANCE, WEIGHT_ONE};
use self::lights::Source;
pub use self::lights::Transport;
use self::sampler::{PixelSeeds, Sampler};
use super::transmit::{self, Media};
use super::{Frame, ShadeLight};
use crate::trace::{spawn_offset, Counters, Geometry, Hit, Ray, PATH_BINS};

/// Surfaces a path meets before Russian roulette may end it.
const ROULETTE_AFTER: u32 = 3;

/// A pixel's samples, each splatted into `patch` where it lands: `frame.samples` of
/// them, or with adaptive sampling as many as the pixel's noise needs, weighed as
/// `frame.samples` ([`Patch::scale`]).
fn pixel(g: &dyn Geometry, frame: &Frame, t: &Transport, (px, py): (u32, u32), c: &mut Counters, patch: &mut Patch) {
    let most = frame.samples.max(1);
    let pixel = py.wrapping_mul(frame.width).wrapping_add(px);
    let mut p = Noise::default();
    let mut seeds = PixelSeeds::new(pixel);
    let mut count = 0u32;
    // Adaptive sampling doubles the samples until the error estimate is small enough:
    // powers of two keep every pair of the sampler stratified.
    let mut target = if t.noise.is_some() { ADAPTIVE_FIRST.min(most) } else { most };
    loop {
        while count < target {
            let mut sampler = Sampler::new(&mut seeds, t.first_sample.wrapping_add(count));
            let at = sampler.next2();
            let ray = camera_ray(frame, t, (px as f32 + at.0, py as f32 + at.1), &mut sampler);
            c.primary_rays += 1;
            let mut l = radiance(g, frame, t, ray, &mut sampler, c);
            if !l.is_finite() {
                c.nonfinite_samples += 1;
                l = Vec3A::ZERO;
            }
            if let Some(most) = t.clamp {
                let top = l.max_element();
                if top > most {
                    l *= most / top;
                    c.clamped_samples += 1;
                }
            }
            p.add(l);
            patch.splat(at, l);
            count += 1;
        }
        match t.noise {
            Some(eps) if count < most && p.relative_error(count, t.exposure) > eps => {
                target = target.saturating_mul(2).min(most);
            }
            _ => break,
        }
    }
    patch.scale(count, most);
    c.path_pixels += 1;
    if count >= 2 {
        c.noise_pixels += 1;
        c.noise_ppm += (f64::from(p.relative_error(count, t.exposure)) * 1e6).min(1e12) as u64;
    }
}

/// Samples adaptive sampling takes before it first estimates a pixel's error.
pub const ADAPTIVE_FIRST: u32 = 16;

/// One pixel's samples so far for the error estimate: their luminance's sum and sum of
/// squares (in f64: a sum of squares over a million samples in f32 would lose the
/// variance).
#[derive(Default)]
struct Noise {
    y: f64,
    y2: f64,
}

impl Noise {
    fn add(&mut self, l: Vec3A) {
        let y = f64::from(l.dot(Vec3A::new(0.2126, 0.7152, 0.0722)));
        self.y += y;
        self.y2 += y * y;
    }

    /// The standard error of the mean luminance of `count` samples over the mean, the mean taken as at
    /// least 1/256 of white after `exposure` (darker, the error counts as absolute: a
    /// black pixel's noise is what shows, not its ratio to nothing).
    fn relative_error(&self, count: u32, exposure: f32) -> f32 {
        let n = f64::from(count);
        if n < 2.0 {
            return f32::INFINITY;
        }
        let mean = self.y / n;
        let var = ((self.y2 - n * mean * mean) / (n - 1.0)).max(0.0);
        let floor = 1.0 / (256.0 * f64::from(exposure));
        ((var / n).sqrt() / mean.max(floor)) as f32
    }
}

/// The camera ray of one sample: through the point `(x, y)` of the image plane (in
/// pixels), from a point of the lens when it has an aperture.
fn camera_ray(frame: &Frame, t: &Transport, (x, y): (f32, f32), s: &mut Sampler) -> Ray {
    let dir = frame.direction(x, y);
    // Drawn whether or not there is a lens, so the later pairs are the same either way.
    let (l1, l2) = s.next2();
    if t.lens_radius <= 0.0 {
        return Ray::new(Vec3A::ZERO, dir, frame.max_distance);
    }
    // Every point at the focus distance along the view is sharp: the ray through the
    // lens point aims where the pinhole ray crosses that plane.
    let focal = dir * (t.focus / dir.dot(frame.forward).max(1e-6));
    let r = t.lens_radius * l1.sqrt();
    let phi = std::f32::consts::TAU * l2;
    let lens = frame.right.normalize() * (r * phi.cos()) + frame.up.normalize() * (r * phi.sin());
    Ray::new(lens, (focal - lens).normalize(), frame.max_distance)
}

/// What a ray meets first.
enum Event {
    /// Nothing: it escapes to the environment.
    Escape,
    /// A rectangle or sphere of light, with the radiance it sends back along the ray (0
    /// from behind), at a distance.
    Lamp(f32, f32),
    /// A surface.
    Surface(Hit),
}

/// The first thing along `ray`: a surface the geometry reports, or one of the lights
/// light transport draws itself, whichever is nearer.
fn first_event(g: &dyn Geometry, t: &Transport, ray: &Ray, c: &mut Counters) -> Event {
    let hit = g.intersect(ray, c);
    match (nearest_lamp(t, ray, hit.map_or(ray.t_max, |h| h.t)), hit) {
        (Some((radiance, d)), _) => Event::Lamp(radiance, d),
        (None, Some(h)) => Event::Surface(h),
        (None, None) => Event::Escape,
    }
}

/// The nearest rectangle or sphere of light along `ray` before `limit`: the radiance it
/// sends back along the ray (0 from behind), and its distance.
fn nearest_lamp(t: &Transport, ray: &Ray, limit: f32) -> Option<(f32, f32)> {
    let mut nearest = limit;
    let mut lamp = None;
    for r in &t.rects {
        if let Some(d) = lights::rect_hit(r, ray.origin, ray.dir) {
            if d < nearest && d >= ray.t_min {
                nearest = d;
                lamp = Some(if r.normal.dot(ray.dir) < 0.0 { r.radiance } else { 0.0 });
            }
        }
    }
    for b in &t.balls[..t.lamps] {
        if let Some((d, outside)) = lights::ball_hit(b, ray.origin, ray.dir) {
            if d < nearest && d >= ray.t_min {
                nearest = d;
                lamp = Some(if outside { b.radiance } else { 0.0 });
            }
        }
    }
    lamp.map(|radiance| (radiance, nearest))
}

/// The radiance a light ray brings back: what it meets first, emitting or not. When
/// nothing glows and the ray was aimed at a lamp, only that lamp (or a nearer one) can
/// send light along it, so an any-hit shadow query up to the lamp stands in for the
/// closest hit and its shading (the same light, for less work on every back-end).
fn light_along(
    g: &dyn Geometry,
    frame: &Frame,
    t: &Transport,
    ray: &Ray,
    aimed_at_lamp: bool,
    c: &mut Counters,
) -> Vec3A {
    if aimed_at_lamp && !t.glowing {
        return match nearest_lamp(t, ray, ray.t_max) {
            Some((radiance, d)) if radiance > 0.0 => {
                let mut shadow = *ray;
                shadow.t_max = d;
                if g.occluded(&shadow, c) {
                    Vec3A::ZERO
                } else {
                    Vec3A::splat(radiance)
                }
            }
            _ => Vec3A::ZERO,
        };
    }
    match first_event(g, t, ray, c) {
        Event::Escape => Vec3A::splat(t.environment),
        Event::Lamp(radiance, _) => Vec3A::splat(radiance),
        Event::Surface(h) => {
            if h.from_inside {
                Vec3A::ZERO
            } else {
                frame.materials.materials[h.material as usize].emission * (1.0 / 255.0)
            }
        }
    }
}

/// What the previous scattering leaves for weighing emission the next ray finds.
#[derive(Clone, Copy)]
struct Previous {
    /// Where it scattered, and its shading normal there.
    point: Vec3A,
    normal: Vec3A,
    /// The BSDF's density of the direction taken; `None` for a delta lobe or the camera,
    /// whose emission counts whole.
    pdf: Option<f32>,
}

/// The power heuristic's weight of a technique of density `a` against one of `b`.
fn power(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 && (a2 + b2).is_finite() {
        a2 / (a2 + b2)
    } else if a >= b {
        1.0
    } else {
        0.0
    }
}

/// Emission `le` found along a ray scattered by `prev`, in direction `dir`, weighed
/// against light sampling's chance of the same direction.
fn found(t: &Transport, prev: &Previous, dir: Vec3A, le: Vec3A) -> Vec3A {
    match prev.pdf {
        None => le,
        Some(p) => le * power(p, t.pdf(prev.point, prev.normal, dir)),
    }
}

/// The radiance arriving at the camera along `ray`, in units where 1 is a white surface
/// at full light.
///
/// Long because it is the path loop: each surface met adds its emission, light sampled
/// towards a source, and chooses how the path goes on, with the media and roulette
/// carried between — one state machine a reader follows top to bottom.
fn radiance(g: &dyn Geometry, frame: &Frame, t: &Transport, ray: Ray, s: &mut Sampler, c: &mut Counters) -> Vec3A {
    c.paths += 1;
    let mut l = Vec3A::ZERO;
    let mut beta = Vec3A::ONE;
    let mut media = Media::AIR;
    let mut prev = Previous { point: Vec3A::ZERO, normal: Vec3A::ZERO, pdf: None };
    let mut ray = ray;
    let mut surfaces = 0u32;
    loop {
        let event = first_event(g, t, &ray, c);
        // Beer–Lambert along the segment inside an absorbing medium.
        let travelled = match &event {
            Event::Surface(h) => h.t,
            Event::Lamp(_, d) => *d,
            Event::Escape => ray.t_max,
        };
        if let Some(left) = media.absorb(frame, travelled) {
            beta *= left;
        }
        let hit = match event {
            Event::Escape => {
                if t.environment > 0.0 {
                    l += beta * found(t, &prev, ray.dir, Vec3A::splat(t.environment));
                }
                break;
            }
            Event::Lamp(radiance, _) => {
                if radiance > 0.0 {
                    l += beta * found(t, &prev, ray.dir, Vec3A::splat(radiance));
                }
                break;
            }
            Event::Surface(hit) => hit,
        };
        surfaces += 1;
        let view = -ray.dir;
        let normal = if hit.normal.dot(view) < 0.0 { -hit.normal } else { hit.normal };
        let material = &frame.materials.materials[hit.material as usize];
        if !hit.from_inside && material.emission != Vec3A::ZERO {
            l += beta * found(t, &prev, ray.dir, material.emission * (1.0 / 255.0));
        }
        if surfaces > t.bounces {
            break;
        }
        let offset = spawn_offset(hit.point, hit.error);
        let origin = hit.point + normal * offset;
        let albedo = material.color_at(hit.point - normal * offset) * (1.0 / 255.0);
        let glass = material.transparency;
        let bsdf = Bsdf::new(normal, view, albedo, material.specular, glass, (1.0 - glass) * material.reflective);
        let (u_light, u_lobe) = s.next2();
        let u_pos = s.next2();
        let u_dir = s.next2();
        let (u_roulette, _) = s.next2();
        if bsdf.base() > 0.0 {
            l += beta * sample_light(g, frame, t, &hit, &bsdf, view, origin, &media, (u_light, u_pos), c);
        }
        // Where the path goes on.
        let (dir, weight, pdf, from, next_media) = match bsdf.sample(view, u_lobe, u_dir) {
            None => break,
            Some(Lobe::Base(sc)) => (sc.dir, sc.weight, Some(sc.pdf), origin, media),
            Some(Lobe::Mirror) => (normal * (2.0 * normal.dot(view)) - view, Vec3A::ONE, None, origin, media),
            Some(Lobe::Glass) => {
                let beyond = media.crossing(&hit);
                let (n1, n2) = transmit::indices(frame, &hit, &media, &beyond);
                let split = transmit::split(view, normal, n1, n2);
                // Reflect or refract in proportion to the Fresnel reflectance, so each
                // choice's weight is exactly 1; the number that chose the glass lobe,
                // rescaled, is uniform again for this choice.
                let u = (u_lobe / glass).min(0.999_999_9);
                match split.refracted {
                    Some(dir) if u >= split.reflectance => (dir, Vec3A::ONE, None, hit.point - normal * offset, beyond),
                    _ => (normal * (2.0 * normal.dot(view)) - view, Vec3A::ONE, None, origin, media),
                }
            }
        };
        beta *= weight;
        if beta == Vec3A::ZERO || !beta.is_finite() {
            break;
        }
        if surfaces >= ROULETTE_AFTER {
            let q = beta.max_element().min(0.95);
            if u_roulette >= q {
                break;
            }
            beta /= q;
        }
        c.bounce_rays += 1;
        let dir = dir.normalize();
        let mut next = Ray::leaving(&hit, from, dir, frame.max_distance);
        next.inside = next_media.object();
        media = next_media;
        prev = Previous { point: from, normal, pdf };
        ray = next;
    }
    c.path_lengths[(surfaces as usize).min(PATH_BINS - 1)] += 1;
    l
}

/// Light sampled towards one source chosen uniformly, weighed against the BSDF's chance
/// of the same direction: `f·cos·Le/pdf` times the power heuristic (delta lights whole).
#[allow(clippy::too_many_arguments, reason = "the shading state a light ray starts from")]
fn sample_light(
    g: &dyn Geometry,
    frame: &Frame,
    t: &Transport,
    hit: &Hit,
    bsdf: &Bsdf,
    view: Vec3A,
    origin: Vec3A,
    media: &Media,
    (u_pick, (u1, u2)): (f32, (f32, f32)),
    c: &mut Counters,
) -> Vec3A {
    let k = t.sources.len();
    if k == 0 {
        return Vec3A::ZERO;
    }
    let chance = 1.0 / k as f32;
    let source = t.sources[((u_pick * k as f32) as usize).min(k - 1)];
    let normal = bsdf.normal;
    let light_ray = |dir: Vec3A, t_max: f32| {
        let mut r = Ray::leaving(hit, origin, dir, t_max);
        r.inside = media.object();
        r
    };
    let dir = match source {
        Source::Delta(i) => {
            return delta_light(g, frame, &t.deltas[i], bsdf, view, &light_ray, origin, c) / chance;
        }
        other => match light_direction(t, other, origin, normal, (u1, u2)) {
            Some(dir) => dir,
            None => return Vec3A::ZERO,
        },
    };
    let f = bsdf.eval(view, dir);
    if f == Vec3A::ZERO {
        return Vec3A::ZERO;
    }
    let p_light = t.pdf(origin, normal, dir);
    if p_light <= 0.0 || !p_light.is_finite() {
        return Vec3A::ZERO;
    }
    c.light_rays += 1;
    let aimed_at_lamp = match source {
        Source::Rect(_) => true,
        Source::Ball(i) => i < t.lamps,
        Source::Delta(_) | Source::Environment => false,
    };
    let le = light_along(g, frame, t, &light_ray(dir, frame.max_distance), aimed_at_lamp, c);
    if le == Vec3A::ZERO {
        return Vec3A::ZERO;
    }
    f * le * (normal.dot(dir) * power(p_light, bsdf.pdf(view, dir)) / p_light)
}

/// A direction from `origin` towards a source that is not a delta light: a point of a
/// rectangle drawn by area, a direction uniform in a sphere's cone (or over all
/// directions from inside it), or cosine-weighted about `normal` for the environment.
fn light_direction(t: &Transport, source: Source, origin: Vec3A, normal: Vec3A, (u1, u2): (f32, f32)) -> Option<Vec3A> {
    Some(match source {
        Source::Rect(i) => {
            let r = &t.rects[i];
            let p = r.centre + r.u * (2.0 * u1 - 1.0) + r.v * (2.0 * u2 - 1.0);
            let to = p - origin;
            let len = to.length();
            if len <= 0.0 {
                return None;
            }
            to / len
        }
        Source::Ball(i) => {
            let b = &t.balls[i];
            match lights::cone(b, origin) {
                None => uniform_sphere((u1, u2)),
                Some((cos_max, axis)) => {
                    let one_minus = lights::cone_solid_angle(b, origin, cos_max) / std::f32::consts::TAU;
                    let x = u1 * one_minus;
                    let cos = 1.0 - x;
                    let sin = (x * (2.0 - x)).max(0.0).sqrt();
                    let phi = std::f32::consts::TAU * u2;
                    let (bt, bb) = bsdf::basis(axis);
                    (bt * (sin * phi.cos()) + bb * (sin * phi.sin()) + axis * cos).normalize()
                }
            }
        }
        Source::Environment => bsdf::cosine(normal, (u1, u2)).0,
        Source::Delta(_) => return None,
    })
}

/// The light from one delta light (a point or a directional light), over a shadow ray
/// when it casts shadows: `f·cos·E` for its irradiance `E` at the point.
#[allow(clippy::too_many_arguments, reason = "the shading state a light ray starts from")]
fn delta_light(
    g: &dyn Geometry,
    frame: &Frame,
    d: &lights::Delta,
    bsdf: &Bsdf,
    view: Vec3A,
    light_ray: &dyn Fn(Vec3A, f32) -> Ray,
    origin: Vec3A,
    c: &mut Counters,
) -> Vec3A {
    let (dir, dist, irradiance) = match d.light {
        ShadeLight::Point { position, intensity } => {
            let to = position - origin;
            let dist = to.length();
            if dist <= 0.0 {
                return Vec3A::ZERO;
            }
            (to / dist, dist, intensity / (dist * dist))
        }
        ShadeLight::Directional { towards, intensity } => (towards, f32::INFINITY, intensity),
    };
    let f = bsdf.eval(view, dir);
    if f == Vec3A::ZERO {
        return Vec3A::ZERO;
    }
    if d.shadows {
        c.light_rays += 1;
        if g.occluded(&light_ray(dir, dist.min(frame.max_distance)), c) {
            return Vec3A::ZERO;
        }
    }
    f * (bsdf.normal.dot(dir) * irradiance)
}

/// A direction uniform over the unit sphere.
fn uniform_sphere((u1, u2): (f32, f32)) -> Vec3A {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u2;
    Vec3A::new(r * phi.cos(), r * phi.sin(), z)
}
