//! The pure built-in functions of CGA: those whose result depends only on
//! their arguments (math, conversions, strings, arrays and the CGA utility
//! library). The evaluator resolves a call once, by name and argument count,
//! with [`lookup`], and then calls [`Builtin::f`] directly.
//!
//! Each function checks its argument types itself and returns a
//! [`ValueError`] for a mismatch: one name may accept several types (`abs`
//! takes `float` or `float[]`, `findFirst` is both the array built-in and the
//! string function of the utility library).
//!
//! Not here, because they need more than their arguments: `rand`, `p`,
//! `listRandom`, `fileRandom` (randomness); `print` (output; it prints
//! [`crate::to_text`]); `sel` (selectors); shape functions (`geometry.*`,
//! `comp`, `convert`, occlusion, context queries, `edgeAttr`, `getGeoCoord`,
//! `getMaterial`, `getTreeKey`); files and assets (`fileSearch`,
//! `filesSearch`, `fileExists`, `readTextFile`, `readMaterial`,
//! `read*Table`, `asset*`, `image*`).

mod arrays;
mod color;
pub mod convert;
mod lists;
mod math;
mod strings;

pub use color::{color_ramp, hex_to_rgba, rgb_to_hex};
pub use convert::{parse_bool, parse_float};
pub use strings::{char_len, count, find, split_string, substring};

use crate::error::ValueError;
use crate::value::Value;

/// The signature every built-in has.
pub type BuiltinFn = fn(&[Value]) -> Result<Value, ValueError>;

/// One built-in function. `f` is called with between `min_args` and
/// `max_args` arguments (inclusive) and checks their types.
#[derive(Debug)]
pub struct Builtin {
    pub name: &'static str,
    pub min_args: usize,
    pub max_args: usize,
    pub f: BuiltinFn,
}

impl Builtin {
    /// Calls the function, checking the argument count first.
    pub fn call(&self, args: &[Value]) -> Result<Value, ValueError> {
        if args.len() < self.min_args || args.len() > self.max_args {
            return Err(ValueError::new(format!(
                "{}: expected {} arguments, got {}",
                self.name,
                if self.min_args == self.max_args {
                    self.min_args.to_string()
                } else {
                    format!("{} to {}", self.min_args, self.max_args)
                },
                args.len()
            )));
        }
        (self.f)(args)
    }
}

const fn b(name: &'static str, min_args: usize, max_args: usize, f: BuiltinFn) -> Builtin {
    Builtin {
        name,
        min_args,
        max_args,
        f,
    }
}

/// Every pure built-in, by name. Names are unique: overloads of one name are
/// one entry whose function dispatches on the argument count and types.
pub static BUILTINS: &[Builtin] = &[
    // math (func_*.md); trigonometry in degrees
    b("abs", 1, 1, math::abs),
    b("acos", 1, 1, math::acos),
    b("asin", 1, 1, math::asin),
    b("atan", 1, 1, math::atan),
    b("atan2", 2, 2, math::atan2),
    b("ceil", 1, 1, math::ceil),
    b("cos", 1, 1, math::cos),
    b("exp", 1, 1, math::exp),
    b("floor", 1, 1, math::floor),
    b("isinf", 1, 1, math::isinf),
    b("isnan", 1, 1, math::isnan),
    b("isNull", 1, 1, math::is_null),
    b("ln", 1, 1, math::ln),
    b("log10", 1, 1, math::log10),
    b("pow", 2, 2, math::pow),
    b("rint", 1, 1, math::rint),
    b("sin", 1, 1, math::sin),
    b("sqrt", 1, 1, math::sqrt),
    b("tan", 1, 1, math::tan),
    // conversions
    b("bool", 1, 1, convert::bool_fn),
    b("float", 1, 1, convert::float_fn),
    b("str", 1, 1, convert::str_fn),
    b("boolArray", 0, 1, convert::bool_array),
    b("floatArray", 0, 1, convert::float_array),
    b("stringArray", 0, 1, convert::string_array),
    // strings
    b("count", 2, 2, strings::count_fn),
    b("find", 3, 3, strings::find_fn),
    b("len", 1, 1, strings::len_fn),
    b("splitString", 2, 2, strings::split_string_fn),
    b("substring", 3, 3, strings::substring_fn),
    // arrays
    b("findFirst", 2, 3, arrays::find_first),
    b("nColumns", 1, 1, arrays::n_columns),
    b("nRows", 1, 1, arrays::n_rows),
    b("setElems", 3, 4, arrays::set_elems),
    b("size", 1, 1, arrays::size),
    b("sortIndices", 1, 1, arrays::sort_indices),
    b("sortRowIndices", 1, 1, arrays::sort_row_indices),
    b("sum", 1, 1, arrays::sum),
    b("transpose", 1, 1, arrays::transpose),
    // utility library (celib/*.md)
    b("clamp", 3, 3, arrays::clamp),
    b("max", 2, 2, arrays::max),
    b("min", 2, 2, arrays::min),
    b("colorHexToR", 1, 1, color::hex_to_r),
    b("colorHexToG", 1, 1, color::hex_to_g),
    b("colorHexToB", 1, 1, color::hex_to_b),
    b("colorHexToO", 1, 1, color::hex_to_o),
    b("colorHexToH", 1, 1, color::hex_to_h),
    b("colorHexToS", 1, 1, color::hex_to_s),
    b("colorHexToV", 1, 1, color::hex_to_v),
    b("colorRGBToHex", 3, 3, color::rgb_to_hex_fn),
    b("colorRGBOToHex", 4, 4, color::rgbo_to_hex_fn),
    b("colorHSVToHex", 3, 3, color::hsv_to_hex_fn),
    b("colorHSVOToHex", 4, 4, color::hsvo_to_hex_fn),
    b("colorRamp", 2, 2, color::color_ramp_fn),
    b("findLast", 2, 2, strings::find_last_fn),
    b("getPrefix", 2, 2, strings::get_prefix_fn),
    b("getRange", 3, 3, strings::get_range_fn),
    b("getSuffix", 2, 2, strings::get_suffix_fn),
    b("replace", 3, 3, strings::replace_fn),
    b("fileBasename", 1, 1, strings::file_basename),
    b("fileDirectory", 1, 1, strings::file_directory),
    b("fileExtension", 1, 1, strings::file_extension),
    b("fileName", 1, 1, strings::file_name),
    b("listAdd", 2, 2, lists::list_add),
    b("listClean", 1, 1, lists::list_clean),
    b("listCount", 2, 2, lists::list_count),
    b("listFirst", 1, 1, lists::list_first),
    b("listFromArray", 1, 1, lists::list_from_array),
    b("listIndex", 2, 2, lists::list_index),
    b("listItem", 2, 2, lists::list_item),
    b("listLast", 1, 1, lists::list_last),
    b("listRange", 3, 3, lists::list_range),
    b("listRemove", 2, 2, lists::list_remove),
    b("listRemoveAll", 2, 2, lists::list_remove_all),
    b("listRetainAll", 2, 2, lists::list_retain_all),
    b("listSize", 1, 1, lists::list_size),
    b("listTerminate", 1, 1, lists::list_terminate),
    b("listToArray", 1, 1, lists::list_to_array),
];

