//! The requests: what the server answers, on the index of each file and
//! the operation table.

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use cga::operations::{self, ArgMode, OpDef, Status};
use cga::World;
use lsp_types::*;
use serde::de::DeserializeOwned;
use serde_json::Value;

use crate::builtins::{self, Function};
use crate::index::{Def, DefKind, FileIndex, Hit, Ref, RefKind};
use crate::scan::{scan, TokKind};
use crate::server::{self, Failure, Server};

pub fn capabilities() -> ServerCapabilities {
    let strings = |v: &[&str]| Some(v.iter().map(|s| s.to_string()).collect());
    ServerCapabilities {
        text_document_sync: Some(TextDocumentSyncCapability::Kind(
            TextDocumentSyncKind::INCREMENTAL,
        )),
        hover_provider: Some(HoverProviderCapability::Simple(true)),
        completion_provider: Some(CompletionOptions {
            trigger_characters: strings(&[".", "\"", "/", "(", "{", "|", ","]),
            ..Default::default()
        }),
        signature_help_provider: Some(SignatureHelpOptions {
            trigger_characters: strings(&["(", ","]),
            retrigger_characters: None,
            work_done_progress_options: Default::default(),
        }),
        definition_provider: Some(OneOf::Left(true)),
        references_provider: Some(OneOf::Left(true)),
        rename_provider: Some(OneOf::Right(RenameOptions {
            prepare_provider: Some(true),
            work_done_progress_options: Default::default(),
        })),
        document_symbol_provider: Some(OneOf::Left(true)),
        workspace_symbol_provider: Some(OneOf::Left(true)),
        semantic_tokens_provider: Some(SemanticTokensServerCapabilities::SemanticTokensOptions(
            SemanticTokensOptions {
                legend: legend(),
                full: Some(SemanticTokensFullOptions::Bool(true)),
                range: None,
                work_done_progress_options: Default::default(),
            },
        )),
        folding_range_provider: Some(FoldingRangeProviderCapability::Simple(true)),
        document_formatting_provider: Some(OneOf::Left(true)),
        ..Default::default()
    }
}

pub fn dispatch(s: &mut Server, method: &str, params: Value) -> Result<Value, Failure> {
    fn p<T: DeserializeOwned>(v: Value) -> Result<T, Failure> {
        serde_json::from_value(v).map_err(|e| Failure::BadParams(e.to_string()))
    }
    fn json<T: serde::Serialize>(v: T) -> Value {
        serde_json::to_value(v).unwrap_or(Value::Null)
    }
    Ok(match method {
        server::HOVER => json(hover(s, p(params)?)),
        server::COMPLETION => json(completion(s, p(params)?)),
        server::SIGNATURE_HELP => json(signature_help(s, p(params)?)),
        server::DEFINITION => json(definition(s, p(params)?)),
        server::REFERENCES => json(references(s, p(params)?)),
        server::PREPARE_RENAME => json(prepare_rename(s, p(params)?)?),
        server::RENAME => json(rename(s, p(params)?)?),
        server::DOCUMENT_SYMBOL => json(document_symbols(s, p(params)?)),
        server::WORKSPACE_SYMBOL => json(workspace_symbols(s, p(params)?)),
        server::SEMANTIC_TOKENS => json(semantic_tokens(s, p(params)?)),
        server::FOLDING_RANGE => json(folding_ranges(s, p(params)?)),
        server::FORMATTING => json(formatting(s, p(params)?)),
        _ => return Err(Failure::UnknownMethod),
    })
}

/// The document and byte offset of a position.
fn locate_pos(
    s: &Server,
    at: &TextDocumentPositionParams,
) -> Option<(PathBuf, Arc<FileIndex>, usize)> {
    let path = at.text_document.uri.to_file_path().ok()?;
    let index = s.index(&path)?;
    let offset = index.lines.offset(&index.text, at.position);
    Some((path, index, offset))
}

fn url(path: &Path) -> Option<Url> {
    Url::from_file_path(path).ok()
}

// ---------------------------------------------------------------- resolving

/// A user definition: the file and its index in the file's `defs`.
#[derive(Clone)]
struct Found {
    path: PathBuf,
    index: Arc<FileIndex>,
    def: usize,
}

impl Found {
    fn def(&self) -> &Def {
        &self.index.defs[self.def]
    }
}

/// The definition `name` (written in `path`, in the declaration `owner`,
/// at a position of `kind`) names: in the file, else through the import
/// its prefix names, else in the files imported without a prefix.
fn resolve_name(
    s: &Server,
    path: &Path,
    index: &Arc<FileIndex>,
    name: &str,
    kind: RefKind,
    owner: Option<usize>,
    depth: usize,
) -> Option<Found> {
    if depth > 8 {
        return None;
    }
    let r = Ref {
        name: name.to_string(),
        span: 0..0,
        kind,
        owner,
    };
    if let Some(def) = index.resolve_local(&r) {
        return Some(Found {
            path: path.to_path_buf(),
            index: index.clone(),
            def,
        });
    }
    if let Some((alias, rest)) = name.split_once('.') {
        if let Some(import) = index.import_named(alias) {
            let target = s.locate(path, &import.path)?;
            let imported = s.index(&target)?;
            return resolve_name(s, &target, &imported, rest, kind, None, depth + 1);
        }
    }
    for import in index.imports.iter().filter(|i| i.alias.is_none()) {
        let Some(target) = s.locate(path, &import.path) else {
            continue;
        };
        let Some(imported) = s.index(&target) else {
            continue;
        };
        if let Some(found) = resolve_name(s, &target, &imported, name, kind, None, depth + 1) {
            return Some(found);
        }
    }
    None
}

