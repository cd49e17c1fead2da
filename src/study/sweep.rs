//! `scnc sweep`: render one scene across a ladder of accuracy settings for both back-ends
//! and measure, for each, time, work, memory and error against a reference (see
//! [`super::accuracy`] for the metrics and the reference); [`super::report`] writes them.

use std::time::Instant;

use super::accuracy;
use crate::diag::Diagnostic;
use crate::ir::Scene;
use crate::mesh::Detail;
use crate::render::effects;
use crate::render::{self, Image};
use crate::source::Loader;
use crate::trace::Counters;
use crate::world::{self, Mode};

/// One accuracy setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    /// Sphere tracing with a hit threshold and a step budget.
    Sdf {
        /// Relative hit threshold.
        epsilon: f64,
        /// Step budget.
        max_steps: u32,
    },
    /// Tessellation at a detail level.
    Mesh(Detail),
}

impl Setting {
    /// The back-end's name.
    pub fn backend(&self) -> &'static str {
        match self {
            Setting::Sdf { .. } => "sdf",
            Setting::Mesh(_) => "mesh",
        }
    }

    /// The setting as a short label.
    pub fn label(&self) -> String {
        match self {
            Setting::Sdf { epsilon, max_steps } => format!("epsilon {} steps {max_steps}", short_exp(*epsilon)),
            Setting::Mesh(Detail::Low) => "detail low".into(),
            Setting::Mesh(Detail::High) => "detail high".into(),
            Setting::Mesh(Detail::N(n)) => format!("detail {n}"),
        }
    }
}

/// `x` in exponent form with at most four significant digits: `2e-3`, `1.485e-4`.
fn short_exp(x: f64) -> String {
    let s = format!("{x:.3e}");
    match s.split_once('e') {
        Some((mantissa, exp)) => format!("{}e{exp}", mantissa.trim_end_matches('0').trim_end_matches('.')),
        None => s,
    }
}

/// The settings `--tolerance` picks for each back-end.
pub fn picked(scene: &Scene, tol: super::tolerance::Tolerance) -> Vec<Setting> {
    vec![
        Setting::Sdf { epsilon: super::tolerance::sdf_epsilon(scene, tol), max_steps: scene.settings.max_steps },
        Setting::Mesh(super::tolerance::mesh_detail(scene, tol)),
    ]
}

/// The default ladder: SDF thresholds from coarse to fine and two small step budgets;
/// mesh detail from the study's low to 112 rings. `quick` keeps two settings per back-end.
pub fn ladder(quick: bool) -> Vec<Setting> {
    let sdf = |epsilon, max_steps| Setting::Sdf { epsilon, max_steps };
    if quick {
        return vec![sdf(1e-2, 512), sdf(1e-4, 512), Setting::Mesh(Detail::Low), Setting::Mesh(Detail::High)];
    }
    vec![
        sdf(1e-2, 512),
        sdf(1e-3, 512),
        sdf(1e-4, 512),
        sdf(1e-5, 512),
        sdf(1e-4, 8),
        sdf(1e-4, 32),
        Setting::Mesh(Detail::Low),
        Setting::Mesh(Detail::High),
        Setting::Mesh(Detail::N(28)),
        Setting::Mesh(Detail::N(56)),
        Setting::Mesh(Detail::N(112)),
    ]
}

/// What one setting measured.
#[derive(Clone, Debug)]
pub struct Row {
    /// The setting.
    pub setting: Setting,
    /// Median wall time of lowering plus rendering, in milliseconds.
    pub wall_ms: f64,
    /// Rays per second over that time.
    pub rays_per_s: f64,
    /// SDF evaluations per ray (marching).
    pub evals_per_ray: f64,
    /// Primitive (leaf) evaluations per ray, marching and shading: the cost of the trees.
    pub leaves_per_ray: f64,
    /// BVH nodes visited per ray.
    pub visits_per_ray: f64,
    /// Triangle tests per ray.
    pub tests_per_ray: f64,
    /// Bytes of geometry.
    pub bytes: usize,
    /// Triangles (0 for SDF).
    pub triangles: usize,
    /// Peak resident memory of the process while this setting was measured, in KiB
    /// (Linux: the high-water mark is reset before each setting); `None` elsewhere.
    pub peak_rss_kib: Option<u64>,
    /// Mean `|d|` at primary hit points, world units.
    pub geo_mean: f64,
    /// Max `|d|` at primary hit points, world units.
    pub geo_max: f64,
    /// Max `|d|` at primary hit points, in pixel footprints at the hit's depth.
    pub geo_max_px: f64,
    /// Pixels whose coverage differs from the reference.
    pub coverage: usize,
    /// RMSE of the image against the reference.
    pub rmse: f64,
    /// PSNR of the image against the reference, dB.
    pub psnr: f64,
}

