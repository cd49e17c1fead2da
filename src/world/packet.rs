//! Camera rays in packets: one walk of the top-level tree, and of each mesh's tree,
//! shared by four or sixteen rays.

use glam::Vec4;

use super::query::{Found, Query};
use super::{Object, ObjectKind, World};
use crate::accel::bvh::splat3;
use crate::accel::Rays4;
use crate::mesh::triangle::PacketShear;
use crate::sdf::SdfObject;
use crate::trace::{intersect_each, lanes, Counters, Hit, Packet, NO_OBJECT};

impl World {
    /// [`Geometry::intersect4`](crate::trace::Geometry::intersect4) for `N` packets of four traced together: one walk of the
    /// top-level tree and of each mesh's tree for all of their rays.
    #[inline]
    pub(super) fn intersect_packet<const N: usize>(
        &self,
        quads: &[Packet; N],
        c: &mut Counters,
    ) -> [[Option<Hit>; 4]; N] {
        // The shared walk knows no skips; packets of camera rays never have one.
        if !self.share_walks || quads.iter().any(|q| q.rays.iter().any(|r| r.skip != NO_OBJECT)) {
            return self.each_quad(quads, c);
        }
        let mut mask = 0;
        let mut rays4 = [Rays4 { origin: [Vec4::ZERO; 3], inv_dir: [Vec4::ZERO; 3], t_min: Vec4::ZERO }; N];
        let mut dirs = [[Vec4::ZERO; 3]; N];
        let mut t_max = [Vec4::ZERO; N];
        for (g, quad) in quads.iter().enumerate() {
            rays4[g] = Rays4 {
                origin: quad.across(|r| r.origin),
                inv_dir: quad.across(|r| r.inv_dir),
                t_min: quad.each(|r| r.t_min),
            };
            dirs[g] = quad.across(|r| r.dir);
            t_max[g] = quad.each(|r| r.t_max);
            mask |= (quad.mask & 0b1111) << (4 * g);
        }
        // Only the 4-wide triangle test needs the rays to share their origin and shear
        // axes; without (directions too far apart) meshes are tested lane by lane like
        // SDF objects.
        let origin = quads[0].rays[0].origin;
        let shared = || quads.iter().all(|q| q.rays.iter().all(|r| r.origin == origin));
        let shear = (self.has_meshes && shared()).then(|| PacketShear::new(origin, &dirs)).flatten();
        let mut best: [[Option<Found>; 4]; N] = [[None; 4]; N];
        // SDF evaluations per lane; a lane's query is made only for an object tested lane by lane.
        let mut evals = [[0u64; 4]; N];
        let mut visits = 0u64;
        self.bvh.each_packet(&rays4, mask, &mut t_max, &mut visits, |k, lanes, t_max| {
            let i = self.bounded[k as usize];
            let o = &self.objects[i as usize];
            if let (ObjectKind::Mesh(m), Some(shear)) = (&o.kind, &shear) {
                let mut reach = 0;
                for g in 0..N {
                    reach |= sphere_lanes(o, &rays4[g], &dirs[g], t_max[g]) << (4 * g);
                }
                let reach = lanes & reach;
                if reach == 0 {
                    return;
                }
                m.closest_packet(&rays4, shear, reach, t_max, c, |g, l, tri, hit| {
                    best[g][l] = Some(Found::Mesh { object: i, mesh: m, tri, hit });
                });
                return;
            }
            match &o.kind {
                ObjectKind::Sdf(s) if s.walks_packets() => {
                    self.find_packed(i, s, quads, lanes, t_max, &mut best, &mut evals, c);
                }
                _ => self.find_each(i, quads, lanes, t_max, &mut best, &mut evals, c),
            }
        });
        c.node_visits += visits;
        // A loop, not `array::from_fn` (see `intersect_each`).
        let mut hits = [[None; 4]; N];
        for lane in lanes(mask) {
            let (g, l) = (lane / 4, lane % 4);
            let ray = &quads[g].rays[l];
            hits[g][l] = if self.unbounded.is_empty() && evals[g][l] == 0 {
                // No object left to try and no work to settle: only the winner's surface.
                best[g][l].map(|found| found.surface(ray, c))
            } else {
                self.finish(&mut Query::resumed(ray, evals[g][l]), best[g][l], c)
            };
        }
        hits
    }

