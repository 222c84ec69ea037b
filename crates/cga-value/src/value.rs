//! The value type shared by the evaluator and the built-ins.

use std::fmt;
use std::sync::Arc;

use crate::error::ValueError;

/// The largest number of elements an array may hold. CityEngine's default
/// for its "maximum array size" preference; array initialization, ranges,
/// `splitString` and `setElems` fail beyond it instead of exhausting memory.
pub const MAX_ARRAY_SIZE: usize = 100_000;

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
///
/// Invariant: `data.len() == rows * cols`. Code that builds an `Array` by
/// hand must keep it (the functions of this crate index `data` by
/// `row * cols + col`); [`Array::new`] and [`Array::row`] do.
///
/// An empty array is always stored as `1 x 0` (use [`Array::new`] or
/// [`Array::row`] to keep that invariant); [`Array::n_rows`] reports 0 for it.
#[derive(Clone, Debug, PartialEq)]
pub struct Array<T> {
    pub rows: usize,
    pub cols: usize,
    pub data: Vec<T>,
}

impl<T> Array<T> {
    /// A 1D array (one row).
    pub fn row(data: Vec<T>) -> Array<T> {
        Array {
            rows: 1,
            cols: data.len(),
            data,
        }
    }

    /// A `rows x cols` array from row-major data. Empty arrays are normalised
    /// to `1 x 0`. The caller guarantees `data.len() == rows * cols`.
    pub fn new(rows: usize, cols: usize, data: Vec<T>) -> Array<T> {
        debug_assert_eq!(rows * cols, data.len());
        if data.is_empty() {
            Array::row(data)
        } else {
            Array { rows, cols, data }
        }
    }

    /// An empty array.
    pub fn empty() -> Array<T> {
        Array::row(Vec::new())
    }

    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Number of rows as CGA's `nRows` reports it (0 for an empty array).
    pub fn n_rows(&self) -> usize {
        if self.data.is_empty() {
            0
        } else {
            self.rows
        }
    }

    /// Number of columns as CGA's `nColumns` reports it (0 for an empty array).
    pub fn n_cols(&self) -> usize {
        if self.data.is_empty() {
            0
        } else {
            self.cols
        }
    }

    /// True for a one-row array (printed as `(n)[...]`), including the empty array.
    pub fn is_1d(&self) -> bool {
        self.rows <= 1 || self.data.is_empty()
    }

    /// The element at `(row, col)`, if inside the array.
    pub fn get(&self, row: usize, col: usize) -> Option<&T> {
        if row < self.rows && col < self.cols {
            self.data.get(row * self.cols + col)
        } else {
            None
        }
    }

    /// Same shape, elements mapped.
    pub fn map<U>(&self, f: impl FnMut(&T) -> U) -> Array<U> {
        Array {
            rows: self.rows,
            cols: self.cols,
            data: self.data.iter().map(f).collect(),
        }
    }

    /// Same-shape check used by the element-wise operators.
    pub fn same_dims<U>(&self, other: &Array<U>) -> bool {
        (self.is_empty() && other.is_empty())
            || (self.rows == other.rows && self.cols == other.cols)
    }
}

impl<T: Clone> Array<T> {
    /// The transposed array (a `1 x n` row becomes an `n x 1` column).
    pub fn transpose(&self) -> Array<T> {
        if self.is_empty() {
            return Array::empty();
        }
        let mut data = Vec::with_capacity(self.data.len());
        for c in 0..self.cols {
            for r in 0..self.rows {
                data.push(self.data[r * self.cols + c].clone());
            }
        }
        Array::new(self.cols, self.rows, data)
    }
}

/// The element types of CGA arrays, with the default value that invalid
/// indexing returns and enlarging `setElems` fills in (0, false, "").
pub trait Element: Clone + PartialEq + fmt::Debug + Send + Sync + 'static {
    /// `0`, `false` or `""`.
    fn default_value() -> Self;
    /// Wraps an array of this element type into a [`Value`].
    fn wrap_array(array: Array<Self>) -> Value;
    /// Wraps one element into a scalar [`Value`].
    fn wrap(self) -> Value;
}

