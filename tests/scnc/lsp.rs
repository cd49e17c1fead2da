//! `scnc lsp` spoken to as an editor would: the binary is started and fed JSON-RPC over
//! stdio. Every wait is bounded, so a hung server fails the test instead of hanging it.

use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

use serde_json::{json, Value};

const TIMEOUT: Duration = Duration::from_secs(20);

struct Client {
    child: Child,
    stdin: ChildStdin,
    incoming: Receiver<Value>,
    /// Notifications that arrived while waiting for something else.
    pending: Vec<Value>,
    next_id: i64,
}

fn read_message(r: &mut impl BufRead) -> Option<Value> {
    let mut length = None;
    loop {
        let mut line = String::new();
        if r.read_line(&mut line).ok()? == 0 {
            return None;
        }
        let line = line.trim_end();
        if line.is_empty() {
            break;
        }
        if let Some(n) = line.strip_prefix("Content-Length: ") {
            length = n.parse::<usize>().ok();
        }
    }
    let mut body = vec![0; length?];
    r.read_exact(&mut body).ok()?;
    serde_json::from_slice(&body).ok()
}

impl Client {
    fn start() -> Client {
        let mut child = Command::new(env!("CARGO_BIN_EXE_scnc"))
            .arg("lsp")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("starting scnc lsp");
        let stdin = child.stdin.take().expect("stdin");
        let mut stdout = BufReader::new(child.stdout.take().expect("stdout"));
        let (tx, incoming) = mpsc::channel();
        std::thread::spawn(move || {
            while let Some(msg) = read_message(&mut stdout) {
                if tx.send(msg).is_err() {
                    break;
                }
            }
        });
        let mut client = Client { child, stdin, incoming, pending: Vec::new(), next_id: 1 };
        let caps = client.request("initialize", json!({ "processId": null, "rootUri": null, "capabilities": {} }));
        assert_eq!(caps["capabilities"]["hoverProvider"], json!(true), "{caps}");
        client.notify("initialized", json!({}));
        client
    }

    fn send(&mut self, msg: Value) {
        let body = msg.to_string();
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).expect("writing to the server");
        self.stdin.flush().expect("flushing");
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    fn next(&mut self, deadline: Instant) -> Value {
        let left = deadline.saturating_duration_since(Instant::now());
        self.incoming.recv_timeout(left).expect("the server did not answer in time")
    }

