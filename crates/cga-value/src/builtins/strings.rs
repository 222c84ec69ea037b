//! String functions: `count`, `find`, `len`, `splitString`, `substring`,
//! and the string and file-path functions of the utility library.
//!
//! Positions and lengths count characters (Unicode scalar values), not
//! bytes. Pure-ASCII strings, the common case, take byte-indexed fast paths.
//!
//! The utility library functions (`getPrefix`, `getSuffix`, `findLast`,
//! `replace`, ...) are CGA code in CityEngine; their semantics here follow
//! that code, which is built on `count`, `find` and `substring`.

use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::Arc;

use fancy_regex::Regex;

use super::{arg, arg_mismatch, float_arg, str_arg};
use crate::error::ValueError;
use crate::format::write_value;
use crate::value::{Array, Value, MAX_ARRAY_SIZE};

/// Number of characters of `s`.
pub fn char_len(s: &str) -> usize {
    if s.is_ascii() {
        s.len()
    } else {
        s.chars().count()
    }
}

/// Byte offset of character position `pos` (clamped to the end).
fn byte_at(s: &str, pos: usize) -> usize {
    if s.is_ascii() {
        pos.min(s.len())
    } else {
        s.char_indices().nth(pos).map_or(s.len(), |(b, _)| b)
    }
}

/// Character position of byte offset `b` (a char boundary).
fn char_pos(s: &str, b: usize) -> usize {
    if s.is_ascii() {
        b
    } else {
        s[..b].chars().count()
    }
}

/// A float position argument as an integer (fraction dropped, as a C cast
/// does; NaN counts as 0).
fn int_of(f: f64) -> i64 {
    if f.is_nan() {
        0
    } else {
        f.trunc().clamp(i64::MIN as f64, i64::MAX as f64) as i64
    }
}

/// `count(input, match)`: non-overlapping occurrences; 0 for an empty match.
pub fn count(input: &str, pattern: &str) -> usize {
    if pattern.is_empty() {
        0
    } else {
        input.matches(pattern).count()
    }
}

/// `find(input, match, n)`: character index of the n-th (0-based,
/// non-overlapping) occurrence, or -1.
pub fn find(input: &str, pattern: &str, n: f64) -> f64 {
    let n = int_of(n);
    if pattern.is_empty() || n < 0 {
        return -1.0;
    }
    match input.match_indices(pattern).nth(n as usize) {
        Some((b, _)) => char_pos(input, b) as f64,
        None => -1.0,
    }
}

/// `substring(input, start, end)`: characters `start..end`, positions
/// clamped to the string; empty if `start >= end`.
pub fn substring(input: &str, start: f64, end: f64) -> &str {
    let len = char_len(input) as i64;
    let s = int_of(start).clamp(0, len) as usize;
    let e = int_of(end).clamp(0, len) as usize;
    if s >= e {
        return "";
    }
    &input[byte_at(input, s)..byte_at(input, e)]
}

/// `findFirst(input, match)` of the utility library: `find(input, match, 0)`.
pub fn find_first_str(input: &str, pattern: &str) -> f64 {
    find(input, pattern, 0.0)
}

/// `findLast(input, match)`: `find(input, match, count(input, match) - 1)`.
pub fn find_last(input: &str, pattern: &str) -> f64 {
    find(input, pattern, count(input, pattern) as f64 - 1.0)
}

/// `getPrefix(input, match)`: the text before the first occurrence, or the
/// whole input if there is none.
pub fn get_prefix<'a>(input: &'a str, pattern: &str) -> &'a str {
    if count(input, pattern) > 0 {
        substring(input, 0.0, find_first_str(input, pattern))
    } else {
        input
    }
}

/// `getSuffix(input, match)`: the text after the last occurrence, or the
/// whole input if there is none.
pub fn get_suffix<'a>(input: &'a str, pattern: &str) -> &'a str {
    if count(input, pattern) > 0 {
        let start = find_last(input, pattern) + char_len(pattern) as f64;
        substring(input, start, char_len(input) as f64)
    } else {
        input
    }
}

