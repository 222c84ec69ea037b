//! The CGA front end: source files, lexer, parser, syntax tree and diagnostics.
//!
//! `parse` turns the text of one `.cga` file into a [`ast::Module`] and the
//! diagnostics found on the way. The parser recovers from errors so that one
//! run reports every error of a file.

pub mod ast;
pub mod diagnostic;
mod lexer;
mod parser;
pub mod sexpr;
pub mod source;
pub mod span;

pub use diagnostic::{Diagnostic, Severity};
pub use source::{SourceFile, SourceMap};
pub use span::{FileId, Span};

/// Parses one file. The module holds everything that could be parsed; the
/// diagnostics (errors only, in source order) say what could not. A module
/// that comes with errors may hold placeholders (an empty
/// [`ast::ExprKind::Name`] where an expression was missing) and must not be
/// evaluated.
///
/// Never panics, whatever the text; the time taken is linear in its length.
pub fn parse(file: FileId, text: &str) -> (ast::Module, Vec<Diagnostic>) {
    // Spans are 32-bit byte offsets.
    if text.len() >= u32::MAX as usize {
        let diagnostic = Diagnostic {
            severity: Severity::Error,
            message: "rule file is too large (4 GiB or more)".to_string(),
            span: None,
            label: None,
            notes: Vec::new(),
        };
        return (ast::Module::default(), vec![diagnostic]);
    }
    parser::parse(file, text)
}
