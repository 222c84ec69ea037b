//! Problems found in rule files and while generating, as plain data.

use std::path::PathBuf;

use cga_syntax::SourceMap;

/// How bad a problem is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Severity {
    /// The rules cannot be used (loading), or a lot stopped (generating).
    Error,
    /// Something was left out or guessed; the model is still made.
    Warning,
}

/// Where in a rule file a problem is: 1-based lines and columns (columns
/// count characters), and the text of the first line.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Location {
    pub file: PathBuf,
    pub line: usize,
    pub column: usize,
    pub end_line: usize,
    pub end_column: usize,
    /// The source line the location starts on.
    pub line_text: String,
}

/// A problem, with where it is and what was expected.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub message: String,
    /// `None` for problems of no particular place (an unreadable file).
    pub location: Option<Location>,
    /// What the underlined place is (`expected an expression`).
    pub label: Option<String>,
    /// Hints: the closest known name, the lot a runtime error happened in.
    pub notes: Vec<String>,
    rendered: String,
}

impl Diagnostic {
    pub(crate) fn new(d: &cga_syntax::Diagnostic, sources: &SourceMap) -> Diagnostic {
        let location = d.span.map(|span| {
            let file = sources.get(span.file);
            let (line, column) = file.line_col(span.start);
            let (end_line, end_column) = file.line_col(span.end);
            Location {
                file: file.path.clone(),
                line,
                column,
                end_line,
                end_column,
                line_text: file.line_text(line).to_string(),
            }
        });
        Diagnostic {
            severity: match d.severity {
                cga_syntax::Severity::Error => Severity::Error,
                cga_syntax::Severity::Warning => Severity::Warning,
            },
            message: d.message.clone(),
            location,
            label: d.label.clone(),
            notes: d.notes.clone(),
            rendered: d.render(sources),
        }
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// The problem as the `cga` command prints it: the message, then
    /// `--> file:line:column`, the source line with the place underlined,
    /// and the notes.
    pub fn render(&self) -> &str {
        &self.rendered
    }

    /// The same problem with one more note.
    pub fn with_note(mut self, note: impl Into<String>) -> Diagnostic {
        let note = note.into();
        let gutter = self
            .location
            .as_ref()
            .map_or(1, |l| l.line.to_string().len());
        self.rendered
            .push_str(&format!("{} = {note}\n", " ".repeat(gutter)));
        self.notes.push(note);
        self
    }
}

impl std::fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.rendered)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_note_renders_as_the_syntax_crate_renders_notes() {
        let mut sources = SourceMap::new();
        let file = sources.add("r.cga", "x\n".repeat(11) + "Lot --> nope(");
        let span = cga_syntax::Span::new(file, 30, 34);
        let raw = cga_syntax::Diagnostic::error("bad", span);
        let ours = Diagnostic::new(&raw, &sources).with_note("in lot `a`");
        assert_eq!(ours.render(), raw.with_note("in lot `a`").render(&sources));
        let loc = ours.location.unwrap();
        assert_eq!((loc.line, loc.column, loc.end_column), (12, 9, 13));
        assert_eq!(loc.line_text, "Lot --> nope(");
    }
}
