//! The server never crashes: prefixes of every rule file of
//! `../shared/corpus` and random edits go through `didChange`, and every
//! request is asked at random places; each must be answered without an
//! internal error (a panic caught while answering is one).
//!
//! Prefixes are sampled (`CGA_LSP_PREFIXES` per file, default 12, evenly
//! spaced, plus the first 200 bytes one by one), so the test stays within
//! seconds; `CGA_LSP_PREFIXES=0` takes every prefix (long: a benchmark).

use std::path::{Path, PathBuf};

use lsp_server::{ErrorCode, Notification, Request, RequestId};
use serde_json::{json, Value};

use crate::server::{self, Server};

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 33) as usize % n.max(1)
    }
}

pub(crate) fn cga_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            cga_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "cga") {
            out.push(p);
        }
    }
}

struct Session {
    server: Server,
    next_id: i32,
    uri: String,
    version: i32,
}

impl Session {
    fn notify(&mut self, method: &str, params: Value) {
        self.server
            .notification(Notification::new(method.to_string(), params));
    }

    fn set_text(&mut self, text: &str) {
        self.version += 1;
        let uri = self.uri.clone();
        self.notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": uri, "version": self.version},
                   "contentChanges": [{"text": text}]}),
        );
    }

    fn ask(&mut self, method: &str, params: Value, what: &str) {
        self.next_id += 1;
        let response = self.server.request(Request {
            id: RequestId::from(self.next_id),
            method: method.to_string(),
            params,
        });
        if let Some(e) = response.error {
            assert_ne!(
                e.code,
                ErrorCode::InternalError as i32,
                "{method} failed on {what}: {}",
                e.message
            );
        }
    }

    /// Every position request at `line:character`.
    fn ask_at(&mut self, line: usize, character: usize, what: &str) {
        let uri = self.uri.clone();
        let at = json!({"textDocument": {"uri": uri}, "position": {"line": line, "character": character}});
        for method in [
            server::HOVER,
            server::COMPLETION,
            server::SIGNATURE_HELP,
            server::DEFINITION,
            server::PREPARE_RENAME,
        ] {
            self.ask(method, at.clone(), what);
        }
    }

    fn ask_document(&mut self, what: &str) {
        let doc = json!({"textDocument": {"uri": self.uri.clone()}});
        for method in [
            server::DOCUMENT_SYMBOL,
            server::SEMANTIC_TOKENS,
            server::FOLDING_RANGE,
        ] {
            self.ask(method, doc.clone(), what);
        }
    }
}

fn random_position(rng: &mut Rng, text: &str) -> (usize, usize) {
    let lines: Vec<&str> = text.split('\n').collect();
    let line = rng.below(lines.len() + 1);
    let width = lines.get(line).map_or(3, |l| l.encode_utf16().count() + 2);
    (line, rng.below(width))
}