/// What a name at the cursor stands for.
enum Target {
    User(Found),
    Op(&'static OpDef),
    Function(&'static Function),
    ShapeAttr(&'static str, &'static str),
    /// A file named by an import's path.
    File(PathBuf),
    /// A selector keyword (`front`, `y`, `world.up`, `f`).
    Selector(String),
}

/// The target at `offset` and the span of what names it.
fn target_at(
    s: &Server,
    path: &Path,
    index: &Arc<FileIndex>,
    offset: usize,
) -> Option<(Target, Range<usize>)> {
    for import in &index.imports {
        if import.path_span.start < offset && offset < import.path_span.end {
            let found = s.locate(path, &import.path)?;
            return Some((Target::File(found), import.path_span.clone()));
        }
    }
    match index.at(offset)? {
        Hit::Def(i) => Some((
            Target::User(Found {
                path: path.to_path_buf(),
                index: index.clone(),
                def: i,
            }),
            index.defs[i].name_span.clone(),
        )),
        Hit::Ref(i) => {
            let r = &index.refs[i];
            if let Some((alias, _)) = r.split_prefix() {
                let alias_span = r.span.start..r.span.start + alias.len();
                if offset <= alias_span.end {
                    if let Some(import) = index.import_named(alias) {
                        let found = Found {
                            path: path.to_path_buf(),
                            index: index.clone(),
                            def: import.def,
                        };
                        return Some((Target::User(found), alias_span));
                    }
                }
            }
            if let Some(found) = resolve_name(s, path, index, &r.name, r.kind, r.owner, 0) {
                return Some((Target::User(found), r.last_span()));
            }
            let builtin = match r.kind {
                RefKind::Stmt => operations::find(&r.name).map(Target::Op),
                RefKind::Call => builtins::function(&r.name)
                    .map(Target::Function)
                    .or_else(|| operations::find(&r.name).map(Target::Op)),
                RefKind::Value => builtins::SHAPE_ATTRIBUTES
                    .iter()
                    .find(|(n, _)| *n == r.name)
                    .map(|(n, d)| Target::ShapeAttr(n, d))
                    .or_else(|| builtins::function(&r.name).map(Target::Function))
                    .or_else(|| {
                        builtins::is_selector(&r.name).then(|| Target::Selector(r.name.clone()))
                    }),
                RefKind::Leaf => None,
            };
            builtin.map(|t| (t, r.span.clone()))
        }
    }
}

// ---------------------------------------------------------------- hover

fn hover(s: &Server, p: HoverParams) -> Option<Hover> {
    let (path, index, offset) = locate_pos(s, &p.text_document_position_params)?;
    let (target, span) = target_at(s, &path, &index, offset)?;
    let text = match target {
        Target::User(found) => describe_def(&path, &found),
        Target::Op(op) => describe_op(op),
        Target::Function(f) => describe_function(f),
        Target::ShapeAttr(name, what) => format!("```cga\n{name}\n```\nShape attribute. {what}"),
        Target::File(file) => format!("`{}`", file.display()),
        Target::Selector(word) => format!("```cga\n{word}\n```\nselector keyword"),
    };
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: text,
        }),
        range: Some(index.lines.range(&index.text, span)),
    })
}

/// A user definition as hover shows it: its declaration (annotations,
/// then the head of the declaration), the comment above it, and where it
/// is when that is another file.
fn describe_def(from: &Path, found: &Found) -> String {
    let def = found.def();
    let text = &found.index.text;
    let mut out = String::new();
    match def.kind {
        DefKind::Param | DefKind::Local => {
            let owner = def
                .owner
                .map(|o| found.index.defs[o].name.as_str())
                .unwrap_or("");
            out.push_str(&format!(
                "```cga\n{}\n```\n{} of `{owner}`",
                def.name,
                def.kind.word()
            ));
            return out;
        }
        _ => {}
    }
    let decl = text.get(def.span.clone()).unwrap_or("");
    let name_line = text[def.span.start..def.name_span.start.max(def.span.start)]
        .matches('\n')
        .count();
    let extra = if def.kind == DefKind::Rule { 0 } else { 2 };
    let lines: Vec<&str> = decl.lines().collect();
    let keep = (name_line + 1 + extra).min(lines.len());
    let mut shown = lines[..keep].join("\n");
    if keep < lines.len() {
        shown.push_str(" …");
    }
    out.push_str(&format!("```cga\n{shown}\n```\n"));
    if let Some(doc) = &def.doc {
        out.push('\n');
        out.push_str(doc);
        out.push('\n');
    }
    let file = found
        .path
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned());
    if found.path != from {
        out.push_str(&format!("\n*{} in `{file}`*", def.kind.word()));
    } else {
        out.push_str(&format!("\n*{}*", def.kind.word()));
    }
    out
}

fn describe_op(op: &OpDef) -> String {
    let mut out = String::from("```cga\n");
    let signatures = op.signatures();
    if signatures.is_empty() {
        out.push_str(op.name);
    } else {
        out.push_str(&signatures.join("\n"));
    }
    out.push_str("\n```\n");
    out.push_str(op.summary);
    out.push_str(&format!("\n\n*operation ({})*", op.family.name()));
    if !op.aliases.is_empty() {
        out.push_str(&format!(" — also `{}`", op.aliases.join("`, `")));
    }
    match op.status() {
        Status::Runs => {}
        Status::Deprecated(why) => out.push_str(&format!("\n\n**Deprecated**: {why}")),
        Status::NotRun => out.push_str(
            "\n\n**Not run by this engine yet** (a warning; the shape is left unchanged).",
        ),
    }
    out
}

fn describe_function(f: &Function) -> String {
    format!(
        "```cga\n{}\n```\n{}\n\n*built-in function*",
        f.signatures().join("\n"),
        f.summary
    )
}

// ---------------------------------------------------------------- completion

/// Where the cursor is, for completion.
#[derive(Debug, PartialEq)]
enum Ctx {
    /// In a comment, or a string that names no file.
    Nothing,
    /// In the string of an import (`cga`), `i(`/`insert(` (assets),
    /// `texture(` (images): the text typed since the quote.
    Path {
        kinds: &'static [&'static str],
        typed: String,
    },
    /// After `prefix.`.
    Member {
        prefix: String,
    },
    /// `set(` first argument.
    SetAttr,
    /// Selector words.
    Selectors(&'static [&'static str]),
    General,
}

const CGA_FILES: &[&str] = &["cga"];
const ASSET_FILES: &[&str] = &["obj", "fbx", "dae", "glb", "gltf", "3ds", "dxf", "shp"];
const IMAGE_FILES: &[&str] = &[
    "png", "jpg", "jpeg", "tif", "tiff", "bmp", "tga", "gif", "webp", "exr", "hdr",
];
const ANY_FILE: &[&str] = &[];

