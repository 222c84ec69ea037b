//! The CGA front end: source files, lexer, parser, syntax tree and diagnostics.
//!
//! [`parse`] turns the text of one `.cga` file into an [`ast::Module`] and the
//! diagnostics found on the way. The parser recovers from errors so that one
//! run reports every error of a file; it never panics and takes time linear
//! in the length of the text.
//!
//! ```
//! use cga_syntax::{parse, sexpr, SourceMap};
//!
//! let mut sources = SourceMap::new();
//! let text = "Lot --> extrude(10) comp(f) { top : Roof. | side = Wall }";
//! let file = sources.add("lot.cga", text.to_string());
//! let (module, diagnostics) = parse(file, &sources.get(file).text);
//! assert!(diagnostics.is_empty());
//! assert_eq!(
//!     sexpr::module(&module),
//!     "(rule Lot (extrude 10) (comp f {top : Roof. | side = Wall}))\n"
//! );
//!
//! let (_, diagnostics) = parse(file, "Lot --> extrude(10;)");
//! assert_eq!(diagnostics[0].message, "expected `)` to close the argument list, found `;`");
//! ```
//!
//! - `lexer` (private): hand-written; dotted names (`scope.sx`) are one
//!   token, `Leaf.` is a name and a dot, `.+` ... are element-wise operators.
//! - `parser` (private): recursive descent with bracket-pair lookahead;
//!   see the module docs for the recovery strategy.
//! - [`ast`]: the syntax tree, names as written, every node with a [`Span`].
//! - [`sexpr`]: a compact text form of the tree for tests and debugging.
//! - [`Diagnostic`], [`SourceMap`]: errors with `path:line:col`, the source
//!   line and carets.

pub mod ast;
pub mod diagnostic;
mod lexer;
mod parser;
pub mod sexpr;
pub mod source;
pub mod span;

pub use diagnostic::{Diagnostic, Severity};
pub use lexer::string_end;
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
