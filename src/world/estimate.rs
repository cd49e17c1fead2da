//! Soft shadows and ambient occlusion estimated from the distance fields, where every
//! object is an SDF (with meshes they are traced as rays instead).

use glam::Vec3A;

use super::query::Query;
use super::{Object, ObjectKind, World};
use crate::accel::sphere_interval;
use crate::sdf::SdfObject;
use crate::trace::{Counters, Ray};

impl World {
    /// [`Geometry::soft_visibility`](crate::trace::Geometry::soft_visibility): the penumbra estimate, for scenes of SDF objects only.
    pub(super) fn soft_visibility(&self, ray: &Ray, cone: f32, c: &mut Counters) -> Option<f32> {
        let sdfs = self.sdf_objects()?;
        // The penumbra reaches `cone·t` beyond an object, so each object's bounding sphere
        // is widened by the cone's radius at the far end before it is skipped.
        let widen = cone * ray.t_max.min(1e6);
        let mut q = Query::new(ray);
        let mut visibility = 1.0f32;
        for (o, s) in sdfs {
            let (t0, t1) = match o.sphere {
                Some((centre, radius)) => match sphere_interval(ray.origin, ray.dir, centre, radius + widen) {
                    Some((a, b)) => (a.max(ray.t_min), b.min(ray.t_max)),
                    None => continue,
                },
                None => (ray.t_min, ray.t_max),
            };
            if t0 > t1 {
                continue;
            }
            visibility = visibility.min(s.penumbra(ray, (t0, t1), cone, self.params, c, &mut q.evals));
            if visibility <= 0.0 {
                break;
            }
        }
        q.settle(c);
        Some(visibility)
    }

    /// [`Geometry::occlusion`](crate::trace::Geometry::occlusion): the five-tap estimate, for scenes of SDF objects only.
    pub(super) fn occlusion(&self, point: Vec3A, normal: Vec3A, reach: f32, c: &mut Counters) -> Option<f32> {
        let sdfs = self.sdf_objects()?;
        // Five taps along the normal (Quilez): where the field is below the distance
        // travelled, something is near; nearer taps weigh more.
        let mut shortfall = 0.0f32;
        let mut weight = 1.0f32;
        let mut evals = 0u64;
        for i in 1..=5 {
            let h = reach * i as f32 / 5.0;
            let p = point + normal * h;
            let d = sdfs
                .clone()
                .filter(|(o, _)| o.sphere.is_none_or(|(centre, r)| (p - centre).length() - r < reach))
                .map(|(_, s)| {
                    evals += 1;
                    s.eval(p)
                })
                .fold(f32::INFINITY, f32::min);
            shortfall += weight * (h - d.min(h)).max(0.0) / reach;
            weight *= 0.5;
        }
        c.sdf_shading_evals += evals;
        Some((1.0 - shortfall * 1.5).clamp(0.0, 1.0))
    }

    /// Every object with its SDF, when every object is an SDF object; `None` when some
    /// are meshes, which the estimates cannot see (they are traced as rays instead).
    fn sdf_objects(&self) -> Option<impl Iterator<Item = (&Object, &SdfObject)> + Clone> {
        if self.has_meshes {
            return None;
        }
        Some(self.objects.iter().filter_map(|o| match &o.kind {
            ObjectKind::Sdf(s) => Some((o, s)),
            ObjectKind::Mesh(_) => None,
        }))
    }
}
