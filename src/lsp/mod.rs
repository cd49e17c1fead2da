//! `scnc lsp`: a Language Server Protocol server over stdio.
//!
//! Built on `lsp-server` and `lsp-types`, the synchronous crates under rust-analyzer:
//! the compiler is synchronous and fast (a scene checks in milliseconds), so an async
//! runtime would add weight and nothing else. Every edit recompiles the document with
//! the compiler's own front-end ([`check::check_indexed`](crate::check::check_indexed)),
//! so the editor shows exactly what `scnc check` prints. A reader thread counts edits as
//! it reads them, and an analysis stops as soon as a newer edit is waiting, so a document
//! that takes the whole evaluation budget never delays the answer to the next.

pub mod analysis;
pub mod text;
pub mod wire;

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use lsp_server::{Connection, Message, Notification, Request, Response};
use lsp_types::notification::{
    DidChangeTextDocument, DidCloseTextDocument, DidOpenTextDocument, Notification as _, PublishDiagnostics,
};
use lsp_types::request::{
    CodeActionRequest, Completion, DocumentSymbolRequest, Formatting, GotoDefinition, HoverRequest, References,
    Request as _, SignatureHelpRequest,
};
use lsp_types::{self as lt, Uri};

use self::analysis::{Analysis, CandidateKind, Symbol, SymbolKind};
use self::text::{path_to_uri, uri_to_path, LineIndex};
use crate::diag::{Diagnostic, Severity};
use crate::source::SourceMap;
use crate::source::{FsLoader, Loader};
use crate::span::Span;

/// Serves the protocol on stdin/stdout until the client asks to exit (or the input
/// ends). Frames that cannot be messages are skipped and described to `log`, so no input
/// ends the server.
pub fn run_stdio(log: impl Fn(String) + Send + 'static) -> Result<(), String> {
    let (to_server, receiver) = crossbeam_channel::bounded::<Message>(0);
    let (sender, to_client) = crossbeam_channel::bounded::<Message>(0);
    let edits = Arc::new(AtomicU64::new(0));
    let edits_read = edits.clone();
    let no_thread = |e: std::io::Error| format!("cannot start the server's threads: {e}");
    let reader = std::thread::Builder::new().name("lsp-reader".into()).spawn(move || -> std::io::Result<()> {
        let mut input = std::io::stdin().lock();
        loop {
            match wire::read_frame(&mut input)? {
                wire::Received::Message(m) => {
                    // Counted before it waits for the server, so an analysis under way
                    // learns that its document has changed.
                    if matches!(&m, Message::Notification(n) if is_edit(&n.method)) {
                        edits_read.fetch_add(1, Ordering::SeqCst);
                    }
                    let exit = matches!(&m, Message::Notification(n) if n.method == "exit");
                    if to_server.send(m).is_err() || exit {
                        return Ok(());
                    }
                }
                wire::Received::Skipped(why) => log(format!("skipped {why}")),
                wire::Received::End => return Ok(()),
            }
        }
    });
    let reader = reader.map_err(no_thread)?;
    let writer = std::thread::Builder::new()
        .name("lsp-writer".into())
        .spawn(move || -> std::io::Result<()> {
            let mut out = std::io::stdout().lock();
            for m in to_client {
                m.write(&mut out)?;
            }
            Ok(())
        })
        .map_err(no_thread)?;
    let served = serve(&Connection { sender, receiver }, edits);
    // Dropping the connection ends the writer; the reader ends with its input.
    let wrote = writer.join().map_err(|_| "the writer thread panicked".to_string())?;
    wrote.map_err(|e| e.to_string())?;
    served?;
    drop(reader);
    Ok(())
}

