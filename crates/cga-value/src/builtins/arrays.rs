//! Array functions (`size`, `nRows`, `nColumns`, `transpose`, `sum`,
//! `sortIndices`, `sortRowIndices`, `setElems`, `findFirst`) and the
//! utility library's `min`, `max` and `clamp`.

use std::cmp::Ordering;
use std::sync::Arc;

use super::strings::find_first_str;
use super::{arg, arg_mismatch, float_arg};
use crate::error::ValueError;
use crate::ops::{float_relation_gt, float_relation_lt};
use crate::value::{Array, Element, Value};

fn array_arg<'a>(args: &'a [Value], f: &str) -> Result<&'a Value, ValueError> {
    let v = arg(args, 0, f)?;
    if v.is_array() {
        Ok(v)
    } else {
        Err(arg_mismatch(f, 0, "an array", v))
    }
}

pub fn size(args: &[Value]) -> Result<Value, ValueError> {
    let a = array_arg(args, "size")?;
    Ok(Value::Float(a.array_len().unwrap_or(0) as f64))
}

pub fn n_rows(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::Float(match array_arg(args, "nRows")? {
        Value::FloatArray(a) => a.n_rows(),
        Value::BoolArray(a) => a.n_rows(),
        Value::StrArray(a) => a.n_rows(),
        _ => 0,
    } as f64))
}

pub fn n_columns(args: &[Value]) -> Result<Value, ValueError> {
    Ok(Value::Float(match array_arg(args, "nColumns")? {
        Value::FloatArray(a) => a.n_cols(),
        Value::BoolArray(a) => a.n_cols(),
        Value::StrArray(a) => a.n_cols(),
        _ => 0,
    } as f64))
}

pub fn transpose(args: &[Value]) -> Result<Value, ValueError> {
    Ok(match array_arg(args, "transpose")? {
        Value::FloatArray(a) => a.transpose().into(),
        Value::BoolArray(a) => a.transpose().into(),
        Value::StrArray(a) => a.transpose().into(),
        v => v.clone(),
    })
}

/// The sum of a `float[]`, the number of true elements of a `bool[]`, the
/// concatenation of a `string[]`.
pub fn sum(args: &[Value]) -> Result<Value, ValueError> {
    Ok(match array_arg(args, "sum")? {
        Value::FloatArray(a) => Value::Float(a.data.iter().sum()),
        Value::BoolArray(a) => Value::Float(a.data.iter().filter(|b| **b).count() as f64),
        Value::StrArray(a) => Value::from(a.data.concat()),
        v => v.clone(),
    })
}

/// Float order for sorting: NaN after every number, so that sorting is total.
fn cmp_float(a: &f64, b: &f64) -> Ordering {
    a.partial_cmp(b)
        .unwrap_or_else(|| a.is_nan().cmp(&b.is_nan()))
}

fn cmp_str(a: &Arc<str>, b: &Arc<str>) -> Ordering {
    a.as_bytes().cmp(b.as_bytes())
}

/// Indices that sort each row separately (stable), as linear indices.
fn sort_rows<T>(a: &Array<T>, cmp: impl Fn(&T, &T) -> Ordering) -> Value {
    let cols = a.cols;
    let mut out: Vec<f64> = Vec::with_capacity(a.len());
    let mut idx: Vec<usize> = Vec::with_capacity(cols);
    for r in 0..a.n_rows() {
        let row = &a.data[r * cols..(r + 1) * cols];
        idx.clear();
        idx.extend(0..cols);
        idx.sort_by(|&i, &j| cmp(&row[i], &row[j]));
        out.extend(idx.iter().map(|&i| (r * cols + i) as f64));
    }
    Array::new(a.rows, a.cols, out).into()
}

/// `sortIndices(array)`: for each row, the linear indices of its elements in
/// ascending order (duplicates in order of appearance); same dimensions.
pub fn sort_indices(args: &[Value]) -> Result<Value, ValueError> {
    match array_arg(args, "sortIndices")? {
        Value::FloatArray(a) => Ok(sort_rows(a, cmp_float)),
        Value::StrArray(a) => Ok(sort_rows(a, cmp_str)),
        v => Err(arg_mismatch("sortIndices", 0, "float[] or string[]", v)),
    }
}

