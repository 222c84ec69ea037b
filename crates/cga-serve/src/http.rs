//! The HTTP routes (see the table in the crate's documentation).

use std::collections::BTreeMap;
use std::convert::Infallible;
use std::path::PathBuf;
use std::sync::Arc;

use axum::body::{Body, Bytes};
use axum::extract::{DefaultBodyLimit, Query, State};
use axum::http::{header, Method, StatusCode, Uri};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use cga::{ModelWriter, Target};
use serde::Deserialize;
use serde_json::json;
use tokio_stream::StreamExt;

use crate::encode;
use crate::generator::{Params, Preview};
use crate::paths;

/// Largest request body: the page sends a few attribute values.
const MAX_BODY: usize = 64 * 1024;
/// Most attribute values in one request.
const MAX_ATTRS: usize = 4096;
/// Largest workspace file served.
const MAX_FILE: u64 = 256 << 20;

#[derive(Clone)]
struct App {
    preview: Arc<Preview>,
    web_dir: Arc<PathBuf>,
}

pub fn router(preview: Arc<Preview>, web_dir: PathBuf) -> Router {
    let app = App {
        preview,
        web_dir: Arc::new(web_dir),
    };
    Router::new()
        .route("/api/state", get(state))
        .route("/api/events", get(events))
        .route("/api/model.bin", get(model))
        .route("/api/live.bin", get(live))
        .route("/api/lots.bin", get(lots))
        .route("/api/model.glb", get(glb))
        .route("/api/provenance", get(provenance))
        .route("/api/params", post(set_params))
        .fallback(files)
        .layer(DefaultBodyLimit::max(MAX_BODY))
        .with_state(app)
}

fn no_store(content_type: &'static str, body: impl IntoResponse) -> Response {
    (
        [
            (header::CONTENT_TYPE, content_type),
            (header::CACHE_CONTROL, "no-store"),
        ],
        body,
    )
        .into_response()
}

fn not_found() -> Response {
    (StatusCode::NOT_FOUND, "not found\n").into_response()
}

async fn state(State(app): State<App>) -> Response {
    let s = app.preview.snapshot();
    no_store("application/json", s.state.as_str().to_string())
}

async fn events(
    State(app): State<App>,
) -> Sse<impl tokio_stream::Stream<Item = Result<Event, Infallible>>> {
    let preview = app.preview.clone();
    // The current state at once, then each newer one; states published
    // while a client was busy are skipped, only the latest counts.
    let states = tokio_stream::wrappers::WatchStream::new(app.preview.subscribe()).map(move |_| {
        let s = preview.snapshot();
        Ok(Event::default().event("state").data(s.state.as_str()))
    });
    // And a `generating` event as each request is made, before its model.
    let requests =
        tokio_stream::wrappers::WatchStream::from_changes(app.preview.subscribe_requests())
            .map(|n| Ok(Event::default().event("generating").data(n.to_string())));
    let stream = states.merge(requests);
    Sse::new(stream).keep_alive(KeepAlive::default())
}

/// A body of frames sent one after the other, as they are.
fn frames_body(frames: Vec<Bytes>) -> Body {
    Body::from_stream(tokio_stream::iter(
        frames.into_iter().map(Ok::<_, Infallible>),
    ))
}

async fn model(State(app): State<App>) -> Response {
    let frames = app.preview.snapshot().model.clone();
    let length = frames.iter().map(Bytes::len).sum::<usize>();
    let mut response = no_store("application/octet-stream", frames_body(frames));
    response
        .headers_mut()
        .insert(header::CONTENT_LENGTH, header::HeaderValue::from(length));
    response
}

/// Longest wait for the next frame of a model being made: a page whose
/// model does not come in this time is sent an abandoned end (it then
/// fetches the model the next state names).
const LIVE_WAIT: std::time::Duration = std::time::Duration::from_secs(60);

#[derive(Deserialize)]
struct LiveQuery {
    /// The number of the request (the `generating` event's).
    n: u64,
}

