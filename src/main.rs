//! The `scnc` command line: the only code that reads arguments, prints, or exits.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand, ValueEnum};

use scnc::diag::Diagnostic;
use scnc::source::{FsLoader, Loader};
use scnc::Compiled;

#[derive(Parser)]
#[command(name = "scnc", version, about = "Compile and render .scn scene files")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MessageFormat {
    /// Rendered for people, with source excerpts.
    Human,
    /// One JSON object per line, for editors and tests.
    Json,
}

#[derive(Subcommand)]
enum Command {
    /// Check files for errors without rendering (exit 0 clean, 1 on errors).
    Check {
        /// The scene files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// How to print diagnostics.
        #[arg(long, value_enum, default_value = "human")]
        message_format: MessageFormat,
    },
    /// Render a scene to an image (written whole or not at all).
    Render(RenderArgs),
    /// Render, then render again whenever the scene or a file it includes changes;
    /// on errors, print them and keep the last good image. Ctrl-C ends it.
    Watch(RenderArgs),
    /// Render a scene across a ladder of accuracy settings for both back-ends and write
    /// time, work, memory and error for each to DIR/sweep.csv and DIR/sweep.md.
    Sweep(SweepArgs),
    /// Run a Language Server Protocol server on stdin/stdout, for editors.
    Lsp,
    /// Format files in place in the canonical layout (comments and blank lines kept).
    Fmt {
        /// The scene files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Change nothing; list the files that would change and exit 1 if there are any.
        #[arg(long)]
        check: bool,
    },
    /// Print the evaluated scene IR.
    Ir {
        /// The scene file.
        file: PathBuf,
        /// How to print diagnostics.
        #[arg(long, value_enum, default_value = "human")]
        message_format: MessageFormat,
    },
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum GeometryKind {
    /// Sphere-trace signed distance functions.
    Sdf,
    /// Tessellate every shape into triangles, traced through BVHs.
    Mesh,
}

fn parse_detail(s: &str) -> Result<scnc::mesh::Detail, String> {
    match s {
        "low" => Ok(scnc::mesh::Detail::Low),
        "high" => Ok(scnc::mesh::Detail::High),
        n => match n.parse::<u32>() {
            Ok(n) if (3..=2048).contains(&n) => Ok(scnc::mesh::Detail::N(n)),
            _ => Err("expected `low`, `high` or a number of rings from 3 to 2048".into()),
        },
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum EffectsArg {
    /// Build the tracer with the effects the scene calls for.
    Derived,
    /// Build the general tracer with every effect.
    All,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// The scene file.
    file: PathBuf,
    /// Output image (PNG).
    #[arg(short, long)]
    output: PathBuf,
    /// Image width in pixels (overrides the scene's `render`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene's `render`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: Option<u32>,
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024))]
    threads: Option<u16>,
    /// Sphere-tracing hit threshold, relative to distance from the camera.
    #[arg(long, value_parser = parse_epsilon)]
    epsilon: Option<f64>,
    /// Sphere-tracing step budget per ray.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    max_steps: Option<u32>,
    /// Far limit of every ray.
    #[arg(long, value_parser = parse_positive)]
    max_distance: Option<f64>,
    /// Reflection recursion depth.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
    depth: Option<u32>,
    /// Samples per pixel (antialiasing).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=256))]
    samples: Option<u32>,
    /// Pick the cheapest setting expected to keep geometric error under this many world
    /// units, or under a pixel's footprint with `pixel` (sets epsilon, or detail with meshes).
    #[arg(long, conflicts_with_all = ["epsilon", "detail"])]
    tolerance: Option<scnc::tolerance::Tolerance>,
    /// Geometry back-end for shapes (explicit meshes are always meshes).
    #[arg(long, value_enum, default_value = "sdf")]
    geometry: GeometryKind,
    /// Tessellation detail with `--geometry mesh`: `low` (7 rings, 10-point circles),
    /// `high` (14 rings, 50-point circles) or N (N rings, 2N-point circles).
    #[arg(long, value_parser = parse_detail, default_value = "high")]
    detail: scnc::mesh::Detail,
    /// Print the effect set, ray counts, work per ray and memory.
    #[arg(long)]
    stats: bool,
    /// Which tracer to build: `derived` (only the effects the scene calls for) or `all`
    /// (every effect compiled in; a debugging and benchmarking aid, same image).
    #[arg(long, value_enum, default_value = "derived")]
    effects: EffectsArg,
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value = "human")]
    message_format: MessageFormat,
}

