//! The SDF back-end: each object's shape tree becomes a closure-composed distance
//! bound, sphere traced inside the interval where the ray is within the object's
//! bounding box and bounding sphere (the [`world`](crate::world) decides which objects a
//! ray can reach).
//!
//! Supported IR subset: every shape. Explicit `mesh …` objects are lowered by the mesh
//! back-end.

mod build;
mod domain;
mod field;
pub mod march;
pub mod prim;
mod surf;
mod sweep;
#[cfg(test)]
mod testing;
pub mod union;
mod warp;

use glam::{DAffine3, Vec3A};

pub use crate::ir::min_singular_value;
pub use build::{Builder, Root, Walk};
pub use march::MarchParams;
pub use surf::{Sdf, Surf, SurfSdf};

use crate::ir;
use crate::trace::{Counters, Hit, Packet, Ray};

/// One shape object ready for marching, in render space.
#[derive(Clone)]
pub struct SdfObject {
    /// Distance bound, for marching.
    pub dist: Sdf,
    /// Distance, gradient and material, evaluated once per hit.
    pub mat: SurfSdf,
    /// Whether the shape is a convex solid ([`ir::Shape::is_convex`]).
    convex: bool,
    /// How its rays are marched.
    walk: Walk,
    /// Whether its hits are confirmed by [`march::refine`] (`build::looseness` above
    /// 1), and then how many times the scene's step budget its marches get.
    loose: Option<u32>,
}

/// Most times the scene's step budget a loose object's marches get: a stated slope of
/// 64 or more crawls by its bound at up to 64 × 512 steps a ray by default.
const MAX_WIDENING: f64 = 64.0;

/// The most steps a widened budget reaches, unless the scene's own is larger.
const MAX_WIDENED_STEPS: u64 = 1 << 16;

impl SdfObject {
    /// Lowers a shape seen through `xf` (render from world) into closures.
    pub fn new(shape: &ir::Shape, xf: DAffine3, builder: &mut Builder<'_>) -> SdfObject {
        let root = builder.build_root(shape, xf, 0);
        let convex = match &root.walk {
            // A field at the root has asked already (its march steps by it).
            Walk::Field(f) => f.convex,
            Walk::Plain | Walk::Parts(_) | Walk::Warp(_) => shape.is_convex(),
        };
        // A bound that understates the distance `L` times near the surface crawls there
        // at about `L` times the steps: the budget grows with it, so a large stated
        // slope costs steps, not pixels.
        let loose = (root.loose > 1.0).then(|| root.loose.min(MAX_WIDENING).ceil() as u32);
        SdfObject { dist: root.dist, mat: root.surf, walk: root.walk, convex, loose }
    }

    /// `params` with the step budget this object's marches get.
    fn widened(&self, params: MarchParams) -> MarchParams {
        match self.loose {
            Some(k) => {
                let wide = (u64::from(params.max_steps) * u64::from(k)).min(MAX_WIDENED_STEPS);
                MarchParams { max_steps: params.max_steps.max(wide as u32), ..params }
            }
            None => params,
        }
    }

    /// Marches the ray over `[t0, t1]`; on a hit, its distance and the threshold there
    /// (the hit point's error bound). A ray `inside` the solid (refracted into it) is
    /// marched out of it by [`march::march_out`] over the whole tree, and its hit is where
    /// it leaves the solid or meets a cavity (a union's parts are pruned only for rays
    /// outside them).
    pub fn closest(
        &self,
        ray: &Ray,
        (t0, t1): (f32, f32),
        inside: bool,
        params: MarchParams,
        c: &mut Counters,
        evals: &mut u64,
    ) -> Option<(f32, f32)> {
        let params = self.widened(params);
        if inside {
            return march::march_out(&*self.dist, ray, t0, t1, params, c, evals);
        }
        let hit = self.walk_closest(ray, (t0, t1), params, c, evals);
        if self.loose.is_some() {
            self.confirm(hit, ray, t1, params, c, evals)
        } else {
            hit
        }
    }

