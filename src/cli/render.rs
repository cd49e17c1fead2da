//! `scnc render`: one scene compiled, lowered and rendered to a PNG.

use std::collections::HashSet;
use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::ValueEnum;

use scnc::check::{Time, EPSILON_RANGE, MAX_DEPTH, MAX_FRAMES, MAX_IMAGE_SIDE, MAX_PIXELS, MAX_SAMPLES, MAX_STEPS};
use scnc::source::FsLoader;
use scnc::Compiled;

use scnc::render::{BitDepth, PixelRect};

use super::files::{
    cannot_write, check_image_output, is_exr, stop_on_interrupt, write_exr, write_part_png, write_png, FPS_KEY,
};
use super::frames::{frame_path, is_pattern, parse_frames, FrameChoice};
use super::passes::is_pass;
use super::progress::{Progress, Reading};
use super::shared::{Accuracy, Meshing, Messages, Params, Workers};
use super::{compile, report, usage_error, MessageFormat};

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum GeometryKind {
    /// Sphere-trace signed distance functions.
    Sdf,
    /// Tessellate every shape into triangles, traced through BVHs.
    Mesh,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum EffectsArg {
    /// Build the tracer with the effects the scene calls for.
    Derived,
    /// Build the general tracer with every effect.
    All,
}

#[derive(clap::Args)]
pub(crate) struct RenderArgs {
    /// The scene file.
    file: PathBuf,
    /// Output image (PNG).
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// Image width in pixels (overrides the scene's `render`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene's `render`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    height: Option<u32>,
    #[command(flatten)]
    workers: Workers,
    /// Sphere-tracing hit threshold, relative to distance from the camera.
    #[arg(long, value_parser = parse_epsilon, conflicts_with = "tolerance")]
    epsilon: Option<f64>,
    /// Sphere-tracing step budget per ray.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_STEPS as i64))]
    max_steps: Option<u32>,
    /// Far limit of every ray.
    #[arg(long, value_parser = parse_positive)]
    max_distance: Option<f64>,
    /// Reflection recursion depth.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=MAX_DEPTH as i64))]
    depth: Option<u32>,
    /// Samples per pixel (antialiasing).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_SAMPLES as i64))]
    samples: Option<u32>,
    /// Under light transport, sample each pixel until its estimated relative error is
    /// below this (at least 16 samples, at most `--samples`).
    #[arg(long, value_parser = parse_noise, value_name = "EPSILON")]
    noise: Option<f64>,
    #[command(flatten)]
    accuracy: Accuracy,
    /// Geometry back-end for shapes (explicit meshes are always meshes).
    #[arg(long, value_enum, default_value = "sdf")]
    geometry: GeometryKind,
    #[command(flatten)]
    meshing: Meshing,
    /// Bits per channel of the PNG: 8, or 16 (finer steps for grading, as shading is
    /// done in f32 before it is quantised).
    #[arg(long, value_parser = parse_bit_depth, value_name = "8|16", default_value = "8")]
    bit_depth: BitDepth,
    /// Print the effect set, ray counts, work per ray and memory.
    #[arg(long)]
    stats: bool,
    /// Which tracer to build: `derived` (only the effects the scene calls for) or `all`
    /// (every effect compiled in; a debugging and benchmarking aid, same image).
    #[arg(long, value_enum, default_value = "derived")]
    effects: EffectsArg,
    /// Render only the pixels X0..X1 × Y0..Y1 (ends exclusive) and write them as a part:
    /// a full-size RGBA PNG, transparent outside the region, for `scnc merge`.
    #[arg(long, value_parser = parse_region, value_name = "X0,Y0,X1,Y1", conflicts_with = "tile")]
    region: Option<[u32; 4]>,
    /// Render band I of N equal bands of rows (I from 0) as a part, like `--region`.
    #[arg(long, value_parser = parse_tile, value_name = "I/N")]
    tile: Option<(u32, u32)>,
    /// Under light transport, render pass I of N of the samples (I from 0): samples
    /// ⌊I·n/N⌋ to ⌊(I+1)·n/N⌋ − 1 of every pixel, written as exact sums to a `.scnpass`
    /// file, which `scnc merge` adds to the image one render of all the samples makes.
    #[arg(long, value_parser = parse_pass, value_name = "I/N", conflicts_with_all = ["tile", "region", "noise"])]
    pass: Option<(u32, u32)>,
    /// Render the pass picked by the task index in this environment variable
    /// (`SLURM_ARRAY_TASK_ID`, `JOB_COMPLETION_INDEX`, …), of `--passes` N.
    #[arg(long, value_name = "VAR", requires = "passes", conflicts_with_all = ["pass", "tile", "region", "noise"])]
    pass_index_from: Option<String>,
    /// The number of passes with `--pass-index-from`.
    #[arg(long, value_name = "N", requires = "pass_index_from", value_parser = clap::value_parser!(u32).range(1..))]
    passes: Option<u32>,
    /// Frames of the scene's animation to render, `A..B` (end exclusive) or `N`; every
    /// frame it declares by default. More than one needs `#` in the output name.
    #[arg(long, value_parser = parse_frames, value_name = "A..B")]
    frames: Option<Range<u32>>,
    /// Leave frames whose output file already exists (outputs are written whole or not
    /// at all, so one that exists is complete).
    #[arg(long)]
    pub(crate) skip_existing: bool,
    /// Write an animation's frames only when every one has rendered (set by `watch`, so
    /// that an edit failing at a later frame leaves the whole sequence as it was).
    #[arg(skip)]
    pub(crate) whole_revisions: bool,
    /// Render the chunk of frames picked by the task index in this environment variable
    /// (`SLURM_ARRAY_TASK_ID`, `JOB_COMPLETION_INDEX`, …): task I renders frames I·K to
    /// I·K + K − 1 of the selection, K being `--chunk`.
    #[arg(long, value_name = "VAR")]
    frame_index_from: Option<String>,
    /// Frames per task with `--frame-index-from`.
    #[arg(long, value_name = "K", default_value = "1", requires = "frame_index_from",
          value_parser = clap::value_parser!(u32).range(1..=MAX_FRAMES as i64))]
    chunk: u32,
    #[command(flatten)]
    messages: Messages,
    #[command(flatten)]
    pub(crate) params: Params,
}

