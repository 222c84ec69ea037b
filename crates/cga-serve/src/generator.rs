//! Loading and generating on a thread of its own, with the newest request
//! winning: a change cancels the generation it makes obsolete.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Condvar, Mutex, RwLock};
use std::time::Instant;

use axum::body::Bytes;

use cga::{Cancel, ConfinedWorld, DiskWorld, Engine, Error, Lot, LotResult, Options, Rules};
use serde_json::{json, Value as Json};

use crate::encode;

/// How long a file change may take to settle before it is read, unless
/// the writer closes the file sooner (see [`change_of`]).
const SETTLE: std::time::Duration = std::time::Duration::from_millis(15);

/// What the page asked for.
#[derive(Clone, Debug, Default)]
pub struct Params {
    pub seed: u64,
    /// Attribute values by name, as the page sent them.
    pub attrs: BTreeMap<String, Json>,
}

/// What the page shows, as of one generation.
pub struct Snapshot {
    /// Grows with every published change.
    pub version: u64,
    /// The state as JSON (`/api/state`, the `state` event).
    pub state: Arc<String>,
    /// The last good model (binary, see [`encode`]): its frames, shared
    /// with every request that sends them (no copy), and its number.
    pub model: Vec<Bytes>,
    pub model_version: u64,
    /// The number of the request whose generation made the model.
    pub model_request: Option<u64>,
    /// What made the model: for provenance and the GLB download.
    pub made_by: Option<Made>,
}

/// A model made: what made it, its frames but the end, its box and the
/// time its lots took to encode.
struct Model {
    /// The request it was made for.
    request: u64,
    made: Made,
    frames: Vec<Bytes>,
    bounds: Option<encode::Bounds>,
    encode_ms: f64,
}

#[derive(Clone)]
pub struct Made {
    pub rules: Rules,
    /// How long the generation took, in milliseconds.
    pub generate_ms: f64,
    pub results: Arc<Vec<LotResult>>,
    pub options: Options,
}

/// The model being made, frame by frame, for the pages that fetch it as
/// it comes (`/api/live.bin`): the start frame, a frame per lot as it is
/// made, and at last the end frame.
#[derive(Default)]
pub struct Live {
    /// The number of the request it serves.
    pub number: u64,
    pub frames: Vec<Bytes>,
    /// The end frame is the last of `frames`.
    pub ended: bool,
}

pub(crate) struct Request {
    params: Params,
    /// Something needs doing.
    dirty: bool,
    /// Reload the rules (a file changed).
    reload: bool,
    /// The last file change was a writer closing the rule file: the save
    /// is whole, and the rules are read without waiting for it to settle.
    settled: bool,
    stop: bool,
    /// Counts requests: a generation serves the request of this number.
    number: u64,
}

/// The preview's engine, rules and lots, and the thread that generates.
pub struct Preview {
    pub engine: Engine,
    pub rules_path: PathBuf,
    /// The folders the rules (and requests) may read.
    pub roots: Vec<PathBuf>,
    pub lots: Vec<Lot>,
    /// The lots' own outlines as meshes (binary, see [`encode`]).
    pub lots_model: Bytes,
    /// The point models are sent relative to: lots far from the frame's
    /// origin (a national grid's metres) would lose their millimetres in
    /// the page's 32-bit floats.
    pub origin: [f64; 3],
    limits: cga::Limits,
    request: Mutex<Request>,
    wake: Condvar,
    /// The generation running: the number of the request it serves, and
    /// its switch.
    running: Mutex<Option<(u64, Cancel)>>,
    published: RwLock<Arc<Snapshot>>,
    events: tokio::sync::watch::Sender<u64>,
    /// The number of the latest request, sent as it is made: pages learn
    /// that a new model is on its way (a saved file, another page's
    /// values) before it comes.
    requests: tokio::sync::watch::Sender<u64>,
    watcher: Mutex<Option<notify::RecommendedWatcher>>,
    lot_notes: Vec<String>,
    /// The model being made.
    live: tokio::sync::watch::Sender<Live>,
    /// Buffers of lots' frames no longer sent, for the next frames' bytes.
    spare_frames: Arc<Mutex<Vec<Vec<u8>>>>,
}

/// Buffers of lots' frames kept for reuse at most (those of the model
/// shown and of the one being made are the others).
const SPARE_FRAMES: usize = 64;

