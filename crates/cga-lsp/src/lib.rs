//! The CGA language server: `cga lsp` speaks the Language Server Protocol
//! on standard input and output.
//!
//! Built on the `cga` facade: open buffers live in a
//! [`MemoryWorld`](cga::MemoryWorld) over the disk, so that the engine
//! loads an edited file with its unsaved imports exactly as `cga check`
//! would load the saved ones, and its diagnostics (errors and warnings of
//! the parser and the resolver) are published while typing (debounced).
//! Everything else works on the syntax tree of each file
//! ([`cga::syntax`]), which the error-tolerant parser gives for any text,
//! so a file with errors still gets every feature:
//!
//! - hover: operations from the engine's operation table
//!   ([`cga::operations`]), built-in functions and shape attributes from
//!   `builtins`, and the user's rules, attributes, functions and consts
//!   with their declaration, annotations and the comment above;
//! - completion: names of the file and of imports (`imp.`), operations and
//!   functions with parameter snippets, selectors where `comp`, `split` and
//!   `setback` expect them, attributes in `set(`, file paths in strings of
//!   `import`, `i(` and `texture(`;
//! - signature help, go to definition, references and rename (across
//!   imports, relative and workspace-absolute `/Project/...` paths),
//!   document symbols grouped by `@Group`, workspace symbols, semantic
//!   tokens and folding ranges.
//!
//! - formatting (`textDocument/formatting`) with [`format::format`], which
//!   is also `cga fmt`.
//!
//! Modules: `text` (offsets and LSP positions), `scan` (a lexical pass for
//! highlighting), `index` (what a file defines and uses), `builtins`
//! (functions, selectors, keywords), `features` (the requests), `server`
//! (the message loop, documents, debounced diagnostics).

mod builtins;
mod features;
pub mod format;
mod index;
mod scan;
mod server;
mod text;

#[cfg(test)]
mod robust;

pub use server::{run, run_stdio};