/// A relative error in (0, 1].
fn parse_noise(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(e) if e > 0.0 && e <= 1.0 => Ok(e),
        _ => Err(format!("`{s}` is not a relative error: give a number greater than 0 and at most 1, like 0.01")),
    }
}

/// `8` or `16`.
fn parse_bit_depth(s: &str) -> Result<BitDepth, String> {
    match s.trim() {
        "8" => Ok(BitDepth::Eight),
        "16" => Ok(BitDepth::Sixteen),
        other => Err(format!("`{other}` bits per channel: a PNG here has 8 or 16")),
    }
}

/// `X0,Y0,X1,Y1`: four integers, a non-empty rectangle (checked against the image later).
fn parse_region(s: &str) -> Result<[u32; 4], String> {
    let numbers: Vec<u32> = s
        .split(',')
        .map(|n| n.trim().parse::<u32>().map_err(|_| format!("`{n}` is not a pixel coordinate")))
        .collect::<Result<_, _>>()?;
    let [x0, y0, x1, y1] = numbers[..] else {
        return Err(format!("expected X0,Y0,X1,Y1 (four numbers), got {}", numbers.len()));
    };
    if x0 >= x1 || y0 >= y1 {
        return Err(format!("the region {x0}..{x1} × {y0}..{y1} is empty (ends are exclusive)"));
    }
    Ok([x0, y0, x1, y1])
}

/// `I/N` with `0 ≤ I < N`.
fn parse_tile(s: &str) -> Result<(u32, u32), String> {
    parse_one_of(s, "band")
}

/// `I/N` with `I < N`: one of `N` numbered things (bands, passes) named `what`.
fn parse_one_of(s: &str, what: &str) -> Result<(u32, u32), String> {
    let (i, n) = s.split_once('/').ok_or_else(|| format!("expected I/N, like 0/4, got `{s}`"))?;
    let i: u32 = i.trim().parse().map_err(|_| format!("`{i}` is not a {what} number"))?;
    let n: u32 = n.trim().parse().map_err(|_| format!("`{n}` is not a number of {what}s"))?;
    if n == 0 || i >= n {
        return Err(format!("{what} {i} of {n}: {what}s are numbered 0 to N − 1"));
    }
    Ok((i, n))
}

