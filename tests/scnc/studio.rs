//! `scnc studio`: the server's rules over raw HTTP, the render stream against `scnc
//! render`, and the page end to end in a real browser (Debian's `chromium`, skipped with a
//! note where it is not installed; `.ci/run` installs it and requires it).

use std::io::{Read as _, Write as _};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use super::browser::{base64, Browser};
use super::support::have_tool;

/// A studio server on a free port, killed when dropped.
struct Server {
    child: Child,
    port: u16,
}

impl Server {
    fn start(file: &Path) -> Server {
        let port_file = file.with_file_name(".port");
        let _ = std::fs::remove_file(&port_file);
        let child = Command::new(env!("CARGO_BIN_EXE_scnc"))
            .args(["studio", "--port", "0", "--threads", "2", "--port-file"])
            .arg(&port_file)
            .arg(file)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let start = Instant::now();
        let port = loop {
            if let Some(p) = std::fs::read_to_string(&port_file).ok().and_then(|t| t.trim().parse().ok()) {
                break p;
            }
            assert!(start.elapsed() < Duration::from_secs(20), "the studio did not start");
            std::thread::sleep(Duration::from_millis(20));
        };
        std::fs::remove_file(&port_file).unwrap();
        Server { child, port }
    }

    fn url(&self) -> String {
        format!("http://127.0.0.1:{}/", self.port)
    }

    /// Sends one raw request (its `Host` is this server's unless `host` is given): the
    /// status and body.
    fn raw(&self, method: &str, path: &str, headers: &[(&str, &str)], body: &[u8]) -> (u16, Vec<u8>) {
        let mut s = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        let host = format!("127.0.0.1:{}", self.port);
        let host = headers.iter().find(|(k, _)| *k == "Host").map_or(host.as_str(), |(_, v)| v);
        let mut head = format!("{method} {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n");
        for (k, v) in headers.iter().filter(|(k, _)| *k != "Host") {
            head.push_str(&format!("{k}: {v}\r\n"));
        }
        head.push_str(&format!("Content-Length: {}\r\n\r\n", body.len()));
        s.write_all(head.as_bytes()).unwrap();
        // A server that refuses early may close before reading all of a large body.
        let _ = s.write_all(body);
        let mut reply = Vec::new();
        let _ = s.read_to_end(&mut reply);
        let split = reply.windows(4).position(|w| w == b"\r\n\r\n").expect("a reply with a head");
        let head = String::from_utf8_lossy(&reply[..split]).to_string();
        let status = head.split(' ').nth(1).unwrap().parse().unwrap();
        let mut body = reply[split + 4..].to_vec();
        if head.to_ascii_lowercase().contains("transfer-encoding: chunked") {
            body = dechunk(&body);
        }
        (status, body)
    }

    fn post(&self, path: &str, body: &str) -> (u16, Vec<u8>) {
        self.raw("POST", path, &[], body.as_bytes())
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let eol = b.windows(2).position(|w| w == b"\r\n").unwrap();
        let n = usize::from_str_radix(std::str::from_utf8(&b[..eol]).unwrap().trim(), 16).unwrap();
        if n == 0 {
            return out;
        }
        out.extend_from_slice(&b[eol + 2..eol + 2 + n]);
        b = &b[eol + 2 + n + 2..];
    }
}

/// Seed scene 7 and its lights at 160×120, in a directory of its own.
fn seed_scene() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/seed");
    let lights = std::fs::read_to_string(root.join("lights.scn")).unwrap();
    let lights = lights.replace("render(width = 1000, height = 1000", "render(width = 160, height = 120");
    assert!(lights.contains("width = 160"));
    std::fs::write(dir.path().join("lights.scn"), lights).unwrap();
    let scene = dir.path().join("scene.scn");
    std::fs::copy(root.join("07-box-sphere-cylinder.scn"), &scene).unwrap();
    (dir, scene)
}

