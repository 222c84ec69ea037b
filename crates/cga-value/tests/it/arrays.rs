//! Examples of func_array.md, func_colon.md, func_index.md and func_setElems.md.

#![allow(clippy::cloned_ref_to_slice_refs)]

use crate::common::{assert_cga, lit};
use cga_value::builtins::call;
use cga_value::{binary, build_array, index, range, set_elems, to_text, BinaryOp, Value};

fn f(x: f64) -> Value {
    Value::Float(x)
}

fn seq(base: f64, limit: f64) -> Value {
    range(base, None, limit).unwrap()
}

/// func_array.md: 1D and 2D initialization with concatenation.
#[test]
fn array_initialization() {
    let a = build_array(&[vec![Value::str("B"), Value::str("C"), Value::str("D")]]).unwrap();
    assert_eq!(to_text(&a), "(3)[B,C,D]");
    let b = build_array(&[vec![Value::str("A"), a, Value::str("E")]]).unwrap();
    assert_eq!(to_text(&b), "(5)[A,B,C,D,E]");

    let a = build_array(&[vec![f(-1.0)], vec![f(-2.0)]]).unwrap();
    assert_eq!(to_text(&a), "(2x1)\n   -1\n   -2");
    let b = build_array(&[vec![seq(0.0, 2.0)], vec![f(3.0), f(3.0), f(3.0)]]).unwrap();
    assert_eq!(to_text(&b), "(2x3)\n   0   1   2\n   3   3   3");
    let c = build_array(&[vec![a.clone(), b.clone()], vec![b, a]]).unwrap();
    assert_eq!(
        to_text(&c),
        "(4x4)\n   -1   0   1    2\n   -2   3   3    3\n    0   1   2   -1\n    3   3   3   -2"
    );
}

#[test]
fn array_initialization_rules() {
    // empty arrays add nothing: [primes, a[0]] with primes = floatArray
    let empty = call("floatArray", &[]).unwrap();
    let r = build_array(&[vec![empty.clone(), f(2.0)]]).unwrap();
    assert_cga(&r, "[2]");
    let r = build_array(&[vec![empty.clone()]]).unwrap();
    assert_eq!(to_text(&r), "(0)[]");
    let r = build_array(&[vec![empty.clone()], vec![f(1.0), f(2.0)]]).unwrap();
    assert_cga(&r, "[1,2]");
    // a string array and an empty string literal (a fixed CityEngine crash)
    let r = build_array(&[vec![Value::str_row(&["a"]), Value::str("")]]).unwrap();
    assert_eq!(to_text(&r), "(2)[a,]");
    // types cannot be mixed
    let e = build_array(&[vec![f(1.0), Value::str("a")]]).unwrap_err();
    assert!(e.message.contains("float"), "{e}");
    assert!(build_array(&[vec![Value::Bool(true), f(1.0)]]).is_err());
    assert!(build_array(&[vec![empty, Value::str("a")]]).is_err());
    // shapes must fit
    assert!(build_array(&[vec![f(1.0), f(2.0)], vec![f(3.0)]]).is_err());
    let col = lit("[1;2]");
    assert!(build_array(&[vec![col, f(3.0)]]).is_err());
    assert!(build_array(&[]).is_err());
    assert!(build_array(&[vec![]]).is_err());
    // the size limit
    let big = range(1.0, None, 60000.0).unwrap();
    let e = build_array(&[vec![big.clone(), big]]).unwrap_err();
    assert!(e.message.contains("100000"), "{e}");
}

/// func_array.md: the Fibonacci example.
#[test]
fn fibonacci() {
    fn fib(n: usize) -> Value {
        if n <= 2 {
            return range(0.0, None, n as f64 - 1.0).unwrap();
        }
        let mut a = lit("[0,1]");
        while a.array_len().unwrap() < n {
            let k = a.array_len().unwrap() as f64;
            let last2 = index(&a, &[f(k - 2.0)]).unwrap();
            let last1 = index(&a, &[f(k - 1.0)]).unwrap();
            let next = binary(BinaryOp::Add, false, &last2, &last1).unwrap();
            a = build_array(&[vec![a, next]]).unwrap();
        }
        a
    }
    assert_eq!(to_text(&fib(10)), "(10)[0,1,1,2,3,5,8,13,21,34]");
}

