//! Whitted/Phong shading exactly as the study: ambient + Σ lights (diffuse `N·L/|L|` +
//! Phong `(R·V/|R||V|)^s`), hard shadows, reflections blended `(1 − r)·local + r·reflected`,
//! colour clamped once at the end.
//!
//! Transparent materials add refraction: `(1 − t)·surface + t·(F·reflected + (1 − F)·refracted)`
//! for transparency `t` and Fresnel reflectance `F` ([`transmit`]),
//! which is the study's model exactly when `t` = 0.
//!
//! The tracer is built for the scene's effect set: `block`, `trace` and `shade` are
//! generic over a const set of flags (the effect table's [`fx`](super::effects::fx):
//! shadow rays, reflection rays, specular highlights, ambient occlusion, refraction),
//! and [`render`](super::render) runs the monomorphised variant that the effect set
//! calls for, chosen before the first ray. Lights arrive pre-split into an ambient sum, casting and non-casting
//! lists, so no per-ray code tests for an effect or a light kind the scene does not have.

use glam::Vec3A;

use super::transmit::{self, Media};
use super::{Frame, ShadeLight};
use crate::trace::{lanes, spawn_offset, Counters, Geometry, Hit, Packet, Ray};

/// Below this share of a pixel a reflected or refracted ray is not traced (its weight
/// is the product of the mirror and transmitted shares along its path): it could change
/// the pixel by at most half an 8-bit step of a surface at full brightness (255 / 512).
/// Deterministic, unlike Russian roulette, so images stay reproducible.
pub const MIN_WEIGHT: f32 = 1.0 / 512.0;

/// Most reflected and refracted rays one sample's ray tree may trace, whatever their
/// weights: a last guard (`--stats` counts the samples that reach it).
pub const MAX_TREE_RAYS: u32 = 4096;

/// What a sample's ray tree may still spend: the share of the pixel the ray being
/// shaded carries, and the rays left.
struct Tree<'a> {
    weight: f32,
    left: &'a mut u32,
}

impl Tree<'_> {
    /// Whether a ray carrying `share` of this one's light is worth tracing (counted as
    /// pruned or over budget when not), and if so, the tree below it.
    fn branch(&mut self, share: f32, c: &mut Counters) -> Option<Tree<'_>> {
        let weight = self.weight * share;
        if weight < MIN_WEIGHT {
            c.pruned_rays += 1;
            return None;
        }
        if *self.left == 0 {
            return None;
        }
        *self.left -= 1;
        if *self.left == 0 {
            c.tree_budget_hits += 1;
        }
        Some(Tree { weight, left: &mut *self.left })
    }
}

use super::effects::fx::{AO, REFLECT, REFRACT, SHADOWS, SPECULAR};

/// The colours (linear, clamped to 0–255) of a block of up to 4×4 pixels from `(x, y)`,
/// `w` wide and `h` high, each averaging `frame.samples` deterministic samples. Each sample's camera rays go
/// to the back-end together, as four 2×2 packets; each pixel is then shaded on its own
/// (secondary rays go one by one). Pixel `(dx, dy)` of the block is entry `4·dy + dx`.
pub(super) fn block<const FX: u8>(
    g: &dyn Geometry,
    frame: &Frame,
    (x, y): (u32, u32),
    (w, h): (u32, u32),
    c: &mut Counters,
) -> [Vec3A; 16] {
    let n = frame.samples.max(1);
    // Lane `l` of packet `q` is pixel `(dx, dy)` of the block; outside `w × h` it traces
    // the nearest pixel inside, unwanted.
    let offset = |q: usize, l: usize| ((2 * (q % 2) + l % 2) as u32, (2 * (q / 2) + l / 2) as u32);
    let wanted: [u32; 4] = std::array::from_fn(|q| {
        (0..4).filter(|&l| offset(q, l).0 < w && offset(q, l).1 < h).fold(0, |m, l| m | 1 << l)
    });
    let mut sums = [Vec3A::ZERO; 16];
    for s in 0..n {
        let (ox, oy) = sample_offset(s, n);
        // Array literals, not `array::from_fn`: whether its moves became `memcpy` calls
        // followed codegen-unit boundaries, and when they did they cost 3.5 % of seed
        // scene 5's instructions (callgrind, `scnc render … --threads 1`).
        let quad = |q: usize| {
            let ray = |l: usize| {
                let (dx, dy) = offset(q, l);
                let (px, py) = (x + dx.min(w - 1), y + dy.min(h - 1));
                Ray::new(Vec3A::ZERO, frame.direction(px as f32 + ox, py as f32 + oy), frame.max_distance)
            };
            Packet { rays: [ray(0), ray(1), ray(2), ray(3)], mask: wanted[q] }
        };
        let quads = [quad(0), quad(1), quad(2), quad(3)];
        c.primary_rays += u64::from(w * h);
        let hits = g.intersect16(&quads, c);
        for (q, quad) in quads.iter().enumerate() {
            for l in lanes(quad.mask) {
                let ray = &quad.rays[l];
                let mut left = MAX_TREE_RAYS;
                let tree = Tree { weight: 1.0, left: &mut left };
                let mut colour = shade::<FX>(g, frame, ray, hits[q][l], frame.depth, Media::AIR, tree, c);
                if !colour.is_finite() {
                    c.nonfinite_samples += 1;
                    colour = Vec3A::ZERO;
                }
                let (dx, dy) = offset(q, l);
                sums[(4 * dy + dx) as usize] += colour.clamp(Vec3A::ZERO, Vec3A::splat(255.0));
            }
        }
    }
    if n > 1 {
        let inv = 1.0 / n as f32;
        for sum in &mut sums {
            *sum *= inv;
        }
    }
    sums
}

