//! The message loop: documents, debounced diagnostics, request dispatch.

use std::collections::HashMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime};

use cga::{DiskWorld, Engine, MemoryWorld, Workspaces, World};
use lsp_server::{Connection, ErrorCode, Message, Notification, Request, Response};
use lsp_types::notification::Notification as _;
use lsp_types::request::Request as _;
use lsp_types::{notification as n, request as r, Url};
use serde_json::Value;

use crate::index::FileIndex;
use crate::text::{apply_change, LineIndex};

/// How long after the last change diagnostics are computed: typing a word
/// costs one load of the rules, not one per key.
const DEBOUNCE: Duration = Duration::from_millis(150);

/// Stack of the thread that answers: parsing recurses as deep as the text
/// nests.
const STACK: usize = 64 << 20;

type Error = Box<dyn std::error::Error + Send + Sync>;

/// Serves the protocol on standard input and output until the client
/// says `exit`. `workspaces`: where `/Project/...` paths are looked for
/// (`cga lsp --workspace DIR`), before those of the client's
/// `initializationOptions.workspaces` and `CGA_WORKSPACE`.
pub fn run_stdio(workspaces: &[PathBuf]) -> Result<(), Error> {
    let (connection, io_threads) = Connection::stdio();
    run(connection, workspaces)?;
    io_threads.join()?;
    Ok(())
}

/// Serves the protocol over `connection` (stdio, or an in-memory pair in
/// tests) until shutdown.
pub fn run(connection: Connection, workspaces: &[PathBuf]) -> Result<(), Error> {
    std::thread::scope(|scope| {
        std::thread::Builder::new()
            .name("cga-lsp".into())
            .stack_size(STACK)
            .spawn_scoped(scope, || serve(&connection, workspaces))?
            .join()
            .map_err(|_| Error::from("the language server stopped on an internal error"))?
    })
}

fn serve(connection: &Connection, workspaces: &[PathBuf]) -> Result<(), Error> {
    let (id, params) = connection.initialize_start()?;
    // A client that leaves out required fields still gets a server.
    let init: lsp_types::InitializeParams = serde_json::from_value(params).unwrap_or_default();
    let mut server = Server::new(&init, workspaces);
    let result = lsp_types::InitializeResult {
        capabilities: crate::features::capabilities(),
        server_info: Some(lsp_types::ServerInfo {
            name: "cga-lsp".into(),
            version: Some(env!("CARGO_PKG_VERSION").into()),
        }),
    };
    connection.initialize_finish(id, serde_json::to_value(result)?)?;
    loop {
        let wait = server
            .next_deadline()
            .map(|d| d.saturating_duration_since(Instant::now()));
        let message = match wait {
            Some(wait) => match connection.receiver.recv_timeout(wait) {
                Ok(m) => Some(m),
                Err(crossbeam_channel::RecvTimeoutError::Timeout) => None,
                Err(crossbeam_channel::RecvTimeoutError::Disconnected) => return Ok(()),
            },
            None => match connection.receiver.recv() {
                Ok(m) => Some(m),
                Err(_) => return Ok(()),
            },
        };
        match message {
            Some(Message::Request(req)) => {
                if connection.handle_shutdown(&req)? {
                    return Ok(());
                }
                let response = server.request(req);
                connection.sender.send(Message::Response(response))?;
            }
            Some(Message::Notification(note)) => {
                if note.method == n::Exit::METHOD {
                    return Ok(());
                }
                let _ = catch_unwind(AssertUnwindSafe(|| server.notification(note)));
            }
            Some(Message::Response(_)) | None => {}
        }
        for (uri, diagnostics, version) in server.due_diagnostics() {
            let params = lsp_types::PublishDiagnosticsParams {
                uri,
                diagnostics,
                version,
            };
            connection
                .sender
                .send(Message::Notification(Notification::new(
                    n::PublishDiagnostics::METHOD.to_string(),
                    params,
                )))?;
        }
    }
}

/// A file read from disk: its time and size when read, and its index.
type DiskEntry = (Option<SystemTime>, u64, Arc<FileIndex>);

/// An open document.
pub struct Doc {
    pub uri: Url,
    pub version: i32,
    pub text: String,
    index: Option<Arc<FileIndex>>,
}

