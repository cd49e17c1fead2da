//! `scnc sweep`: render one scene across a ladder of accuracy settings for both back-ends
//! and measure, for each, time, work, memory and error against a reference (see
//! [`super::accuracy`] for the metrics and the reference); [`super::report`] writes them.
//!
//! Time is measured as a benchmark harness does it: after a warm-up render of each
//! setting, the settings are rendered in rounds (one render of each per round, so a change
//! in the machine's load falls on all of them alike), each until its median's 95 %
//! confidence interval (from order statistics, so no distribution is assumed) is within
//! [`CONFIDENCE`] of it, or a time cap is reached; the minimum, median and maximum are
//! reported, with the CPU time beside the wall time. On a shared machine
//! a wall time is still the machine's as much as the setting's, so each setting also has
//! its **work**: the unit operations its frame takes (primitive distance evaluations, BVH
//! node visits, triangle tests), counted exactly, the same on every run and machine.

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
            Setting::Mesh(detail) => detail.describe(),
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

/// The median's confidence interval (half its width) that ends a setting's timing, as
/// a share of the median.
pub const CONFIDENCE: f64 = 0.02;

/// How a setting's renders were timed, in milliseconds of lowering plus rendering.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Timed renders (after one warm-up).
    pub runs: usize,
    /// The fastest.
    pub min_ms: f64,
    /// The median.
    pub median_ms: f64,
    /// The slowest.
    pub max_ms: f64,
    /// Half the width of the median's 95 % confidence interval.
    pub ci_ms: f64,
    /// CPU time per render (all threads), if the system tells.
    pub cpu_ms: Option<f64>,
}

impl Timing {
    /// The timing of `times` (at least one), with `cpu_ms` per render.
    pub fn of(mut times: Vec<f64>, cpu_ms: Option<f64>) -> Timing {
        times.sort_by(f64::total_cmp);
        let n = times.len();
        let median = if n % 2 == 1 { times[n / 2] } else { 0.5 * (times[n / 2 - 1] + times[n / 2]) };
        // The ranks bounding the median's 95 % interval: n/2 ± 0.98·√n (a binomial's
        // normal approximation), clamped to the sample.
        let spread = 0.98 * (n as f64).sqrt();
        let lo = ((n as f64 / 2.0 - spread).floor().max(0.0) as usize).min(n - 1);
        let hi = ((n as f64 / 2.0 + spread).ceil() as usize).min(n - 1);
        Timing {
            runs: n,
            min_ms: times[0],
            median_ms: median,
            max_ms: times[n - 1],
            ci_ms: 0.5 * (times[hi] - times[lo]),
            cpu_ms,
        }
    }

    /// Whether the median is known well enough: its interval within [`CONFIDENCE`].
    pub fn settled(&self) -> bool {
        self.ci_ms <= CONFIDENCE * self.median_ms
    }
}

/// What one setting measured.
#[derive(Clone, Debug)]
pub struct Row {
    /// The setting.
    pub setting: Setting,
    /// Its renders' times.
    pub time: Timing,
    /// Unit operations per frame: primitive distance evaluations, BVH node visits and
    /// triangle tests, counted exactly (independent of the machine and its load).
    pub work: u64,
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

/// One lowering and render of a scene: its wall time (ms) and what it made.
fn render_once(
    scene: &Scene,
    mode: Mode,
    loader: &dyn Loader,
) -> Result<(f64, render::Frame, world::World, Image, Counters), Diagnostic> {
    let start = Instant::now();
    let (frame, world) = world::prepare(scene, effects::derive(scene), mode, loader)?;
    let (img, c) = render::render(&world, &frame, &|| {});
    Ok((start.elapsed().as_secs_f64() * 1e3, frame, world, img, c))
}

/// Times every setting (scene and mode) in rounds, each round rendering once each
/// setting still unsettled, so a change in the machine's load falls on all of them
/// alike (as a paired benchmark pairs its commands); a setting leaves the rounds once its
/// median is settled after `min_runs`, and all leave when `cap` seconds per setting have
/// passed. Its wall times, and the CPU time per render if the system tells.
fn time_rounds(settings: &[(Scene, Mode)], opts: &Options<'_>) -> Result<Vec<Timed>, Diagnostic> {
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); settings.len()];
    let mut cpu: Vec<Option<f64>> = vec![Some(0.0); settings.len()];
    let started = Instant::now();
    let cap = opts.cap * settings.len() as f64;
    let mut round = 0;
    loop {
        let open: Vec<usize> = (0..settings.len())
            .filter(|&i| {
                let t = &times[i];
                t.len() < opts.min_runs.max(1) || (t.len() < MAX_RUNS && !Timing::of(t.clone(), None).settled())
            })
            .collect();
        let capped = started.elapsed().as_secs_f64() >= cap && open.iter().all(|&i| times[i].len() >= opts.min_runs);
        if open.is_empty() || capped {
            break;
        }
        round += 1;
        (opts.progress)(Step::Timing { round, open: open.len() });
        for i in open {
            let (scene, mode) = &settings[i];
            let before = (opts.cpu_seconds)();
            let (ms, ..) = render_once(scene, *mode, opts.loader)?;
            times[i].push(ms);
            cpu[i] = match (cpu[i], before, (opts.cpu_seconds)()) {
                (Some(sum), Some(a), Some(b)) => Some(sum + (b - a) * 1e3),
                _ => None,
            };
        }
    }
    Ok(times.into_iter().zip(cpu).map(|(t, c)| (t.clone(), c.map(|sum| sum / t.len().max(1) as f64))).collect())
}