/// func_colon.md.
#[test]
fn ranges() {
    let r = |b: f64, s: Option<f64>, l: f64| to_text(&range(b, s, l).unwrap());
    assert_eq!(r(2.0, None, 4.0), "(3)[2,3,4]");
    assert_eq!(r(0.5, None, 3.0), "(3)[0.5,1.5,2.5]");
    assert_eq!(r(4.0, None, 2.0), "(0)[]");
    assert_eq!(r(1.0, Some(0.5), 3.0), "(5)[1,1.5,2,2.5,3]");
    assert_eq!(r(4.0, Some(-1.0), 2.0), "(3)[4,3,2]");
    assert_eq!(r(1.0, Some(-0.5), 2.0), "(0)[]");
    assert_eq!(r(1.0, Some(-0.5), 1.0), "(1)[1]");
    assert_eq!(r(1.0, Some(0.0), 1.0), "(0)[]");
    // floating point imprecision
    let a = range(0.0, Some(0.15), 0.5).unwrap();
    assert_eq!(to_text(&a), "(4)[0,0.15,0.3,0.45]");
    let a3 = index(&a, &[f(3.0)]).unwrap();
    assert_eq!(
        binary(BinaryOp::Eq, false, &a3, &f(0.45)).unwrap(),
        Value::Bool(false)
    );
    assert!((a3.as_float().unwrap() - 0.45).abs() < 1e-10);
    // limits
    assert!(range(0.0, Some(1e-9), 1.0).is_err());
    assert!(range(0.0, None, f64::INFINITY).is_err());
    assert_eq!(range(0.0, None, f64::NAN).unwrap().array_len(), Some(0));
    assert_eq!(
        range(1.0, None, 100000.0).unwrap().array_len(),
        Some(100000)
    );
    assert!(range(1.0, None, 100001.0).is_err());
}

fn array() -> Value {
    lit("[1,2,3,4]")
}

fn array2d() -> Value {
    lit("[1,2,3;4,5,6;7,8,9]")
}

fn idx(a: &Value, i: &str) -> Value {
    index(a, &[lit(i)]).unwrap()
}

fn idx2(a: &Value, r: &Value, c: &Value) -> Value {
    index(a, &[r.clone(), c.clone()]).unwrap()
}

/// func_index.md: index values and index arrays.
#[test]
fn indexing() {
    assert_eq!(idx(&array(), "0"), f(1.0));
    assert_eq!(idx(&array(), "3"), f(4.0));
    assert_eq!(idx2(&array2d(), &f(1.0), &f(1.0)), f(5.0));
    assert_cga(&idx(&array(), "[0,2]"), "[1,3]");
    assert_cga(&idx(&array(), "[1,1]"), "[2,2]");
    assert_cga(
        &index(&array(), &[range(3.0, Some(-1.0), 1.0).unwrap()]).unwrap(),
        "[4,3,2]",
    );
    assert_cga(&idx(&array(), "[0,1;2,3]"), "[1,2;3,4]");
    assert_cga(&idx2(&array2d(), &f(1.0), &lit("[0,2]")), "[4,6]");
    assert_cga(&idx2(&array2d(), &lit("[0,0,1]"), &f(2.0)), "[3;3;6]");
    assert_cga(
        &idx2(&array2d(), &seq(0.0, 2.0), &lit("[0,2]")),
        "[1,3;4,6;7,9]",
    );
    // arrayTypes.md
    assert_eq!(idx(&lit("[1,2,3]"), "1"), f(2.0));
    assert_eq!(idx2(&lit("[1,2;3,4]"), &f(1.0), &f(0.0)), f(3.0));
}

/// func_index.md: logical indexing.
#[test]
fn logical_indexing() {
    let a = array();
    assert_cga(&idx(&a, "[true,false,true]"), "[1,3]");
    let gt2 = binary(BinaryOp::Gt, true, &a, &f(2.0)).unwrap();
    assert_cga(&index(&a, &[gt2]).unwrap(), "[3,4]");
    let gt1 = binary(BinaryOp::Gt, true, &a, &f(1.0)).unwrap();
    let le3 = binary(BinaryOp::Le, true, &a, &f(3.0)).unwrap();
    let both = binary(BinaryOp::And, true, &gt1, &le3).unwrap();
    assert_cga(&index(&a, &[both]).unwrap(), "[2,3]");
    assert_cga(
        &idx2(&array2d(), &lit("[false,true,true]"), &f(0.0)),
        "[4;7]",
    );
    // logical indexing is always linear
    assert_cga(&idx(&a, "[true,false;true,false]"), "[1,3]");
}

