//! What can go wrong at the library's boundary.

use std::fmt;
use std::path::PathBuf;

pub use cga_export::ExportError;

/// An error that keeps a call from doing its work. Problems of single lots
/// (a rule error, a limit) are not errors of the call: they are reported in
/// the lot's [`LotResult::error`](crate::LotResult::error) and the other lots
/// are generated.
#[derive(Debug)]
pub enum Error {
    /// The rule file (or one it imports) has errors; they are in
    /// [`Rules::diagnostics`](crate::Rules::diagnostics).
    Rules { path: PathBuf, errors: usize },
    /// The start rule asked for does not exist (or takes parameters).
    StartRule(String),
    /// An attribute set by name that the rule file does not declare.
    UnknownAttribute { name: String, known: Vec<String> },
    /// A value that cannot be used for what it was given for (an
    /// attribute's value of the wrong type, a seed that is not a whole
    /// number).
    Value(String),
    /// A lot could not be read or made.
    Lot(String),
    /// Writing the model failed.
    Export(ExportError),
    /// The caller cancelled the generation.
    Cancelled,
    /// The worker threads could not be started.
    Threads(std::io::Error),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Rules { path, errors } => write!(
                f,
                "{} has {errors} error{}",
                path.display(),
                if *errors == 1 { "" } else { "s" }
            ),
            Error::StartRule(message) => f.write_str(message),
            Error::UnknownAttribute { name, known } => write!(
                f,
                "the rule file has no attribute `{name}` (attributes: {})",
                if known.is_empty() {
                    "none".to_string()
                } else {
                    known.join(", ")
                }
            ),
            Error::Lot(message) | Error::Value(message) => f.write_str(message),
            Error::Export(e) => write!(f, "writing the model failed: {e}"),
            Error::Cancelled => f.write_str("the generation was cancelled"),
            Error::Threads(e) => write!(f, "cannot start worker threads: {e}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Export(e) => Some(e),
            Error::Threads(e) => Some(e),
            _ => None,
        }
    }
}

impl From<ExportError> for Error {
    fn from(e: ExportError) -> Error {
        Error::Export(e)
    }
}
