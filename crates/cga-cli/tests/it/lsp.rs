//! `cga lsp` driven over stdio by a small JSON-RPC client, as an editor
//! drives it: initialize, open, change (incremental), diagnostics, hover,
//! completion, signature help, definition, references, rename, symbols,
//! semantic tokens, folding, shutdown. Every answer is checked for real
//! positions, labels and messages.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use serde_json::{json, Value};

use crate::common::{cga, temp_dir, TempDir};

struct Client {
    child: Child,
    stdin: ChildStdin,
    messages: mpsc::Receiver<Value>,
    next_id: i64,
    /// Notifications received while waiting for something else.
    notes: Vec<Value>,
}

impl Client {
    fn start(root: &Path) -> Client {
        let mut child = cga()
            .args(["lsp", "--stdio"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("cga lsp starts");
        let stdin = child.stdin.take().unwrap();
        let stdout = child.stdout.take().unwrap();
        let (tx, messages) = mpsc::channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(stdout);
            loop {
                let mut length = None;
                loop {
                    let mut line = String::new();
                    if reader.read_line(&mut line).unwrap_or(0) == 0 {
                        return;
                    }
                    let line = line.trim_end();
                    if line.is_empty() {
                        break;
                    }
                    if let Some(n) = line.strip_prefix("Content-Length: ") {
                        length = n.parse::<usize>().ok();
                    }
                }
                let mut body = vec![0; length.expect("a Content-Length header")];
                reader.read_exact(&mut body).unwrap();
                let value: Value = serde_json::from_slice(&body).expect("JSON");
                if tx.send(value).is_err() {
                    return;
                }
            }
        });
        let mut client = Client {
            child,
            stdin,
            messages,
            next_id: 1,
            notes: Vec::new(),
        };
        let init = client.request(
            "initialize",
            json!({
                "processId": null,
                "rootUri": uri(root),
                "workspaceFolders": [{"uri": uri(root), "name": "ws"}],
                "capabilities": {},
            }),
        );
        let caps = &init["capabilities"];
        assert_eq!(caps["textDocumentSync"], json!(2), "incremental sync");
        assert_eq!(caps["hoverProvider"], json!(true));
        assert_eq!(caps["renameProvider"]["prepareProvider"], json!(true));
        client.notify("initialized", json!({}));
        client
    }

    fn send(&mut self, message: Value) {
        let body = message.to_string();
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).unwrap();
        self.stdin.flush().unwrap();
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(json!({"jsonrpc": "2.0", "method": method, "params": params}));
    }

    fn next(&mut self) -> Value {
        self.messages
            .recv_timeout(Duration::from_secs(60))
            .expect("the server answers within a minute")
    }

    /// The whole response (result or error).
    fn request_raw(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        self.send(json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}));
        loop {
            let m = self.next();
            if m["id"] == json!(id) && m.get("method").is_none() {
                return m;
            }
            self.notes.push(m);
        }
    }

    fn request(&mut self, method: &str, params: Value) -> Value {
        let response = self.request_raw(method, params);
        assert!(response.get("error").is_none(), "{method}: {response}");
        response["result"].clone()
    }

    /// The next diagnostics published for `uri`.
    fn diagnostics(&mut self, uri: &str) -> Vec<Value> {
        let is_ours = |m: &Value| {
            m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == uri
        };
        if let Some(i) = self.notes.iter().position(is_ours) {
            let m = self.notes.remove(i);
            return m["params"]["diagnostics"].as_array().unwrap().clone();
        }
        loop {
            let m = self.next();
            if is_ours(&m) {
                return m["params"]["diagnostics"].as_array().unwrap().clone();
            }
            self.notes.push(m);
        }
    }
}

fn uri(path: &Path) -> String {
    format!("file://{}", path.display())
}

/// The position of the `nth` occurrence of `needle` in `text`, moved
/// `delta` characters (ASCII text).
fn pos(text: &str, needle: &str, nth: usize, delta: usize) -> Value {
    let offset = text.match_indices(needle).nth(nth).expect(needle).0 + delta;
    let line = text[..offset].matches('\n').count();
    let column = offset - text[..offset].rfind('\n').map_or(0, |i| i + 1);
    json!({"line": line, "character": column})
}

fn at(file: &str, text: &str, needle: &str, nth: usize, delta: usize) -> Value {
    json!({"textDocument": {"uri": file}, "position": pos(text, needle, nth, delta)})
}

