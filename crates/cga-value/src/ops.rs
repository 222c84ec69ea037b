//! CGA's operators on values: arithmetic, string concatenation, equality,
//! relational and logical operators, and their element-wise (dotted) array
//! forms with scalar broadcasting.
//!
//! The enums mirror `UnaryOp` / `BinaryOp` of the syntax tree; the evaluator
//! maps one onto the other (this crate does not depend on the parser).

use std::cmp::Ordering;
use std::sync::Arc;

use crate::error::ValueError;
use crate::format::{bool_text, write_float, write_value};
use crate::value::{Array, Element, Value};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum UnaryOp {
    /// `-a`, `.-a`
    Neg,
    /// `+a`, `.+a`
    Plus,
    /// `!a`, `.!a`
    Not,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    And,
    Or,
}

impl UnaryOp {
    pub fn symbol(self) -> &'static str {
        match self {
            UnaryOp::Neg => "-",
            UnaryOp::Plus => "+",
            UnaryOp::Not => "!",
        }
    }
}

impl BinaryOp {
    pub fn symbol(self) -> &'static str {
        match self {
            BinaryOp::Add => "+",
            BinaryOp::Sub => "-",
            BinaryOp::Mul => "*",
            BinaryOp::Div => "/",
            BinaryOp::Rem => "%",
            BinaryOp::Eq => "==",
            BinaryOp::Ne => "!=",
            BinaryOp::Lt => "<",
            BinaryOp::Le => "<=",
            BinaryOp::Gt => ">",
            BinaryOp::Ge => ">=",
            BinaryOp::And => "&&",
            BinaryOp::Or => "||",
        }
    }
}

fn op_name(symbol: &str, elementwise: bool) -> String {
    if elementwise {
        format!(".{symbol}")
    } else {
        symbol.to_string()
    }
}

fn binary_mismatch(op: BinaryOp, elementwise: bool, a: &Value, b: &Value) -> ValueError {
    ValueError::new(format!(
        "operator {} cannot be applied to {} and {}",
        op_name(op.symbol(), elementwise),
        a.type_name(),
        b.type_name()
    ))
}

/// Applies a unary operator. `elementwise` selects the dotted array form
/// (`.-a`, `.!a`); applied to a scalar it behaves like the plain operator.
pub fn unary(op: UnaryOp, elementwise: bool, v: &Value) -> Result<Value, ValueError> {
    match (op, v) {
        (UnaryOp::Neg, Value::Float(x)) => Ok(Value::Float(-x)),
        (UnaryOp::Plus, Value::Float(x)) => Ok(Value::Float(*x)),
        (UnaryOp::Not, Value::Bool(b)) => Ok(Value::Bool(!b)),
        (UnaryOp::Neg, Value::FloatArray(a)) if elementwise => Ok(a.map(|x| -x).into()),
        (UnaryOp::Plus, Value::FloatArray(_)) if elementwise => Ok(v.clone()),
        (UnaryOp::Not, Value::BoolArray(a)) if elementwise => Ok(a.map(|b| !b).into()),
        _ => Err(ValueError::new(format!(
            "operator {} cannot be applied to {}{}",
            op_name(op.symbol(), elementwise),
            v.type_name(),
            if v.is_array() && !elementwise {
                " (use the element-wise operator with a leading dot)"
            } else {
                ""
            }
        ))),
    }
}

/// Applies a binary operator. `elementwise` selects the dotted array form
/// (`a .+ b`, `a .== b`, ...), which broadcasts a scalar operand over an
/// array and requires two array operands to have equal dimensions.
///
/// `&&` and `||` are evaluated here on two values; short-circuiting is the
/// evaluator's business.
pub fn binary(op: BinaryOp, elementwise: bool, a: &Value, b: &Value) -> Result<Value, ValueError> {
    if elementwise {
        elementwise_binary(op, a, b)
    } else {
        plain_binary(op, a, b)
    }
}

/// Scalar float comparison as compiled CGA rules evaluate it: the compiler
/// emits the JVM instruction `dcmpl`, which treats an unordered pair (a NaN
/// operand) as "less". So `nan < x` and `nan <= x` are true while `nan > x`
/// and `nan >= x` are false (seen in CityEngine's compiled rule files).
#[allow(clippy::neg_cmp_op_on_partial_ord)] // the negations are the point
fn float_relation(op: BinaryOp, x: f64, y: f64) -> bool {
    match op {
        BinaryOp::Lt => !(x >= y),
        BinaryOp::Le => !(x > y),
        BinaryOp::Gt => x > y,
        BinaryOp::Ge => x >= y,
        _ => false,
    }
}

