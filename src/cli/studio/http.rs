//! Requests and replies over tiny_http, and the one stream format the page reads.

use std::io::{Read, Write};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

/// Largest request body: a scene's source limit and room for the query.
const MAX_BODY: u64 = scnc::source::MAX_FILE_BYTES as u64 + 4096;

/// How long a request's body may take to arrive: past it the handler gives up on it
/// (a page sends its few kilobytes at once).
pub(crate) const BODY_DEADLINE: Duration = Duration::from_secs(10);

/// Bodies read at once, given up on or not: a reader waits on its client until the
/// body arrives or the connection closes, so a client that never sends one holds a
/// thread, and past this many new bodies are refused.
const MAX_READERS: usize = 64;

/// Readers running, over the whole server.
static READERS: AtomicUsize = AtomicUsize::new(0);

/// A request with its path and query split.
pub(crate) struct Req {
    inner: Option<tiny_http::Request>,
    path: String,
    query: Vec<(String, String)>,
}

/// A whole reply.
pub(crate) struct Reply {
    status: u16,
    content_type: &'static str,
    body: Vec<u8>,
    /// A `Content-Disposition` file name: the browser downloads the body.
    download: Option<String>,
    /// Assets may be cached by the browser for the life of the server.
    cache: bool,
}

impl Reply {
    /// Plain text (errors).
    pub(crate) fn text(status: u16, text: &str) -> Reply {
        Reply {
            status,
            content_type: "text/plain; charset=utf-8",
            body: text.as_bytes().to_vec(),
            download: None,
            cache: false,
        }
    }

    /// A JSON value.
    pub(crate) fn json(value: &serde_json::Value) -> Reply {
        Reply {
            status: 200,
            content_type: "application/json",
            body: value.to_string().into_bytes(),
            download: None,
            cache: false,
        }
    }

    /// A page asset.
    pub(crate) fn asset(content_type: &'static str, text: &'static str) -> Reply {
        Reply { status: 200, content_type, body: text.as_bytes().to_vec(), download: None, cache: true }
    }

    /// A file to download under `name`.
    pub(crate) fn download(content_type: &'static str, name: String, body: Vec<u8>) -> Reply {
        Reply { status: 200, content_type, body, download: Some(name), cache: false }
    }
}

impl Req {
    pub(crate) fn new(inner: tiny_http::Request) -> Req {
        let url = inner.url().to_string();
        let (path, query) = url.split_once('?').unwrap_or((&url, ""));
        let query = query
            .split('&')
            .filter(|kv| !kv.is_empty())
            .map(|kv| {
                let (k, v) = kv.split_once('=').unwrap_or((kv, ""));
                (percent_decode(k), percent_decode(v))
            })
            .collect();
        Req { path: path.to_string(), query, inner: Some(inner) }
    }

    /// `GET`, `POST`, …
    pub(crate) fn method(&self) -> String {
        self.inner.as_ref().map_or_else(String::new, |r| r.method().as_str().to_ascii_uppercase())
    }

    /// The path, as sent (never decoded, so `/%2e%2e/` is no path of ours either).
    pub(crate) fn path(&self) -> &str {
        &self.path
    }