pub struct Server {
    pub docs: HashMap<PathBuf, Doc>,
    /// Open buffers over the disk: what the engine and the features read.
    pub world: Arc<MemoryWorld>,
    engine: Engine,
    pub workspaces: Workspaces,
    /// The client's workspace folders: searched for references, rename
    /// and workspace symbols.
    pub roots: Vec<PathBuf>,
    /// Documents whose diagnostics are due, and when.
    pending: HashMap<PathBuf, Instant>,
    /// Indexes of files read from disk, with the metadata they were read at.
    disk: Mutex<HashMap<PathBuf, DiskEntry>>,
    /// Paths written in rule files as found, for the request being
    /// answered (files may come and go between requests): highlighting a
    /// file with a thousand `imp.X` looks for `imp`'s file once.
    located: Mutex<HashMap<(PathBuf, String), Option<PathBuf>>>,
}

impl Server {
    pub fn new(init: &lsp_types::InitializeParams, workspaces: &[PathBuf]) -> Server {
        let world = Arc::new(MemoryWorld::over(Arc::new(DiskWorld)));
        let mut roots: Vec<PathBuf> = init
            .workspace_folders
            .iter()
            .flatten()
            .filter_map(|f| f.uri.to_file_path().ok())
            .collect();
        #[allow(deprecated)]
        if roots.is_empty() {
            roots.extend(init.root_uri.as_ref().and_then(|u| u.to_file_path().ok()));
        }
        // `initializationOptions: { "workspaces": ["DIR", ...] }`: where
        // `/Project/...` paths are looked for besides the file's ancestors
        // (as `cga --workspace`), then `CGA_WORKSPACE`.
        let mut dirs = workspaces.to_vec();
        dirs.extend(
            init.initialization_options
                .as_ref()
                .and_then(|o| o.get("workspaces"))
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
                .filter_map(Value::as_str)
                .map(PathBuf::from),
        );
        let workspaces = Workspaces::with_env(&dirs);
        let engine = Engine::with_world(world.clone()).workspaces(workspaces.clone());
        Server {
            docs: HashMap::new(),
            world,
            engine,
            workspaces,
            roots,
            pending: HashMap::new(),
            disk: Mutex::new(HashMap::new()),
            located: Mutex::new(HashMap::new()),
        }
    }

    fn next_deadline(&self) -> Option<Instant> {
        self.pending.values().min().copied()
    }

    pub(crate) fn notification(&mut self, note: Notification) {
        self.forget_located();
        match note.method.as_str() {
            m if m == n::DidOpenTextDocument::METHOD => {
                let Ok(p) =
                    serde_json::from_value::<lsp_types::DidOpenTextDocumentParams>(note.params)
                else {
                    return;
                };
                let Ok(path) = p.text_document.uri.to_file_path() else {
                    return;
                };
                self.world.set(&path, p.text_document.text.clone());
                self.docs.insert(
                    path.clone(),
                    Doc {
                        uri: p.text_document.uri,
                        version: p.text_document.version,
                        text: p.text_document.text,
                        index: None,
                    },
                );
                // A newly opened file is checked at once (its text may
                // differ from the disk's, which importers saw).
                self.check_soon(path, Instant::now());
            }
            m if m == n::DidChangeTextDocument::METHOD => {
                let Ok(p) =
                    serde_json::from_value::<lsp_types::DidChangeTextDocumentParams>(note.params)
                else {
                    return;
                };
                let Ok(path) = p.text_document.uri.to_file_path() else {
                    return;
                };
                let Some(doc) = self.docs.get_mut(&path) else {
                    return;
                };
                for change in &p.content_changes {
                    apply_change(&mut doc.text, change.range, &change.text);
                }
                doc.version = p.text_document.version;
                doc.index = None;
                self.world.set(&path, doc.text.clone());
                self.check_soon(path, Instant::now() + DEBOUNCE);
            }
            m if m == n::DidCloseTextDocument::METHOD => {
                let Ok(p) =
                    serde_json::from_value::<lsp_types::DidCloseTextDocumentParams>(note.params)
                else {
                    return;
                };
                if let Ok(path) = p.text_document.uri.to_file_path() {
                    self.docs.remove(&path);
                    self.world.remove(&path);
                    self.pending.remove(&path);
                }
            }
            _ => {}
        }
    }

    /// Diagnostics of `path` due at `when`, and of the open documents
    /// that import it (their problems may change with it).
    fn check_soon(&mut self, path: PathBuf, when: Instant) {
        let others: Vec<PathBuf> = self.docs.keys().filter(|k| **k != path).cloned().collect();
        for other in others {
            if self.imports_of(&other).contains(&path) {
                self.pending.insert(other, when);
            }
        }
        self.pending.insert(path, when);
    }