/// CGA's scalar `a < b` (true when either is NaN, see [`float_relation`]).
pub(crate) fn float_relation_lt(x: f64, y: f64) -> bool {
    float_relation(BinaryOp::Lt, x, y)
}

/// CGA's scalar `a > b`.
pub(crate) fn float_relation_gt(x: f64, y: f64) -> bool {
    float_relation(BinaryOp::Gt, x, y)
}

/// CGA's scalar `a >= b`.
pub(crate) fn float_relation_ge(x: f64, y: f64) -> bool {
    float_relation(BinaryOp::Ge, x, y)
}

fn ordering_relation(op: BinaryOp, ord: Ordering) -> bool {
    match op {
        BinaryOp::Lt => ord == Ordering::Less,
        BinaryOp::Le => ord != Ordering::Greater,
        BinaryOp::Gt => ord == Ordering::Greater,
        BinaryOp::Ge => ord != Ordering::Less,
        _ => false,
    }
}

fn is_relational(op: BinaryOp) -> bool {
    matches!(
        op,
        BinaryOp::Lt | BinaryOp::Le | BinaryOp::Gt | BinaryOp::Ge
    )
}

fn plain_binary(op: BinaryOp, a: &Value, b: &Value) -> Result<Value, ValueError> {
    use BinaryOp::*;
    use Value as V;
    match (op, a, b) {
        (Add, V::Float(x), V::Float(y)) => Ok(V::Float(x + y)),
        (Sub, V::Float(x), V::Float(y)) => Ok(V::Float(x - y)),
        (Mul, V::Float(x), V::Float(y)) => Ok(V::Float(x * y)),
        (Div, V::Float(x), V::Float(y)) => Ok(V::Float(x / y)),
        // Rust's `%` on f64 is C's fmod: the result has the sign of the dividend.
        (Rem, V::Float(x), V::Float(y)) => Ok(V::Float(x % y)),
        // String concatenation with anything, arrays included.
        (Add, V::Str(_), _) | (Add, _, V::Str(_)) => {
            let mut s = String::new();
            write_value(&mut s, a);
            write_value(&mut s, b);
            Ok(V::from(s))
        }
        (Eq | Ne, _, _) => {
            let eq = values_equal(a, b).ok_or_else(|| binary_mismatch(op, false, a, b))?;
            Ok(V::Bool(eq == (op == Eq)))
        }
        (_, V::Float(x), V::Float(y)) if is_relational(op) => {
            Ok(V::Bool(float_relation(op, *x, *y)))
        }
        (_, V::Str(x), V::Str(y)) if is_relational(op) => Ok(V::Bool(ordering_relation(
            op,
            x.as_bytes().cmp(y.as_bytes()),
        ))),
        (_, V::FloatArray(x), V::FloatArray(y)) if is_relational(op) => Ok(V::Bool(
            ordering_relation(op, compare_arrays(x, y, cmp_float_dcmpl)),
        )),
        (_, V::StrArray(x), V::StrArray(y)) if is_relational(op) => Ok(V::Bool(ordering_relation(
            op,
            compare_arrays(x, y, |p, q| p.as_bytes().cmp(q.as_bytes())),
        ))),
        (And, V::Bool(x), V::Bool(y)) => Ok(V::Bool(*x && *y)),
        (Or, V::Bool(x), V::Bool(y)) => Ok(V::Bool(*x || *y)),
        _ => {
            let mut e = binary_mismatch(op, false, a, b);
            if a.is_array() || b.is_array() {
                e.message
                    .push_str(" (use the element-wise operator with a leading dot)");
            }
            Err(e)
        }
    }
}

/// `==` on two values of the same type; `None` if the types differ.
/// Arrays are equal if they have equal dimensions and equal elements.
pub fn values_equal(a: &Value, b: &Value) -> Option<bool> {
    use Value as V;
    Some(match (a, b) {
        (V::Float(x), V::Float(y)) => x == y,
        (V::Bool(x), V::Bool(y)) => x == y,
        (V::Str(x), V::Str(y)) => x == y,
        (V::FloatArray(x), V::FloatArray(y)) => x.same_dims(y) && x.data == y.data,
        (V::BoolArray(x), V::BoolArray(y)) => x.same_dims(y) && x.data == y.data,
        (V::StrArray(x), V::StrArray(y)) => x.same_dims(y) && x.data == y.data,
        _ => return None,
    })
}

