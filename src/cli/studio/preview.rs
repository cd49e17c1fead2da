//! Renders for the page: a coarse image first, then the full frame in bands of rows as
//! they finish, streamed; a newer request stops an older one between one 4×4 block of
//! pixels and the next, in the coarse pass, the full frame or the reference. With an
//! accuracy rung, the same view rendered at the finest rung is the reference the error
//! is measured against (`scnc sweep`'s ladder, felt under the hand).
//!
//! The stream is a sequence of messages (see [`super::http::Stream::message`]):
//! `M` the image about to come (JSON), `B` a band of it (`y0`, `rows`, `width` as u32
//! and RGB bytes), `S` the render's statistics, `A` the accuracy against the finest rung,
//! `N` a note, `E` diagnostics that stopped it, `X` overtaken by a newer request,
//! `C` the compiled scene's diagnostics (warnings) and parameters, for the editor and the
//! controls, and `L` lowering begun (`objects`: how many), sent after the scene compiled.
//! An edit asks for nothing else: the text is compiled once, for its image.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use glam::DQuat;

use scnc::check::Overrides;
use scnc::diag::Diagnostic;
use scnc::mesh::Detail;
use scnc::mesh::Wanted;
use scnc::render::{Frame, Image, PixelRect};
use scnc::trace::Counters;
use scnc::world::{Mode, World};

use super::diagnostics::{diagnostics_json, page_range};
use super::files::lock;
use super::http::{Reply, Req, Stream};
use super::Studio;

/// The hit thresholds of the accuracy slider, coarse to fine (the last is the reference).
const SDF_RUNGS: [f64; 6] = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5];
/// Mesh detail (rings) of the accuracy slider, coarse to fine.
const MESH_RUNGS: [u32; 6] = [4, 7, 14, 28, 56, 112];
/// Largest full frame the page renders; a larger scene is previewed at this many pixels.
const MAX_PIXELS: u64 = 1 << 20;
/// Rows per band of the full frame (a multiple of the tracer's 4-row strips).
const BAND_ROWS: u32 = 16;
/// Longest full frame the studio starts, as estimated from the coarse one: past it the
/// preview stays coarse and says so.
const MAX_FULL_SECONDS: f64 = 30.0;
/// A full frame estimated to take longer than this is announced with its estimate.
const SLOW_FULL_SECONDS: f64 = 1.0;
/// A pixel "differs" from the reference past this many steps of 255 in any channel.
const DIFF_THRESHOLD: u8 = 16;

/// The renders of one server.
pub(crate) struct Previews {
    /// Render workers.
    pub(crate) pool: rayon::ThreadPool,
    /// The newest render request: an older one stops at its next band.
    newest: Arc<AtomicU64>,
    /// One render at a time.
    running: Mutex<()>,
    /// The last reference render: its key and image.
    reference: Mutex<Option<(u64, Arc<Image>, f64)>>,
}

impl Previews {
    pub(crate) fn new(pool: rayon::ThreadPool) -> Previews {
        Previews { pool, newest: Arc::new(AtomicU64::new(0)), running: Mutex::new(()), reference: Mutex::new(None) }
    }
}

/// The page's view: an orbit, zoom and pan about the scene camera's `look_at`, which
/// never touches the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct View {
    /// Degrees about the camera's up axis.
    yaw: f64,
    /// Degrees up or down, kept off the poles.
    pitch: f64,
    /// Distance factor (1: the scene's).
    zoom: f64,
    /// Pan along the image's right and up, in units of the distance to `look_at`.
    pan: [f64; 2],
}

impl Default for View {
    /// The scene's own camera.
    fn default() -> View {
        View { yaw: 0.0, pitch: 0.0, zoom: 1.0, pan: [0.0; 2] }
    }
}

