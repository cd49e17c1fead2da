//! Whitted/Phong shading exactly as the study: ambient + Σ lights (diffuse `N·L/|L|` +
//! Phong `(R·V/|R||V|)^s`), hard shadows, reflections blended `(1 − r)·local + r·reflected`,
//! colour clamped once at the end.
//!
//! The tracer is built for the scene's effect set: `block`, `trace` and `shade` are
//! generic over four const flags (shadow rays, reflection rays, specular highlights,
//! ambient occlusion), and [`render`](super::render) picks the one of sixteen
//! monomorphised variants that the effect set calls for before the first ray. Lights
//! arrive pre-split into an ambient sum, casting and non-casting lists, so no per-ray
//! code tests for an effect or a light kind the scene does not have.

use glam::Vec3A;

use super::{lanes, spawn_offset, Counters, Frame, Geometry, Hit, Packet, Ray, ShadeLight};

/// The 8-bit colours of a block of up to 4×4 pixels from `(x, y)`, `w` wide and `h` high,
/// each averaging `frame.samples` deterministic samples. Each sample's camera rays go
/// to the back-end together, as four 2×2 packets; each pixel is then shaded on its own
/// (secondary rays go one by one). Pixel `(dx, dy)` of the block is entry `4·dy + dx`.
pub(super) fn block<const SHADOWS: bool, const REFLECT: bool, const SPECULAR: bool, const AO: bool>(
    g: &dyn Geometry,
    frame: &Frame,
    (x, y): (u32, u32),
    (w, h): (u32, u32),
    c: &mut Counters,
) -> [[u8; 3]; 16] {
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
                let mut colour = shade::<SHADOWS, REFLECT, SPECULAR, AO>(g, frame, ray, hits[q][l], frame.depth, c);
                if !colour.is_finite() {
                    c.nonfinite_samples += 1;
                    colour = Vec3A::ZERO;
                }
                let (dx, dy) = offset(q, l);
                sums[(4 * dy + dx) as usize] += colour.clamp(Vec3A::ZERO, Vec3A::splat(255.0));
            }
        }
    }
    sums.map(|sum| {
        let avg = if n == 1 { sum } else { sum * (1.0 / n as f32) };
        // Values are in [0, 255], so adding one half and truncating rounds to nearest.
        let q = avg + 0.5;
        [q.x as u8, q.y as u8, q.z as u8]
    })
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

/// The light a point receives from one direct light, before shadowing: `None` when the
/// light adds nothing there (behind the surface, no highlight), so no shadow ray is needed.
#[inline(always)]
fn direct<const SPECULAR: bool>(
    light: &ShadeLight,
    point: Vec3A,
    normal: Vec3A,
    view: Vec3A,
    specular: Option<f32>,
) -> Option<(Vec3A, f32, f32)> {
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
    if SPECULAR {
        if let Some(s) = specular {
            let r = normal * (2.0 * n_dot_l) - l_unit;
            let r_dot_v = r.dot(view) / r.length().max(f32::MIN_POSITIVE);
            if r_dot_v > 0.0 {
                spec = r_dot_v.powf(s);
            }
        }
    }
    (diffuse > 0.0 || spec > 0.0).then_some((l_unit, dist, power * (diffuse + spec)))
}

/// Shadow rays per soft light when the back-end cannot estimate a penumbra.
const SOFT_SAMPLES: u32 = 16;

