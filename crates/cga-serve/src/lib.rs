//! `cga serve`: a live preview of CGA rules in the browser.
//!
//! The server stands on the `cga` library facade only. It loads the rule
//! file through an [`Engine`](cga::Engine) over a
//! [`ConfinedWorld`](cga::ConfinedWorld) (the rules read nothing outside
//! their workspace), generates the lots into plain meshes, and serves:
//!
//! | request | answer |
//! | --- | --- |
//! | `GET /` and `GET /NAME` | the page (`web/dist`: `index.html`, `main.js`, ...) |
//! | `GET /api/state` | JSON: attributes with annotations, values, diagnostics, prints, reports, statistics |
//! | `GET /api/events` | server-sent events: a `state` event (the same JSON) after every change, a `generating` event (the request's number) as each regeneration is asked for |
//! | `GET /api/model.bin` | the last good model: a frame of meshes per lot and material (see [`encode`]) |
//! | `GET /api/live.bin?n=N` | the model being made for request `N`, each lot's frame sent as the lot is made; it ends complete, or abandoned when a newer request replaced it |
//! | `GET /api/lots.bin` | the lots, in the same form, to draw under the buildings |
//! | `GET /api/model.glb` | the model as a GLB file (download) |
//! | `GET /api/provenance?lot=L&mesh=M&tri=T` | the rule and source line that made a triangle |
//! | `POST /api/params` | `{"seed": N, "attrs": {"NAME": VALUE}}`: regenerate with these values |
//! | `GET /files/PATH` | a file of the workspace (textures, assets) |
//!
//! Saving the rule file, an import or an asset (anything under the
//! workspace) reloads the rules and regenerates; a newer change or a slider
//! cancels a generation it made obsolete ([`cga::Cancel`]). The engine keeps
//! what it read, so a reload rereads only files that changed.

pub mod encode;
mod generator;
mod http;
pub mod paths;

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use generator::Preview;

/// What `cga serve` was asked for.
#[derive(Clone, Debug)]
pub struct Config {
    /// The rule file (`.cga`).
    pub rules: PathBuf,
    /// `--lot` specifications, as `cga generate` takes them (read from disk:
    /// the user named them).
    pub lots: Vec<String>,
    pub host: String,
    /// 0: any free port (the URL printed says which).
    pub port: u16,
    /// Further folders the rules may read (`--workspace`).
    pub workspaces: Vec<PathBuf>,
    /// The built page (`web/dist`); `None`: [`default_web_dir`].
    pub web_dir: Option<PathBuf>,
    /// Limits of each generation; the time limit is short by default so
    /// that a runaway rule is reported quickly and the preview stays live.
    pub limits: cga::Limits,
}

impl Config {
    pub fn new(rules: impl Into<PathBuf>) -> Config {
        Config {
            rules: rules.into(),
            lots: Vec::new(),
            host: "127.0.0.1".to_string(),
            port: DEFAULT_PORT,
            workspaces: Vec::new(),
            web_dir: None,
            limits: cga::Limits {
                max_seconds: DEFAULT_MAX_SECONDS,
                ..cga::Limits::default()
            },
        }
    }
}

/// The port `cga serve` listens on without `--port`.
pub const DEFAULT_PORT: u16 = 8417;

/// Seconds a lot may take in the preview before it is stopped.
pub const DEFAULT_MAX_SECONDS: f64 = 20.0;

/// The page's files: `CGA_WEB_DIR` if set, else `web/dist` of the source
/// tree this binary was built from (a developer's checkout).
pub fn default_web_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("CGA_WEB_DIR") {
        return PathBuf::from(dir);
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../web/dist")
}

/// What to run when the page's files are missing.
pub const WEB_BUILD_HINT: &str = "npm ci --prefix web && npm run build --prefix web";

/// A running server.
pub struct Server {
    pub addr: SocketAddr,
    pub preview: Arc<Preview>,
    shutdown: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Server {
    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// Runs until the process ends.
    pub fn wait(mut self) {
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        if let Some(tx) = self.shutdown.take() {
            let _ = tx.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        self.preview.stop();
    }
}

/// Loads the rules, starts generating and watching, and listens.
pub fn start(config: Config) -> Result<Server, String> {
    let web_dir = config.web_dir.clone().unwrap_or_else(default_web_dir);
    let preview = Preview::start(&config)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| format!("cannot start the server: {e}"))?;
    let listener = runtime
        .block_on(tokio::net::TcpListener::bind((
            config.host.as_str(),
            config.port,
        )))
        .map_err(|e| format!("cannot listen on {}:{}: {e}", config.host, config.port))?;
    let addr = listener
        .local_addr()
        .map_err(|e| format!("cannot listen: {e}"))?;
    let app = http::router(preview.clone(), web_dir);
    let (tx, rx) = tokio::sync::oneshot::channel::<()>();
    let thread = std::thread::Builder::new()
        .name("cga-serve".into())
        .spawn(move || {
            // Not a graceful shutdown: open event streams would hold it
            // forever. Dropping the server drops its connections.
            runtime.block_on(async move {
                tokio::select! {
                    _ = axum::serve(listener, app) => {}
                    _ = rx => {}
                }
            });
            runtime.shutdown_timeout(std::time::Duration::from_millis(100));
        })
        .map_err(|e| format!("cannot start the server: {e}"))?;
    Ok(Server {
        addr,
        preview,
        shutdown: Some(tx),
        thread: Some(thread),
    })
}

/// `cga serve`: starts, prints the URL and serves until killed.
pub fn run(config: Config) -> Result<(), String> {
    let web_dir = config.web_dir.clone().unwrap_or_else(default_web_dir);
    if !web_dir.join("index.html").is_file() {
        eprintln!(
            "warning: the preview page is not built ({} is missing).\n\
             Run once, in the repository: {WEB_BUILD_HINT}\n\
             (or set CGA_WEB_DIR to a built web/dist folder)",
            web_dir.join("index.html").display()
        );
    }
    let server = start(config)?;
    println!("cga serve: preview at {}", server.url());
    use std::io::Write;
    let _ = std::io::stdout().flush();
    server.wait();
    Ok(())
}