/// func_index.md: invalid and linear indexing.
#[test]
fn invalid_and_linear_indexing() {
    assert_eq!(idx(&array(), "-1"), f(0.0));
    assert_cga(&idx(&array(), "[false,false,true,true,true]"), "[3,4,0]");
    let r = idx2(&array2d(), &lit("[2,3]"), &range(-1.0, None, 1.0).unwrap());
    assert_cga(&r, "[0,7,8;0,0,0]");
    assert_eq!(idx(&array2d(), "3"), f(4.0));
    // The page shows [0,1,...,9] here, which is not this array2d; the
    // flattening itself is what the example is about.
    let all = index(&array2d(), &[seq(0.0, 8.0)]).unwrap();
    assert_cga(&all, "[1,2,3,4,5,6,7,8,9]");
    assert_cga(&idx(&array2d(), "[0;3;6]"), "[1;4;7]");
    assert_cga(&idx2(&array2d(), &f(0.0), &lit("[0,1;2,3]")), "[1,2,3,0]");
    // defaults by type
    assert_eq!(idx(&lit("[true]"), "5"), Value::Bool(false));
    assert_eq!(idx(&lit("[\"a\"]"), "5"), Value::str(""));
    assert_eq!(idx2(&lit("[\"a\"]"), &f(0.0), &f(-1.0)), Value::str(""));
    // errors are values
    assert!(index(&f(1.0), &[f(0.0)]).is_err());
    assert!(index(&array(), &[Value::str("0")]).is_err());
    assert!(index(&array(), &[]).is_err());
    assert!(index(&array(), &[f(0.0), f(0.0), f(0.0)]).is_err());
}

/// func_index.md: indexing by 2D arrays, out of bounds, prime numbers,
/// and the parsed table.
#[test]
fn index_examples() {
    let a = lit("[\"_\",\"d\",\"i\",\"a\",\"g\"]");
    let b = lit("[1,0,0,0;0,2,0,0;0,0,3,0;0,0,0,4]");
    let c = index(&a, &[b]).unwrap();
    assert_eq!(
        to_text(&c),
        "(4x4)\n   d   _   _   _\n   _   i   _   _\n   _   _   a   _\n   _   _   _   g"
    );

    // zeros(elems) = floatArray[1:elems]; ones(rows,cols) = floatArray[1:rows,1:cols] .+ 1
    let empty = call("floatArray", &[]).unwrap();
    let zeros = index(&empty, &[seq(1.0, 4.0)]).unwrap();
    assert_cga(&zeros, "[0,0,0,0]");
    let ones = index(&empty, &[seq(1.0, 2.0), seq(1.0, 3.0)]).unwrap();
    let ones = binary(BinaryOp::Add, true, &ones, &f(1.0)).unwrap();
    assert_cga(&ones, "[1,1,1;1,1,1]");

    fn find_primes(max: f64) -> Value {
        if max <= 1.0 {
            return call("floatArray", &[]).unwrap();
        }
        let limit = max.sqrt();
        let mut a = range(2.0, None, max).unwrap();
        let mut primes = call("floatArray", &[]).unwrap();
        loop {
            let a0 = index(&a, &[Value::Float(0.0)]).unwrap();
            if a0.as_float().unwrap() > limit {
                return build_array(&[vec![primes, a]]).unwrap();
            }
            let rem = binary(BinaryOp::Rem, true, &a, &a0).unwrap();
            let keep = binary(BinaryOp::Ne, true, &rem, &Value::Float(0.0)).unwrap();
            a = index(&a, &[keep]).unwrap();
            primes = build_array(&[vec![primes, a0]]).unwrap();
        }
    }
    assert_eq!(to_text(&find_primes(20.0)), "(8)[2,3,5,7,11,13,17,19]");

    let cells = call(
        "splitString",
        &[Value::str("a;b;c\nd;e;f\ng;h;i"), Value::str("$;|\n")],
    )
    .unwrap();
    let indexes = range(0.0, Some(3.0), 8.0).unwrap();
    assert_eq!(to_text(&indexes), "(3)[0,3,6]");
    assert_eq!(to_text(&index(&cells, &[indexes]).unwrap()), "(3)[a,d,g]");
    let table = lit("[\"a\",\"b\",\"c\";\"d\",\"e\",\"f\";\"g\",\"h\",\"i\"]");
    let first_col = index(&table, &[seq(0.0, 2.0), f(0.0)]).unwrap();
    assert_cga(&first_col, "[\"a\";\"d\";\"g\"]");
}

fn set(a: &Value, idx: &[Value], v: &str) -> Value {
    set_elems(a, idx, &lit(v)).unwrap()
}