/// The messages of a render stream: kind and payload.
fn messages(mut b: &[u8]) -> Vec<(u8, Vec<u8>)> {
    let mut out = Vec::new();
    while b.len() >= 5 {
        let n = u32::from_le_bytes(b[1..5].try_into().unwrap()) as usize;
        out.push((b[0], b[5..5 + n].to_vec()));
        b = &b[5 + n..];
    }
    out
}

/// The RGB pixels of `scnc render` of `scene`.
fn rendered(scene: &Path) -> image::RgbImage {
    let png = scene.with_file_name("reference.png");
    let out = Command::new(env!("CARGO_BIN_EXE_scnc")).arg("render").arg(scene).arg("-o").arg(&png).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    image::open(&png).unwrap().to_rgb8()
}

#[test]
fn studio_refuses_other_hosts_origins_paths_and_methods() {
    let (_dir, scene) = seed_scene();
    let before = std::fs::read_to_string(&scene).unwrap();
    let s = Server::start(&scene);
    assert_eq!(s.raw("GET", "/", &[], b"").0, 200);
    assert_eq!(s.raw("GET", "/", &[("Host", &format!("localhost:{}", s.port))], b"").0, 200);
    // DNS rebinding: a page of evil.example whose name now points at 127.0.0.1.
    let (status, body) = s.raw("GET", "/api/file", &[("Host", &format!("evil.example:{}", s.port))], b"");
    assert_eq!(status, 403, "{}", String::from_utf8_lossy(&body));
    // A cross-site form or fetch: refused before anything is written.
    let (status, _) = s.raw("POST", "/api/save", &[("Origin", "http://evil.example")], b"object sphere(1)");
    assert_eq!(status, 403);
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), before, "a refused save wrote the file");
    for path in
        ["/../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/assets/../../etc/passwd", "/scene.scn", "/lights.scn"]
    {
        let (status, body) = s.raw("GET", path, &[], b"");
        assert_eq!(status, 404, "{path}");
        assert!(!String::from_utf8_lossy(&body).contains("root:"), "{path}");
    }
    assert_eq!(s.raw("DELETE", "/", &[], b"").0, 405);
    let huge = vec![b' '; 5 << 20];
    assert_eq!(s.raw("POST", "/api/check", &[], &huge).0, 413);
    assert_eq!(s.raw("POST", "/api/check", &[], &[0xff, 0xfe]).0, 400);
    // The server is still there after all of that.
    assert_eq!(s.raw("GET", "/assets/studio.js", &[], b"").0, 200);
}

#[test]
fn studio_reads_includes_only_below_the_files_directory() {
    let outer = tempfile::tempdir().unwrap();
    let inner = outer.path().join("scenes");
    std::fs::create_dir(&inner).unwrap();
    std::fs::write(outer.path().join("secret.scn"), "let secret = 1\n").unwrap();
    let scene = inner.join("scene.scn");
    std::fs::write(&scene, "object sphere(1)\n").unwrap();
    let s = Server::start(&scene);
    for include in ["../secret.scn", &outer.path().join("secret.scn").display().to_string()] {
        let (status, body) = s.post("/api/check", &format!("include \"{include}\"\nobject sphere(1)\n"));
        assert_eq!(status, 200);
        let body = String::from_utf8(body).unwrap();
        assert!(body.contains("E0600") && body.contains("outside"), "{include}: {body}");
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(outer.path().join("secret.scn"), inner.join("link.scn")).unwrap();
        let (_, body) = s.post("/api/check", "include \"link.scn\"\nobject sphere(1)\n");
        assert!(String::from_utf8(body).unwrap().contains("outside"), "a link out of the directory was followed");
    }
}