/// What the server offers.
fn capabilities() -> lt::ServerCapabilities {
    lt::ServerCapabilities {
        text_document_sync: Some(lt::TextDocumentSyncCapability::Kind(lt::TextDocumentSyncKind::FULL)),
        hover_provider: Some(lt::HoverProviderCapability::Simple(true)),
        definition_provider: Some(lt::OneOf::Left(true)),
        references_provider: Some(lt::OneOf::Left(true)),
        completion_provider: Some(lt::CompletionOptions {
            trigger_characters: Some(vec!["(".into(), ",".into()]),
            ..Default::default()
        }),
        signature_help_provider: Some(lt::SignatureHelpOptions {
            trigger_characters: Some(vec!["(".into(), ",".into()]),
            ..Default::default()
        }),
        document_symbol_provider: Some(lt::OneOf::Left(true)),
        document_formatting_provider: Some(lt::OneOf::Left(true)),
        code_action_provider: Some(lt::CodeActionProviderCapability::Options(lt::CodeActionOptions {
            code_action_kinds: Some(vec![lt::CodeActionKind::QUICKFIX]),
            ..Default::default()
        })),
        ..Default::default()
    }
}

/// Whether a notification changes the open documents (and so makes analyses stale).
fn is_edit(method: &str) -> bool {
    matches!(method, DidOpenTextDocument::METHOD | DidChangeTextDocument::METHOD | DidCloseTextDocument::METHOD)
}

/// Runs the protocol on `connection`: the handshake, then requests until shutdown.
/// `edits_read` counts the document edits read from the client so far, including those
/// still queued; an analysis stops as soon as it is behind it.
pub fn serve(connection: &Connection, edits_read: Arc<AtomicU64>) -> Result<(), String> {
    let caps = serde_json::to_value(capabilities()).map_err(|e| e.to_string())?;
    connection.initialize(caps).map_err(|e| format!("the client sent no `initialize` request ({e})"))?;
    let mut server =
        Server { docs: HashMap::new(), published: HashMap::new(), cache: Cache::default(), edits_read, edits_seen: 0 };
    let mut shut_down = false;
    for msg in &connection.receiver {
        match msg {
            Message::Request(req) if req.method == "shutdown" => {
                shut_down = true;
                connection.sender.send(Response::new_ok(req.id, ()).into()).map_err(|e| e.to_string())?;
            }
            Message::Request(req) if shut_down => {
                // After `shutdown` only `exit` is expected; anything else is refused, not fatal.
                let code = lsp_server::ErrorCode::InvalidRequest as i32;
                let resp = Response::new_err(req.id, code, "the server is shutting down".into());
                connection.sender.send(resp.into()).map_err(|e| e.to_string())?;
            }
            Message::Request(req) => {
                let resp = server.request(req);
                connection.sender.send(resp.into()).map_err(|e| e.to_string())?;
            }
            Message::Notification(note) if note.method == "exit" => return Ok(()),
            Message::Notification(note) => {
                for out in server.notification(note) {
                    connection.sender.send(out.into()).map_err(|e| e.to_string())?;
                }
            }
            Message::Response(_) => {}
        }
    }
    Ok(())
}

/// An open document.
struct Doc {
    text: String,
    version: i32,
}

/// The last analysis of each open document, dropped whenever any document changes
/// (an open document may be included by another).
type Cache = std::cell::RefCell<HashMap<String, Rc<Analysis>>>;

struct Server {
    /// Open documents by URI.
    docs: HashMap<String, Doc>,
    /// For each open document, the other files its last compile published diagnostics to.
    published: HashMap<String, HashSet<String>>,
    cache: Cache,
    /// Document edits the client has sent (some perhaps not yet handled).
    edits_read: Arc<AtomicU64>,
    /// Document edits handled.
    edits_seen: u64,
}

/// Why a document has no analysis to answer from.
enum Unavailable {
    /// The client has not opened it.
    NotOpen,
    /// It changed while it was being analysed; the newer text will be analysed next.
    Superseded,
}

/// A request that could not be answered: a JSON-RPC error code and message.
struct Failure {
    code: i32,
    message: String,
}

impl From<String> for Failure {
    fn from(message: String) -> Failure {
        Failure { code: lsp_server::ErrorCode::InvalidParams as i32, message }
    }
}

impl From<&str> for Failure {
    fn from(message: &str) -> Failure {
        Failure::from(message.to_string())
    }
}