impl View {
    /// The view in a request's query (`yaw`, `pitch`, `zoom`, `panx`, `pany`).
    pub(crate) fn from_query(req: &Req) -> View {
        let zoom = req.query_f64("zoom").filter(|z| *z > 1e-3 && *z < 1e3).unwrap_or(1.0);
        let clamp = |k: &str| req.query_f64(k).unwrap_or(0.0).clamp(-1e3, 1e3);
        View { yaw: clamp("yaw"), pitch: clamp("pitch"), zoom, pan: [clamp("panx"), clamp("pany")] }
    }

    /// `camera` seen from this view.
    pub(crate) fn apply(&self, camera: &scnc::ir::Camera) -> scnc::ir::Camera {
        let mut c = camera.clone();
        if *self == View::default() {
            return c;
        }
        let up = c.up.normalize();
        let offset = c.position - c.look_at;
        let distance = offset.length();
        let forward = -offset / distance;
        // The frame's own axes (left-handed, as render::frame builds them).
        let right = up.cross(forward).normalize();
        let screen_up = forward.cross(right).normalize();
        let look_at = c.look_at + (right * self.pan[0] + screen_up * self.pan[1]) * distance;
        let turned = DQuat::from_axis_angle(up, self.yaw.to_radians()) * offset;
        // Pitch about the turned right axis, stopping a degree short of the up axis so
        // the view never looks along it.
        let axis = up.cross(-turned).normalize();
        let elevation = (turned.normalize().dot(up)).clamp(-1.0, 1.0).asin().to_degrees();
        let pitch = (elevation + self.pitch).clamp(-89.0, 89.0) - elevation;
        let turned = DQuat::from_axis_angle(axis, pitch.to_radians()) * turned;
        c.look_at = look_at;
        c.position = look_at + turned * self.zoom;
        c
    }
}

/// A render request: its stream answered until done, overtaken, or the page gone.
pub(crate) fn render(studio: &Arc<Studio>, mut req: Req) {
    let text = match req.body() {
        Ok(t) => t,
        Err(reply) => return req.reply(reply),
    };
    let ask = Ask {
        view: View::from_query(&req),
        coarse: req.query_u32("coarse").clamp(1, 16),
        mesh: req.query("backend") == Some("mesh"),
        rung: req.query("rung").and_then(|r| r.parse::<usize>().ok()).filter(|r| *r < SDF_RUNGS.len()),
        frame: req.query_u32("frame"),
        set: super::page_params(&req),
    };
    let previews = &studio.preview;
    let id = previews.newest.fetch_add(1, Ordering::AcqRel) + 1;
    let Some(mut out) = req.stream("application/octet-stream") else { return };
    let _one = lock(&previews.running);
    let newest = Arc::clone(&previews.newest);
    let current: Wanted = Arc::new(move || newest.load(Ordering::Acquire) == id);
    if !current() {
        let _ = out.message(b'X', b"{}");
        return;
    }
    // Failing to write means the page is gone (or moved on): stop either way.
    let _ = run(studio, &text, &ask, &mut out, &current);
}

/// The object under the point `(x, y)` of the preview (fractions of its width and
/// height) with the page's view: the span of its `object` statement, in the page's
/// UTF-16 offsets, or `null` where the ray meets nothing (or the text has errors).
pub(crate) fn pick(studio: &Studio, text: String, set: &Overrides, view: &View, x: f64, y: f64) -> Reply {
    let mut compiled = studio.files.compile(text, set);
    let Some(mut scene) = compiled.scene.take() else { return Reply::json(&serde_json::Value::Null) };
    scene.camera = view.apply(&scene.camera);
    let always: Wanted = Arc::new(|| true);
    let Ok(Some((frame, world))) = lower(studio, &scene, Mode::Sdf, &always) else {
        return Reply::json(&serde_json::Value::Null);
    };
    let (px, py) = ((x.clamp(0.0, 1.0) * frame.width as f64) as f32, (y.clamp(0.0, 1.0) * frame.height as f64) as f32);
    let ray = scnc::trace::Ray::new(glam::Vec3A::ZERO, frame.direction(px, py), frame.max_distance);
    let hit = scnc::trace::Geometry::intersect(&world, &ray, &mut Counters::default());
    let range = hit.and_then(|h| world.span_of(h.object)).and_then(|s| page_range(&compiled.map, s));
    let answer = range.map(|(from, to)| serde_json::json!({ "from": from, "to": to }));
    Reply::json(&answer.unwrap_or(serde_json::Value::Null))
}