fn cmp_float_dcmpl(x: &f64, y: &f64) -> Ordering {
    x.partial_cmp(y).unwrap_or(Ordering::Less)
}

/// The order of two arrays: row by row, each row compared element by element
/// over the common columns; if those are equal the array with fewer columns
/// is less; if all rows compared equal, the array with fewer rows is less.
pub fn compare_arrays<T>(a: &Array<T>, b: &Array<T>, cmp: impl Fn(&T, &T) -> Ordering) -> Ordering {
    let (ar, br) = (a.n_rows(), b.n_rows());
    let (ac, bc) = (a.n_cols(), b.n_cols());
    for r in 0..ar.min(br) {
        for c in 0..ac.min(bc) {
            let ord = cmp(&a.data[r * ac + c], &b.data[r * bc + c]);
            if ord != Ordering::Equal {
                return ord;
            }
        }
        if ac != bc {
            return ac.cmp(&bc);
        }
    }
    ar.cmp(&br)
}

/// One operand of an element-wise operator: a scalar broadcast over the
/// other operand, or an array.
enum Side<'a, T> {
    One(&'a T),
    Many(&'a Array<T>),
}

// Manual impls: a derive would require `T: Copy`, but only references are copied.
impl<T> Clone for Side<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Side<'_, T> {}

impl<'a, T> Side<'a, T> {
    #[inline]
    fn get(&self, i: usize) -> &'a T {
        match *self {
            Side::One(x) => x,
            Side::Many(a) => &a.data[i],
        }
    }

    fn array(&self) -> Option<&'a Array<T>> {
        match *self {
            Side::One(_) => None,
            Side::Many(a) => Some(a),
        }
    }
}

fn float_side(v: &Value) -> Option<Side<'_, f64>> {
    match v {
        Value::Float(x) => Some(Side::One(x)),
        Value::FloatArray(a) => Some(Side::Many(a)),
        _ => None,
    }
}

fn bool_side(v: &Value) -> Option<Side<'_, bool>> {
    match v {
        Value::Bool(x) => Some(Side::One(x)),
        Value::BoolArray(a) => Some(Side::Many(a)),
        _ => None,
    }
}

fn str_side(v: &Value) -> Option<Side<'_, Arc<str>>> {
    match v {
        Value::Str(x) => Some(Side::One(x)),
        Value::StrArray(a) => Some(Side::Many(a)),
        _ => None,
    }
}