impl From<Unavailable> for Failure {
    fn from(why: Unavailable) -> Failure {
        match why {
            Unavailable::NotOpen => Failure::from("the document is not open"),
            // The code the protocol has for this: the client asks again if it still cares.
            Unavailable::Superseded => Failure {
                code: lsp_server::ErrorCode::ContentModified as i32,
                message: "the document changed while it was being analysed".into(),
            },
        }
    }
}

/// Reads open documents from the editor's buffers and other files from disk, so an
/// included file shows its unsaved edits.
struct Overlay {
    open: HashMap<PathBuf, String>,
}

impl Loader for Overlay {
    fn read(&self, path: &Path) -> std::io::Result<String> {
        match self.open.get(path) {
            Some(text) => Ok(text.clone()),
            None => FsLoader.read(path),
        }
    }
}

fn doc_path(uri: &str) -> PathBuf {
    uri_to_path(uri).unwrap_or_else(|| PathBuf::from(uri))
}

fn parse_uri(s: &str) -> Option<Uri> {
    s.parse().ok()
}

impl Server {
    fn analyse(&self, uri: &str) -> Result<Rc<Analysis>, Unavailable> {
        if let Some(a) = self.cache.borrow().get(uri) {
            return Ok(a.clone());
        }
        let doc = self.docs.get(uri).ok_or(Unavailable::NotOpen)?;
        let open = self.docs.iter().map(|(u, d)| (doc_path(u), d.text.clone())).collect();
        let (edits_read, seen) = (&*self.edits_read, self.edits_seen);
        let stale = move || edits_read.load(Ordering::SeqCst) > seen;
        let a = Analysis::new(&doc_path(uri), doc.text.clone(), &Overlay { open }, &stale);
        let a = Rc::new(a.ok_or(Unavailable::Superseded)?);
        self.cache.borrow_mut().insert(uri.to_string(), a.clone());
        Ok(a)
    }

    /// The URI and range of `span` in the compile of the document `root`: the document's
    /// own URI for itself, the editor's URI for another open file, else a `file://` URI.
    fn locate(&self, root: &str, map: &SourceMap, span: Span) -> (String, lt::Range) {
        let (id, r) = map.local_range(span);
        let file = map.file(id);
        let uri = if id.0 == 0 {
            root.to_string()
        } else {
            let open = self.docs.keys().find(|u| doc_path(u) == file.path);
            open.cloned().unwrap_or_else(|| path_to_uri(&file.path))
        };
        (uri, LineIndex::new(&file.text).range(r))
    }

    fn location(&self, root: &str, map: &SourceMap, span: Span) -> Option<lt::Location> {
        let (uri, range) = self.locate(root, map, span);
        Some(lt::Location { uri: parse_uri(&uri)?, range })
    }

    fn notification(&mut self, note: Notification) -> Vec<Notification> {
        if is_edit(&note.method) {
            self.edits_seen += 1;
        }
        self.cache.borrow_mut().clear();
        let uri = match note.method.as_str() {
            DidOpenTextDocument::METHOD => {
                let Ok(p) = serde_json::from_value::<lt::DidOpenTextDocumentParams>(note.params) else {
                    return Vec::new();
                };
                let uri = p.text_document.uri.as_str().to_string();
                self.docs.insert(uri.clone(), Doc { text: p.text_document.text, version: p.text_document.version });
                uri
            }
            DidChangeTextDocument::METHOD => {
                let Ok(p) = serde_json::from_value::<lt::DidChangeTextDocumentParams>(note.params) else {
                    return Vec::new();
                };
                let uri = p.text_document.uri.as_str().to_string();
                // Full sync: the last change holds the whole text.
                let Some(change) = p.content_changes.into_iter().last() else {
                    return Vec::new();
                };
                self.docs.insert(uri.clone(), Doc { text: change.text, version: p.text_document.version });
                uri
            }
            DidCloseTextDocument::METHOD => {
                let Ok(p) = serde_json::from_value::<lt::DidCloseTextDocumentParams>(note.params) else {
                    return Vec::new();
                };
                let uri = p.text_document.uri.as_str().to_string();
                self.docs.remove(&uri);
                let mut out: Vec<Notification> = Vec::new();
                for other in self.published.remove(&uri).unwrap_or_default().into_iter().chain([uri]) {
                    out.extend(publish(&other, Vec::new(), None));
                }
                return out;
            }
            _ => return Vec::new(),
        };
        self.publish_all(&uri)
    }