/// A frame's bytes, which go back to the spare buffers when the last
/// request sending them is done with them.
struct Pooled {
    bytes: Vec<u8>,
    spares: std::sync::Weak<Mutex<Vec<Vec<u8>>>>,
}

impl AsRef<[u8]> for Pooled {
    fn as_ref(&self) -> &[u8] {
        &self.bytes
    }
}

impl Drop for Pooled {
    fn drop(&mut self) {
        if let Some(spares) = self.spares.upgrade() {
            let mut spares = spares.lock().unwrap_or_else(|e| e.into_inner());
            if spares.len() < SPARE_FRAMES {
                spares.push(std::mem::take(&mut self.bytes));
            }
        }
    }
}

/// The folder a rule file's project is: the parent of a `rules` folder
/// (a CityEngine project holds `rules/` and `assets/` side by side), else
/// the rule file's own folder.
pub fn workspace_of(rules: &Path) -> PathBuf {
    let dir = rules.parent().unwrap_or(Path::new(".")).to_path_buf();
    if dir.file_name().is_some_and(|n| n == "rules") {
        if let Some(project) = dir.parent() {
            return project.to_path_buf();
        }
    }
    dir
}

impl Preview {
    pub fn start(config: &crate::Config) -> Result<Arc<Preview>, String> {
        let rules_path = config
            .rules
            .canonicalize()
            .map_err(|e| format!("{}: {e}", config.rules.display()))?;
        let mut roots = vec![workspace_of(&rules_path)];
        for w in &config.workspaces {
            roots.push(
                w.canonicalize()
                    .map_err(|e| format!("{}: {e}", w.display()))?,
            );
        }
        let world = ConfinedWorld::new(Arc::new(DiskWorld), roots.clone());
        let engine = Engine::new(world);
        // Lot files are read from disk: the user named them.
        let lot_set = cga::lots::read(&config.lots).map_err(|e| e.to_string())?;
        let lots = lot_set.lots;
        let origin = cga::lots::local_origin(&lots).map_or([0.0; 3], |o| o.to_array());
        let lots_model = Bytes::from(lot_outlines(&engine, &roots[0], &lots, origin));
        let (events, _) = tokio::sync::watch::channel(0);
        let (requests, _) = tokio::sync::watch::channel(0);
        let empty = Snapshot {
            version: 0,
            state: Arc::new("{}".to_string()),
            model: vec![Bytes::from(encode::model(&[], origin, &mut |_| None))],
            model_version: 0,
            model_request: None,
            made_by: None,
        };
        let preview = Arc::new(Preview {
            engine,
            rules_path,
            roots,
            lots,
            lots_model,
            origin,
            limits: config.limits,
            request: Mutex::new(Request {
                params: Params::default(),
                dirty: true,
                reload: true,
                settled: true,
                stop: false,
                number: 0,
            }),
            wake: Condvar::new(),
            running: Mutex::new(None),
            published: RwLock::new(Arc::new(empty)),
            events,
            requests,
            watcher: Mutex::new(None),
            live: tokio::sync::watch::channel(Live::default()).0,
            spare_frames: Arc::default(),
            lot_notes: lot_set.warnings,
        });
        let worker = preview.clone();
        std::thread::Builder::new()
            .name("cga-serve-generate".into())
            .spawn(move || worker.work())
            .map_err(|e| format!("cannot start generating: {e}"))?;
        preview.watch();
        // The first state before anyone asks.
        preview.wait_for_version(1, std::time::Duration::from_secs(600));
        Ok(preview)
    }

    /// Watches the workspace folders: any change reloads.
    fn watch(self: &Arc<Self>) {
        use notify::{RecursiveMode, Watcher};
        let weak = Arc::downgrade(self);
        let rules = std::fs::canonicalize(&self.rules_path).ok();
        let handler = move |event: notify::Result<notify::Event>| {
            let Ok(event) = event else { return };
            let settled = match change_of(&event.kind) {
                Change::None => return,
                // Only the rule file's own close: a file written beside
                // it and then renamed over it (a safe save) closes first,
                // and reading then would read the old rules.
                Change::Closed => event
                    .paths
                    .iter()
                    .any(|p| std::fs::canonicalize(p).ok() == rules),
                Change::Step => false,
            };
            // Build output and version control under a workspace change
            // often and are never read by rules.
            if !event.paths.iter().any(|p| !is_ignored(p)) {
                return;
            }
            if let Some(p) = weak.upgrade() {
                p.request(|r| {
                    r.reload = true;
                    r.settled = settled;
                });
            }
        };
        match notify::recommended_watcher(handler) {
            Ok(mut watcher) => {
                for root in &self.roots {
                    if let Err(e) = watcher.watch(root, RecursiveMode::Recursive) {
                        eprintln!("warning: cannot watch {}: {e}", root.display());
                    }
                }
                *self.watcher.lock().unwrap() = Some(watcher);
            }
            Err(e) => eprintln!("warning: cannot watch files for changes: {e}"),
        }
    }

