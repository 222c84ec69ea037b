//! Conversions: `bool`, `float`, `str`, `boolArray`, `floatArray`, `stringArray`.

use std::sync::Arc;

use super::{arg, arg_mismatch};
use crate::error::ValueError;
use crate::format::{bool_text, format_float, to_text};
use crate::value::{Array, Value};

/// `float(string)`: the longest prefix that reads as a number, as C's
/// `strtod` does (leading white space, sign, digits, point, exponent, and
/// `inf`/`infinity`/`nan`); NaN if there is none. So `"001.5"` is 1.5,
/// `"5+6"` is 5 and `"nixda"` is NaN.
pub fn parse_float(s: &str) -> f64 {
    let bytes = s.as_bytes();
    let mut i = 0;
    while i < bytes.len() && matches!(bytes[i], b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c) {
        i += 1;
    }
    let start = i;
    if i < bytes.len() && (bytes[i] == b'+' || bytes[i] == b'-') {
        i += 1;
    }
    let negative = start < bytes.len() && bytes[start] == b'-';
    let rest = &s[i..];
    let lower_starts = |p: &str| rest.len() >= p.len() && rest[..p.len()].eq_ignore_ascii_case(p);
    if lower_starts("inf") {
        return if negative {
            f64::NEG_INFINITY
        } else {
            f64::INFINITY
        };
    }
    if lower_starts("nan") {
        return f64::NAN;
    }
    let digits_from = |mut j: usize| {
        while j < bytes.len() && bytes[j].is_ascii_digit() {
            j += 1;
        }
        j
    };
    let int_end = digits_from(i);
    let mut end = int_end;
    let mut frac_digits = 0;
    if end < bytes.len() && bytes[end] == b'.' {
        let frac_end = digits_from(end + 1);
        frac_digits = frac_end - (end + 1);
        end = frac_end;
    }
    if int_end == i && frac_digits == 0 {
        return f64::NAN;
    }
    if end < bytes.len() && (bytes[end] == b'e' || bytes[end] == b'E') {
        let mut j = end + 1;
        if j < bytes.len() && (bytes[j] == b'+' || bytes[j] == b'-') {
            j += 1;
        }
        let exp_end = digits_from(j);
        if exp_end > j {
            end = exp_end;
        }
    }
    // Rust's parser takes "1.", ".5" and "1e5" alike; the slice is all ASCII.
    s[start..end].parse::<f64>().unwrap_or(f64::NAN)
}

/// `bool(string)`: false for `"f"`, `"false"` (any case), the empty string
/// and any text that reads entirely as the number 0 (`"0"`, `"0.0"`,
/// `" -0e3 "`); true otherwise.
pub fn parse_bool(s: &str) -> bool {
    let t = s.trim();
    if t.is_empty() || t.eq_ignore_ascii_case("f") || t.eq_ignore_ascii_case("false") {
        return false;
    }
    if t.as_bytes()[0].is_ascii_digit() || matches!(t.as_bytes()[0], b'+' | b'-' | b'.') {
        if let Ok(x) = t.parse::<f64>() {
            return x != 0.0;
        }
    }
    true
}

fn float_to_bool(x: f64) -> bool {
    // NaN is not equal to 0, so it converts to true (as in C).
    x != 0.0
}

fn bool_to_float(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

pub fn bool_fn(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::Bool(match arg(args, 0, "bool")? {
        Value::Float(x) => float_to_bool(*x),
        Value::Bool(b) => *b,
        Value::Str(s) => parse_bool(s),
        v => return Err(arg_mismatch("bool", 0, "float, bool or string", v)),
    }))
}

pub fn float_fn(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::Float(match arg(args, 0, "float")? {
        Value::Float(x) => *x,
        Value::Bool(b) => bool_to_float(*b),
        Value::Str(s) => parse_float(s),
        v => return Err(arg_mismatch("float", 0, "float, bool or string", v)),
    }))
}

/// `str(value)`: any value, arrays included, as [`to_text`] writes it.
pub fn str_fn(args: &[Value]) -> Result<Value, ValueError> {
    let v = arg(args, 0, "str")?;
    Ok(match v {
        Value::Str(_) => v.clone(),
        _ => Value::from(to_text(v)),
    })
}

pub fn bool_array(args: &[Value]) -> Result<Value, ValueError> {
    let Some(v) = args.first() else {
        return Ok(Array::<bool>::empty().into());
    };
    Ok(match v {
        Value::BoolArray(_) => v.clone(),
        Value::FloatArray(a) => a.map(|x| float_to_bool(*x)).into(),
        Value::StrArray(a) => a.map(|s| parse_bool(s)).into(),
        _ => return Err(arg_mismatch("boolArray", 0, "an array", v)),
    })
}

pub fn float_array(args: &[Value]) -> Result<Value, ValueError> {
    let Some(v) = args.first() else {
        return Ok(Array::<f64>::empty().into());
    };
    Ok(match v {
        Value::FloatArray(_) => v.clone(),
        Value::BoolArray(a) => a.map(|b| bool_to_float(*b)).into(),
        Value::StrArray(a) => a.map(|s| parse_float(s)).into(),
        _ => return Err(arg_mismatch("floatArray", 0, "an array", v)),
    })
}

