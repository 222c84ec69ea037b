//! Attribute values given from outside the rules (the command line, a
//! host's options, GIS properties): read from text, converted to the
//! attribute's type, and checked against its annotations.

use std::sync::Arc;

use cga_value::builtins::convert::parse_bool;
use cga_value::{Array, Value, ValueType};

use crate::attributes::Attribute;

/// A value as the `cga` command reads `--attr NAME=VALUE`: `true`/`false`,
/// a number, an array in CGA's literal form (`[5,5]`, `["a","b"]`,
/// `[1,2;3,4]` for two rows), else a string (quotes around it dropped).
pub fn parse_value(text: &str) -> Value {
    let t = text.trim();
    if let Some(inner) = t.strip_prefix('[').and_then(|s| s.strip_suffix(']')) {
        if let Some(array) = parse_array(inner) {
            return array;
        }
    }
    match t {
        "true" => Value::Bool(true),
        "false" => Value::Bool(false),
        _ => match t.parse::<f64>() {
            Ok(x) => Value::Float(x),
            Err(_) => Value::Str(Arc::from(unquote(text))),
        },
    }
}

fn unquote(s: &str) -> &str {
    let t = s.trim();
    t.strip_prefix('"')
        .and_then(|u| u.strip_suffix('"'))
        .unwrap_or(s)
}

/// The elements of an array literal without its brackets: rows separated by
/// `;`, elements by `,`, all of one type (numbers, `true`/`false`, or
/// strings). `None` when the rows differ in length or the types mix.
fn parse_array(inner: &str) -> Option<Value> {
    if inner.trim().is_empty() {
        return Some(Value::FloatArray(Arc::new(Array::row(Vec::new()))));
    }
    let rows: Vec<Vec<Value>> = inner
        .split(';')
        .map(|row| row.split(',').map(parse_value).collect())
        .collect();
    let cols = rows[0].len();
    if rows.iter().any(|r| r.len() != cols) {
        return None;
    }
    let n_rows = rows.len();
    let flat: Vec<Value> = rows.into_iter().flatten().collect();
    let all = |f: fn(&Value) -> bool| flat.iter().all(f);
    if all(|v| matches!(v, Value::Float(_))) {
        let data = flat.iter().map(|v| v.as_float().unwrap_or(0.0)).collect();
        return Some(Value::FloatArray(Arc::new(Array::new(n_rows, cols, data))));
    }
    if all(|v| matches!(v, Value::Bool(_))) {
        let data = flat
            .iter()
            .map(|v| matches!(v, Value::Bool(true)))
            .collect();
        return Some(Value::BoolArray(Arc::new(Array::new(n_rows, cols, data))));
    }
    if all(|v| matches!(v, Value::Str(_))) {
        let data = flat
            .iter()
            .map(|v| match v {
                Value::Str(s) => s.clone(),
                _ => Arc::from(""),
            })
            .collect();
        return Some(Value::StrArray(Arc::new(Array::new(n_rows, cols, data))));
    }
    None
}

/// `value` in the type `ty` of an attribute: a float from text that reads
/// as a number, a bool from text or a number as CGA's `bool()` converts,
/// a string from anything (its CGA text form), arrays as given. `Err` says
/// why the value cannot be one (`abc` is not a number).
pub(crate) fn convert(value: &Value, ty: ValueType) -> Result<Value, String> {
    let text = || cga_engine::values::to_text(value);
    match (ty, value) {
        (ValueType::Float, Value::Float(_))
        | (ValueType::Bool, Value::Bool(_))
        | (ValueType::Str, Value::Str(_))
        | (ValueType::FloatArray, Value::FloatArray(_))
        | (ValueType::BoolArray, Value::BoolArray(_))
        | (ValueType::StrArray, Value::StrArray(_)) => Ok(value.clone()),
        (ValueType::Float, Value::Str(s)) => s
            .trim()
            .parse::<f64>()
            .map(Value::Float)
            .map_err(|_| format!("`{s}` is not a number")),
        (ValueType::Float, Value::Bool(b)) => Ok(Value::Float(if *b { 1.0 } else { 0.0 })),
        (ValueType::Bool, Value::Str(s)) => Ok(Value::Bool(parse_bool(s))),
        (ValueType::Bool, Value::Float(x)) => Ok(Value::Bool(*x != 0.0)),
        (ValueType::Str, _) => Ok(Value::Str(Arc::from(text().as_str()))),
        // A single value for an array attribute: an array of one.
        (ValueType::FloatArray, _) => convert(value, ValueType::Float)
            .map(|v| Value::FloatArray(Arc::new(Array::row(vec![v.as_float().unwrap_or(0.0)])))),
        (ValueType::BoolArray, _) => convert(value, ValueType::Bool)
            .map(|v| Value::BoolArray(Arc::new(Array::row(vec![matches!(v, Value::Bool(true))])))),
        (ValueType::StrArray, _) => Ok(Value::StrArray(Arc::new(Array::row(vec![Arc::from(
            text().as_str(),
        )])))),
        (_, _) => Err(format!("{} is not a {}", text(), ty.name())),
    }
}