fn parse_pass(s: &str) -> Result<(u32, u32), String> {
    parse_one_of(s, "pass")
}

fn parse_epsilon(s: &str) -> Result<f64, String> {
    let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if EPSILON_RANGE.admits(x) {
        Ok(x)
    } else {
        Err(format!("must be {} (f32 cannot resolve less than 1e-6)", EPSILON_RANGE.rule(false)))
    }
}

fn parse_positive(s: &str) -> Result<f64, String> {
    let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if x > 0.0 && x <= scnc::check::MAX_REACH {
        Ok(x)
    } else {
        Err("must be greater than 0 and at most 1e15 (the renderable range)".into())
    }
}

pub(crate) fn render_cmd(args: RenderArgs) -> ExitCode {
    // Interrupted, nothing is written: the shell's 128 + SIGINT.
    let pool = match args.checked_pool(130) {
        Ok(p) => p,
        Err(code) => return code,
    };
    match render_once(&args, &pool).result {
        Ok(()) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}

impl RenderArgs {
    /// Applies the command line's overrides and `--tolerance` to the scene, and says which
    /// back-end renders its shapes and which part of the image to render (`None`: all);
    /// an image too large or a part outside it is a usage error.
    fn apply(&self, scene: &mut scnc::ir::Scene) -> Result<(scnc::world::Mode, Option<PixelRect>), ExitCode> {
        let s = &mut scene.settings;
        s.width = self.width.unwrap_or(s.width);
        s.height = self.height.unwrap_or(s.height);
        s.epsilon = self.epsilon.unwrap_or(s.epsilon);
        s.max_steps = self.max_steps.unwrap_or(s.max_steps);
        s.max_distance = self.max_distance.unwrap_or(s.max_distance);
        s.depth = self.depth.unwrap_or(s.depth);
        s.samples = self.samples.unwrap_or(s.samples);
        s.noise = self.noise.or(s.noise);
        if s.width as u64 * s.height as u64 > MAX_PIXELS {
            return Err(usage_error(&format!("{}×{} is too large: at most {} pixels", s.width, s.height, MAX_PIXELS)));
        }
        let part = self.part(s.width, s.height).map_err(|e| usage_error(&e))?;
        let mut detail = self.meshing.detail;
        if let Some(tol) = self.accuracy.tolerance {
            let picked = match self.geometry {
                GeometryKind::Sdf => {
                    scene.settings.epsilon = scnc::study::tolerance::sdf_epsilon(scene, tol);
                    format!("epsilon {:.3e}", scene.settings.epsilon)
                }
                GeometryKind::Mesh => {
                    detail = scnc::study::tolerance::mesh_detail(scene, tol);
                    detail.describe()
                }
            };
            let _ = writeln!(std::io::stderr(), "tolerance {tol}: picked {picked}");
        }
        let mode = match self.geometry {
            GeometryKind::Sdf => scnc::world::Mode::Sdf,
            GeometryKind::Mesh => scnc::world::Mode::Mesh(detail),
        };
        Ok((mode, part))
    }

    /// The pass `--pass`, or `--pass-index-from` with `--passes`, asks for, if any.
    fn pass(&self) -> Result<Option<(u32, u32)>, String> {
        let (Some(var), Some(n)) = (&self.pass_index_from, self.passes) else {
            return Ok(self.pass);
        };
        let value =
            std::env::var(var).map_err(|_| format!("--pass-index-from {var}: the variable `{var}` is not set"))?;
        match value.trim().parse::<u32>() {
            Ok(i) if i < n => Ok(Some((i, n))),
            Ok(i) => Err(format!("--pass-index-from {var}: task {i} of {n} passes (they are numbered 0 to {})", n - 1)),
            Err(_) => Err(format!("--pass-index-from {var}: `{value}` is not a task index (a whole number from 0)")),
        }
    }

    /// The region `--region` or `--tile` asks for in a `width × height` image, if any;
    /// an error when it does not fit.
    fn part(&self, width: u32, height: u32) -> Result<Option<PixelRect>, String> {
        if let Some([x0, y0, x1, y1]) = self.region {
            if x1 > width || y1 > height {
                return Err(format!("the region {x0}..{x1} × {y0}..{y1} is outside the {width}×{height} image"));
            }
            return Ok(Some(PixelRect { x0, y0, x1, y1 }));
        }
        match self.tile {
            Some((_, n)) if n > height => Err(format!("{n} bands of rows in an image {height} rows high")),
            Some((i, n)) => Ok(Some(PixelRect::band(i, n, width, height))),
            None => Ok(None),
        }
    }

    /// The worker pool, once the output path is known to be writable and Ctrl-C ends the
    /// process with `interrupted` (leaving no partial output): what `render` and `watch`
    /// both need before any work.
    pub(crate) fn checked_pool(&self, interrupted: i32) -> Result<rayon::ThreadPool, ExitCode> {
        // A frame sequence gets its directory made, as Blender's output path does: an
        // animation is written into a directory of its own.
        if is_pattern(&self.output) {
            if let Some(dir) = self.output.parent().filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
                std::fs::create_dir_all(dir).map_err(|e| {
                    usage_error(&format!("cannot create `{}` for the frames: {}", dir.display(), e.kind()))
                })?;
            }
        }
        let pass = self.pass.is_some() || self.pass_index_from.is_some();
        if pass != is_pass(&self.output) {
            return Err(usage_error(if pass {
                "a pass is written as exact sums to a `.scnpass` file, for `scnc merge`"
            } else {
                "a `.scnpass` file holds a pass of samples: give `--pass I/N`"
            }));
        }
        if !is_pass(&self.output) {
            check_image_output(&self.output).map_err(|e| usage_error(&e))?;
        } else {
            super::files::check_output_as(&self.output, "a file name ending in `.scnpass`")
                .map_err(|e| usage_error(&e))?;
        }
        if is_exr(&self.output) && (self.region.is_some() || self.tile.is_some()) {
            return Err(usage_error("a tile or band of an image is written as a PNG part: give a `.png` file name"));
        }
        if let Err(e) = stop_on_interrupt(interrupted) {
            let _ = writeln!(std::io::stderr(), "warning: {e}");
        }
        self.workers.pool().map_err(|e| usage_error(&e))
    }
}