/// Sample positions inside the pixel: its centre for one sample, else the R2
/// low-discrepancy sequence (Roberts 2018), which is stratified and deterministic.
fn sample_offset(s: u32, n: u32) -> (f32, f32) {
    if n == 1 {
        return (0.5, 0.5);
    }
    const G: f64 = 1.324_717_957_244_746; // the plastic number
    let (a1, a2) = (1.0 / G, 1.0 / (G * G));
    let i = s as f64 + 1.0;
    (((0.5 + a1 * i) % 1.0) as f32, ((0.5 + a2 * i) % 1.0) as f32)
}

/// The light a point receives from one direct light, before shadowing: the unit vector
/// and distance to the light, the diffuse and highlight light together, and the
/// highlight alone; `None` when the light adds nothing there (behind the surface, no
/// highlight), so no shadow ray is needed.
#[inline(always)]
fn direct<const FX: u8>(
    light: &ShadeLight,
    point: Vec3A,
    normal: Vec3A,
    view: Vec3A,
    specular: Option<f32>,
) -> Option<(Vec3A, f32, f32, f32)> {
    let (to_light, dist, power) = match *light {
        ShadeLight::Point { position, intensity } => {
            let l = position - point;
            (l, l.length(), intensity)
        }
        ShadeLight::Directional { towards, intensity } => (towards, f32::INFINITY, intensity),
    };
    let l_len = to_light.length();
    if l_len <= 0.0 {
        return None;
    }
    let l_unit = to_light / l_len;
    let n_dot_l = normal.dot(l_unit);
    let diffuse = n_dot_l.max(0.0);
    let mut spec = 0.0;
    if FX & SPECULAR != 0 {
        if let Some(s) = specular {
            let r = normal * (2.0 * n_dot_l) - l_unit;
            let r_dot_v = r.dot(view) / r.length().max(f32::MIN_POSITIVE);
            if r_dot_v > 0.0 {
                spec = r_dot_v.powf(s);
            }
        }
    }
    (diffuse > 0.0 || spec > 0.0).then_some((l_unit, dist, power * (diffuse + spec), power * spec))
}

/// Shadow rays per soft light when the back-end cannot estimate a penumbra.
const SOFT_SAMPLES: u32 = 16;

/// The light let through from a round light of `radius` at distance `t_max` along
/// `dir`, per channel: the back-end's one-query penumbra estimate if it has one (SDF
/// scenes without transparent materials), else the average over [`SOFT_SAMPLES`] shadow
/// rays to points spread over the light's disk.
#[allow(clippy::too_many_arguments, reason = "the shading state a shadow ray starts from")]
fn soft_visibility<const FX: u8>(
    g: &dyn Geometry,
    frame: &Frame,
    hit: &Hit,
    origin: Vec3A,
    dir: Vec3A,
    t_max: f32,
    radius: f32,
    media: Media,
    c: &mut Counters,
) -> Vec3A {
    let cone = radius / t_max.max(f32::MIN_POSITIVE);
    // The cone estimate cannot see through glass; with transparent materials every
    // sample is a ray that can.
    if FX & REFRACT == 0 {
        c.shadow_rays += 1;
        // The cone, unlike a ray leaving the surface, may graze the object it starts on (its
        // own horizon hides part of the light near the terminator), so it skips nothing.
        if let Some(v) = g.soft_visibility(&Ray::new(origin, dir, t_max), cone, c) {
            return Vec3A::splat(v);
        }
        c.shadow_rays -= 1;
    }
    let centre = origin + dir * t_max;
    let u = dir.any_orthonormal_vector();
    let w = dir.cross(u);
    let mut visible = Vec3A::ZERO;
    for s in 0..SOFT_SAMPLES {
        // Deterministic, evenly spread points on the disk (Vogel's sunflower spiral).
        let r = radius * ((s as f32 + 0.5) / SOFT_SAMPLES as f32).sqrt();
        let a = s as f32 * 2.399_963;
        let target = centre + u * (r * a.cos()) + w * (r * a.sin());
        let to = target - origin;
        let len = to.length();
        let ray = spawn::<FX>(hit, origin, to / len, len, &media);
        visible += shadow::<FX>(g, frame, &ray, media, c);
    }
    visible / SOFT_SAMPLES as f32
}

