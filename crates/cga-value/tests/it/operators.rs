//! The operator examples of simpleTypes.md and arrayTypes.md.

#![allow(clippy::cloned_ref_to_slice_refs)]

use crate::common::{assert_cga, lit};
use cga_value::{binary, to_text, unary, BinaryOp, UnaryOp, Value};

fn op(a: &str, op: BinaryOp, b: &str) -> Value {
    binary(op, false, &lit(a), &lit(b)).unwrap()
}

fn dot(a: &str, op: BinaryOp, b: &str) -> Value {
    binary(op, true, &lit(a), &lit(b)).unwrap()
}

use BinaryOp::*;

#[test]
fn arithmetic_on_floats() {
    assert_eq!(op("3", Add, "4"), Value::Float(7.0));
    assert_eq!(op("3", Sub, "4"), Value::Float(-1.0));
    assert_eq!(op("3", Mul, "4"), Value::Float(12.0));
    assert_eq!(op("3", Div, "4"), Value::Float(0.75));
    assert_eq!(op("1", Div, "0"), Value::Float(f64::INFINITY));
    // `%` is C's fmod: the sign of the dividend
    assert_eq!(op("7", Rem, "3"), Value::Float(1.0));
    assert_eq!(op("-7", Rem, "3"), Value::Float(-1.0));
    assert_eq!(op("7", Rem, "-3"), Value::Float(1.0));
    assert_eq!(to_text(&op("5.5", Rem, "2")), "1.5");
    assert_eq!(
        unary(UnaryOp::Neg, false, &lit("2")).unwrap(),
        Value::Float(-2.0)
    );
    assert_eq!(
        unary(UnaryOp::Plus, false, &lit("2")).unwrap(),
        Value::Float(2.0)
    );
    assert!(binary(Sub, false, &lit("\"a\""), &lit("1")).is_err());
    assert!(binary(Add, false, &lit("true"), &lit("1")).is_err());
    assert!(binary(Add, false, &lit("[1,2]"), &lit("1")).is_err());
    assert!(unary(UnaryOp::Neg, false, &lit("[1,2]")).is_err());
    assert!(unary(UnaryOp::Not, false, &lit("1")).is_err());
}

#[test]
fn string_concatenation() {
    assert_eq!(op("\"City\"", Add, "\"Engine\""), Value::str("CityEngine"));
    assert_eq!(op("\"Rule: \"", Add, "1"), Value::str("Rule: 1"));
    assert_eq!(op("1", Add, "\"th Rule\""), Value::str("1th Rule"));
    assert_eq!(op("\"a\"", Add, "1"), Value::str("a1"));
    assert_eq!(op("\"a\"", Add, "0.5"), Value::str("a0.5"));
    assert_eq!(op("\"Result: \"", Add, "true"), Value::str("Result: true"));
    assert_eq!(
        op("true", Add, "\" is the result\""),
        Value::str("true is the result")
    );
    // with arrays (arrayTypes.md)
    assert_eq!(
        op("\"array: \"", Add, "[\"element\"]"),
        Value::str("array: (1)[element]")
    );
    assert_eq!(
        op("[\"element\"]", Add, "\" is an array\""),
        Value::str("(1)[element] is an array")
    );
    assert_eq!(
        op("\"array:\n\"", Add, "[1,2;3,4]"),
        Value::str("array:\n(2x2)\n   1   2\n   3   4")
    );
    assert_eq!(
        op("[1,2;3,4]", Add, "\"\nis an array\""),
        Value::str("(2x2)\n   1   2\n   3   4\nis an array")
    );
    assert_eq!(
        op("\"array: \"", Add, "[true,true]"),
        Value::str("array: (2)[true,true]")
    );
    assert_eq!(
        op("[true,true]", Add, "\" is an array\""),
        Value::str("(2)[true,true] is an array")
    );
}