/// The visible fraction of a round light of `radius` at distance `t_max` along `dir`:
/// the back-end's one-query penumbra estimate if it has one (SDF scenes), else the
/// fraction of [`SOFT_SAMPLES`] shadow rays to points spread over the light's disk.
fn soft_visibility(
    g: &dyn Geometry,
    hit: &Hit,
    origin: Vec3A,
    dir: Vec3A,
    t_max: f32,
    radius: f32,
    c: &mut Counters,
) -> f32 {
    let cone = radius / t_max.max(f32::MIN_POSITIVE);
    c.shadow_rays += 1;
    // The cone, unlike a ray leaving the surface, may graze the object it starts on (its
    // own horizon hides part of the light near the terminator), so it skips nothing.
    if let Some(v) = g.soft_visibility(&Ray::new(origin, dir, t_max), cone, c) {
        return v;
    }
    c.shadow_rays -= 1;
    let centre = origin + dir * t_max;
    let u = dir.any_orthonormal_vector();
    let w = dir.cross(u);
    let mut visible = 0;
    for s in 0..SOFT_SAMPLES {
        // Deterministic, evenly spread points on the disk (Vogel's sunflower spiral).
        let r = radius * ((s as f32 + 0.5) / SOFT_SAMPLES as f32).sqrt();
        let a = s as f32 * 2.399_963;
        let target = centre + u * (r * a.cos()) + w * (r * a.sin());
        let to = target - origin;
        let len = to.length();
        c.shadow_rays += 1;
        if !g.occluded(&Ray::leaving(hit, origin, to / len, len), c) {
            visible += 1;
        }
    }
    visible as f32 / SOFT_SAMPLES as f32
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

/// The colour seen along `ray`, 0–255 per channel but not yet clamped.
fn trace<const SHADOWS: bool, const REFLECT: bool, const SPECULAR: bool, const AO: bool>(
    g: &dyn Geometry,
    frame: &Frame,
    ray: &Ray,
    depth: u32,
    c: &mut Counters,
) -> Vec3A {
    let hit = g.intersect(ray, c);
    shade::<SHADOWS, REFLECT, SPECULAR, AO>(g, frame, ray, hit, depth, c)
}

/// The colour seen along `ray` given what it hit (`None`: the background).
fn shade<const SHADOWS: bool, const REFLECT: bool, const SPECULAR: bool, const AO: bool>(
    g: &dyn Geometry,
    frame: &Frame,
    ray: &Ray,
    hit: Option<Hit>,
    depth: u32,
    c: &mut Counters,
) -> Vec3A {
    let Some(hit) = hit else {
        return frame.background;
    };
    let view = -ray.dir;
    // Seen from behind (inside a solid or a one-sided surface): shade the side we see.
    let normal = if hit.normal.dot(view) < 0.0 { -hit.normal } else { hit.normal };
    let material = frame.materials.materials[hit.material as usize];
    let offset = spawn_offset(hit.point, hit.error);
    let origin = hit.point + normal * offset;

    let mut intensity = frame.ambient;
    if AO {
        intensity *= occlusion(g, &hit, origin, normal, frame.ao_reach, c);
    }
    if SHADOWS {
        for light in &frame.casting {
            let Some((l_unit, dist, amount)) = direct::<SPECULAR>(light, hit.point, normal, view, material.specular)
            else {
                continue;
            };
            c.shadow_rays += 1;
            let shadow = Ray::leaving(&hit, origin, l_unit, (dist - offset).min(frame.max_distance));
            if shadow.t_max > 0.0 && g.occluded(&shadow, c) {
                continue;
            }
            intensity += amount;
        }
        for (light, radius) in &frame.soft {
            let Some((l_unit, dist, amount)) = direct::<SPECULAR>(light, hit.point, normal, view, material.specular)
            else {
                continue;
            };
            let t_max = (dist - offset).min(frame.max_distance);
            if t_max <= 0.0 {
                intensity += amount;
                continue;
            }
            intensity += amount * soft_visibility(g, &hit, origin, l_unit, t_max, *radius, c);
        }
    }
    for light in &frame.plain {
        if let Some((_, _, amount)) = direct::<SPECULAR>(light, hit.point, normal, view, material.specular) {
            intensity += amount;
        }
    }
    let local = material.color * intensity;
    if !REFLECT {
        return local;
    }
    let r = material.reflective;
    if depth == 0 || r <= 0.0 {
        return local;
    }
    let reflected_dir = (normal * (2.0 * normal.dot(view)) - view).normalize();
    c.reflection_rays += 1;
    let reflected = trace::<SHADOWS, REFLECT, SPECULAR, AO>(
        g,
        frame,
        &Ray::leaving(&hit, origin, reflected_dir, frame.max_distance),
        depth - 1,
        c,
    );
    local * (1.0 - r) + reflected * r
}