#[test]
fn prefixes_and_random_edits_of_the_corpus_never_crash_the_server() {
    let Some(corpus) = cga_testkit::shared("corpus/workspace") else {
        return;
    };
    // Document keys are the paths of their URIs (without `..`).
    let corpus = corpus.canonicalize().unwrap();
    let samples: usize = std::env::var("CGA_LSP_PREFIXES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(12);
    let mut files = Vec::new();
    cga_files(&corpus, &mut files);
    assert!(
        files.len() >= 50,
        "{} rule files in the corpus",
        files.len()
    );
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let init = lsp_types::InitializeParams::default();
    for path in &files {
        let text = cga::decode_text(&std::fs::read(path).unwrap());
        let mut s = Session {
            server: Server::new(&init, &[]),
            next_id: 0,
            uri: lsp_types::Url::from_file_path(path).unwrap().to_string(),
            version: 1,
        };
        let uri = s.uri.clone();
        s.notify(
            "textDocument/didOpen",
            json!({"textDocument": {"uri": uri, "languageId": "cga", "version": 1, "text": text}}),
        );
        let name = path
            .strip_prefix(&corpus)
            .unwrap_or(path)
            .display()
            .to_string();
        // Whole file: diagnostics and every request.
        assert!(!s
            .server
            .diagnostics(path)
            .iter()
            .any(|d| d.message.is_empty()));
        s.ask_document(&name);
        for _ in 0..20 {
            let (l, c) = random_position(&mut rng, &text);
            s.ask_at(l, c, &name);
        }
        // Prefixes.
        let bounds: Vec<usize> = (0..=text.len())
            .filter(|&i| text.is_char_boundary(i))
            .collect();
        let cuts: Vec<usize> = if samples == 0 {
            bounds.clone()
        } else {
            let mut cuts: Vec<usize> = bounds.iter().copied().take_while(|&i| i <= 200).collect();
            cuts.extend((1..=samples).map(|k| bounds[(bounds.len() - 1) * k / samples]));
            cuts
        };
        for (n, &cut) in cuts.iter().enumerate() {
            let prefix = &text[..cut];
            s.set_text(prefix);
            let what = format!("{name} cut at byte {cut}");
            // The engine's load is the costly part: on a few prefixes.
            if n % 50 == 0 || n + 1 == cuts.len() {
                s.server.diagnostics(path);
                s.ask_document(&what);
            }
            let (l, c) = random_position(&mut rng, prefix);
            s.ask_at(l, c, &what);
        }
        // Random edits: pieces of the file pasted over random ranges.
        let mut current = text.clone();
        for _ in 0..10 {
            let a = random_position(&mut rng, &current);
            let b = random_position(&mut rng, &current);
            let (start, end) = if a <= b { (a, b) } else { (b, a) };
            let from = bounds[rng.below(bounds.len())];
            let to = bounds
                [(bounds.partition_point(|&i| i < from) + rng.below(40)).min(bounds.len() - 1)];
            let piece = &text[from..to.max(from)];
            s.version += 1;
            s.notify(
                "textDocument/didChange",
                json!({"textDocument": {"uri": uri, "version": s.version}, "contentChanges": [{
                    "range": {"start": {"line": start.0, "character": start.1},
                              "end": {"line": end.0, "character": end.1}},
                    "text": piece}]}),
            );
            let index = crate::text::LineIndex::new(&current);
            let (so, eo) = (
                index.offset(
                    &current,
                    lsp_types::Position::new(start.0 as u32, start.1 as u32),
                ),
                index.offset(
                    &current,
                    lsp_types::Position::new(end.0 as u32, end.1 as u32),
                ),
            );
            current.replace_range(so..eo.max(so), piece);
            assert_eq!(
                s.server.docs[path].text, current,
                "incremental sync of {name}"
            );
            let (l, c) = random_position(&mut rng, &current);
            s.ask_at(l, c, &format!("{name} after edits"));
        }
        s.server.diagnostics(path);
        s.ask_document(&format!("{name} after edits"));
    }
}

/// Latency on the largest file of the corpus (a benchmark, not a timed
/// test: `cargo test -p cga-lsp --release -- --ignored --nocapture
/// latency`): median time of diagnostics after a change and of a
/// completion, over 100 runs each.
#[test]
#[ignore]
fn latency_on_the_largest_corpus_file() {
    use std::time::Instant;
    let Some(corpus) = cga_testkit::shared("corpus/workspace") else {
        return;
    };
    let corpus = corpus.canonicalize().unwrap();
    let mut files = Vec::new();
    cga_files(&corpus, &mut files);
    let path = files
        .iter()
        .max_by_key(|p| std::fs::metadata(p).map_or(0, |m| m.len()))
        .unwrap()
        .clone();
    let text = cga::decode_text(&std::fs::read(&path).unwrap());
    let mut s = Session {
        server: Server::new(&lsp_types::InitializeParams::default(), &[]),
        next_id: 0,
        uri: lsp_types::Url::from_file_path(&path).unwrap().to_string(),
        version: 1,
    };
    let uri = s.uri.clone();
    s.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri, "languageId": "cga", "version": 1, "text": text}}),
    );
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut diag = Vec::new();
    let mut completion = Vec::new();
    let line = text.lines().count() / 2;
    for i in 0..100 {
        s.version += 1;
        s.notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": uri, "version": s.version}, "contentChanges": [{
                "range": {"start": {"line": line, "character": 0}, "end": {"line": line, "character": 0}},
                "text": if i % 2 == 0 { " " } else { "" }}]}),
        );
        // A completion right after the change: it indexes the changed
        // text first (the parse is most of its time).
        let t = Instant::now();
        s.ask(
            server::COMPLETION,
            json!({"textDocument": {"uri": uri}, "position": {"line": line, "character": 4}}),
            "latency",
        );
        completion.push(t.elapsed().as_secs_f64() * 1e3);
        // Diagnostics as the server computes them when the change's time
        // comes: the engine loads the text (parse, resolve, attributes).
        let t = Instant::now();
        s.server.ensure_indexed();
        s.server.diagnostics(&path);
        diag.push(t.elapsed().as_secs_f64() * 1e3);
    }
    println!(
        "{} ({} bytes): diagnostics after a change {:.2} ms, completion {:.2} ms (medians of 100)",
        path.file_name().unwrap().to_string_lossy(),
        text.len(),
        median(diag),
        median(completion)
    );
}
