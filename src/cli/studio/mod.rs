//! `scnc studio`: a local web page that edits one scene and renders it as you type.
//!
//! - this file: the command, the server loop and the rules every request passes first
//!   (its `Host` and `Origin` are the server's own, its body is bounded, its path is one
//!   of a fixed set: nothing is served from the disk by name);
//! - [`http`]: requests and responses, streamed ones included;
//! - [`diagnostics`]: diagnostics and text positions as the page counts them;
//! - [`edit`]: the editor's questions (check, hover, completion, format, save, the
//!   camera line) and export;
//! - [`examples`]: the Examples menu and the scene a new file starts from;
//! - [`preview`]: renders, coarse first then the full frame in bands, the newest
//!   request winning;
//! - [`files`]: the one file it edits, the includes below its directory, and the
//!   watcher that tells the page when they change on disk.

mod diagnostics;
mod edit;
mod examples;
mod files;
mod http;
mod preview;

use std::collections::HashMap;
use std::io::Write;
use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use files::lock;
use http::{Reply, Req};

use super::shared::{Params, Workers};
use super::usage_error;

#[derive(clap::Args)]
pub(crate) struct StudioArgs {
    /// The scene file to edit; it need not exist yet (the first save writes it).
    #[arg(default_value = "scene.scn")]
    file: PathBuf,
    /// The port to listen on; 0 picks a free one.
    #[arg(long, default_value = "7117")]
    port: u16,
    /// The address to listen on. Anything but a loopback address lets other machines
    /// edit and render this file: say so explicitly.
    #[arg(long, default_value = "127.0.0.1")]
    host: IpAddr,
    #[command(flatten)]
    workers: Workers,
    #[command(flatten)]
    params: Params,
    /// Write the port listened on to this file (for tests and scripts with `--port 0`).
    #[arg(long, hide = true)]
    port_file: Option<PathBuf>,
}

/// Connections open at once (a page keeps a few, and each must send its request within
/// `http::DEADLINE`); more are turned away with 503.
const MAX_CONNECTIONS: usize = 64;

/// Requests with a body handled at once for one client address; more are refused with
/// 429, so one client sending bodies slowly cannot take every slot.
const MAX_BODIES_PER_CLIENT: usize = 8;

/// What every request handler shares.
pub(crate) struct Studio {
    /// The file, its directory and the watcher's subscribers.
    files: files::Files,
    /// `Host` header values that name this server.
    hosts: Vec<String>,
    /// Renders: the newest wins.
    preview: preview::Previews,
}

pub(crate) fn studio_cmd(args: StudioArgs) -> ExitCode {
    let set = match args.params.overrides() {
        Ok(set) => set,
        Err(e) => return usage_error(&e),
    };
    let files = match files::Files::open(&args.file, set) {
        Ok(f) => f,
        Err(e) => return usage_error(&e),
    };
    let pool = match args.workers.pool() {
        Ok(p) => p,
        Err(e) => return usage_error(&e),
    };
    let server = match std::net::TcpListener::bind(SocketAddr::new(args.host, args.port)) {
        Ok(s) => s,
        Err(e) => {
            return usage_error(&format!(
                "cannot listen on {}: {e}{}",
                SocketAddr::new(args.host, args.port),
                if args.port != 0 { " (try another --port, or --port 0 for any free one)" } else { "" }
            ))
        }
    };
    let Ok(addr) = server.local_addr() else {
        return usage_error("the server has no IP address");
    };
    if !args.host.is_loopback() {
        let _ = writeln!(
            std::io::stderr(),
            "warning: listening on {}: anyone who can reach this machine can read, change and render `{}`",
            args.host,
            args.file.display()
        );
    }
    let studio = Arc::new(Studio { hosts: own_hosts(addr), files, preview: preview::Previews::new(pool) });
    studio.files.start_watching(&studio);
    let url = format!("http://{}/", display_addr(addr));
    if let Some(path) = &args.port_file {
        if let Err(e) = super::files::write_text(path, &format!("{}\n", addr.port())) {
            return usage_error(&super::files::cannot_write(path, &e));
        }
    }
    let _ = writeln!(std::io::stderr(), "scnc studio: editing {} at {url} (Ctrl-C ends it)", args.file.display());
    serve(&server, &studio);
    ExitCode::SUCCESS
}

/// The address as a URL writes it (an IPv6 one in brackets).
fn display_addr(addr: SocketAddr) -> String {
    match addr {
        SocketAddr::V4(a) => a.to_string(),
        SocketAddr::V6(a) => format!("[{}]:{}", a.ip(), a.port()),
    }
}

/// The `Host` values a browser sends to this server: its address, and `localhost` when
/// it listens on loopback. A page served from any other name (a DNS-rebinding attack
/// points one at 127.0.0.1) is refused.
fn own_hosts(addr: SocketAddr) -> Vec<String> {
    let port = addr.port();
    let mut hosts = vec![display_addr(addr)];
    if addr.ip().is_loopback() {
        hosts.push(format!("localhost:{port}"));
    }
    if addr.ip().is_unspecified() {
        hosts.push(format!("127.0.0.1:{port}"));
        hosts.push(format!("localhost:{port}"));
    }
    hosts
}

