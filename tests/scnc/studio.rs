//! `scnc studio`: the server's rules over raw HTTP and the render stream against `scnc
//! render`. The page in a real browser is tested in `tests/tools/page.rs`.

use std::io::{Read as _, Write as _};
use std::net::TcpStream;
use std::path::Path;
use std::process::Command;

use super::studio_server::{image_difference, messages, rendered, seed_scene, Server};

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
    // HEAD is answered with GET's head; a second `Host` or `Origin` is refused (RFC 9112),
    // even when the first is this server's.
    let head = |lines: &str| {
        let mut c = TcpStream::connect(("127.0.0.1", s.port)).unwrap();
        c.set_read_timeout(Some(std::time::Duration::from_secs(60))).unwrap();
        let ours = format!("127.0.0.1:{}", s.port);
        write!(c, "{}\r\nConnection: close\r\n\r\n", lines.replace("OURS", &ours)).unwrap();
        let mut reply = String::new();
        let _ = c.read_to_string(&mut reply);
        reply
    };
    let reply = head("HEAD / HTTP/1.1\r\nHost: OURS");
    assert!(reply.starts_with("HTTP/1.1 200") && reply.contains("text/html") && !reply.contains("<html"), "{reply}");
    assert!(head("GET /api/file HTTP/1.1\r\nHost: OURS\r\nHost: evil.example").starts_with("HTTP/1.1 400"));
    let two_origins = "POST /api/save HTTP/1.1\r\nHost: OURS\r\nOrigin: http://OURS\r\nOrigin: http://evil.example\r\nContent-Length: 0";
    assert!(head(two_origins).starts_with("HTTP/1.1 400"));
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), before, "a refused save wrote the file");
    let huge = vec![b' '; 5 << 20];
    assert_eq!(s.raw("POST", "/api/check", &[], &huge).0, 413);
    assert_eq!(s.raw("POST", "/api/check", &[], &[0xff, 0xfe]).0, 400);
    // The server is still there after all of that, and the tab's icon is served.
    assert_eq!(s.raw("GET", "/assets/studio.js", &[], b"").0, 200);
    let (status, icon) = s.raw("GET", "/favicon.svg", &[], b"");
    assert!(status == 200 && String::from_utf8_lossy(&icon).starts_with("<svg"), "{status}");
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
    assert!(kinds.starts_with("CLMBM") && kinds.ends_with('S'), "{kinds}");
    let compiled: serde_json::Value = serde_json::from_slice(&msgs[0].1).unwrap();
    assert_eq!(compiled, serde_json::json!({ "diagnostics": [], "params": [] }));
    let full: Vec<u8> = msgs.iter().skip(5).filter(|(k, _)| *k == b'B').flat_map(|(_, p)| p[12..].to_vec()).collect();
    let full = image::RgbImage::from_raw(160, 120, full).expect("a full 160×120 frame");
    if let Some(d) = image_difference("streamed", &full, &rendered(&scene)) {
        panic!("the streamed frame differs from `scnc render`'s: {d}");
    }
    // An error keeps nothing: diagnostics instead of an image.
    let (_, body) = s.post("/api/render", "object sphre(1)\n");
    let msgs = messages(&body);
    assert_eq!(msgs.len(), 1);
    assert!(msgs[0].0 == b'E' && String::from_utf8_lossy(&msgs[0].1).contains("E0201"));
    // An edit is compiled once, for its image: the stream brings the editor its
    // warnings and the controls the parameters, with the page's values.
    let (_, body) = s.post(
        "/api/render?coarse=1&set=%7B%22r%22%3A%221.5%22%7D",
        "param r = 1 in 0.5 .. 2\nobject field(p => 20 * (length(p) - r), bounds = [[-2, -2, -2], [2, 2, 2]])\n",
    );
    let msgs = messages(&body);
    assert_eq!(msgs[0].0, b'C');
    let compiled: serde_json::Value = serde_json::from_slice(&msgs[0].1).unwrap();
    let warnings = compiled["diagnostics"].as_array().unwrap();
    assert!(warnings.iter().any(|d| d["severity"] == "warning"), "{compiled}");
    let params = compiled["params"].as_array().unwrap();
    assert_eq!(
        (params.len(), params[0]["name"].as_str(), params[0]["value"].as_f64()),
        (1, Some("r"), Some(1.5)),
        "{compiled}"
    );
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
    assert!(full_frame(&first) != full_frame(&later), "frame 12 is frame 0");
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