/// `splitString(input, delimiter)`. A delimiter starting with `$` is a
/// regular expression (Perl syntax, lookaround included); an empty
/// delimiter splits between all characters (`"abc"` gives `["","a","b","c",""]`);
/// an empty input gives `[""]`. At most [`MAX_ARRAY_SIZE`] parts.
pub fn split_string(input: &str, delimiter: &str) -> Result<Vec<Arc<str>>, ValueError> {
    let mut parts: Vec<Arc<str>> = Vec::new();
    let mut push = |s: &str| -> Result<(), ValueError> {
        if parts.len() == MAX_ARRAY_SIZE {
            return Err(ValueError::too_large("splitString", MAX_ARRAY_SIZE + 1));
        }
        parts.push(Arc::from(s));
        Ok(())
    };
    if input.is_empty() {
        push("")?;
    } else if let Some(pattern) = delimiter.strip_prefix('$') {
        let re = cached_regex(pattern)?;
        // As a regex token iterator does: the text before each match, then
        // the rest after the last match unless it is empty.
        let mut last = 0;
        for m in re.find_iter(input) {
            let m = m.map_err(|e| ValueError::new(format!("splitString: {e}")))?;
            push(&input[last..m.start()])?;
            last = m.end();
        }
        if last < input.len() {
            push(&input[last..])?;
        }
    } else if delimiter.is_empty() {
        push("")?;
        for (i, c) in input.char_indices() {
            push(&input[i..i + c.len_utf8()])?;
        }
        push("")?;
    } else {
        for part in input.split(delimiter) {
            push(part)?;
        }
    }
    Ok(parts)
}

/// Compiled regular expressions by pattern: rules call `splitString` with the
/// same few patterns on every shape.
fn cached_regex(pattern: &str) -> Result<Arc<Regex>, ValueError> {
    thread_local! {
        static CACHE: RefCell<HashMap<String, Arc<Regex>>> = RefCell::new(HashMap::new());
    }
    CACHE.with(|cache| {
        if let Some(re) = cache.borrow().get(pattern) {
            return Ok(Arc::clone(re));
        }
        let re = Arc::new(Regex::new(pattern).map_err(|e| {
            ValueError::new(format!(
                "splitString: invalid regular expression {pattern:?}: {e}"
            ))
        })?);
        let mut cache = cache.borrow_mut();
        if cache.len() >= 256 {
            cache.clear();
        }
        cache.insert(pattern.to_string(), Arc::clone(&re));
        Ok(re)
    })
}

pub fn count_fn(args: &[Value]) -> Result<Value, ValueError> {
    let s = str_arg(args, 0, "count")?;
    let m = str_arg(args, 1, "count")?;
    Ok(Value::Float(count(s, m) as f64))
}

pub fn find_fn(args: &[Value]) -> Result<Value, ValueError> {
    let s = str_arg(args, 0, "find")?;
    let m = str_arg(args, 1, "find")?;
    let n = float_arg(args, 2, "find")?;
    Ok(Value::Float(find(s, m, n)))
}

pub fn len_fn(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::Float(char_len(str_arg(args, 0, "len")?) as f64))
}

pub fn substring_fn(args: &[Value]) -> Result<Value, ValueError> {
    let s = str_arg(args, 0, "substring")?;
    let start = float_arg(args, 1, "substring")?;
    let end = float_arg(args, 2, "substring")?;
    Ok(Value::str(substring(s, start, end)))
}

pub fn split_string_fn(args: &[Value]) -> Result<Value, ValueError> {
    let s = str_arg(args, 0, "splitString")?;
    let d = str_arg(args, 1, "splitString")?;
    Ok(Array::row(split_string(s, d)?).into())
}

pub fn find_last_fn(args: &[Value]) -> Result<Value, ValueError> {
    let s = str_arg(args, 0, "findLast")?;
    let m = str_arg(args, 1, "findLast")?;
    Ok(Value::Float(find_last(s, m)))
}

pub fn get_prefix_fn(args: &[Value]) -> Result<Value, ValueError> {
    let s = str_arg(args, 0, "getPrefix")?;
    let m = str_arg(args, 1, "getPrefix")?;
    Ok(Value::str(get_prefix(s, m)))
}

pub fn get_suffix_fn(args: &[Value]) -> Result<Value, ValueError> {
    let s = str_arg(args, 0, "getSuffix")?;
    let m = str_arg(args, 1, "getSuffix")?;
    Ok(Value::str(get_suffix(s, m)))
}

/// `getRange(input, left, right)`: from the end of the first occurrence of
/// `left` to the start of the last occurrence of `right`; empty if they
/// overlap or either is missing.
pub fn get_range_fn(args: &[Value]) -> Result<Value, ValueError> {
    let s = str_arg(args, 0, "getRange")?;
    let l = str_arg(args, 1, "getRange")?;
    let r = str_arg(args, 2, "getRange")?;
    if count(s, l) == 0 || count(s, r) == 0 {
        return Ok(Value::str(""));
    }
    let start = find_first_str(s, l) + char_len(l) as f64;
    Ok(Value::str(substring(s, start, find_last(s, r))))
}

