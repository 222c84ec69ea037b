//! String lists of the utility library: items stored in one string, each
//! followed by `;` (`"rule;your;city;"`).
//!
//! In CityEngine these functions are CGA code built on `count`, `find` and
//! `substring`. `listTerminate`, `listSize`, `listFirst`, `listItem` and
//! `listRange` follow that code literally (including its edge cases: a
//! fractional or negative index, an unterminated list), as read from the
//! compiled library in a CityEngine rule package. The others have no known
//! source and follow their reference pages.

use std::sync::Arc;

use super::strings::{char_len, count, find, get_prefix, substring};
use super::{arg, arg_mismatch, float_arg, str_arg};
use crate::error::ValueError;
use crate::format::write_value;
use crate::ops::{float_relation_ge, float_relation_gt, float_relation_lt};
use crate::value::{Array, Value};

/// `listTerminate`: appends the missing `;` to a non-empty list.
pub fn terminate(list: &str) -> std::borrow::Cow<'_, str> {
    if !list.is_empty() && !list.ends_with(';') {
        std::borrow::Cow::Owned(format!("{list};"))
    } else {
        std::borrow::Cow::Borrowed(list)
    }
}

/// The items of a list (the last one need not be terminated).
pub fn items(list: &str) -> impl Iterator<Item = &str> {
    list.split_terminator(';')
}

/// `listSize`: the number of `;` in the terminated list.
pub fn size(list: &str) -> usize {
    count(&terminate(list), ";")
}

/// A search string with optional leading/trailing `*` wildcards.
fn matches(item: &str, pattern: &str) -> bool {
    let lead = pattern.starts_with('*');
    let inner = pattern.strip_prefix('*').unwrap_or(pattern);
    let trail = inner.ends_with('*');
    let inner = inner.strip_suffix('*').unwrap_or(inner);
    match (lead, trail) {
        (true, true) => item.contains(inner),
        (true, false) => item.ends_with(inner),
        (false, true) => item.starts_with(inner),
        (false, false) => item == pattern,
    }
}

fn join<'a>(items: impl Iterator<Item = &'a str>) -> Value {
    let mut out = String::new();
    for i in items {
        out.push_str(i);
        out.push(';');
    }
    Value::from(out)
}

pub fn list_terminate(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listTerminate")?;
    Ok(match terminate(l) {
        std::borrow::Cow::Borrowed(_) => args[0].clone(),
        std::borrow::Cow::Owned(s) => Value::from(s),
    })
}

pub fn list_size(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::Float(size(str_arg(args, 0, "listSize")?) as f64))
}

/// `listFirst(l)` is `getPrefix(l, ";")`.
pub fn list_first(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::str(get_prefix(str_arg(args, 0, "listFirst")?, ";")))
}

pub fn list_last(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listLast")?;
    Ok(Value::str(items(l).last().unwrap_or("")))
}

/// `listItem(l, i)`: `listFirst(l)` for `i == 0`; for `i < listSize(l)`
/// the text between the `i`-th `;` and the next; otherwise `""`.
pub fn list_item(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listItem")?;
    let i = float_arg(args, 1, "listItem")?;
    if i == 0.0 {
        return Ok(Value::str(get_prefix(l, ";")));
    }
    if float_relation_lt(i, size(l) as f64) {
        let start = find(l, ";", i - 1.0) + 1.0;
        let end = find(&terminate(l), ";", i);
        return Ok(Value::str(substring(l, start, end)));
    }
    Ok(Value::str(""))
}

/// `listRange(l, left, right)`: items `left..right`, each with its `;`.
pub fn list_range(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listRange")?;
    let left = float_arg(args, 1, "listRange")?;
    let right = float_arg(args, 2, "listRange")?;
    let n = size(l) as f64;
    let len = char_len(l) as f64;
    if float_relation_ge(left, right) || float_relation_ge(left, n) {
        return Ok(Value::str(""));
    }
    // `left <= 0` in CGA, where a NaN compares as less.
    let from_start = !float_relation_gt(left, 0.0);
    Ok(if from_start {
        if float_relation_lt(right, n) {
            Value::str(substring(l, 0.0, find(l, ";", right - 1.0) + 1.0))
        } else {
            Value::str(&terminate(l))
        }
    } else {
        let start = find(l, ";", left - 1.0) + 1.0;
        if float_relation_ge(right, n) {
            Value::str(&terminate(substring(l, start, len)))
        } else {
            Value::str(substring(l, start, find(l, ";", right - 1.0) + 1.0))
        }
    })
}