impl Element for f64 {
    fn default_value() -> f64 {
        0.0
    }
    fn wrap_array(array: Array<f64>) -> Value {
        Value::FloatArray(Arc::new(array))
    }
    fn wrap(self) -> Value {
        Value::Float(self)
    }
}

impl Element for bool {
    fn default_value() -> bool {
        false
    }
    fn wrap_array(array: Array<bool>) -> Value {
        Value::BoolArray(Arc::new(array))
    }
    fn wrap(self) -> Value {
        Value::Bool(self)
    }
}

impl Element for Arc<str> {
    fn default_value() -> Arc<str> {
        empty_str()
    }
    fn wrap_array(array: Array<Arc<str>>) -> Value {
        Value::StrArray(Arc::new(array))
    }
    fn wrap(self) -> Value {
        Value::Str(self)
    }
}

/// A shared empty string; avoids allocating for every `""` default.
pub fn empty_str() -> Arc<str> {
    thread_local! {
        static EMPTY: Arc<str> = Arc::from("");
    }
    EMPTY.with(Arc::clone)
}

/// The type of a value, as CGA names it (`float`, `string[]`, ...).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ValueType {
    Float,
    Bool,
    Str,
    FloatArray,
    BoolArray,
    StrArray,
}

impl ValueType {
    pub fn name(self) -> &'static str {
        match self {
            ValueType::Float => "float",
            ValueType::Bool => "bool",
            ValueType::Str => "string",
            ValueType::FloatArray => "float[]",
            ValueType::BoolArray => "bool[]",
            ValueType::StrArray => "string[]",
        }
    }

    pub fn is_array(self) -> bool {
        matches!(
            self,
            ValueType::FloatArray | ValueType::BoolArray | ValueType::StrArray
        )
    }

    /// The element type of an array type, the type itself for a scalar.
    pub fn element(self) -> ValueType {
        match self {
            ValueType::FloatArray => ValueType::Float,
            ValueType::BoolArray => ValueType::Bool,
            ValueType::StrArray => ValueType::Str,
            t => t,
        }
    }
}

impl fmt::Display for ValueType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Value {
    /// The value with storage of its own (a string or array not shared
    /// with the value it was made from). For values a derivation keeps and
    /// clones often (attribute values): cloned from the program's
    /// constants, which every thread shares, each clone and drop would
    /// change a reference count that bounces between the cores.
    pub fn own_copy(&self) -> Value {
        match self {
            Value::Float(x) => Value::Float(*x),
            Value::Bool(b) => Value::Bool(*b),
            Value::Str(s) => Value::Str(Arc::from(&**s)),
            Value::FloatArray(a) => Value::FloatArray(Arc::new((**a).clone())),
            Value::BoolArray(a) => Value::BoolArray(Arc::new((**a).clone())),
            Value::StrArray(a) => Value::StrArray(Arc::new(Array {
                rows: a.rows,
                cols: a.cols,
                data: a.data.iter().map(|s| Arc::from(&**s)).collect(),
            })),
        }
    }

    pub fn str(s: &str) -> Value {
        Value::Str(Arc::from(s))
    }

    /// A 1D float array.
    pub fn float_row(data: Vec<f64>) -> Value {
        Value::FloatArray(Arc::new(Array::row(data)))
    }

    /// A 1D bool array.
    pub fn bool_row(data: Vec<bool>) -> Value {
        Value::BoolArray(Arc::new(Array::row(data)))
    }

    /// A 1D string array.
    pub fn str_row<S: AsRef<str>>(data: &[S]) -> Value {
        Value::StrArray(Arc::new(Array::row(
            data.iter().map(|s| Arc::from(s.as_ref())).collect(),
        )))
    }

    pub fn value_type(&self) -> ValueType {
        match self {
            Value::Float(_) => ValueType::Float,
            Value::Bool(_) => ValueType::Bool,
            Value::Str(_) => ValueType::Str,
            Value::FloatArray(_) => ValueType::FloatArray,
            Value::BoolArray(_) => ValueType::BoolArray,
            Value::StrArray(_) => ValueType::StrArray,
        }
    }