    /// Compiles the document and publishes its diagnostics, and those in files it
    /// includes; clears files that had diagnostics from its previous compile.
    fn publish_all(&mut self, uri: &str) -> Vec<Notification> {
        // A superseded analysis publishes nothing: the edit that superseded it publishes.
        let Ok(analysis) = self.analyse(uri) else {
            return Vec::new();
        };
        let version = self.docs.get(uri).map(|d| d.version);
        let mut by_file: HashMap<String, Vec<lt::Diagnostic>> = HashMap::new();
        by_file.insert(uri.to_string(), Vec::new());
        for d in &analysis.diagnostics {
            let (file_uri, _) = self.locate(uri, &analysis.map, d.span());
            // An included file that is open itself gets its diagnostics from its own compile.
            if file_uri != uri && self.docs.contains_key(&file_uri) {
                continue;
            }
            by_file.entry(file_uri).or_default().push(to_lsp(d, &|span| self.locate(uri, &analysis.map, span)));
        }
        let others: HashSet<String> = by_file.keys().filter(|u| *u != uri).cloned().collect();
        let stale = self.published.insert(uri.to_string(), others).unwrap_or_default();
        let mut out = Vec::new();
        for gone in stale.iter().filter(|u| !by_file.contains_key(*u)) {
            out.extend(publish(gone, Vec::new(), None));
        }
        for (file_uri, diags) in by_file {
            let v = if file_uri == uri { version } else { None };
            out.extend(publish(&file_uri, diags, v));
        }
        out
    }

    fn request(&mut self, req: Request) -> Response {
        let id = req.id.clone();
        match self.answer(req) {
            Ok(value) => Response::new_ok(id, value),
            Err(Failure { code, message }) => Response::new_err(id, code, message),
        }
    }

