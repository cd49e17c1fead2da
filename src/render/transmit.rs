//! Light through transparent objects: the media a ray is inside, Snell's law, the
//! Fresnel equations, Beer–Lambert absorption, and shadow rays that pass through glass.
//!
//! The approximations, stated once: shadow rays go straight through transparent
//! surfaces, scaled by each one's `transparency` and by absorption inside (no bending
//! and no Fresnel loss, so no caustics); a ray that runs out of depth brings back black,
//! as POV-Ray's does at `max_trace_level`; the camera is taken to be in air.

use glam::Vec3A;

use super::Frame;
use crate::trace::{spawn_offset, Counters, Geometry, Hit, Ray, NO_OBJECT};

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

/// The indices of refraction on either side of `hit`'s surface for a ray in `media`
/// that would be in `beyond` past it: the medium it comes from and the one it would
/// pass into.
pub(super) fn indices(frame: &Frame, hit: &Hit, media: &Media, beyond: &Media) -> (f32, f32) {
    let own = frame.materials.materials[hit.material as usize].ior;
    if hit.from_inside {
        (own, beyond.ior(frame))
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
        // On in the same direction from just past the surface: off it along the normal,
        // which a grazing ray would not get far enough from by moving along itself.
        let offset = spawn_offset(hit.point, hit.error);
        let rest = ray.t_max - hit.t - offset;
        if rest <= 0.0 {
            return through;
        }
        let beyond = if hit.from_inside { hit.normal } else { -hit.normal };
        let mut next = Ray::new(hit.point + beyond * offset, ray.dir, rest);
        next.inside = media.object();
        ray = next;
        c.shadow_rays += 1;
    }
    Vec3A::ZERO
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit view vector at `degrees` from the normal +z, in the xz plane.
    fn view_at(degrees: f32) -> Vec3A {
        let a = degrees.to_radians();
        Vec3A::new(a.sin(), 0.0, a.cos())
    }

    #[test]
    fn snell_bends_by_the_ratio_of_sines() {
        for angle in [0.0f32, 10.0, 30.0, 45.0, 60.0, 80.0, 89.0] {
            let s = split(view_at(angle), Vec3A::Z, 1.0, 1.5);
            let t = s.refracted.expect("air to glass always refracts");
            assert!((t.length() - 1.0).abs() < 1e-6);
            assert!(t.z < 0.0, "the refracted ray goes through the surface");
            // sin θt = sin θi / 1.5, and the ray stays in the plane of incidence, on the far side.
            let sin_t = t.x.abs();
            assert!((sin_t - angle.to_radians().sin() / 1.5).abs() < 1e-5, "{angle}°: sin θt = {sin_t}");
            assert!(t.y.abs() < 1e-6 && t.x <= 0.0);
        }
    }

    #[test]
    fn fresnel_has_its_known_values() {
        // Normal incidence: ((n1 − n2) / (n1 + n2))², 0.04 for glass from air.
        assert!((split(view_at(0.0), Vec3A::Z, 1.0, 1.5).reflectance - 0.04).abs() < 1e-6);
        assert!((split(view_at(0.0), Vec3A::Z, 1.5, 1.0).reflectance - 0.04).abs() < 1e-6);
        // Brewster's angle, atan(1.5): the p-polarised half vanishes, so F = Rs / 2.
        let brewster = 1.5f32.atan().to_degrees();
        let rs = {
            let (ci, ct) = (brewster.to_radians().cos(), (90.0 - brewster).to_radians().cos());
            ((ci - 1.5 * ct) / (ci + 1.5 * ct)).powi(2)
        };
        assert!((split(view_at(brewster), Vec3A::Z, 1.0, 1.5).reflectance - rs / 2.0).abs() < 1e-5);
        // Grazing light is all reflected.
        assert!(split(view_at(90.0), Vec3A::Z, 1.0, 1.5).reflectance > 0.999);
        // Reflectance grows with the angle from air into glass.
        let mut last = 0.0;
        for angle in (0..90).step_by(5) {
            let f = split(view_at(angle as f32), Vec3A::Z, 1.0, 1.5).reflectance;
            assert!(f >= last - 1e-6 && (0.0..=1.0).contains(&f));
            last = f;
        }
    }

    #[test]
    fn total_internal_reflection_starts_at_the_critical_angle() {
        let critical = (1.0f32 / 1.5).asin().to_degrees();
        let below = split(view_at(critical - 0.05), Vec3A::Z, 1.5, 1.0);
        assert!(below.refracted.is_some() && below.reflectance < 1.0);
        // Just below it the refracted ray already grazes the surface.
        assert!(below.refracted.is_some_and(|t| t.z.abs() < 0.05));
        let above = split(view_at(critical + 0.05), Vec3A::Z, 1.5, 1.0);
        assert!(above.refracted.is_none());
        assert_eq!(above.reflectance, 1.0);
    }

    fn crossing(object: u32, material: u32, from_inside: bool) -> Hit {
        Hit { t: 1.0, point: Vec3A::ZERO, normal: Vec3A::Z, material, error: 0.0, object, behind: None, from_inside }
    }

    #[test]
    fn media_nest_and_unnest_by_object() {
        // Into water (object 1), into an air bubble in it (object 2), out of the bubble.
        let water = Media::AIR.crossing(&crossing(1, 5, false));
        let bubble = water.crossing(&crossing(2, 6, false));
        assert_eq!((water.object(), bubble.object()), (1, 2));
        assert_eq!(bubble.crossing(&crossing(2, 6, true)).object(), 1);
        // Leaving the water while still in the bubble (objects that overlap) keeps the bubble.
        assert_eq!(bubble.crossing(&crossing(1, 5, true)).object(), 2);
        // Leaving what the ray never entered (a camera inside glass) changes nothing.
        assert_eq!(Media::AIR.crossing(&crossing(3, 7, true)).object(), NO_OBJECT);
        // Past the deepest nesting, entering is ignored and leaving still finds its entry.
        let deep = (0..MAX_NESTING as u32 + 2).fold(Media::AIR, |m, o| m.crossing(&crossing(o, 0, false)));
        assert_eq!(deep.object(), MAX_NESTING as u32 - 1);
    }

    #[test]
    fn equal_indices_reflect_nothing_and_bend_nothing() {
        for angle in [0.0f32, 20.0, 45.0, 70.0, 89.5] {
            let v = view_at(angle);
            let s = split(v, Vec3A::Z, 1.33, 1.33);
            assert!(s.reflectance < 1e-6, "{angle}°: {}", s.reflectance);
            let t = s.refracted.expect("no interface, no reflection");
            assert!((t + v).length() < 1e-5, "{angle}°: {t} is not straight on");
        }
    }
}
