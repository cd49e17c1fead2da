//! Single-ray queries: the closest hit and any hit, through the top-level tree and
//! then the unbounded objects.

use glam::Vec3A;

use super::{Object, ObjectKind, World};
use crate::accel::sphere_interval;
use crate::geom::hull::{Hull, Round};
use crate::mesh::{self, MeshObject};
use crate::sdf::SdfObject;
use crate::trace::{Counters, Geometry, Hit, Packet, Ray};

impl World {
    /// The interval of the ray inside object `i`'s bounds, clipped to `[ray.t_min, t_max]`.
    #[inline]
    pub(super) fn interval(&self, i: u32, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        self.reach(i, ray, t_max).map(|(span, _)| span)
    }

    /// [`interval`](Self::interval), and whether the ray, from outside, enters a hull
    /// that is the solid itself at the interval's start: a hit there, with no step.
    #[inline]
    fn reach(&self, i: u32, ray: &Ray, t_max: f32) -> Option<((f32, f32), bool)> {
        let o = &self.objects[i as usize];
        let (t0, t1) = match o.bounds {
            Some(b) => b.slab(ray.origin, ray.inv_dir, ray.t_min, t_max)?,
            None => (ray.t_min, t_max),
        };
        let (t0, t1) = clip_to_sphere(o, ray, (t0, t1))?;
        // A ray marching out of the solid needs its whole interval.
        if ray.inside == i {
            return Some(((t0, t1), false));
        }
        match (o.half_space, &o.hull) {
            (Some(h), _) => clip_to_half_space(h, ray, (t0, t1)).map(|span| (span, false)),
            (None, Some(hull)) => hull.clip(self.params.epsilon, ray, (t0, t1)),
            (None, None) => Some(((t0, t1), false)),
        }
    }

    /// A hit where the ray enters the solid's hull, which is the solid ([`World::reach`]).
    #[inline]
    fn entered<'w>(&self, i: u32, sdf: &'w SdfObject, ray: &Ray, t: f32) -> Found<'w> {
        let error = crate::sdf::march::threshold(self.params.epsilon, ray.origin.length(), t);
        Found::Sdf { object: i, sdf, t, error, leaving: false }
    }

    /// Whether the ray can reach mesh object `o` before `t_max`. Only its sphere is
    /// tested: its box is the root of the mesh's own BVH, whose walk tests it anyway.
    #[inline]
    fn may_reach_mesh(&self, o: &Object, ray: &Ray, t_max: f32) -> bool {
        clip_to_sphere(o, ray, (ray.t_min, t_max)).is_some()
    }

    /// Whether a ray starts inside SDF object `i` over `interval`, and so must be marched
    /// out of it: it was refracted into it (`ray.inside`), or where it starts the solid's
    /// field is negative — a ray in a bubble inside this water, or a camera inside a
    /// solid. A march from outside would take its start for a hit.
    #[inline]
    fn leaving(&self, i: u32, sdf: &SdfObject, ray: &Ray, (t0, _): (f32, f32), evals: &mut u64) -> bool {
        if i == ray.inside {
            return true;
        }
        if t0 > ray.t_min {
            return false;
        }
        *evals += 1;
        sdf.eval(ray.at(ray.t_min)) < 0.0
    }

    /// The closest surface of object `i` before `t_max`, without its shading data.
    pub(super) fn find(&self, i: u32, q: &mut Query<'_>, t_max: f32, c: &mut Counters) -> Option<Found<'_>> {
        if i == q.ray.skip {
            return None;
        }
        let o = &self.objects[i as usize];
        match &o.kind {
            ObjectKind::Sdf(s) => {
                let (interval, entered) = self.reach(i, q.ray, t_max)?;
                if entered {
                    return Some(self.entered(i, s, q.ray, interval.0));
                }
                let leaving = self.leaving(i, s, q.ray, interval, &mut q.evals);
                s.closest(q.ray, interval, leaving, self.params, c, &mut q.evals).map(|(t, error)| Found::Sdf {
                    object: i,
                    sdf: s,
                    t,
                    error,
                    leaving,
                })
            }
            // Triangles are tested exactly; the sphere only decides whether to look.
            ObjectKind::Mesh(m) if self.may_reach_mesh(o, q.ray, t_max) => {
                m.closest(q.ray, q.shear(), t_max, c).map(|(tri, hit)| Found::Mesh { object: i, mesh: m, tri, hit })
            }
            ObjectKind::Mesh(_) => None,
        }
    }

    /// Completes a ray's closest-hit query: the unbounded objects (outside the top-level
    /// tree) are tried up to the tree's closest hit, then the counters are settled and the
    /// winner's surface is computed.
    #[inline(always)]
    pub(super) fn finish<'w>(
        &'w self,
        q: &mut Query<'_>,
        mut best: Option<Found<'w>>,
        c: &mut Counters,
    ) -> Option<Hit> {
        for &i in &self.unbounded {
            let limit = best.map_or(q.ray.t_max, |f| f.t());
            if let Some(found) = self.find(i, q, limit, c) {
                best = Some(found);
            }
        }
        q.settle(c);
        Some(best?.surface(q.ray, c))
    }

    fn blocks(&self, i: u32, q: &mut Query<'_>, t_max: f32, c: &mut Counters) -> bool {
        if i == q.ray.skip {
            return false;
        }
        let o = &self.objects[i as usize];
        match &o.kind {
            ObjectKind::Sdf(s) => self.reach(i, q.ray, t_max).is_some_and(|(interval, entered)| {
                if entered {
                    return true;
                }
                let leaving = self.leaving(i, s, q.ray, interval, &mut q.evals);
                s.closest(q.ray, interval, leaving, self.params, c, &mut q.evals).is_some()
            }),
            ObjectKind::Mesh(m) => self.may_reach_mesh(o, q.ray, t_max) && m.occluded(q.ray, q.shear(), t_max, c),
        }
    }
}