fn context(text: &str, offset: usize) -> Ctx {
    let offset = offset.min(text.len());
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line = &text[line_start..offset];
    // A comment or string on the line so far.
    let mut quote = None;
    let bytes = line.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => quote = if quote.is_some() { None } else { Some(i) },
            b'#' if quote.is_none() => return Ctx::Nothing,
            b'/' if quote.is_none() && bytes.get(i + 1) == Some(&b'/') => return Ctx::Nothing,
            _ => {}
        }
        i += 1;
    }
    if in_block_comment(text, offset) {
        return Ctx::Nothing;
    }
    if let Some(q) = quote {
        let typed = line[q + 1..].to_string();
        let before = line[..q].trim_end();
        if line.trim_start().starts_with("import") {
            return Ctx::Path {
                kinds: CGA_FILES,
                typed,
            };
        }
        if let Some(head) = before.strip_suffix('(') {
            let name = last_word(head);
            let kinds = match name {
                "i" | "insert" => ASSET_FILES,
                "texture" | "setupProjection" | "projectUV" => IMAGE_FILES,
                "fileExists" | "readTextFile" | "readFloatTable" | "readStringTable"
                | "assetInfo" | "imageInfo" => ANY_FILE,
                _ => return Ctx::Nothing,
            };
            return Ctx::Path { kinds, typed };
        }
        return Ctx::Nothing;
    }
    let word_start = word_start(text, offset);
    let word = &text[word_start..offset];
    if let Some((prefix, _)) = word.rsplit_once('.') {
        return Ctx::Member {
            prefix: prefix.to_string(),
        };
    }
    // The bracket the cursor is in.
    let b = text.as_bytes();
    let mut depth = 0i32;
    let mut commas = 0;
    // Whether the cursor is in a block part's head (before its `:`):
    // scanning back, a `:` or `=` comes first in a body, a `|` or the
    // `{` first in a head.
    let mut in_head = true;
    let mut part_seen = false;
    let mut j = word_start;
    let limit = word_start.saturating_sub(20_000);
    while j > limit {
        j -= 1;
        match b[j] {
            b')' | b']' | b'}' => depth += 1,
            b'(' | b'[' if depth > 0 => depth -= 1,
            b'{' if depth > 0 => depth -= 1,
            b',' if depth == 0 => commas += 1,
            b':' | b'=' if depth == 0 && !part_seen => in_head = false,
            b'|' if depth == 0 => part_seen = true,
            b'(' => {
                let name = last_word(&text[..j]);
                return match (name, commas) {
                    ("set", 0) => Ctx::SetAttr,
                    ("comp", 0) => Ctx::Selectors(builtins::COMP_TYPES),
                    ("split" | "splitArea", 0) => Ctx::Selectors(builtins::SPLIT_AXES),
                    _ => match operations::find(name) {
                        Some(op) if op.mode(commas + 1, commas) == ArgMode::Selector => {
                            Ctx::Selectors(builtins::OTHER_SELECTORS)
                        }
                        _ => Ctx::General,
                    },
                };
            }
            b'[' => return Ctx::General,
            b'{' => {
                if !in_head {
                    return Ctx::General;
                }
                let before = text[..j].trim_end();
                let Some(call) = before.strip_suffix(')') else {
                    return Ctx::General;
                };
                let name = last_word(&call[..matching_open(call)]);
                return match name {
                    "comp" => Ctx::Selectors(builtins::COMP_SELECTORS),
                    "setback" | "offset" | "setbackPerimeter" | "setbackToArea" | "shapeL"
                    | "shapeU" | "shapeO" => Ctx::Selectors(builtins::SETBACK_SELECTORS),
                    _ => Ctx::General,
                };
            }
            _ => {}
        }
    }
    Ctx::General
}

/// Whether `offset` is inside a `/* */` comment.
fn in_block_comment(text: &str, offset: usize) -> bool {
    match text[..offset].rfind("/*") {
        Some(open) => !text[open..offset].contains("*/"),
        None => false,
    }
}

/// Where the name ending at `offset` starts (letters, digits, `_`, `.`).
fn word_start(text: &str, offset: usize) -> usize {
    let b = text.as_bytes();
    let mut i = offset;
    while i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.') {
        i -= 1;
    }
    i
}

fn last_word(text: &str) -> &str {
    let t = text.trim_end();
    &t[word_start(t, t.len())..]
}

/// The offset of the `(` matching the `)` that `text` ends before (text
/// is what precedes that `)`), or 0.
fn matching_open(text: &str) -> usize {
    let mut depth = 0;
    for (i, c) in text.bytes().enumerate().rev() {
        match c {
            b')' => depth += 1,
            b'(' if depth == 0 => return i,
            b'(' => depth -= 1,
            _ => {}
        }
    }
    0
}