/// `replace(input, old, new)`: every non-overlapping occurrence of `old`,
/// left to right, replaced by `new` (a string, float or bool, as text).
pub fn replace_fn(args: &[Value]) -> Result<Value, ValueError> {
    let s = str_arg(args, 0, "replace")?;
    let old = str_arg(args, 1, "replace")?;
    let new = arg(args, 2, "replace")?;
    if new.is_array() {
        return Err(arg_mismatch("replace", 2, "float, bool or string", new));
    }
    if old.is_empty() || !s.contains(old) {
        return Ok(args[0].clone());
    }
    let mut text = String::new();
    write_value(&mut text, new);
    Ok(Value::from(s.replace(old, &text)))
}

fn file_name_of(path: &str) -> &str {
    path.rfind('/').map_or(path, |i| &path[i + 1..])
}

/// `fileName("assets/obj/a.01.obj")` is `"a.01.obj"`.
pub fn file_name(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::str(file_name_of(str_arg(args, 0, "fileName")?)))
}

/// `fileDirectory("assets/obj/a.01.obj")` is `"assets/obj/"`.
pub fn file_directory(args: &[Value]) -> Result<Value, ValueError> {
    let p = str_arg(args, 0, "fileDirectory")?;
    Ok(Value::str(p.rfind('/').map_or("", |i| &p[..=i])))
}

/// `fileExtension("assets/obj/a.01.obj")` is `"obj"` (empty without a dot).
pub fn file_extension(args: &[Value]) -> Result<Value, ValueError> {
    let n = file_name_of(str_arg(args, 0, "fileExtension")?);
    Ok(Value::str(n.rfind('.').map_or("", |i| &n[i + 1..])))
}