/// `listAdd(l, item)`: both terminated and concatenated.
pub fn list_add(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listAdd")?;
    let item = str_arg(args, 1, "listAdd")?;
    Ok(Value::from(format!("{}{}", terminate(l), terminate(item))))
}

/// `listClean(l)`: empty items removed, terminated.
pub fn list_clean(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listClean")?;
    Ok(join(items(l).filter(|i| !i.is_empty())))
}

pub fn list_count(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listCount")?;
    let p = str_arg(args, 1, "listCount")?;
    Ok(Value::Float(
        items(l).filter(|i| matches(i, p)).count() as f64
    ))
}

pub fn list_index(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listIndex")?;
    let p = str_arg(args, 1, "listIndex")?;
    Ok(Value::Float(
        items(l)
            .position(|i| matches(i, p))
            .map_or(-1.0, |k| k as f64),
    ))
}

pub fn list_remove(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listRemove")?;
    let p = str_arg(args, 1, "listRemove")?;
    let skip = items(l).position(|i| matches(i, p));
    Ok(join(
        items(l)
            .enumerate()
            .filter(|(k, _)| Some(*k) != skip)
            .map(|(_, i)| i),
    ))
}

pub fn list_remove_all(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listRemoveAll")?;
    let p = str_arg(args, 1, "listRemoveAll")?;
    Ok(join(items(l).filter(|i| !matches(i, p))))
}

pub fn list_retain_all(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listRetainAll")?;
    let p = str_arg(args, 1, "listRetainAll")?;
    Ok(join(items(l).filter(|i| matches(i, p))))
}

/// `listFromArray(a)`: each element as text, followed by `;`.
pub fn list_from_array(args: &[Value]) -> Result<Value, ValueError> {
    let a = arg(args, 0, "listFromArray")?;
    let mut out = String::new();
    let mut push = |v: Value| {
        write_value(&mut out, &v);
        out.push(';');
    };
    match a {
        Value::FloatArray(x) => x.data.iter().for_each(|e| push(Value::Float(*e))),
        Value::BoolArray(x) => x.data.iter().for_each(|e| push(Value::Bool(*e))),
        Value::StrArray(x) => x.data.iter().for_each(|e| push(Value::Str(e.clone()))),
        _ => return Err(arg_mismatch("listFromArray", 0, "an array", a)),
    }
    Ok(Value::from(out))
}

/// `listToArray(l)`: the items as a `string[]`.
pub fn list_to_array(args: &[Value]) -> Result<Value, ValueError> {
    let l = str_arg(args, 0, "listToArray")?;
    Ok(Array::row(items(l).map(Arc::from).collect::<Vec<Arc<str>>>()).into())
}

#[cfg(test)]
mod tests {
    use crate::builtins::call;
    use crate::to_text;
    use crate::value::Value;

    fn s(name: &str, args: &[Value]) -> Value {
        call(name, args).unwrap()
    }
    fn v(x: &str) -> Value {
        Value::str(x)
    }
    fn f(x: f64) -> Value {
        Value::Float(x)
    }