#[test]
fn studio_streams_what_scnc_render_makes() {
    let (_dir, scene) = seed_scene();
    let s = Server::start(&scene);
    let text = std::fs::read_to_string(&scene).unwrap();
    let (status, body) = s.post("/api/render?coarse=4", &text);
    assert_eq!(status, 200);
    let msgs = messages(&body);
    let kinds: String = msgs.iter().map(|(k, _)| *k as char).collect();
    assert!(kinds.starts_with("MBM") && kinds.ends_with('S'), "{kinds}");
    let full: Vec<u8> = msgs.iter().skip(3).filter(|(k, _)| *k == b'B').flat_map(|(_, p)| p[12..].to_vec()).collect();
    assert_eq!(full, rendered(&scene).into_raw(), "the streamed frame differs from `scnc render`'s");
    // An error keeps nothing: diagnostics instead of an image.
    let (_, body) = s.post("/api/render", "object sphre(1)\n");
    let msgs = messages(&body);
    assert_eq!(msgs.len(), 1);
    assert!(msgs[0].0 == b'E' && String::from_utf8_lossy(&msgs[0].1).contains("E0201"));
    // The camera line, through the formatter, and still a scene.
    let (_, body) = s.post("/api/camera?yaw=30&pitch=10&zoom=1.5", &text);
    let v: serde_json::Value = serde_json::from_slice(&body).unwrap();
    let moved = v["text"].as_str().unwrap();
    assert!(moved.contains("camera(position = ["), "{moved}");
    let edited = scene.with_file_name("moved.scn");
    std::fs::write(&edited, moved).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_scnc")).arg("check").arg(&edited).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

/// The full frame of a render stream.
fn full_frame(body: &[u8]) -> Vec<u8> {
    let msgs = messages(body);
    let full = msgs.iter().position(|(k, p)| *k == b'M' && String::from_utf8_lossy(p).contains("\"full\"")).unwrap();
    msgs[full..].iter().filter(|(k, _)| *k == b'B').flat_map(|(_, p)| p[12..].to_vec()).collect()
}

#[test]
fn studio_renders_the_frame_the_scrubber_asks_for() {
    let orbit = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/animation/orbit.scn");
    let s = Server::start(&orbit);
    let text = std::fs::read_to_string(&orbit).unwrap();
    let (_, first) = s.post("/api/render?coarse=1", &text);
    let meta = messages(&first).into_iter().find(|(k, _)| *k == b'M').unwrap().1;
    let meta: serde_json::Value = serde_json::from_slice(&meta).unwrap();
    assert_eq!((meta["frames"].as_u64(), meta["fps"].as_f64()), (Some(48), Some(24.0)));
    let (_, later) = s.post("/api/render?coarse=1&frame=12", &text);
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("f-##.png");
    let out = Command::new(env!("CARGO_BIN_EXE_scnc"))
        .arg("render")
        .arg(&orbit)
        .args(["--frames", "12..13", "-o"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let expected = image::open(dir.path().join("f-12.png")).unwrap().to_rgb8().into_raw();
    assert_ne!(full_frame(&first), full_frame(&later), "frame 12 is frame 0");
    assert_eq!(full_frame(&later), expected, "frame 12 differs from `scnc render --frames 12..13`");
}

#[test]
fn studio_on_a_busy_port_is_a_usage_error() {
    let (_dir, scene) = seed_scene();
    let s = Server::start(&scene);
    let out = Command::new(env!("CARGO_BIN_EXE_scnc"))
        .args(["studio", "--port", &s.port.to_string()])
        .arg(&scene)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot listen"));
}

/// Where the end-to-end test leaves its screenshots.
fn artefacts() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("studio-screenshots");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The preview canvas's pixels.
fn canvas_pixels(b: &mut Browser) -> image::RgbImage {
    let url = b.eval("document.querySelector('[data-testid=preview]').toDataURL('image/png')");
    let data = url.as_str().unwrap().strip_prefix("data:image/png;base64,").unwrap().to_string();
    image::load_from_memory(&base64(&data)).unwrap().to_rgb8()
}

const FINISHED: &str = "Number(document.querySelector('[data-testid=preview]').dataset.finished || 0)";
const IDLE: &str = "document.querySelector('[data-testid=preview]').dataset.busy === '0'";

#[test]
fn studio_in_a_browser() {
    if !have_tool("chromium") {
        return;
    }
    let (dir, scene) = seed_scene();
    let original = std::fs::read_to_string(&scene).unwrap();
    let s = Server::start(&scene);
    let shots = artefacts();
    let mut b = Browser::launch();
    b.open(&s.url());
    let limit = Duration::from_secs(30);

    // The page shows the scene as `scnc render` renders it.
    b.wait_for(&format!("{FINISHED} >= 1 && {IDLE}"), limit);
    b.screenshot(&shots.join("1-opened.png"));
    let first = canvas_pixels(&mut b);
    assert_eq!(first, rendered(&scene), "the preview differs from `scnc render` at the same size");

    // A misspelt builtin: its diagnostic within 2 s, and the image stays.
    b.eval("(() => { const e = scnStudio.editor; e.focus(); e.dispatch({ selection: { anchor: e.state.doc.length } }); })()");
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.type_text("object sphre(0.4) at [0, 1.3, 8] with red\n");
    b.wait_for(
        "[...document.querySelectorAll('[data-testid=diagnostics] li')].some(li => li.textContent.includes('E0201') \
         && li.textContent.includes('unknown function `sphre`'))",
        Duration::from_secs(2),
    );
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    b.screenshot(&shots.join("2-misspelt.png"));
    assert_eq!(canvas_pixels(&mut b), first, "an edit with errors replaced the image");

    // Fixed by typing over the misspelt name: no diagnostics, and a new image.
    b.eval(
        "(() => { const e = scnStudio.editor; const at = e.state.doc.toString().indexOf('sphre('); \
         e.dispatch({ selection: { anchor: at, head: at + 5 } }); })()",
    );
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.type_text("sphere");
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    b.wait_for("document.querySelectorAll('[data-testid=diagnostics] li').length === 0", limit);
    b.screenshot(&shots.join("3-fixed.png"));
    let fixed = canvas_pixels(&mut b);
    assert_ne!(fixed, first, "the fixed scene rendered the same image");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), original, "typing wrote the file");

    // Dragging turns the view; the file is not touched.
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.drag("[data-testid=preview]", (60.0, 20.0));
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    b.screenshot(&shots.join("4-dragged.png"));
    assert_ne!(canvas_pixels(&mut b), fixed, "dragging did not change the view");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), original, "dragging wrote the file");

    // View → camera writes the dragged view into the text as a camera line; the page's
    // own view is reset, so the image stays (to the camera line's 4 decimals).
    let dragged = canvas_pixels(&mut b);
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.click("[data-testid=write-camera]");
    b.wait_for("scnStudio.ScnEditor.textOf(scnStudio.editor).includes('camera(position = [')", limit);
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    let written = canvas_pixels(&mut b);
    let differing = written
        .pixels()
        .zip(dragged.pixels())
        .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 16))
        .count();
    assert!(differing * 100 < written.len() / 3, "{differing} pixels changed when the view became the camera line");
    b.screenshot(&shots.join("5-camera-written.png"));

    // Ctrl-S saves the editor's text, whole, leaving no temporary file.
    b.eval("scnStudio.editor.focus()");
    b.ctrl('s');
    let text = b.eval("scnStudio.ScnEditor.textOf(scnStudio.editor)").as_str().unwrap().to_string();
    let start = Instant::now();
    while std::fs::read_to_string(&scene).unwrap() != text {
        assert!(start.elapsed() < limit, "Ctrl-S did not save");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(text.contains("object sphere(0.4)"));
    let stray: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.starts_with(".scnc-"))
        .collect();
    assert!(stray.is_empty(), "temporary files left: {stray:?}");
    b.wait_for("document.querySelector('[data-testid=saved]').textContent.startsWith('saved')", limit);
    b.screenshot(&shots.join("6-saved.png"));

    // An edit made outside the page replaces the page's text.
    let outside = text.replace("sphere(0.4)", "sphere(0.3)");
    std::fs::write(&scene, &outside).unwrap();
    b.wait_for("scnStudio.ScnEditor.textOf(scnStudio.editor).includes('sphere(0.3)')", limit);

    // Export STL: a file downloads, and it is a valid STL of the scene's objects.
    let downloads = tempfile::tempdir().unwrap();
    b.downloads_to(downloads.path());
    b.click("[data-testid=export-stl]");
    let start = Instant::now();
    let stl = loop {
        let found = std::fs::read_dir(downloads.path())
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.extension().is_some_and(|e| e == "stl"));
        if let Some(p) = found {
            break p;
        }
        assert!(start.elapsed() < limit, "no STL was downloaded");
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut file = std::fs::File::open(&stl).unwrap();
    let mesh = stl_io::read_stl(&mut file).expect("a valid STL");
    assert!(mesh.faces.len() > 1000, "{} triangles", mesh.faces.len());
    mesh.validate().expect("an STL whose faces name its vertices");
    b.screenshot(&shots.join("7-exported.png"));
}