/// What the page asked for.
struct Ask {
    view: View,
    /// The coarse pass's reduction (4: a quarter of each side); 1 skips it.
    coarse: u32,
    mesh: bool,
    /// The accuracy slider's rung, if the page shows it.
    rung: Option<usize>,
    frame: u32,
    /// The page's parameter controls.
    set: Overrides,
}

impl Ask {
    /// Sets `scene` to rung `r` (or leaves its own setting) and says which back-end
    /// renders it: the SDF's hit threshold or the mesh's detail, one place for both.
    fn setting(&self, rung: Option<usize>, scene: &mut scnc::ir::Scene) -> Mode {
        match (self.mesh, rung) {
            (true, Some(r)) => Mode::Mesh(Detail::N(MESH_RUNGS[r])),
            (true, None) => Mode::Mesh(Detail::High),
            (false, Some(r)) => {
                scene.settings.epsilon = SDF_RUNGS[r];
                Mode::Sdf
            }
            (false, None) => Mode::Sdf,
        }
    }
}

/// `scene` lowered for `mode` with the effects it calls for, on the render workers;
/// `None` once `current` says a newer request came (an isosurface stops at its next
/// sample).
fn lower(
    studio: &Studio,
    scene: &scnc::ir::Scene,
    mode: Mode,
    current: &Wanted,
) -> Result<Option<(Frame, World)>, Diagnostic> {
    let effects = scnc::render::effects::derive(scene);
    let limit = scnc::mesh::lower::DEFAULT_MEMORY_LIMIT;
    let loader = studio.files.loader();
    let wanted = Arc::clone(current);
    studio.preview.pool.install(|| scnc::world::prepare_until(scene, effects, mode, &loader, limit, wanted))
}

fn json_message(out: &mut Stream, kind: u8, value: serde_json::Value) -> std::io::Result<()> {
    out.message(kind, value.to_string().as_bytes())
}