    /// CGA's name of this value's type (`float`, `bool[]`, ...).
    pub fn type_name(&self) -> &'static str {
        self.value_type().name()
    }

    pub fn is_array(&self) -> bool {
        self.value_type().is_array()
    }

    pub fn as_float(&self) -> Option<f64> {
        match self {
            Value::Float(v) => Some(*v),
            _ => None,
        }
    }

    pub fn as_bool(&self) -> Option<bool> {
        match self {
            Value::Bool(v) => Some(*v),
            _ => None,
        }
    }

    pub fn as_str(&self) -> Option<&str> {
        match self {
            Value::Str(v) => Some(v),
            _ => None,
        }
    }

    /// The float, or a type error naming `what` (a function or parameter).
    pub fn expect_float(&self, what: &str) -> Result<f64, ValueError> {
        self.as_float()
            .ok_or_else(|| ValueError::type_mismatch(what, "float", self))
    }

    pub fn expect_bool(&self, what: &str) -> Result<bool, ValueError> {
        self.as_bool()
            .ok_or_else(|| ValueError::type_mismatch(what, "bool", self))
    }

    pub fn expect_str(&self, what: &str) -> Result<&str, ValueError> {
        self.as_str()
            .ok_or_else(|| ValueError::type_mismatch(what, "string", self))
    }

    /// `(rows, cols)` of an array, `None` for a scalar.
    pub fn dims(&self) -> Option<(usize, usize)> {
        match self {
            Value::FloatArray(a) => Some((a.rows, a.cols)),
            Value::BoolArray(a) => Some((a.rows, a.cols)),
            Value::StrArray(a) => Some((a.rows, a.cols)),
            _ => None,
        }
    }

    /// Number of elements of an array, `None` for a scalar.
    pub fn array_len(&self) -> Option<usize> {
        match self {
            Value::FloatArray(a) => Some(a.len()),
            Value::BoolArray(a) => Some(a.len()),
            Value::StrArray(a) => Some(a.len()),
            _ => None,
        }
    }
}

impl From<f64> for Value {
    fn from(v: f64) -> Value {
        Value::Float(v)
    }
}

impl From<bool> for Value {
    fn from(v: bool) -> Value {
        Value::Bool(v)
    }
}

impl From<&str> for Value {
    fn from(v: &str) -> Value {
        Value::str(v)
    }
}

impl From<String> for Value {
    fn from(v: String) -> Value {
        Value::Str(Arc::from(v))
    }
}

impl From<Arc<str>> for Value {
    fn from(v: Arc<str>) -> Value {
        Value::Str(v)
    }
}

impl From<Array<f64>> for Value {
    fn from(v: Array<f64>) -> Value {
        Value::FloatArray(Arc::new(v))
    }
}

impl From<Array<bool>> for Value {
    fn from(v: Array<bool>) -> Value {
        Value::BoolArray(Arc::new(v))
    }
}

impl From<Array<Arc<str>>> for Value {
    fn from(v: Array<Arc<str>>) -> Value {
        Value::StrArray(Arc::new(v))
    }
}

impl fmt::Display for Value {
    /// The text `str()` and `print()` produce.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut s = String::new();
        crate::format::write_value(&mut s, self);
        f.write_str(&s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn own_copies_are_equal_and_unshared() {
        let s = Value::str("#d8cfc4");
        let row = Value::float_row(vec![1.0, 2.5]);
        let names = Value::StrArray(Arc::new(Array {
            rows: 1,
            cols: 2,
            data: vec![Arc::from("a"), Arc::from("b")],
        }));
        for v in [&s, &row, &names, &Value::Float(3.0), &Value::Bool(true)] {
            assert_eq!(&v.own_copy(), v);
        }
        let (Value::Str(a), Value::Str(b)) = (&s, &s.own_copy()) else {
            unreachable!()
        };
        assert!(!Arc::ptr_eq(a, b));
        let (Value::StrArray(a), Value::StrArray(b)) = (&names, &names.own_copy()) else {
            unreachable!()
        };
        assert!(!Arc::ptr_eq(a, b));
        assert!(!Arc::ptr_eq(&a.data[1], &b.data[1]));
        assert_eq!((b.rows, b.cols), (1, 2));
    }
}