#[test]
fn studio_survives_pages_that_leave_mid_render_and_renders_that_are_overtaken() {
    let (_dir, scene) = seed_scene();
    let s = Server::start(&scene);
    let text = std::fs::read_to_string(&scene).unwrap();
    for _ in 0..3 {
        let mut c = TcpStream::connect(("127.0.0.1", s.port)).unwrap();
        let head = format!(
            "POST /api/render?coarse=4 HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Length: {}\r\n\r\n",
            s.port,
            text.len()
        );
        c.write_all(head.as_bytes()).unwrap();
        c.write_all(text.as_bytes()).unwrap();
        let mut some = [0u8; 64];
        let _ = c.read(&mut some);
        // Gone after the first bytes.
    }
    // Renders at once: each finishes or says it was overtaken (at a band, or before it
    // began), and the last to arrive always finishes.
    let ends: Vec<String> = std::thread::scope(|scope| {
        let runs: Vec<_> = (0..3)
            .map(|_| {
                scope.spawn(|| {
                    let (status, body) = s.post("/api/render?coarse=1", &text);
                    assert_eq!(status, 200);
                    messages(&body).iter().map(|(k, _)| *k as char).collect::<String>()
                })
            })
            .collect();
        runs.into_iter().map(|r| r.join().unwrap()).collect()
    });
    assert!(ends.iter().all(|e| e.ends_with('S') || e.ends_with('X')), "{ends:?}");
    assert!(ends.iter().any(|e| e.ends_with('S')), "{ends:?}");
    assert_eq!(s.raw("GET", "/", &[], b"").0, 200);
}