/// A page that asks for a heavy render and leaves does not hold the render thread: the
/// next request preempts it between one 4×4 block and the next, in the coarse pass as
/// in the full frame, and a light scene's render comes back within a few seconds where
/// the heavy one would take minutes (a field reading the last level twice, 15 levels:
/// about 5 ms a pixel).
#[test]
fn an_abandoned_heavy_render_does_not_hold_the_next_one() {
    let (_dir, scene) = seed_scene();
    let s = Server::start(&scene);
    // The coarse image's `M` says the coarse pass is under way.
    let (c, _) = heavy_render(&s, 15, "render(width = 256, height = 256)\nobject s15\n", b"\"level\"");
    drop(c);
    light_render_comes_back(&s, "the heavy render");
}

/// A newer request stops an older one's lowering too, not only its render: an
/// isosurface of a heavy field (a field reading the last level twice, 12 levels: 4,096
/// sphere evaluations a sample, minutes of meshing) asks at every sample whether it is
/// still wanted, so a light scene sent once the heavy one has begun lowering (its `L`
/// message) comes back within seconds.
#[test]
fn an_abandoned_lowering_does_not_hold_the_next_render() {
    let (_dir, scene) = seed_scene();
    let s = Server::start(&scene);
    let object = "render(width = 64, height = 64)\nobject mesh isosurface(s12, cell = 0.005)\n";
    let (mut c, mut got) = heavy_render(&s, 12, object, b"\"objects\"");
    light_render_comes_back(&s, "the heavy lowering");
    // The heavy request is told it was overtaken.
    let mut rest = Vec::new();
    let _ = c.read_to_end(&mut rest);
    got.extend_from_slice(&rest);
    assert!(got.windows(7).any(|w| w == b"X\x02\0\0\0{}"), "{}", String::from_utf8_lossy(&got));
}

/// Posts a scene whose field reads the level below twice, `levels` deep (2^levels
/// sphere evaluations a sample), with `tail` (its render and object statements), and
/// reads the stream until `marker` has come: the connection and what it sent.
fn heavy_render(s: &Server, levels: u32, tail: &str, marker: &[u8]) -> (TcpStream, Vec<u8>) {
    let mut heavy = String::from("let s0 = sphere(1)\n");
    for i in 1..=levels {
        let b = "bounds = [[-2, -2, -2], [2, 2, 2]]";
        heavy += &format!("let s{i} = field(p => min(dist(s{}, p), dist(s{}, p * 1.01)), {b})\n", i - 1, i - 1);
    }
    heavy += "camera(position = [0, 0, -4], look_at = [0, 0, 0])\nlight ambient(1)\n";
    heavy += tail;
    stream_until(s, "/api/render?coarse=4", &heavy, marker)
}

/// Posts `text` to `path` and reads the streamed answer until `marker` has come: the
/// connection, still open, and what it sent.
fn stream_until(s: &Server, path: &str, text: &str, marker: &[u8]) -> (TcpStream, Vec<u8>) {
    let mut c = TcpStream::connect(("127.0.0.1", s.port)).unwrap();
    c.set_read_timeout(Some(std::time::Duration::from_secs(60))).unwrap();
    let head = format!("POST {path} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Length: {}\r\n\r\n", s.port, text.len());
    c.write_all(head.as_bytes()).unwrap();
    c.write_all(text.as_bytes()).unwrap();
    let mut got = Vec::new();
    let mut some = [0u8; 4096];
    while !got.windows(marker.len()).any(|w| w == marker) {
        let n = c.read(&mut some).expect("the render's first messages");
        assert!(n > 0, "the render ended early: {}", String::from_utf8_lossy(&got));
        got.extend_from_slice(&some[..n]);
    }
    (c, got)
}