fn with_setting(scene: &Scene, s: Setting) -> (Scene, Mode) {
    let mut scene = scene.clone();
    match s {
        Setting::Sdf { epsilon, max_steps } => {
            scene.settings.epsilon = epsilon;
            scene.settings.max_steps = max_steps;
            (scene, Mode::Sdf)
        }
        Setting::Mesh(d) => (scene, Mode::Mesh(d)),
    }
}

/// What one render of a setting produced.
struct Measured {
    image: Image,
    counters: Counters,
    hits: Vec<Option<glam::Vec3A>>,
    bytes: usize,
    triangles: usize,
    wall_ms: f64,
}

/// Renders once to warm up, then `runs` more times; the median wall time of lowering
/// plus rendering, and the last render's image, counters, primary hits and memory.
fn measure(scene: &Scene, mode: Mode, runs: usize, loader: &dyn Loader) -> Result<Measured, Diagnostic> {
    let once = || -> Result<(f64, render::Frame, world::World, Image, Counters), Diagnostic> {
        let start = Instant::now();
        let (frame, world) = world::prepare(scene, effects::derive(scene), mode, loader)?;
        let (img, c) = render::render(&world, &frame, &|| {});
        Ok((start.elapsed().as_secs_f64() * 1e3, frame, world, img, c))
    };
    let mut last = once()?;
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs {
        last = once()?;
        times.push(last.0);
    }
    times.sort_by(f64::total_cmp);
    let wall_ms = times.get(times.len() / 2).copied().unwrap_or(last.0);
    let (_, frame, world, image, counters) = last;
    let hits = accuracy::primary_hits(&world, &frame);
    let mem = world.memory();
    Ok(Measured { image, counters, hits, bytes: mem.total(), triangles: mem.triangles(), wall_ms })
}

/// Where the peak memory of each setting comes from: the process's own accounting,
/// which only the binary may read (the library reads no system state).
pub trait PeakMemory {
    /// Starts a new measurement.
    fn reset(&self);
    /// The peak resident memory since the last reset, in KiB, if the system tells.
    fn peak_kib(&self) -> Option<u64>;
}

/// Measures no memory (the `peak_rss_kib` column stays empty).
pub struct NoPeakMemory;

impl PeakMemory for NoPeakMemory {
    fn reset(&self) {}

    fn peak_kib(&self) -> Option<u64> {
        None
    }
}

/// How to run a sweep.
pub struct Options<'a> {
    /// Timed renders per setting after one warm-up.
    pub runs: usize,
    /// Reads mesh files.
    pub loader: &'a dyn Loader,
    /// Measures peak memory per setting.
    pub memory: &'a dyn PeakMemory,
    /// Called after each setting.
    pub progress: &'a dyn Fn(&Setting),
}

/// Runs the ladder on `scene` (already sized).
pub fn run(scene: &Scene, settings: &[Setting], opts: &Options<'_>) -> Result<Vec<Row>, Diagnostic> {
    let Options { runs, loader, memory, progress } = *opts;
    let (reference_scene, _) = with_setting(scene, Setting::Sdf { epsilon: 1e-6, max_steps: 100_000 });
    let (ref_frame, ref_world) =
        world::prepare(&reference_scene, effects::derive(&reference_scene), Mode::Sdf, loader)?;
    let (ref_image, _) = render::render(&ref_world, &ref_frame, &|| {});
    let ref_hits = accuracy::primary_hits(&ref_world, &ref_frame);
    let distance = accuracy::scene_distance(&ref_world);
    let mut rows = Vec::with_capacity(settings.len());
    for &setting in settings {
        let (s, mode) = with_setting(scene, setting);
        memory.reset();
        let m = measure(&s, mode, runs, loader)?;
        let peak_rss_kib = memory.peak_kib();
        let (geo_mean, geo_max) = accuracy::geometric_error(&m.hits, &distance);
        let geo_max_px = accuracy::geometric_error_pixels(&m.hits, &distance, super::tolerance::pixel_angle(scene));
        let c = &m.counters;
        let rays = c.rays().max(1) as f64;
        let rmse = accuracy::rmse(&m.image, &ref_image);
        rows.push(Row {
            setting,
            wall_ms: m.wall_ms,
            rays_per_s: c.rays() as f64 / (m.wall_ms / 1e3).max(1e-9),
            evals_per_ray: c.sdf_evals as f64 / rays,
            leaves_per_ray: c.leaf_evals as f64 / rays,
            visits_per_ray: c.node_visits as f64 / rays,
            tests_per_ray: c.triangle_tests as f64 / rays,
            bytes: m.bytes,
            triangles: m.triangles,
            peak_rss_kib,
            geo_mean,
            geo_max,
            geo_max_px,
            coverage: accuracy::coverage_error(&m.hits, &ref_hits),
            rmse,
            psnr: accuracy::psnr(rmse),
        });
        progress(&setting);
    }
    Ok(rows)
}