/// One render: the files it read (for `watch`), and whether the image was written
/// (the exit code otherwise, after the reason was printed).
pub(crate) struct Attempt {
    pub(crate) files: Vec<PathBuf>,
    pub(crate) result: Result<(), ExitCode>,
}

pub(crate) fn render_once(args: &RenderArgs, pool: &rayon::ThreadPool) -> Attempt {
    let Some(compiled) = compile(&args.file, args.messages.message_format, &args.params) else {
        return Attempt { files: vec![args.file.clone()], result: Err(ExitCode::from(1)) };
    };
    let files: Vec<PathBuf> = compiled.map.files().map(|(_, f)| f.path.clone()).collect();
    let result = render_compiled(args, pool, compiled);
    Attempt { files, result }
}

fn render_compiled(args: &RenderArgs, pool: &rayon::ThreadPool, mut compiled: Compiled) -> Result<(), ExitCode> {
    if report(&compiled, args.messages.message_format) {
        return Err(ExitCode::from(1));
    }
    let Some(first) = compiled.scene.take() else {
        return Err(ExitCode::from(1));
    };
    let declared = first.settings.clone();
    let choice =
        FrameChoice { frames: args.frames.clone(), index_from: args.frame_index_from.as_deref(), chunk: args.chunk };
    let frames = choice.select(declared.frames, &|var| std::env::var(var).ok()).map_err(|e| usage_error(&e))?;
    if frames.len() > 1 && !is_pattern(&args.output) {
        return Err(usage_error(&format!(
            "{} frames cannot all be written to `{}`: put `#` in the file name for the frame number, \
             like `frame-####.png`",
            frames.len(),
            args.output.display()
        )));
    }
    let mut first = Some(first);
    let mut sequence = Sequence {
        cache: scnc::world::FrameCache::default(),
        shown: compiled.diagnostics.iter().map(diagnostic_key).collect(),
    };
    // With `whole_revisions`, frames are staged beside their outputs and renamed into
    // place only once every frame has rendered: an error at a later frame leaves the
    // whole sequence as it was, never frames of two revisions.
    let together = args.whole_revisions && frames.len() > 1;
    let mut staged: Vec<(tempfile::NamedTempFile, PathBuf, super::files::Pending)> = Vec::new();
    for number in frames {
        let output = frame_path(&args.output, number);
        if args.skip_existing && output.exists() {
            let _ = writeln!(std::io::stderr(), "skipped {}: it exists", output.display());
            continue;
        }
        let scene = match first.take().filter(|_| number == 0) {
            Some(scene) => scene,
            None => {
                evaluate_frame(&mut compiled, number, &declared, &mut sequence.shown, args.messages.message_format)?
            }
        };
        if together {
            let target = super::files::link_target(&output);
            let stage = super::files::stage_beside(&target, ".png.tmp").map_err(|e| {
                let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(&output, &e));
                ExitCode::from(1)
            })?;
            let pending = super::files::Pending::new(stage.path());
            render_scene(args, pool, &compiled.map, scene, stage.path(), &output, &mut sequence)?;
            staged.push((stage, target, pending));
        } else {
            render_scene(args, pool, &compiled.map, scene, &output, &output, &mut sequence)?;
        }
    }
    let count = staged.len();
    for (stage, target, _pending) in staged {
        stage.persist(&target).map_err(|e| {
            let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(&target, &e.error));
            ExitCode::from(1)
        })?;
    }
    if together {
        let _ = writeln!(std::io::stderr(), "wrote {count} frames of {}, all of this revision", args.output.display());
    }
    Ok(())
}