fn range(start: (u64, u64), end: (u64, u64)) -> Value {
    json!({"start": {"line": start.0, "character": start.1}, "end": {"line": end.0, "character": end.1}})
}

const FACADE: &str = "// A storey's height.
attr floorHeight = 3

Facade --> split(y) { ~floorHeight : Floor }*
Floor --> color(\"#ffffff\") Floor.
";

const MAIN: &str = "import fac : \"/Lib/rules/facade.cga\"

// The building's height in metres.
@Range(min=3, max=60) @Group(\"Massing\")
attr height = 10
@Group(\"Massing\")
attr depth = 5
const k = 2
twice(x) = x * k

@StartRule
Lot --> extrude(height) comp(f) { side : fac.Facade | top : Roof }
Roof --> set(height, twice(3)) roofHip(30) Roof.
";

/// A CityEngine workspace: projects `Lib` and `Main` side by side.
fn workspace() -> (TempDir, PathBuf, PathBuf) {
    let root = temp_dir("lsp");
    let lib = root.join("Lib/rules");
    let main = root.join("Main/rules");
    std::fs::create_dir_all(&lib).unwrap();
    std::fs::create_dir_all(&main).unwrap();
    std::fs::create_dir_all(root.join("Main/assets/windows")).unwrap();
    std::fs::write(root.join("Main/assets/window.obj"), "").unwrap();
    std::fs::write(root.join("Main/assets/notes.txt"), "").unwrap();
    std::fs::write(lib.join("facade.cga"), FACADE).unwrap();
    std::fs::write(main.join("main.cga"), MAIN).unwrap();
    let (main, lib) = (main.join("main.cga"), lib.join("facade.cga"));
    (root, main, lib)
}

#[test]
fn an_editor_session_over_stdio() {
    let (root, main_path, facade_path) = workspace();
    let main = uri(&main_path);
    let facade = uri(&facade_path);
    let mut c = Client::start(&root);
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": main, "languageId": "cga", "version": 1, "text": MAIN}}),
    );
    assert_eq!(c.diagnostics(&main), Vec::<Value>::new(), "a clean file");

    // Hover: a user attribute with its annotations and comment.
    let h = c.request(
        "textDocument/hover",
        at(&main, MAIN, "extrude(height)", 0, 9),
    );
    let text = h["contents"]["value"].as_str().unwrap();
    assert!(
        text.contains("@Range(min=3, max=60) @Group(\"Massing\")\nattr height = 10"),
        "{text}"
    );
    assert!(text.contains("The building's height in metres."), "{text}");
    assert_eq!(h["range"], range((11, 16), (11, 22)));
    // An operation, from the operation table.
    let h = c.request("textDocument/hover", at(&main, MAIN, "extrude", 0, 2));
    let text = h["contents"]["value"].as_str().unwrap();
    assert!(text.contains("extrude(distance)"), "{text}");
    assert!(text.contains("extrude(extrusionType, distance)"), "{text}");
    assert!(text.contains("operation (geometry creation)"), "{text}");
    // A rule of the imported file, through the workspace path.
    let h = c.request("textDocument/hover", at(&main, MAIN, "fac.Facade", 0, 6));
    let text = h["contents"]["value"].as_str().unwrap();
    assert!(text.contains("Facade --> split(y)"), "{text}");
    assert!(text.contains("rule in `facade.cga`"), "{text}");
    // A built-in function.
    let h = c.request("textDocument/hover", at(&main, MAIN, "twice(3)", 0, 1));
    assert!(h["contents"]["value"]
        .as_str()
        .unwrap()
        .contains("twice(x) = x * k"));

    // A selector keyword.
    let h = c.request("textDocument/hover", at(&main, MAIN, "side :", 0, 1));
    assert_eq!(
        h["contents"]["value"],
        "```cga\nside\n```\nselector keyword"
    );

    // Definition: across the import, and of a parameter.
    let d = c.request(
        "textDocument/definition",
        at(&main, MAIN, "fac.Facade", 0, 5),
    );
    assert_eq!(d, json!({"uri": facade, "range": range((3, 0), (3, 6))}));
    let d = c.request("textDocument/definition", at(&main, MAIN, "x * k", 0, 0));
    assert_eq!(d, json!({"uri": main, "range": range((8, 6), (8, 7))}));
    let d = c.request(
        "textDocument/definition",
        at(&main, MAIN, "/Lib/rules", 0, 3),
    );
    assert_eq!(d["uri"], json!(facade));

    // References of the imported rule: its declaration and the use.
    let refs = c.request(
        "textDocument/references",
        json!({"textDocument": {"uri": facade}, "position": pos(FACADE, "Facade", 0, 1),
               "context": {"includeDeclaration": true}}),
    );
    let mut refs: Vec<(String, Value)> = refs
        .as_array()
        .unwrap()
        .iter()
        .map(|l| (l["uri"].as_str().unwrap().to_string(), l["range"].clone()))
        .collect();
    refs.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(
        refs,
        [
            (facade.clone(), range((3, 0), (3, 6))),
            (main.clone(), range((11, 45), (11, 51))),
        ]
    );

    // Rename the attribute: declaration, uses, and `set(height, ...)`.
    let edit = c.request(
        "textDocument/rename",
        json!({"textDocument": {"uri": main}, "position": pos(MAIN, "attr height", 0, 6), "newName": "storeys"}),
    );
    let mut edits = edit["changes"][&main].as_array().unwrap().clone();
    edits.sort_by_key(|e| {
        (
            e["range"]["start"]["line"].as_u64(),
            e["range"]["start"]["character"].as_u64(),
        )
    });
    let ranges: Vec<&Value> = edits.iter().map(|e| &e["range"]).collect();
    assert_eq!(
        ranges,
        [
            &range((4, 5), (4, 11)),
            &range((11, 16), (11, 22)),
            &range((12, 13), (12, 19))
        ]
    );
    assert!(edits.iter().all(|e| e["newText"] == "storeys"));
    // Renaming the imported rule edits both files, only `Facade` of `fac.Facade`.
    let edit = c.request(
        "textDocument/rename",
        json!({"textDocument": {"uri": main}, "position": pos(MAIN, "fac.Facade", 0, 7), "newName": "Front"}),
    );
    assert_eq!(
        edit["changes"][&main],
        json!([{"range": range((11, 45), (11, 51)), "newText": "Front"}])
    );
    assert_eq!(
        edit["changes"][&facade],
        json!([{"range": range((3, 0), (3, 6)), "newText": "Front"}])
    );
    // Built-ins cannot be renamed; names must be names.
    let r = c.request_raw(
        "textDocument/rename",
        json!({"textDocument": {"uri": main}, "position": pos(MAIN, "extrude", 0, 1), "newName": "x"}),
    );
    assert!(
        r["error"]["message"]
            .as_str()
            .unwrap()
            .contains("can be renamed"),
        "{r}"
    );
    let r = c.request_raw(
        "textDocument/rename",
        json!({"textDocument": {"uri": main}, "position": pos(MAIN, "attr depth", 0, 6), "newName": "a b"}),
    );
    assert!(
        r["error"]["message"]
            .as_str()
            .unwrap()
            .contains("not a CGA name"),
        "{r}"
    );
    let r = c.request_raw(
        "textDocument/rename",
        json!({"textDocument": {"uri": main}, "position": pos(MAIN, "attr depth", 0, 6), "newName": "height"}),
    );
    assert_eq!(
        r["error"]["message"], "`height` is already defined in main.cga",
        "{r}"
    );

    // Completion: selectors in a comp block, names of an import, attributes
    // in set(), operations with snippets, file paths.
    let labels = |v: &Value| -> Vec<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|i| i["label"].as_str().unwrap().to_string())
            .collect()
    };
    let items = c.request("textDocument/completion", at(&main, MAIN, "side :", 0, 0));
    let l = labels(&items);
    assert!(
        l.contains(&"front".to_string()) && l.contains(&"street.front".to_string()),
        "{l:?}"
    );
    assert!(!l.contains(&"extrude".to_string()));
    let items = c.request(
        "textDocument/completion",
        at(&main, MAIN, "fac.Facade", 0, 4),
    );
    let l = labels(&items);
    assert_eq!(l, ["floorHeight", "Facade", "Floor"]);
    let items = c.request(
        "textDocument/completion",
        at(&main, MAIN, "set(height", 0, 4),
    );
    let l = labels(&items);
    assert!(
        l.starts_with(&[
            "height".to_string(),
            "depth".to_string(),
            "fac.floorHeight".to_string()
        ]),
        "{l:?}"
    );
    assert!(l.contains(&"material.color.rgb".to_string()));
    let items = c.request("textDocument/completion", at(&main, MAIN, "roofHip", 0, 0));
    let all = items.as_array().unwrap();
    let split = all
        .iter()
        .find(|i| i["label"] == "split")
        .expect("split offered");
    assert_eq!(split["insertText"], "split(${1:axis}) { $0 }");
    assert_eq!(split["insertTextFormat"], 2);
    let twice = all
        .iter()
        .find(|i| i["label"] == "twice")
        .expect("twice offered");
    assert_eq!(twice["insertText"], "twice(${1:x})");
    assert!(all.iter().any(|i| i["label"] == "Lot" && i["kind"] == 7));
    assert!(all.iter().any(|i| i["label"] == "rand" && i["kind"] == 3));

    // Signature help inside roofHip( and set(.
    let s = c.request(
        "textDocument/signatureHelp",
        at(&main, MAIN, "roofHip(30)", 0, 8),
    );
    assert_eq!(
        s["signatures"][s["activeSignature"].as_u64().unwrap() as usize]["label"],
        "roofHip(angle)"
    );
    assert_eq!(s["activeParameter"], 0);
    let s = c.request(
        "textDocument/signatureHelp",
        at(&main, MAIN, "twice(3)", 0, 6),
    );
    assert_eq!(s["signatures"][0]["label"], "twice(x)");

    // Incremental change: a typo in a rule name gives a warning, an
    // unknown name an error, at their places.
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": main, "version": 2}, "contentChanges": [
            {"range": range((11, 60), (11, 64)), "text": "Rof"},
            {"range": range((11, 16), (11, 22)), "text": "hieght"},
        ]}),
    );
    let diags = c.diagnostics(&main);
    let mut found: Vec<(String, Value, u64)> = diags
        .iter()
        .map(|d| {
            (
                d["message"].as_str().unwrap().to_string(),
                d["range"].clone(),
                d["severity"].as_u64().unwrap(),
            )
        })
        .collect();
    found.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(found.len(), 2, "{found:?}");
    assert!(
        found[0].0.starts_with("rule `Rof` is not defined"),
        "{found:?}"
    );
    assert!(found[0].0.contains("did you mean `Roof`?"), "{found:?}");
    assert_eq!(
        (found[0].1.clone(), found[0].2),
        (range((11, 60), (11, 63)), 2)
    );
    assert_eq!(
        found[1].0,
        "unknown name `hieght`\nhelp: did you mean `height`?"
    );
    assert_eq!(
        (found[1].1.clone(), found[1].2),
        (range((11, 16), (11, 22)), 1)
    );

    // A file that does not parse still gets features.
    c.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": main, "version": 3}, "contentChanges": [
            {"range": range((9, 0), (9, 0)), "text": "Broken --> extrude(\n"},
        ]}),
    );
    let diags = c.diagnostics(&main);
    assert!(diags.iter().any(|d| d["severity"] == 1), "{diags:?}");
    let edited = {
        let mut lines: Vec<&str> = MAIN.lines().collect();
        lines.insert(9, "Broken --> extrude(");
        lines.join("\n")
    };
    let h = c.request("textDocument/hover", at(&main, &edited, "attr depth", 0, 6));
    assert!(h["contents"]["value"]
        .as_str()
        .unwrap()
        .contains("attr depth = 5"));

    // Symbols: attributes grouped by @Group.
    let symbols = c.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": main}}),
    );
    let names: Vec<&str> = symbols
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        ["fac", "Massing", "k", "twice", "Broken", "Lot", "Roof"]
    );
    let massing: Vec<&str> = symbols[1]["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(massing, ["height", "depth"]);
    let ws = c.request("workspace/symbol", json!({"query": "flhe"}));
    assert_eq!(ws.as_array().unwrap().len(), 1, "{ws}");
    assert_eq!(ws[0]["name"], "floorHeight");
    assert_eq!(ws[0]["location"]["uri"], json!(facade));

    // Semantic tokens: the comment line, `attr` keyword, `height` declared.
    let tokens = c.request(
        "textDocument/semanticTokens/full",
        json!({"textDocument": {"uri": facade}}),
    );
    let data: Vec<u64> = tokens["data"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    // [deltaLine, deltaStart, length, type, modifiers]: comment, `attr`,
    // `floorHeight` (variable, declaration), `3`.
    assert_eq!(
        &data[..20],
        &[0, 0, 21, 8, 0, 1, 0, 4, 5, 0, 0, 5, 11, 2, 1, 0, 14, 1, 7, 0]
    );
    // `Facade` declared (type), `split` (operation, built-in).
    assert_eq!(&data[20..30], &[2, 0, 6, 1, 1, 0, 11, 5, 10, 4]);

    // Folding: the block comment of a longer file.
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri(&root.join("Main/rules/fold.cga")), "languageId": "cga", "version": 1,
               "text": "// one\n// two\nLot -->\n    comp(f) {\n        top : X.\n    }\n"}}),
    );
    let folds = c.request(
        "textDocument/foldingRange",
        json!({"textDocument": {"uri": uri(&root.join("Main/rules/fold.cga"))}}),
    );
    let folds: Vec<(u64, u64)> = folds
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["startLine"].as_u64().unwrap(),
                f["endLine"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(folds, [(0, 1), (2, 5), (3, 5)]);

    // File paths inside i("...") and import "...".
    let text = "Lot --> i(\"window.obj\") X.\nimport f : \"/Lib/\"\n";
    let scratch = uri(&root.join("Main/rules/paths.cga"));
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": scratch, "languageId": "cga", "version": 1, "text": text}}),
    );
    let items = c.request(
        "textDocument/completion",
        at(&scratch, text, "window.obj", 0, 0),
    );
    let l = labels(&items);
    assert!(
        l.contains(&"window.obj".to_string()) && l.contains(&"windows/".to_string()),
        "{l:?}"
    );
    assert!(!l.contains(&"notes.txt".to_string()), "{l:?}");
    let items = c.request("textDocument/completion", at(&scratch, text, "/Lib/", 0, 5));
    assert_eq!(labels(&items), ["rules/"]);

    // Formatting: one edit replacing the document.
    let messy = "Lot -->\n extrude(1)   \n";
    let fmt_uri = uri(&root.join("Main/rules/messy.cga"));
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": fmt_uri, "languageId": "cga", "version": 1, "text": messy}}),
    );
    let edits = c.request(
        "textDocument/formatting",
        json!({"textDocument": {"uri": fmt_uri}, "options": {"tabSize": 4, "insertSpaces": true}}),
    );
    assert_eq!(
        edits,
        json!([{"range": range((0, 0), (2, 0)), "newText": "Lot -->\n    extrude(1)\n"}])
    );

    // A problem in an imported file shows on the import that leads there.
    let broken_facade = FACADE.replace("color(\"#ffffff\")", "colr(1)");
    c.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": facade, "languageId": "cga", "version": 1, "text": broken_facade}}),
    );
    let own = c.diagnostics(&facade);
    assert_eq!(own.len(), 1, "{own:?}");
    assert_eq!(own[0]["range"], range((4, 10), (4, 14)));
    let message = own[0]["message"].as_str().unwrap().to_string();
    let importer = c.diagnostics(&main);
    let shown: Vec<&Value> = importer
        .iter()
        .filter(|d| {
            d["message"]
                .as_str()
                .unwrap()
                .starts_with("in facade.cga:5:11: ")
        })
        .collect();
    assert_eq!(shown.len(), 1, "{importer:?}");
    assert_eq!(
        shown[0]["message"],
        format!("in facade.cga:5:11: {message}")
    );
    assert_eq!(shown[0]["range"], range((0, 0), (0, 36)));

    // Unknown methods are answered with an error, not a crash.
    let r = c.request_raw("textDocument/unknownThing", json!({}));
    assert_eq!(r["error"]["code"], -32601);

    assert_eq!(c.request("shutdown", Value::Null), Value::Null);
    c.notify("exit", Value::Null);
    let status = c.child.wait().unwrap();
    assert!(status.success(), "{status}");
}

#[test]
fn fmt_formats_in_place_and_check_reports() {
    let dir = temp_dir("fmt");
    let file = dir.join("a.cga");
    let messy = "Lot -->  \n\textrude(10)\n  comp(f) {\ntop : Roof.\n}\n\n\n\nRoof --> X.";
    std::fs::write(&file, messy).unwrap();
    let out = cga().args(["fmt", "--check"]).arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("a.cga: not formatted"));
    assert_eq!(
        std::fs::read_to_string(&file).unwrap(),
        messy,
        "--check changes nothing"
    );
    let out = cga().arg("fmt").arg(&file).output().unwrap();
    assert!(out.status.success());
    assert_eq!(
        std::fs::read_to_string(&file).unwrap(),
        "Lot -->\n    extrude(10)\n    comp(f) {\n        top : Roof.\n    }\n\nRoof --> X.\n"
    );
    let out = cga().args(["fmt", "--check"]).arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
}