    /// A query parameter.
    pub(crate) fn query(&self, key: &str) -> Option<&str> {
        self.query.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    /// A query parameter as a number (0 when absent or malformed).
    pub(crate) fn query_u32(&self, key: &str) -> u32 {
        self.query(key).and_then(|v| v.parse().ok()).unwrap_or(0)
    }

    /// A query parameter as a finite number.
    pub(crate) fn query_f64(&self, key: &str) -> Option<f64> {
        self.query(key).and_then(|v| v.parse::<f64>().ok()).filter(|x| x.is_finite())
    }

    /// Every value of the header `name`, in the order sent.
    fn headers(&self, name: &str) -> Vec<String> {
        let Some(r) = self.inner.as_ref() else { return Vec::new() };
        r.headers()
            .iter()
            .filter(|h| h.field.as_str().as_str().eq_ignore_ascii_case(name))
            .map(|h| h.value.as_str().to_string())
            .collect()
    }

    /// `Ok` when the request names this server in `Host` and, if it says where it comes
    /// from, comes from a page of this server: what stops a site in another tab (or one
    /// rebound to 127.0.0.1) from reading or changing the file. The refusal: 400 for a
    /// request that sends `Host` or `Origin` twice (RFC 9112: which one a proxy and this
    /// server would each believe is not to be guessed), 403 for a foreign one.
    pub(crate) fn same_origin(&self, hosts: &[String]) -> Result<(), Reply> {
        let (host, origin) = (self.headers("Host"), self.headers("Origin"));
        if host.len() > 1 || origin.len() > 1 {
            return Err(Reply::text(400, "refused: a request with more than one `Host` or `Origin` header"));
        }
        let host = host.first().map_or("", String::as_str);
        if !hosts.iter().any(|h| h.eq_ignore_ascii_case(host)) {
            return Err(Reply::text(
                403,
                &format!("refused: `Host: {host}` is not this server ({})", hosts.join(", ")),
            ));
        }
        if let Some(origin) = origin.first() {
            let ours = hosts.iter().any(|h| origin.eq_ignore_ascii_case(&format!("http://{h}")));
            if !ours {
                return Err(Reply::text(
                    403,
                    &format!("refused: a request from `{origin}`, not from this server's page"),
                ));
            }
        }
        Ok(())
    }

    /// The body as text, or the reply that refuses it (too large, not UTF-8, not
    /// arrived within [`BODY_DEADLINE`]: then the handler's slot is free again, and the
    /// client gets no reply).
    ///
    /// The body is read on a thread of its own, as tiny_http's sockets have no read
    /// timeout; a reader given up on ends when its client sends or closes.
    pub(crate) fn body(&mut self) -> Result<String, Reply> {
        let Some(mut inner) = self.inner.take() else { return Err(Reply::text(400, "no request")) };
        if READERS.fetch_add(1, Ordering::AcqRel) >= MAX_READERS {
            READERS.fetch_sub(1, Ordering::AcqRel);
            self.inner = Some(inner);
            return Err(Reply::text(503, "too many request bodies are arriving at once; try again"));
        }
        let (tx, rx) = std::sync::mpsc::channel();
        let reader = std::thread::Builder::new().name("studio-body".into()).spawn(move || {
            let mut bytes = Vec::new();
            let read = inner.as_reader().take(MAX_BODY + 1).read_to_end(&mut bytes);
            READERS.fetch_sub(1, Ordering::AcqRel);
            let _ = tx.send((inner, read.map(|_| bytes)));
        });
        if reader.is_err() {
            READERS.fetch_sub(1, Ordering::AcqRel);
            return Err(Reply::text(503, "the system would not start a thread to read the request; try again"));
        }
        let (inner, read) = rx.recv_timeout(BODY_DEADLINE).map_err(|_| {
            Reply::text(408, &format!("the request body did not arrive within {} s", BODY_DEADLINE.as_secs()))
        })?;
        self.inner = Some(inner);
        let Ok(bytes) = read else {
            return Err(Reply::text(400, "the request body could not be read"));
        };
        if bytes.len() as u64 > MAX_BODY {
            return Err(Reply::text(413, "the request body is larger than a scene may be (4 MiB)"));
        }
        String::from_utf8(bytes).map_err(|_| Reply::text(400, "the request body is not UTF-8 text"))
    }

    /// Sends `reply`; a client that went away is no error of ours.
    pub(crate) fn reply(mut self, reply: Reply) {
        let Some(inner) = self.inner.take() else { return };
        let mut response = tiny_http::Response::from_data(reply.body).with_status_code(reply.status);
        let mut add = |k: &str, v: &str| {
            if let Ok(h) = tiny_http::Header::from_bytes(k.as_bytes(), v.as_bytes()) {
                response.add_header(h);
            }
        };
        add("Content-Type", reply.content_type);
        add("X-Content-Type-Options", "nosniff");
        add("Cache-Control", if reply.cache { "max-age=3600" } else { "no-store" });
        if let Some(name) = &reply.download {
            add("Content-Disposition", &format!("attachment; filename=\"{name}\""));
        }
        let _ = inner.respond(response);
    }

    /// Starts a streamed reply: chunked, flushed message by message, ended by dropping
    /// the stream. `None` when the client is already gone.
    pub(crate) fn stream(mut self, content_type: &str) -> Option<Stream> {
        let inner = self.inner.take()?;
        let mut w = inner.into_writer();
        let head = format!(
            "HTTP/1.1 200 OK\r\nContent-Type: {content_type}\r\nCache-Control: no-store\r\n\
             X-Content-Type-Options: nosniff\r\nTransfer-Encoding: chunked\r\n\r\n"
        );
        w.write_all(head.as_bytes()).ok()?;
        w.flush().ok()?;
        Some(Stream { w })
    }
}

impl Drop for Req {
    fn drop(&mut self) {
        // A request dropped unanswered (a handler that returned early) is told so.
        if let Some(inner) = self.inner.take() {
            let _ = inner.respond(tiny_http::Response::from_string("not answered").with_status_code(500));
        }
    }
}

/// A chunked reply being written.
pub(crate) struct Stream {
    w: Box<dyn Write + Send>,
}

impl Stream {
    /// Sends one chunk now; an error means the client has gone.
    pub(crate) fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        if bytes.is_empty() {
            return Ok(());
        }
        write!(self.w, "{:x}\r\n", bytes.len())?;
        self.w.write_all(bytes)?;
        self.w.write_all(b"\r\n")?;
        self.w.flush()
    }

    /// Sends a message of the render stream: a kind byte, the payload's length (u32,
    /// little-endian) and the payload (see `assets/studio.js`, `readMessages`).
    pub(crate) fn message(&mut self, kind: u8, payload: &[u8]) -> std::io::Result<()> {
        // One chunk, written in place: a band is megabytes, not worth copying.
        write!(self.w, "{:x}\r\n", payload.len() + 5)?;
        self.w.write_all(&[kind])?;
        self.w.write_all(&(payload.len() as u32).to_le_bytes())?;
        self.w.write_all(payload)?;
        self.w.write_all(b"\r\n")?;
        self.w.flush()
    }
}

impl Drop for Stream {
    fn drop(&mut self) {
        let _ = self.w.write_all(b"0\r\n\r\n");
        let _ = self.w.flush();
    }
}

/// `%XX` escapes and `+` decoded; invalid escapes kept as they are.
fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'%' if i + 2 < bytes.len() => match (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                (Some(hi), Some(lo)) => {
                    out.push(hi << 4 | lo);
                    i += 3;
                    continue;
                }
                _ => out.push(b'%'),
            },
            b'+' => out.push(b' '),
            b => out.push(b),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn hex(b: u8) -> Option<u8> {
    (b as char).to_digit(16).map(|d| d as u8)
}

#[cfg(test)]
mod tests {
    use super::percent_decode;

    #[test]
    fn query_values_are_decoded() {
        assert_eq!(percent_decode("a%20b+c"), "a b c");
        assert_eq!(percent_decode("%2e%2E"), "..");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("%zz"), "%zz");
        assert_eq!(percent_decode("%e2%82%ac"), "€");
    }
}