/// A surface found along a ray, before its shading data is computed: the object it is
/// on (numbered, and lowered by its back-end) and where.
#[derive(Clone, Copy)]
pub(super) enum Found<'w> {
    /// An SDF hit: distance and the threshold there, and whether the ray was marched
    /// out of the object (it started inside).
    Sdf { object: u32, sdf: &'w SdfObject, t: f32, error: f32, leaving: bool },
    /// A triangle hit.
    Mesh { object: u32, mesh: &'w MeshObject, tri: mesh::TriRef, hit: mesh::triangle::TriHit },
}

impl Found<'_> {
    /// Distance along the ray.
    pub(super) fn t(&self) -> f32 {
        match self {
            Found::Sdf { t, .. } => *t,
            Found::Mesh { hit, .. } => hit.t,
        }
    }

    /// Normal, material and error of the winning surface, computed once per ray.
    pub(super) fn surface(self, ray: &Ray, c: &mut Counters) -> Hit {
        match self {
            Found::Sdf { object, sdf, t, error, leaving } => sdf.surface(ray, t, error, object, leaving, c),
            Found::Mesh { object, mesh, tri, hit } => mesh.surface(tri, hit, object, ray.dir),
        }
    }
}

/// Per-ray state shared by the objects one query visits.
pub(super) struct Query<'a> {
    pub(super) ray: &'a Ray,
    /// The triangle test's shear, computed the first time a mesh is visited.
    shear: Option<mesh::triangle::Shear>,
    /// SDF evaluations so far.
    pub(super) evals: u64,
    /// Top-level BVH nodes visited.
    visits: u64,
}