/// `fileBasename("assets/obj/a.01.obj")` is `"a.01"`.
pub fn file_basename(args: &[Value]) -> Result<Value, ValueError> {
    let n = file_name_of(str_arg(args, 0, "fileBasename")?);
    Ok(Value::str(n.rfind('.').map_or(n, |i| &n[..i])))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtins::call;
    use crate::to_text;

    fn s(name: &str, args: &[Value]) -> Value {
        call(name, args).unwrap()
    }
    fn v(x: &str) -> Value {
        Value::str(x)
    }
    fn f(x: f64) -> Value {
        Value::Float(x)
    }

    /// func_count.md, func_find.md, func_len.md, func_substring.md.
    #[test]
    fn builtin_string_examples() {
        assert_eq!(s("count", &[v("cityengine"), v("e")]), f(2.0));
        let long = "cityengine rocks my world; cityengine should rock yours too";
        assert_eq!(s("count", &[v(long), v("cityengine")]), f(2.0));
        let ce = "CE_Zero CE_One CE_Two";
        assert_eq!(s("find", &[v(ce), v("CE"), f(0.0)]), f(0.0));
        assert_eq!(s("find", &[v(ce), v("CE"), f(1.0)]), f(8.0));
        assert_eq!(s("find", &[v(long), v("cityengine"), f(0.0)]), f(0.0));
        assert_eq!(s("find", &[v(long), v("cityengine"), f(1.0)]), f(27.0));
        assert_eq!(s("find", &[v(ce), v("asdf"), f(1.0)]), f(-1.0));
        assert_eq!(s("len", &[v("cityengine")]), f(10.0));
        assert_eq!(s("len", &[v("abc")]), f(3.0));
        let digits = v("0123456789");
        let sub = |a: f64, b: f64| s("substring", &[digits.clone(), f(a), f(b)]);
        assert_eq!(sub(0.0, 5.0), v("01234"));
        assert_eq!(sub(2.0, 5.0), v("234"));
        assert_eq!(sub(-20.0, 5.0), v("01234"));
        assert_eq!(sub(0.0, 20.0), v("0123456789"));
        assert_eq!(sub(5.0, 0.0), v(""));
    }

    #[test]
    fn characters_not_bytes() {
        assert_eq!(s("len", &[v("grüße")]), f(5.0));
        assert_eq!(s("find", &[v("grüße grüße"), v("ß"), f(1.0)]), f(9.0));
        assert_eq!(s("substring", &[v("grüße"), f(2.0), f(4.0)]), v("üß"));
        assert_eq!(s("count", &[v("aaaa"), v("aa")]), f(2.0));
        assert_eq!(s("count", &[v("abc"), v("")]), f(0.0));
        assert_eq!(s("find", &[v("abc"), v("b"), f(-1.0)]), f(-1.0));
    }

    fn split(a: &str, d: &str) -> String {
        to_text(&s("splitString", &[v(a), v(d)]))
    }

    /// func_splitString.md examples.
    #[test]
    fn split_string_examples() {
        assert_eq!(split("a.b.c", "."), "(3)[a,b,c]");
        assert_eq!(split(".b.", "."), "(3)[,b,]");
        assert_eq!(split("a.b\nc.d", "\n"), "(2)[a.b,c.d]");
        assert_eq!(split("a\\b\\c", "\\"), "(3)[a,b,c]");
        assert_eq!(split("abc", ""), "(5)[,a,b,c,]");
        assert_eq!(split("a;b;c", "$;"), "(3)[a,b,c]");
        assert_eq!(split("a.b.c", "$\\."), "(3)[a,b,c]");
        assert_eq!(split("a\t\tb\tc", "$\t+"), "(3)[a,b,c]");
        assert_eq!(split("a b  c", "$\\s+"), "(3)[a,b,c]");
        assert_eq!(split("a$b$c", "$\\$"), "(3)[a,b,c]");
        assert_eq!(split("abc", "$\\B"), "(3)[a,b,c]");
        assert_eq!(split("abacba", "$(?<=a)b(?=a)"), "(2)[a,acba]");
        // func_index.md: parsing a table file
        assert_eq!(
            split("a;b;c\nd;e;f\ng;h;i", "$;|\n"),
            "(9)[a,b,c,d,e,f,g,h,i]"
        );
        // "Parsing files": rows of "a;b\nc;d\n", then the header row
        assert_eq!(split("a;b\nc;d\n", "\n"), "(3)[a;b,c;d,]");
        assert_eq!(split("a;b", ";"), "(2)[a,b]");
        // an empty input gives [""] (changelog 2021.0)
        assert_eq!(split("", ";"), "(1)[]");
        assert_eq!(s("splitString", &[v(""), v(";")]).array_len(), Some(1));
        assert!(call("splitString", &[v("abc"), v("$(")]).is_err());
    }

    /// celib getPrefix / getSuffix / getRange / replace / findFirst / findLast.
    #[test]
    fn utility_string_examples() {
        let rule = v("rule your city with cityengine");
        assert_eq!(s("getPrefix", &[rule.clone(), v("city")]), v("rule your "));
        assert_eq!(
            s("getPrefix", &[v("myTexture.has.prefix.jpg"), v(".")]),
            v("myTexture")
        );
        assert_eq!(s("getSuffix", &[rule.clone(), v("city")]), v("engine"));
        assert_eq!(
            s("getRange", &[rule.clone(), v("y"), v("city")]),
            v("our city with ")
        );
        let tex = v("myTexture.hasName.001.jpg");
        assert_eq!(
            s("getRange", &[tex.clone(), v("hasName."), v(".jpg")]),
            v("001")
        );
        assert_eq!(s("getRange", &[tex, v("."), v(".")]), v("hasName.001"));
        assert_eq!(
            s("getRange", &[v("CityEngine"), v("CityEn"), v("tyEngine")]),
            v("")
        );
        assert_eq!(
            s("replace", &[rule.clone(), v("your city"), v("designs")]),
            v("rule designs with cityengine")
        );
        assert_eq!(
            s("replace", &[v("myTexture.#.jpg"), v("#"), v("1")]),
            v("myTexture.1.jpg")
        );
        assert_eq!(
            s("replace", &[v("myTexture.#.jpg"), v("#"), f(2.0)]),
            v("myTexture.2.jpg")
        );
        assert_eq!(s("findFirst", &[rule.clone(), v("city")]), f(10.0));
        assert_eq!(s("findLast", &[rule, v("city")]), f(20.0));
        // not found
        assert_eq!(s("getPrefix", &[v("abc"), v("x")]), v("abc"));
        assert_eq!(s("getSuffix", &[v("abc"), v("x")]), v("abc"));
        assert_eq!(s("findLast", &[v("abc"), v("x")]), f(-1.0));
        assert_eq!(s("replace", &[v("abc"), v(""), v("x")]), v("abc"));
    }

    /// celib fileBasename / fileDirectory / fileExtension / fileName.
    #[test]
    fn file_path_examples() {
        let p = v("assets/obj/mygeometry.01.obj");
        assert_eq!(s("fileBasename", &[p.clone()]), v("mygeometry.01"));
        assert_eq!(s("fileDirectory", &[p.clone()]), v("assets/obj/"));
        assert_eq!(s("fileExtension", &[p.clone()]), v("obj"));
        assert_eq!(s("fileName", &[p]), v("mygeometry.01.obj"));
        assert_eq!(s("fileDirectory", &[v("a.jpg")]), v(""));
        assert_eq!(s("fileExtension", &[v("dir.x/README")]), v(""));
        assert_eq!(s("fileBasename", &[v("dir.x/README")]), v("README"));
    }
}
