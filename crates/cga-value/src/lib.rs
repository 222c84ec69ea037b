//! CGA's values: `float`, `bool`, `string` and their 1D/2D arrays, the
//! operators on them, their text form (`str()`, `print()`), and the built-in
//! functions that depend only on their arguments (math, strings, conversions,
//! arrays, the utility library). Functions that read the current shape live
//! in `cga-engine`.

pub mod value;

pub use value::{Array, Value};
