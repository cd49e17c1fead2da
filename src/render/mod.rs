//! The common Whitted tracer: camera, lights, Phong shading, hard shadows, recursive
//! reflections. It knows geometry only through the [`Geometry`] contract, so the SDF
//! and mesh back-ends plug in unchanged.
//!
//! Everything here works in *render space*: world space translated so the camera sits at
//! the origin, in f32. Lowering subtracts the camera position in f64 first, so a scene
//! far from the world origin keeps its precision.
//!
//! **Invariant:** the image depends only on the scene and the settings, never on the
//! thread count: rows are independent and counters are summed exactly.

mod frame;
mod shade;

use glam::{Mat4, Vec3A, Vec4};
use rayon::prelude::*;

pub use frame::{Frame, MaterialTable, ShadeLight, ShadeMaterial};

/// A ray in render space.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3A,
    /// Unit direction.
    pub dir: Vec3A,
    /// Component-wise `1 / dir`, for slab tests.
    pub inv_dir: Vec3A,
    /// Nearest accepted hit distance.
    pub t_min: f32,
    /// Farthest accepted hit distance.
    pub t_max: f32,
    /// An object the ray cannot meet, which a back-end may leave out ([`NO_OBJECT`] for none):
    /// the convex object a secondary ray leaves (see [`Ray::leaving`]).
    pub skip: u32,
}

/// No object: the [`Ray::skip`] of a ray that may meet anything.
pub const NO_OBJECT: u32 = u32::MAX;

impl Ray {
    /// A ray from `origin` along the unit vector `dir`, accepting hits in `[0, t_max]`.
    pub fn new(origin: Vec3A, dir: Vec3A, t_max: f32) -> Ray {
        debug_assert!(origin.is_finite() && dir.is_finite(), "non-finite ray");
        Ray { origin, dir, inv_dir: dir.recip(), t_min: 0.0, t_max, skip: NO_OBJECT }
    }

    /// A secondary ray from `origin`, just off `hit`'s surface, along `dir`. When the hit
    /// object lies wholly behind its tangent plane at the hit ([`Hit::convex`]) and the ray
    /// starts in front of that plane and moves away from it, every point of the ray is in
    /// front of the plane, so the ray cannot meet the object again and skips it: that
    /// saves walking the object's own BVH, which every such ray starts inside, and makes
    /// self-intersection there impossible rather than only guarded by the offset.
    pub fn leaving(hit: &Hit, origin: Vec3A, dir: Vec3A, t_max: f32) -> Ray {
        let mut ray = Ray::new(origin, dir, t_max);
        if hit.convex && hit.normal.dot(origin - hit.point) > 0.0 && hit.normal.dot(dir) > 0.0 {
            ray.skip = hit.object;
        }
        ray
    }

    /// The point at distance `t`.
    pub fn at(&self, t: f32) -> Vec3A {
        self.origin + self.dir * t
    }
}

/// Up to four rays traced together (a 2×2 block of camera rays; the tracer sends four
/// as a 4×4 block, [`Geometry::intersect16`]). Lane `k` is wanted when
/// bit `k` of `mask` is set; an unwanted lane holds a copy of a wanted ray, so every lane
/// is a valid ray and a back-end may trace all four.
#[derive(Clone, Copy, Debug)]
pub struct Packet {
    /// The rays, one per lane.
    pub rays: [Ray; 4],
    /// Wanted lanes.
    pub mask: u32,
}

impl Packet {
    /// A packet of one to four rays (lanes beyond `rays.len()` are unwanted copies of the last).
    pub fn new(rays: &[Ray]) -> Packet {
        Packet::from_fn(rays.len(), |l| rays[l])
    }