fn completion(s: &Server, p: CompletionParams) -> Option<CompletionResponse> {
    let (path, index, offset) = locate_pos(s, &p.text_document_position)?;
    let ctx = context(&index.text, offset);
    let mut items = Vec::new();
    match ctx {
        Ctx::Nothing => return None,
        Ctx::Path { kinds, typed } => path_items(s, &path, kinds, &typed, &mut items),
        Ctx::Member { prefix } => {
            if let Some(import) = index.import_named(&prefix) {
                if let Some(target) = s.locate(&path, &import.path) {
                    if let Some(imported) = s.index(&target) {
                        for d in imported.defs.iter().filter(|d| d.owner.is_none()) {
                            if matches!(
                                d.kind,
                                DefKind::Rule | DefKind::Attr | DefKind::Function | DefKind::Const
                            ) {
                                items.push(def_item(d, &d.name));
                            }
                        }
                    }
                }
            }
            let dotted = format!("{prefix}.");
            for (name, what) in builtins::SHAPE_ATTRIBUTES {
                if let Some(rest) = name.strip_prefix(&dotted) {
                    items.push(simple(rest, CompletionItemKind::PROPERTY, what));
                }
            }
            for f in builtins::FUNCTIONS {
                if let Some(rest) = f.name.strip_prefix(&dotted) {
                    items.push(function_item(f, rest));
                }
            }
            for sel in builtins::COMP_SELECTORS
                .iter()
                .chain(builtins::OTHER_SELECTORS)
            {
                if let Some(rest) = sel.strip_prefix(&dotted) {
                    items.push(simple(rest, CompletionItemKind::ENUM_MEMBER, "selector"));
                }
            }
        }
        Ctx::SetAttr => {
            for d in index.defs.iter().filter(|d| d.kind == DefKind::Attr) {
                items.push(def_item(d, &d.name));
            }
            // The attributes of imports, by their prefix (`set(fac.height, 3)`).
            for import in &index.imports {
                let Some(alias) = &import.alias else { continue };
                let Some(imported) = s.locate(&path, &import.path).and_then(|t| s.index(&t)) else {
                    continue;
                };
                for d in imported.defs.iter().filter(|d| d.kind == DefKind::Attr) {
                    items.push(def_item(d, &format!("{alias}.{}", d.name)));
                }
            }
            for (name, what) in builtins::SHAPE_ATTRIBUTES {
                if !name.starts_with("split.") && !name.starts_with("comp.") {
                    items.push(simple(name, CompletionItemKind::PROPERTY, what));
                }
            }
        }
        Ctx::Selectors(words) => {
            for w in words {
                items.push(simple(w, CompletionItemKind::ENUM_MEMBER, "selector"));
            }
            if words.contains(&"isTagged") {
                items.retain(|i| i.label != "isTagged");
                items.push(CompletionItem {
                    label: "isTagged".into(),
                    kind: Some(CompletionItemKind::FUNCTION),
                    insert_text: Some("isTagged(\"${1:tag}\")".into()),
                    insert_text_format: Some(InsertTextFormat::SNIPPET),
                    ..Default::default()
                });
            }
        }
        Ctx::General => general_items(s, &path, &index, offset, &mut items),
    }
    Some(CompletionResponse::Array(items))
}

fn simple(label: &str, kind: CompletionItemKind, detail: &str) -> CompletionItem {
    CompletionItem {
        label: label.to_string(),
        kind: Some(kind),
        detail: Some(detail.to_string()),
        ..Default::default()
    }
}

fn def_item(d: &Def, label: &str) -> CompletionItem {
    let kind = match d.kind {
        DefKind::Rule => CompletionItemKind::CLASS,
        DefKind::Attr => CompletionItemKind::FIELD,
        DefKind::Function => CompletionItemKind::FUNCTION,
        DefKind::Const => CompletionItemKind::CONSTANT,
        DefKind::Import => CompletionItemKind::MODULE,
        DefKind::Style => CompletionItemKind::MODULE,
        DefKind::Param | DefKind::Local => CompletionItemKind::VARIABLE,
    };
    let detail = if d.params.is_empty() {
        d.kind.word().to_string()
    } else {
        format!("{} {}({})", d.kind.word(), d.name, d.params.join(", "))
    };
    let (insert_text, format) = if d.params.is_empty() {
        (None, None)
    } else {
        (
            Some(snippet(label, d.params.iter().map(String::as_str))),
            Some(InsertTextFormat::SNIPPET),
        )
    };
    CompletionItem {
        label: label.to_string(),
        kind: Some(kind),
        detail: Some(detail),
        documentation: d.doc.clone().map(Documentation::String),
        insert_text,
        insert_text_format: format,
        ..Default::default()
    }
}

fn snippet<'a>(name: &str, params: impl Iterator<Item = &'a str>) -> String {
    let args: Vec<String> = params
        .enumerate()
        .map(|(i, p)| format!("${{{}:{}}}", i + 1, p))
        .collect();
    format!("{name}({})", args.join(", "))
}

fn function_item(f: &Function, label: &str) -> CompletionItem {
    let form = f.forms.first().copied().unwrap_or(&[]);
    CompletionItem {
        label: label.to_string(),
        kind: Some(CompletionItemKind::FUNCTION),
        detail: Some(f.signatures().join(" | ")),
        documentation: Some(Documentation::String(f.summary.to_string())),
        insert_text: Some(snippet(label, form.iter().copied())),
        insert_text_format: Some(InsertTextFormat::SNIPPET),
        ..Default::default()
    }
}

fn op_item(op: &'static OpDef) -> CompletionItem {
    let form = op.forms.first().copied().unwrap_or(&[]);
    let mut insert = if form.is_empty() && op.forms.is_empty() {
        op.name.to_string()
    } else {
        snippet(op.name, form.iter().map(|p| p.name))
    };
    match op.block {
        operations::Block::Parts => insert.push_str(" { $0 }"),
        operations::Block::Operations => insert.push_str(" { $0 }"),
        operations::Block::None => {}
    }
    let deprecated = !matches!(op.status(), Status::Runs);
    CompletionItem {
        label: op.name.to_string(),
        kind: Some(CompletionItemKind::METHOD),
        detail: Some(op.signatures().join(" | ")),
        documentation: Some(Documentation::String(op.summary.to_string())),
        insert_text: Some(insert),
        insert_text_format: Some(InsertTextFormat::SNIPPET),
        tags: deprecated.then(|| vec![CompletionItemTag::DEPRECATED]),
        ..Default::default()
    }
}

fn general_items(
    s: &Server,
    path: &Path,
    index: &Arc<FileIndex>,
    offset: usize,
    items: &mut Vec<CompletionItem>,
) {
    let owner = index
        .defs
        .iter()
        .position(|d| d.owner.is_none() && d.span.start <= offset && offset <= d.span.end);
    for d in &index.defs {
        if d.owner.is_none() || d.owner == owner {
            if d.kind == DefKind::Style {
                continue;
            }
            items.push(def_item(d, &d.name));
        }
    }
    // Names of files imported without a prefix.
    for import in index.imports.iter().filter(|i| i.alias.is_none()) {
        if let Some(imported) = s.locate(path, &import.path).and_then(|t| s.index(&t)) {
            for d in imported
                .defs
                .iter()
                .filter(|d| d.owner.is_none() && d.kind != DefKind::Import)
            {
                items.push(def_item(d, &d.name));
            }
        }
    }
    for op in operations::all() {
        items.push(op_item(op));
    }
    for f in builtins::FUNCTIONS {
        items.push(function_item(f, f.name));
    }
    for (name, what) in builtins::SHAPE_ATTRIBUTES {
        items.push(simple(name, CompletionItemKind::PROPERTY, what));
    }
    for k in builtins::KEYWORDS {
        items.push(simple(k, CompletionItemKind::KEYWORD, "keyword"));
    }
}