/// One preview: compile, lower, the coarse pass, the full frame in bands, statistics and
/// accuracy. Long because it is that sequence, each step able to end the stream (errors, a
/// newer request, a gone page).
fn run(studio: &Studio, text: &str, ask: &Ask, out: &mut Stream, current: &Wanted) -> std::io::Result<()> {
    let loader = studio.files.loader();
    let mut compiled = studio.files.compile(text.to_string(), &ask.set);
    studio.files.watch_read(&compiled.map);
    let Some(first) = compiled.scene.take() else {
        return json_message(out, b'E', diagnostics_json(&compiled.map, &compiled.diagnostics));
    };
    // What the editor shows of this text comes with its image, from this one compile.
    json_message(
        out,
        b'C',
        serde_json::json!({
            "diagnostics": diagnostics_json(&compiled.map, &compiled.diagnostics),
            "params": super::diagnostics::param_list(&compiled.map, &first),
        }),
    )?;
    let declared = first.settings.clone();
    let mut scene = if ask.frame > 0 && ask.frame < declared.frames {
        let (scene, diagnostics) = scnc::with_big_stack(|| compiled.frame(ask.frame, &declared, &loader))
            .unwrap_or_else(|e| (None, vec![e.diagnostic()]));
        match scene {
            Some(s) => s,
            None => return json_message(out, b'E', diagnostics_json(&compiled.map, &diagnostics)),
        }
    } else {
        first
    };
    scene.camera = ask.view.apply(&scene.camera);
    let s = &mut scene.settings;
    let (full_w, full_h) = (s.width, s.height);
    let pixels = full_w as u64 * full_h as u64;
    if pixels > MAX_PIXELS {
        let k = (MAX_PIXELS as f64 / pixels as f64).sqrt();
        s.width = ((full_w as f64 * k) as u32).max(1);
        s.height = ((full_h as f64 * k) as u32).max(1);
        let note = format!(
            "previewed at {}×{} of the scene's {full_w}×{full_h} (`scnc render` makes the full size)",
            s.width, s.height
        );
        json_message(out, b'N', serde_json::json!({ "note": note }))?;
    }
    let mode = ask.setting(ask.rung, &mut scene);
    json_message(out, b'L', serde_json::json!({ "objects": scene.objects.len() }))?;
    let started = Instant::now();
    let (mut frame, world) = match lower(studio, &scene, mode, current) {
        Ok(Some(l)) => l,
        Ok(None) => return out.message(b'X', b"{}"),
        Err(d) => return json_message(out, b'E', diagnostics_json(&compiled.map, &[d])),
    };
    let lower_s = started.elapsed().as_secs_f64();
    // Light transport converges in front of the user: one sample a pixel first, as the
    // film's exact sums so later passes add to it, then ever more while nothing newer
    // is asked.
    let converging = frame.transport.is_some();
    if converging {
        frame.samples = 1;
        frame.bit_depth = scnc::render::BitDepth::Sums;
    }
    let meta = |level: &str, width: u32, height: u32| {
        serde_json::json!({
            "level": level, "width": width, "height": height,
            "frames": declared.frames, "fps": declared.fps, "frame": ask.frame.min(declared.frames - 1),
            "warnings": diagnostics_json(&compiled.map, &world.warnings),
        })
    };
    // The coarse pass: the same frame with fewer pixels.
    let mut trace_s = 0.0;
    if ask.coarse > 1 {
        let mut small = frame.clone();
        small.width = (frame.width / ask.coarse).max(1);
        small.height = (frame.height / ask.coarse).max(1);
        json_message(out, b'M', meta("coarse", small.width, small.height))?;
        let t = Instant::now();
        let full = PixelRect::full(small.width, small.height);
        let stop = || !current();
        let coarse =
            studio.preview.pool.install(|| scnc::render::render_region_until(&world, &small, full, &|| {}, &stop));
        let Some((image, _)) = coarse else { return out.message(b'X', b"{}") };
        trace_s = t.elapsed().as_secs_f64();
        send_band(out, 0, &image.tone_mapped(&small))?;
        let estimate = trace_s * (ask.coarse * ask.coarse) as f64;
        if estimate > SLOW_FULL_SECONDS && estimate <= MAX_FULL_SECONDS {
            // Said before the wait, not after it: an edit that makes the scene slow (a
            // camera moved into a mirror sphere) is seen as such at once.
            let note =
                format!("the full frame will take about {estimate:.1} s: it replaces this coarse image band by band");
            json_message(out, b'N', serde_json::json!({ "note": note, "estimate_s": estimate }))?;
        }
        if estimate > MAX_FULL_SECONDS {
            let note = format!(
                "the full frame would take about {estimate:.0} s: showing the coarse preview; `scnc render` makes it"
            );
            return json_message(out, b'N', serde_json::json!({ "note": note }));
        }
    }
    if !current() {
        return out.message(b'X', b"{}");
    }
    json_message(out, b'M', meta("full", frame.width, frame.height))?;
    let t = Instant::now();
    let mut counters = Counters::default();
    let mut whole = Vec::with_capacity(frame.width as usize * frame.height as usize * 3);
    let mut y0 = 0;
    while y0 < frame.height {
        if !current() {
            return out.message(b'X', b"{}");
        }
        let y1 = (y0 + BAND_ROWS).min(frame.height);
        let region = PixelRect { x0: 0, y0, x1: frame.width, y1 };
        let stop = || !current();
        let band =
            studio.preview.pool.install(|| scnc::render::render_region_until(&world, &frame, region, &|| {}, &stop));
        let Some((band, c)) = band else { return out.message(b'X', b"{}") };
        counters.add(&c);
        send_band(out, y0, &band.tone_mapped(&frame))?;
        whole.extend_from_slice(&band.pixels);
        y0 = y1;
    }
    let full_s = t.elapsed().as_secs_f64();
    let stats = crate::cli::stats::stats_text(&counters, &world, &compiled.map, lower_s, full_s);
    json_message(
        out,
        b'S',
        serde_json::json!({
            "text": stats, "effects": frame.effects.to_string(), "lower_ms": lower_s * 1e3,
            "coarse_ms": trace_s * 1e3, "full_ms": full_s * 1e3, "rays": counters.rays(),
            "setting": setting_label(mode, &scene),
        }),
    )?;
    let image = Image { width: frame.width, height: frame.height, depth: frame.bit_depth, pixels: whole };
    if converging {
        return converge(studio, &world, &frame, &image, out, current);
    }
    if let Some(rung) = ask.rung {
        accuracy(studio, text, ask, rung, &scene, &image, lower_s + full_s, out, current)?;
    }
    Ok(())
}