    /// Diagnostics of the documents whose time has come.
    fn due_diagnostics(&mut self) -> Vec<(Url, Vec<lsp_types::Diagnostic>, Option<i32>)> {
        self.forget_located();
        // Index the changed documents once, here, for the requests to come.
        self.ensure_indexed();
        let now = Instant::now();
        let due: Vec<PathBuf> = self
            .pending
            .iter()
            .filter(|(_, t)| **t <= now)
            .map(|(p, _)| p.clone())
            .collect();
        let mut out = Vec::new();
        for path in due {
            self.pending.remove(&path);
            let Some(doc) = self.docs.get(&path) else {
                continue;
            };
            let (uri, version) = (doc.uri.clone(), doc.version);
            let diagnostics =
                catch_unwind(AssertUnwindSafe(|| self.diagnostics(&path))).unwrap_or_default();
            out.push((uri, diagnostics, Some(version)));
        }
        out
    }

    /// The engine's diagnostics for an open document: those in the file
    /// itself, and those in files it imports on the import that leads
    /// there.
    pub fn diagnostics(&self, path: &Path) -> Vec<lsp_types::Diagnostic> {
        let Some(doc) = self.docs.get(path) else {
            return Vec::new();
        };
        let rules = self.engine.load_text(path, doc.text.clone());
        let index = self.index(path).expect("open");
        let own = self.world.canonical(path);
        let imports: Vec<(PathBuf, std::ops::Range<usize>)> = index
            .imports
            .iter()
            .filter_map(|i| {
                let found =
                    cga::syntax::locate(&*self.world, path, &i.path, &self.workspaces).ok()?;
                Some((self.world.canonical(&found), index.defs[i.def].span.clone()))
            })
            .collect();
        let lines = LineIndex::new(&doc.text);
        let mut out = Vec::new();
        for d in rules.diagnostics() {
            let severity = Some(if d.is_error() {
                lsp_types::DiagnosticSeverity::ERROR
            } else {
                lsp_types::DiagnosticSeverity::WARNING
            });
            let mut message = d.message.clone();
            for note in &d.notes {
                message.push('\n');
                message.push_str(note);
            }
            let range = match &d.location {
                Some(l) if self.world.canonical(&l.file) == own => {
                    let start = lines.offset_of_line_col(&doc.text, l.line, l.column);
                    let end = lines.offset_of_line_col(&doc.text, l.end_line, l.end_column);
                    lines.range(&doc.text, start..end.max(start))
                }
                Some(l) => {
                    let file = self.world.canonical(&l.file);
                    let Some((_, span)) = imports.iter().find(|(p, _)| *p == file) else {
                        continue;
                    };
                    message = format!(
                        "in {}:{}:{}: {message}",
                        l.file
                            .file_name()
                            .map_or(String::new(), |n| n.to_string_lossy().into_owned()),
                        l.line,
                        l.column
                    );
                    lines.range(&doc.text, span.clone())
                }
                None => lines.range(&doc.text, 0..0),
            };
            out.push(lsp_types::Diagnostic {
                range,
                severity,
                source: Some("cga".into()),
                message,
                ..Default::default()
            });
        }
        out
    }

    /// The index of a file: an open document's, else the disk's (cached
    /// while its size and time stay the same).
    pub fn index(&self, path: &Path) -> Option<Arc<FileIndex>> {
        if let Some(doc) = self.docs.get(path) {
            if let Some(i) = &doc.index {
                return Some(i.clone());
            }
            // Documents are indexed on demand; `&self` here, so the index is
            // not kept (the request handlers call `ensure_indexed` first).
            return Some(Arc::new(FileIndex::new(doc.text.clone())));
        }
        let meta = self.world.metadata(path)?;
        if meta.is_dir {
            return None;
        }
        let mut disk = self.disk.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((modified, len, index)) = disk.get(path) {
            if *modified == meta.modified && *len == meta.len {
                return Some(index.clone());
            }
        }
        let text = self.world.read_text(path).ok()?;
        let index = Arc::new(FileIndex::new(text));
        disk.insert(path.to_path_buf(), (meta.modified, meta.len, index.clone()));
        Some(index)
    }

    /// Indexes open documents whose index is stale.
    pub(crate) fn ensure_indexed(&mut self) {
        for doc in self.docs.values_mut() {
            if doc.index.is_none() {
                doc.index = Some(Arc::new(FileIndex::new(doc.text.clone())));
            }
        }
    }

