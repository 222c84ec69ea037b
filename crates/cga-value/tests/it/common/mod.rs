//! Test helpers: CGA literals as the reference pages write them.

#![allow(dead_code)]

use cga_value::{build_array, to_text, Value};

/// A value from a CGA literal: `1.5`, `-2`, `"a"`, `true`, or an array
/// literal of those, `[1,2;3,4]`, `["a";"b"]`, `[true,false]`.
pub fn lit(s: &str) -> Value {
    let s = s.trim();
    if let Some(inner) = s.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
        let rows: Vec<Vec<Value>> = split_top(inner, ';')
            .iter()
            .map(|row| split_top(row, ',').iter().map(|e| lit(e)).collect())
            .collect();
        return build_array(&rows).expect("valid array literal");
    }
    if let Some(text) = s.strip_prefix('"').and_then(|r| r.strip_suffix('"')) {
        return Value::str(text);
    }
    match s {
        "true" => Value::Bool(true),
        "false" => Value::Bool(false),
        _ => Value::Float(s.parse().unwrap_or_else(|_| panic!("bad literal {s:?}"))),
    }
}

/// Splits at `sep` outside of string quotes.
fn split_top(s: &str, sep: char) -> Vec<String> {
    let mut parts = vec![String::new()];
    let mut quoted = false;
    for c in s.chars() {
        if c == '"' {
            quoted = !quoted;
        }
        if c == sep && !quoted {
            parts.push(String::new());
        } else {
            parts.last_mut().unwrap().push(c);
        }
    }
    parts
}

/// Asserts that `got` prints like the literal `expected` (the reference
/// pages state results in that form, rounded to the printed digits), and
/// has its type and dimensions.
#[track_caller]
pub fn assert_cga(got: &Value, expected: &str) {
    let want = lit(expected);
    assert_eq!(
        got.value_type(),
        want.value_type(),
        "type of {got:?}, expected {expected}"
    );
    assert_eq!(
        got.dims(),
        want.dims(),
        "dimensions of {got:?}, expected {expected}"
    );
    assert_eq!(to_text(got), to_text(&want), "expected {expected}");
}
