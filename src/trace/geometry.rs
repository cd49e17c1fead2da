//! The one contract both geometry back-ends meet, and the hit it reports.

use glam::Vec3A;

use super::{lanes, Counters, Packet, Ray};

/// A surface hit.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f32,
    /// Hit point in render space.
    pub point: Vec3A,
    /// Unit outward surface normal.
    pub normal: Vec3A,
    /// Index into the frame's material table.
    pub material: u32,
    /// A bound on how far `point` may lie from the true surface (the back-end's own
    /// tolerance); secondary rays start beyond it.
    pub error: f32,
    /// The object hit, in the back-end's numbering ([`NO_OBJECT`](super::NO_OBJECT) if it has none).
    pub object: u32,
    /// When the object lies wholly behind the surface's tangent plane at `point` (a
    /// convex solid, or a flat surface), that plane's unit normal (the face's for a mesh,
    /// whatever its shading normal): a ray leaving the front of that plane cannot meet
    /// the object again.
    pub behind: Option<Vec3A>,
    /// Whether the ray met the surface from the object's inside (the side its normal
    /// points away from: the geometric side for a mesh, whatever its shading normal).
    pub from_inside: bool,
}

/// What a geometry back-end provides to the tracer.
pub trait Geometry: Sync {
    /// The closest hit along the ray within `[t_min, t_max]`. A back-end may leave out
    /// the object `ray.skip`: the tracer names one only when the ray leaves a hit of it
    /// with a [`Hit::behind`] plane, outward ([`Ray::leaving`]), so the ray cannot meet it.
    fn intersect(&self, ray: &Ray, counters: &mut Counters) -> Option<Hit>;
    /// [`intersect`](Self::intersect) for each wanted lane of a packet (`None` for the
    /// others). A back-end may share work between the lanes, but each lane must hit or
    /// miss as its ray does alone, at the same distance up to rounding; only where two
    /// surfaces tie within rounding (a ray through an edge) may it return the other one.
    fn intersect4(&self, packet: &Packet, counters: &mut Counters) -> [Option<Hit>; 4] {
        intersect_each(self, packet, counters)
    }
    /// [`intersect4`](Self::intersect4) for a 4×4 block given as four 2×2 packets (a
    /// packet may want no lane), under the same contract; a back-end may share work
    /// between all sixteen rays.
    fn intersect16(&self, quads: &[Packet; 4], counters: &mut Counters) -> [[Option<Hit>; 4]; 4] {
        let mut hits = [[None; 4]; 4];
        for (hits, quad) in hits.iter_mut().zip(quads) {
            *hits = self.intersect4(quad, counters);
        }
        hits
    }
    /// Whether anything lies along the ray within `[t_min, t_max]` (for shadows).
    fn occluded(&self, ray: &Ray, counters: &mut Counters) -> bool;
    /// The unblocked fraction of a cone of half-angle `atan(cone)` around the ray (a soft
    /// shadow from a round light), if the back-end can estimate it from one query; `None`
    /// asks the tracer to sample the light with several shadow rays instead.
    fn soft_visibility(&self, _ray: &Ray, _cone: f32, _counters: &mut Counters) -> Option<f32> {
        None
    }
    /// How open the space above a surface point is, within `reach` along the normal
    /// (1 = unoccluded), if the back-end can estimate it without rays; `None` asks the
    /// tracer to cast occlusion rays instead.
    fn occlusion(&self, _point: Vec3A, _normal: Vec3A, _reach: f32, _counters: &mut Counters) -> Option<f32> {
        None
    }
    /// Bytes of the back-end's geometry structures.
    fn bytes(&self) -> usize;
}

/// Each wanted lane of a packet traced alone ([`Geometry::intersect4`]'s default).
pub fn intersect_each<G: Geometry + ?Sized>(g: &G, packet: &Packet, counters: &mut Counters) -> [Option<Hit>; 4] {
    // A loop over a filled array, not `array::from_fn`: that measured a quarter of the
    // time of a one-object SDF packet, in copies of the array being built (bench
    // `primary rays/packets sdf/01-sphere`).
    let mut hits = [None; 4];
    for l in lanes(packet.mask) {
        hits[l] = g.intersect(&packet.rays[l], counters);
    }
    hits
}