    /// The answer to one request. Long because it is one match over the request methods,
    /// each arm a few lines; a table of handlers would only move the arms.
    fn answer(&mut self, req: Request) -> Result<serde_json::Value, Failure> {
        fn params<P: serde::de::DeserializeOwned>(req: Request) -> Result<P, Failure> {
            serde_json::from_value(req.params).map_err(|e| Failure::from(e.to_string()))
        }
        match req.method.as_str() {
            HoverRequest::METHOD => {
                let p: lt::HoverParams = params(req)?;
                let (uri, a, at) = self.at(&p.text_document_position_params)?;
                let hover = a.hover(at).map(|(span, markdown)| lt::Hover {
                    contents: lt::HoverContents::Markup(lt::MarkupContent {
                        kind: lt::MarkupKind::Markdown,
                        value: markdown,
                    }),
                    range: self.location(&uri, &a.map, span).map(|l| l.range),
                });
                Ok(json(&hover))
            }
            GotoDefinition::METHOD => {
                let p: lt::GotoDefinitionParams = params(req)?;
                let (uri, a, at) = self.at(&p.text_document_position_params)?;
                let loc = a.definition(at).and_then(|d| self.location(&uri, &a.map, d));
                Ok(json(&loc.map(lt::GotoDefinitionResponse::Scalar)))
            }
            References::METHOD => {
                let p: lt::ReferenceParams = params(req)?;
                let (uri, a, at) = self.at(&p.text_document_position)?;
                let locs: Vec<lt::Location> = a
                    .references(at, p.context.include_declaration)
                    .into_iter()
                    .filter_map(|s| self.location(&uri, &a.map, s))
                    .collect();
                Ok(json(&locs))
            }
            Completion::METHOD => {
                let p: lt::CompletionParams = params(req)?;
                let (_, a, at) = self.at(&p.text_document_position)?;
                let items: Vec<lt::CompletionItem> = a
                    .complete(at)
                    .into_iter()
                    .enumerate()
                    .map(|(i, c)| lt::CompletionItem {
                        insert_text: (c.kind == CandidateKind::Argument).then(|| format!("{} = ", c.label)),
                        label: c.label,
                        kind: Some(match c.kind {
                            CandidateKind::Argument => lt::CompletionItemKind::FIELD,
                            CandidateKind::Variable => lt::CompletionItemKind::VARIABLE,
                            CandidateKind::Function | CandidateKind::Builtin => lt::CompletionItemKind::FUNCTION,
                            CandidateKind::Constant => lt::CompletionItemKind::CONSTANT,
                            CandidateKind::Keyword => lt::CompletionItemKind::KEYWORD,
                        }),
                        detail: Some(c.detail),
                        documentation: c.doc.map(lt::Documentation::String),
                        // Keep the analysis's order: arguments, then names in scope, then builtins.
                        sort_text: Some(format!("{i:04}")),
                        ..Default::default()
                    })
                    .collect();
                Ok(json(&lt::CompletionResponse::Array(items)))
            }
            SignatureHelpRequest::METHOD => {
                let p: lt::SignatureHelpParams = params(req)?;
                let (_, a, at) = self.at(&p.text_document_position_params)?;
                let help = a.signature_help(at).map(|h| lt::SignatureHelp {
                    active_parameter: h.active.map(|i| i as u32),
                    signatures: vec![lt::SignatureInformation {
                        label: h.label,
                        documentation: Some(lt::Documentation::String(h.doc)),
                        parameters: Some(
                            h.params
                                .into_iter()
                                .map(|(label, doc)| lt::ParameterInformation {
                                    label: lt::ParameterLabel::Simple(label),
                                    documentation: Some(lt::Documentation::String(doc)),
                                })
                                .collect(),
                        ),
                        active_parameter: h.active.map(|i| i as u32),
                    }],
                    active_signature: Some(0),
                });
                Ok(json(&help))
            }
            DocumentSymbolRequest::METHOD => {
                let p: lt::DocumentSymbolParams = params(req)?;
                let uri = p.text_document.uri.as_str().to_string();
                let a = self.analyse(&uri)?;
                let index = LineIndex::new(a.text());
                let symbols: Vec<lt::DocumentSymbol> = a.symbols().iter().map(|s| document_symbol(s, &index)).collect();
                Ok(json(&lt::DocumentSymbolResponse::Nested(symbols)))
            }
            CodeActionRequest::METHOD => {
                let p: lt::CodeActionParams = params(req)?;
                let uri = p.text_document.uri.as_str().to_string();
                let a = self.analyse(&uri)?;
                let index = LineIndex::new(a.text());
                let range = index.offset(p.range.start) as u32..index.offset(p.range.end) as u32;
                let actions: Vec<lt::CodeActionOrCommand> = a
                    .fixable(range)
                    .into_iter()
                    .flat_map(|d| {
                        let single = d.fixes.len() == 1;
                        let diag = to_lsp(d, &|span| self.locate(&uri, &a.map, span));
                        d.fixes.iter().map(move |f| (f.clone(), diag.clone(), single))
                    })
                    .map(|(fix, diag, single)| {
                        let edit = lt::TextEdit { range: index.range(fix.span.range()), new_text: fix.text.clone() };
                        let changes = parse_uri(&uri).map(|u| HashMap::from([(u, vec![edit])]));
                        lt::CodeActionOrCommand::CodeAction(lt::CodeAction {
                            title: format!("Replace with `{}`", fix.text),
                            kind: Some(lt::CodeActionKind::QUICKFIX),
                            diagnostics: Some(vec![diag]),
                            edit: Some(lt::WorkspaceEdit { changes, ..Default::default() }),
                            is_preferred: Some(single),
                            ..Default::default()
                        })
                    })
                    .collect();
                Ok(json(&actions))
            }
            Formatting::METHOD => {
                let p: lt::DocumentFormattingParams = params(req)?;
                let doc = self.docs.get(p.text_document.uri.as_str()).ok_or("the document is not open")?;
                // A file with syntax errors is left as it is, as `scnc fmt` leaves it.
                let edits = match crate::fmt::format(&doc.text) {
                    Ok(formatted) if formatted != doc.text => {
                        let index = LineIndex::new(&doc.text);
                        vec![lt::TextEdit { range: index.range(0..doc.text.len()), new_text: formatted }]
                    }
                    _ => Vec::new(),
                };
                Ok(json(&edits))
            }
            other => Err(Failure::from(format!("scnc lsp does not handle `{other}`"))),
        }
    }