    /// The walk's first hit, unconfirmed.
    fn walk_closest(
        &self,
        ray: &Ray,
        (t0, t1): (f32, f32),
        params: MarchParams,
        c: &mut Counters,
        evals: &mut u64,
    ) -> Option<(f32, f32)> {
        match &self.walk {
            Walk::Field(field) => field.march(ray, (t0, t1), params, c, evals),
            Walk::Warp(warp) => warp.march(ray, (t0, t1), params, c, evals),
            Walk::Parts(parts) => parts.march(ray, (t0, t1), params, c, evals),
            Walk::Plain => march::march(&*self.dist, ray, t0, t1, params, c, evals),
        }
    }

    /// A loose object's hit `hit` confirmed by [`march::refine`], the march going on
    /// past each place the ray only passes near the surface. The confirmations share one
    /// step budget.
    fn confirm(
        &self,
        mut hit: Option<(f32, f32)>,
        ray: &Ray,
        t1: f32,
        params: MarchParams,
        c: &mut Counters,
        evals: &mut u64,
    ) -> Option<(f32, f32)> {
        for _ in 0..params.max_steps {
            let (t, _) = hit?;
            match march::refine(&*self.dist, &*self.mat, ray, (t, t1), params, c, evals) {
                march::Refined::Hit(t, threshold) => return Some((t, threshold)),
                march::Refined::Miss => return None,
                march::Refined::Resume(t) => hit = self.walk_closest(ray, (t, t1), params, c, evals),
            }
        }
        c.budget_misses += 1;
        None
    }

    /// Whether packets of camera rays are marched together: a sharp union's walk of
    /// its parts, a field's evaluations ([`closest_packet`](Self::closest_packet)).
    pub fn walks_packets(&self) -> bool {
        match &self.walk {
            Walk::Field(_) => true,
            Walk::Parts(p) => p.k == 0.0,
            Walk::Plain | Walk::Warp(_) => false,
        }
    }

    /// [`closest`](Self::closest) for the lanes `mask` of `N` packets of rays starting
    /// outside the solid, lane `l` of packet `g` over `spans[g][l]`, with `evals` per lane:
    /// a sharp union's lanes share one walk of its parts, a field's evaluate its body
    /// together, any other object marches each lane alone.
    pub fn closest_packet<const N: usize>(
        &self,
        quads: &[Packet; N],
        mask: u32,
        spans: &[[(f32, f32); 4]; N],
        params: MarchParams,
        c: &mut Counters,
        evals: &mut [[u64; 4]; N],
    ) -> [[Option<(f32, f32)>; 4]; N] {
        let wide = self.widened(params);
        let mut hits = match &self.walk {
            Walk::Field(field) => field.march_packet(quads, mask, spans, wide, c, evals),
            Walk::Parts(parts) if parts.k == 0.0 => parts.march_packet(quads, mask, spans, wide, c, evals),
            Walk::Plain | Walk::Parts(_) | Walk::Warp(_) => {
                return self.each_lane(quads, mask, spans, params, c, evals)
            }
        };
        if self.loose.is_some() {
            for lane in crate::trace::lanes(mask) {
                let (g, l) = (lane / 4, lane % 4);
                let (ray, t1) = (&quads[g].rays[l], spans[g][l].1);
                hits[g][l] = self.confirm(hits[g][l], ray, t1, wide, c, &mut evals[g][l]);
            }
        }
        hits
    }