#[derive(clap::Args)]
struct SweepArgs {
    /// The scene file.
    file: PathBuf,
    /// Directory for sweep.csv and sweep.md (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Image width for the sweep.
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..=4096))]
    width: u32,
    /// Image height for the sweep.
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..=4096))]
    height: u32,
    /// Timed renders per setting (after one warm-up); the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u16).range(1..=100))]
    runs: u16,
    /// Two settings per back-end instead of the full ladder.
    #[arg(long)]
    quick: bool,
    /// Sweep only the settings `render --tolerance` would pick (world units or `pixel`),
    /// to check that they hold.
    #[arg(long, conflicts_with = "quick")]
    tolerance: Option<scnc::tolerance::Tolerance>,
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value = "human")]
    message_format: MessageFormat,
}

fn sweep_cmd(args: SweepArgs) -> ExitCode {
    if let Err(e) = std::fs::create_dir_all(&args.out) {
        return usage_error(&format!("cannot create `{}`: {e}", args.out.display()));
    }
    let Some(compiled) = compile(&args.file, args.message_format) else { return ExitCode::from(1) };
    if report(&compiled, args.message_format) {
        return ExitCode::from(1);
    }
    let Some(mut scene) = compiled.scene else { return ExitCode::from(1) };
    scene.settings.width = args.width;
    scene.settings.height = args.height;
    let ladder = match args.tolerance {
        Some(tol) => scnc::sweep::picked(&scene, tol),
        None => scnc::sweep::ladder(args.quick),
    };
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(ladder.len() as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} settings, {msg}") {
            bar.set_style(style);
        }
        bar
    });
    let progress = |s: &scnc::sweep::Setting| {
        if let Some(bar) = &bar {
            bar.set_message(format!("{} {}", s.backend(), s.label()));
            bar.inc(1);
        }
    };
    let rows = match scnc::sweep::run(&scene, &ladder, args.runs as usize, &FsLoader, &progress) {
        Ok(rows) => rows,
        Err(d) => {
            let c = Compiled { map: compiled.map, scene: None, diagnostics: vec![d] };
            report(&c, args.message_format);
            return ExitCode::from(1);
        }
    };
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let title = format!("{} at {}×{}", args.file.display(), args.width, args.height);
    for (name, text) in [("sweep.csv", scnc::sweep::csv(&rows)), ("sweep.md", scnc::sweep::markdown(&rows, &title))] {
        let path = args.out.join(name);
        if let Err(e) = write_atomic(&path, text.as_bytes()) {
            let _ = writeln!(std::io::stderr(), "error: cannot write `{}`: {e}", path.display());
            return ExitCode::from(1);
        }
    }
    for (name, axis) in
        [("time-vs-error.png", scnc::chart::Axis::Time), ("memory-vs-error.png", scnc::chart::Axis::Memory)]
    {
        let path = args.out.join(name);
        let written = scnc::chart::error_chart(&rows, axis, &title)
            .map_err(std::io::Error::other)
            .and_then(|img| write_png(&path, &img));
        if let Err(e) = written {
            let _ = writeln!(std::io::stderr(), "error: cannot write `{}`: {e}", path.display());
            return ExitCode::from(1);
        }
    }
    let _ = writeln!(std::io::stderr(), "swept {} settings: {}", rows.len(), args.out.join("sweep.md").display());
    ExitCode::SUCCESS
}

