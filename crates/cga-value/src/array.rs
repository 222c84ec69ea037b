//! Array construction (`[a, b ; c, d]`), ranges (`[base : step : limit]`),
//! the index operator (`a[i]`, `a[i, j]`) and `setElems`.

use std::sync::Arc;

use crate::error::ValueError;
use crate::value::{Array, Element, Value, ValueType, MAX_ARRAY_SIZE};

/// One element of an array initialization: a scalar or an array to concatenate.
enum Piece<'a, T> {
    One(&'a T),
    Many(&'a Array<T>),
}

impl<T> Piece<'_, T> {
    fn rows(&self) -> usize {
        match self {
            Piece::One(_) => 1,
            Piece::Many(a) => a.n_rows(),
        }
    }
    fn cols(&self) -> usize {
        match self {
            Piece::One(_) => 1,
            Piece::Many(a) => a.n_cols(),
        }
    }
}

/// The array initialization `[v, v, ... ; v, v, ... ; ...]`.
///
/// Each inner vector is one `;`-separated row of the source. Elements are
/// scalars or arrays: within a row they are concatenated side by side (all
/// must have the same number of rows), and the rows are stacked (all must
/// have the same number of columns). Empty arrays contribute nothing. All
/// elements must have the same element type: a `float[]` is made from floats
/// and `float[]`s, and so on. At most [`MAX_ARRAY_SIZE`] elements.
pub fn build_array(rows: &[Vec<Value>]) -> Result<Value, ValueError> {
    let first = rows
        .iter()
        .flatten()
        .next()
        .ok_or_else(|| ValueError::new("array initialization needs at least one element"))?;
    match first.value_type().element() {
        ValueType::Float => concat(rows, |v| match v {
            Value::Float(x) => Some(Piece::One(x)),
            Value::FloatArray(a) => Some(Piece::Many(a)),
            _ => None,
        }),
        ValueType::Bool => concat(rows, |v| match v {
            Value::Bool(x) => Some(Piece::One(x)),
            Value::BoolArray(a) => Some(Piece::Many(a)),
            _ => None,
        }),
        _ => concat(rows, |v| match v {
            Value::Str(x) => Some(Piece::One(x)),
            Value::StrArray(a) => Some(Piece::Many(a)),
            _ => None,
        }),
    }
}

