//! `scnc sweep`: render one scene across a ladder of accuracy settings for both back-ends
//! and measure, for each, time, work, memory and error against a reference (see
//! [`crate::accuracy`] for the metrics and the reference).

use std::fmt::Write as _;
use std::time::Instant;

use crate::accuracy;
use crate::diag::Diagnostic;
use crate::effects;
use crate::ir::Scene;
use crate::mesh::Detail;
use crate::render::{self, Counters, Image};
use crate::source::Loader;
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
pub fn picked(scene: &Scene, tol: crate::tolerance::Tolerance) -> Vec<Setting> {
    vec![
        Setting::Sdf { epsilon: crate::tolerance::sdf_epsilon(scene, tol), max_steps: scene.settings.max_steps },
        Setting::Mesh(crate::tolerance::mesh_detail(scene, tol)),
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

/// Runs the ladder on `scene` (already sized), calling `progress` after each setting.
pub fn run(
    scene: &Scene,
    settings: &[Setting],
    runs: usize,
    loader: &dyn Loader,
    progress: &dyn Fn(&Setting),
) -> Result<Vec<Row>, Diagnostic> {
    let (reference_scene, _) = with_setting(scene, Setting::Sdf { epsilon: 1e-6, max_steps: 100_000 });
    let (ref_frame, ref_world) =
        world::prepare(&reference_scene, effects::derive(&reference_scene), Mode::Sdf, loader)?;
    let (ref_image, _) = render::render(&ref_world, &ref_frame, &|| {});
    let ref_hits = accuracy::primary_hits(&ref_world, &ref_frame);
    let distance = accuracy::scene_distance(&ref_world);
    let mut rows = Vec::with_capacity(settings.len());
    for &setting in settings {
        let (s, mode) = with_setting(scene, setting);
        reset_peak_rss();
        let m = measure(&s, mode, runs, loader)?;
        let peak_rss_kib = peak_rss_kib();
        let (geo_mean, geo_max) = accuracy::geometric_error(&m.hits, &distance);
        let geo_max_px = accuracy::geometric_error_pixels(&m.hits, &distance, crate::tolerance::pixel_angle(scene));
        let c = &m.counters;
        let rays = c.rays().max(1) as f64;
        let rmse = accuracy::rmse(&m.image, &ref_image);
        rows.push(Row {
            setting,
            wall_ms: m.wall_ms,
            rays_per_s: c.rays() as f64 / (m.wall_ms / 1e3).max(1e-9),
            evals_per_ray: c.sdf_evals as f64 / rays,
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

/// Resets the process's peak resident set size (Linux ≥ 4.0); a no-op elsewhere.
fn reset_peak_rss() {
    // Writing 5 to clear_refs resets VmHWM to the current RSS. Failure only means the
    // column is the peak since an earlier point, which `peak_rss_kib` cannot tell; on
    // systems without procfs both calls do nothing.
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// The process's peak resident set size in KiB, from /proc/self/status (Linux).
fn peak_rss_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The columns of `sweep.csv`.
pub const CSV_HEADER: &str = "backend,setting,wall_ms,rays_per_s,sdf_evals_per_ray,node_visits_per_ray,triangle_tests_per_ray,geometry_bytes,triangles,peak_rss_kib,geo_error_mean,geo_error_max,geo_error_max_pixels,coverage_error_px,rmse,psnr_db";

/// Rows as CSV.
pub fn csv(rows: &[Row]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{:.3},{:.0},{:.3},{:.3},{:.3},{},{},{},{:e},{:e},{:.4},{},{:.4},{:.2}",
            r.setting.backend(),
            r.setting.label(),
            r.wall_ms,
            r.rays_per_s,
            r.evals_per_ray,
            r.visits_per_ray,
            r.tests_per_ray,
            r.bytes,
            r.triangles,
            r.peak_rss_kib.map_or(String::new(), |k| k.to_string()),
            r.geo_mean,
            r.geo_max,
            r.geo_max_px,
            r.coverage,
            r.rmse,
            r.psnr
        );
    }
    out
}

/// Rows as a Markdown table.
pub fn markdown(rows: &[Row], title: &str) -> String {
    let mut out = format!("# Sweep: {title}\n\nReference: the SDF render at epsilon 1e-6 with a 100 000-step budget. Geometric error is |d| at primary hits, in world units.\n\n| back-end | setting | wall | rays/s | evals/ray | visits/ray | tri tests/ray | bytes | triangles | peak RSS | geo error mean | geo error max | max in pixels | coverage px | RMSE | PSNR |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.1} ms | {:.2} M | {:.2} | {:.2} | {:.2} | {} | {} | {} | {:.2e} | {:.2e} | {:.3} | {} | {:.2} | {:.1} dB |",
            r.setting.backend(),
            r.setting.label(),
            r.wall_ms,
            r.rays_per_s / 1e6,
            r.evals_per_ray,
            r.visits_per_ray,
            r.tests_per_ray,
            r.bytes,
            r.triangles,
            r.peak_rss_kib.map_or("n/a".to_string(), |k| format!("{:.1} MiB", k as f64 / 1024.0)),
            r.geo_mean,
            r.geo_max,
            r.geo_max_px,
            r.coverage,
            r.rmse,
            r.psnr
        );
    }
    out
}