    /// A packet of `count` (one to four) rays, lane `l` being `ray(l)`; lanes beyond
    /// `count` are unwanted copies of the last.
    pub fn from_fn(count: usize, mut ray: impl FnMut(usize) -> Ray) -> Packet {
        assert!((1..=4).contains(&count), "a packet holds one to four rays");
        Packet { rays: std::array::from_fn(|l| ray(l.min(count - 1))), mask: (1 << count) - 1 }
    }

    /// A vector of the lanes' rays across SIMD lanes (structure of arrays) per axis:
    /// component `k` of `f(ray l)` is lane `l` of vector `k`. One transpose.
    #[inline(always)]
    pub fn across(&self, f: impl Fn(&Ray) -> Vec3A) -> [Vec4; 3] {
        let col = |l: usize| f(&self.rays[l]).extend(0.0);
        let m = Mat4::from_cols(col(0), col(1), col(2), col(3)).transpose();
        [m.x_axis, m.y_axis, m.z_axis]
    }

    /// `f(ray l)` in lane `l`.
    #[inline(always)]
    pub fn each(&self, f: impl Fn(&Ray) -> f32) -> Vec4 {
        Vec4::from_array(self.rays.each_ref().map(f))
    }
}

/// The lanes set in a packet's `mask`, lowest first (bit `k` is lane `k`; packets traced
/// together number their lanes on, four to a packet).
#[inline(always)]
pub fn lanes(mask: u32) -> impl Iterator<Item = usize> {
    let mut rest = mask;
    std::iter::from_fn(move || {
        let lane = (rest != 0).then(|| rest.trailing_zeros() as usize)?;
        rest &= rest - 1;
        Some(lane)
    })
}

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
    /// The object hit, in the back-end's numbering ([`NO_OBJECT`] if it has none).
    pub object: u32,
    /// Whether the object lies wholly behind the plane through `point` normal to `normal`
    /// (a convex solid with its geometric normal, or a flat surface), so a ray leaving the
    /// front of that plane cannot meet it again.
    pub convex: bool,
}

/// Work counters, summed over the whole render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Camera rays.
    pub primary_rays: u64,
    /// Shadow (occlusion) rays.
    pub shadow_rays: u64,
    /// Reflection rays.
    pub reflection_rays: u64,
    /// Ambient-occlusion rays (mesh scenes; SDF scenes estimate without rays).
    pub occlusion_rays: u64,
    /// SDF evaluations during marching (SDF back-end).
    pub sdf_evals: u64,
    /// SDF evaluations for normals and materials at hits.
    pub sdf_shading_evals: u64,
    /// Most SDF evaluations spent on one ray.
    pub max_evals_per_ray: u64,
    /// Marches that ran out of steps before deciding (counted as misses).
    pub budget_misses: u64,
    /// BVH nodes visited (a node a packet visits counts once for each ray the walk
    /// carries into it: every wanted ray from its first active one, see
    /// [`Bvh::each_packet`](crate::accel::Bvh::each_packet)).
    pub node_visits: u64,
    /// Ray–triangle tests (mesh back-end; a packet's test counts once per ray it tests).
    pub triangle_tests: u64,
    /// Samples whose colour was not finite (always 0 unless there is a bug; such a
    /// sample is written as black).
    pub nonfinite_samples: u64,
}

impl Counters {
    /// Adds another set of counters.
    pub fn add(&mut self, o: &Counters) {
        self.primary_rays += o.primary_rays;
        self.shadow_rays += o.shadow_rays;
        self.reflection_rays += o.reflection_rays;
        self.occlusion_rays += o.occlusion_rays;
        self.sdf_evals += o.sdf_evals;
        self.sdf_shading_evals += o.sdf_shading_evals;
        self.max_evals_per_ray = self.max_evals_per_ray.max(o.max_evals_per_ray);
        self.budget_misses += o.budget_misses;
        self.node_visits += o.node_visits;
        self.triangle_tests += o.triangle_tests;
        self.nonfinite_samples += o.nonfinite_samples;
    }

    /// All rays cast.
    pub fn rays(&self) -> u64 {
        self.primary_rays + self.shadow_rays + self.reflection_rays + self.occlusion_rays
    }
}