/// The model being made for request `n`, its frames sent as they come
/// (see [`crate::generator::Live`]). A request that another replaced
/// before its model was done ends with an abandoned end frame.
async fn live(State(app): State<App>, Query(q): Query<LiveQuery>) -> Response {
    if q.n > app.preview.latest_request() {
        return not_found();
    }
    let mut live = app.preview.subscribe_live();
    let preview = app.preview.clone();
    let (tx, rx) = tokio::sync::mpsc::channel::<Result<Bytes, Infallible>>(4);
    tokio::spawn(async move {
        // Frames sent so far.
        let mut sent = 0;
        let abandoned = |sent: usize| {
            let mut end = Vec::new();
            if sent == 0 {
                end = preview.start_frame();
            }
            end.extend_from_slice(&encode::end_frame(false, None, None));
            Bytes::from(end)
        };
        loop {
            let (frames, ended) = {
                let l = live.borrow_and_update();
                match l.number.cmp(&q.n) {
                    std::cmp::Ordering::Less => (Vec::new(), false),
                    std::cmp::Ordering::Equal => (l.frames[sent..].to_vec(), l.ended),
                    // Replaced: by the time this page caught up, its model
                    // may have been done (it is then the one published,
                    // the same frames) or not.
                    std::cmp::Ordering::Greater => {
                        let s = preview.snapshot();
                        match s.model_request == Some(q.n) {
                            true => (s.model.get(sent..).unwrap_or_default().to_vec(), true),
                            false => (vec![abandoned(sent)], true),
                        }
                    }
                }
            };
            for frame in frames {
                if tx.send(Ok(frame)).await.is_err() {
                    return; // The page went away.
                }
                sent += 1;
            }
            if ended {
                return;
            }
            match tokio::time::timeout(LIVE_WAIT, live.changed()).await {
                Ok(Ok(())) => {}
                // Waited too long, or the server stops.
                _ => {
                    let _ = tx.send(Ok(abandoned(sent))).await;
                    return;
                }
            }
        }
    });
    no_store(
        "application/octet-stream",
        Body::from_stream(tokio_stream::wrappers::ReceiverStream::new(rx)),
    )
}

async fn lots(State(app): State<App>) -> Response {
    no_store("application/octet-stream", app.preview.lots_model.clone())
}

/// The last good model as a GLB, generated again into a writer with the
/// values that made it.
async fn glb(State(app): State<App>) -> Response {
    let preview = app.preview.clone();
    let made = match app.preview.snapshot().made_by.clone() {
        Some(m) => m,
        None => return (StatusCode::CONFLICT, "no model yet\n").into_response(),
    };
    let job = tokio::task::spawn_blocking(move || -> Result<Vec<u8>, cga::Error> {
        let export = cga::ExportOptions {
            origin: cga::lots::local_origin(&preview.lots),
            ..made.rules.export_options()
        };
        let mut writer = ModelWriter::glb_in_memory(export)?;
        made.rules.generate_lots(
            &preview.lots,
            &made.options,
            Target::Writer(&mut writer),
            |_| {},
        )?;
        Ok(writer.finish_bytes()?.0)
    });
    match job.await {
        Ok(Ok(bytes)) => (
            [
                (header::CONTENT_TYPE, "model/gltf-binary"),
                (
                    header::CONTENT_DISPOSITION,
                    "attachment; filename=\"model.glb\"",
                ),
            ],
            bytes,
        )
            .into_response(),
        Ok(Err(e)) => (StatusCode::INTERNAL_SERVER_ERROR, format!("{e}\n")).into_response(),
        Err(_) => (StatusCode::INTERNAL_SERVER_ERROR, "export failed\n").into_response(),
    }
}

#[derive(Deserialize)]
struct Triangle {
    lot: usize,
    mesh: usize,
    tri: usize,
}