/// An operand of element-wise string concatenation (any element type).
#[derive(Clone, Copy)]
enum TextSide<'a> {
    F(Side<'a, f64>),
    B(Side<'a, bool>),
    S(Side<'a, Arc<str>>),
}

impl<'a> TextSide<'a> {
    fn of(v: &'a Value) -> TextSide<'a> {
        if let Some(s) = float_side(v) {
            TextSide::F(s)
        } else if let Some(s) = bool_side(v) {
            TextSide::B(s)
        } else {
            // The remaining cases are the string ones.
            TextSide::S(str_side(v).unwrap_or(Side::Many(empty_str_array())))
        }
    }

    fn write(&self, out: &mut String, i: usize) {
        match self {
            TextSide::F(s) => write_float(out, *s.get(i)),
            TextSide::B(s) => out.push_str(bool_text(*s.get(i))),
            TextSide::S(s) => out.push_str(s.get(i)),
        }
    }

    fn dims(&self) -> Option<(usize, usize, bool)> {
        fn d<T>(a: &Array<T>) -> (usize, usize, bool) {
            (a.rows, a.cols, a.is_empty())
        }
        match self {
            TextSide::F(s) => s.array().map(d),
            TextSide::B(s) => s.array().map(d),
            TextSide::S(s) => s.array().map(d),
        }
    }
}

fn empty_str_array() -> &'static Array<Arc<str>> {
    static EMPTY: Array<Arc<str>> = Array {
        rows: 1,
        cols: 0,
        data: Vec::new(),
    };
    &EMPTY
}

/// Result shape of an element-wise operation: `None` if both are scalars.
fn result_dims(
    op: BinaryOp,
    a: Option<(usize, usize, bool)>,
    b: Option<(usize, usize, bool)>,
) -> Result<Option<(usize, usize)>, ValueError> {
    match (a, b) {
        (None, None) => Ok(None),
        (Some((r, c, _)), None) | (None, Some((r, c, _))) => Ok(Some((r, c))),
        (Some((ar, ac, ae)), Some((br, bc, be))) => {
            if (ae && be) || (ar == br && ac == bc) {
                Ok(Some((ar, ac)))
            } else {
                Err(ValueError::new(format!(
                    "operator .{}: array dimensions differ ({}x{} and {}x{})",
                    op.symbol(),
                    ar,
                    ac,
                    br,
                    bc
                )))
            }
        }
    }
}

fn dims_of<T>(s: &Side<'_, T>) -> Option<(usize, usize, bool)> {
    s.array().map(|a| (a.rows, a.cols, a.is_empty()))
}

fn zip_with<A, B, R: Element>(
    op: BinaryOp,
    a: Side<'_, A>,
    b: Side<'_, B>,
    f: impl Fn(&A, &B) -> R,
) -> Result<Value, ValueError> {
    match result_dims(op, dims_of(&a), dims_of(&b))? {
        None => Ok(f(a.get(0), b.get(0)).wrap()),
        Some((rows, cols)) => {
            let n = rows * cols;
            let data: Vec<R> = (0..n).map(|i| f(a.get(i), b.get(i))).collect();
            Ok(R::wrap_array(Array::new(rows, cols, data)))
        }
    }
}

fn elementwise_binary(op: BinaryOp, a: &Value, b: &Value) -> Result<Value, ValueError> {
    use BinaryOp::*;
    let mismatch = || binary_mismatch(op, true, a, b);
    let is_text = |v: &Value| matches!(v, Value::Str(_) | Value::StrArray(_));
    match op {
        Add if is_text(a) || is_text(b) => {
            let (ta, tb) = (TextSide::of(a), TextSide::of(b));
            let dims = result_dims(op, ta.dims(), tb.dims())?;
            let concat = |i: usize| -> Arc<str> {
                let mut s = String::new();
                ta.write(&mut s, i);
                tb.write(&mut s, i);
                Arc::from(s)
            };
            Ok(match dims {
                None => Value::Str(concat(0)),
                Some((rows, cols)) => {
                    Array::new(rows, cols, (0..rows * cols).map(concat).collect()).into()
                }
            })
        }
        Add | Sub | Mul | Div | Rem => {
            let (x, y) = (
                float_side(a).ok_or_else(mismatch)?,
                float_side(b).ok_or_else(mismatch)?,
            );
            match op {
                Add => zip_with(op, x, y, |p, q| p + q),
                Sub => zip_with(op, x, y, |p, q| p - q),
                Mul => zip_with(op, x, y, |p, q| p * q),
                Div => zip_with(op, x, y, |p, q| p / q),
                _ => zip_with(op, x, y, |p, q| p % q),
            }
        }
        Eq | Ne => {
            let want = op == Eq;
            if let (Some(x), Some(y)) = (float_side(a), float_side(b)) {
                zip_with(op, x, y, |p, q| (p == q) == want)
            } else if let (Some(x), Some(y)) = (bool_side(a), bool_side(b)) {
                zip_with(op, x, y, |p, q| (p == q) == want)
            } else if let (Some(x), Some(y)) = (str_side(a), str_side(b)) {
                zip_with(op, x, y, |p, q| (p == q) == want)
            } else {
                Err(mismatch())
            }
        }
        Lt | Le | Gt | Ge => {
            if let (Some(x), Some(y)) = (float_side(a), float_side(b)) {
                // Element-wise comparisons are native built-ins: IEEE semantics.
                zip_with(op, x, y, |p, q| match op {
                    Lt => p < q,
                    Le => p <= q,
                    Gt => p > q,
                    _ => p >= q,
                })
            } else if let (Some(x), Some(y)) = (str_side(a), str_side(b)) {
                zip_with(op, x, y, |p, q| {
                    ordering_relation(op, p.as_bytes().cmp(q.as_bytes()))
                })
            } else {
                Err(mismatch())
            }
        }
        And | Or => {
            let (x, y) = (
                bool_side(a).ok_or_else(mismatch)?,
                bool_side(b).ok_or_else(mismatch)?,
            );
            if op == And {
                zip_with(op, x, y, |p, q| *p && *q)
            } else {
                zip_with(op, x, y, |p, q| *p || *q)
            }
        }
    }
}