/// Why `value` is not one the attribute's `@Range` or `@Enum` allows, if
/// it is not (unrestricted annotations allow anything).
pub(crate) fn outside_annotations(attr: &Attribute, value: &Value) -> Option<String> {
    if let (Some(range), Value::Float(x)) = (attr.range(), value) {
        if range.restricted && (*x < range.min || *x > range.max) {
            return Some(format!(
                "{} is outside the @Range of attribute `{}` ({} to {})",
                cga_engine::values::to_text(value),
                attr.name,
                cga_engine::values::to_text(&Value::Float(range.min)),
                cga_engine::values::to_text(&Value::Float(range.max)),
            ));
        }
    }
    let restricted = attr
        .annotation("Enum")
        .is_some_and(|a| !matches!(a.arg("restricted", usize::MAX), Some(Value::Bool(false))));
    if let (Some(values), true) = (attr.enum_values(), restricted) {
        let same = |v: &Value| match (v, value) {
            (Value::Float(a), Value::Float(b)) => (a - b).abs() <= 1e-9 * a.abs().max(1.0),
            _ => v == value,
        };
        if !values.is_empty() && !values.iter().any(same) {
            let list: Vec<String> = values.iter().map(cga_engine::values::to_text).collect();
            return Some(format!(
                "{} is not one of the @Enum values of attribute `{}` ({})",
                cga_engine::values::to_text(value),
                attr.name,
                list.join(", ")
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_reads_as_numbers_bools_arrays_and_strings() {
        assert_eq!(parse_value("3.5"), Value::Float(3.5));
        assert_eq!(parse_value("true"), Value::Bool(true));
        assert_eq!(parse_value("abc"), Value::from("abc"));
        assert_eq!(parse_value("\"12\""), Value::from("12"));
        assert_eq!(
            parse_value("[5,5]"),
            Value::FloatArray(Arc::new(Array::row(vec![5.0, 5.0])))
        );
        assert_eq!(
            parse_value("[1,2;3,4]"),
            Value::FloatArray(Arc::new(Array::new(2, 2, vec![1.0, 2.0, 3.0, 4.0])))
        );
        assert_eq!(
            parse_value("[\"a\", \"b\"]"),
            Value::StrArray(Arc::new(Array::row(vec![Arc::from("a"), Arc::from("b")])))
        );
        assert_eq!(
            parse_value("[true,false]"),
            Value::BoolArray(Arc::new(Array::row(vec![true, false])))
        );
        // Mixed types, ragged rows: a string.
        assert_eq!(parse_value("[1,a]"), Value::from("[1,a]"));
        assert_eq!(parse_value("[1,2;3]"), Value::from("[1,2;3]"));
    }

    #[test]
    fn values_convert_to_the_attribute_type() {
        assert_eq!(
            convert(&Value::from("20"), ValueType::Float),
            Ok(Value::Float(20.0))
        );
        assert_eq!(
            convert(&Value::from("abc"), ValueType::Float),
            Err("`abc` is not a number".to_string())
        );
        // As the bool page converts: "f", "false", "0" are false.
        for (text, b) in [
            ("f", false),
            ("0", false),
            ("false", false),
            ("yes", true),
            ("1", true),
        ] {
            assert_eq!(
                convert(&Value::from(text), ValueType::Bool),
                Ok(Value::Bool(b)),
                "{text}"
            );
        }
        assert_eq!(
            convert(&Value::Float(2.0), ValueType::Str),
            Ok(Value::from("2"))
        );
        assert_eq!(
            convert(&Value::Float(2.0), ValueType::FloatArray),
            Ok(Value::FloatArray(Arc::new(Array::row(vec![2.0]))))
        );
        assert!(convert(&Value::from("x"), ValueType::FloatArray).is_err());
    }
}