/// One setting's wall times (ms) and its mean CPU time per render, if the system tells.
type Timed = (Vec<f64>, Option<f64>);

/// Most timed renders of one setting, whatever the time cap.
const MAX_RUNS: usize = 1000;

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
    /// The fewest timed renders per setting, after one warm-up.
    pub min_runs: usize,
    /// Seconds after which a setting's timing stops though its median is not settled
    /// (once it has `min_runs`).
    pub cap: f64,
    /// CPU seconds the process has used so far (all threads), if the system tells:
    /// only the binary reads system state.
    pub cpu_seconds: &'a dyn Fn() -> Option<f64>,
    /// Reads mesh files.
    pub loader: &'a dyn Loader,
    /// Measures peak memory per setting.
    pub memory: &'a dyn PeakMemory,
    /// Told where the sweep is: the reference render, each setting's first render (its
    /// accuracy known), then each round of timing.
    pub progress: &'a dyn Fn(Step<'_>),
}

/// A point a sweep reports reaching, for a progress display.
#[derive(Clone, Copy, Debug)]
pub enum Step<'a> {
    /// The many-step reference render, at this setting, is starting.
    Reference(&'a Setting),
    /// Setting `done` of `total` has had its first render (accuracy measured).
    Measured {
        /// The setting.
        setting: &'a Setting,
        /// How many settings are measured, this one included.
        done: usize,
        /// How many there are.
        total: usize,
    },
    /// A round of timing renders is starting, with `open` settings still unsettled.
    Timing {
        /// The round, from 1.
        round: usize,
        /// Settings timed in this round.
        open: usize,
    },
}

/// Runs the ladder on `scene` (already sized).
pub fn run(scene: &Scene, settings: &[Setting], opts: &Options<'_>) -> Result<Vec<Row>, Diagnostic> {
    let Options { loader, memory, progress, .. } = *opts;
    let reference = Setting::Sdf { epsilon: 1e-6, max_steps: 100_000 };
    progress(Step::Reference(&reference));
    let (reference_scene, _) = with_setting(scene, reference);
    let (ref_frame, ref_world) =
        world::prepare(&reference_scene, effects::derive(&reference_scene), Mode::Sdf, loader)?;
    let (ref_image, _) = render::render(&ref_world, &ref_frame, &|| {});
    let ref_hits = accuracy::primary_hits(&ref_world, &ref_frame);
    let distance = accuracy::scene_distance(&ref_world);
    // First what each setting makes and how close it comes, one render each (also the
    // timing's warm-up), with the process's peak memory during it; only the figures are
    // kept, so no setting's peak holds another's image.
    let variants: Vec<(Scene, Mode)> = settings.iter().map(|&s| with_setting(scene, s)).collect();
    let mut rows = Vec::with_capacity(settings.len());
    for ((s, mode), &setting) in variants.iter().zip(settings) {
        memory.reset();
        let (_, frame, world, image, c) = render_once(s, *mode, loader)?;
        let peak_rss_kib = memory.peak_kib();
        let hits = accuracy::primary_hits(&world, &frame);
        let mem = world.memory();
        let (geo_mean, geo_max) = accuracy::geometric_error(&hits, &distance);
        let geo_max_px = accuracy::geometric_error_pixels(&hits, &distance, super::tolerance::pixel_angle(scene));
        let rays = c.rays().max(1) as f64;
        let rmse = accuracy::rmse(&image, &ref_image);
        rows.push(Row {
            setting,
            time: Timing::of(vec![0.0], None),
            work: c.leaf_evals + c.node_visits + c.triangle_tests,
            rays_per_s: c.rays() as f64,
            evals_per_ray: c.sdf_evals as f64 / rays,
            leaves_per_ray: c.leaf_evals as f64 / rays,
            visits_per_ray: c.node_visits as f64 / rays,
            tests_per_ray: c.triangle_tests as f64 / rays,
            bytes: mem.total(),
            triangles: mem.triangles(),
            peak_rss_kib,
            geo_mean,
            geo_max,
            geo_max_px,
            coverage: accuracy::coverage_error(&hits, &ref_hits),
            rmse,
            psnr: accuracy::psnr(rmse),
        });
        progress(Step::Measured { setting: &setting, done: rows.len(), total: settings.len() });
    }
    // Then how long each takes, all timed in rounds; rays per second from the median.
    for (row, (times, cpu_ms)) in rows.iter_mut().zip(time_rounds(&variants, opts)?) {
        row.time = Timing::of(times, cpu_ms);
        row.rays_per_s /= (row.time.median_ms / 1e3).max(1e-9);
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timings_know_their_median_and_its_interval() {
        let t = Timing::of(vec![10.0, 12.0, 11.0], Some(20.0));
        assert_eq!((t.runs, t.min_ms, t.median_ms, t.max_ms, t.cpu_ms), (3, 10.0, 11.0, 12.0, Some(20.0)));
        assert_eq!(Timing::of(vec![4.0, 1.0, 3.0, 2.0], None).median_ms, 2.5);
        // Twenty close runs and one outlier: the interval ignores the outlier.
        let mut times: Vec<f64> = (0..20).map(|i| 100.0 + (i % 3) as f64 * 0.5).collect();
        times.push(400.0);
        let t = Timing::of(times, None);
        assert!(t.settled(), "{t:?}");
        assert_eq!(t.max_ms, 400.0);
        // Five scattered runs are not.
        assert!(!Timing::of(vec![50.0, 90.0, 70.0, 120.0, 60.0], None).settled());
    }
}