async fn provenance(State(app): State<App>, Query(t): Query<Triangle>) -> Response {
    let s = app.preview.snapshot();
    let Some(made) = &s.made_by else {
        return not_found();
    };
    let Some(lot) = made.results.get(t.lot) else {
        return not_found();
    };
    let Some(p) = lot.provenance(&made.rules, t.mesh, t.tri) else {
        return not_found();
    };
    let mut j = json!({
        "lot": lot.name,
        "rule": p.rule,
        "shape": p.shape.as_ref(),
        "model_version": s.model_version,
    });
    if let Some(at) = &p.location {
        let root = &app.preview.roots;
        let file = root
            .iter()
            .find_map(|r| at.file.strip_prefix(r).ok())
            .unwrap_or(&at.file);
        j["file"] = json!(file.to_string_lossy());
        j["line"] = json!(at.line);
        j["column"] = json!(at.column);
        j["line_text"] = json!(at.line_text);
    }
    no_store("application/json", j.to_string())
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamsBody {
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    attrs: BTreeMap<String, serde_json::Value>,
}

async fn set_params(State(app): State<App>, Json(body): Json<serde_json::Value>) -> Response {
    // Only an object: serde would also take `[]` for a struct whose
    // fields all have defaults.
    if !body.is_object() {
        return (StatusCode::UNPROCESSABLE_ENTITY, "expected a JSON object\n").into_response();
    }
    let body: ParamsBody = match serde_json::from_value(body) {
        Ok(b) => b,
        Err(e) => return (StatusCode::UNPROCESSABLE_ENTITY, format!("{e}\n")).into_response(),
    };
    if body.attrs.len() > MAX_ATTRS {
        return (StatusCode::PAYLOAD_TOO_LARGE, "too many attributes\n").into_response();
    }
    let request = app.preview.set_params(Params {
        seed: body.seed,
        attrs: body.attrs,
    });
    (
        StatusCode::ACCEPTED,
        Json(json!({"accepted": true, "request": request})),
    )
        .into_response()
}

/// The page's files (`/`, `/main.js`) and the workspace's (`/files/...`),
/// by the raw request path: nothing here decodes before checking.
async fn files(State(app): State<App>, method: Method, uri: Uri) -> Response {
    if method != Method::GET && method != Method::HEAD {
        return (StatusCode::METHOD_NOT_ALLOWED, "method not allowed\n").into_response();
    }
    let path = uri.path();
    if let Some(rest) = path.strip_prefix("/files/") {
        return workspace_file(&app, rest).await;
    }
    let name = match path {
        "/" | "/index.html" => "index.html",
        _ => match path.strip_prefix('/').and_then(paths::page_file) {
            Some(n) => n,
            None => return not_found(),
        },
    };
    let file = app.web_dir.join(name);
    match tokio::fs::read(&file).await {
        Ok(bytes) => no_store(paths::content_type(&file), bytes),
        Err(_) if name == "index.html" => (
            StatusCode::SERVICE_UNAVAILABLE,
            [(header::CONTENT_TYPE, "text/html; charset=utf-8")],
            format!(
                "<!doctype html><title>cga serve</title><h1>The preview page is not built</h1>\
                 <p>Run once, in the repository:</p><pre>{}</pre><p>then reload.</p>",
                crate::WEB_BUILD_HINT
            ),
        )
            .into_response(),
        Err(_) => not_found(),
    }
}

async fn workspace_file(app: &App, raw: &str) -> Response {
    let Some(rel) = paths::relative_path(raw) else {
        return not_found();
    };
    let preview = app.preview.clone();
    let read = tokio::task::spawn_blocking(move || {
        let world = preview.engine.world();
        for root in &preview.roots {
            let path = root.join(&rel);
            // The confined world refuses what leads out of the roots
            // (symbolic links included).
            match world.metadata(&path) {
                Some(m) if !m.is_dir && m.len <= MAX_FILE => {
                    if let Ok(bytes) = world.read(&path) {
                        return Some((path, bytes));
                    }
                }
                _ => {}
            }
        }
        None
    })
    .await;
    match read {
        Ok(Some((path, bytes))) => no_store(paths::content_type(&path), bytes),
        _ => not_found(),
    }
}