fn sort_row_order<T>(a: &Array<T>, cmp: impl Fn(&T, &T) -> Ordering) -> Value {
    let cols = a.cols;
    let mut idx: Vec<usize> = (0..a.n_rows()).collect();
    idx.sort_by(|&i, &j| {
        let (ri, rj) = (
            &a.data[i * cols..(i + 1) * cols],
            &a.data[j * cols..(j + 1) * cols],
        );
        ri.iter()
            .zip(rj)
            .map(|(x, y)| cmp(x, y))
            .find(|o| *o != Ordering::Equal)
            .unwrap_or(Ordering::Equal)
    });
    Value::float_row(idx.into_iter().map(|i| i as f64).collect())
}

/// `sortRowIndices(array)`: the row indices in the order that sorts the rows
/// (element by element; duplicate rows in order of appearance).
pub fn sort_row_indices(args: &[Value]) -> Result<Value, ValueError> {
    match array_arg(args, "sortRowIndices")? {
        Value::FloatArray(a) => Ok(sort_row_order(a, cmp_float)),
        Value::StrArray(a) => Ok(sort_row_order(a, cmp_str)),
        v => Err(arg_mismatch("sortRowIndices", 0, "float[] or string[]", v)),
    }
}

/// `setElems(array, indices, values)` / `setElems(array, rows, cols, values)`.
pub fn set_elems(args: &[Value]) -> Result<Value, ValueError> {
    let array = array_arg(args, "setElems")?;
    match args.len() {
        3 => crate::array::set_elems(array, &args[1..2], &args[2]),
        4 => crate::array::set_elems(array, &args[1..3], &args[3]),
        n => Err(ValueError::new(format!(
            "setElems: expected 3 or 4 arguments, got {n}"
        ))),
    }
}

/// `findFirst(array, value)` / `findFirst(floatArray, value, epsilon)`: the
/// linear index of the first equal element (floats: within epsilon), or -1.
/// With two strings it is the utility library's `findFirst(input, match)`.
pub fn find_first(args: &[Value]) -> Result<Value, ValueError> {
    let f = "findFirst";
    let a = arg(args, 0, f)?;
    let v = arg(args, 1, f)?;
    let pos = |p: Option<usize>| Value::Float(p.map_or(-1.0, |i| i as f64));
    match (a, v, args.len()) {
        (Value::Str(s), Value::Str(m), 2) => Ok(Value::Float(find_first_str(s, m))),
        (Value::FloatArray(x), Value::Float(y), 3) => {
            let eps = float_arg(args, 2, f)?;
            Ok(pos(x.data.iter().position(|e| (e - y).abs() <= eps)))
        }
        (Value::FloatArray(_), Value::Float(_), _) => Err(ValueError::new(
            "findFirst: a float array needs an epsilon: findFirst(array, value, epsilon)",
        )),
        (Value::BoolArray(x), Value::Bool(y), 2) => Ok(pos(x.data.iter().position(|e| e == y))),
        (Value::StrArray(x), Value::Str(y), 2) => Ok(pos(x.data.iter().position(|e| e == y))),
        _ => Err(ValueError::new(format!(
            "findFirst: cannot search {} for {}{}",
            a.type_name(),
            v.type_name(),
            if args.len() == 3 {
                " with an epsilon"
            } else {
                ""
            }
        ))),
    }
}

/// Applies a scalar rule to scalars, or element-wise to two or three arrays
/// of the same dimensions (`min`, `max`, `clamp` on `float[]`/`string[]`).
fn elementwise<T: Element>(
    name: &str,
    arrays: &[&Arc<Array<T>>],
    f: impl Fn(&[&T]) -> T,
) -> Result<Value, ValueError> {
    let first = arrays[0];
    if arrays.iter().any(|a| !a.same_dims(first)) {
        return Err(ValueError::new(format!("{name}: array dimensions differ")));
    }
    let mut elems: Vec<&T> = Vec::with_capacity(arrays.len());
    let data = (0..first.len())
        .map(|i| {
            elems.clear();
            elems.extend(arrays.iter().map(|a| &a.data[i]));
            f(&elems)
        })
        .collect();
    Ok(T::wrap_array(Array::new(first.rows, first.cols, data)))
}