    /// The document, its analysis and the global offset of a position in it.
    fn at(&self, p: &lt::TextDocumentPositionParams) -> Result<(String, Rc<Analysis>, u32), Failure> {
        let uri = p.text_document.uri.as_str().to_string();
        let a = self.analyse(&uri)?;
        let at = LineIndex::new(a.text()).offset(p.position) as u32;
        Ok((uri, a, at))
    }
}

/// A response value as JSON; the lsp-types values always serialise.
fn json<T: serde::Serialize>(value: &T) -> serde_json::Value {
    serde_json::to_value(value).unwrap_or(serde_json::Value::Null)
}

fn publish(uri: &str, diagnostics: Vec<lt::Diagnostic>, version: Option<i32>) -> Option<Notification> {
    let params = lt::PublishDiagnosticsParams { uri: parse_uri(uri)?, diagnostics, version };
    Some(Notification::new(PublishDiagnostics::METHOD.to_string(), params))
}

/// One diagnostic as LSP has it: notes and hints follow the message, as `scnc check`
/// prints them; secondary labels become related information.
fn to_lsp(d: &Diagnostic, located: &dyn Fn(Span) -> (String, lt::Range)) -> lt::Diagnostic {
    let mut message = d.message.clone();
    for note in &d.notes {
        message.push_str(&format!("\nnote: {note}"));
    }
    for hint in &d.hints {
        message.push_str(&format!("\nhelp: {hint}"));
    }
    let related: Vec<lt::DiagnosticRelatedInformation> = d.labels[1..]
        .iter()
        .filter_map(|l| {
            let (uri, range) = located(l.span);
            Some(lt::DiagnosticRelatedInformation {
                location: lt::Location { uri: parse_uri(&uri)?, range },
                message: l.message.clone(),
            })
        })
        .collect();
    lt::Diagnostic {
        range: located(d.span()).1,
        severity: Some(match d.severity {
            Severity::Error => lt::DiagnosticSeverity::ERROR,
            Severity::Warning => lt::DiagnosticSeverity::WARNING,
        }),
        code: Some(lt::NumberOrString::String(d.code.to_string())),
        source: Some("scnc".into()),
        message,
        related_information: (!related.is_empty()).then_some(related),
        ..Default::default()
    }
}

#[allow(deprecated, reason = "`deprecated` is a required field of DocumentSymbol in lsp-types")]
fn document_symbol(s: &Symbol, index: &LineIndex<'_>) -> lt::DocumentSymbol {
    let range = index.range(s.span.range());
    let selection_range = index.range(s.name_span.range());
    lt::DocumentSymbol {
        name: s.name.clone(),
        detail: None,
        kind: match s.kind {
            SymbolKind::Value => lt::SymbolKind::VARIABLE,
            SymbolKind::Function => lt::SymbolKind::FUNCTION,
            SymbolKind::Object => lt::SymbolKind::OBJECT,
            SymbolKind::Light => lt::SymbolKind::EVENT,
            SymbolKind::Setting => lt::SymbolKind::PROPERTY,
            SymbolKind::Loop => lt::SymbolKind::NAMESPACE,
            SymbolKind::Conditional => lt::SymbolKind::NAMESPACE,
        },
        tags: None,
        deprecated: None,
        range,
        selection_range,
        children: (!s.children.is_empty()).then(|| s.children.iter().map(|c| document_symbol(c, index)).collect()),
    }
}
