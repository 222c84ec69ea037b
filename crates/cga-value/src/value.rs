//! The value type shared by the evaluator and the built-ins.

use std::sync::Arc;

/// A CGA value. Cloning is cheap: strings and arrays are shared.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Float(f64),
    Bool(bool),
    Str(Arc<str>),
    FloatArray(Arc<Array<f64>>),
    BoolArray(Arc<Array<bool>>),
    StrArray(Arc<Array<Arc<str>>>),
}

/// A row-major array. A 1D array has `rows == 1` and prints as `(n)[...]`;
/// any other shape prints as a `(rows x cols)` table.
#[derive(Clone, Debug, PartialEq)]
pub struct Array<T> {
    pub rows: usize,
    pub cols: usize,
    pub data: Vec<T>,
}

impl<T> Array<T> {
    pub fn row(data: Vec<T>) -> Array<T> {
        Array {
            rows: 1,
            cols: data.len(),
            data,
        }
    }

    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
}

impl Value {
    pub fn str(s: &str) -> Value {
        Value::Str(Arc::from(s))
    }
}