    /// The examples of the celib/list*.md pages.
    #[test]
    fn list_examples() {
        assert_eq!(
            s("listAdd", &[v("rule;your;"), v("city")]),
            v("rule;your;city;")
        );
        assert_eq!(
            s("listAdd", &[v("rule;your;"), v("city;")]),
            v("rule;your;city;")
        );
        assert_eq!(
            s("listClean", &[v(";;;;;my;city;rules;;your;;city;;")]),
            v("my;city;rules;your;city;")
        );
        assert_eq!(
            s("listClean", &[v(";;cityengine;;;rules")]),
            v("cityengine;rules;")
        );
        assert_eq!(s("listCount", &[v("rule;your;city;"), v("city")]), f(1.0));
        assert_eq!(
            s("listCount", &[v("city;cityengine;city;"), v("city")]),
            f(2.0)
        );
        assert_eq!(s("listCount", &[v("rule;your;city;"), v("*y*")]), f(2.0));
        assert_eq!(s("listCount", &[v("rule;your;city;"), v("*y")]), f(1.0));
        assert_eq!(s("listFirst", &[v("rule;your;city;")]), v("rule"));
        assert_eq!(
            to_text(&s(
                "listFromArray",
                &[Value::float_row(vec![1.0, 2.0, 3.0])]
            )),
            "1;2;3;"
        );
        assert_eq!(
            s("listFromArray", &[Value::bool_row(vec![true, false, true])]),
            v("true;false;true;")
        );
        assert_eq!(
            s(
                "listFromArray",
                &[Value::str_row(&["rule", "your", "city"])]
            ),
            v("rule;your;city;")
        );
        assert_eq!(s("listIndex", &[v("rule;your;city;"), v("city")]), f(2.0));
        assert_eq!(s("listIndex", &[v("rule;your;city;"), v("*y")]), f(2.0));
        assert_eq!(s("listIndex", &[v("rule;your;city;"), v("*y*")]), f(1.0));
        assert_eq!(s("listIndex", &[v("rule;your;city;"), v("town")]), f(-1.0));
        assert_eq!(s("listItem", &[v("rule;your;city;"), f(2.0)]), v("city"));
        assert_eq!(
            s(
                "listItem",
                &[v("texture_1.jpg;texture_2.jpg;texture_3.jpg;"), f(0.0)]
            ),
            v("texture_1.jpg")
        );
        assert_eq!(s("listLast", &[v("rule;your;city;")]), v("city"));
        assert_eq!(
            s(
                "listRange",
                &[v("rule;your;city;with;cityengine;"), f(0.0), f(3.0)]
            ),
            v("rule;your;city;")
        );
        // The page states "texture_3" for this one, without the `;` that its
        // first example keeps; the library code returns the item with it.
        assert_eq!(
            s(
                "listRange",
                &[
                    v("texture_1;texture_2;texture_3;texture_4;texture_5;texture_6;"),
                    f(2.0),
                    f(3.0)
                ]
            ),
            v("texture_3;")
        );
        assert_eq!(
            s("listRemove", &[v("rule;your;city;"), v("your")]),
            v("rule;city;")
        );
        assert_eq!(
            s("listRemove", &[v("rule;your;city;"), v("*u*")]),
            v("your;city;")
        );
        assert_eq!(
            s("listRemove", &[v("floor_1;floor_2;floor_3;"), v("*_2")]),
            v("floor_1;floor_3;")
        );
        assert_eq!(
            s(
                "listRemoveAll",
                &[v("rule;your;designs;and;your;cities;"), v("your")]
            ),
            v("rule;designs;and;cities;")
        );
        assert_eq!(
            s(
                "listRemoveAll",
                &[v("rule;your;designs;and;your;cities;"), v("*u*")]
            ),
            v("designs;and;cities;")
        );
        assert_eq!(
            s(
                "listRetainAll",
                &[v("rule;your;designs;and;your;cities;"), v("*s")]
            ),
            v("designs;cities;")
        );
        assert_eq!(
            s("listRetainAll", &[v("floor;floor_1;floor_2;"), v("*_*")]),
            v("floor_1;floor_2;")
        );
        assert_eq!(s("listSize", &[v("cityengine;rules;")]), f(2.0));
        assert_eq!(s("listTerminate", &[v("a;b")]), v("a;b;"));
        assert_eq!(s("listTerminate", &[v("a;b;")]), v("a;b;"));
        assert_eq!(s("listTerminate", &[v("")]), v(""));
        let floats = s("floatArray", &[s("listToArray", &[v("1;2;3;")])]);
        assert_eq!(to_text(&floats), "(3)[1,2,3]");
        let bools = s("boolArray", &[s("listToArray", &[v("true;false;true;")])]);
        assert_eq!(to_text(&bools), "(3)[true,false,true]");
        assert_eq!(
            s("listToArray", &[v("rule;your;city;")]),
            Value::str_row(&["rule", "your", "city"])
        );
    }

    #[test]
    fn list_edge_cases_follow_the_library_code() {
        // unterminated lists
        assert_eq!(s("listSize", &[v("a;b")]), f(2.0));
        assert_eq!(s("listSize", &[v("")]), f(0.0));
        assert_eq!(s("listItem", &[v("a;b"), f(1.0)]), v("b"));
        assert_eq!(s("listFirst", &[v("abc")]), v("abc"));
        // out of range
        assert_eq!(s("listItem", &[v("a;b;"), f(2.0)]), v(""));
        assert_eq!(s("listItem", &[v("a;b;"), f(-1.0)]), v(""));
        // ranges reaching the end are terminated
        assert_eq!(s("listRange", &[v("a;b;c"), f(1.0), f(5.0)]), v("b;c;"));
        assert_eq!(s("listRange", &[v("a;b;c"), f(0.0), f(5.0)]), v("a;b;c;"));
        assert_eq!(s("listRange", &[v("a;b;c;"), f(2.0), f(1.0)]), v(""));
        assert_eq!(s("listRange", &[v("a;b;c;"), f(3.0), f(4.0)]), v(""));
        assert_eq!(s("listLast", &[v("")]), v(""));
        assert_eq!(s("listToArray", &[v("")]).array_len(), Some(0));
    }
}