/// func_setElems.md.
#[test]
fn set_elems_examples() {
    let a1 = lit("[0,0,0,0,0,0]");
    assert_cga(&set(&a1, &[f(2.0)], "1"), "[0,0,1,0,0,0]");
    assert_cga(&set(&a1, &[seq(1.0, 4.0)], "1"), "[0,1,1,1,1,0]");
    assert_cga(&set(&a1, &[lit("[1,3,5]")], "[1,2,3]"), "[0,1,0,2,0,3]");
    assert_cga(&set(&a1, &[lit("[5,1,3]")], "[1,2,3]"), "[0,2,0,3,0,1]");
    assert_cga(&set(&a1, &[lit("[1,1,1]")], "[1,2,3]"), "[0,3,0,0,0,0]");

    let a2 = lit("[0,0,0;0,0,0;0,0,0]");
    assert_cga(&set(&a2, &[f(1.0), f(1.0)], "5"), "[0,0,0;0,5,0;0,0,0]");
    assert_cga(
        &set(&a2, &[lit("[0,2]"), seq(0.0, 2.0)], "1"),
        "[1,1,1;0,0,0;1,1,1]",
    );
    assert_cga(
        &set(&a2, &[lit("[1,2]"), lit("[0,2]")], "[1,2;3,4]"),
        "[0,0,0;1,0,2;3,0,4]",
    );
    assert_cga(
        &set(&a2, &[lit("[2,1]"), lit("[2,0]")], "[1,2;3,4]"),
        "[0,0,0;4,0,3;2,0,1]",
    );
    assert_cga(
        &set(&a2, &[lit("[1,1]"), lit("[0,2]")], "[1,2;3,4]"),
        "[0,0,0;3,0,4;0,0,0]",
    );

    let sequence = seq(1.0, 7.0);
    let gt4 = binary(BinaryOp::Gt, true, &sequence, &f(4.0)).unwrap();
    assert_cga(&set(&sequence, &[gt4.clone()], "4"), "[1,2,3,4,4,4,4]");
    assert_cga(&set(&sequence, &[gt4], "[3,2,1]"), "[1,2,3,4,3,2,1]");

    let small = lit("[1,1]");
    assert_cga(&set(&small, &[f(3.0)], "5"), "[1,1,0,5]");
    assert_cga(&set(&small, &[f(2.0), f(2.0)], "5"), "[1,1,0;0,0,0;0,0,5]");
    // negative indices are skipped
    assert_cga(&set(&small, &[lit("[-1,0]")], "[7,8]"), "[8,1]");
}

#[test]
fn set_elems_function_examples() {
    // enumerate(array, value) = setElems(floatArray, found, [1:sum(found)])
    let arr = lit("[\"a\",\"c\",\"b\",\"a\",\"d\",\"a\"]");
    let found = binary(BinaryOp::Eq, true, &arr, &Value::str("a")).unwrap();
    let n = call("sum", &[found.clone()]).unwrap().as_float().unwrap();
    let empty = call("floatArray", &[]).unwrap();
    let e = call("setElems", &[empty.clone(), found, seq(1.0, n)]).unwrap();
    assert_cga(&e, "[1,0,0,2,0,3]");

    // diag(n) = setElems(floatArray[1:n,1:n], [0:n+1:n*n-1], 1)
    let zeros = index(&empty, &[seq(1.0, 3.0), seq(1.0, 3.0)]).unwrap();
    let diag = call(
        "setElems",
        &[zeros, range(0.0, Some(4.0), 8.0).unwrap(), f(1.0)],
    )
    .unwrap();
    assert_cga(&diag, "[1,0,0;0,1,0;0,0,1]");

    // reshape(array, rows, cols) = setElems(floatArray[1:rows,1:cols], [0:rows*cols-1], array)
    let zeros = index(&empty, &[seq(1.0, 3.0), seq(1.0, 2.0)]).unwrap();
    let reshaped = call("setElems", &[zeros, seq(0.0, 5.0), lit("[1,2,3;4,5,6]")]).unwrap();
    assert_cga(&reshaped, "[1,2;3,4;5,6]");
}

#[test]
fn set_elems_errors() {
    let a = lit("[1,2,3]");
    // values of the wrong type or count
    assert!(set_elems(&a, &[f(0.0)], &Value::str("x")).is_err());
    assert!(set_elems(&a, &[lit("[0,1]")], &lit("[1,2,3]")).is_err());
    assert!(set_elems(&a, &[lit("[0,1]"), lit("[0]")], &lit("[1,2,3]")).is_err());
    assert!(set_elems(&f(1.0), &[f(0.0)], &f(1.0)).is_err());
    // growing past the size limit
    assert!(set_elems(&a, &[f(200000.0)], &f(1.0)).is_err());
    assert!(set_elems(&a, &[f(1000.0), f(1000.0)], &f(1.0)).is_err());
    // a linear index past the end of a 2D array adds rows
    let m = lit("[1,2;3,4]");
    assert_cga(&set_elems(&m, &[f(5.0)], &f(9.0)).unwrap(), "[1,2;3,4;0,9]");
}