// `min`, `max` and `clamp` are CGA code in CityEngine (`case a < b : a
// else : b`), so floats compare as CGA's `<` does (see `ops`).

fn min_f(a: f64, b: f64) -> f64 {
    if float_relation_lt(a, b) {
        a
    } else {
        b
    }
}

fn max_f(a: f64, b: f64) -> f64 {
    if float_relation_gt(a, b) {
        a
    } else {
        b
    }
}

fn clamp_f(x: f64, lo: f64, hi: f64) -> f64 {
    if float_relation_lt(x, lo) {
        lo
    } else if float_relation_gt(x, hi) {
        hi
    } else {
        x
    }
}

fn min_s<'a>(a: &'a Arc<str>, b: &'a Arc<str>) -> &'a Arc<str> {
    if a.as_bytes() < b.as_bytes() {
        a
    } else {
        b
    }
}

fn max_s<'a>(a: &'a Arc<str>, b: &'a Arc<str>) -> &'a Arc<str> {
    if a.as_bytes() > b.as_bytes() {
        a
    } else {
        b
    }
}

fn clamp_s<'a>(x: &'a Arc<str>, lo: &'a Arc<str>, hi: &'a Arc<str>) -> &'a Arc<str> {
    if x.as_bytes() < lo.as_bytes() {
        lo
    } else if x.as_bytes() > hi.as_bytes() {
        hi
    } else {
        x
    }
}

fn same_type_error(name: &str, args: &[Value]) -> ValueError {
    let types: Vec<&str> = args.iter().map(Value::type_name).collect();
    ValueError::new(format!(
        "{name}: arguments must all be float, string, float[] or string[] of one type, got {}",
        types.join(", ")
    ))
}

pub fn min(args: &[Value]) -> Result<Value, ValueError> {
    use Value as V;
    match (arg(args, 0, "min")?, arg(args, 1, "min")?) {
        (V::Float(a), V::Float(b)) => Ok(V::Float(min_f(*a, *b))),
        (V::Str(a), V::Str(b)) => Ok(V::Str(min_s(a, b).clone())),
        (V::FloatArray(a), V::FloatArray(b)) => {
            elementwise("min", &[a, b], |e| min_f(*e[0], *e[1]))
        }
        (V::StrArray(a), V::StrArray(b)) => {
            elementwise("min", &[a, b], |e| min_s(e[0], e[1]).clone())
        }
        _ => Err(same_type_error("min", args)),
    }
}

pub fn max(args: &[Value]) -> Result<Value, ValueError> {
    use Value as V;
    match (arg(args, 0, "max")?, arg(args, 1, "max")?) {
        (V::Float(a), V::Float(b)) => Ok(V::Float(max_f(*a, *b))),
        (V::Str(a), V::Str(b)) => Ok(V::Str(max_s(a, b).clone())),
        (V::FloatArray(a), V::FloatArray(b)) => {
            elementwise("max", &[a, b], |e| max_f(*e[0], *e[1]))
        }
        (V::StrArray(a), V::StrArray(b)) => {
            elementwise("max", &[a, b], |e| max_s(e[0], e[1]).clone())
        }
        _ => Err(same_type_error("max", args)),
    }
}

pub fn clamp(args: &[Value]) -> Result<Value, ValueError> {
    use Value as V;
    let f = "clamp";
    match (arg(args, 0, f)?, arg(args, 1, f)?, arg(args, 2, f)?) {
        (V::Float(x), V::Float(lo), V::Float(hi)) => Ok(V::Float(clamp_f(*x, *lo, *hi))),
        (V::Str(x), V::Str(lo), V::Str(hi)) => Ok(V::Str(clamp_s(x, lo, hi).clone())),
        (V::FloatArray(x), V::FloatArray(lo), V::FloatArray(hi)) => {
            elementwise(f, &[x, lo, hi], |e| clamp_f(*e[0], *e[1], *e[2]))
        }
        (V::StrArray(x), V::StrArray(lo), V::StrArray(hi)) => {
            elementwise(f, &[x, lo, hi], |e| clamp_s(e[0], e[1], e[2]).clone())
        }
        _ => Err(same_type_error(f, args)),
    }
}