/// Files and folders for the path typed so far: relative to the rule
/// file's folder (and, for assets, each ancestor's `assets/`), or, for
/// `/Project/...`, the projects of the workspace.
fn path_items(
    s: &Server,
    from: &Path,
    kinds: &[&str],
    typed: &str,
    items: &mut Vec<CompletionItem>,
) {
    let (dir, _) = typed
        .rsplit_once('/')
        .map_or(("", typed), |(d, rest)| (d, rest));
    let folder = from.parent().unwrap_or(Path::new("/"));
    let mut places: Vec<PathBuf> = Vec::new();
    if let Some(rel) = typed.strip_prefix('/') {
        let rel_dir = rel.rsplit_once('/').map_or("", |(d, _)| d);
        for a in folder.ancestors() {
            places.push(a.join(rel_dir));
        }
        for root in &s.workspaces.roots {
            places.push(root.join(rel_dir));
        }
        places.extend(s.roots.iter().map(|r| r.join(rel_dir)));
    } else {
        places.push(folder.join(dir));
        if kinds != CGA_FILES {
            for a in folder.ancestors() {
                places.push(a.join("assets").join(dir));
            }
        }
    }
    let mut seen = std::collections::HashSet::new();
    for place in places {
        let Ok(entries) = s.world.read_dir(&place) else {
            continue;
        };
        for e in entries {
            let Some(name) = e.file_name().and_then(|n| n.to_str()) else {
                continue;
            };
            if name.starts_with('.') || !seen.insert(name.to_string()) {
                continue;
            }
            if s.world.is_dir(&e) {
                let mut item = simple(&format!("{name}/"), CompletionItemKind::FOLDER, "folder");
                // Ask for the next part right away.
                item.command = Some(Command::new(
                    "".into(),
                    "editor.action.triggerSuggest".into(),
                    None,
                ));
                items.push(item);
            } else {
                let ext = e
                    .extension()
                    .and_then(|x| x.to_str())
                    .unwrap_or("")
                    .to_ascii_lowercase();
                if kinds.is_empty() || kinds.contains(&ext.as_str()) {
                    items.push(simple(name, CompletionItemKind::FILE, "file"));
                }
            }
        }
    }
    items.sort_by(|a, b| a.label.cmp(&b.label));
}

// ---------------------------------------------------------------- signature help

fn signature_help(s: &Server, p: SignatureHelpParams) -> Option<SignatureHelp> {
    let (path, index, offset) = locate_pos(s, &p.text_document_position_params)?;
    let text = &index.text;
    let b = text.as_bytes();
    let (mut depth, mut commas) = (0, 0u32);
    let mut j = offset.min(text.len());
    let open = loop {
        if j == 0 || offset - j > 10_000 {
            return None;
        }
        j -= 1;
        match b[j] {
            b')' | b']' => depth += 1,
            b'[' if depth > 0 => depth -= 1,
            b'(' if depth > 0 => depth -= 1,
            b'(' => break j,
            b',' if depth == 0 => commas += 1,
            b'{' | b'}' | b'[' | b';' => return None,
            _ => {}
        }
    };
    let name_end = text[..open].trim_end().len();
    let name_start = word_start(text, name_end);
    let name = &text[name_start..name_end];
    if name.is_empty() {
        return None;
    }
    let mut signatures: Vec<(String, Vec<String>, Option<String>)> = Vec::new();
    let user = index
        .refs
        .iter()
        .find(|r| r.span.start == name_start)
        .and_then(|r| resolve_name(s, &path, &index, &r.name, r.kind, r.owner, 0))
        .or_else(|| resolve_name(s, &path, &index, name, RefKind::Stmt, None, 0))
        .or_else(|| resolve_name(s, &path, &index, name, RefKind::Call, None, 0));
    if let Some(found) = user {
        let d = found.def();
        signatures.push((d.name.clone(), d.params.clone(), d.doc.clone()));
    } else if let Some(op) = operations::find(name) {
        for form in op.forms {
            signatures.push((
                op.name.to_string(),
                form.iter().map(|p| p.name.to_string()).collect(),
                Some(op.summary.to_string()),
            ));
        }
    } else if let Some(f) = builtins::function(name) {
        for form in f.forms {
            signatures.push((
                f.name.to_string(),
                form.iter().map(|p| p.to_string()).collect(),
                Some(f.summary.to_string()),
            ));
        }
    }
    if signatures.is_empty() {
        return None;
    }
    let active = signatures
        .iter()
        .position(|(_, params, _)| params.len() > commas as usize)
        .unwrap_or(signatures.len() - 1);
    Some(SignatureHelp {
        signatures: signatures
            .into_iter()
            .map(|(name, params, doc)| SignatureInformation {
                label: format!("{name}({})", params.join(", ")),
                documentation: doc.map(Documentation::String),
                parameters: Some(
                    params
                        .iter()
                        .map(|p| ParameterInformation {
                            label: ParameterLabel::Simple(p.clone()),
                            documentation: None,
                        })
                        .collect(),
                ),
                active_parameter: None,
            })
            .collect(),
        active_signature: Some(active as u32),
        active_parameter: Some(commas),
    })
}

// ---------------------------------------------------------------- navigation

fn def_location(found: &Found) -> Option<Location> {
    let d = found.def();
    Some(Location::new(
        url(&found.path)?,
        found
            .index
            .lines
            .range(&found.index.text, d.name_span.clone()),
    ))
}

fn definition(s: &Server, p: GotoDefinitionParams) -> Option<GotoDefinitionResponse> {
    let (path, index, offset) = locate_pos(s, &p.text_document_position_params)?;
    let (target, _) = target_at(s, &path, &index, offset)?;
    let location = match target {
        Target::User(found) => def_location(&found)?,
        Target::File(file) => Location::new(url(&file)?, lsp_types::Range::default()),
        _ => return None,
    };
    Some(GotoDefinitionResponse::Scalar(location))
}