    /// Each packet's rays traced alone: out of line, like [`World::find_each`].
    #[inline(never)]
    pub(super) fn each_quad<const N: usize>(&self, quads: &[Packet; N], c: &mut Counters) -> [[Option<Hit>; 4]; N] {
        let mut hits = [[None; 4]; N];
        for (hits, quad) in hits.iter_mut().zip(quads) {
            *hits = intersect_each(self, quad, c);
        }
        hits
    }

    /// Object `i` tested for each lane of `lanes` alone, as the packet walk does for SDF
    /// objects: out of line, so the walk's loop stays small enough for the instruction
    /// cache (inlined, the march loop made it four times larger).
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn find_each<'w, const N: usize>(
        &'w self,
        i: u32,
        quads: &[Packet; N],
        lanes: u32,
        t_max: &mut [Vec4; N],
        best: &mut [[Option<Found<'w>>; 4]; N],
        evals: &mut [[u64; 4]; N],
        c: &mut Counters,
    ) {
        for lane in crate::trace::lanes(lanes) {
            let (g, l) = (lane / 4, lane % 4);
            let mut q = Query::resumed(&quads[g].rays[l], evals[g][l]);
            if let Some(found) = self.find(i, &mut q, t_max[g][l], c) {
                t_max[g][l] = found.t();
                best[g][l] = Some(found);
            }
            evals[g][l] = q.evals;
        }
    }

    /// SDF object `i` (whose parts packets walk together) tested for the lanes of
    /// `lanes`: each lane's interval as [`World::find`] takes it, then one walk of the
    /// parts for all of them. Out of line for the reason [`World::find_each`] is.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn find_packed<'w, const N: usize>(
        &'w self,
        i: u32,
        sdf: &'w SdfObject,
        quads: &[Packet; N],
        lanes: u32,
        t_max: &mut [Vec4; N],
        best: &mut [[Option<Found<'w>>; 4]; N],
        evals: &mut [[u64; 4]; N],
        c: &mut Counters,
    ) {
        // A ray that skips the object is left to `find`, which knows why; so is one that
        // may start inside it (marched out of it over the whole tree, alone).
        let mut spans = [[(0.0, 0.0); 4]; N];
        let mut reach = 0;
        for lane in crate::trace::lanes(lanes) {
            let (g, l) = (lane / 4, lane % 4);
            let ray = &quads[g].rays[l];
            if ray.skip == i || ray.inside == i {
                return self.find_each(i, quads, lanes, t_max, best, evals, c);
            }
            if let Some(span) = self.interval(i, ray, t_max[g][l]) {
                if span.0 <= ray.t_min {
                    return self.find_each(i, quads, lanes, t_max, best, evals, c);
                }
                spans[g][l] = span;
                reach |= 1 << lane;
            }
        }
        if reach == 0 {
            return;
        }
        let found = sdf.closest_packet(quads, reach, &spans, self.params, c, evals);
        for lane in crate::trace::lanes(reach) {
            let (g, l) = (lane / 4, lane % 4);
            if let Some((t, error)) = found[g][l] {
                t_max[g][l] = t;
                best[g][l] = Some(Found::Sdf { object: i, sdf, t, error, leaving: false });
            }
        }
    }
}

/// The lanes of a packet that may reach object `o` before their `t_max`: its bounding
/// sphere tested for four rays at once, lane by lane the arithmetic of
/// [`sphere_interval`](crate::accel::sphere_interval) and [`clip_to_sphere`](super::query::clip_to_sphere) (a mesh object's box is its BVH's root,
/// which the walk tests anyway).
#[inline]
fn sphere_lanes(o: &Object, rays: &Rays4, dir: &[Vec4; 3], t_max: Vec4) -> u32 {
    let Some((centre, radius)) = o.sphere else { return 0b1111 };
    let centre = splat3(centre);
    let oc = [rays.origin[0] - centre[0], rays.origin[1] - centre[1], rays.origin[2] - centre[2]];
    let b = oc[0] * dir[0] + oc[1] * dir[1] + oc[2] * dir[2];
    let perp = [oc[0] - dir[0] * b, oc[1] - dir[1] * b, oc[2] - dir[2] * b];
    let disc = Vec4::splat(radius * radius) - (perp[0] * perp[0] + perp[1] * perp[1] + perp[2] * perp[2]);
    let s = disc.sqrt();
    let (t0, t1) = (rays.t_min.max(-b - s), t_max.min(-b + s));
    (disc.cmpge(Vec4::ZERO) & t0.cmple(t1)).bitmask()
}