/// Occlusion rays per hit when the back-end cannot estimate occlusion.
const AO_SAMPLES: u32 = 16;

/// The open fraction of the hemisphere above `origin` within `reach`: the back-end's
/// estimate if it has one (SDF scenes), else the fraction of [`AO_SAMPLES`]
/// cosine-distributed rays (deterministic) that escape.
fn occlusion(g: &dyn Geometry, hit: &Hit, origin: Vec3A, normal: Vec3A, reach: f32, c: &mut Counters) -> f32 {
    if let Some(open) = g.occlusion(origin, normal, reach, c) {
        return open;
    }
    let u = normal.any_orthonormal_vector();
    let w = normal.cross(u);
    let mut open = 0;
    for s in 0..AO_SAMPLES {
        // A disk point (Vogel's spiral) lifted onto the hemisphere: cosine-distributed.
        let r2 = (s as f32 + 0.5) / AO_SAMPLES as f32;
        let a = s as f32 * 2.399_963;
        let (x, y) = (r2.sqrt() * a.cos(), r2.sqrt() * a.sin());
        let dir = (u * x + w * y + normal * (1.0 - r2).max(0.0).sqrt()).normalize();
        c.occlusion_rays += 1;
        if !g.occluded(&Ray::leaving(hit, origin, dir, reach), c) {
            open += 1;
        }
    }
    open as f32 / AO_SAMPLES as f32
}

/// The colour seen along `ray` travelling in `media`, 0–255 per channel but not yet clamped.
fn trace<const FX: u8>(
    g: &dyn Geometry,
    frame: &Frame,
    ray: &Ray,
    depth: u32,
    media: Media,
    tree: Tree<'_>,
    c: &mut Counters,
) -> Vec3A {
    let hit = g.intersect(ray, c);
    let colour = shade::<FX>(g, frame, ray, hit, depth, media, tree, c);
    if FX & REFRACT == 0 {
        return colour;
    }
    // Beer–Lambert: the medium the ray crossed to get here absorbs along the way.
    match media.absorb(frame, hit.map_or(ray.t_max, |h| h.t)) {
        Some(left) => colour * left,
        None => colour,
    }
}

/// The light arriving from one direct light over a shadow ray, per channel: all or
/// nothing, or, through transparent objects, what they let pass.
#[inline(always)]
fn shadow<const FX: u8>(g: &dyn Geometry, frame: &Frame, ray: &Ray, media: Media, c: &mut Counters) -> Vec3A {
    c.shadow_rays += 1;
    if ray.t_max <= 0.0 {
        return Vec3A::ONE;
    }
    if FX & REFRACT != 0 {
        return transmit::light_through(g, frame, ray, media, c);
    }
    if g.occluded(ray, c) {
        Vec3A::ZERO
    } else {
        Vec3A::ONE
    }
}

/// A secondary ray from `origin`, just off `hit`, travelling in `media` (which only a
/// tracer with refraction tracks; without it every ray is in air).
#[inline(always)]
fn spawn<const FX: u8>(hit: &Hit, origin: Vec3A, dir: Vec3A, t_max: f32, media: &Media) -> Ray {
    let mut ray = Ray::leaving(hit, origin, dir, t_max);
    if FX & REFRACT != 0 {
        ray.inside = media.object();
    }
    ray
}