    /// [`closest_packet`](Self::closest_packet) lane by lane.
    fn each_lane<const N: usize>(
        &self,
        quads: &[Packet; N],
        mask: u32,
        spans: &[[(f32, f32); 4]; N],
        params: MarchParams,
        c: &mut Counters,
        evals: &mut [[u64; 4]; N],
    ) -> [[Option<(f32, f32)>; 4]; N] {
        let mut hits = [[None; 4]; N];
        for lane in crate::trace::lanes(mask) {
            let (g, l) = (lane / 4, lane % 4);
            hits[g][l] = self.closest(&quads[g].rays[l], spans[g][l], false, params, c, &mut evals[g][l]);
        }
        hits
    }

    /// The surface at a hit found by [`closest`](Self::closest): normal from the field's
    /// analytic gradient and material from the surface closure, numbered `object`. Done
    /// once per ray, for the winner.
    /// `leaving` says the hit was found marching from inside: the ray is leaving the solid
    /// there whatever the gradient says (at grazing, or in a wall thinner than the
    /// threshold, it can point either way), so the normal is turned to agree.
    // Kept out of line: inlined into `World::intersect` it bloated the march loop's caller
    // and cost a one-object SDF scene ~10% of its primary-ray throughput (bench
    // `primary rays/intersect sdf/01-sphere`).
    #[inline(never)]
    pub fn surface(&self, ray: &Ray, t: f32, error: f32, object: u32, leaving: bool, c: &mut Counters) -> Hit {
        let point = ray.at(t);
        let Surf { d, g, mat: material } = match &self.walk {
            Walk::Parts(parts) => parts.surface(point, error),
            Walk::Plain | Walk::Field(_) | Walk::Warp(_) => (self.mat)(point),
        };
        // A flat gradient (at a crease or a cusp) gets a defined, finite normal.
        let normal = g.try_normalize().unwrap_or(Vec3A::Y);
        c.sdf_shading_evals += 1;
        // The gradient of a convex solid's field is its outward normal, but only on the
        // surface: a ray starting inside the solid "hits" where it starts, below it.
        let convex = self.convex && d > -error;
        let from_inside = leaving || normal.dot(ray.dir) > 0.0;
        let normal = if leaving && normal.dot(ray.dir) < 0.0 { -normal } else { normal };
        Hit { t, point, normal, material, error, object, behind: convex.then_some(normal), from_inside }
    }

    /// The unblocked fraction of a cone of slope `cone` around the ray over `[t0, t1]`: the
    /// penumbra estimate `min(h / (cone·t))` gathered while marching (Quilez), 0 on a hit.
    /// `(t0, t1)` is the interval to march.
    pub fn penumbra(
        &self,
        ray: &Ray,
        (t0, t1): (f32, f32),
        cone: f32,
        params: MarchParams,
        c: &mut Counters,
        evals: &mut u64,
    ) -> f32 {
        let params = self.widened(params);
        let base = ray.origin.length();
        let mut t = t0;
        let mut res = 1.0f32;
        for _ in 0..params.max_steps {
            let h = (self.dist)(ray.at(t));
            *evals += 1;
            if h < march::threshold(params.epsilon, base, t) {
                if self.loose.is_none() {
                    return 0.0;
                }
                match march::refine(&*self.dist, &*self.mat, ray, (t, t1), params, c, evals) {
                    march::Refined::Hit(..) => return 0.0,
                    march::Refined::Miss => break,
                    // Beside the surface, not on it: the penumbra goes on from
                    // where the confirmation left the ray.
                    march::Refined::Resume(next) => {
                        t = next.max(t + 1e-3 * t);
                        continue;
                    }
                }
            }
            res = res.min(h / (cone * t.max(f32::MIN_POSITIVE)));
            // Never step less than a small fraction of the distance, so grazing stays cheap.
            t += h.max(1e-3 * t);
            if t > t1 || res <= 0.0 {
                break;
            }
        }
        if t <= t1 && res > 0.0 {
            c.budget_misses += 1;
        }
        res.clamp(0.0, 1.0)
    }

    /// The distance bound at a render-space point.
    pub fn eval(&self, p: Vec3A) -> f32 {
        (self.dist)(p)
    }
}
