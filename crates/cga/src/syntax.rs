//! Rule files as text: the syntax tree and where a path written in a rule
//! file leads, for tools that work on the text itself (the language server,
//! a formatter) rather than on loaded [`Rules`](crate::Rules).
//!
//! [`parse`] is the engine's own error-tolerant parser: it never panics,
//! always gives a tree (with placeholders where text was missing) and the
//! syntax errors found. Spans are byte offsets into the text parsed.
//! [`sexpr`] writes a tree in a compact text form without spans: two
//! texts with the same form mean the same (a formatter's test).

use std::path::{Path, PathBuf};

pub use cga_syntax::ast;
pub use cga_syntax::{parse, sexpr, string_end, FileId, Span};

use crate::{Workspaces, World};

/// The file `target` (an import, asset or texture path as written in the
/// rule file `from`) names, found as the engine finds it when loading:
/// workspace paths (`/Project/...`) in the ancestors of `from` then in
/// `workspaces`, other paths relative to `from`'s folder and its
/// ancestors' `assets/`. `Err` lists every place searched.
pub fn locate(
    world: &dyn World,
    from: &Path,
    target: &str,
    workspaces: &Workspaces,
) -> Result<PathBuf, Vec<PathBuf>> {
    cga_engine::locate::locate(world, from, target, workspaces)
}

/// The comment lines right above the line holding `offset` (annotation
/// lines between them and the declaration skipped), without markers: an
/// attribute's or rule's documentation.
pub fn doc_comment(text: &str, offset: usize) -> Option<String> {
    let before = &text[..text[..offset.min(text.len())].rfind('\n').map_or(0, |i| i)];
    let mut lines = Vec::new();
    if offset.min(text.len()) > 0 && text[..offset.min(text.len())].contains('\n') {
        for line in before.lines().rev() {
            let t = line.trim();
            if t.starts_with('@') {
                continue;
            }
            let stripped = t
                .strip_prefix("//")
                .or_else(|| t.strip_prefix('#'))
                .or_else(|| {
                    let s = t.strip_prefix("/*").unwrap_or(t);
                    let s = s.strip_suffix("*/").unwrap_or(s);
                    (s.len() != t.len()).then_some(s)
                })
                .or_else(|| t.strip_prefix('*'));
            match stripped {
                Some(s) => lines.push(s.trim().to_string()),
                None => break,
            }
        }
    }
    lines.reverse();
    let doc = lines.join("\n").trim().to_string();
    (!doc.is_empty()).then_some(doc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MemoryWorld;

    #[test]
    fn parses_and_locates_as_the_engine_does() {
        let text = "import f : \"/Lib/rules/f.cga\"\nLot --> f.Facade";
        let (module, errors) = parse(FileId(0), text);
        assert!(errors.is_empty());
        let ast::Item::Import(import) = &module.items[0] else {
            panic!("an import");
        };
        assert_eq!(import.path, "/Lib/rules/f.cga");
        assert_eq!(&text[import.path_span.range()], "\"/Lib/rules/f.cga\"");

        let world = MemoryWorld::new().with("/ws/Lib/rules/f.cga", "Facade --> X.");
        let from = Path::new("/ws/Main/rules/main.cga");
        let found = locate(&world, from, &import.path, &Workspaces::default());
        assert_eq!(found, Ok(PathBuf::from("/ws/Lib/rules/f.cga")));
        let missing = locate(&world, from, "g.cga", &Workspaces::default()).unwrap_err();
        assert_eq!(missing[0], PathBuf::from("/ws/Main/rules/g.cga"));
    }
}