    /// Asks for a new generation (after `change`), cancelling the running
    /// one, which the change makes obsolete; returns the request's number.
    pub(crate) fn request(&self, change: impl FnOnce(&mut Request)) -> u64 {
        let number = {
            let mut r = self.request.lock().unwrap();
            change(&mut r);
            r.dirty = true;
            r.number += 1;
            r.number
        };
        self.wake.notify_all();
        self.requests.send_replace(number);
        // Only an older request's generation: the worker may already have
        // taken this very request.
        let mut running = self.running.lock().unwrap();
        if running.as_ref().is_some_and(|(n, _)| *n < number) {
            if let Some((_, cancel)) = running.take() {
                cancel.cancel();
            }
        }
        number
    }

    /// New values from the page; returns the number of the request (its
    /// model being made is `/api/live.bin?n=` it).
    pub fn set_params(&self, params: Params) -> u64 {
        self.request(|r| r.params = params)
    }

    pub fn params(&self) -> Params {
        self.request.lock().unwrap().params.clone()
    }

    pub fn stop(&self) {
        self.request(|r| r.stop = true);
        *self.watcher.lock().unwrap() = None;
    }

    pub fn snapshot(&self) -> Arc<Snapshot> {
        self.published.read().unwrap().clone()
    }

    pub fn subscribe(&self) -> tokio::sync::watch::Receiver<u64> {
        self.events.subscribe()
    }

    /// The number of each request as it is made (see `requests`).
    pub fn subscribe_requests(&self) -> tokio::sync::watch::Receiver<u64> {
        self.requests.subscribe()
    }

    /// The number of the latest request.
    pub fn latest_request(&self) -> u64 {
        *self.requests.borrow()
    }

    /// The model being made, as its frames come.
    pub fn subscribe_live(&self) -> tokio::sync::watch::Receiver<Live> {
        self.live.subscribe()
    }

    /// A model's start frame (the origin and the number of lots).
    pub fn start_frame(&self) -> Vec<u8> {
        encode::start_frame(self.origin, self.lots.len())
    }

    /// The model being made for request `number`, begun.
    fn begun_live(&self, number: u64) -> Live {
        Live {
            number,
            frames: vec![Bytes::from(self.start_frame())],
            ended: false,
        }
    }

    /// Ends the model being made for request `number` (started or not)
    /// with `end`, unless it has ended.
    fn end_live(&self, number: u64, end: Bytes) {
        self.live.send_modify(|l| {
            if l.number != number || l.frames.is_empty() {
                *l = self.begun_live(number);
            }
            if !l.ended {
                l.frames.push(end);
                l.ended = true;
            }
        });
    }

    /// Gives up the model being made for request `number`.
    fn abandon_live(&self, number: u64) {
        self.end_live(number, Bytes::from(encode::end_frame(false, None, None)));
    }