#[test]
fn equality_and_relations_on_scalars() {
    assert_eq!(op("1", Eq, "1"), Value::Bool(true));
    assert_eq!(op("1", Ne, "1"), Value::Bool(false));
    assert_eq!(op("\"a\"", Eq, "\"a\""), Value::Bool(true));
    assert_eq!(op("true", Ne, "false"), Value::Bool(true));
    assert_eq!(op("1", Lt, "2"), Value::Bool(true));
    assert_eq!(op("2", Le, "2"), Value::Bool(true));
    assert_eq!(op("2", Gt, "2"), Value::Bool(false));
    assert_eq!(op("3", Ge, "2"), Value::Bool(true));
    assert_eq!(op("\"abc\"", Lt, "\"abd\""), Value::Bool(true));
    assert_eq!(op("\"B\"", Lt, "\"a\""), Value::Bool(true));
    assert_eq!(op("\"ab\"", Gt, "\"a\""), Value::Bool(true));
    // the float example of func_colon.md
    let a3 = 0.0 + 3.0 * 0.15;
    let b = binary(Eq, false, &Value::Float(a3), &Value::Float(0.45)).unwrap();
    assert_eq!(b, Value::Bool(false));
    // no comparisons across types, none on bools
    assert!(binary(Eq, false, &lit("1"), &lit("\"1\"")).is_err());
    assert!(binary(Lt, false, &lit("true"), &lit("false")).is_err());
    assert!(binary(Lt, false, &lit("[true]"), &lit("[false]")).is_err());
}

/// Compiled CGA compares floats with `dcmpl`: NaN is "less" for `<`/`<=`.
#[test]
fn nan_compares_as_compiled_cga_does() {
    let nan = Value::Float(f64::NAN);
    let one = Value::Float(1.0);
    let b = |o| binary(o, false, &nan, &one).unwrap();
    assert_eq!(b(Lt), Value::Bool(true));
    assert_eq!(b(Le), Value::Bool(true));
    assert_eq!(b(Gt), Value::Bool(false));
    assert_eq!(b(Ge), Value::Bool(false));
    assert_eq!(b(Eq), Value::Bool(false));
    assert_eq!(b(Ne), Value::Bool(true));
}

#[test]
fn logical_operators() {
    assert_eq!(op("true", And, "false"), Value::Bool(false));
    assert_eq!(op("true", Or, "false"), Value::Bool(true));
    assert_eq!(
        unary(UnaryOp::Not, false, &lit("true")).unwrap(),
        Value::Bool(false)
    );
    assert!(binary(And, false, &lit("1"), &lit("true")).is_err());
}

/// arrayTypes.md: equality operators.
#[test]
fn array_equality() {
    assert_eq!(op("[1,2]", Eq, "[1,2]"), Value::Bool(true));
    assert_eq!(op("[\"a\",\"b\"]", Eq, "[\"a\";\"b\"]"), Value::Bool(false));
    assert_eq!(op("[true,false]", Eq, "[true,true]"), Value::Bool(false));
    assert_eq!(op("[1,2]", Ne, "[1;2]"), Value::Bool(true));
    assert_eq!(op("[\"a\",\"b\"]", Ne, "[\"a\";\"b\"]"), Value::Bool(true));
    assert_eq!(op("[true,true]", Ne, "[true,true]"), Value::Bool(false));
    assert!(binary(Eq, false, &lit("[1]"), &lit("[\"1\"]")).is_err());
}

/// arrayTypes.md: relational operators.
#[test]
fn array_relations() {
    assert_eq!(op("[1,2]", Lt, "[1,3]"), Value::Bool(true));
    assert_eq!(op("[\"a\",\"b\"]", Lt, "[\"a\";\"b\"]"), Value::Bool(false));
    assert_eq!(op("[1,2]", Le, "[1,2]"), Value::Bool(true));
    assert_eq!(op("[\"a\";\"b\"]", Le, "[\"a\"]"), Value::Bool(false));
    assert_eq!(op("[1,3]", Gt, "[1,2]"), Value::Bool(true));
    assert_eq!(op("[\"a\";\"b\"]", Gt, "[\"a\"]"), Value::Bool(true));
    assert_eq!(op("[1,2,3]", Ge, "[1,2]"), Value::Bool(true));
    assert_eq!(op("[\"a\";\"b\"]", Ge, "[\"a\";\"b\"]"), Value::Bool(true));
    // rows compared in order: the first row decides before the second
    assert_eq!(op("[1,2;0,0]", Gt, "[1,1;9,9]"), Value::Bool(true));
    assert_eq!(op("[1;2]", Lt, "[1;3]"), Value::Bool(true));
}