/// A light scene's render, sent behind `what`, is whole within a few seconds.
fn light_render_comes_back(s: &Server, what: &str) {
    let light = "camera(position = [0, 0, -4], look_at = [0, 0, 0])\nrender(width = 64, height = 64)\n\
                 light ambient(1)\nobject sphere(1)\n";
    let started = std::time::Instant::now();
    let (status, body) = s.post("/api/render?coarse=4", light);
    let took = started.elapsed();
    assert_eq!(status, 200);
    let kinds: String = messages(&body).iter().map(|(k, _)| *k as char).collect();
    assert!(kinds.ends_with('S'), "{kinds}");
    assert!(took < std::time::Duration::from_secs(4), "the light render took {took:?} behind {what}");
}

/// Clients that declare a large body and send one byte of it hold no slot the page
/// needs: with 32 of them connected at once, `GET /` is answered at once, the bodies
/// past the eighth from one address are refused with 429 (unread) while eight wait for
/// theirs, and once they leave a body is read again. (Each connection must send its
/// request within 10 s; a server whose connections wait on their clients without a
/// deadline was wedged by these.)
#[test]
fn slow_request_bodies_do_not_block_the_page() {
    use std::time::{Duration, Instant};
    let (_dir, scene) = seed_scene();
    let s = Server::start(&scene);
    // Each slow connection is answered either 429 at once (eight of its client's are in
    // hand) or 408 when its own 10 s are up. A machine that stalls the server for longer
    // than that can time the first eight out before it reads the rest, so that none is
    // refused: then the attempt is made again, and a server that never refuses fails
    // every one. The answers are read from the slow connections themselves, so no
    // request of the test's has to land inside the 10 s.
    let deadline = Instant::now() + Duration::from_secs(180);
    loop {
        let slow: Vec<TcpStream> = (0..32)
            .map(|_| {
                let mut c = TcpStream::connect(("127.0.0.1", s.port)).unwrap();
                let head = format!(
                    "POST /api/check HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Length: 1000000\r\n\r\nx",
                    s.port
                );
                c.write_all(head.as_bytes()).unwrap();
                c
            })
            .collect();
        let started = Instant::now();
        let (status, _) = s.raw("GET", "/", &[], b"");
        assert_eq!(status, 200);
        assert!(started.elapsed() < Duration::from_secs(5), "GET / took {:?}", started.elapsed());
        let answers: Vec<u16> = slow
            .into_iter()
            .map(|mut c| {
                c.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
                let mut reply = Vec::new();
                let _ = c.read_to_end(&mut reply);
                let reply = String::from_utf8_lossy(&reply);
                reply.split(' ').nth(1).and_then(|code| code.parse().ok()).unwrap_or(0)
            })
            .collect();
        assert!(answers.iter().all(|&a| a == 408 || a == 429), "answers to the slow bodies: {answers:?}");
        let waited = answers.iter().filter(|&&a| a == 408).count();
        assert!(waited >= 8, "fewer than eight slow bodies were waited for: {answers:?}");
        if waited < answers.len() {
            break;
        }
        assert!(Instant::now() < deadline, "no body past the eighth from one client was ever refused");
    }
    // Every slow connection has been answered and closed: once the server's threads
    // have let them go, bodies are read again.
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (status, _) = s.post("/api/check", "light ambient(1)\n");
        if status == 200 {
            break;
        }
        assert!(Instant::now() < deadline, "bodies are still refused ({status}) after the clients left");
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// A request that never finishes arriving is answered 408 once its 10 s are up, and a
/// malformed one 400, each with the connection closed: none holds a thread for longer.
#[test]
fn requests_that_never_arrive_are_timed_out() {
    let (_dir, scene) = seed_scene();
    let s = Server::start(&scene);
    let mut c = TcpStream::connect(("127.0.0.1", s.port)).unwrap();
    c.set_read_timeout(Some(std::time::Duration::from_secs(60))).unwrap();
    let head = format!("POST /api/check HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Length: 100\r\n\r\nx", s.port);
    c.write_all(head.as_bytes()).unwrap();
    let mut reply = Vec::new();
    let _ = c.read_to_end(&mut reply);
    let reply = String::from_utf8_lossy(&reply);
    assert!(reply.starts_with("HTTP/1.1 408"), "{reply}");
    let (status, _) = s.raw("GET", "/", &[("Content-Length", "x")], b"");
    assert_eq!(status, 400);
}

/// Under light transport the preview converges: after the first image, passes of ever
/// more samples arrive, each with a `P` message of the samples a pixel has (doubling up
/// to the studio's 4,096) and a noise estimate that falls; a newer request stops the
/// accumulation at once.
#[test]
fn light_transport_converges_while_idle_and_an_edit_restarts_it() {
    let (_dir, scene) = seed_scene();
    let s = Server::start(&scene);
    let glow = "camera(position = [0, 0, -4], look_at = [0, 0, 0])\nrender(width = 8, height = 8)\n\
                object sphere(1) with material(emission = rgb(255, 128, 0))\nobject box(3, 0.1, 3) at [0, -1.2, 0]\n";
    let (status, body) = s.post("/api/render?coarse=1", glow);
    assert_eq!(status, 200);
    let passes: Vec<serde_json::Value> = messages(&body)
        .into_iter()
        .filter(|(k, _)| *k == b'P')
        .map(|(_, p)| serde_json::from_slice(&p).expect("a P message is JSON"))
        .collect();
    let samples: Vec<u64> = passes.iter().map(|p| p["samples"].as_u64().expect("samples")).collect();
    assert_eq!(samples, (1..=12).map(|k| 1u64 << k).collect::<Vec<_>>(), "doubling to 4,096");
    let noise = |i: usize| passes[i]["noise_percent"].as_f64().expect("noise");
    // The first pass, of one sample a pixel, has no estimate; from 4 to 4,096 samples
    // the noise falls as the root of their ratio, 32 times.
    assert!(passes[0]["noise_percent"].is_null());
    assert!(noise(11) < noise(1) / 8.0, "the noise falls: {} then {}", noise(1), noise(11));
    // The film's sums are added exactly: the last image is `scnc render`'s of as many
    // samples, pixel for pixel.
    let last = messages(&body).into_iter().rev().find(|(k, _)| *k == b'B').expect("an image").1;
    let shown = image::RgbImage::from_raw(8, 8, last[12..].to_vec()).expect("an 8×8 image");
    let file = scene.with_file_name("glow.scn");
    std::fs::write(&file, glow.replace("height = 8)", "height = 8, samples = 4096)")).unwrap();
    if let Some(d) = image_difference("converged", &shown, &rendered(&file)) {
        panic!("4,096 samples in the studio differ from `scnc render --samples 4096`: {d}");
    }

    // A larger image converges for long; a light render sent meanwhile comes back at
    // once, and the accumulation is told it was overtaken.
    let big = glow.replace("width = 8, height = 8", "width = 128, height = 128");
    let (mut c, mut got) = stream_until(&s, "/api/render?coarse=1", &big, b"\"samples\"");
    light_render_comes_back(&s, "a converging render");
    let mut rest = Vec::new();
    let _ = c.read_to_end(&mut rest);
    got.extend_from_slice(&rest);
    assert!(got.windows(7).any(|w| w == b"X\x02\0\0\0{}"), "the accumulation was not stopped");
}