    /// Blocks until a state of at least `version` is published (tests,
    /// start-up).
    pub fn wait_for_version(&self, version: u64, timeout: std::time::Duration) -> bool {
        let end = Instant::now() + timeout;
        while Instant::now() < end {
            if self.snapshot().version >= version {
                return true;
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        false
    }

    fn work(self: Arc<Self>) {
        let mut rules: Option<Rules> = None;
        let mut load_ms = 0.0;
        loop {
            let (params, reload, number) = {
                let mut r = self.request.lock().unwrap();
                while !r.dirty && !r.stop {
                    r = self.wake.wait(r).unwrap();
                }
                // An editor saves in steps (truncate, write, close or
                // rename): the events of one save come within
                // milliseconds, and a file read between them would be
                // half-written. The wait ends early when the rule file's
                // writer closes it (the save of most editors, `cat >`, a
                // program's write).
                let settle = Instant::now() + SETTLE;
                while r.reload && !r.settled && !r.stop {
                    let left = settle.saturating_duration_since(Instant::now());
                    if left.is_zero() {
                        break;
                    }
                    r = self.wake.wait_timeout(r, left).unwrap().0;
                }
                if r.stop {
                    return;
                }
                r.dirty = false;
                r.settled = false;
                (r.params.clone(), std::mem::take(&mut r.reload), r.number)
            };
            if reload || rules.is_none() {
                let t = Instant::now();
                rules = Some(self.engine.load(&self.rules_path));
                load_ms = t.elapsed().as_secs_f64() * 1e3;
            }
            let rules = rules.clone().expect("loaded above");
            self.generate(&rules, &params, load_ms, number);
        }
    }

    /// One generation, published unless a newer request cancelled it.
    fn generate(&self, rules: &Rules, params: &Params, load_ms: f64, number: u64) {
        let mut problems: Vec<Json> = rules
            .diagnostics()
            .iter()
            .map(|d| self.diagnostic(d, None))
            .collect();
        for w in &self.lot_notes {
            problems.push(json!({"severity": "warning", "message": w}));
        }
        let previous = self.snapshot();
        if rules.has_errors() {
            self.publish(rules, params, problems, None, load_ms, 0.0, &previous);
            self.abandon_live(number);
            return;
        }
        let cancel = Cancel::new();
        *self.running.lock().unwrap() = Some((number, cancel.clone()));
        // A newer request that came before the switch was set: it did not
        // cancel this generation, so this one is not started.
        if self.request.lock().unwrap().number != number {
            self.running.lock().unwrap().take();
            self.abandon_live(number);
            return;
        }
        let mut options = Options::default()
            .seed(params.seed)
            .limits(self.limits)
            .cancel(cancel);
        for (name, v) in &params.attrs {
            // Values of attributes an edit removed, or that do not fit
            // the attribute's type, are left out.
            if let Some(attr) = rules.attribute(name) {
                if let Some(value) = encode::attr_value(attr.ty, v) {
                    options = options.attr(name.clone(), value);
                }
            }
        }
        // Each lot is encoded as it comes, on this thread while the
        // workers derive the next, and sent to the pages fetching the
        // model being made.
        self.live.send_replace(self.begun_live(number));
        let mut results = Vec::with_capacity(self.lots.len());
        let mut bounds = None;
        let mut encode_ms = 0.0;
        let mut found = std::collections::HashMap::new();
        let mut texture = |path: &str| {
            found
                .entry(path.to_string())
                .or_insert_with(|| self.texture_url(path))
                .clone()
        };
        let t = Instant::now();
        let outcome = rules.generate_lots(
            &self.lots,
            &options,
            cga::Target::Drawing(self.origin),
            |lot| {
                let encoding = Instant::now();
                // Written into a buffer of an earlier frame, and given
                // back when no request sends it any more.
                let spare = self.spare_frames.lock().unwrap().pop().unwrap_or_default();
                let (bytes, b) = encode::lot_frame(&lot, &mut texture, spare);
                bounds = encode::union(bounds, b);
                let frame = Bytes::from_owner(Pooled {
                    bytes,
                    spares: Arc::downgrade(&self.spare_frames),
                });
                self.live.send_modify(|l| l.frames.push(frame));
                encode_ms += encoding.elapsed().as_secs_f64() * 1e3;
                results.push(lot);
            },
        );
        let gen_ms = t.elapsed().as_secs_f64() * 1e3;
        self.running.lock().unwrap().take();
        match outcome {
            Ok(_) => {
                for lot in &results {
                    for w in &lot.warnings {
                        problems.push(self.diagnostic(w, Some(&lot.name)));
                    }
                    if let Some(e) = &lot.error {
                        problems.push(self.diagnostic(e, Some(&lot.name)));
                    }
                }
                // A later download regenerates with these values; it must
                // not be stopped by this generation's switch.
                options.cancel = None;
                let made = Made {
                    rules: rules.clone(),
                    generate_ms: gen_ms,
                    results: Arc::new(results),
                    options,
                };
                let frames = self.live.borrow().frames.clone();
                let model = Model {
                    request: number,
                    made,
                    frames,
                    bounds,
                    encode_ms,
                };
                self.publish(
                    rules,
                    params,
                    problems,
                    Some(model),
                    load_ms,
                    gen_ms,
                    &previous,
                );
                // The same end frame: with the number the state gives the
                // model, published first (a page drawing the model may ask
                // for its provenance at once).
                if let Some(end) = self.snapshot().model.last() {
                    self.end_live(number, end.clone());
                }
            }
            // A newer request is waiting: it will publish.
            Err(Error::Cancelled) => self.abandon_live(number),
            Err(e) => {
                problems.push(json!({"severity": "error", "message": e.to_string()}));
                self.publish(rules, params, problems, None, load_ms, gen_ms, &previous);
                self.abandon_live(number);
            }
        }
    }

    /// Publishes the state, with `model` as the new model shown (else
    /// the last good one stays).
    #[allow(clippy::too_many_arguments)]
    fn publish(
        &self,
        rules: &Rules,
        params: &Params,
        problems: Vec<Json>,
        model: Option<Model>,
        load_ms: f64,
        gen_ms: f64,
        previous: &Snapshot,
    ) {
        let version = previous.version + 1;
        let fresh = model.is_some();
        let (model, model_version, model_request, made_by, encode_ms) = match model {
            Some(Model {
                request,
                made,
                mut frames,
                bounds,
                encode_ms,
            }) => {
                frames.push(Bytes::from(encode::end_frame(true, bounds, Some(version))));
                (frames, version, Some(request), Some(made), encode_ms)
            }
            None => (
                previous.model.clone(),
                previous.model_version,
                previous.model_request,
                previous.made_by.clone(),
                0.0,
            ),
        };
        let results: &[LotResult] = made_by.as_ref().map(|m| &m.results[..]).unwrap_or(&[]);
        let mut prints = Vec::new();
        let mut reports = Vec::new();
        for lot in results {
            for p in &lot.prints {
                prints.push(json!({"lot": lot.name, "text": p}));
            }
            for (k, v) in &lot.reports {
                reports.push(json!({"lot": lot.name, "key": k, "value": encode::value(v)}));
            }
        }
        let stats = json!({
            "lots": results.len(),
            "failed": results.iter().filter(|l| l.error.is_some()).count(),
            "shapes": results.iter().map(|l| l.shapes).sum::<usize>(),
            "leaves": results.iter().map(|l| l.leaf_count).sum::<usize>(),
            "faces": results.iter().map(|l| l.drawing.faces).sum::<u64>(),
            "triangles": results.iter().map(|l| l.drawing.triangles()).sum::<usize>(),
            "load_ms": load_ms,
            "generate_ms": made_by.as_ref().map(|m| m.generate_ms).unwrap_or(gen_ms),
            // Making the bytes the page fetches.
            "encode_ms": encode_ms,
            "model_bytes": model.iter().map(Bytes::len).sum::<usize>(),
        });
        let state = json!({
            "version": version,
            "rules": self.display_path(rules.path()),
            "model_version": model_version,
            // The model shown is not of the current text (it has errors).
            "stale": !fresh,
            "has_errors": rules.has_errors(),
            "seed": params.seed,
            "values": params.attrs,
            // Rules with errors may not know their attributes' types: the
            // panel keeps those of the rules that made the model shown.
            "attributes": match (&made_by, rules.has_errors()) {
                (Some(m), true) => self.attributes(&m.rules),
                _ => self.attributes(rules),
            },
            "problems": problems,
            "prints": prints,
            "reports": reports,
            "stats": stats,
            "lots": results.iter().map(|l| json!({"name": l.name, "error": l.error.is_some()})).collect::<Vec<_>>(),
        });
        let snapshot = Snapshot {
            version,
            state: Arc::new(state.to_string()),
            model,
            model_version,
            model_request,
            made_by,
        };
        *self.published.write().unwrap() = Arc::new(snapshot);
        self.events.send_replace(version);
    }

    fn attributes(&self, rules: &Rules) -> Vec<Json> {
        rules
            .attributes()
            .iter()
            .map(|a| {
                let range = a
                    .range()
                    .map(|r| json!({"min": r.min, "max": r.max, "step": r.step}));
                let files = a.file_extensions().map(|ext| self.files_with(&ext));
                json!({
                    "name": a.name,
                    "type": a.ty.map(|t| format!("{t:?}").to_lowercase()),
                    "default": a.default.as_ref().map(encode::value),
                    "range": range,
                    "enum": choices(a).map(|vs| vs.iter().map(encode::value).collect::<Vec<_>>()),
                    "color": a.is_color(),
                    "group": a.group().map(|(g, o)| json!({"name": g, "order": o})),
                    "order": a.order(),
                    "hidden": a.is_hidden(),
                    "description": a.description().or_else(|| a.doc.clone()),
                    "files": files,
                    "line": a.location.as_ref().map(|l| l.line),
                })
            })
            .collect()
    }

    /// Workspace files with one of the extensions (for `@File`), as paths
    /// relative to the rule file's folder, at most a few thousand.
    fn files_with(&self, extensions: &[String]) -> Vec<String> {
        let base = self.rules_path.parent().unwrap_or(Path::new("/"));
        let mut out = Vec::new();
        let mut stack = vec![self.roots[0].clone()];
        let mut seen = 0;
        while let Some(dir) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            for e in entries.flatten() {
                seen += 1;
                if seen > 20_000 || out.len() >= 2_000 {
                    return out;
                }
                let path = e.path();
                let Ok(ft) = e.file_type() else { continue };
                if ft.is_dir() {
                    if !e.file_name().to_string_lossy().starts_with('.') {
                        stack.push(path);
                    }
                    continue;
                }
                let ext = path
                    .extension()
                    .map(|x| x.to_string_lossy().to_lowercase())
                    .unwrap_or_default();
                let wanted = extensions.is_empty()
                    || extensions
                        .iter()
                        .any(|x| x.trim_start_matches('.').eq_ignore_ascii_case(&ext));
                if wanted {
                    out.push(relative_to(&path, base));
                }
            }
        }
        out.sort();
        out
    }

    fn diagnostic(&self, d: &cga::Diagnostic, lot: Option<&str>) -> Json {
        let severity = if d.is_error() { "error" } else { "warning" };
        let mut j = json!({
            "severity": severity,
            "message": d.message,
            "lot": lot,
            "text": d.render(),
        });
        if let Some(at) = &d.location {
            j["file"] = json!(self.display_path(&at.file));
            j["line"] = json!(at.line);
            j["column"] = json!(at.column);
            j["line_text"] = json!(at.line_text);
        }
        j
    }

    /// The URL (`files/...`) of a texture the rules name, found as the
    /// engine finds it from the rule file; `None` when it is not in the
    /// workspace.
    fn texture_url(&self, written: &str) -> Option<String> {
        let found = cga::syntax::locate(
            self.engine.world().as_ref(),
            &self.rules_path,
            written,
            &cga::Workspaces::default(),
        )
        .ok()?;
        let rel = self.roots.iter().find_map(|r| found.strip_prefix(r).ok())?;
        let parts: Vec<String> = rel
            .components()
            .map(|c| {
                percent_encoding::utf8_percent_encode(&c.as_os_str().to_string_lossy(), URL_PART)
                    .to_string()
            })
            .collect();
        Some(format!("files/{}", parts.join("/")))
    }

    /// A path as the user reads it: relative to the workspace it is in.
    fn display_path(&self, path: &Path) -> String {
        for root in &self.roots {
            if let Ok(rel) = path.strip_prefix(root) {
                return rel.to_string_lossy().into_owned();
            }
        }
        path.to_string_lossy().into_owned()
    }
}

/// The values a drop-down offers: `@Enum`'s, or those of a `@Range` of
/// strings (`@Range("Visualization", "3DPrint")`, an older form
/// CityEngine's Inspector also shows as a list).
fn choices(a: &cga::Attribute) -> Option<Vec<cga::Value>> {
    if let Some(values) = a.enum_values() {
        return Some(values);
    }
    let range = a.annotation("Range")?;
    let values: Vec<cga::Value> = range.args.iter().filter_map(|(_, v)| v.clone()).collect();
    let strings = !values.is_empty() && values.iter().all(|v| matches!(v, cga::Value::Str(_)));
    strings.then_some(values)
}

/// Paths whose changes do not regenerate: inside `.git`, `target` or
/// `node_modules` folders.
/// What a file event says of the workspace's contents.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Change {
    /// Nothing changed (a file opened, read or closed unwritten).
    None,
    /// A writer closed a file it wrote: its contents are whole.
    Closed,
    /// A change that may be one step of several (a truncation, a write
    /// before the close, a rename away, a removal before the new file).
    Step,
}