impl<'a> Query<'a> {
    pub(super) fn new(ray: &'a Ray) -> Query<'a> {
        Query::resumed(ray, 0)
    }

    /// A query for `ray` that has already spent `evals` SDF evaluations (a packet lane).
    pub(super) fn resumed(ray: &'a Ray, evals: u64) -> Query<'a> {
        Query { ray, shear: None, evals, visits: 0 }
    }

    /// Adds this query's work to the counters.
    pub(super) fn settle(&self, c: &mut Counters) {
        c.node_visits += self.visits;
        c.sdf_evals += self.evals;
        c.max_evals_per_ray = c.max_evals_per_ray.max(self.evals);
    }

    fn shear(&mut self) -> &mesh::triangle::Shear {
        let dir = self.ray.dir;
        self.shear.get_or_insert_with(|| mesh::triangle::Shear::new(dir))
    }
}

/// `(t0, t1)` narrowed to where the ray is inside the object's bounding sphere, if it has one.
#[inline]
pub(super) fn clip_to_sphere(o: &Object, ray: &Ray, (t0, t1): (f32, f32)) -> Option<(f32, f32)> {
    let (t0, t1) = match o.sphere {
        Some((centre, radius)) => {
            let (s0, s1) = sphere_interval(ray.origin, ray.dir, centre, radius)?;
            (t0.max(s0), t1.min(s1))
        }
        None => (t0, t1),
    };
    (t0 <= t1).then_some((t0, t1))
}

/// `(t0, t1)` from where the ray enters the half-space `n·p ≤ offset`, or `None` if it
/// stays outside; a ray starting inside keeps its interval. The entry is moved back by
/// a millionth of its distance, more than the f32 rounding of `t` (a few 1e-7 of it), so
/// a surface on the plane is never passed; a march starting there is within the hit
/// threshold (`epsilon ≥ 1e-6` of the distance) at once. Without it, a ray grazing a
/// floor steps geometrically towards it, by the floor's height times `1 − sin θ` each
/// step, and runs out of steps before the horizon (`stability::grazing_rays_match_analytic_coverage`).
#[inline]
fn clip_to_half_space((n, offset): (Vec3A, f32), ray: &Ray, (t0, t1): (f32, f32)) -> Option<(f32, f32)> {
    let above = n.dot(ray.origin) - offset;
    if above <= 0.0 {
        return Some((t0, t1));
    }
    let closing = -n.dot(ray.dir);
    if closing <= 0.0 {
        return None;
    }
    let enter = above / closing;
    let t0 = t0.max(enter - enter * 1e-6);
    (t0 <= t1).then_some((t0, t1))
}

/// A convex set holding an SDF object, in render space: what its rays are clipped to
/// before they are marched.
pub(super) struct Entry {
    /// Planes `n·p ≤ offset`.
    planes: Box<[(Vec3A, f32)]>,
    /// Cones or an ellipsoid about an axis, in f64: a quadratic's roots lose too much in
    /// f32 where a ray grazes.
    round: Option<Round>,
    /// Whether the set is the solid itself ([`crate::ir::Shape::hull_is_solid`]).
    solid: bool,
}

impl Entry {
    /// The render-space hull of an object; `solid` when it is the solid itself.
    pub(super) fn new(hull: Hull, solid: bool) -> Entry {
        let planes = hull.planes.iter().map(|(n, o)| (n.as_vec3a(), *o as f32)).collect();
        Entry { planes, round: hull.round, solid }
    }

    /// `(t0, t1)` from where the ray enters the set, or `None` if it never comes within
    /// the hit threshold of it; the ends are moved out by a millionth of their distance
    /// as for a half-space ([`clip_to_half_space`]). The set holds the solid and is
    /// grown by the threshold (`sdf::march::threshold` with relative `epsilon`), so no
    /// hit the march would take is clipped away. The march ends where the ray leaves
    /// the grown set, not at `t1`: a grazing ray creeps along a surface, and a shadow
    /// ray leaving one steps out slowly. With it, whether the ray enters the set itself
    /// from outside and the set is the solid: then its start is a hit (and the interval
    /// may end where the ray leaves the solid).
    #[inline]
    fn clip(&self, epsilon: f32, ray: &Ray, (t0, t1): (f32, f32)) -> Option<((f32, f32), bool)> {
        // The threshold, ε·(t + min(t, |origin|)), is at most `reach·t`.
        let reach = 2.0 * epsilon;
        // [enter, leave] on the set itself, and on it grown by the threshold.
        let (mut solid, mut grown) = ((t0, t1), (t0, t1));
        for &(n, offset) in self.planes.iter() {
            let above = n.dot(ray.origin) - offset;
            let closing = -n.dot(ray.dir);
            for ((enter, leave), closing) in [(&mut solid, closing), (&mut grown, closing + reach)] {
                // Inside the plane (grown by reach·t) at t: above ≤ t·closing.
                if closing == 0.0 {
                    if above > 0.0 {
                        *leave = f32::NEG_INFINITY;
                    }
                    continue;
                }
                let t = above / closing;
                if closing > 0.0 {
                    *enter = enter.max(t - t.abs() * 1e-6);
                } else {
                    *leave = leave.min(t + t.abs() * 1e-6);
                }
            }
        }
        if let Some(round) = &self.round {
            // Where the planes leave no room for the grown set, the round part cannot.
            if grown.0 > grown.1 {
                return None;
            }
            let local = round.local(ray.origin.as_dvec3(), ray.dir.as_dvec3());
            let cut = |(enter, leave): &mut (f32, f32), (lo, hi): (f64, f64)| {
                if lo > hi {
                    // Empty (its ends may be infinite, which the slack below would make NaN).
                    *leave = f32::NEG_INFINITY;
                    return;
                }
                *enter = enter.max((lo - lo.abs() * 1e-6) as f32);
                *leave = leave.min((hi + hi.abs() * 1e-6) as f32);
            };
            let solid_first = self.solid && solid.0 <= solid.1;
            if solid_first {
                // A ray from outside entering a set that is the solid hits there: the
                // grown set (where a march would end) is not asked for.
                cut(&mut solid, round.interval_local(local, 0.0));
                if solid.0 <= solid.1 && solid.0 > t0 {
                    return Some((solid, true));
                }
            }
            // The threshold is at most `far` before `t1`.
            let far = crate::sdf::march::threshold(epsilon, ray.origin.length(), t1);
            cut(&mut grown, round.interval_local(local, f64::from(far)));
            if grown.0 > grown.1 {
                return None;
            }
            if !solid_first {
                cut(&mut solid, round.interval_local(local, 0.0));
            }
        }
        // A hit lies within the grown set, so the march ends where the ray leaves it: a
        // ray leaving a surface (a shadow ray) stops at the hull, not the sphere (both
        // ends start at `t1` and only come nearer).
        match (solid, grown) {
            ((enter, leave), (_, out)) if enter <= leave => Some(((enter, out), self.solid && enter > t0)),
            (_, (enter, leave)) if enter <= leave => Some(((enter, leave), false)),
            _ => None,
        }
    }
}

impl Geometry for World {
    fn intersect(&self, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        let mut q = Query::new(ray);
        let mut visits = 0u64;
        let mut best: Option<Found> = None;
        self.bvh.closest(ray.origin, ray.inv_dir, ray.t_min, ray.t_max, &mut visits, |k, t_max| {
            let found = self.find(self.bounded[k as usize], &mut q, t_max, c)?;
            best = Some(found);
            Some(found.t())
        });
        q.visits = visits;
        self.finish(&mut q, best, c)
    }

    fn intersect4(&self, packet: &Packet, c: &mut Counters) -> [Option<Hit>; 4] {
        let [hits] = self.intersect_packet(std::array::from_ref(packet), c);
        hits
    }

    fn intersect16(&self, quads: &[Packet; 4], c: &mut Counters) -> [[Option<Hit>; 4]; 4] {
        self.intersect_packet(quads, c)
    }

    fn occluded(&self, ray: &Ray, c: &mut Counters) -> bool {
        let mut q = Query::new(ray);
        let mut visits = 0u64;
        let hit = self.bvh.any(ray.origin, ray.inv_dir, ray.t_min, ray.t_max, &mut visits, |k, t_max| {
            self.blocks(self.bounded[k as usize], &mut q, t_max, c)
        }) || self.unbounded.iter().any(|&i| self.blocks(i, &mut q, ray.t_max, c));
        q.visits = visits;
        q.settle(c);
        hit
    }

    fn soft_visibility(&self, ray: &Ray, cone: f32, c: &mut Counters) -> Option<f32> {
        World::soft_visibility(self, ray, cone, c)
    }

    fn occlusion(&self, point: Vec3A, normal: Vec3A, reach: f32, c: &mut Counters) -> Option<f32> {
        World::occlusion(self, point, normal, reach, c)
    }

    fn bytes(&self) -> usize {
        self.memory().total()
    }
}