/// Writes bytes to a temporary file beside `path`, then renames it into place.
fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new().prefix(".scnc-").suffix(".tmp").tempfile_in(dir)?;
    // Replacing a file keeps its permissions (a temporary file is private by default).
    if let Ok(meta) = std::fs::metadata(path) {
        tmp.as_file().set_permissions(meta.permissions())?;
    }
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Formats each file in place, or with `check` lists those that would change.
fn fmt_cmd(files: &[PathBuf], check: bool) -> ExitCode {
    let mut failed = false;
    let mut unformatted = false;
    for path in files {
        let name = path.display().to_string();
        let text = match FsLoader.read(path) {
            Ok(text) => text,
            Err(e) => {
                let _ = writeln!(std::io::stderr(), "error: cannot read `{name}`: {}", scnc::source::io_reason(&e));
                failed = true;
                continue;
            }
        };
        let formatted = match scnc::fmt::format(&text) {
            Ok(f) => f,
            Err(diagnostics) => {
                let mut map = scnc::source::SourceMap::new();
                let _ = map.add(&name, path, text);
                report(&Compiled { map, scene: None, diagnostics }, MessageFormat::Human);
                let _ = writeln!(std::io::stderr(), "error: `{name}` was not formatted: it has syntax errors");
                failed = true;
                continue;
            }
        };
        if formatted == text {
            continue;
        }
        if check {
            let _ = writeln!(std::io::stdout(), "{name}");
            unformatted = true;
        } else if let Err(e) = write_atomic(path, formatted.as_bytes()) {
            let _ = writeln!(std::io::stderr(), "error: cannot write `{name}`: {e}");
            failed = true;
        }
    }
    if failed || unformatted {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

fn parse_epsilon(s: &str) -> Result<f64, String> {
    let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if x > 0.0 && x < 1.0 {
        Ok(x)
    } else {
        Err("must be between 0 and 1 (exclusive)".into())
    }
}

fn parse_positive(s: &str) -> Result<f64, String> {
    let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if x > 0.0 && x.is_finite() {
        Ok(x)
    } else {
        Err("must be a finite number greater than 0".into())
    }
}

/// Reads and compiles a file. A file that cannot be read has no source to point into, so
/// it is reported here, in the requested format, and `None` returned (exit 1).
fn compile(path: &Path, format: MessageFormat) -> Option<Compiled> {
    let name = path.display().to_string();
    match FsLoader.read(path) {
        Ok(text) => Some(scnc::with_big_stack(|| scnc::compile_source(&name, path, text, &FsLoader))),
        Err(e) => {
            let code = scnc::diag::codes::INCLUDE_READ;
            let message = format!("cannot read `{name}`: {}", scnc::source::io_reason(&e));
            let line = match format {
                MessageFormat::Human => format!("error[{code}]: {message}"),
                MessageFormat::Json => serde_json::json!({
                    "severity": "error", "code": code, "message": message,
                    "span": { "file": name }, "related": [], "notes": [], "hints": [],
                })
                .to_string(),
            };
            let _ = writeln!(std::io::stderr(), "{line}");
            None
        }
    }
}

/// Prints diagnostics to stderr; returns whether any was an error.
fn report(c: &Compiled, format: MessageFormat) -> bool {
    let color = std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none();
    let mut err = std::io::stderr().lock();
    for d in &c.diagnostics {
        let text = match format {
            MessageFormat::Human => d.render(&c.map, color),
            MessageFormat::Json => format!("{}\n", d.to_json(&c.map)),
        };
        let _ = err.write_all(text.as_bytes());
    }
    c.diagnostics.iter().any(Diagnostic::is_error)
}

/// A usage problem found after argument parsing: printed like clap's, exit 2.
fn usage_error(msg: &str) -> ExitCode {
    let _ = writeln!(std::io::stderr(), "error: {msg}");
    ExitCode::from(2)
}

/// The usage error for an output path scnc cannot write a PNG to.
fn check_output(path: &Path) -> Result<(), String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if ext.as_deref() != Some("png") {
        return Err(format!("cannot write `{}`: scnc writes PNG images; try a `.png` file name", path.display()));
    }
    let out_dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !out_dir.is_dir() {
        return Err(format!("cannot write `{}`: the directory `{}` does not exist", path.display(), out_dir.display()));
    }
    Ok(())
}

fn worker_pool(threads: Option<u16>) -> Result<rayon::ThreadPool, String> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        pool = pool.num_threads(n as usize);
    }
    pool.build().map_err(|e| format!("cannot start worker threads: {e}"))
}

