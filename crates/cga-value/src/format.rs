//! The text form of values: what `str()`, `print()` and string
//! concatenation produce, matching CityEngine's output character for
//! character.
//!
//! Floats follow CityEngine's runtime (measured on its 2024+ runtime, which
//! prints at most 15 significant digits; the reference pages still show some
//! 16-digit examples from older versions):
//!
//! * `0` is `0` (`-0` for negative zero), NaN is `nan`, infinities `inf`/`-inf`;
//! * `|v| <= 1e-5` or `|v| >= 1e16`: scientific, mantissa as C's `%.15e` with
//!   trailing zeros removed but one decimal kept (`1.0`), exponent with a `-`
//!   only when negative and at least two digits: `1.0e-05`, `1.2e16`, `1.0e100`;
//! * `|v| < 1`: C's `%.15f` with trailing zeros (and point) removed;
//! * otherwise C's `%.15g`, except that where `%g` would switch to exponent
//!   form (`>= 1e15` after rounding), `%.15f` trimmed is used instead
//!   (`999999999999999.9` prints as `999999999999999.875`).

use std::fmt::Write as _;

use crate::value::{Array, Value};

/// A fixed stack buffer for `core::fmt` output, so that formatting a float
/// does not allocate.
struct StackBuf {
    buf: [u8; 400],
    len: usize,
}

impl StackBuf {
    fn new() -> StackBuf {
        StackBuf {
            buf: [0; 400],
            len: 0,
        }
    }

    fn as_str(&self) -> &str {
        // Only ever filled through `write_str` with whole `&str`s.
        std::str::from_utf8(&self.buf[..self.len]).unwrap_or("")
    }
}

impl std::fmt::Write for StackBuf {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let end = self.len + s.len();
        if end > self.buf.len() {
            return Err(std::fmt::Error);
        }
        self.buf[self.len..end].copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// The text of a float, as `str()` gives it.
pub fn format_float(v: f64) -> String {
    let mut s = String::new();
    write_float(&mut s, v);
    s
}

/// Appends the text of a float (see the module documentation for the rules).
pub fn write_float(out: &mut String, v: f64) {
    if v.is_nan() {
        out.push_str("nan");
        return;
    }
    if v.is_infinite() {
        out.push_str(if v < 0.0 { "-inf" } else { "inf" });
        return;
    }
    if v == 0.0 {
        out.push_str(if v.is_sign_negative() { "-0" } else { "0" });
        return;
    }
    let a = v.abs();
    if a <= 1e-5 || a >= 1e16 {
        write_scientific(out, v);
        return;
    }
    if a < 1.0 {
        write_fixed_trimmed(out, v, 15);
        return;
    }
    // The common case of whole numbers (indices, counts, sizes): exact in an
    // i64 and fewer than 16 digits, so `%.15g` prints them as they are.
    if a < 1e15 && v.fract() == 0.0 {
        let _ = write!(out, "{}", v as i64);
        return;
    }
    // `%.15g`: the decimal exponent after rounding to 15 significant digits
    // decides the number of decimals.
    let mut buf = StackBuf::new();
    let _ = write!(buf, "{:.14e}", a);
    let exp = buf
        .as_str()
        .rsplit('e')
        .next()
        .and_then(|e| e.parse::<i32>().ok())
        .unwrap_or(0);
    if exp >= 15 {
        write_fixed_trimmed(out, v, 15);
    } else {
        write_fixed_trimmed(out, v, (14 - exp).max(0) as usize);
    }
}

/// `%.{decimals}f` with trailing zeros and a trailing point removed.
fn write_fixed_trimmed(out: &mut String, v: f64, decimals: usize) {
    let mut buf = StackBuf::new();
    if write!(buf, "{:.*}", decimals, v).is_err() {
        // Cannot happen for |v| < 1e16 with at most 15 decimals; stay total.
        let _ = write!(out, "{v}");
        return;
    }
    let mut s = buf.as_str();
    if s.contains('.') {
        s = s.trim_end_matches('0');
        s = s.trim_end_matches('.');
    }
    out.push_str(s);
}

/// `%.15e` with the mantissa trimmed to at least one decimal and CGA's
/// exponent form (`e-05`, `e16`, `e100`).
fn write_scientific(out: &mut String, v: f64) {
    let mut buf = StackBuf::new();
    let _ = write!(buf, "{:.15e}", v);
    let s = buf.as_str();
    let (mantissa, exp) = match s.split_once('e') {
        Some(parts) => parts,
        None => (s, "0"),
    };
    let mut m = mantissa.trim_end_matches('0');
    if m.ends_with('.') {
        // keep one decimal: "1." -> "1.0"
        m = &mantissa[..m.len() + 1];
    }
    out.push_str(m);
    out.push('e');
    let e: i32 = exp.parse().unwrap_or(0);
    if e < 0 {
        out.push('-');
    }
    let _ = write!(out, "{:02}", e.unsigned_abs());
}

/// `true` / `false`.
pub fn bool_text(b: bool) -> &'static str {
    if b {
        "true"
    } else {
        "false"
    }
}