/// Most samples a pixel the studio accumulates to while the user is idle.
const MOST_STUDIO_SAMPLES: u32 = 4096;

/// Light transport's preview converging: passes of as many new samples as the image
/// has (so each halves the noise's variance), each added to the film's sums and the
/// whole image sent, with a `P` message of the samples a pixel has and the noise
/// estimate, until [`MOST_STUDIO_SAMPLES`] or a newer request. `first` is the sums
/// image of the first sample; after each pass the image is the very one `scnc render
/// --samples` makes of as many.
fn converge(
    studio: &Studio,
    world: &scnc::world::World,
    frame: &scnc::render::Frame,
    first: &Image,
    out: &mut Stream,
    current: &Wanted,
) -> std::io::Result<()> {
    let mut sums = first.sums();
    let mut total = 1u32;
    let full = PixelRect::full(frame.width, frame.height);
    let started = Instant::now();
    while total < MOST_STUDIO_SAMPLES {
        let mut pass = frame.clone();
        pass.samples = total;
        if let Some(t) = &mut pass.transport {
            t.first_sample = total;
        }
        let stop = || !current();
        let rendered =
            studio.preview.pool.install(|| scnc::render::render_region_until(world, &pass, full, &|| {}, &stop));
        let Some((image, c)) = rendered else { return out.message(b'X', b"{}") };
        for (s, p) in sums.iter_mut().zip(image.sums()) {
            s.merge(&p);
        }
        let done = total * 2;
        // The pass's estimate for its own samples, scaled to all of them (the error of a
        // mean falls as the root of its samples).
        // A pass of one sample a pixel has no estimate.
        let noise = (c.noise_pixels > 0).then(|| {
            let pass_noise = c.noise_ppm as f64 / c.noise_pixels as f64 / 1e6;
            100.0 * pass_noise * (f64::from(total) / f64::from(done)).sqrt()
        });
        let mut pixels = Vec::with_capacity(sums.len() * scnc::render::path::PathPixel::BYTES);
        for s in &sums {
            s.write_sums(&mut pixels);
        }
        let shown = Image { width: frame.width, height: frame.height, depth: frame.bit_depth, pixels };
        send_band(out, 0, &shown.tone_mapped(frame))?;
        total = done;
        json_message(
            out,
            b'P',
            serde_json::json!({
                "samples": total, "noise_percent": noise,
                "seconds": started.elapsed().as_secs_f64(),
            }),
        )?;
    }
    Ok(())
}

/// What the accuracy setting of this render was.
fn setting_label(mode: Mode, scene: &scnc::ir::Scene) -> String {
    match mode {
        Mode::Sdf => format!("SDF, hit threshold {:e}", scene.settings.epsilon),
        Mode::Mesh(d) => format!("mesh, detail {}", d.rings()),
    }
}

fn send_band(out: &mut Stream, y0: u32, image: &Image) -> std::io::Result<()> {
    let mut payload = Vec::with_capacity(12 + image.pixels.len());
    for n in [y0, image.height, image.width] {
        payload.extend_from_slice(&n.to_le_bytes());
    }
    payload.extend_from_slice(&image.pixels);
    out.message(b'B', &payload)
}

