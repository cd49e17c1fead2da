//! HTTP/1.1 for the studio, by hand: one request per connection (`Connection: close`),
//! bodies by `Content-Length`, replies whole or chunked: what a page on localhost needs,
//! with what a server facing slow or hostile clients needs. A request must arrive, head
//! and body, within [`DEADLINE`] of its connection; every read waits only for what is
//! left of it; a refused body is never read. (tiny_http, used before, kept a thread on
//! each connection whose body never came, and its pool could starve new connections
//! behind them.)

use std::io::{Read, Write};
use std::net::{Shutdown, SocketAddr, TcpStream};
use std::time::{Duration, Instant};

/// Largest request body: a scene's source limit and room for the query.
const MAX_BODY: u64 = scnc::source::MAX_FILE_BYTES as u64 + 4096;

/// Largest request head (line and headers).
const MAX_HEAD: usize = 16 * 1024;

/// How long a request, head and body, may take to arrive from the moment its connection
/// is accepted: past it the connection is answered 408 and closed.
pub(crate) const DEADLINE: Duration = Duration::from_secs(10);

/// A request with its path and query split.
pub(crate) struct Req {
    conn: Option<Conn>,
    path: String,
    query: Vec<(String, String)>,
}

/// A connection whose request head has been read.
struct Conn {
    stream: TcpStream,
    method: String,
    headers: Vec<(String, String)>,
    /// The body's length (`Content-Length`; 0 without one).
    body_len: u64,
    /// Body bytes read with the head.
    pending: Vec<u8>,
    /// When the connection was accepted.
    started: Instant,
}

impl Conn {
    fn new(stream: TcpStream) -> Conn {
        Conn {
            stream,
            method: String::new(),
            headers: Vec::new(),
            body_len: 0,
            pending: Vec::new(),
            started: Instant::now(),
        }
    }

    /// Reads into `buf` within what is left of the deadline; `None` past it or when the
    /// client has gone.
    fn read_some(&mut self, buf: &mut [u8]) -> Option<usize> {
        let left = DEADLINE.checked_sub(self.started.elapsed()).filter(|d| !d.is_zero())?;
        self.stream.set_read_timeout(Some(left)).ok()?;
        match self.stream.read(buf) {
            Ok(0) | Err(_) => None,
            Ok(n) => Some(n),
        }
    }

    /// Every value of the header `name`, in the order sent.
    fn header_values(&self, name: &str) -> Vec<&str> {
        self.headers.iter().filter(|(k, _)| k.eq_ignore_ascii_case(name)).map(|(_, v)| v.as_str()).collect()
    }
}

/// Reads the request head of a new connection within [`DEADLINE`]: the request, or
/// `None` after answering one that is malformed, too large or too slow (or finding the
/// client gone).
pub(crate) fn accept(stream: TcpStream) -> Option<Req> {
    let _ = stream.set_nodelay(true);
    let mut conn = Conn::new(stream);
    let mut buf = vec![0u8; MAX_HEAD];
    let mut have = 0;
    let end = loop {
        if let Some(i) = buf[..have].windows(4).position(|w| w == b"\r\n\r\n") {
            break i;
        }
        if have == MAX_HEAD {
            return refuse(conn, Reply::text(431, "the request head is larger than 16 KiB"));
        }
        let Some(n) = conn.read_some(&mut buf[have..]) else {
            let late = conn.started.elapsed() >= DEADLINE;
            return if late { refuse(conn, Reply::text(408, "the request did not arrive in time")) } else { None };
        };
        have += n;
    };
    conn.pending = buf[end + 4..have].to_vec();
    let Ok(head) = std::str::from_utf8(&buf[..end]) else {
        return refuse(conn, Reply::text(400, "the request head is not text"));
    };
    let mut lines = head.split("\r\n");
    let first: Vec<&str> = lines.next().unwrap_or("").split(' ').collect();
    let [method, target, version] = first[..] else {
        return refuse(conn, Reply::text(400, "a malformed request line"));
    };
    if !version.starts_with("HTTP/1.") {
        return refuse(conn, Reply::text(400, "a malformed request line"));
    }
    for line in lines {
        let Some((k, v)) = line.split_once(':') else {
            return refuse(conn, Reply::text(400, "a malformed header"));
        };
        conn.headers.push((k.trim().to_string(), v.trim().to_string()));
    }
    conn.method = method.to_ascii_uppercase();
    let length = match conn.header_values("Content-Length")[..] {
        [] => Some(0),
        [l] => l.parse::<u64>().ok(),
        _ => None,
    };
    let Some(length) = length else {
        return refuse(conn, Reply::text(400, "a malformed or repeated `Content-Length`"));
    };
    if !conn.header_values("Transfer-Encoding").is_empty() {
        return refuse(conn, Reply::text(411, "request bodies are read by `Content-Length`, not chunked"));
    }
    conn.body_len = length;
    let target = target.to_string();
    let (path, query) = target.split_once('?').unwrap_or((&target, ""));
    let query = query
        .split('&')
        .filter(|kv| !kv.is_empty())
        .map(|kv| {
            let (k, v) = kv.split_once('=').unwrap_or((kv, ""));
            (percent_decode(k), percent_decode(v))
        })
        .collect();
    Some(Req { path: path.to_string(), query, conn: Some(conn) })
}

/// Answers `conn` with `reply` and gives no request.
fn refuse(conn: Conn, reply: Reply) -> Option<Req> {
    Req { conn: Some(conn), path: String::new(), query: Vec::new() }.reply(reply);
    None
}

