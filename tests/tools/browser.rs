//! A headless Chromium driven over the Chrome DevTools Protocol: just what the studio's
//! end-to-end tests need (open a page, evaluate, click, drag, type, press keys, take
//! screenshots, allow downloads), over one WebSocket.

use std::io::BufRead as _;
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{json, Value};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

/// One browser with one page.
pub struct Browser {
    child: Child,
    ws: WebSocket<MaybeTlsStream<TcpStream>>,
    next_id: u64,
    session: Option<String>,
    _profile: tempfile::TempDir,
}

impl Browser {
    /// Starts Debian's `chromium` headless with a fresh profile, as the machine's notes
    /// say it runs here (no sandbox as root, no background networking).
    pub fn launch() -> Browser {
        let profile = tempfile::tempdir().unwrap();
        let mut child = Command::new("chromium")
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--remote-debugging-port=0",
                "--window-size=1280,800",
            ])
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .arg("about:blank")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("starting chromium");
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        // Chromium says where its endpoint is on stderr; the rest is drained so it never
        // blocks on a full pipe.
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(stderr).lines().map_while(Result::ok) {
                if let Some(url) = line.strip_prefix("DevTools listening on ") {
                    let _ = tx.send(url.trim().to_string());
                }
            }
        });
        let url = rx.recv_timeout(Duration::from_secs(30)).expect("chromium printed its DevTools address");
        let (ws, _) = tungstenite::connect(url.as_str()).expect("connecting to chromium");
        if let MaybeTlsStream::Plain(s) = ws.get_ref() {
            s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        }
        Browser { child, ws, next_id: 0, session: None, _profile: profile }
    }

    /// Calls `method` (on the page once one is open, unless `browser` is set).
    fn send(&mut self, method: &str, params: Value, browser: bool) -> Value {
        self.next_id += 1;
        let id = self.next_id;
        let mut msg = json!({ "id": id, "method": method, "params": params });
        if let (Some(s), false) = (&self.session, browser) {
            msg["sessionId"] = s.clone().into();
        }
        self.ws.send(Message::text(msg.to_string())).expect("sending to chromium");
        loop {
            let reply = self.ws.read().expect("chromium answers");
            let Message::Text(t) = reply else { continue };
            let v: Value = serde_json::from_str(t.as_str()).unwrap();
            if v["id"] == id {
                assert!(v.get("error").is_none(), "{method} failed: {}", v["error"]);
                return v["result"].clone();
            }
        }
    }

    /// A DevTools command on the page.
    pub fn call(&mut self, method: &str, params: Value) -> Value {
        self.send(method, params, false)
    }

    /// Opens `url` in a new page, which later calls address.
    pub fn open(&mut self, url: &str) {
        let target = self.send("Target.createTarget", json!({ "url": url }), true);
        let attached =
            self.send("Target.attachToTarget", json!({ "targetId": target["targetId"], "flatten": true }), true);
        self.session = Some(attached["sessionId"].as_str().unwrap().to_string());
    }

    /// Lets the page download files into `dir`.
    pub fn downloads_to(&mut self, dir: &Path) {
        self.send(
            "Browser.setDownloadBehavior",
            json!({ "behavior": "allow", "downloadPath": dir.display().to_string() }),
            true,
        );
    }

    /// The value of a JavaScript expression (promises awaited).
    pub fn eval(&mut self, expression: &str) -> Value {
        let r = self
            .call("Runtime.evaluate", json!({ "expression": expression, "awaitPromise": true, "returnByValue": true }));
        assert!(r.get("exceptionDetails").is_none(), "`{expression}` threw: {}", r["exceptionDetails"]);
        r["result"]["value"].clone()
    }

    /// Waits until `expression` is truthy (checked every 25 ms) and returns how long that
    /// took; fails after `limit`.
    pub fn wait_for(&mut self, expression: &str, limit: Duration) -> Duration {
        let start = Instant::now();
        loop {
            // Before the page has loaded, its elements are not there: not yet true.
            let v =
                self.eval(&format!("(() => {{ try {{ return !!({expression}); }} catch (e) {{ return false; }} }})()"));
            if v == Value::Bool(true) {
                return start.elapsed();
            }
            assert!(start.elapsed() < limit, "`{expression}` still false after {limit:?}");
            std::thread::sleep(Duration::from_millis(25));
        }
    }

    /// The centre of the element `selector`, in page pixels.
    pub fn centre(&mut self, selector: &str) -> (f64, f64) {
        let r = self.eval(&format!(
            "(() => {{ const r = document.querySelector('{selector}').getBoundingClientRect(); \
             return [r.x + r.width / 2, r.y + r.height / 2]; }})()"
        ));
        (r[0].as_f64().unwrap(), r[1].as_f64().unwrap())
    }

    fn mouse(&mut self, kind: &str, (x, y): (f64, f64), buttons: u32) {
        let button = if kind == "mouseMoved" && buttons == 0 { "none" } else { "left" };
        self.call(
            "Input.dispatchMouseEvent",
            json!({ "type": kind, "x": x, "y": y, "button": button, "buttons": buttons, "clickCount": 1 }),
        );
    }

    /// Moves the mouse to `(x, y)` (page pixels) without pressing, as a pointer resting
    /// over something (a hover) does.
    pub fn move_to(&mut self, at: (f64, f64)) {
        self.mouse("mouseMoved", at, 0);
    }

    /// Clicks at `(x, y)`, page pixels.
    pub fn click_at(&mut self, at: (f64, f64)) {
        self.mouse("mouseMoved", at, 0);
        self.mouse("mousePressed", at, 1);
        self.mouse("mouseReleased", at, 0);
    }

    /// A left click at the centre of `selector`.
    pub fn click(&mut self, selector: &str) {
        let at = self.centre(selector);
        self.mouse("mousePressed", at, 1);
        self.mouse("mouseReleased", at, 0);
    }

    /// A left-button drag from the centre of `selector` by `(dx, dy)`, in steps.
    pub fn drag(&mut self, selector: &str, (dx, dy): (f64, f64)) {
        let (x, y) = self.centre(selector);
        self.mouse("mouseMoved", (x, y), 0);
        self.mouse("mousePressed", (x, y), 1);
        for i in 1..=8 {
            let t = i as f64 / 8.0;
            self.mouse("mouseMoved", (x + dx * t, y + dy * t), 1);
        }
        self.mouse("mouseReleased", (x + dx, y + dy), 0);
    }

    /// Types `text` where the focus is, as an input method would.
    pub fn type_text(&mut self, text: &str) {
        self.call("Input.insertText", json!({ "text": text }));
    }

    /// Presses Ctrl and a letter key.
    pub fn ctrl(&mut self, letter: char) {
        let upper = letter.to_ascii_uppercase();
        let key = json!({
            "modifiers": 2, "key": letter.to_string(), "code": format!("Key{upper}"),
            "windowsVirtualKeyCode": upper as u32, "nativeVirtualKeyCode": upper as u32,
        });
        for kind in ["rawKeyDown", "keyUp"] {
            let mut k = key.clone();
            k["type"] = kind.into();
            self.call("Input.dispatchKeyEvent", k);
        }
    }

    /// A PNG of the page.
    pub fn screenshot(&mut self, path: &Path) {
        let shot = self.call("Page.captureScreenshot", json!({ "format": "png" }));
        std::fs::write(path, base64(shot["data"].as_str().unwrap())).unwrap();
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Standard base64 (with or without padding) to bytes.
pub fn base64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let digits: Vec<u8> = text.bytes().filter(|c| *c != b'=').map(value).collect();
    let mut out = Vec::with_capacity(digits.len() * 3 / 4);
    for chunk in digits.chunks(4) {
        let n = chunk.iter().enumerate().fold(0u32, |n, (i, d)| n | (*d as u32) << (18 - 6 * i));
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

#[test]
fn base64_decodes() {
    assert_eq!(base64("aGVsbG8="), b"hello");
    assert_eq!(base64("aGk"), b"hi");
    assert_eq!(base64("YWJj"), b"abc");
}