/// The numbers in the README's "Studio" section: for each seed scene at its own size
/// (1000×1000), the time from an edit to the first (quarter-size) image and to the full
/// frame, as the page measures them, median of 7 edits. Run with
/// `cargo test --release --test scnc -- --ignored --nocapture studio_latency`.
#[test]
#[ignore = "a measurement, not a test: run by hand for the README's table"]
fn studio_latency_on_the_seed_scenes() {
    if !have_tool("chromium") {
        return;
    }
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/seed");
    let mut b = Browser::launch();
    let mut table = String::from("| scene | edit → first image (ms) | edit → full frame (ms) |\n|---|---|---|\n");
    for n in 1..=7 {
        let file = std::fs::read_dir(&seeds)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.file_name().unwrap().to_string_lossy().starts_with(&format!("0{n}-")))
            .unwrap();
        let s = Server::start(&file);
        b.open(&s.url());
        b.wait_for(&format!("{FINISHED} >= 1 && {IDLE}"), Duration::from_secs(60));
        let (mut first, mut full) = (Vec::new(), Vec::new());
        for i in 0..7 {
            let done = b.eval(FINISHED).as_u64().unwrap();
            b.eval("(() => { const e = scnStudio.editor; e.focus(); e.dispatch({ selection: { anchor: e.state.doc.length } }); })()");
            b.type_text(&format!("\n// edit {i}"));
            b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), Duration::from_secs(60));
            let mut ms =
                |k: &str| b.eval(&format!("Number(document.querySelector('[data-testid=preview]').dataset.{k})"));
            first.push(ms("firstImageMs").as_f64().unwrap());
            full.push(ms("fullMs").as_f64().unwrap());
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        table.push_str(&format!("| {name} | {:.0} | {:.0} |\n", median(&mut first), median(&mut full)));
    }
    #[allow(clippy::print_stdout, reason = "the measurement's result")]
    {
        println!("{table}");
    }
}