#[cfg(test)]
mod tests {
    use crate::array::{build_array, index, range};
    use crate::builtins::call;
    use crate::ops::{binary, BinaryOp};
    use crate::to_text;
    use crate::value::{Array, Value};

    fn c(name: &str, args: &[Value]) -> Value {
        call(name, args).unwrap()
    }
    fn t(v: &Value) -> String {
        to_text(v)
    }
    fn f(x: f64) -> Value {
        Value::Float(x)
    }
    fn floats(rows: usize, cols: usize, d: &[f64]) -> Value {
        Array::new(rows, cols, d.to_vec()).into()
    }
    fn strs(rows: usize, cols: usize, d: &[&str]) -> Value {
        Array::new(
            rows,
            cols,
            d.iter().map(|s| std::sync::Arc::from(*s)).collect(),
        )
        .into()
    }

    /// func_size.md, func_nRows.md, func_nColumns.md.
    #[test]
    fn dimensions() {
        let a = range(1.0, None, 4.0).unwrap();
        let b = floats(2, 2, &[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(c("size", &[a]), f(4.0));
        assert_eq!(c("size", &[b]), f(4.0));
        let m = floats(2, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(c("nRows", &[m.clone()]), f(2.0));
        assert_eq!(c("nColumns", &[m]), f(3.0));
        let empty = c("floatArray", &[]);
        assert_eq!(c("size", &[empty.clone()]), f(0.0));
        assert_eq!(c("nRows", &[empty.clone()]), f(0.0));
        assert_eq!(c("nColumns", &[empty]), f(0.0));
        assert!(call("size", &[f(1.0)]).is_err());
    }

    /// func_transpose.md.
    #[test]
    fn transpose_examples() {
        let a = strs(3, 2, &["a", "b", "c", "d", "e", "f"]);
        assert_eq!(
            c("transpose", &[a]),
            strs(2, 3, &["a", "c", "e", "b", "d", "f"])
        );
        // zipping
        let a = Value::float_row(vec![1.0; 3]);
        let b = Value::float_row(vec![2.0; 3]);
        let ab = build_array(&[vec![a.clone()], vec![b.clone()]]).unwrap();
        let zipped = c("transpose", &[ab]);
        assert_eq!(zipped, floats(3, 2, &[1.0, 2.0, 1.0, 2.0, 1.0, 2.0]));
        let flat = index(&zipped, &[range(0.0, None, 5.0).unwrap()]).unwrap();
        assert_eq!(t(&flat), "(6)[1,2,1,2,1,2]");
        let side_by_side =
            build_array(&[vec![c("transpose", &[a]), c("transpose", &[b])]]).unwrap();
        assert_eq!(side_by_side, zipped);
    }

    /// func_sum.md, including the cumsum example written with ranges.
    #[test]
    fn sum_examples() {
        assert_eq!(c("sum", &[Value::float_row(vec![1.0, 2.0, 3.0])]), f(6.0));
        assert_eq!(
            c("sum", &[Value::bool_row(vec![true, false, true])]),
            f(2.0)
        );
        assert_eq!(
            c("sum", &[Value::str_row(&["a", "b", "c"])]),
            Value::str("abc")
        );
        // cumsum(array) = [cumsum(array[0:size-2]), sum(array)]
        fn cumsum(a: &Value) -> Value {
            let n = a.array_len().unwrap();
            if n < 2 {
                return build_array(&[vec![call("sum", &[a.clone()]).unwrap()]]).unwrap();
            }
            let head = index(a, &[range(0.0, None, n as f64 - 2.0).unwrap()]).unwrap();
            build_array(&[vec![cumsum(&head), call("sum", &[a.clone()]).unwrap()]]).unwrap()
        }
        assert_eq!(
            t(&cumsum(&range(1.0, None, 5.0).unwrap())),
            "(5)[1,3,6,10,15]"
        );
        assert_eq!(
            t(&cumsum(&Value::str_row(&["a", "b", "c", "d", "e"]))),
            "(5)[a,ab,abc,abcd,abcde]"
        );
        assert_eq!(
            t(&cumsum(&Value::bool_row(vec![
                false, true, true, false, true
            ]))),
            "(5)[0,1,2,2,3]"
        );
    }

    /// func_sortIndices.md.
    #[test]
    fn sort_indices_examples() {
        let a = Value::str_row(&["c", "b", "d", "a"]);
        let s = c("sortIndices", &[a.clone()]);
        assert_eq!(t(&s), "(4)[3,1,0,2]");
        assert_eq!(t(&index(&a, &[s]).unwrap()), "(4)[a,b,c,d]");
        let a = Value::float_row(vec![2.0, 1.0, 3.0, 3.0, 1.0]);
        let s = c("sortIndices", &[a.clone()]);
        assert_eq!(t(&s), "(5)[1,4,0,2,3]");
        assert_eq!(t(&index(&a, &[s]).unwrap()), "(5)[1,1,2,3,3]");
        let m = strs(3, 3, &["e", "c", "d", "b", "a", "c", "d", "a", "d"]);
        let s = c("sortIndices", &[m.clone()]);
        assert_eq!(
            s,
            floats(3, 3, &[1.0, 2.0, 0.0, 4.0, 3.0, 5.0, 7.0, 6.0, 8.0])
        );
        assert_eq!(
            index(&m, &[s]).unwrap(),
            strs(3, 3, &["c", "d", "e", "a", "b", "c", "a", "d", "d"])
        );
        // sortAsc / sortDesc / findMin / findMax examples
        let a = Value::str_row(&["a", "c", "b"]);
        let asc = index(&a, &[c("sortIndices", &[a.clone()])]).unwrap();
        assert_eq!(t(&asc), "(3)[a,b,c]");
        let desc = index(&asc, &[range(2.0, Some(-1.0), 0.0).unwrap()]).unwrap();
        assert_eq!(t(&desc), "(3)[c,b,a]");
        let a = Value::float_row(vec![1.0, 4.0, -1.0, 9.0]);
        let order = c("sortIndices", &[a.clone()]);
        let min = index(&a, &[index(&order, &[f(0.0)]).unwrap()]).unwrap();
        let max = index(&a, &[index(&order, &[f(3.0)]).unwrap()]).unwrap();
        assert_eq!((min, max), (f(-1.0), f(9.0)));
        assert!(call("sortIndices", &[Value::bool_row(vec![true])]).is_err());
    }

    /// func_sortRowIndices.md.
    #[test]
    fn sort_row_indices_examples() {
        let a = floats(4, 3, &[4., 0., 1., 2., 1., 9., 1., 3., 0., 2., 1., 0.]);
        let s = c("sortRowIndices", &[a.clone()]);
        assert_eq!(t(&s), "(4)[2,3,1,0]");
        let all_cols = range(0.0, None, 2.0).unwrap();
        assert_eq!(
            index(&a, &[s, all_cols.clone()]).unwrap(),
            floats(4, 3, &[1., 3., 0., 2., 1., 0., 2., 1., 9., 4., 0., 1.])
        );
        let sort_rows = |precedence: Value| {
            let rows = range(0.0, None, 3.0).unwrap();
            let keys = index(&a, &[rows, precedence]).unwrap();
            index(&a, &[c("sortRowIndices", &[keys]), all_cols.clone()]).unwrap()
        };
        assert_eq!(
            sort_rows(f(1.0)),
            floats(4, 3, &[4., 0., 1., 2., 1., 9., 2., 1., 0., 1., 3., 0.])
        );
        assert_eq!(
            sort_rows(Value::float_row(vec![1.0, 0.0, 2.0])),
            floats(4, 3, &[4., 0., 1., 2., 1., 0., 2., 1., 9., 1., 3., 0.])
        );
    }

    /// func_findFirst.md and the findAll/getValues examples of func_abs.md.
    #[test]
    fn find_first_examples() {
        let a1 = Value::float_row(vec![1.0, 2.0, 3.0, 4.0]);
        let a2 = floats(2, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(c("findFirst", &[a1.clone(), f(2.0), f(0.0)]), f(1.0));
        assert_eq!(index(&a1, &[f(1.0)]).unwrap(), f(2.0));
        assert_eq!(c("findFirst", &[a2.clone(), f(4.0), f(0.0)]), f(3.0));
        assert_eq!(index(&a2, &[f(3.0)]).unwrap(), f(4.0));
        let edges = Value::float_row(vec![6.0, 8.1, 6.0, 8.1]);
        assert_eq!(c("findFirst", &[edges, f(8.0), f(0.5)]), f(1.0));
        assert_eq!(c("findFirst", &[a1.clone(), f(7.0), f(0.5)]), f(-1.0));
        assert!(call("findFirst", &[a1, f(2.0)]).is_err());
        assert_eq!(
            c("findFirst", &[Value::str_row(&["x", "y"]), Value::str("y")]),
            f(1.0)
        );
        assert_eq!(
            c(
                "findFirst",
                &[Value::bool_row(vec![false, false]), Value::Bool(true)]
            ),
            f(-1.0)
        );

        let sequence = range(0.0, Some(0.1), 2.0).unwrap();
        assert_eq!(sequence.array_len(), Some(21));
        let first = c("findFirst", &[sequence.clone(), f(1.0), f(0.15)]);
        assert_eq!(first, f(9.0));
        assert_eq!(t(&index(&sequence, &[first]).unwrap()), "0.9");
        // findAll(array, value, epsilon) = [0 : size(array)-1][abs(array .- value) .<= epsilon]
        let diff = binary(BinaryOp::Sub, true, &sequence, &f(1.0)).unwrap();
        let close = binary(BinaryOp::Le, true, &c("abs", &[diff]), &f(0.15)).unwrap();
        let all = range(0.0, None, 20.0).unwrap();
        let found = index(&all, &[close.clone()]).unwrap();
        assert_eq!(t(&found), "(3)[9,10,11]");
        assert_eq!(t(&index(&sequence, &[found]).unwrap()), "(3)[0.9,1,1.1]");
        assert_eq!(t(&index(&sequence, &[close]).unwrap()), "(3)[0.9,1,1.1]");
    }

    /// celib/min.md, max.md, clamp.md.
    #[test]
    fn min_max_clamp() {
        assert_eq!(c("min", &[f(10.0), f(-10.0)]), f(-10.0));
        assert_eq!(
            c("min", &[Value::str("abc"), Value::str("def")]),
            Value::str("abc")
        );
        assert_eq!(c("max", &[f(10.0), f(-10.0)]), f(10.0));
        assert_eq!(
            c("max", &[Value::str("abc"), Value::str("def")]),
            Value::str("def")
        );
        assert_eq!(c("clamp", &[f(1.5), f(0.0), f(1.0)]), f(1.0));
        assert_eq!(c("clamp", &[f(-11.0), f(-10.0), f(10.0)]), f(-10.0));
        assert_eq!(c("clamp", &[f(0.5), f(0.0), f(1.0)]), f(0.5));
        let x = Value::float_row(vec![1.0, 5.0, -3.0]);
        let y = Value::float_row(vec![2.0, 2.0, 2.0]);
        assert_eq!(t(&c("min", &[x.clone(), y.clone()])), "(3)[1,2,-3]");
        assert_eq!(t(&c("max", &[x.clone(), y.clone()])), "(3)[2,5,2]");
        let lo = Value::float_row(vec![0.0; 3]);
        assert_eq!(t(&c("clamp", &[x, lo, y])), "(3)[1,2,0]");
        assert!(call("min", &[f(1.0), Value::str("a")]).is_err());
        assert!(call(
            "min",
            &[
                Value::float_row(vec![1.0]),
                Value::float_row(vec![1.0, 2.0])
            ]
        )
        .is_err());
    }
}