fn concat<T: Element>(
    rows: &[Vec<Value>],
    piece: impl for<'a> Fn(&'a Value) -> Option<Piece<'a, T>>,
) -> Result<Value, ValueError> {
    let mut total_rows = 0usize;
    let mut total_cols: Option<usize> = None;
    let mut blocks: Vec<(usize, Vec<Piece<'_, T>>)> = Vec::with_capacity(rows.len());
    let mut first_type = None;
    for row in rows {
        let mut pieces = Vec::with_capacity(row.len());
        let mut height: Option<usize> = None;
        let mut width = 0usize;
        for v in row {
            let p = piece(v).ok_or_else(|| {
                ValueError::new(format!(
                    "array initialization: cannot combine {} with {}",
                    first_type.unwrap_or(v.type_name()),
                    v.type_name()
                ))
            })?;
            first_type.get_or_insert(v.type_name());
            if p.rows() == 0 {
                continue; // an empty array adds nothing
            }
            match height {
                None => height = Some(p.rows()),
                Some(h) if h != p.rows() => {
                    return Err(ValueError::new(format!(
                        "array initialization: cannot concatenate arrays with {h} and {} rows",
                        p.rows()
                    )))
                }
                Some(_) => {}
            }
            width += p.cols();
            pieces.push(p);
        }
        let Some(height) = height else { continue };
        match total_cols {
            None => total_cols = Some(width),
            Some(c) if c != width => {
                return Err(ValueError::new(format!(
                    "array initialization: rows have different numbers of columns ({c} and {width})"
                )))
            }
            Some(_) => {}
        }
        total_rows += height;
        blocks.push((height, pieces));
    }
    let cols = total_cols.unwrap_or(0);
    let size = total_rows.saturating_mul(cols);
    if size > MAX_ARRAY_SIZE {
        return Err(ValueError::too_large("array initialization", size));
    }
    let mut data = Vec::with_capacity(size);
    for (height, pieces) in &blocks {
        for r in 0..*height {
            for p in pieces {
                match p {
                    Piece::One(x) => data.push((*x).clone()),
                    Piece::Many(a) => {
                        let c = a.cols;
                        data.extend_from_slice(&a.data[r * c..(r + 1) * c]);
                    }
                }
            }
        }
    }
    Ok(T::wrap_array(Array::new(total_rows, cols, data)))
}

/// The colon operator: `[base : limit]` (`step` = `None`, i.e. 1) and
/// `[base : step : limit]`. Elements are `base + i * step` while they do not
/// pass `limit`; a zero step, or a step pointing away from `limit`, gives an
/// empty array. At most [`MAX_ARRAY_SIZE`] elements.
pub fn range(base: f64, step: Option<f64>, limit: f64) -> Result<Value, ValueError> {
    let step = step.unwrap_or(1.0);
    let mut data = Vec::new();
    if step != 0.0 && !step.is_nan() {
        let ascending = step > 0.0;
        // Reject huge ranges before allocating anything.
        let estimate = ((limit - base) / step).floor();
        if estimate >= MAX_ARRAY_SIZE as f64 {
            return Err(ValueError::too_large("range", MAX_ARRAY_SIZE + 1));
        }
        let mut i = 0usize;
        loop {
            let v = base + i as f64 * step;
            let inside = if ascending { v <= limit } else { v >= limit };
            if !inside {
                break;
            }
            if data.len() == MAX_ARRAY_SIZE {
                return Err(ValueError::too_large("range", MAX_ARRAY_SIZE + 1));
            }
            data.push(v);
            i += 1;
        }
    }
    Ok(Value::float_row(data))
}

/// A float index as an element position: the fraction is dropped (as a C
/// cast does); negative and NaN indices are `None` (invalid).
fn position(f: f64) -> Option<usize> {
    if f.is_nan() {
        return None;
    }
    let t = f.trunc();
    if t < 0.0 {
        None
    } else if t >= usize::MAX as f64 {
        Some(usize::MAX)
    } else {
        Some(t as usize)
    }
}

/// A row/column/linear index argument: one index, or a list of them (from a
/// float index array, row-wise, or the true positions of a bool array).
enum Indices {
    One(Option<usize>),
    List(Vec<Option<usize>>),
}

impl Indices {
    fn of(v: &Value, what: &str) -> Result<Indices, ValueError> {
        Ok(match v {
            Value::Float(f) => Indices::One(position(*f)),
            Value::FloatArray(a) => Indices::List(a.data.iter().map(|f| position(*f)).collect()),
            Value::BoolArray(a) => Indices::List(
                a.data
                    .iter()
                    .enumerate()
                    .filter(|(_, b)| **b)
                    .map(|(i, _)| Some(i))
                    .collect(),
            ),
            _ => {
                return Err(ValueError::new(format!(
                    "{what}: an index must be float, float[] or bool[], not {}",
                    v.type_name()
                )))
            }
        })
    }

    fn as_slice(&self) -> &[Option<usize>] {
        match self {
            Indices::One(i) => std::slice::from_ref(i),
            Indices::List(l) => l,
        }
    }
}

/// The index operator: `array[index]` with one index value (linear
/// indexing, also for 2D arrays) or `array[row, col]` with two.
///
/// * a float index gives one element;
/// * a float index array gives an array of the index array's dimensions
///   (for 2D indexing: `rows x cols` of the two index lists);
/// * a bool index array selects the positions where it is true (always
///   linear; the result is a 1D array, or a column for row selection);
/// * an index outside the array gives the default value (0, false, "").
pub fn index(array: &Value, indices: &[Value]) -> Result<Value, ValueError> {
    match array {
        Value::FloatArray(a) => index_typed(a, indices),
        Value::BoolArray(a) => index_typed(a, indices),
        Value::StrArray(a) => index_typed(a, indices),
        _ => Err(ValueError::new(format!(
            "index operator: {} is not an array",
            array.type_name()
        ))),
    }
}

fn index_typed<T: Element>(a: &Array<T>, indices: &[Value]) -> Result<Value, ValueError> {
    let linear = |k: Option<usize>| -> T {
        k.and_then(|k| a.data.get(k).cloned())
            .unwrap_or_else(T::default_value)
    };
    match indices {
        [idx] => match idx {
            Value::Float(f) => Ok(linear(position(*f)).wrap()),
            Value::FloatArray(ix) => Ok(T::wrap_array(ix.map(|f| linear(position(*f))))),
            Value::BoolArray(_) => {
                let Indices::List(list) = Indices::of(idx, "index operator")? else {
                    unreachable!("a bool array gives a list")
                };
                Ok(T::wrap_array(Array::row(
                    list.into_iter().map(linear).collect(),
                )))
            }
            _ => Err(ValueError::new(format!(
                "index operator: an index must be float, float[] or bool[], not {}",
                idx.type_name()
            ))),
        },
        [r, c] => {
            let (ri, ci) = (
                Indices::of(r, "index operator")?,
                Indices::of(c, "index operator")?,
            );
            let at = |r: Option<usize>, c: Option<usize>| -> T {
                match (r, c) {
                    (Some(r), Some(c)) => a.get(r, c).cloned().unwrap_or_else(T::default_value),
                    _ => T::default_value(),
                }
            };
            if let (Indices::One(r), Indices::One(c)) = (&ri, &ci) {
                return Ok(at(*r, *c).wrap());
            }
            let (rs, cs) = (ri.as_slice(), ci.as_slice());
            let size = rs.len().saturating_mul(cs.len());
            if size > MAX_ARRAY_SIZE {
                return Err(ValueError::too_large("index operator", size));
            }
            let mut data = Vec::with_capacity(size);
            for r in rs {
                for c in cs {
                    data.push(at(*r, *c));
                }
            }
            Ok(T::wrap_array(Array::new(rs.len(), cs.len(), data)))
        }
        _ => Err(ValueError::new(format!(
            "index operator: expected 1 or 2 indices, got {}",
            indices.len()
        ))),
    }
}

/// `setElems(array, indices, values)` (`indices.len() == 1`) and
/// `setElems(array, rowIndices, colIndices, values)` (`indices.len() == 2`).
///
/// Indices follow the index operator (float, float[] or bool[]). `values` is
/// one value for all selected elements or an array with one value per
/// selected element (`rows x cols` of the two index lists for 2D); repeated
/// indices override in order. Negative indices are skipped; indices past the
/// end enlarge the array, filled with the default value.
pub fn set_elems(array: &Value, indices: &[Value], values: &Value) -> Result<Value, ValueError> {
    match array {
        Value::FloatArray(a) => set_typed(a, indices, values, |v| match v {
            Value::Float(x) => Some(Piece::One(x)),
            Value::FloatArray(a) => Some(Piece::Many(a)),
            _ => None,
        }),
        Value::BoolArray(a) => set_typed(a, indices, values, |v| match v {
            Value::Bool(x) => Some(Piece::One(x)),
            Value::BoolArray(a) => Some(Piece::Many(a)),
            _ => None,
        }),
        Value::StrArray(a) => set_typed(a, indices, values, |v| match v {
            Value::Str(x) => Some(Piece::One(x)),
            Value::StrArray(a) => Some(Piece::Many(a)),
            _ => None,
        }),
        _ => Err(ValueError::type_mismatch("setElems", "an array", array)),
    }
}

fn set_typed<T: Element>(
    a: &Arc<Array<T>>,
    indices: &[Value],
    values: &Value,
    piece: impl for<'a> Fn(&'a Value) -> Option<Piece<'a, T>>,
) -> Result<Value, ValueError> {
    let vals = piece(values).ok_or_else(|| {
        ValueError::new(format!(
            "setElems: cannot set {} values in a {} array",
            values.type_name(),
            match a.data.first() {
                Some(x) => x.clone().wrap().type_name(),
                None => T::default_value().wrap().type_name(),
            }
        ))
    })?;
    let value_at = |i: usize| -> T {
        match &vals {
            Piece::One(x) => (*x).clone(),
            Piece::Many(v) => v.data[i].clone(),
        }
    };
    let check_count = |n: usize| -> Result<(), ValueError> {
        match &vals {
            Piece::Many(v) if v.len() != n => Err(ValueError::new(format!(
                "setElems: {} values given for {n} selected elements",
                v.len()
            ))),
            _ => Ok(()),
        }
    };
    match indices {
        [idx] => {
            let ix = Indices::of(idx, "setElems")?;
            let list = ix.as_slice();
            check_count(list.len())?;
            let max = list.iter().flatten().max().copied();
            let mut out: Array<T> = (**a).clone();
            if let Some(max) = max {
                if max >= out.len() {
                    let needed = max.saturating_add(1);
                    if out.is_1d() {
                        if needed > MAX_ARRAY_SIZE {
                            return Err(ValueError::too_large("setElems", needed));
                        }
                        out.data.resize(needed, T::default_value());
                        out.rows = 1;
                        out.cols = needed;
                    } else {
                        // A 2D array grows by whole rows.
                        let rows = needed.div_ceil(out.cols);
                        let size = rows.saturating_mul(out.cols);
                        if size > MAX_ARRAY_SIZE {
                            return Err(ValueError::too_large("setElems", size));
                        }
                        out.data.resize(size, T::default_value());
                        out.rows = rows;
                    }
                }
            }
            for (i, k) in list.iter().enumerate() {
                if let Some(k) = k {
                    out.data[*k] = value_at(i);
                }
            }
            Ok(T::wrap_array(out))
        }
        [r, c] => {
            let (ri, ci) = (Indices::of(r, "setElems")?, Indices::of(c, "setElems")?);
            let (rs, cs) = (ri.as_slice(), ci.as_slice());
            check_count(rs.len().saturating_mul(cs.len()))?;
            let (old_rows, old_cols) = (a.n_rows(), a.n_cols());
            let max_r = rs.iter().flatten().max().map_or(0, |m| m.saturating_add(1));
            let max_c = cs.iter().flatten().max().map_or(0, |m| m.saturating_add(1));
            let (rows, cols) = (old_rows.max(max_r), old_cols.max(max_c));
            let size = rows.saturating_mul(cols);
            if size > MAX_ARRAY_SIZE {
                return Err(ValueError::too_large("setElems", size));
            }
            let mut out: Array<T> = if (rows, cols) == (old_rows, old_cols) {
                (**a).clone()
            } else {
                let mut data = Vec::with_capacity(size);
                for r in 0..rows {
                    for c in 0..cols {
                        data.push(a.get(r, c).cloned().unwrap_or_else(T::default_value));
                    }
                }
                Array::new(rows, cols, data)
            };
            for (i, r) in rs.iter().enumerate() {
                for (j, c) in cs.iter().enumerate() {
                    if let (Some(r), Some(c)) = (r, c) {
                        out.data[r * cols + c] = value_at(i * cs.len() + j);
                    }
                }
            }
            Ok(T::wrap_array(out))
        }
        _ => Err(ValueError::new(format!(
            "setElems: expected 1 or 2 index arguments, got {}",
            indices.len()
        ))),
    }
}