/// The README's picture of the studio (`docs/studio.png` is this, looked at and copied):
/// the tour scene with the accuracy ladder on. Run with
/// `cargo test --release --test scnc -- --ignored studio_screenshot`.
#[test]
#[ignore = "makes a picture for the README"]
fn studio_screenshot_for_the_readme() {
    if !have_tool("chromium") {
        return;
    }
    let tour = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/tour.scn");
    let s = Server::start(&tour);
    let mut b = Browser::launch();
    b.open(&s.url());
    b.wait_for(&format!("{FINISHED} >= 1 && {IDLE}"), Duration::from_secs(60));
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.click("[data-testid=accuracy-on]");
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), Duration::from_secs(60));
    b.wait_for(
        "document.querySelector('[data-testid=accuracy-result]').textContent.length > 0",
        Duration::from_secs(60),
    );
    b.screenshot(&artefacts().join("readme.png"));
}

/// The accuracy ladder over the API: each rung's error against the finest falls to 0 at
/// the finest, on both back-ends; and the export buttons' files are what the formats'
/// own readers accept.
#[test]
fn studio_measures_the_ladder_and_exports_valid_files() {
    let (_dir, scene) = seed_scene();
    let s = Server::start(&scene);
    let text = std::fs::read_to_string(&scene).unwrap();
    for backend in ["sdf", "mesh"] {
        let mut off = Vec::new();
        for rung in [0, 2, 5] {
            let (status, body) = s.post(&format!("/api/render?coarse=1&backend={backend}&rung={rung}"), &text);
            assert_eq!(status, 200);
            let msgs = messages(&body);
            let stats = msgs.iter().find(|(k, _)| *k == b'S').expect("statistics");
            let stats: serde_json::Value = serde_json::from_slice(&stats.1).unwrap();
            assert!(stats["setting"].as_str().unwrap().to_lowercase().starts_with(backend), "{stats}");
            let a = msgs.iter().find(|(k, _)| *k == b'A').expect("an accuracy message");
            let a: serde_json::Value = serde_json::from_slice(&a.1).unwrap();
            off.push(a["differing_percent"].as_f64().unwrap());
        }
        assert_eq!(off[2], 0.0, "{backend}: the finest rung against itself");
        assert!(off[0] >= off[1] && off[0] > 0.0, "{backend}: coarser is not worse: {off:?}");
    }
    let (status, stl) = s.post("/api/export?format=stl", &text);
    assert_eq!(status, 200);
    let mesh = stl_io::read_stl(&mut std::io::Cursor::new(stl)).expect("an STL");
    assert!(mesh.faces.len() > 100);
    let (status, three_mf) = s.post("/api/export?format=3mf", &text);
    assert_eq!(status, 200);
    let models = threemf::read(std::io::Cursor::new(three_mf)).expect("a 3MF");
    assert_eq!(models.len(), 1);
    let (status, glb) = s.post("/api/export?format=glb", &text);
    assert_eq!(status, 200);
    let gltf = gltf::Gltf::from_slice(&glb).expect("a glb");
    assert_eq!(gltf.nodes().count(), 3, "one node per object");
    assert_eq!(s.post("/api/export?format=dwg", &text).0, 400);
    assert_eq!(s.post("/api/export?format=stl", "object sphre(1)").0, 422);
}