/// The error of `image` (at `rung`) against the finest rung of the same view, which is
/// rendered once per scene text, view and size and kept.
#[allow(clippy::too_many_arguments, reason = "one render's whole context")]
fn accuracy(
    studio: &Studio,
    text: &str,
    ask: &Ask,
    rung: usize,
    scene: &scnc::ir::Scene,
    image: &Image,
    seconds: f64,
    out: &mut Stream,
    current: &Wanted,
) -> std::io::Result<()> {
    use std::hash::{Hash, Hasher};
    let finest = SDF_RUNGS.len() - 1;
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (text, ask.mesh, ask.frame, image.width, image.height).hash(&mut h);
    [ask.view.yaw, ask.view.pitch, ask.view.zoom, ask.view.pan[0], ask.view.pan[1]].map(f64::to_bits).hash(&mut h);
    let key = h.finish();
    let cached =
        lock(&studio.preview.reference).as_ref().filter(|(k, _, _)| *k == key).map(|(_, i, s)| (Arc::clone(i), *s));
    let (reference, reference_s) = match cached {
        Some(r) => r,
        None if rung == finest => (Arc::new(image.clone()), seconds),
        None => {
            if !current() {
                return out.message(b'X', b"{}");
            }
            let mut scene = scene.clone();
            let mode = ask.setting(Some(finest), &mut scene);
            let t = Instant::now();
            let stop = || !current();
            let rendered = lower(studio, &scene, mode, current).map(|lowered| {
                let (frame, world) = lowered?;
                let all = PixelRect::full(frame.width, frame.height);
                studio.preview.pool.install(|| scnc::render::render_region_until(&world, &frame, all, &|| {}, &stop))
            });
            match rendered {
                Ok(Some((i, _))) => (Arc::new(i), t.elapsed().as_secs_f64()),
                Ok(None) => return out.message(b'X', b"{}"),
                Err(d) => {
                    let note = format!("the finest rung cannot be made: {}", d.message);
                    return json_message(out, b'N', serde_json::json!({ "note": note }));
                }
            }
        }
    };
    *lock(&studio.preview.reference) = Some((key, Arc::clone(&reference), reference_s));
    let differing = image
        .pixels
        .chunks_exact(3)
        .zip(reference.pixels.chunks_exact(3))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > DIFF_THRESHOLD))
        .count();
    let total = (image.width as usize * image.height as usize).max(1);
    json_message(
        out,
        b'A',
        serde_json::json!({
            "rung": rung, "rungs": SDF_RUNGS.len(), "ms": seconds * 1e3, "reference_ms": reference_s * 1e3,
            "differing_percent": 100.0 * differing as f64 / total as f64,
            "rmse": scnc::study::accuracy::rmse(image, &reference),
            "threshold": DIFF_THRESHOLD,
        }),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn camera() -> scnc::ir::Camera {
        scnc::ir::Camera {
            position: DVec3::new(0.0, 0.0, -5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov: 50.0,
            ..scnc::ir::Camera::default()
        }
    }

    #[test]
    fn the_view_orbits_about_look_at_and_never_reaches_the_pole() {
        let c = camera();
        assert_eq!(View::default().apply(&c).position, c.position);
        let turned = View { yaw: 90.0, ..View::default() }.apply(&c);
        assert!((turned.position.length() - 5.0).abs() < 1e-9, "{:?}", turned.position);
        assert!(turned.position.z.abs() < 1e-9, "a quarter turn leaves the z axis: {:?}", turned.position);
        let over = View { pitch: 500.0, ..View::default() }.apply(&c);
        let elevation = over.position.normalize().dot(DVec3::Y).asin().to_degrees();
        assert!((elevation - 89.0).abs() < 1e-6, "{elevation}");
        let zoomed = View { zoom: 0.5, ..View::default() }.apply(&c);
        assert!((zoomed.position.length() - 2.5).abs() < 1e-9);
        let panned = View { pan: [0.1, 0.0], ..View::default() }.apply(&c);
        assert!((panned.look_at - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-9, "{:?}", panned.look_at);
    }
}