pub fn string_array(args: &[Value]) -> Result<Value, ValueError> {
    let Some(v) = args.first() else {
        return Ok(Array::<Arc<str>>::empty().into());
    };
    Ok(match v {
        Value::StrArray(_) => v.clone(),
        Value::FloatArray(a) => a.map(|x| Arc::from(format_float(*x))).into(),
        Value::BoolArray(a) => a.map(|b| Arc::from(bool_text(*b))).into(),
        _ => return Err(arg_mismatch("stringArray", 0, "an array", v)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtins::call;

    fn c(name: &str, v: Value) -> Value {
        call(name, &[v]).unwrap()
    }

    /// func_bool.md examples.
    #[test]
    fn bool_examples() {
        assert_eq!(c("bool", Value::Float(1.0)), Value::Bool(true));
        assert_eq!(c("bool", Value::Float(0.0)), Value::Bool(false));
        assert_eq!(c("bool", Value::str("1")), Value::Bool(true));
        assert_eq!(c("bool", Value::Float(6.66)), Value::Bool(true));
        assert_eq!(c("bool", Value::str("false")), Value::Bool(false));
        assert_eq!(c("bool", Value::str("f")), Value::Bool(false));
        assert_eq!(c("bool", Value::str("true")), Value::Bool(true));
        assert_eq!(
            c("bool", Value::str("beneath the remains")),
            Value::Bool(true)
        );
        assert_eq!(c("bool", Value::Bool(11.5 == 0.0)), Value::Bool(false));
        // "0.0" etc. from the description
        assert_eq!(c("bool", Value::str("0")), Value::Bool(false));
        assert_eq!(c("bool", Value::str("0.0")), Value::Bool(false));
        assert_eq!(c("bool", Value::str("00")), Value::Bool(false));
    }

    /// func_float.md examples.
    #[test]
    fn float_examples() {
        assert_eq!(c("float", Value::str("0.5")), Value::Float(0.5));
        assert_eq!(c("float", Value::Bool(true)), Value::Float(1.0));
        assert_eq!(c("float", Value::str("001.5")), Value::Float(1.5));
        assert_eq!(
            c("float", Value::Float(1.0 / 0.0)),
            Value::Float(f64::INFINITY)
        );
        assert_eq!(to_text(&c("float", Value::Float(1.0 / 0.0))), "inf");
        assert!(parse_float("a").is_nan());
        assert!(parse_float("").is_nan());
        assert!(parse_float(".").is_nan());
        assert!(parse_float("-").is_nan());
        assert_eq!(parse_float("5+6"), 5.0);
        assert_eq!(parse_float("  -2.5e2xyz"), -250.0);
        assert_eq!(parse_float("1e"), 1.0);
        assert_eq!(parse_float(".5"), 0.5);
        assert_eq!(parse_float("7."), 7.0);
        assert_eq!(parse_float("-Infinity"), f64::NEG_INFINITY);
    }

    /// func_str.md examples.
    #[test]
    fn str_examples() {
        assert_eq!(c("str", Value::Float(1.69)), Value::str("1.69"));
        assert_eq!(c("str", Value::Float(1.69 - 69.0 / 100.0)), Value::str("1"));
        assert_eq!(c("str", Value::Float(1.0)), Value::str("1"));
        assert_eq!(c("str", Value::Bool(true)), Value::str("true"));
        assert_eq!(
            c("str", Value::float_row(vec![1.0, 2.5])),
            Value::str("(2)[1,2.5]")
        );
    }

    /// func_boolArray.md, func_floatArray.md, func_stringArray.md examples.
    #[test]
    fn array_conversions() {
        let t = |name: &str, v: Value| to_text(&c(name, v));
        assert_eq!(
            t("boolArray", Value::float_row(vec![1.0, 0.0, 1.0, 20.0])),
            "(4)[true,false,true,true]"
        );
        assert_eq!(
            t(
                "boolArray",
                Value::str_row(&["true", "1", "0", "f", "false", "schwiizer nati"])
            ),
            "(6)[true,true,false,false,false,true]"
        );
        assert_eq!(
            t("boolArray", Value::bool_row(vec![true, false, true])),
            "(3)[true,false,true]"
        );
        assert_eq!(
            t("floatArray", Value::float_row(vec![1.0, 0.0, 1.777, 20.0])),
            "(4)[1,0,1.777,20]"
        );
        assert_eq!(
            t(
                "floatArray",
                Value::str_row(&["1.5", "-2", "0", "nixda", "5+6"])
            ),
            "(5)[1.5,-2,0,nan,5]"
        );
        assert_eq!(
            t("floatArray", Value::bool_row(vec![true, false, true])),
            "(3)[1,0,1]"
        );
        assert_eq!(
            t("stringArray", Value::float_row(vec![1.0, 0.0, 1.777, 20.0])),
            "(4)[1,0,1.777,20]"
        );
        assert_eq!(
            t("stringArray", Value::str_row(&["true", "CityEngine", ""])),
            "(3)[true,CityEngine,]"
        );
        assert_eq!(
            t("stringArray", Value::bool_row(vec![true, false, true])),
            "(3)[true,false,true]"
        );
        // the empty forms
        assert_eq!(to_text(&call("floatArray", &[]).unwrap()), "(0)[]");
        assert_eq!(
            call("boolArray", &[]).unwrap().value_type().name(),
            "bool[]"
        );
        assert_eq!(call("stringArray", &[]).unwrap().array_len(), Some(0));
        // conversions keep the dimensions
        let m = Value::from(Array::new(2, 1, vec![0.0, 3.0]));
        assert_eq!(t("boolArray", m), "(2x1)\n   false\n    true");
    }
}
