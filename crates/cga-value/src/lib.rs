//! CGA's values: `float`, `bool`, `string` and their 1D/2D arrays, the
//! operators on them, their text form (`str()`, `print()`), and the built-in
//! functions that depend only on their arguments (math, strings, conversions,
//! arrays, the utility library). Functions that read the current shape live
//! in `cga-engine`.
//!
//! Everything here is total: bad input gives a [`ValueError`], never a panic.
//!
//! * [`value`]: [`Value`], [`Array`] (row-major, `rows x cols`; 1D = one row).
//! * [`ops`]: [`binary`] / [`unary`] for `+ - * / % == != < <= > >= && || !`
//!   and their dotted element-wise forms.
//! * [`array`](mod@array): [`build_array`] (`[a, b ; c, d]`), [`range`] (`[a : s : b]`),
//!   [`index`] (`a[i]`, `a[i, j]`), [`set_elems`].
//! * [`format`](mod@format): [`to_text`], the text of `str()` / `print()` / concatenation.
//! * [`builtins`]: the function registry, resolved once per call site with
//!   [`lookup`] (name and argument count).

// Tests pass `&[v.clone()]` argument lists freely.
#![cfg_attr(test, allow(clippy::cloned_ref_to_slice_refs))]

pub mod array;
pub mod builtins;
pub mod error;
pub mod format;
pub mod ops;
pub mod value;

pub use array::{build_array, index, range, set_elems};
pub use builtins::{lookup, lookup_name, Builtin, BuiltinFn, BUILTINS};
pub use error::ValueError;
pub use format::{format_float, to_text, write_float, write_value};
pub use ops::{binary, unary, values_equal, BinaryOp, UnaryOp};
pub use value::{Array, Element, Value, ValueType, MAX_ARRAY_SIZE};