    /// The files `path` imports, as found.
    pub fn imports_of(&self, path: &Path) -> Vec<PathBuf> {
        let Some(index) = self.index(path) else {
            return Vec::new();
        };
        index
            .imports
            .iter()
            .filter_map(|i| self.locate(path, &i.path))
            .collect()
    }

    /// The file a path written in `from` names.
    pub fn locate(&self, from: &Path, target: &str) -> Option<PathBuf> {
        let key = (from.to_path_buf(), target.to_string());
        let mut located = self.located.lock().unwrap_or_else(|e| e.into_inner());
        located
            .entry(key)
            .or_insert_with(|| {
                cga::syntax::locate(&*self.world, from, target, &self.workspaces).ok()
            })
            .clone()
    }

    /// Every rule file of the workspace: open documents, the `.cga` files
    /// under the client's folders, and what those import.
    pub fn workspace_files(&self) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = self.docs.keys().cloned().collect();
        for root in &self.roots {
            walk(&*self.world, root, &mut files, 0);
        }
        let mut i = 0;
        while i < files.len() && files.len() < MAX_FILES {
            for imported in self.imports_of(&files[i].clone()) {
                if !files.contains(&imported) {
                    files.push(imported);
                }
            }
            i += 1;
        }
        files
    }

    /// Forgets where paths led: files may have come or gone since.
    fn forget_located(&self) {
        self.located
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clear();
    }

    pub(crate) fn request(&mut self, req: Request) -> Response {
        self.ensure_indexed();
        self.forget_located();
        let id = req.id.clone();
        let method = req.method.clone();
        match catch_unwind(AssertUnwindSafe(|| {
            crate::features::dispatch(self, &method, req.params)
        })) {
            Ok(Ok(value)) => Response::new_ok(id, value),
            Ok(Err(Failure::UnknownMethod)) => Response::new_err(
                id,
                ErrorCode::MethodNotFound as i32,
                format!("unknown method {method}"),
            ),
            Ok(Err(Failure::BadParams(e))) => {
                Response::new_err(id, ErrorCode::InvalidParams as i32, e)
            }
            Ok(Err(Failure::Refused(e))) => {
                Response::new_err(id, ErrorCode::RequestFailed as i32, e)
            }
            Err(_) => Response::new_err(
                id,
                ErrorCode::InternalError as i32,
                format!("internal error answering {method}"),
            ),
        }
    }
}

/// Why a request got no answer.
pub enum Failure {
    UnknownMethod,
    BadParams(String),
    /// A request that cannot be done (renaming to a name that is no name).
    Refused(String),
}

const MAX_FILES: usize = 5000;

fn walk(world: &dyn World, dir: &Path, out: &mut Vec<PathBuf>, depth: usize) {
    if depth > 12 || out.len() >= MAX_FILES {
        return;
    }
    let Ok(mut entries) = world.read_dir(dir) else {
        return;
    };
    entries.sort();
    for e in entries {
        let hidden = e
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.starts_with('.') || n == "node_modules" || n == "target");
        if hidden {
            continue;
        }
        if world.is_dir(&e) {
            walk(world, &e, out, depth + 1);
        } else if e.extension().is_some_and(|x| x.eq_ignore_ascii_case("cga")) && !out.contains(&e)
        {
            out.push(e);
        }
    }
}

// The method names the dispatcher matches, from lsp-types' own constants.
pub(crate) const HOVER: &str = r::HoverRequest::METHOD;
pub(crate) const COMPLETION: &str = r::Completion::METHOD;
pub(crate) const SIGNATURE_HELP: &str = r::SignatureHelpRequest::METHOD;
pub(crate) const DEFINITION: &str = r::GotoDefinition::METHOD;
pub(crate) const REFERENCES: &str = r::References::METHOD;
pub(crate) const RENAME: &str = r::Rename::METHOD;
pub(crate) const PREPARE_RENAME: &str = r::PrepareRenameRequest::METHOD;
pub(crate) const DOCUMENT_SYMBOL: &str = r::DocumentSymbolRequest::METHOD;
pub(crate) const WORKSPACE_SYMBOL: &str = r::WorkspaceSymbolRequest::METHOD;
pub(crate) const SEMANTIC_TOKENS: &str = r::SemanticTokensFullRequest::METHOD;
pub(crate) const FOLDING_RANGE: &str = r::FoldingRangeRequest::METHOD;
pub(crate) const FORMATTING: &str = r::Formatting::METHOD;