fn render_cmd(args: RenderArgs) -> ExitCode {
    if let Err(e) = check_output(&args.output) {
        return usage_error(&e);
    }
    let pool = match worker_pool(args.threads) {
        Ok(p) => p,
        Err(e) => return usage_error(&e),
    };
    match render_once(&args, &pool).result {
        Ok(()) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}

/// What wakes `watch` up.
enum Wake {
    /// These paths changed.
    Changed(Vec<PathBuf>),
    /// Ctrl-C.
    Stop,
}

/// How long `watch` waits for more changes before rendering, so one save (often
/// several file-system events) renders once.
const DEBOUNCE: std::time::Duration = std::time::Duration::from_millis(150);

fn watch_cmd(args: RenderArgs) -> ExitCode {
    use notify::Watcher as _;
    if let Err(e) = check_output(&args.output) {
        return usage_error(&e);
    }
    let pool = match worker_pool(args.threads) {
        Ok(p) => p,
        Err(e) => return usage_error(&e),
    };
    let (tx, rx) = std::sync::mpsc::channel();
    let stop = tx.clone();
    // The handler only wakes the loop, so a render in progress finishes and its output
    // is written whole (or not at all) before the process ends.
    if let Err(e) = ctrlc::set_handler(move || {
        let _ = stop.send(Wake::Stop);
    }) {
        let _ = writeln!(std::io::stderr(), "warning: Ctrl-C will stop watch abruptly: {e}");
    }
    let watcher = notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
        if let Ok(event) = event {
            if !event.kind.is_access() {
                let _ = tx.send(Wake::Changed(event.paths));
            }
        }
    });
    let mut watcher = match watcher {
        Ok(w) => w,
        Err(e) => return usage_error(&format!("cannot watch files: {e}")),
    };
    let mut watched_dirs: Vec<PathBuf> = Vec::new();
    loop {
        let attempt = render_once(&args, &pool);
        if attempt.result.is_err() {
            let _ = writeln!(
                std::io::stderr(),
                "not rendered; `{}` keeps the last good image. Watching for changes…",
                args.output.display()
            );
        }
        // Editors save by replacing files, which ends a watch on the file itself, so
        // the directories are watched and events filtered by path.
        let files: Vec<PathBuf> = attempt.files.iter().filter_map(|f| std::path::absolute(f).ok()).collect();
        let mut dirs: Vec<PathBuf> = files.iter().filter_map(|f| f.parent().map(Path::to_path_buf)).collect();
        dirs.sort();
        dirs.dedup();
        for dir in watched_dirs.iter().filter(|d| !dirs.contains(d)) {
            let _ = watcher.unwatch(dir);
        }
        for dir in dirs.iter().filter(|d| !watched_dirs.contains(d)) {
            if let Err(e) = watcher.watch(dir, notify::RecursiveMode::NonRecursive) {
                let _ = writeln!(std::io::stderr(), "warning: cannot watch `{}`: {e}", dir.display());
            }
        }
        watched_dirs = dirs;
        // Wait for a change to one of the files, then for the burst of events to end.
        loop {
            match rx.recv() {
                Ok(Wake::Changed(paths)) if paths.iter().any(|p| files.contains(p)) => break,
                Ok(Wake::Changed(_)) => {}
                Ok(Wake::Stop) | Err(_) => return ExitCode::SUCCESS,
            }
        }
        loop {
            match rx.recv_timeout(DEBOUNCE) {
                Ok(Wake::Changed(_)) => {}
                Ok(Wake::Stop) | Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => return ExitCode::SUCCESS,
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => break,
            }
        }
    }
}

/// One render: the files it read (for `watch`), and whether the image was written
/// (the exit code otherwise, after the reason was printed).
struct Attempt {
    files: Vec<PathBuf>,
    result: Result<(), ExitCode>,
}

fn render_once(args: &RenderArgs, pool: &rayon::ThreadPool) -> Attempt {
    let Some(compiled) = compile(&args.file, args.message_format) else {
        return Attempt { files: vec![args.file.clone()], result: Err(ExitCode::from(1)) };
    };
    let files: Vec<PathBuf> = compiled.map.files().map(|(_, f)| f.path.clone()).collect();
    let result = render_compiled(args, pool, compiled);
    Attempt { files, result }
}