/// What a geometry back-end provides to the tracer.
pub trait Geometry: Sync {
    /// The closest hit along the ray within `[t_min, t_max]`. A back-end may leave out
    /// the object `ray.skip`: the tracer names one only when the ray leaves a hit of it
    /// marked [`Hit::convex`] outward ([`Ray::leaving`]), so the ray cannot meet it.
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
    // time of a one-object SDF packet, in copies of the array being built.
    let mut hits = [None; 4];
    for l in lanes(packet.mask) {
        hits[l] = g.intersect(&packet.rays[l], counters);
    }
    hits
}

/// A rendered image: RGB, 8 bits per channel, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height × 3` bytes.
    pub pixels: Vec<u8>,
}

/// Renders the frame with any geometry. Rows run in parallel on the current rayon
/// pool; `progress` is called once per finished row.
pub fn render(geometry: &dyn Geometry, frame: &Frame, progress: &(dyn Fn() + Sync)) -> (Image, Counters) {
    let e = &frame.effects;
    // Pick the tracer built for this effect set, once, before the first ray.
    macro_rules! pick {
        ($($s:literal $r:literal $p:literal $a:literal),*) => {
            match (e.shadows(), e.reflections, e.specular, e.ambient_occlusion.is_some()) {
                $(($s, $r, $p, $a) => rows::<$s, $r, $p, $a>(geometry, frame, progress),)*
            }
        };
    }
    pick!(
        false false false false, false false false true, false false true false, false false true true,
        false true false false, false true false true, false true true false, false true true true,
        true false false false, true false false true, true false true false, true false true true,
        true true false false, true true false true, true true true false, true true true true
    )
}

fn rows<const SHADOWS: bool, const REFLECT: bool, const SPECULAR: bool, const AO: bool>(
    geometry: &dyn Geometry,
    frame: &Frame,
    progress: &(dyn Fn() + Sync),
) -> (Image, Counters) {
    let (w, h) = (frame.width, frame.height);
    // Rows go in fours, so camera rays can be cast in 4×4 blocks.
    let rows: Vec<(Vec<u8>, Counters)> = (0..h.div_ceil(4))
        .into_par_iter()
        .flat_map_iter(|strip| {
            let (y, rows_here) = (4 * strip, (h - 4 * strip).min(4));
            let mut c = Counters::default();
            let mut rows: Vec<Vec<u8>> = (0..rows_here).map(|_| Vec::with_capacity(w as usize * 3)).collect();
            for x in (0..w).step_by(4) {
                let cols = (w - x).min(4);
                let px =
                    shade::block::<SHADOWS, REFLECT, SPECULAR, AO>(geometry, frame, (x, y), (cols, rows_here), &mut c);
                for (dy, row) in rows.iter_mut().enumerate() {
                    row.extend(px[4 * dy..4 * dy + cols as usize].iter().flatten());
                }
            }
            for _ in 0..rows_here {
                progress();
            }
            // The strip's counters travel with its first row.
            let mut counters = Some(c);
            rows.into_iter().map(move |row| (row, counters.take().unwrap_or_default()))
        })
        .collect();
    let mut counters = Counters::default();
    let mut pixels = Vec::with_capacity(w as usize * h as usize * 3);
    for (row, c) in rows {
        pixels.extend_from_slice(&row);
        counters.add(&c);
    }
    (Image { width: w, height: h, pixels }, counters)
}

/// How far a secondary ray must start from a hit point to not find the same surface:
/// beyond the back-end's stated error, plus a few f32 ulps of the point's magnitude
/// (so the offset grows with distance instead of being a fixed 1e-3).
pub fn spawn_offset(point: Vec3A, error: f32) -> f32 {
    2.0 * error + point.abs().max_element() * 4.0 * f32::EPSILON + f32::MIN_POSITIVE
}