/// Every place naming `target`: (file, index, span of the part a rename
/// replaces), the declaration first when asked for.
fn uses(
    s: &Server,
    target: &Found,
    with_decl: bool,
) -> Vec<(PathBuf, Arc<FileIndex>, Range<usize>)> {
    let d = target.def();
    let mut out = Vec::new();
    if with_decl {
        out.push((
            target.path.clone(),
            target.index.clone(),
            d.name_span.clone(),
        ));
    }
    match d.kind {
        DefKind::Param | DefKind::Local => {
            for r in &target.index.refs {
                if target.index.resolve_local(r) == Some(target.def) {
                    out.push((target.path.clone(), target.index.clone(), r.span.clone()));
                }
            }
        }
        DefKind::Import => {
            for r in &target.index.refs {
                if let Some((alias, _)) = r.split_prefix() {
                    if alias == d.name
                        && target.index.import_named(alias).map(|i| i.def) == Some(target.def)
                    {
                        out.push((
                            target.path.clone(),
                            target.index.clone(),
                            r.span.start..r.span.start + alias.len(),
                        ));
                    }
                }
            }
        }
        _ => {
            let want = s.world.canonical(&target.path);
            for file in s.workspace_files() {
                let Some(index) = s.index(&file) else {
                    continue;
                };
                for r in &index.refs {
                    if r.kind == RefKind::Leaf || r.name.rsplit('.').next() != Some(d.name.as_str())
                    {
                        continue;
                    }
                    let Some(found) = resolve_name(s, &file, &index, &r.name, r.kind, r.owner, 0)
                    else {
                        continue;
                    };
                    if found.def == target.def && s.world.canonical(&found.path) == want {
                        out.push((file.clone(), index.clone(), r.last_span()));
                    }
                }
            }
        }
    }
    out
}

fn references(s: &Server, p: ReferenceParams) -> Option<Vec<Location>> {
    let (path, index, offset) = locate_pos(s, &p.text_document_position)?;
    let (Target::User(found), _) = target_at(s, &path, &index, offset)? else {
        return None;
    };
    Some(
        uses(s, &found, p.context.include_declaration)
            .into_iter()
            .filter_map(|(file, index, span)| {
                Some(Location::new(
                    url(&file)?,
                    index.lines.range(&index.text, span),
                ))
            })
            .collect(),
    )
}

fn prepare_rename(
    s: &Server,
    p: TextDocumentPositionParams,
) -> Result<Option<PrepareRenameResponse>, Failure> {
    let Some((path, index, offset)) = locate_pos(s, &p) else {
        return Ok(None);
    };
    match target_at(s, &path, &index, offset) {
        Some((Target::User(found), span)) => {
            if found.def().kind == DefKind::Import
                && index.defs[found.def].name_span.start
                    == index
                        .imports
                        .iter()
                        .find(|i| i.def == found.def)
                        .map_or(usize::MAX, |i| i.path_span.start)
            {
                return Err(Failure::Refused(
                    "an import without a name cannot be renamed".into(),
                ));
            }
            Ok(Some(PrepareRenameResponse::RangeWithPlaceholder {
                range: index.lines.range(&index.text, span.clone()),
                placeholder: index.text.get(span).unwrap_or("").to_string(),
            }))
        }
        Some(_) => Err(Failure::Refused("built-in names cannot be renamed".into())),
        None => Ok(None),
    }
}

fn rename(s: &Server, p: RenameParams) -> Result<Option<WorkspaceEdit>, Failure> {
    let new = p.new_name.trim();
    let valid = new
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && new.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !valid {
        return Err(Failure::Refused(format!("`{new}` is not a CGA name")));
    }
    let Some((path, index, offset)) = locate_pos(s, &p.text_document_position) else {
        return Ok(None);
    };
    let Some((Target::User(found), _)) = target_at(s, &path, &index, offset) else {
        return Err(Failure::Refused(
            "only rules, attributes, functions, consts, parameters and imports can be renamed"
                .into(),
        ));
    };
    // A name the declaration's file already defines (a rule for a rule,
    // a value for a value) would merge two definitions.
    let d = found.def();
    let clash = match d.kind {
        DefKind::Param | DefKind::Local => found
            .index
            .defs
            .iter()
            .any(|o| o.owner == d.owner && o.name == new),
        DefKind::Import => found.index.import_named(new).is_some(),
        kind => found.index.top_level(new).any(|(_, o)| {
            (o.kind == DefKind::Rule) == (kind == DefKind::Rule) && o.kind != DefKind::Import
        }),
    };
    if clash && new != d.name {
        let file = found
            .path
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        return Err(Failure::Refused(format!(
            "`{new}` is already defined in {file}"
        )));
    }
    let mut changes: HashMap<Url, Vec<TextEdit>> = HashMap::new();
    for (file, index, span) in uses(s, &found, true) {
        let Some(u) = url(&file) else { continue };
        let edit = TextEdit::new(index.lines.range(&index.text, span), new.to_string());
        let list = changes.entry(u).or_default();
        if !list.contains(&edit) {
            list.push(edit);
        }
    }
    Ok(Some(WorkspaceEdit {
        changes: Some(changes),
        ..Default::default()
    }))
}

// ---------------------------------------------------------------- symbols

fn symbol_kind(kind: DefKind) -> SymbolKind {
    match kind {
        DefKind::Rule => SymbolKind::CLASS,
        DefKind::Attr => SymbolKind::FIELD,
        DefKind::Function => SymbolKind::FUNCTION,
        DefKind::Const => SymbolKind::CONSTANT,
        DefKind::Import => SymbolKind::MODULE,
        DefKind::Style => SymbolKind::NAMESPACE,
        DefKind::Param | DefKind::Local => SymbolKind::VARIABLE,
    }
}

