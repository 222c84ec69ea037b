//! Errors and warnings about rule files, rendered in the style of modern
//! compilers: `file:line:col`, the source line, a caret, what was expected.

use crate::source::SourceMap;
use crate::span::Span;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    Error,
    Warning,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub message: String,
    /// Where; `None` for diagnostics about no particular place.
    pub span: Option<Span>,
    /// Short text shown under the caret (e.g. "expected `)`").
    pub label: Option<String>,
    /// Extra lines shown after the snippet (e.g. "help: did you mean `extrude`?").
    pub notes: Vec<String>,
}

impl Diagnostic {
    pub fn error(message: impl Into<String>, span: Span) -> Diagnostic {
        Diagnostic {
            severity: Severity::Error,
            message: message.into(),
            span: Some(span),
            label: None,
            notes: Vec::new(),
        }
    }

    pub fn warning(message: impl Into<String>, span: Span) -> Diagnostic {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(message, span)
        }
    }

    pub fn with_label(mut self, label: impl Into<String>) -> Diagnostic {
        self.label = Some(label.into());
        self
    }

    pub fn with_note(mut self, note: impl Into<String>) -> Diagnostic {
        self.notes.push(note.into());
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// Renders the diagnostic as text for a terminal (no colours).
    pub fn render(&self, sources: &SourceMap) -> String {
        use std::fmt::Write;
        let kind = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        let mut out = format!("{kind}: {}\n", self.message);
        if let Some(span) = self.span {
            let file = sources.get(span.file);
            let (line, col) = file.line_col(span.start);
            let text = file.line_text(line);
            let gutter = line.to_string().len();
            let pad = " ".repeat(gutter);
            let _ = writeln!(out, "{pad}--> {}:{line}:{col}", file.path.display());
            let _ = writeln!(out, "{pad} |");
            let _ = writeln!(out, "{line} | {text}");
            // The carets cover the span on its first line (to the end of
            // that line for a span over several lines), at least one column.
            let (end_line, end_col) = file.line_col(span.end);
            let width = if end_line == line {
                end_col.saturating_sub(col).max(1)
            } else {
                (text.chars().count() + 1).saturating_sub(col).max(1)
            };
            let lead: String = text
                .chars()
                .take(col - 1)
                .map(|c| if c == '\t' { '\t' } else { ' ' })
                .collect();
            let _ = write!(out, "{pad} | {lead}{}", "^".repeat(width));
            if let Some(label) = &self.label {
                let _ = write!(out, " {label}");
            }
            out.push('\n');
        }
        // Notes line up with the gutter (`  = ` for one-digit line numbers).
        let pad = match self.span {
            Some(span) => " ".repeat(
                sources
                    .get(span.file)
                    .line_col(span.start)
                    .0
                    .to_string()
                    .len(),
            ),
            None => " ".to_string(),
        };
        for note in &self.notes {
            let _ = writeln!(out, "{pad} = {note}");
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::span::Span;

    fn sources(text: &str) -> SourceMap {
        let mut sources = SourceMap::new();
        sources.add("r.cga", text.to_string());
        sources
    }

    fn span(start: u32, end: u32) -> Span {
        Span::new(crate::FileId(0), start, end)
    }

    #[test]
    fn renders_location_line_carets_label_and_notes() {
        let s = sources("Lot -->\n\textrude(x;)\n");
        let d = Diagnostic::error("bad", span(18, 19))
            .with_label("here")
            .with_note("a note");
        assert_eq!(
            d.render(&s),
            "error: bad\n --> r.cga:2:11\n  |\n2 | \textrude(x;)\n  | \t         ^ here\n  = a note\n"
        );
    }

    #[test]
    fn spans_over_several_lines_underline_the_rest_of_the_first_line() {
        let s = sources("a = (1 +\n 2");
        let d = Diagnostic::warning("multi", span(4, 11));
        assert_eq!(
            d.render(&s),
            "warning: multi\n --> r.cga:1:5\n  |\n1 | a = (1 +\n  |     ^^^^\n"
        );
    }

    #[test]
    fn notes_line_up_with_wide_gutters_and_end_of_file_spans_render() {
        let text = "x\n".repeat(11) + "y";
        let s = sources(&text);
        let end = text.len() as u32;
        let d = Diagnostic::error("eof", span(end, end)).with_note("n");
        assert_eq!(
            d.render(&s),
            "error: eof\n  --> r.cga:12:2\n   |\n12 | y\n   |  ^\n   = n\n"
        );
    }

    #[test]
    fn diagnostics_without_span_and_offsets_inside_characters() {
        let d = Diagnostic {
            span: None,
            ..Diagnostic::error("no place", span(0, 0)).with_note("n")
        };
        assert_eq!(d.render(&sources("")), "error: no place\n  = n\n");
        // An offset inside `ö` counts as the `ö`.
        let s = sources("aö b");
        assert_eq!(s.get(crate::FileId(0)).line_col(2), (1, 2));
        let d = Diagnostic::error("mid", span(2, 3));
        assert!(d.render(&s).contains(" --> r.cga:1:2\n"));
    }
}
