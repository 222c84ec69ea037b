//! The server over real sockets: what it serves, what it refuses, and that
//! it stays up when a rule runs away.
//!
//! Requests are written by hand on a TCP stream, so that paths reach the
//! server exactly as written (an HTTP client library would normalise
//! `/../`).

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::Path;
use std::time::Duration;

use cga_serve::{Config, Server};
use serde_json::Value as Json;

fn request(addr: SocketAddr, raw: &[u8]) -> (u16, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    s.write_all(raw).unwrap();
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    let text = String::from_utf8_lossy(&out);
    let status = text
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status in {text:?}"));
    let body = match out.windows(4).position(|w| w == b"\r\n\r\n") {
        Some(i) => out[i + 4..].to_vec(),
        None => Vec::new(),
    };
    (status, body)
}

fn get(addr: SocketAddr, path: &str) -> (u16, Vec<u8>) {
    request(
        addr,
        format!("GET {path} HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n").as_bytes(),
    )
}

fn post(addr: SocketAddr, path: &str, body: &str) -> (u16, Vec<u8>) {
    request(
        addr,
        format!(
            "POST {path} HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\
             Content-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
            body.len()
        )
        .as_bytes(),
    )
}

/// A body sent in chunks (`Transfer-Encoding: chunked`), joined.
fn dechunk(mut body: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let line = body.windows(2).position(|w| w == b"\r\n").unwrap();
        let size = usize::from_str_radix(std::str::from_utf8(&body[..line]).unwrap(), 16).unwrap();
        if size == 0 {
            return out;
        }
        out.extend_from_slice(&body[line + 2..line + 2 + size]);
        body = &body[line + 2 + size + 2..];
    }
}

/// The frames of a binary model (see `cga_serve::encode`): headers and
/// data.
fn frames(bytes: &[u8]) -> Vec<(Json, Vec<u8>)> {
    assert_eq!(&bytes[..4], b"CGAF");
    let mut at = 4;
    let mut out = Vec::new();
    while at < bytes.len() {
        let h = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        let d = u32::from_le_bytes(bytes[at + 4..at + 8].try_into().unwrap()) as usize;
        let header = serde_json::from_slice(&bytes[at + 8 + d..at + 8 + d + h]).unwrap();
        out.push((header, bytes[at + 8..at + 8 + d].to_vec()));
        at += 8 + d + h;
    }
    assert_eq!(at, bytes.len());
    out
}

fn state(addr: SocketAddr) -> Json {
    let (status, body) = get(addr, "/api/state");
    assert_eq!(status, 200);
    serde_json::from_slice(&body).unwrap()
}

/// A workspace with a rule file (in `rules/`, beside `assets/`), a web
/// folder with a page, and a secret beside the workspace.
fn workspace(rule: &str) -> (tempfile::TempDir, Server) {
    let dir = tempfile::tempdir().unwrap();
    let project = dir.path().join("project");
    std::fs::create_dir_all(project.join("rules")).unwrap();
    std::fs::create_dir_all(project.join("assets")).unwrap();
    std::fs::create_dir_all(dir.path().join("web")).unwrap();
    std::fs::write(project.join("rules/a.cga"), rule).unwrap();
    std::fs::write(project.join("assets/brick.png"), b"\x89PNG fake").unwrap();
    std::fs::write(project.join("assets/tree.obj"), b"v 0 0 0\n").unwrap();
    std::fs::write(dir.path().join("secret.txt"), b"secret").unwrap();
    std::fs::write(dir.path().join("web/index.html"), b"<!doctype html>page").unwrap();
    let mut config = Config::new(project.join("rules/a.cga"));
    config.port = 0;
    config.web_dir = Some(dir.path().join("web"));
    config.limits.max_seconds = 2.0;
    let server = cga_serve::start(config).unwrap();
    (dir, server)
}

