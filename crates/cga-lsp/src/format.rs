//! `cga fmt`: the layout of a rule file made regular, and nothing else.
//!
//! The formatter changes only whitespace where CGA gives it no meaning:
//! - each line's indentation: four spaces per open bracket (`{`, `(`, `[`)
//!   at its start, a line that starts with a closing bracket one level
//!   less, and one more level for a line that goes on a declaration begun
//!   on an earlier line (a rule's operations below its `-->`);
//! - trailing spaces and tabs are removed;
//! - runs of blank lines become one blank line; none at the start; the
//!   file ends with one line break; line breaks keep the file's style
//!   (`\r\n` when most lines end so).
//!
//! Lines that begin inside a block comment or inside a string that spans
//! lines are left exactly as they are (their leading whitespace belongs to
//! the comment or the string), and every comment stays. Spacing within a
//! line is kept as written. So the syntax tree of the result is the
//! original's (a test checks it over every file of `../shared/corpus`),
//! and formatting twice changes nothing: indentation depends only on the
//! tokens, which formatting does not change.

use crate::index::FileIndex;
use crate::scan::{scan, TokKind};

const INDENT: &str = "    ";

/// `text` formatted.
pub fn format(text: &str) -> String {
    let crlf = text.matches("\r\n").count() * 2 > text.matches('\n').count();
    let text = text.replace("\r\n", "\n");
    let tokens = scan(&text);
    // Top-level declarations: a line starting inside one, after the line
    // of its name, is a continuation.
    let index = FileIndex::new(text.clone());
    // Each as (where its name's line starts, where it ends): lines of its
    // annotations above are not continuations.
    let mut decls: Vec<(usize, usize)> = index
        .defs
        .iter()
        .filter(|d| d.owner.is_none())
        .map(|d| {
            let name_line = text[..d.name_span.start.min(text.len())]
                .rfind('\n')
                .map_or(0, |i| i + 1);
            (name_line.max(d.span.start), d.span.end)
        })
        .collect();
    decls.sort_by_key(|d| d.0);

    // Whether each byte is code (not in a comment or string): brackets
    // count only there.
    let mut code = vec![true; text.len()];
    let mut comment = vec![false; text.len()];
    for t in tokens
        .iter()
        .filter(|t| matches!(t.kind, TokKind::Comment | TokKind::Str))
    {
        code[t.span.clone()].fill(false);
        if t.kind == TokKind::Comment {
            comment[t.span.clone()].fill(true);
        }
    }
    let mut out = String::with_capacity(text.len() + 64);
    let mut depth: i64 = 0;
    let mut tok = 0;
    let mut blank_run = 0;
    let mut line_start = 0;
    let mut decl = 0;
    let mut after_colon = false;
    while line_start < text.len() {
        let line_end = text[line_start..]
            .find('\n')
            .map_or(text.len(), |i| line_start + i);
        let line = &text[line_start..line_end];
        // Tokens before this line: update the depth and skip them.
        while tok < tokens.len() && tokens[tok].span.end <= line_start {
            tok += 1;
        }
        let inside_token = tok < tokens.len()
            && tokens[tok].span.start < line_start
            && matches!(tokens[tok].kind, TokKind::Comment | TokKind::Str);
        let body = line.trim_end_matches([' ', '\t']);
        if inside_token {
            out.push_str(body);
            out.push('\n');
            blank_run = 0;
        } else if body.trim().is_empty() {
            blank_run += 1;
        } else {
            if blank_run > 0 && !out.is_empty() {
                out.push('\n');
            }
            blank_run = 0;
            let content = body.trim_start_matches([' ', '\t']);
            let first_offset = line_start + (body.len() - content.len());
            let closers = content
                .bytes()
                .take_while(|c| matches!(c, b'}' | b')' | b']'))
                .count() as i64;
            while decl < decls.len() && decls[decl].1 <= first_offset {
                decl += 1;
            }
            let continuation =
                decl < decls.len() && decls[decl].0 < first_offset && first_offset < decls[decl].1;
            // The body of a branch written below its `case c :`, `else :`
            // or `30% :` (or a comp/split part's below its head).
            let branch = after_colon && !starts_branch(content);
            let level =
                (depth - closers.min(1)).max(0) + i64::from(continuation) + i64::from(branch);
            for _ in 0..level {
                out.push_str(INDENT);
            }
            out.push_str(content);
            out.push('\n');
        }
        // Brackets of this line, outside comments and strings; whether its
        // code ends with a colon.
        if !body.trim().is_empty() && !inside_token {
            let last_code = line
                .bytes()
                .enumerate()
                .rev()
                .find(|(i, c)| !comment[line_start + i] && !c.is_ascii_whitespace());
            if let Some((_, c)) = last_code {
                after_colon = c == b':';
            }
        }
        for (i, c) in line.bytes().enumerate() {
            if code[line_start + i] {
                match c {
                    b'{' | b'(' | b'[' => depth += 1,
                    b'}' | b')' | b']' => depth = (depth - 1).max(0),
                    _ => {}
                }
            }
        }
        line_start = line_end + 1;
    }
    // A file of nothing but blank lines is empty.
    if crlf {
        out = out.replace('\n', "\r\n");
    }
    out
}

