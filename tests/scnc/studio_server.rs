//! A studio server under test and what its tests share: shared by the HTTP tests
//! (`tests/scnc/studio.rs`) and the browser tests (`tests/tools/`), which include this
//! file by path.

use std::io::{Read as _, Write as _};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A studio server on a free port, killed when dropped.
pub struct Server {
    child: Child,
    /// Where it listens, on 127.0.0.1.
    pub port: u16,
}

impl Server {
    /// Starts `scnc studio` on `file`, waiting (up to 20 s) for its port.
    pub fn start(file: &Path) -> Server {
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

    /// Sends one raw request (its `Host` is this server's unless `host` is given): the
    /// status and body.
    pub fn raw(&self, method: &str, path: &str, headers: &[(&str, &str)], body: &[u8]) -> (u16, Vec<u8>) {
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

    /// A POST of `body`: the status and body.
    pub fn post(&self, path: &str, body: &str) -> (u16, Vec<u8>) {
        self.raw("POST", path, &[], body.as_bytes())
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The body of a chunked reply, joined.
pub fn dechunk(mut b: &[u8]) -> Vec<u8> {
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
pub fn seed_scene() -> (tempfile::TempDir, PathBuf) {
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
pub fn messages(mut b: &[u8]) -> Vec<(u8, Vec<u8>)> {
    let mut out = Vec::new();
    while b.len() >= 5 {
        let n = u32::from_le_bytes(b[1..5].try_into().unwrap()) as usize;
        out.push((b[0], b[5..5 + n].to_vec()));
        b = &b[5 + n..];
    }
    out
}

/// The RGB pixels of `scnc render` of `scene`.
pub fn rendered(scene: &Path) -> image::RgbImage {
    let png = scene.with_file_name("reference.png");
    let out = Command::new(env!("CARGO_BIN_EXE_scnc")).arg("render").arg(scene).arg("-o").arg(&png).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    image::open(&png).unwrap().to_rgb8()
}

/// Where the end-to-end test leaves its screenshots.
pub fn artefacts() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("studio-screenshots");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Two images compared for a test's message: equal, or what differs (size, how many
/// pixels, by how much at most) with both written to [`artefacts`] under `name`, never
/// the pixels themselves.
pub fn image_difference(name: &str, a: &image::RgbImage, b: &image::RgbImage) -> Option<String> {
    if a == b {
        return None;
    }
    let dir = artefacts();
    let (pa, pb) = (dir.join(format!("{name}-a.png")), dir.join(format!("{name}-b.png")));
    let _ = a.save(&pa);
    let _ = b.save(&pb);
    if a.dimensions() != b.dimensions() {
        return Some(format!(
            "sizes {:?} and {:?}; written to {} and {}",
            a.dimensions(),
            b.dimensions(),
            pa.display(),
            pb.display()
        ));
    }
    let diffs: Vec<u8> = a
        .pixels()
        .zip(b.pixels())
        .map(|(x, y)| x.0.iter().zip(y.0).map(|(p, q)| p.abs_diff(q)).max().unwrap_or(0))
        .filter(|&d| d > 0)
        .collect();
    Some(format!(
        "{} of {} pixels differ, by up to {}/255; written to {} and {}",
        diffs.len(),
        a.len() / 3,
        diffs.iter().max().copied().unwrap_or(0),
        pa.display(),
        pb.display()
    ))
}
