//! Light through transparent objects: the media a ray is inside, Snell's law, the
//! Fresnel equations, Beer–Lambert absorption, and shadow rays that pass through glass.
//!
//! The approximations, stated once: shadow rays go straight through transparent
//! surfaces, scaled by each one's `transparency` and by absorption inside (no bending
//! and no Fresnel loss, so no caustics); a ray that runs out of depth brings back black,
//! as POV-Ray's does at `max_trace_level`; the camera is taken to be in air.

use glam::Vec3A;

use super::{spawn_offset, Counters, Frame, Geometry, Hit, Ray, NO_OBJECT};

/// How many transparent objects one ray can be inside at once; deeper nesting is
/// traced as if the innermost ones were not entered.
const MAX_NESTING: usize = 8;

/// The transparent objects a ray is inside, innermost last, with their materials.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Media {
    objects: [(u32, u32); MAX_NESTING],
    len: usize,
}

impl Media {
    /// Air: inside nothing.
    pub(super) const AIR: Media = Media { objects: [(NO_OBJECT, 0); MAX_NESTING], len: 0 };

    /// The innermost object and its material, if any.
    fn innermost(&self) -> Option<(u32, u32)> {
        self.len.checked_sub(1).map(|i| self.objects[i])
    }

    /// The object a ray travelling in these media starts inside ([`Ray::inside`]).
    pub(super) fn object(&self) -> u32 {
        self.innermost().map_or(NO_OBJECT, |(o, _)| o)
    }

    /// Index of refraction of the innermost medium (1 for air).
    fn ior(&self, frame: &Frame) -> f32 {
        self.innermost().map_or(1.0, |(_, m)| frame.materials.materials[m as usize].ior)
    }

    /// Light left after travelling `distance` through the innermost medium.
    pub(super) fn absorb(&self, frame: &Frame, distance: f32) -> Option<Vec3A> {
        let (_, m) = self.innermost()?;
        let sigma = frame.materials.materials[m as usize].absorption;
        (sigma != Vec3A::ZERO).then(|| (-sigma * distance).exp())
    }

    /// The media after crossing `hit`'s surface: into its object, or out of it.
    pub(super) fn crossing(mut self, hit: &Hit) -> Media {
        if hit.from_inside {
            // Leave the object (its latest entry; a ray that never entered it, as one
            // starting inside, leaves the media as they are).
            if let Some(i) = self.objects[..self.len].iter().rposition(|&(o, _)| o == hit.object) {
                self.objects.copy_within(i + 1..self.len, i);
                self.len -= 1;
            }
        } else if self.len < MAX_NESTING {
            self.objects[self.len] = (hit.object, hit.material);
            self.len += 1;
        }
        self
    }
}

/// What happens at a transparent surface: the reflected share and, unless the light is
/// totally reflected, the refracted direction.
pub(super) struct Split {
    /// Fresnel reflectance in [0, 1] (1 under total internal reflection).
    pub(super) reflectance: f32,
    /// The refracted unit direction.
    pub(super) refracted: Option<Vec3A>,
}

/// Snell's law and the exact Fresnel equations for unpolarised light at a surface with
/// unit normal `n` facing the incoming ray (`view` = −direction, unit), from a medium of
/// index `n1` into one of index `n2`. Equal indices reflect nothing and bend nothing.
pub(super) fn split(view: Vec3A, n: Vec3A, n1: f32, n2: f32) -> Split {
    // A shading normal can tilt a grazing ray just past the horizon; treat it as grazing.
    let cos_i = n.dot(view).clamp(0.0, 1.0);
    let eta = n1 / n2;
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return Split { reflectance: 1.0, refracted: None };
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let rp = (n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i);
    // At exact grazing (cos_i = cos_t = 0 with n1 = n2) both quotients are 0/0.
    let reflectance = if (rs * rs + rp * rp).is_finite() { 0.5 * (rs * rs + rp * rp) } else { 1.0 };
    let refracted = (-view * eta + n * (eta * cos_i - cos_t)).normalize_or_zero();
    Split { reflectance: reflectance.clamp(0.0, 1.0), refracted: (refracted != Vec3A::ZERO).then_some(refracted) }
}

/// The indices of refraction on either side of `hit`'s surface for a ray in `media`:
/// the medium it comes from and the one it would pass into.
pub(super) fn indices(frame: &Frame, hit: &Hit, media: &Media) -> (f32, f32) {
    let own = frame.materials.materials[hit.material as usize].ior;
    if hit.from_inside {
        (own, media.crossing(hit).ior(frame))
    } else {
        (media.ior(frame), own)
    }
}

/// Most transparent surfaces one shadow ray passes through before it counts as blocked.
const MAX_CROSSINGS: u32 = 16;

/// The light that reaches the end of a shadow ray through transparent objects, per
/// channel (0 when something opaque is in the way). The ray is first asked whether
/// anything is in the way at all, so only shadow rays that meet something pay for
/// closest-hit queries.
pub(super) fn light_through(g: &dyn Geometry, frame: &Frame, ray: &Ray, media: Media, c: &mut Counters) -> Vec3A {
    if !g.occluded(ray, c) {
        return media.absorb(frame, ray.t_max - ray.t_min).unwrap_or(Vec3A::ONE);
    }
    let (mut ray, mut media, mut through) = (*ray, media, Vec3A::ONE);
    for _ in 0..MAX_CROSSINGS {
        let Some(hit) = g.intersect(&ray, c) else {
            return through * media.absorb(frame, ray.t_max).unwrap_or(Vec3A::ONE);
        };
        let m = &frame.materials.materials[hit.material as usize];
        if m.transparency <= 0.0 {
            return Vec3A::ZERO;
        }
        through *= m.transparency * media.absorb(frame, hit.t).unwrap_or(Vec3A::ONE);
        media = media.crossing(&hit);
        // On along the same line, from just past the surface.
        let offset = spawn_offset(hit.point, hit.error);
        let rest = ray.t_max - hit.t - offset;
        if rest <= 0.0 {
            return through;
        }
        let mut next = Ray::new(hit.point + ray.dir * offset, ray.dir, rest);
        next.inside = media.object();
        ray = next;
        c.shadow_rays += 1;
    }
    Vec3A::ZERO
}