#[allow(deprecated)]
fn document_symbols(s: &Server, p: DocumentSymbolParams) -> Option<DocumentSymbolResponse> {
    let path = p.text_document.uri.to_file_path().ok()?;
    let index = s.index(&path)?;
    let range = |span: Range<usize>| index.lines.range(&index.text, span);
    let mut out: Vec<DocumentSymbol> = Vec::new();
    let mut groups: Vec<(String, usize)> = Vec::new();
    for d in index.defs.iter().filter(|d| d.owner.is_none()) {
        let detail = (!d.params.is_empty()).then(|| format!("({})", d.params.join(", ")));
        let symbol = DocumentSymbol {
            name: d.name.clone(),
            detail: detail.or_else(|| Some(d.kind.word().to_string())),
            kind: symbol_kind(d.kind),
            tags: None,
            deprecated: None,
            range: range(d.span.clone()),
            selection_range: range(d.name_span.clone()),
            children: None,
        };
        match &d.group {
            Some(g) => {
                let at = match groups.iter().find(|(n, _)| n == g) {
                    Some((_, at)) => *at,
                    None => {
                        out.push(DocumentSymbol {
                            name: g.clone(),
                            detail: Some("@Group".into()),
                            kind: SymbolKind::NAMESPACE,
                            tags: None,
                            deprecated: None,
                            range: symbol.range,
                            selection_range: symbol.selection_range,
                            children: Some(Vec::new()),
                        });
                        groups.push((g.clone(), out.len() - 1));
                        out.len() - 1
                    }
                };
                let group = &mut out[at];
                group.range.end = group.range.end.max(symbol.range.end);
                group.children.get_or_insert_with(Vec::new).push(symbol);
            }
            None => out.push(symbol),
        }
    }
    Some(DocumentSymbolResponse::Nested(out))
}

/// Whether the letters of `query` appear in `name` in order (ignoring case).
fn fuzzy(query: &str, name: &str) -> bool {
    let mut chars = name.chars().map(|c| c.to_ascii_lowercase());
    query
        .chars()
        .map(|c| c.to_ascii_lowercase())
        .all(|q| chars.by_ref().any(|c| c == q))
}

#[allow(deprecated)]
fn workspace_symbols(s: &Server, p: WorkspaceSymbolParams) -> Option<Vec<SymbolInformation>> {
    let mut out = Vec::new();
    for file in s.workspace_files() {
        let Some(index) = s.index(&file) else {
            continue;
        };
        let Some(u) = url(&file) else { continue };
        let container = file.file_name().map(|n| n.to_string_lossy().into_owned());
        for d in index
            .defs
            .iter()
            .filter(|d| d.owner.is_none() && d.kind != DefKind::Import)
        {
            if fuzzy(&p.query, &d.name) {
                out.push(SymbolInformation {
                    name: d.name.clone(),
                    kind: symbol_kind(d.kind),
                    tags: None,
                    deprecated: None,
                    location: Location::new(
                        u.clone(),
                        index.lines.range(&index.text, d.name_span.clone()),
                    ),
                    container_name: container.clone(),
                });
            }
        }
        if out.len() > 2000 {
            break;
        }
    }
    Some(out)
}

// ---------------------------------------------------------------- highlighting

const TOKEN_TYPES: &[SemanticTokenType] = &[
    SemanticTokenType::NAMESPACE,   // 0 import
    SemanticTokenType::TYPE,        // 1 rule
    SemanticTokenType::VARIABLE,    // 2 attribute
    SemanticTokenType::FUNCTION,    // 3 function, built-in function
    SemanticTokenType::PARAMETER,   // 4 parameter, local
    SemanticTokenType::KEYWORD,     // 5
    SemanticTokenType::STRING,      // 6
    SemanticTokenType::NUMBER,      // 7
    SemanticTokenType::COMMENT,     // 8
    SemanticTokenType::DECORATOR,   // 9 annotation
    SemanticTokenType::METHOD,      // 10 operation
    SemanticTokenType::ENUM_MEMBER, // 11 selector
    SemanticTokenType::PROPERTY,    // 12 shape attribute
];
const MOD_DECLARATION: u32 = 1;
const MOD_READONLY: u32 = 2;
const MOD_DEFAULT_LIBRARY: u32 = 4;

pub fn legend() -> SemanticTokensLegend {
    SemanticTokensLegend {
        token_types: TOKEN_TYPES.to_vec(),
        token_modifiers: vec![
            SemanticTokenModifier::DECLARATION,
            SemanticTokenModifier::READONLY,
            SemanticTokenModifier::DEFAULT_LIBRARY,
        ],
    }
}

fn def_token(kind: DefKind) -> (u32, u32) {
    match kind {
        DefKind::Import | DefKind::Style => (0, 0),
        DefKind::Rule => (1, 0),
        DefKind::Attr => (2, 0),
        DefKind::Function => (3, 0),
        DefKind::Const => (2, MOD_READONLY),
        DefKind::Param | DefKind::Local => (4, 0),
    }
}

fn semantic_tokens(s: &Server, p: SemanticTokensParams) -> Option<SemanticTokensResult> {
    let path = p.text_document.uri.to_file_path().ok()?;
    let index = s.index(&path)?;
    let text = &index.text;
    let defs: HashMap<usize, &Def> = index.defs.iter().map(|d| (d.name_span.start, d)).collect();
    let refs: HashMap<usize, &Ref> = index.refs.iter().map(|r| (r.span.start, r)).collect();
    let mut raw: Vec<(Range<usize>, u32, u32)> = Vec::new();
    for tok in scan(text) {
        let kind = match tok.kind {
            TokKind::Comment => Some((8, 0)),
            TokKind::Str => Some((6, 0)),
            TokKind::Number => Some((7, 0)),
            TokKind::Annotation => Some((9, 0)),
            TokKind::Word => {
                let word = &text[tok.span.clone()];
                if let Some(d) = defs.get(&tok.span.start) {
                    let (t, m) = def_token(d.kind);
                    Some((t, m | MOD_DECLARATION))
                } else if let Some(r) = refs.get(&tok.span.start) {
                    Some(ref_token(s, &path, &index, r))
                } else if builtins::KEYWORDS.contains(&word) {
                    Some((5, 0))
                } else {
                    None
                }
            }
        };
        if let Some((t, m)) = kind {
            raw.push((tok.span, t, m));
        }
    }
    // One token per line: clients need not support multi-line tokens.
    let mut data = Vec::new();
    let (mut last_line, mut last_col) = (0u32, 0u32);
    for (span, t, m) in raw {
        let mut start = span.start;
        while start < span.end {
            let end = text[start..span.end]
                .find('\n')
                .map_or(span.end, |e| start + e);
            if end > start {
                let a = index.lines.position(text, start);
                let b = index.lines.position(text, end);
                let delta_line = a.line - last_line;
                let delta_start = if delta_line == 0 {
                    a.character - last_col
                } else {
                    a.character
                };
                data.push(SemanticToken {
                    delta_line,
                    delta_start,
                    length: b.character - a.character,
                    token_type: t,
                    token_modifiers_bitset: m,
                });
                last_line = a.line;
                last_col = a.character;
            }
            start = end + 1;
        }
    }
    Some(SemanticTokensResult::Tokens(SemanticTokens {
        result_id: None,
        data,
    }))
}