/// The text of a value: what `str()` returns and `print()` writes (without
/// the line break `print` adds).
pub fn to_text(v: &Value) -> String {
    match v {
        Value::Str(s) => s.to_string(),
        _ => {
            let mut out = String::new();
            write_value(&mut out, v);
            out
        }
    }
}

/// Appends the text of a value (see [`to_text`]).
pub fn write_value(out: &mut String, v: &Value) {
    match v {
        Value::Float(f) => write_float(out, *f),
        Value::Bool(b) => out.push_str(bool_text(*b)),
        Value::Str(s) => out.push_str(s),
        Value::FloatArray(a) => write_array(out, a, |o, f| write_float(o, *f)),
        Value::BoolArray(a) => write_array(out, a, |o, b| o.push_str(bool_text(*b))),
        Value::StrArray(a) => write_array(out, a, |o, s| o.push_str(s)),
    }
}

/// 1D: `(3)[0,1,2]`. 2D: the header `(RxC)`, then one line per row where
/// each element is right-aligned to the widest element of its column plus 3.
fn write_array<T>(out: &mut String, a: &Array<T>, elem: impl Fn(&mut String, &T)) {
    if a.is_1d() {
        let _ = write!(out, "({})[", a.len());
        for (i, e) in a.data.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            elem(out, e);
        }
        out.push(']');
        return;
    }
    let _ = write!(out, "({}x{})", a.rows, a.cols);
    let texts: Vec<String> = a
        .data
        .iter()
        .map(|e| {
            let mut s = String::new();
            elem(&mut s, e);
            s
        })
        .collect();
    let mut widths = vec![0usize; a.cols];
    for (i, t) in texts.iter().enumerate() {
        let w = &mut widths[i % a.cols];
        *w = (*w).max(t.chars().count());
    }
    for r in 0..a.rows {
        out.push('\n');
        for (c, width) in widths.iter().enumerate() {
            let t = &texts[r * a.cols + c];
            for _ in t.chars().count()..width + 3 {
                out.push(' ');
            }
            out.push_str(t);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Measured output of CityEngine's runtime for `str()` / `print()`.
    /// The inputs are written as they were measured, digits beyond f64 included.
    #[test]
    #[allow(clippy::approx_constant, clippy::excessive_precision)]
    fn floats_print_as_cityengine_does() {
        let cases: &[(f64, &str)] = &[
            (1.0 / 3.0, "0.333333333333333"),
            (2.0 / 3.0, "0.666666666666667"),
            (1e-7, "1.0e-07"),
            (123456789.123, "123456789.123"),
            (1e20, "1.0e20"),
            (-0.5, "-0.5"),
            (2.5e-5, "0.000025"),
            (0.1 + 0.2, "0.3"),
            (100.0, "100"),
            (1234567.0, "1234567"),
            (12345678.0, "12345678"),
            (0.000123, "0.000123"),
            (3.14159265358979, "3.14159265358979"),
            (1e6, "1000000"),
            (1e15, "1000000000000000"),
            (1e16, "1.0e16"),
            (1e-4, "0.0001"),
            (1e-5, "1.0e-05"),
            (f64::NAN, "nan"),
            (f64::INFINITY, "inf"),
            (1.1e-5, "0.000011"),
            (9.9e-6, "9.9e-06"),
            (1.00000001e-5, "0.0000100000001"),
            (9999999999999998.0, "9999999999999998"),
            (1.2e16, "1.2e16"),
            (5e15, "5000000000000000"),
            (-1e-5, "-1.0e-05"),
            (-2e-5, "-0.00002"),
            (0.0, "0"),
            (-0.0, "-0"),
            (1.5e-7, "1.5e-07"),
            (123456.7890123456789, "123456.789012346"),
            (0.1, "0.1"),
            (1e21, "1.0e21"),
            (1.23456789012345678e-10, "1.234567890123457e-10"),
            (1e100, "1.0e100"),
            (1e-100, "1.0e-100"),
            (2.5, "2.5"),
            (-3.0, "-3"),
            (5e-6, "5.0e-06"),
            (1e-6, "1.0e-06"),
            (0.000333333333333333333, "0.000333333333333"),
            (1234.5678901234567, "1234.56789012346"),
            (99.99999999999999, "100"),
            (0.9999999999999999, "1"),
            (0.12345678901234567, "0.123456789012346"),
            (12.345678901234567, "12.3456789012346"),
            (999999999999999.9, "999999999999999.875"),
            (0.00001234567890123456, "0.000012345678901"),
        ];
        let mut failures = Vec::new();
        for &(v, expected) in cases {
            let got = format_float(v);
            if got != expected {
                failures.push(format!("{v:e}: expected {expected}, got {got}"));
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }

    #[test]
    fn float_edge_cases() {
        assert_eq!(format_float(f64::NEG_INFINITY), "-inf");
        // str(1.69 - 69/100) and str(001) from the str() page
        assert_eq!(format_float(1.69 - 69.0 / 100.0), "1");
        assert_eq!(format_float(1.69), "1.69");
        assert_eq!(format_float(1.0), "1");
        // Ties are rounded to even, as C's printf does on the exact binary value:
        // 2^-16 = 0.0000152587890625 has its 16th decimal a tie.
        assert_eq!(format_float(2f64.powi(-16)), "0.000015258789062");
        // %g drops the zeros left after rounding to 15 significant digits.
        assert_eq!(format_float(1.0000000000000007), "1");
        assert_eq!(format_float(-123.456), "-123.456");
        assert_eq!(format_float(-1e16), "-1.0e16");
        assert_eq!(format_float(f64::MAX), "1.797693134862316e308");
        assert_eq!(format_float(f64::MIN_POSITIVE), "2.225073858507201e-308");
        assert_eq!(format_float(5e-324), "4.940656458412465e-324");
    }

    #[test]
    fn one_dimensional_arrays() {
        assert_eq!(
            to_text(&Value::float_row(vec![0.0, 1.0, 2.0])),
            "(3)[0,1,2]"
        );
        assert_eq!(to_text(&Value::bool_row(vec![false])), "(1)[false]");
        assert_eq!(to_text(&Value::str_row(&["uhm"])), "(1)[uhm]");
        assert_eq!(to_text(&Value::str_row(&["a b", ""])), "(2)[a b,]");
        assert_eq!(to_text(&Value::float_row(vec![])), "(0)[]");
        assert_eq!(
            to_text(&Value::float_row(vec![0.0, 0.15, 0.3, 0.15 * 3.0])),
            "(4)[0,0.15,0.3,0.45]"
        );
    }

    #[test]
    fn two_dimensional_arrays() {
        let f = Value::from(Array::new(2, 3, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]));
        assert_eq!(to_text(&f), "(2x3)\n   1   2   3\n   4   5   6");
        let b = Value::from(Array::new(2, 2, vec![false, true, true, false]));
        assert_eq!(to_text(&b), "(2x2)\n   false    true\n    true   false");
        let s: Vec<std::sync::Arc<str>> = [
            "first", "row", "second", "row", "third", "row", "fourth", "row",
        ]
        .iter()
        .map(|s| std::sync::Arc::from(*s))
        .collect();
        let s = Value::from(Array::new(4, 2, s));
        assert_eq!(
            to_text(&s),
            "(4x2)\n    first   row\n   second   row\n    third   row\n   fourth   row"
        );
        // func_array.md: [-1 ; -2]
        let col = Value::from(Array::new(2, 1, vec![-1.0, -2.0]));
        assert_eq!(to_text(&col), "(2x1)\n   -1\n   -2");
        assert_eq!(format!("{col}"), "(2x1)\n   -1\n   -2");
    }
}