    fn request(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        self.send(json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }));
        let deadline = Instant::now() + TIMEOUT;
        loop {
            let msg = self.next(deadline);
            if msg["id"] == json!(id) {
                assert!(msg.get("error").is_none(), "{method} failed: {msg}");
                return msg["result"].clone();
            }
            self.pending.push(msg);
        }
    }

    /// The next diagnostics published for `uri`.
    fn diagnostics(&mut self, uri: &str) -> Vec<Value> {
        let msg = self.publication(uri);
        msg["params"]["diagnostics"].as_array().cloned().unwrap_or_default()
    }

    /// The next `publishDiagnostics` message for `uri`, whole (with its version).
    fn publication(&mut self, uri: &str) -> Value {
        let deadline = Instant::now() + TIMEOUT;
        loop {
            let found = self
                .pending
                .iter()
                .position(|m| m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == json!(uri));
            if let Some(i) = found {
                return self.pending.remove(i);
            }
            let msg = self.next(deadline);
            self.pending.push(msg);
        }
    }

    fn open(&mut self, uri: &str, text: &str) {
        let doc = json!({ "uri": uri, "languageId": "scn", "version": 1, "text": text });
        self.notify("textDocument/didOpen", json!({ "textDocument": doc }));
    }

    fn at(&mut self, method: &str, uri: &str, line: u32, character: u32) -> Value {
        let mut params = json!({
            "textDocument": { "uri": uri },
            "position": { "line": line, "character": character },
        });
        if method == "textDocument/references" {
            params["context"] = json!({ "includeDeclaration": true });
        }
        self.request(method, params)
    }

    /// The hover text at a position (empty when there is none).
    fn hover(&mut self, uri: &str, line: u32, character: u32) -> String {
        let h = self.at("textDocument/hover", uri, line, character);
        h["contents"]["value"].as_str().unwrap_or_default().to_string()
    }

    fn stop(mut self) {
        self.request("shutdown", Value::Null);
        self.notify("exit", Value::Null);
        let deadline = Instant::now() + TIMEOUT;
        loop {
            if let Some(status) = self.child.try_wait().expect("waiting for the server") {
                assert!(status.success(), "scnc lsp exited with {status}");
                return;
            }
            assert!(Instant::now() < deadline, "scnc lsp did not exit after `exit`");
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn uri(path: &Path) -> String {
    scnc::lsp::text::path_to_uri(path)
}

fn range(line: u32, start: u32, end: u32) -> Value {
    json!({ "start": { "line": line, "character": start }, "end": { "line": line, "character": end } })
}

/// A comment with a 4-byte, 2-unit character before the first mistake, so a server that
/// counted bytes or characters instead of UTF-16 units would put it in the wrong place.
const SCENE: &str = "light ambient(0.2)
let ball = sphere(1)
/* 𝄞 é */ object sphere(radus = 1) at [0, 0, 5]
object bal at [2, 0, 5]
object ball at [-2, 0, 5]
";

#[test]
fn diagnostics_follow_edits_and_offer_fixes() {
    let dir = tempfile::tempdir().expect("temp dir");
    let doc = uri(&dir.path().join("scene.scn"));
    let mut c = Client::start();
    c.open(&doc, SCENE);
    let diags = c.diagnostics(&doc);
    assert_eq!(diags.len(), 2, "{diags:#?}");
    assert_eq!(diags[0]["code"], "E0302");
    assert_eq!(diags[0]["range"], range(2, 25, 30));
    assert!(diags[0]["message"].as_str().is_some_and(|m| m.contains("did you mean `r`?")), "{}", diags[0]);
    assert_eq!(diags[1]["code"], "E0200");
    assert_eq!(diags[1]["range"], range(3, 7, 10));
    assert_eq!(diags[1]["severity"], 1);

    // The quick-fix for the misspelt argument.
    let actions = c.request(
        "textDocument/codeAction",
        json!({ "textDocument": { "uri": doc }, "range": range(2, 26, 26), "context": { "diagnostics": [] } }),
    );
    let actions = actions.as_array().expect("a list of actions");
    assert_eq!(actions.len(), 1, "{actions:#?}");
    assert_eq!(actions[0]["title"], "Replace with `r`");
    assert_eq!(actions[0]["edit"]["changes"][&doc], json!([{ "range": range(2, 25, 30), "newText": "r" }]));

    // Fix one mistake: one diagnostic is left.
    let fixed = SCENE.replace("object bal ", "object ball ");
    let change = json!({ "textDocument": { "uri": doc, "version": 2 }, "contentChanges": [{ "text": fixed }] });
    c.notify("textDocument/didChange", change);
    let diags = c.diagnostics(&doc);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(diags[0]["code"], "E0302");
    c.stop();
}

#[test]
fn hover_definition_references_completion_and_symbols() {
    let dir = tempfile::tempdir().expect("temp dir");
    let lib = dir.path().join("lib.scn");
    std::fs::write(&lib, "// shared parts\nlet post(h) = cylinder(0.1, h / 2)\n").expect("writing lib.scn");
    let doc = uri(&dir.path().join("scene.scn"));
    let text = "include \"lib.scn\"
light ambient(0.2)
let ball = sphere(1) with material(color = #ff0000)
for i in 0..3 {
  object post(2) at [i, 0, 5]
}
object ball at [0, 0, 5]
object ball at [2, 0, 5]
object sphere(
";
    let mut c = Client::start();
    c.open(&doc, text);

    // Hover: a builtin's signature and doc, a name's type, an expression's type, a parameter.
    let h = c.hover(&doc, 2, 12);
    assert!(h.contains("sphere(r: num)") && h.contains("- `r`: the radius; greater than 0"), "{h}");
    let h = c.at("textDocument/hover", &doc, 6, 8);
    assert!(h["contents"]["value"].as_str().is_some_and(|v| v.contains("let ball: shape")), "{h}");
    assert_eq!(h["range"], range(6, 7, 11));
    let h = c.at("textDocument/hover", &doc, 4, 20);
    assert!(h["contents"]["value"].as_str().is_some_and(|v| v.contains("vec3")), "{h}");
    let h = c.at("textDocument/hover", &doc, 2, 37);
    assert!(h["contents"]["value"].as_str().is_some_and(|v| v.contains("color: color")), "{h}");

    // Definition: a let, a loop variable, and a function in the included file.
    let d = c.at("textDocument/definition", &doc, 7, 9);
    assert_eq!(d, json!({ "uri": doc, "range": range(2, 4, 8) }));
    let d = c.at("textDocument/definition", &doc, 4, 21);
    assert_eq!(d, json!({ "uri": doc, "range": range(3, 4, 5) }));
    let d = c.at("textDocument/definition", &doc, 4, 10);
    assert_eq!(d, json!({ "uri": uri(&lib), "range": range(1, 4, 8) }));

    // References: the definition and both uses.
    let refs = c.at("textDocument/references", &doc, 2, 5);
    let lines: Vec<&Value> = refs.as_array().expect("locations").iter().map(|l| &l["range"]["start"]["line"]).collect();
    assert_eq!(lines, [&json!(2), &json!(6), &json!(7)]);

    // Completion: the open call's arguments first, then names in scope and builtins.
    let items = c.at("textDocument/completion", &doc, 8, 14);
    let items = items.as_array().expect("items");
    let labels: Vec<&str> = items.iter().filter_map(|i| i["label"].as_str()).collect();
    assert_eq!(labels[0], "r", "{labels:?}");
    assert_eq!(items[0]["detail"], "r: num");
    assert_eq!(items[0]["insertText"], "r = ");
    for name in ["ball", "post", "sphere", "torus", "pi"] {
        assert!(labels.contains(&name), "{name} missing from {labels:?}");
    }
    assert!(!labels.contains(&"i"), "the loop variable is out of scope here: {labels:?}");
    assert!(
        items[0]["documentation"].as_str().is_some_and(|d| d.starts_with("the radius; greater than 0")),
        "{}",
        items[0]
    );
    let inside = c.at("textDocument/completion", &doc, 4, 24);
    let inside: Vec<&str> = inside.as_array().expect("items").iter().filter_map(|i| i["label"].as_str()).collect();
    assert!(inside.contains(&"i"), "{inside:?}");

    // Signature help: the builtin being called, its parameters' docs and ranges, and the
    // one the cursor is at (after `sphere(`, the first).
    let help = c.at("textDocument/signatureHelp", &doc, 8, 14);
    assert_eq!(help["signatures"][0]["label"], "sphere(r: num)", "{help}");
    assert_eq!(help["signatures"][0]["parameters"][0]["documentation"], "the radius; greater than 0");
    assert_eq!(help["activeParameter"], 0);

    // The outline.
    let symbols = c.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": doc } }));
    let names: Vec<&str> = symbols.as_array().expect("symbols").iter().filter_map(|s| s["name"].as_str()).collect();
    assert_eq!(names, ["light ambient(…)", "ball", "for i in 0..3", "object ball", "object ball"]);
    assert_eq!(symbols[2]["children"][0]["name"], "object post(…)");

    // Formatting replaces the whole document with `scnc fmt`'s layout.
    let edits = c.request(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": doc }, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    assert_eq!(edits, json!([]), "a file with a syntax error is not formatted");
    let messy = "light  ambient(1)\nobject sphere( 1 ) at [0,0,5]\n";
    let change = json!({ "textDocument": { "uri": doc, "version": 2 }, "contentChanges": [{ "text": messy }] });
    c.notify("textDocument/didChange", change);
    let edits = c.request(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": doc }, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    assert_eq!(edits[0]["newText"], "light ambient(1)\nobject sphere(1) at [0, 0, 5]\n");
    assert_eq!(edits[0]["range"]["end"], json!({ "line": 2, "character": 0 }));
    c.stop();
}

#[test]
fn diagnostics_in_an_included_file_go_to_that_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let lib = dir.path().join("lib.scn");
    std::fs::write(&lib, "let post = cylindr(0.1, 1)\n").expect("writing lib.scn");
    let doc = uri(&dir.path().join("scene.scn"));
    let mut c = Client::start();
    c.open(&doc, "include \"lib.scn\"\nlight ambient(1)\nobject post at [0, 0, 5]\n");
    let diags = c.diagnostics(&uri(&lib));
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(diags[0]["code"], "E0201");
    assert_eq!(diags[0]["range"], range(0, 11, 18));
    assert!(c.diagnostics(&doc).is_empty());
    c.stop();
}

/// The server never dies of its input: malformed frames are skipped, an oversized
/// document is a diagnostic, a document including a device is an error, a request after
/// `shutdown` is refused with an error reply, and `exit` still ends it cleanly.
#[test]
fn malformed_input_never_ends_the_server() {
    let mut client = Client::start();
    let raw = |client: &mut Client, bytes: &[u8]| {
        client.stdin.write_all(bytes).expect("writing");
        client.stdin.flush().expect("flushing");
    };
    raw(&mut client, b"Content-Length: 99999999999999999999999\r\n\r\n");
    raw(&mut client, b"Content-Length: 9\r\n\r\n{not json");
    raw(&mut client, b"Content-Length: 3\r\n\r\n\xff\xfe\xfd");
    raw(&mut client, b"Content-Type: nothing\r\n\r\n");
    // Still answering.
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("dev.scn");
    let u = uri(&file);
    client.open(&u, "include \"/dev/stdin\"\nlight ambient(1)\nobject sphere(1) at [0, 0, 5]\n");
    let diags = client.diagnostics(&u);
    assert!(
        diags.iter().any(|d| d["message"].as_str().is_some_and(|m| m.contains("cannot read `/dev/stdin`"))),
        "{diags:?}"
    );
    let big = format!("// {}\nlight ambient(1)\n", "x".repeat(5 << 20));
    let large = dir.path().join("large.scn");
    client.open(&uri(&large), &big);
    let diags = client.diagnostics(&uri(&large));
    assert!(diags.iter().any(|d| d["code"] == "E0705"), "{diags:?}");
    client.request("shutdown", Value::Null);
    let id = client.next_id;
    client.next_id += 1;
    client.send(json!({ "jsonrpc": "2.0", "id": id, "method": "textDocument/hover", "params": {} }));
    let deadline = Instant::now() + TIMEOUT;
    let reply = loop {
        let msg = client.next(deadline);
        if msg["id"] == json!(id) {
            break msg;
        }
    };
    assert!(reply.get("error").is_some(), "a request after shutdown is refused: {reply}");
    client.notify("exit", Value::Null);
    let deadline = Instant::now() + TIMEOUT;
    loop {
        if let Some(status) = client.child.try_wait().expect("waiting for the server") {
            assert!(status.success(), "scnc lsp exited with {status}");
            break;
        }
        assert!(Instant::now() < deadline, "scnc lsp did not exit after `exit`");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// An edit stops the analysis of the text it replaces: a document that takes the whole
/// evaluation budget (about half a second) is superseded by the next edit, so its
/// diagnostics are never published and the edit's are, and a request that follows is
/// answered from the new text. (The server's reader counts the edit as soon as it has
/// read it, within the first of the old analysis's thousands of polls.)
#[test]
fn an_edit_cancels_the_analysis_it_makes_stale() {
    let mut client = Client::start();
    let dir = tempfile::tempdir().expect("temp dir");
    let u = uri(&dir.path().join("slow.scn"));
    let mut slow = String::from("let f0(x) = x + 1\n");
    for i in 1..=24 {
        slow += &format!("let f{i}(x) = f{}(x) + f{}(x)\n", i - 1, i - 1);
    }
    slow += "light ambient(1)\nobject sphere(f24(1)) at [0, 0, 5]\n";
    let fixed = "light ambient(1)\nobject spher(1) at [0, 0, 5]\n";
    let open = json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {
        "textDocument": { "uri": u, "languageId": "scn", "version": 1, "text": slow } } });
    let change = json!({ "jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
        "textDocument": { "uri": u, "version": 2 }, "contentChanges": [{ "text": fixed }] } });
    // Both in one write, so the server has the edit in hand while it analyses the first.
    let (open, change) = (open.to_string(), change.to_string());
    let both = format!("Content-Length: {}\r\n\r\n{open}Content-Length: {}\r\n\r\n{change}", open.len(), change.len());
    client.stdin.write_all(both.as_bytes()).expect("writing");
    client.stdin.flush().expect("flushing");
    let hover = client.at("textDocument/hover", &u, 0, 8);
    assert!(hover.to_string().contains("ambient"), "the hover reads the new text: {hover}");
    let first = client.publication(&u);
    assert_eq!(first["params"]["version"], json!(2), "the stale analysis published nothing: {first}");
    let codes: Vec<&Value> =
        first["params"]["diagnostics"].as_array().into_iter().flatten().map(|d| &d["code"]).collect();
    assert!(codes.contains(&&json!("E0201")), "{first}");
    client.stop();
}

/// Comprehensions and conditions: their variables are hovered, defined and completed
/// where they are in scope only, an `if` shows the type it gives, an overloaded builtin
/// shows the signature its arguments chose, and an `if` statement is in the outline.
#[test]
fn comprehensions_and_conditions_in_the_editor() {
    let dir = tempfile::tempdir().expect("temp dir");
    let doc = uri(&dir.path().join("scene.scn"));
    let text = "light ambient(0.2)
let n = 6
let blobs = [for i in 0..n, j in 0..2 if i != j => sphere(0.2) at [i, j, 5]]
let r = if n > 3 then round(2.6) else 1
if n > 2 {
  object union(blobs, smooth = 0.1)
} else {
  object sphere(r) at [0, 0, 5]
}
";
    let mut c = Client::start();
    c.open(&doc, text);
    // The comprehension's variables, its type, an `if` expression's type, the overload.
    assert!(c.hover(&doc, 2, 68).contains("for i: num"));
    assert!(c.hover(&doc, 2, 41).contains("for i: num"), "in the filter");
    assert!(c.hover(&doc, 2, 13).contains("list<shape>"));
    assert!(c.hover(&doc, 3, 8).contains("num"), "the `if` expression's type");
    assert!(c.hover(&doc, 3, 22).contains("round(x: num)"), "the overload the number chose");
    assert!(c.hover(&doc, 5, 10).contains("union(shape…"), "inside the branch that ran");
    assert!(c.hover(&doc, 7, 10).contains("sphere(r: num)"), "inside the branch that did not run");
    assert!(c.hover(&doc, 7, 16).contains("let r: num"), "a use inside the branch that did not run");
    let d = c.at("textDocument/definition", &doc, 2, 68);
    assert_eq!(d, json!({ "uri": doc, "range": range(2, 17, 18) }));

    // Generator variables complete in the body and nowhere else.
    let labels = |c: &mut Client, line, col| -> Vec<String> {
        let items = c.at("textDocument/completion", &doc, line, col);
        items.as_array().expect("items").iter().filter_map(|i| i["label"].as_str().map(String::from)).collect()
    };
    let body = labels(&mut c, 2, 67);
    assert!(body.iter().any(|l| l == "i") && body.iter().any(|l| l == "j"), "{body:?}");
    let branch = labels(&mut c, 5, 15);
    assert!(!branch.iter().any(|l| l == "i") && branch.iter().any(|l| l == "blobs"), "{branch:?}");

    // The `if` statement is a node of the outline with both branches' objects below it.
    let symbols = c.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": doc } }));
    assert_eq!(symbols[4]["name"], "if n > 2", "{symbols}");
    let inner: Vec<&str> =
        symbols[4]["children"].as_array().expect("children").iter().filter_map(|s| s["name"].as_str()).collect();
    assert_eq!(inner, ["object union(…)", "object sphere(…)"]);
    c.stop();
}

/// `clock` and `frame` are known to hover and completion, with what they mean.
#[test]
fn the_animation_names_in_the_editor() {
    let dir = tempfile::tempdir().expect("temp dir");
    let doc = uri(&dir.path().join("scene.scn"));
    let text = "render(frames = 24)\nlight ambient(0.2)\nobject sphere(0.5 + clock) at [frame, 0, 5]\n";
    let mut c = Client::start();
    c.open(&doc, text);
    let h = c.hover(&doc, 2, 22);
    assert!(h.contains("clock: num") && h.contains("0 at the first frame"), "{h}");
    let h = c.hover(&doc, 2, 32);
    assert!(h.contains("frame: int") && h.contains("frame being rendered"), "{h}");
    let h = c.hover(&doc, 0, 9);
    assert!(h.contains("frames: int = 1"), "{h}");
    let items = c.at("textDocument/completion", &doc, 2, 20);
    let labels: Vec<&str> = items.as_array().expect("items").iter().filter_map(|i| i["label"].as_str()).collect();
    assert!(labels.contains(&"clock") && labels.contains(&"frame"), "{labels:?}");
}