fn ref_token(s: &Server, path: &Path, index: &Arc<FileIndex>, r: &Ref) -> (u32, u32) {
    if let Some(def) = index.resolve_local(r) {
        return def_token(index.defs[def].kind);
    }
    if let Some((alias, _)) = r.split_prefix() {
        if index.import_named(alias).is_some() {
            return match resolve_name(s, path, index, &r.name, r.kind, r.owner, 0) {
                Some(found) => def_token(found.def().kind),
                None => (0, 0),
            };
        }
    }
    match r.kind {
        RefKind::Stmt if operations::find(&r.name).is_some() => (10, MOD_DEFAULT_LIBRARY),
        RefKind::Stmt | RefKind::Leaf => (1, 0),
        RefKind::Call => (3, MOD_DEFAULT_LIBRARY),
        RefKind::Value => {
            if builtins::SHAPE_ATTRIBUTES.iter().any(|(n, _)| *n == r.name) {
                (12, MOD_DEFAULT_LIBRARY)
            } else if builtins::COMP_SELECTORS.contains(&r.name.as_str())
                || builtins::OTHER_SELECTORS.contains(&r.name.as_str())
                || builtins::COMP_TYPES.contains(&r.name.as_str())
            {
                (11, MOD_DEFAULT_LIBRARY)
            } else {
                (2, 0)
            }
        }
    }
}

// ---------------------------------------------------------------- folding

fn folding_ranges(s: &Server, p: FoldingRangeParams) -> Option<Vec<FoldingRange>> {
    let path = p.text_document.uri.to_file_path().ok()?;
    let index = s.index(&path)?;
    let text = &index.text;
    let line = |o: usize| index.lines.position(text, o).line;
    let mut out: Vec<FoldingRange> = Vec::new();
    let mut push = |start: u32, end: u32, kind: Option<FoldingRangeKind>| {
        if end > start
            && !out
                .iter()
                .any(|f| f.start_line == start && f.end_line == end)
        {
            out.push(FoldingRange {
                start_line: start,
                end_line: end,
                kind,
                ..Default::default()
            });
        }
    };
    for span in &index.folds {
        push(line(span.start), line(span.end), None);
    }
    // Comments: a block comment, or a run of line comments.
    let mut run: Option<(u32, u32)> = None;
    for tok in scan(text)
        .into_iter()
        .filter(|t| t.kind == TokKind::Comment)
    {
        let (a, b) = (line(tok.span.start), line(tok.span.end));
        if b > a {
            push(a, b, Some(FoldingRangeKind::Comment));
            continue;
        }
        run = match run {
            Some((start, end)) if a == end + 1 => Some((start, a)),
            Some((start, end)) => {
                push(start, end, Some(FoldingRangeKind::Comment));
                Some((a, a))
            }
            None => Some((a, a)),
        };
    }
    if let Some((start, end)) = run {
        push(start, end, Some(FoldingRangeKind::Comment));
    }
    out.sort_by_key(|f| (f.start_line, f.end_line));
    Some(out)
}

// ---------------------------------------------------------------- formatting

/// The whole document replaced by its formatted text, when that differs.
fn formatting(s: &Server, p: DocumentFormattingParams) -> Option<Vec<TextEdit>> {
    let path = p.text_document.uri.to_file_path().ok()?;
    let index = s.index(&path)?;
    let formatted = crate::format::format(&index.text);
    if formatted == index.text {
        return Some(Vec::new());
    }
    let all = index.lines.range(&index.text, 0..index.text.len());
    Some(vec![TextEdit::new(all, formatted)])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx(text_with_cursor: &str) -> Ctx {
        let offset = text_with_cursor.find('^').unwrap();
        let text = text_with_cursor.replacen('^', "", 1);
        context(&text, offset)
    }

    #[test]
    fn completion_contexts() {
        assert_eq!(
            ctx("Lot --> comp(f) { fr^ }"),
            Ctx::Selectors(builtins::COMP_SELECTORS)
        );
        assert_eq!(
            ctx("Lot --> comp(f) { front : A \n| si^ }"),
            Ctx::Selectors(builtins::COMP_SELECTORS)
        );
        assert_eq!(ctx("Lot --> comp(f) { front : A ^ }"), Ctx::General);
        assert_eq!(ctx("Lot --> comp(^"), Ctx::Selectors(builtins::COMP_TYPES));
        assert_eq!(
            ctx("Lot --> split(^) { 1 : A }"),
            Ctx::Selectors(builtins::SPLIT_AXES)
        );
        assert_eq!(
            ctx("Lot --> setback(2) { str^ }"),
            Ctx::Selectors(builtins::SETBACK_SELECTORS)
        );
        assert_eq!(ctx("Lot --> set(^"), Ctx::SetAttr);
        assert_eq!(ctx("Lot --> set(height, h^"), Ctx::General);
        assert_eq!(
            ctx("Lot --> imp.^"),
            Ctx::Member {
                prefix: "imp".into()
            }
        );
        assert_eq!(
            ctx("Lot --> i(\"assets/wi^"),
            Ctx::Path {
                kinds: ASSET_FILES,
                typed: "assets/wi".into()
            }
        );
        assert_eq!(
            ctx("import x : \"/Lib/ru^"),
            Ctx::Path {
                kinds: CGA_FILES,
                typed: "/Lib/ru".into()
            }
        );
        assert_eq!(ctx("Lot --> print(\"a^"), Ctx::Nothing);
        assert_eq!(ctx("// Lot --> ex^"), Ctx::Nothing);
        assert_eq!(ctx("/* Lot --> ex^"), Ctx::Nothing);
        assert_eq!(ctx("Lot --> ex^"), Ctx::General);
    }
}