/// Answers a connection whose request is not even read (the server is full): `reply`,
/// written with a short timeout, so that a client not reading cannot hold the caller.
pub(crate) fn turn_away(stream: TcpStream, reply: Reply) {
    let _ = stream.set_write_timeout(Some(Duration::from_millis(200)));
    Req { conn: Some(Conn::new(stream)), path: String::new(), query: Vec::new() }.reply(reply);
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
    /// `GET`, `POST`, …
    pub(crate) fn method(&self) -> String {
        self.conn.as_ref().map_or_else(String::new, |c| c.method.clone())
    }

    /// Whether the request carries a body.
    pub(crate) fn has_body(&self) -> bool {
        self.conn.as_ref().is_some_and(|c| c.body_len > 0)
    }

    /// The client's address.
    pub(crate) fn client(&self) -> Option<SocketAddr> {
        self.conn.as_ref().and_then(|c| c.stream.peer_addr().ok())
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
        let Some(c) = self.conn.as_ref() else { return Vec::new() };
        c.header_values(name).into_iter().map(str::to_string).collect()
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

    /// The body as text, or the reply that refuses it: too large (refused before a byte
    /// of it is read), not arrived within [`DEADLINE`] of the connection, not UTF-8.
    pub(crate) fn body(&mut self) -> Result<String, Reply> {
        let Some(conn) = self.conn.as_mut() else { return Err(Reply::text(400, "no request")) };
        if conn.body_len > MAX_BODY {
            return Err(Reply::text(413, "the request body is larger than a scene may be (4 MiB)"));
        }
        if conn.header_values("Expect").iter().any(|e| e.eq_ignore_ascii_case("100-continue")) {
            let _ = conn.stream.write_all(b"HTTP/1.1 100 Continue\r\n\r\n");
        }
        let len = conn.body_len as usize;
        let mut bytes = std::mem::take(&mut conn.pending);
        bytes.truncate(len);
        let mut buf = vec![0u8; 64 * 1024];
        while bytes.len() < len {
            let want = (len - bytes.len()).min(buf.len());
            let Some(n) = conn.read_some(&mut buf[..want]) else {
                let message = format!("the request body did not arrive within {} s", DEADLINE.as_secs());
                return Err(Reply::text(408, &message));
            };
            bytes.extend_from_slice(&buf[..n]);
        }
        String::from_utf8(bytes).map_err(|_| Reply::text(400, "the request body is not UTF-8 text"))
    }

    /// Sends `reply` and closes the connection; a client that went away is no error of
    /// ours. A `HEAD` request gets the head alone.
    pub(crate) fn reply(mut self, reply: Reply) {
        let Some(mut conn) = self.conn.take() else { return };
        let mut head = format!(
            "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nX-Content-Type-Options: nosniff\r\n\
             Cache-Control: {}\r\nConnection: close\r\n",
            reply.status,
            reason(reply.status),
            reply.content_type,
            reply.body.len(),
            if reply.cache { "max-age=3600" } else { "no-store" }
        );
        if let Some(name) = &reply.download {
            head.push_str(&format!("Content-Disposition: attachment; filename=\"{name}\"\r\n"));
        }
        head.push_str("\r\n");
        let _ = conn.stream.write_all(head.as_bytes());
        if conn.method != "HEAD" {
            let _ = conn.stream.write_all(&reply.body);
        }
        close(conn.stream);
    }

    /// Starts a streamed reply: chunked, flushed message by message, ended by dropping
    /// the stream. `None` when the client is already gone.
    pub(crate) fn stream(mut self, content_type: &str) -> Option<Stream> {
        let conn = self.conn.take()?;
        let mut w = conn.stream;
        let head = format!(
            "HTTP/1.1 200 OK\r\nContent-Type: {content_type}\r\nCache-Control: no-store\r\n\
             X-Content-Type-Options: nosniff\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\n"
        );
        w.write_all(head.as_bytes()).ok()?;
        w.flush().ok()?;
        Some(Stream { w })
    }
}

/// Closes a connection after its reply: the write side first, then what the client may
/// still be sending (a body refused unread) is read off for a moment, so that the close
/// is not a reset that could discard the reply before the client reads it.
fn close(mut stream: TcpStream) {
    let _ = stream.shutdown(Shutdown::Write);
    let _ = stream.set_read_timeout(Some(Duration::from_millis(100)));
    let mut sink = [0u8; 4096];
    let until = Instant::now() + Duration::from_millis(200);
    while Instant::now() < until {
        match stream.read(&mut sink) {
            Ok(0) | Err(_) => break,
            Ok(_) => {}
        }
    }
}

/// The reason phrase of `status`.
fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        411 => "Length Required",
        413 => "Content Too Large",
        429 => "Too Many Requests",
        431 => "Request Header Fields Too Large",
        500 => "Internal Server Error",
        503 => "Service Unavailable",
        _ => "",
    }
}

impl Drop for Req {
    fn drop(&mut self) {
        // A request dropped unanswered (a handler that returned early) is told so.
        if self.conn.is_some() {
            let unanswered = Req { conn: self.conn.take(), path: String::new(), query: Vec::new() };
            unanswered.reply(Reply::text(500, "not answered"));
        }
    }
}

/// A chunked reply being written.
pub(crate) struct Stream {
    w: TcpStream,
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
