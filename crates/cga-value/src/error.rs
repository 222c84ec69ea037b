//! The error of an operator or built-in function applied to values.

use std::fmt;

use crate::value::Value;

/// A runtime error on values: a type mismatch, incompatible array
/// dimensions, an exceeded size limit, an invalid argument. It carries only a
/// message; the evaluator attaches the source location.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ValueError {
    pub message: String,
}

impl ValueError {
    pub fn new(message: impl Into<String>) -> ValueError {
        ValueError {
            message: message.into(),
        }
    }

    /// `what: expected float, got string`.
    pub fn type_mismatch(what: &str, expected: &str, got: &Value) -> ValueError {
        ValueError::new(format!(
            "{what}: expected {expected}, got {}",
            got.type_name()
        ))
    }

    /// The array size limit of CGA (100000 elements) was exceeded.
    pub fn too_large(what: &str, size: usize) -> ValueError {
        ValueError::new(format!(
            "{what}: array size {size} exceeds the maximum of {}",
            crate::value::MAX_ARRAY_SIZE
        ))
    }
}

impl fmt::Display for ValueError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for ValueError {}