/// The built-in `name` if it accepts `arg_count` arguments.
pub fn lookup(name: &str, arg_count: usize) -> Option<&'static Builtin> {
    lookup_name(name).filter(|b| (b.min_args..=b.max_args).contains(&arg_count))
}

/// The built-in called `name`, whatever its argument count (for messages
/// such as "abs expects 1 argument").
pub fn lookup_name(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// Calls the built-in `name` (looked up each time: for tests and tools; the
/// evaluator should keep the [`Builtin`] from [`lookup`]).
pub fn call(name: &str, args: &[Value]) -> Result<Value, ValueError> {
    match lookup_name(name) {
        Some(b) => b.call(args),
        None => Err(ValueError::new(format!("no built-in function {name}"))),
    }
}

// Argument access shared by the modules. Arity is checked by `lookup`, but a
// function must stay total if called directly with too few arguments.

pub(crate) fn arg<'a>(args: &'a [Value], i: usize, f: &str) -> Result<&'a Value, ValueError> {
    args.get(i)
        .ok_or_else(|| ValueError::new(format!("{f}: missing argument {}", i + 1)))
}

pub(crate) fn float_arg(args: &[Value], i: usize, f: &str) -> Result<f64, ValueError> {
    let v = arg(args, i, f)?;
    v.as_float().ok_or_else(|| arg_mismatch(f, i, "float", v))
}

pub(crate) fn str_arg<'a>(args: &'a [Value], i: usize, f: &str) -> Result<&'a str, ValueError> {
    let v = arg(args, i, f)?;
    v.as_str().ok_or_else(|| arg_mismatch(f, i, "string", v))
}

pub(crate) fn arg_mismatch(f: &str, i: usize, expected: &str, got: &Value) -> ValueError {
    ValueError::new(format!(
        "{f}: argument {} must be {expected}, not {}",
        i + 1,
        got.type_name()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_arities_sane() {
        let mut names: Vec<&str> = BUILTINS.iter().map(|b| b.name).collect();
        names.sort_unstable();
        let n = names.len();
        names.dedup();
        assert_eq!(names.len(), n, "duplicate built-in names");
        for b in BUILTINS {
            assert!(b.min_args <= b.max_args, "{}", b.name);
        }
    }

    #[test]
    fn lookup_checks_arity() {
        assert!(lookup("abs", 1).is_some());
        assert!(lookup("abs", 2).is_none());
        assert!(lookup("floatArray", 0).is_some());
        assert!(lookup("floatArray", 1).is_some());
        assert!(lookup("setElems", 4).is_some());
        assert!(lookup("setElems", 2).is_none());
        assert!(lookup("rand", 0).is_none());
        assert_eq!(lookup_name("findFirst").map(|b| b.max_args), Some(3));
    }

    #[test]
    fn wrong_count_is_an_error_not_a_panic() {
        for b in BUILTINS {
            // Too few arguments through the checked call, and straight into f.
            if b.min_args > 0 {
                assert!(b.call(&[]).is_err(), "{}", b.name);
                assert!((b.f)(&[]).is_err(), "{}", b.name);
            }
            let too_many = vec![Value::Float(1.0); b.max_args + 1];
            assert!(b.call(&too_many).is_err(), "{}", b.name);
        }
    }

    #[test]
    fn wrong_types_never_panic() {
        let samples = [
            Value::Float(1.0),
            Value::Float(f64::NAN),
            Value::Float(-1e300),
            Value::Bool(true),
            Value::str(""),
            Value::str("a;b;"),
            Value::float_row(vec![]),
            Value::float_row(vec![1.0, 2.0]),
            Value::bool_row(vec![true]),
            Value::str_row(&["x", ""]),
        ];
        for b in BUILTINS {
            for n in b.min_args..=b.max_args {
                // every combination of the samples would be large; rotate instead
                for k in 0..samples.len() {
                    let args: Vec<Value> = (0..n)
                        .map(|i| samples[(k + i * 3) % samples.len()].clone())
                        .collect();
                    let _ = b.call(&args);
                }
            }
        }
    }
}