fn render_compiled(args: &RenderArgs, pool: &rayon::ThreadPool, compiled: Compiled) -> Result<(), ExitCode> {
    if report(&compiled, args.message_format) {
        return Err(ExitCode::from(1));
    }
    let Some(mut scene) = compiled.scene else {
        return Err(ExitCode::from(1));
    };
    let s = &mut scene.settings;
    s.width = args.width.unwrap_or(s.width);
    s.height = args.height.unwrap_or(s.height);
    s.epsilon = args.epsilon.unwrap_or(s.epsilon);
    s.max_steps = args.max_steps.unwrap_or(s.max_steps);
    s.max_distance = args.max_distance.unwrap_or(s.max_distance);
    s.depth = args.depth.unwrap_or(s.depth);
    s.samples = args.samples.unwrap_or(s.samples);
    if s.width as u64 * s.height as u64 > scnc::check::construct::MAX_PIXELS {
        return Err(usage_error(&format!(
            "{}×{} is too large: at most {} pixels",
            s.width,
            s.height,
            scnc::check::construct::MAX_PIXELS
        )));
    }
    let mut detail = args.detail;
    if let Some(tol) = args.tolerance {
        match args.geometry {
            GeometryKind::Sdf => scene.settings.epsilon = scnc::tolerance::sdf_epsilon(&scene, tol),
            GeometryKind::Mesh => detail = scnc::tolerance::mesh_detail(&scene, tol),
        }
        let picked = match args.geometry {
            GeometryKind::Sdf => format!("epsilon {:.3e}", scene.settings.epsilon),
            GeometryKind::Mesh => format!("detail {}", detail.rings()),
        };
        let _ = writeln!(std::io::stderr(), "tolerance {tol:?}: picked {picked}");
    }
    let mode = match args.geometry {
        GeometryKind::Sdf => scnc::world::Mode::Sdf,
        GeometryKind::Mesh => scnc::world::Mode::Mesh(detail),
    };
    let started = Instant::now();
    let effects = match args.effects {
        EffectsArg::Derived => scnc::effects::derive(&scene),
        EffectsArg::All => scnc::effects::Effects::all(&scene),
    };
    let lowered = pool.install(|| scnc::world::prepare(&scene, effects, mode, &FsLoader));
    let (frame, geometry) = match lowered {
        Ok(g) => g,
        Err(d) => {
            let c = Compiled { map: compiled.map, scene: None, diagnostics: vec![d] };
            report(&c, args.message_format);
            return Err(ExitCode::from(1));
        }
    };
    let lowered = started.elapsed();
    let progress = Progress::new(frame.height);
    let (image, counters) = pool.install(|| scnc::render::render(&geometry, &frame, &|| progress.row()));
    progress.finish();
    let traced = started.elapsed() - lowered;
    if let Err(e) = write_png(&args.output, &image) {
        let _ = writeln!(std::io::stderr(), "error: cannot write `{}`: {e}", args.output.display());
        return Err(ExitCode::from(1));
    }
    let secs = traced.as_secs_f64();
    let mut err = std::io::stderr().lock();
    let _ = writeln!(
        err,
        "rendered {}: {}×{} in {:.3} s ({:.2} M rays/s, {} threads)",
        args.output.display(),
        image.width,
        image.height,
        started.elapsed().as_secs_f64(),
        counters.rays() as f64 / secs.max(1e-9) / 1e6,
        pool.current_num_threads()
    );
    if args.stats {
        let _ = writeln!(err, "{}", frame.effects);
        let _ = write!(err, "{}", stats_text(&counters, &geometry, &compiled.map, lowered.as_secs_f64(), secs));
    }
    Ok(())
}