/// Whether a line starts a branch of a case or stochastic chain.
fn starts_branch(line: &str) -> bool {
    let word = |w: &str| {
        line.strip_prefix(w)
            .is_some_and(|rest| !rest.starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_'))
    };
    if word("case") || word("else") {
        return true;
    }
    let digits = line.trim_start_matches(|c: char| c.is_ascii_digit() || c == '.');
    digits.len() < line.len() && digits.trim_start().starts_with('%')
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Over every rule file of `../shared/corpus`: the formatted text has
    /// the original's syntax tree and syntax errors, keeps every comment,
    /// and formatting it again changes nothing.
    #[test]
    fn the_corpus_formats_idempotently_without_changing_meaning() {
        use cga::syntax::{parse, sexpr, FileId};
        let Some(corpus) = cga_testkit::shared("corpus/workspace") else {
            return;
        };
        let mut files = Vec::new();
        crate::robust::cga_files(&corpus, &mut files);
        assert!(files.len() >= 50);
        let mut changed = 0;
        for path in &files {
            let text = cga::decode_text(&std::fs::read(path).unwrap());
            let formatted = format(&text);
            let name = path.display();
            assert_eq!(format(&formatted), formatted, "idempotent: {name}");
            let (a, a_errors) = parse(FileId(0), &text);
            let (b, b_errors) = parse(FileId(0), &formatted);
            assert_eq!(sexpr::module(&a), sexpr::module(&b), "same tree: {name}");
            let a_errors: Vec<&String> = a_errors.iter().map(|d| &d.message).collect();
            let b_errors: Vec<&String> = b_errors.iter().map(|d| &d.message).collect();
            assert_eq!(a_errors, b_errors, "same errors: {name}");
            let comments = |t: &str| -> Vec<String> {
                scan(t)
                    .into_iter()
                    .filter(|k| k.kind == TokKind::Comment)
                    .map(|k| {
                        t[k.span]
                            .lines()
                            .map(str::trim_end)
                            .collect::<Vec<_>>()
                            .join("\n")
                    })
                    .collect()
            };
            assert_eq!(
                comments(&text),
                comments(&formatted),
                "comments kept: {name}"
            );
            changed += usize::from(formatted != text);
        }
        // The corpus is written by many hands: formatting changes most files.
        assert!(
            changed * 2 > files.len(),
            "{changed} of {} files changed",
            files.len()
        );
    }

    /// Over every rule file of `../shared/corpus` that loads without
    /// errors: the formatted file, loaded in its place (its imports and
    /// assets found as before), generates the same model on the default
    /// lot: the same meshes (positions, normals, UVs, indices, materials),
    /// prints, reports and error. Lots are capped (shapes, time) to keep
    /// the test short; both runs stop at the same cap.
    #[test]
    fn formatted_corpus_files_generate_the_same_models() {
        use std::sync::Arc;
        let Some(corpus) = cga_testkit::shared("corpus/workspace") else {
            return;
        };
        let mut files = Vec::new();
        crate::robust::cga_files(&corpus, &mut files);
        let options = cga::Options::default().jobs(1).limits(cga::Limits {
            max_shapes: 20_000,
            max_seconds: 20.0,
            ..Default::default()
        });
        let lot = cga::lots::rect(20.0, 30.0);
        let (mut compared, mut with_geometry) = (0, 0);
        for path in &files {
            let disk = cga::Engine::on_disk();
            let original = disk.load(path);
            if original.has_errors() {
                continue;
            }
            let text = cga::decode_text(&std::fs::read(path).unwrap());
            let formatted = format(&text);
            let world = Arc::new(cga::MemoryWorld::over(Arc::new(cga::DiskWorld)));
            world.set(path, formatted.clone());
            let ours = cga::Engine::with_world(world).load(path);
            let name = path.display();
            assert!(!ours.has_errors(), "{name}: {}", ours.render_diagnostics());
            let a = original.generate(&lot, &options).map_err(|e| e.to_string());
            let b = ours.generate(&lot, &options).map_err(|e| e.to_string());
            match (a, b) {
                (Ok(a), Ok(b)) => {
                    with_geometry += usize::from(!a.model.meshes.is_empty());
                    assert!(a.model == b.model, "{name}: another model");
                    assert_eq!(a.prints, b.prints, "{name}");
                    assert_eq!(a.reports, b.reports, "{name}");
                    assert_eq!(
                        a.error.map(|e| e.message),
                        b.error.map(|e| e.message),
                        "{name}"
                    );
                }
                (a, b) => assert_eq!(a.err(), b.err(), "{name}"),
            }
            compared += 1;
        }
        println!("{compared} files compared, {with_geometry} with geometry");
        assert!(compared >= 20, "{compared} files loaded without errors");
        assert!(with_geometry >= 10, "{with_geometry} files made geometry");
    }

    #[test]
    fn indents_by_brackets_and_declarations() {
        let text = "\n\n// A rule.\n@StartRule\nLot -->   \n  extrude(10)\n\t comp(f) {\n top : Roof\n| side :\n split(y) { 3 : Floor }*\n      }\n\n\n\nRoof --> X.";
        let want = "// A rule.\n@StartRule\nLot -->\n    extrude(10)\n    comp(f) {\n        top : Roof\n        | side :\n            split(y) { 3 : Floor }*\n    }\n\nRoof --> X.\n";
        assert_eq!(format(text), want);
        assert_eq!(format(want), want);
        let text = "f =\ncase a :\n1\nelse:\n3\ng =\n  30% :\n2\nelse:\n3\n";
        let want = "f =\n    case a :\n        1\n    else:\n        3\ng =\n    30% :\n        2\n    else:\n        3\n";
        assert_eq!(format(text), want);
    }

    #[test]
    fn comments_and_strings_over_lines_are_kept() {
        let text = "/* a\n     b */\nattr s = \"x\n   y\"\n@Enum(\"a\",\n\"b\") attr e = \"a\"\r\n";
        let want =
            "/* a\n     b */\nattr s = \"x\n   y\"\n@Enum(\"a\",\n    \"b\") attr e = \"a\"\n";
        assert_eq!(format(text), want);
        assert_eq!(format("a = 1\r\nb = 2\r\n"), "a = 1\r\nb = 2\r\n");
    }
}