/// arrayTypes.md: element-wise logical operators.
#[test]
fn elementwise_logic() {
    assert_cga(
        &unary(UnaryOp::Not, true, &lit("[true,false]")).unwrap(),
        "[false,true]",
    );
    assert_cga(&dot("[true,false]", Or, "true"), "[true,true]");
    assert_cga(&dot("false", Or, "[false;true]"), "[false;true]");
    assert_cga(&dot("[false,true]", Or, "[false,false]"), "[false,true]");
    assert_cga(&dot("[false;true]", And, "true"), "[false;true]");
    assert_cga(
        &dot("false", And, "[true;true;true]"),
        "[false;false;false]",
    );
    assert_cga(&dot("[true,false]", And, "[false,true]"), "[false,false]");
}

/// arrayTypes.md: element-wise arithmetic operators.
#[test]
fn elementwise_arithmetic() {
    assert_cga(&dot("[1,2]", Add, "1"), "[2,3]");
    assert_cga(&dot("1", Add, "[1;2]"), "[2;3]");
    assert_cga(&dot("[1,2]", Add, "[2,1]"), "[3,3]");
    assert_cga(&unary(UnaryOp::Plus, true, &lit("[1,2]")).unwrap(), "[1,2]");
    assert_cga(&dot("[1,2;3,4]", Sub, "1"), "[0,1;2,3]");
    assert_cga(&dot("3", Sub, "[1,2]"), "[2,1]");
    assert_cga(&dot("[3;2]", Sub, "[2;1]"), "[1;1]");
    assert_cga(
        &unary(UnaryOp::Neg, true, &lit("[1;2]")).unwrap(),
        "[-1;-2]",
    );
    assert_cga(&dot("[4,2]", Mul, "2.5"), "[10,5]");
    assert_cga(&dot("-4", Mul, "[0.25;-0.75;-1]"), "[-1;3;4]");
    assert_cga(&dot("[1,2;3,4]", Mul, "[4,3;2,1]"), "[4,6;6,4]");
    assert_cga(&dot("[4;3]", Div, "2"), "[2;1.5]");
    assert_cga(&dot("12", Div, "[2,3,4]"), "[6,4,3]");
    assert_cga(&dot("[1.6,3.8]", Div, "[0.8,1.9]"), "[2,2]");
    assert_cga(&dot("[8;-5;0]", Rem, "3"), "[2;-2;0]");
    assert_cga(&dot("7", Rem, "[2.7,-3]"), "[1.6,1]");
    assert_cga(&dot("[-5,3.8]", Rem, "[-3,0.7]"), "[-2,0.3]");
}

/// arrayTypes.md: element-wise equality and relational operators.
#[test]
fn elementwise_comparisons() {
    assert_cga(&dot("1", Eq, "[1,2]"), "[true,false]");
    assert_cga(&dot("[\"a\",\"b\"]", Eq, "\"b\""), "[false,true]");
    assert_cga(&dot("[true;false]", Eq, "[true;false]"), "[true;true]");
    assert_cga(
        &dot("[1,1;2,2]", Ne, "[1,2;1,2]"),
        "[false,true;true,false]",
    );
    assert_cga(&dot("[\"a\"]", Ne, "\"a\""), "[false]");
    assert_cga(&dot("false", Ne, "[true]"), "[true]");
    assert_cga(&dot("1", Lt, "[1,2]"), "[false,true]");
    assert_cga(&dot("[\"a\",\"b\"]", Lt, "\"b\""), "[true,false]");
    assert_cga(
        &dot("[1,2;2,1]", Lt, "[2,1;1,2]"),
        "[true,false;false,true]",
    );
    assert_cga(&dot("1", Le, "[1,2]"), "[true,true]");
    assert_cga(
        &dot("[\"a\";\"b\";\"c\"]", Le, "\"b\""),
        "[true;true;false]",
    );
    assert_cga(&dot("[\"a\",\"b\"]", Le, "[\"b\",\"a\"]"), "[true,false]");
    assert_cga(
        &dot("[1,2;3,4]", Gt, "[1,1;3,3]"),
        "[false,true;false,true]",
    );
    assert_cga(&dot("\"a\"", Gt, "[\"a\";\"a\"]"), "[false;false]");
    assert_cga(&dot("[\"a\";\"b\"]", Gt, "\"a\""), "[false;true]");
    assert_cga(&dot("[1;2;3]", Ge, "[2;2;2]"), "[false;true;true]");
    assert_cga(&dot("2", Ge, "[1,2,3]"), "[true,true,false]");
    assert_cga(&dot("[\"a\"]", Ge, "\"a\""), "[true]");
}