const RULE: &str = r##"
@Range(min=1, max=20) @Group("Massing", 1) @Order(1)
attr height = 10
@Enum("flat", "gable") @Group("Massing", 1) @Order(2)
attr roof = "flat"
@Range("Visualization", "3DPrint")
attr mode = "Visualization"
@Color @Description("The wall's colour")
attr wall = "#c0b0a0"
@File("png")
attr texture = "../assets/brick.png"
@Hidden
attr secret = 1
attr tall = false

@StartRule
Lot --> extrude(height) color(wall) texture(texture) print("made") report("h", height) Mass.
"##;

#[test]
fn state_model_provenance_and_parameters() {
    let (_dir, server) = workspace(RULE);
    let addr = server.addr;
    let s = state(addr);
    assert_eq!(s["rules"], "rules/a.cga");
    assert_eq!(s["stale"], false);
    assert_eq!(s["prints"][0]["text"], "made");
    assert_eq!(s["reports"][0]["value"], 10.0);
    assert_eq!(s["stats"]["lots"], 1);
    let attr = |name: &str| {
        s["attributes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|a| a["name"] == name)
            .unwrap()
            .clone()
    };
    assert_eq!(attr("height")["range"]["max"], 20.0);
    assert_eq!(attr("height")["group"]["name"], "Massing");
    assert_eq!(attr("height")["order"], 1.0);
    assert_eq!(attr("roof")["enum"], serde_json::json!(["flat", "gable"]));
    assert_eq!(
        attr("mode")["enum"],
        serde_json::json!(["Visualization", "3DPrint"])
    );
    assert_eq!(attr("height")["enum"], Json::Null);
    assert_eq!(attr("wall")["color"], true);
    assert_eq!(attr("wall")["description"], "The wall's colour");
    assert_eq!(attr("secret")["hidden"], true);
    assert_eq!(attr("tall")["type"], "bool");
    assert_eq!(
        attr("texture")["files"],
        serde_json::json!(["../assets/brick.png"])
    );

    // The model: a box 10 m high on the default 20 x 30 lot.
    let (status, model) = get(addr, "/api/model.bin");
    assert_eq!(status, 200);
    let frames = frames(&model);
    // The start, the lot, the end.
    assert_eq!(frames.len(), 3);
    assert_eq!(frames[0].0["start"]["lots"], 1);
    let mesh = &frames[1].0["lot"]["meshes"][0];
    // The texture named relative to the rule file, served from the workspace.
    assert_eq!(mesh["texture"], "files/assets/brick.png");
    assert_eq!(mesh["triangles"], 12);
    assert_eq!(frames[2].0["end"]["complete"], true);
    assert_eq!(frames[2].0["end"]["model_version"], s["model_version"]);
    let (status, lots) = get(addr, "/api/lots.bin");
    assert_eq!((status, &lots[..4]), (200, &b"CGAF"[..]));
    let (status, glb) = get(addr, "/api/model.glb");
    assert_eq!((status, &glb[..4]), (200, &b"glTF"[..]));
    let (status, body) = get(addr, "/api/provenance?lot=0&mesh=0&tri=0");
    assert_eq!(status, 200);
    let p: Json = serde_json::from_slice(&body).unwrap();
    assert_eq!(p["rule"], "Lot");
    assert_eq!(p["file"], "rules/a.cga");
    assert_eq!(p["line"], 17);
    assert_eq!(get(addr, "/api/provenance?lot=0&mesh=0&tri=99999").0, 404);
    assert_eq!(get(addr, "/api/provenance?lot=7&mesh=0&tri=0").0, 404);

    // New values regenerate; the report shows the new height.
    let version = s["version"].as_u64().unwrap();
    let (status, _) = post(
        addr,
        "/api/params",
        r#"{"seed": 3, "attrs": {"height": 15}}"#,
    );
    assert_eq!(status, 202);
    assert!(server
        .preview
        .wait_for_version(version + 1, Duration::from_secs(30)));
    let s = state(addr);
    assert_eq!(s["reports"][0]["value"], 15.0);
    assert_eq!(s["seed"], 3);
    // Values of unknown attributes or the wrong type are left out.
    let version = s["version"].as_u64().unwrap();
    let (status, _) = post(
        addr,
        "/api/params",
        r#"{"attrs": {"nothing": 1, "height": "tall"}}"#,
    );
    assert_eq!(status, 202);
    assert!(server
        .preview
        .wait_for_version(version + 1, Duration::from_secs(30)));
    let s = state(addr);
    assert_eq!(s["reports"][0]["value"], 10.0);
    assert_eq!(s["problems"], serde_json::json!([]));
}

/// The model being made comes in frames for the request that asked for
/// it; a request replaced before its model ends abandoned; one not yet
/// made is not found.
#[test]
fn the_model_being_made_comes_for_its_request() {
    let (dir, server) = workspace(RULE);
    let addr = server.addr;
    let version = state(addr)["version"].as_u64().unwrap();
    let (status, body) = post(addr, "/api/params", r#"{"attrs": {"height": 15}}"#);
    assert_eq!(status, 202);
    // The answer names the request.
    let n = serde_json::from_slice::<Json>(&body).unwrap()["request"]
        .as_u64()
        .unwrap();
    assert_eq!(n, server.preview.latest_request());
    assert_eq!(get(addr, &format!("/api/live.bin?n={}", n + 1)).0, 404);
    // Asked for while it is made or after: all of its frames.
    let (status, body) = get(addr, &format!("/api/live.bin?n={n}"));
    assert_eq!(status, 200);
    let live = frames(&dechunk(&body));
    assert_eq!(
        live.len(),
        3,
        "{:?}",
        live.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    assert_eq!(live[1].0["lot"]["meshes"][0]["triangles"], 12);
    // The box of the model 15 m high.
    assert_eq!(live[2].0["end"]["bounds"]["max"][1], 15.0);
    assert_eq!(live[2].0["end"]["complete"], true);
    assert!(server
        .preview
        .wait_for_version(version + 1, Duration::from_secs(30)));
    let s = state(addr);
    assert_eq!(live[2].0["end"]["model_version"], s["model_version"]);
    // The model sent whole is the same frames.
    let (_, model) = get(addr, "/api/model.bin");
    assert_eq!(frames(&model), live);

    // An older request's model, replaced: abandoned.
    let (status, body) = get(addr, &format!("/api/live.bin?n={}", n - 1));
    assert_eq!(status, 200);
    let old = frames(&dechunk(&body));
    assert_eq!(old.len(), 2);
    assert_eq!(old[1].0["end"]["complete"], false);

    // Rules with an error make no model: abandoned too, and the model
    // shown stays.
    let rules = dir.path().join("project/rules/a.cga");
    let text = std::fs::read_to_string(&rules).unwrap();
    std::fs::write(&rules, format!("{text}\nBroken --> split(\n")).unwrap();
    assert!(server
        .preview
        .wait_for_version(s["version"].as_u64().unwrap() + 1, Duration::from_secs(30)));
    let n = server.preview.latest_request();
    let (_, body) = get(addr, &format!("/api/live.bin?n={n}"));
    let broken = frames(&dechunk(&body));
    assert_eq!(broken.last().unwrap().0["end"]["complete"], false);
    let s = state(addr);
    assert_eq!(s["has_errors"], true);
    assert_eq!(s["model_version"], live[2].0["end"]["model_version"]);
}

/// Rules with an error from the start: the first request's model is
/// abandoned, in frames a page reads (the magic, the start, the end).
#[test]
fn the_first_model_of_rules_with_an_error_is_abandoned_in_frames() {
    let (_dir, server) = workspace("Lot --> split(\n");
    assert_eq!(state(server.addr)["has_errors"], true);
    let (status, body) = get(server.addr, "/api/live.bin?n=0");
    assert_eq!(status, 200);
    let live = frames(&dechunk(&body));
    assert_eq!(live.len(), 2);
    assert_eq!(live[0].0["start"]["lots"], 1);
    assert_eq!(live[1].0["end"]["complete"], false);
}

#[test]
fn only_the_page_and_workspace_files_are_served() {
    let (_dir, server) = workspace(RULE);
    let addr = server.addr;
    assert_eq!(get(addr, "/").0, 200);
    assert_eq!(get(addr, "/index.html").1, b"<!doctype html>page");
    let (status, body) = get(addr, "/files/assets/brick.png");
    assert_eq!((status, body.as_slice()), (200, &b"\x89PNG fake"[..]));
    assert_eq!(get(addr, "/files/rules/a.cga").0, 200);
    assert_eq!(get(addr, "/files/assets%2Ftree.obj").0, 200);
    for path in [
        "/../../etc/passwd",
        "/..%2f..%2fetc%2fpasswd",
        "/%2e%2e/%2e%2e/etc/passwd",
        "/files/../../etc/passwd",
        "/files/..%2f..%2fetc%2fpasswd",
        "/files/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
        "/files/%2E%2E%2F%2E%2E%2Fetc%2Fpasswd",
        "/files/%252e%252e/%252e%252e/etc/passwd",
        "/files/..%5c..%5cetc%5cpasswd",
        "/files/%2fetc%2fpasswd",
        "/files//etc/passwd",
        "/files/assets/../../secret.txt",
        "/files/..%2fsecret.txt",
        "/files/%2e%2e/secret.txt",
        "/files/%c0%ae%c0%ae/secret.txt",
        "/files/assets",
        "/files/",
        "/etc/passwd",
        "/web/index.html",
        "/.env",
        "/nothing.js",
    ] {
        let (status, body) = get(addr, path);
        assert_eq!(status, 404, "{path}");
        assert!(!String::from_utf8_lossy(&body).contains("root:"), "{path}");
        assert!(!String::from_utf8_lossy(&body).contains("secret"), "{path}");
    }
}

#[test]
fn malformed_requests_get_4xx_and_the_server_stays_up() {
    let (_dir, server) = workspace(RULE);
    let addr = server.addr;
    let bad_posts = [
        "{",
        "[]",
        r#"{"seed": -1}"#,
        r#"{"seed": "x"}"#,
        r#"{"attrs": 5}"#,
        r#"{"other": 1}"#,
    ];
    for body in bad_posts {
        let status = post(addr, "/api/params", body).0;
        assert!((400..500).contains(&status), "{body}: {status}");
    }
    // Too large a body.
    let big = format!(r#"{{"attrs": {{"a": "{}"}}}}"#, "x".repeat(200_000));
    let status = post(addr, "/api/params", &big).0;
    assert_eq!(status, 413);
    // No JSON content type.
    let status = request(
        addr,
        b"POST /api/params HTTP/1.1\r\nHost: x\r\nConnection: close\r\nContent-Length: 2\r\n\r\n{}",
    )
    .0;
    assert_eq!(status, 415);
    for path in [
        "/api/provenance",
        "/api/provenance?lot=a&mesh=0&tri=0",
        "/api/provenance?lot=-1&mesh=0&tri=0",
    ] {
        assert_eq!(get(addr, path).0, 400, "{path}");
    }
    assert_eq!(get(addr, "/api/params").0, 405);
    assert_eq!(
        request(
            addr,
            b"DELETE /index.html HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
        )
        .0,
        405
    );
    // Not HTTP at all, and a header far too long.
    let mut s = TcpStream::connect(addr).unwrap();
    s.write_all(b"\x00\x01garbage\r\n\r\n").unwrap();
    let mut out = Vec::new();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let _ = s.read_to_end(&mut out);
    assert!(out.is_empty() || String::from_utf8_lossy(&out).starts_with("HTTP/1.1 4"));
    let long = format!(
        "GET / HTTP/1.1\r\nHost: x\r\nX-Long: {}\r\nConnection: close\r\n\r\n",
        "a".repeat(1 << 20)
    );
    let mut s = TcpStream::connect(addr).unwrap();
    let _ = s.write_all(long.as_bytes());
    let mut out = Vec::new();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let _ = s.read_to_end(&mut out);
    assert!(out.is_empty() || String::from_utf8_lossy(&out).starts_with("HTTP/1.1 4"));
    // Still serving.
    assert_eq!(state(addr)["stale"], false);
    // An open event stream does not keep the server from stopping.
    let mut events = TcpStream::connect(addr).unwrap();
    events
        .write_all(b"GET /api/events HTTP/1.1\r\nHost: x\r\n\r\n")
        .unwrap();
    let mut first = [0u8; 256];
    let n = events.read(&mut first).unwrap();
    assert!(String::from_utf8_lossy(&first[..n]).contains("text/event-stream"));
    let t = std::time::Instant::now();
    drop(server);
    assert!(t.elapsed() < Duration::from_secs(5));
}

#[test]
fn a_runaway_rule_is_stopped_and_reported_and_the_server_stays_up() {
    // Twenty thousand shapes a level, a thousand levels: stopped by the
    // time limit (2 s here) in any build. (Halving the lot at every level
    // would not do: a release build runs out of width in under a second.)
    let runaway = "Lot --> A\nA --> B A\nB --> split(x) { 0.001 : NIL }*\n";
    let (dir, server) = workspace(runaway);
    let addr = server.addr;
    let s = state(addr);
    let problems = s["problems"].as_array().unwrap();
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert_eq!(problems[0]["severity"], "error");
    assert_eq!(problems[0]["lot"], "rect 20x30");
    let message = problems[0]["message"].as_str().unwrap();
    assert!(
        message.contains("limit") || message.contains("time") || message.contains("depth"),
        "{message}"
    );
    assert_eq!(s["stats"]["failed"], 1);
    // The server answers while and after it ran.
    assert_eq!(get(addr, "/").0, 200);
    // A fixed rule file brings a model.
    let version = s["version"].as_u64().unwrap();
    write(
        &dir.path().join("project/rules/a.cga"),
        "Lot --> extrude(4) A.\n",
    );
    assert!(server
        .preview
        .wait_for_version(version + 1, Duration::from_secs(30)));
    let s = state(addr);
    assert_eq!(s["problems"], serde_json::json!([]), "{s}");
    assert_eq!(s["stats"]["triangles"], 12);
}

#[test]
fn a_newer_change_cancels_a_running_generation() {
    // Runs until the time limit (2 s) unless cancelled.
    let slow = "attr n = 1\nLot --> A\nA --> B A\nB --> split(x) { 0.001 : NIL }*\n";
    let (_dir, server) = workspace(slow);
    let addr = server.addr;
    let version = state(addr)["version"].as_u64().unwrap();
    let start = std::time::Instant::now();
    // The first starts a long generation, the second (right after)
    // cancels it; the third state is the last request's.
    post(addr, "/api/params", r#"{"attrs": {"n": 2}}"#);
    std::thread::sleep(Duration::from_millis(200));
    post(addr, "/api/params", r#"{"seed": 9, "attrs": {"n": 3}}"#);
    assert!(server
        .preview
        .wait_for_version(version + 1, Duration::from_secs(30)));
    let s = state(addr);
    // The state published is the newest request's: the n = 2 one was
    // cancelled, not published.
    assert_eq!(s["seed"], 9);
    assert_eq!(s["values"]["n"], 3);
    // One time-limited generation (2 s) after the cancelled one, not two.
    assert!(
        start.elapsed() < Duration::from_millis(3900),
        "{:?}",
        start.elapsed()
    );
}

/// Writes a file so that watchers see it as one change.
fn write(path: &Path, text: &str) {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, text).unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

#[test]
fn every_request_is_served_however_it_meets_the_generation() {
    // A request must not cancel the generation that serves it. It once
    // could, when the worker took the request between its being set and
    // its cancelling the running generation, and the page then waited
    // forever (seen in the latency benchmark, about one run in three).
    // The window is narrow: this test does not reliably hit it with the
    // old code; it checks that 40 quick requests are each served.
    let (_dir, server) = workspace(RULE);
    let addr = server.addr;
    for i in 0..40 {
        let height = 2 + i % 15;
        let version = server.preview.snapshot().version;
        let (status, _) = post(
            addr,
            "/api/params",
            &format!(r#"{{"attrs": {{"height": {height}}}}}"#),
        );
        assert_eq!(status, 202);
        let end = std::time::Instant::now() + Duration::from_secs(20);
        loop {
            let s = state(addr);
            if s["version"].as_u64().unwrap() > version
                && s["reports"][0]["value"] == serde_json::json!(height as f64)
            {
                break;
            }
            assert!(std::time::Instant::now() < end, "request {i} not served");
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

#[test]
fn a_saved_file_is_announced_before_its_model() {
    let (dir, server) = workspace("Lot --> extrude(4) A.\n");
    let addr = server.addr;
    let version = state(addr)["version"].as_u64().unwrap();
    let mut events = TcpStream::connect(addr).unwrap();
    events
        .write_all(b"GET /api/events HTTP/1.1\r\nHost: x\r\n\r\n")
        .unwrap();
    events
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    // Reads the stream until `until` holds of what came so far.
    let mut seen = String::new();
    let mut read_until = |until: &dyn Fn(&str) -> bool| {
        let mut buf = [0u8; 4096];
        while !until(&seen) {
            let n = events.read(&mut buf).unwrap();
            assert!(n > 0, "the stream ended: {seen}");
            seen.push_str(&String::from_utf8_lossy(&buf[..n]));
        }
        seen.clone()
    };
    // The current state comes first, and no request is announced yet.
    let start = read_until(&|s| s.contains("event: state"));
    assert!(!start.contains("event: generating"), "{start}");
    let before = start.len();
    write(
        &dir.path().join("project/rules/a.cga"),
        "Lot --> extrude(9) split(y) { 3 : A }*\n",
    );
    let after = read_until(&|s| s[before..].contains("event: state"));
    let fresh = &after[before..];
    let generating = fresh.find("event: generating").expect("announced");
    assert!(generating < fresh.find("event: state").unwrap(), "{fresh}");
    assert!(server
        .preview
        .wait_for_version(version + 1, Duration::from_secs(30)));
    // Three boxes of 12 triangles.
    assert_eq!(state(addr)["stats"]["triangles"], 36);
}

#[test]
fn a_file_written_in_place_is_read_when_its_writer_closes_it() {
    let (dir, server) = workspace("Lot --> extrude(4) A.\n");
    let version = state(server.addr)["version"].as_u64().unwrap();
    let path = dir.path().join("project/rules/a.cga");
    // Truncated, written in two parts, then closed: as an editor saving
    // in place does. The close ends the wait for the save to settle; the
    // rules read are the whole file.
    {
        let mut file = std::fs::File::create(&path).unwrap();
        file.write_all(b"Lot --> extrude(8) split(y) ").unwrap();
        file.write_all(b"{ 2 : A }*\n").unwrap();
    }
    assert!(server
        .preview
        .wait_for_version(version + 1, Duration::from_secs(30)));
    let end = std::time::Instant::now() + Duration::from_secs(30);
    // Four boxes of 12 triangles (a generation of a half-written file, if
    // one was started, is cancelled by the close's).
    while state(server.addr)["stats"]["triangles"] != 48 {
        assert!(std::time::Instant::now() < end, "{}", state(server.addr));
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(state(server.addr)["problems"], serde_json::json!([]));
}