/// The colour seen along `ray` (travelling in `media`) given what it hit (`None`: the
/// background); `tree` is what its sample may still spend on reflected and refracted rays.
///
/// Long because it is the one place the effects apply, in the order light is gathered
/// (occlusion, direct light and shadows, highlights, reflection, refraction), each
/// behind its compile-time flag.
#[allow(clippy::too_many_arguments, reason = "the state a ray is shaded in")]
fn shade<const FX: u8>(
    g: &dyn Geometry,
    frame: &Frame,
    ray: &Ray,
    hit: Option<Hit>,
    depth: u32,
    media: Media,
    mut tree: Tree<'_>,
    c: &mut Counters,
) -> Vec3A {
    let Some(hit) = hit else {
        return frame.background;
    };
    let view = -ray.dir;
    // Seen from behind (inside a solid or a one-sided surface): shade the side we see.
    let normal = if hit.normal.dot(view) < 0.0 { -hit.normal } else { hit.normal };
    let material = &frame.materials.materials[hit.material as usize];
    let offset = spawn_offset(hit.point, hit.error);
    let origin = hit.point + normal * offset;
    let transparency = if FX & REFRACT != 0 { material.transparency } else { 0.0 };

    // The surface's own light, and its highlights alone: a transparent surface shows
    // its diffuse light in proportion to its opacity, but its highlights whole (they
    // are the lights' reflections). Skipped where neither shows (clear glass, matte).
    let mut local = Vec3A::ZERO;
    let mut shine = Vec3A::ZERO;
    let highlights = FX & SPECULAR != 0 && material.specular.is_some();
    if transparency < 1.0 || highlights {
        let mut light = Vec3A::splat(frame.ambient);
        if FX & AO != 0 {
            light *= occlusion(g, &hit, origin, normal, frame.ao_reach, c);
        }
        // A light's diffuse and highlight light together, and (for the transmitted
        // share) its highlight alone, each as much as reached the point.
        let mut gather = |amount: f32, spec: f32, passed: Vec3A| {
            light += amount * passed;
            if FX & REFRACT != 0 {
                shine += spec * passed;
            }
        };
        if FX & SHADOWS != 0 {
            for l in &frame.casting {
                let Some((l_unit, dist, amount, spec)) = direct::<FX>(l, hit.point, normal, view, material.specular)
                else {
                    continue;
                };
                let ray = spawn::<FX>(&hit, origin, l_unit, (dist - offset).min(frame.max_distance), &media);
                gather(amount, spec, shadow::<FX>(g, frame, &ray, media, c));
            }
            for (l, radius) in &frame.soft {
                let Some((l_unit, dist, amount, spec)) = direct::<FX>(l, hit.point, normal, view, material.specular)
                else {
                    continue;
                };
                let t_max = (dist - offset).min(frame.max_distance);
                let passed = if t_max <= 0.0 {
                    Vec3A::ONE
                } else {
                    soft_visibility::<FX>(g, frame, &hit, origin, l_unit, t_max, *radius, media, c)
                };
                gather(amount, spec, passed);
            }
        }
        for l in &frame.plain {
            if let Some((_, _, amount, spec)) = direct::<FX>(l, hit.point, normal, view, material.specular) {
                gather(amount, spec, Vec3A::ONE);
            }
        }
        // Patterns are read just inside the surface (see `ShadeMaterial::color_at`).
        let paint = material.color_at(hit.point - normal * offset);
        local = paint * light;
        // A dielectric's highlight is the light's own colour, as in POV-Ray, Blender's
        // principled BSDF and every physically based model (only metals tint theirs):
        // white light at full brightness, not the surface's colour.
        shine *= 255.0;
    }
    if FX & (REFLECT | REFRACT) == 0 {
        return local;
    }
    let r = if FX & REFLECT != 0 { material.reflective } else { 0.0 };
    let surface = if depth > 0 && r > 0.0 { local * (1.0 - r) } else { local };
    if transparency <= 0.0 && (depth == 0 || r <= 0.0) {
        return surface;
    }
    // Highlights over the transmitted light, which the surface's weight leaves out.
    let highlight = shine * transparency;
    if depth == 0 {
        return surface * (1.0 - transparency) + highlight;
    }
    // How much of the mirror direction shows, and the transmitted direction with the
    // media beyond the surface and its share.
    let mut mirror = r * (1.0 - transparency);
    let mut transmitted = None;
    if transparency > 0.0 {
        let beyond = media.crossing(&hit);
        let (n1, n2) = transmit::indices(frame, &hit, &media, &beyond);
        let split = transmit::split(view, normal, n1, n2);
        mirror += transparency * split.reflectance;
        let through = transparency * (1.0 - split.reflectance);
        transmitted = split.refracted.filter(|_| through > 0.0).map(|dir| (dir, beyond, through));
    }
    let mut colour = surface * (1.0 - transparency) + highlight;
    if mirror > 0.0 {
        if let Some(below) = tree.branch(mirror, c) {
            let reflected_dir = (normal * (2.0 * normal.dot(view)) - view).normalize();
            c.reflection_rays += 1;
            let ray = spawn::<FX>(&hit, origin, reflected_dir, frame.max_distance, &media);
            colour += trace::<FX>(g, frame, &ray, depth - 1, media, below, c) * mirror;
        }
    }
    if let Some((dir, beyond, through)) = transmitted {
        if let Some(below) = tree.branch(through, c) {
            c.refraction_rays += 1;
            let ray = spawn::<FX>(&hit, hit.point - normal * offset, dir, frame.max_distance, &beyond);
            colour += trace::<FX>(g, frame, &ray, depth - 1, beyond, below, c) * through;
        }
    }
    colour
}