fn change_of(kind: &notify::EventKind) -> Change {
    use notify::event::{AccessKind, AccessMode, EventKind};
    match kind {
        EventKind::Access(AccessKind::Close(AccessMode::Write)) => Change::Closed,
        EventKind::Access(_) | EventKind::Other => Change::None,
        _ => Change::Step,
    }
}

fn is_ignored(path: &Path) -> bool {
    path.components().any(|c| {
        matches!(
            c.as_os_str().to_str(),
            Some(".git" | "target" | "node_modules")
        )
    })
}

/// What is escaped in a part of a URL path: all but letters, digits and
/// `.-_` (so `/` and `%` in names stay inside their part).
const URL_PART: &percent_encoding::AsciiSet = &percent_encoding::NON_ALPHANUMERIC
    .remove(b'.')
    .remove(b'-')
    .remove(b'_');

/// `path` relative to `base` (`../assets/a.obj` where it is not below).
fn relative_to(path: &Path, base: &Path) -> String {
    let p: Vec<_> = path.components().collect();
    let b: Vec<_> = base.components().collect();
    let common = p.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &p[common..] {
        out.push(c);
    }
    out.to_string_lossy().replace('\\', "/")
}

/// The lots themselves as meshes, by a rule that leaves them as they are
/// (loaded from text: nothing is read).
fn lot_outlines(engine: &Engine, root: &Path, lots: &[Lot], origin: [f64; 3]) -> Vec<u8> {
    let rules = engine.load_text(
        root.join("cga-serve-lots.cga"),
        "Lot --> color(\"#9a9a92\") Ground.\n",
    );
    match encode::drawn(&rules, lots, &Options::default(), origin) {
        Ok(results) => encode::model(&results, origin, &mut |_| None),
        Err(_) => encode::model(&[], origin, &mut |_| None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A model's buffer goes back to the spares when the last copy of its
    /// bytes is dropped, and no more than a few are kept.
    #[test]
    fn model_buffers_come_back_when_no_one_sends_them() {
        let spares: Arc<Mutex<Vec<Vec<u8>>>> = Arc::default();
        let pooled = |n: usize| {
            Bytes::from_owner(Pooled {
                bytes: vec![7u8; n],
                spares: Arc::downgrade(&spares),
            })
        };
        let a = pooled(100);
        let sent = a.clone();
        drop(a);
        assert!(spares.lock().unwrap().is_empty());
        assert_eq!(&sent[..3], &[7, 7, 7]);
        drop(sent);
        assert_eq!(spares.lock().unwrap().len(), 1);
        assert_eq!(spares.lock().unwrap()[0].len(), 100);
        let more: Vec<Bytes> = (0..SPARE_FRAMES + 2).map(|_| pooled(10)).collect();
        drop(more);
        assert_eq!(spares.lock().unwrap().len(), SPARE_FRAMES);
    }

    /// A writer's close ends a save; its other steps and renames may be
    /// followed by more; opening or reading changes nothing.
    #[test]
    fn file_events_say_whether_a_save_is_whole() {
        use notify::event::{
            AccessKind, AccessMode, CreateKind, DataChange, EventKind, ModifyKind, RemoveKind,
            RenameMode,
        };
        let closed = EventKind::Access(AccessKind::Close(AccessMode::Write));
        assert_eq!(change_of(&closed), Change::Closed);
        for none in [
            EventKind::Access(AccessKind::Open(AccessMode::Any)),
            EventKind::Access(AccessKind::Close(AccessMode::Read)),
            EventKind::Access(AccessKind::Read),
            EventKind::Other,
        ] {
            assert_eq!(change_of(&none), Change::None, "{none:?}");
        }
        for step in [
            EventKind::Modify(ModifyKind::Data(DataChange::Content)),
            EventKind::Modify(ModifyKind::Name(RenameMode::From)),
            EventKind::Modify(ModifyKind::Name(RenameMode::To)),
            EventKind::Create(CreateKind::File),
            EventKind::Remove(RemoveKind::File),
        ] {
            assert_eq!(change_of(&step), Change::Step, "{step:?}");
        }
    }

    #[test]
    fn workspaces_and_relative_paths() {
        assert_eq!(
            workspace_of(Path::new("/w/proj/rules/a.cga")),
            PathBuf::from("/w/proj")
        );
        assert_eq!(workspace_of(Path::new("/w/x/a.cga")), PathBuf::from("/w/x"));
        assert_eq!(
            relative_to(
                Path::new("/w/proj/assets/a.obj"),
                Path::new("/w/proj/rules")
            ),
            "../assets/a.obj"
        );
        assert_eq!(
            relative_to(Path::new("/w/a/b.png"), Path::new("/w/a")),
            "b.png"
        );
    }
}