/// arrayTypes.md: element-wise string concatenation.
#[test]
fn elementwise_concatenation() {
    assert_cga(&dot("[\"a\",\"b\"]", Add, "\"c\""), "[\"ac\",\"bc\"]");
    assert_cga(&dot("\"a\"", Add, "[\"b\";\"c\"]"), "[\"ab\";\"ac\"]");
    assert_cga(
        &dot("[\"a\",\"b\"]", Add, "[\"c\",\"d\"]"),
        "[\"ac\",\"bd\"]",
    );
    assert_cga(&dot("[\"a\",\"b\"]", Add, "1"), "[\"a1\",\"b1\"]");
    assert_cga(
        &dot("\"a\"", Add, "[1,2;3,4]"),
        "[\"a1\",\"a2\";\"a3\",\"a4\"]",
    );
    assert_cga(&dot("[1;2]", Add, "[\"a\";\"b\"]"), "[\"1a\";\"2b\"]");
    assert_cga(&dot("[true;false]", Add, "\"a\""), "[\"truea\";\"falsea\"]");
    assert_cga(&dot("\"a\"", Add, "[true]"), "[\"atrue\"]");
    assert_cga(
        &dot("[\"a\";\"b\"]", Add, "[false;true]"),
        "[\"afalse\";\"btrue\"]",
    );
    assert_cga(&dot("[\"x\"]", Add, "0.5"), "[\"x0.5\"]");
}

#[test]
fn elementwise_errors() {
    // dimensions must be equal
    let e = binary(Add, true, &lit("[1,2]"), &lit("[1;2]")).unwrap_err();
    assert!(e.message.contains("dimensions"), "{e}");
    assert!(binary(Add, true, &lit("[1,2]"), &lit("[1,2,3]")).is_err());
    // types must fit
    assert!(binary(Sub, true, &lit("[\"a\"]"), &lit("1")).is_err());
    assert!(binary(Add, true, &lit("[true]"), &lit("[false]")).is_err());
    assert!(binary(And, true, &lit("[1]"), &lit("true")).is_err());
    assert!(binary(Eq, true, &lit("[1]"), &lit("\"1\"")).is_err());
    assert!(binary(Lt, true, &lit("[true]"), &lit("false")).is_err());
    assert!(unary(UnaryOp::Neg, true, &lit("[\"a\"]")).is_err());
    assert!(unary(UnaryOp::Not, true, &lit("[1]")).is_err());
}

#[test]
fn elementwise_with_empty_arrays_and_scalars() {
    let empty = Value::float_row(vec![]);
    let r = binary(Add, true, &empty, &Value::Float(1.0)).unwrap();
    assert_eq!(to_text(&r), "(0)[]");
    let r = binary(Mul, true, &empty, &empty).unwrap();
    assert_eq!(r.array_len(), Some(0));
    // on two scalars the dotted form acts like the plain one
    assert_eq!(dot("2", Mul, "3"), Value::Float(6.0));
    assert_eq!(dot("\"a\"", Add, "1"), Value::str("a1"));
}