fn serve(server: &std::net::TcpListener, studio: &Arc<Studio>) {
    let open = Arc::new(AtomicUsize::new(0));
    let per_client: Arc<Mutex<HashMap<IpAddr, usize>>> = Arc::default();
    for stream in server.incoming() {
        let Ok(stream) = stream else { continue };
        // The accept loop never waits on a client: past the limit a connection is
        // turned away at once, and each is read within its deadline on its own thread.
        if open.fetch_add(1, Ordering::AcqRel) >= MAX_CONNECTIONS {
            open.fetch_sub(1, Ordering::AcqRel);
            http::turn_away(stream, Reply::text(503, "the studio has too many connections open; try again"));
            continue;
        }
        let (studio, done, per_client) = (Arc::clone(studio), Arc::clone(&open), Arc::clone(&per_client));
        let run = move || {
            if let Some(req) = http::accept(stream) {
                // A handler that panics loses its request, never the server.
                let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| admit(&studio, req, &per_client)));
            }
            done.fetch_sub(1, Ordering::AcqRel);
        };
        if let Err(e) = std::thread::Builder::new().name("studio-request".into()).spawn(run) {
            // The closure (and its count) went with the failed spawn.
            let _ = writeln!(std::io::stderr(), "scnc studio: cannot start a thread for a request: {e}");
            open.fetch_sub(1, Ordering::AcqRel);
        }
    }
}

/// Handles `req` unless its client already has [`MAX_BODIES_PER_CLIENT`] requests
/// with a body in hand (429, the body unread).
fn admit(studio: &Arc<Studio>, req: Req, per_client: &Mutex<HashMap<IpAddr, usize>>) {
    let Some(ip) = req.client().map(|a| a.ip()).filter(|_| req.has_body()) else {
        return handle(studio, req);
    };
    {
        let mut clients = lock(per_client);
        let n = clients.entry(ip).or_insert(0);
        if *n >= MAX_BODIES_PER_CLIENT {
            drop(clients);
            return req.reply(Reply::text(429, "too many requests at once from this client"));
        }
        *n += 1;
    }
    handle(studio, req);
    let mut clients = lock(per_client);
    if let Some(n) = clients.get_mut(&ip) {
        *n -= 1;
        if *n == 0 {
            clients.remove(&ip);
        }
    }
}

/// The assets of the page, compiled into the binary.
const INDEX_HTML: &str = include_str!("assets/index.html");
const STUDIO_JS: &str = include_str!("assets/studio.js");
const STUDIO_CSS: &str = include_str!("assets/studio.css");
/// CodeMirror 6, bundled by `studio/` (`npm ci && npm run build`).
const EDITOR_JS: &str = include_str!("assets/editor.js");
/// The tab's icon (browsers ask for `/favicon.ico` when a page names none).
const FAVICON: &str = include_str!("assets/favicon.svg");

fn handle(studio: &Arc<Studio>, mut req: Req) {
    if let Err(refused) = req.same_origin(&studio.hosts) {
        return req.reply(refused);
    }
    let method = req.method();
    let path = req.path().to_string();
    // HEAD is answered as GET is (`Req::reply` leaves the body out).
    let get = if method == "HEAD" { "GET" } else { method.as_str() };
    let reply = match (get, path.as_str()) {
        ("GET", "/") => Reply::asset("text/html; charset=utf-8", INDEX_HTML),
        ("GET", "/assets/studio.js") => Reply::asset("text/javascript; charset=utf-8", STUDIO_JS),
        ("GET", "/assets/studio.css") => Reply::asset("text/css; charset=utf-8", STUDIO_CSS),
        ("GET", "/assets/editor.js") => Reply::asset("text/javascript; charset=utf-8", EDITOR_JS),
        ("GET", "/favicon.svg" | "/favicon.ico") => Reply::asset("image/svg+xml", FAVICON),
        ("GET", "/api/file") => edit::file(studio),
        ("GET", "/api/examples") => Reply::json(&examples::json()),
        ("GET", "/api/formats") => edit::formats(),
        ("GET", "/api/events") => return studio.files.subscribe(req),
        ("POST", "/api/render") => return preview::render(studio, req),
        ("POST", path) if path.starts_with("/api/") => match req.body() {
            Ok(text) => match path {
                "/api/check" => edit::check(studio, text),
                "/api/params" => edit::params(studio, text, &page_params(&req)),
                "/api/hover" => edit::hover(studio, text, req.query_u32("pos")),
                "/api/complete" => edit::complete(studio, text, req.query_u32("pos")),
                "/api/signature" => edit::signature(studio, text, req.query_u32("pos")),
                "/api/pick" => {
                    let at = |k: &str| req.query_f64(k).unwrap_or(-1.0);
                    let view = preview::View::from_query(&req);
                    preview::pick(studio, text, &page_params(&req), &view, at("x"), at("y"))
                }
                "/api/format" => edit::format(text),
                "/api/save" => edit::save(studio, text),
                "/api/camera" => edit::camera_line(studio, text, &preview::View::from_query(&req)),
                "/api/export" => edit::export(studio, text, &page_params(&req), req.query("format").unwrap_or("stl")),
                _ => Reply::text(404, "no such page"),
            },
            Err(reply) => reply,
        },
        ("GET", _) => Reply::text(404, "no such page"),
        _ => Reply::text(405, "method not allowed"),
    };
    req.reply(reply);
}

/// The values the page's parameter controls set (the query's `set`, a JSON object of
/// names to values as text); none when it sends none or something else.
pub(crate) fn page_params(req: &Req) -> scnc::check::Overrides {
    let given: serde_json::Map<String, serde_json::Value> =
        req.query("set").and_then(|s| serde_json::from_str(s).ok()).unwrap_or_default();
    let set = given.into_iter().filter_map(|(name, value)| {
        let text = value.as_str()?.to_string();
        let origin = format!("the studio's `{name}` control ({text})");
        Some(scnc::check::Override { name, text, origin })
    });
    scnc::check::Overrides(set.collect())
}