/// What the frames of one render share.
struct Sequence {
    /// Each frame's lowered objects, for the next to reuse.
    cache: scnc::world::FrameCache,
    /// The diagnostics shown so far ([`diagnostic_key`]): a later frame shows only new ones.
    shown: HashSet<DiagnosticKey>,
}

/// What makes a diagnostic the same one at another frame: code, place and message, as
/// the checker tells repeats apart.
type DiagnosticKey = (&'static str, scnc::span::Span, String);

fn diagnostic_key(d: &scnc::diag::Diagnostic) -> DiagnosticKey {
    (d.code, d.span(), d.message.clone())
}

/// Frame `number` of the animation `declared` (frame 0's settings) evaluated, its new
/// diagnostics printed with the frame named; the exit code when it has errors.
fn evaluate_frame(
    compiled: &mut Compiled,
    number: u32,
    declared: &scnc::ir::Settings,
    seen: &mut HashSet<DiagnosticKey>,
    format: MessageFormat,
) -> Result<scnc::ir::Scene, ExitCode> {
    let (scene, diagnostics) = scnc::with_big_stack(|| compiled.frame(number, declared, &FsLoader))
        .unwrap_or_else(|e| (None, vec![e.diagnostic()]));
    let clock = Time::of(number, declared).clock;
    let fresh: Vec<_> = diagnostics
        .into_iter()
        .filter(|d| seen.insert(diagnostic_key(d)))
        .map(|d| d.with_note(format!("at frame {number} (clock = {clock})")))
        .collect();
    if super::report_in(&compiled.map, &fresh, format) {
        return Err(ExitCode::from(1));
    }
    scene.ok_or(ExitCode::from(1))
}

/// Lowers and renders one evaluated scene (a still or one frame) to `output`.
///
/// Long because it is the render's sequence (lower, trace, report, write), each step with
/// its own error.
fn render_scene(
    args: &RenderArgs,
    pool: &rayon::ThreadPool,
    map: &scnc::source::SourceMap,
    mut scene: scnc::ir::Scene,
    output: &Path,
    shown: &Path,
    sequence: &mut Sequence,
) -> Result<(), ExitCode> {
    let (mode, part) = args.apply(&mut scene)?;
    let started = Instant::now();
    let effects = match args.effects {
        EffectsArg::Derived => scnc::render::effects::derive(&scene),
        EffectsArg::All => scnc::render::effects::Effects::all(&scene),
    };
    let building = Progress::new(scnc::world::lowering_steps(&scene), "steps", "lowering");
    let lowered = pool.install(|| {
        let cache = &mut sequence.cache;
        scnc::world::prepare_reusing(&scene, effects, mode, &Reading, args.meshing.memory_limit, cache, &|| {
            building.step()
        })
    });
    building.finish();
    let (mut frame, geometry) = match lowered {
        Ok(g) => {
            let fresh: Vec<_> =
                g.1.warnings.iter().filter(|d| sequence.shown.insert(diagnostic_key(d))).cloned().collect();
            super::report_in(map, &fresh, args.messages.message_format);
            g
        }
        Err(d) => {
            super::report_in(map, &[d], args.messages.message_format);
            return Err(ExitCode::from(1));
        }
    };
    // OpenEXR keeps the light: linear float radiance, never clamped or encoded.
    frame.bit_depth = if is_exr(output) { scnc::render::BitDepth::Float } else { args.bit_depth };
    let asked = args.pass().map_err(|e| usage_error(&e))?;
    let pass = match asked {
        None => None,
        Some((i, n)) => {
            let samples = frame.samples;
            let Some(t) = &mut frame.transport else {
                let _ = writeln!(
                    std::io::stderr(),
                    "error: `--pass` splits light transport's samples, and this scene is not lit by light transport \
                     (it has no glowing material, area or environment light, or `bounces`)"
                );
                return Err(ExitCode::from(2));
            };
            let Some((first, count)) = super::passes::range(i, n, samples) else {
                let _ = writeln!(std::io::stderr(), "error: pass {i} of {n} of {samples} samples holds none");
                return Err(ExitCode::from(2));
            };
            t.first_sample = first;
            frame.samples = count;
            frame.bit_depth = scnc::render::BitDepth::Sums;
            let info = super::passes::PassInfo {
                width: frame.width,
                height: frame.height,
                samples,
                first,
                count,
                exposure: t.exposure,
                color: scene.settings.color.name().to_string(),
            };
            Some(info)
        }
    };
    let lowered = started.elapsed();
    let region = part.unwrap_or(PixelRect::full(frame.width, frame.height));
    let progress = Progress::new(region.height() as u64, "rows", "rendering");
    let (image, counters) =
        pool.install(|| scnc::render::render_region(&geometry, &frame, region, &|| progress.step()));
    progress.finish();
    let traced = started.elapsed() - lowered;
    let written = match part {
        Some(region) => write_part_png(output, frame.width, frame.height, region, &image),
        None if pass.is_some() => super::passes::write_pass(output, pass.as_ref().expect("a pass"), &image),
        None if is_exr(output) => write_exr(output, &image),
        // An animation's frames carry its rate, which `scnc encode` reads.
        None if scene.settings.frames > 1 => write_png(output, &image, &[(FPS_KEY, scene.settings.fps.to_string())]),
        None => write_png(output, &image, &[]),
    };
    if let Err(e) = written {
        let _ = writeln!(std::io::stderr(), "error: {}", cannot_write(shown, &e));
        return Err(ExitCode::from(1));
    }
    let secs = traced.as_secs_f64();
    let mut err = std::io::stderr().lock();
    let size = match part {
        Some(r) => format!("pixels {}..{} × {}..{} of {}×{}", r.x0, r.x1, r.y0, r.y1, frame.width, frame.height),
        None => format!("{}×{}", image.width, image.height),
    };
    let _ = writeln!(
        err,
        "rendered {}: {size} in {:.3} s ({:.2} M rays/s, {} thread{})",
        shown.display(),
        started.elapsed().as_secs_f64(),
        counters.rays() as f64 / secs.max(1e-9) / 1e6,
        pool.current_num_threads(),
        if pool.current_num_threads() == 1 { "" } else { "s" }
    );
    if args.stats {
        let _ = writeln!(err, "{}", frame.effects);
        let _ = write!(err, "{}", super::stats::stats_text(&counters, &geometry, map, lowered.as_secs_f64(), secs));
        if scene.settings.frames > 1 {
            let _ = writeln!(
                err,
                "  animation       {} of {} objects reused from the previous frame (not lowered again)",
                sequence.cache.reused,
                geometry.len()
            );
        }
    }
    Ok(())
}