fn stats_text(
    c: &scnc::render::Counters,
    g: &scnc::world::World,
    map: &scnc::source::SourceMap,
    lower_s: f64,
    trace_s: f64,
) -> String {
    let mem = g.memory();
    let rays = c.rays().max(1) as f64;
    let mut out = format!(
        "stats:
  time            lower {:.3} s (tessellation and BVH builds), trace {:.3} s
  rays            {} primary, {} shadow, {} reflection, {} occlusion ({} total, {:.2} M/s)
  sdf evaluations {} marching ({:.1} per ray, max {} on one ray), {} for normals and materials
  step budget     {} marches ran out of steps (counted as misses)
  bvh             {} node visits ({:.2} per ray), {} triangle tests ({:.2} per ray)
  memory          {} bytes in total: {} SDF objects with {} bytes of closures, {} bytes of top-level BVH
",
        lower_s,
        trace_s,
        c.primary_rays,
        c.shadow_rays,
        c.reflection_rays,
        c.occlusion_rays,
        c.rays(),
        c.rays() as f64 / trace_s.max(1e-9) / 1e6,
        c.sdf_evals,
        c.sdf_evals as f64 / rays,
        c.max_evals_per_ray,
        c.sdf_shading_evals,
        c.budget_misses,
        c.node_visits,
        c.node_visits as f64 / rays,
        c.triangle_tests,
        c.triangle_tests as f64 / rays,
        mem.total(),
        mem.sdf_objects,
        mem.closure_bytes,
        mem.top_bvh_bytes,
    );
    if !mem.meshes.is_empty() {
        let tri = mem.triangles();
        let bytes: usize = mem.meshes.iter().map(|(_, m)| m.vertex_bytes + m.index_bytes + m.bvh_bytes).sum();
        out.push_str(&format!(
            "  meshes          {} objects, {} triangles, {} bytes ({:.1} bytes per triangle)\n",
            mem.meshes.len(),
            tri,
            bytes,
            bytes as f64 / tri.max(1) as f64
        ));
        for (span, m) in mem.meshes.iter().take(20) {
            let (id, r) = map.local_range(*span);
            let (line, _) = map.line_col(id, r.start);
            out.push_str(&format!(
                "    {}:{line}: {} triangles; vertices {} B, indices {} B, BVH {} B ({} nodes, depth {})\n",
                map.file(id).name,
                m.triangles,
                m.vertex_bytes,
                m.index_bytes,
                m.bvh_bytes,
                m.bvh_nodes,
                m.bvh_depth
            ));
        }
        if mem.meshes.len() > 20 {
            out.push_str(&format!("    … and {} more mesh objects\n", mem.meshes.len() - 20));
        }
    }
    out
}

/// Encodes to a temporary file beside the target, then renames it over the target, so
/// the output is written whole or not at all and an existing file survives any failure.
fn write_png(path: &Path, image: &scnc::render::Image) -> std::io::Result<()> {
    use image::ImageEncoder;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new().prefix(".scnc-").suffix(".png.tmp").tempfile_in(dir)?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file_mut());
        image::codecs::png::PngEncoder::new(&mut w)
            .write_image(&image.pixels, image.width, image.height, image::ExtendedColorType::Rgb8)
            .map_err(std::io::Error::other)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// A progress bar on a terminal, shown only once a render has taken a second.
struct Progress {
    bar: Option<indicatif::ProgressBar>,
    started: Instant,
}

impl Progress {
    fn new(rows: u32) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar =
                indicatif::ProgressBar::with_draw_target(Some(rows as u64), indicatif::ProgressDrawTarget::hidden());
            if let Ok(style) = indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} rows, {eta} left") {
                bar.set_style(style);
            }
            bar
        });
        Progress { bar, started: Instant::now() }
    }

    fn row(&self) {
        if let Some(bar) = &self.bar {
            if bar.is_hidden() && self.started.elapsed().as_secs_f64() > 1.0 {
                bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            }
            bar.inc(1);
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

fn run(cli: Cli) -> ExitCode {
    match cli.command {
        Command::Render(args) => render_cmd(args),
        Command::Watch(args) => watch_cmd(args),
        Command::Sweep(args) => sweep_cmd(args),
        Command::Fmt { files, check } => fmt_cmd(&files, check),
        Command::Lsp => match scnc::lsp::run_stdio() {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                let _ = writeln!(std::io::stderr(), "error: the language server stopped: {e}");
                ExitCode::from(1)
            }
        },
        Command::Check { files, message_format } => {
            let mut failed = false;
            for file in &files {
                failed |= compile(file, message_format).is_none_or(|c| report(&c, message_format));
            }
            if failed {
                ExitCode::from(1)
            } else {
                ExitCode::SUCCESS
            }
        }
        Command::Ir { file, message_format } => {
            let Some(compiled) = compile(&file, message_format) else { return ExitCode::from(1) };
            if report(&compiled, message_format) {
                return ExitCode::from(1);
            }
            if let Some(scene) = &compiled.scene {
                let text = format!("{}{}\n", scnc::ir::dump(scene, &compiled.map), scnc::effects::derive(scene));
                let _ = std::io::stdout().lock().write_all(text.as_bytes());
            }
            ExitCode::SUCCESS
        }
    }
}

fn main() -> ExitCode {
    run(Cli::parse())
}
