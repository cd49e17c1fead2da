//! Work counters: rays by kind, SDF evaluations, BVH visits, triangle tests.

/// Work counters, summed over the whole render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Camera rays.
    pub primary_rays: u64,
    /// Shadow (occlusion) rays.
    pub shadow_rays: u64,
    /// Reflection rays (mirrors, and the Fresnel reflection of transparent surfaces).
    pub reflection_rays: u64,
    /// Refraction rays (transmitted through transparent surfaces).
    pub refraction_rays: u64,
    /// Ambient-occlusion rays (mesh scenes; SDF scenes estimate without rays).
    pub occlusion_rays: u64,
    /// SDF evaluations during marching (SDF back-end).
    pub sdf_evals: u64,
    /// SDF evaluations for normals and materials at hits.
    pub sdf_shading_evals: u64,
    /// Primitive (leaf) evaluations inside those, marching and shading together: the
    /// cost of the trees.
    pub leaf_evals: u64,
    /// Most SDF evaluations spent on one ray.
    pub max_evals_per_ray: u64,
    /// Marches that ran out of steps before deciding (counted as misses).
    pub budget_misses: u64,
    /// Bounds of a field's rate of change along a stretch of a ray (segment tracing).
    pub segment_bounds: u64,
    /// BVH nodes visited (a node a packet visits counts once for each ray the walk
    /// carries into it: every wanted ray from its first active one, see
    /// [`Bvh::each_packet`](crate::accel::Bvh::each_packet)).
    pub node_visits: u64,
    /// Ray–triangle tests (mesh back-end; a packet's test counts once per ray it tests).
    pub triangle_tests: u64,
    /// Reflection and refraction rays not traced because their share of the pixel was
    /// below [`MIN_WEIGHT`](crate::render::MIN_WEIGHT).
    pub pruned_rays: u64,
    /// Samples whose ray tree reached [`MAX_TREE_RAYS`](crate::render::MAX_TREE_RAYS)
    /// (its further rays were not traced).
    pub tree_budget_hits: u64,
    /// Samples whose colour was not finite (always 0 unless there is a bug; such a
    /// sample is written as black).
    pub nonfinite_samples: u64,
    /// Light-transport samples scaled down to `render(clamp = …)`.
    pub clamped_samples: u64,
    /// Light-transport paths (one per sample of a pixel).
    pub paths: u64,
    /// Rays towards a chosen light (next-event estimation).
    pub light_rays: u64,
    /// Rays that continue a path in a direction its surface scattered it (BSDF sampling).
    pub bounce_rays: u64,
    /// Paths by how many surfaces they met (the last bin: that many or more).
    pub path_lengths: [u64; PATH_BINS],
    /// Pixels light transport rendered.
    pub path_pixels: u64,
    /// Pixels of two samples or more (which have an error estimate), and the sum of
    /// their estimated relative errors (the standard error of the mean's luminance over
    /// the mean, in millionths).
    pub noise_pixels: u64,
    /// See `noise_pixels`.
    pub noise_ppm: u64,
}

/// Bins of [`Counters::path_lengths`].
pub const PATH_BINS: usize = 10;

impl Counters {
    /// Adds another set of counters.
    pub fn add(&mut self, o: &Counters) {
        self.primary_rays += o.primary_rays;
        self.shadow_rays += o.shadow_rays;
        self.reflection_rays += o.reflection_rays;
        self.refraction_rays += o.refraction_rays;
        self.occlusion_rays += o.occlusion_rays;
        self.sdf_evals += o.sdf_evals;
        self.sdf_shading_evals += o.sdf_shading_evals;
        self.leaf_evals += o.leaf_evals;
        self.max_evals_per_ray = self.max_evals_per_ray.max(o.max_evals_per_ray);
        self.budget_misses += o.budget_misses;
        self.segment_bounds += o.segment_bounds;
        self.node_visits += o.node_visits;
        self.triangle_tests += o.triangle_tests;
        self.pruned_rays += o.pruned_rays;
        self.tree_budget_hits += o.tree_budget_hits;
        self.nonfinite_samples += o.nonfinite_samples;
        self.clamped_samples += o.clamped_samples;
        self.paths += o.paths;
        self.light_rays += o.light_rays;
        self.bounce_rays += o.bounce_rays;
        self.path_pixels += o.path_pixels;
        self.noise_pixels += o.noise_pixels;
        self.noise_ppm += o.noise_ppm;
        for (a, b) in self.path_lengths.iter_mut().zip(o.path_lengths) {
            *a += b;
        }
    }

    /// All rays cast.
    pub fn rays(&self) -> u64 {
        self.primary_rays
            + self.shadow_rays
            + self.reflection_rays
            + self.refraction_rays
            + self.occlusion_rays
            + self.light_rays
            + self.bounce_rays
    }
}

thread_local! {
    /// Primitive evaluations on this thread, for `--stats`: how much a tree costs,
    /// where the march counts only evaluations of a whole object.
    static LEAVES: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Counts one primitive evaluation (the SDF back-end's leaves call it).
#[inline(always)]
pub fn count_leaf() {
    LEAVES.with(|c| c.set(c.get() + 1));
}

/// Primitive (leaf) evaluations on this thread since the last call.
pub fn take_leaf_evals() -> u64 {
    LEAVES.with(|c| c.replace(0))
}
