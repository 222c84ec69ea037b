//! The interpreter's single entry point into `cga-value`: operators, arrays,
//! text form and the pure built-in functions.

use std::sync::Arc;

use cga_syntax::ast::{BinaryOp, UnaryOp};
use cga_value::{Array, Value};

pub struct Builtin {
    pub name: &'static str,
    pub min_args: usize,
    pub max_args: usize,
    pub f: fn(&[Value]) -> Result<Value, String>,
}

impl std::fmt::Debug for Builtin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "builtin {}", self.name)
    }
}

fn num(v: &Value) -> Result<f64, String> {
    match v {
        Value::Float(x) => Ok(*x),
        Value::Bool(b) => Ok(if *b { 1.0 } else { 0.0 }),
        other => Err(format!("expected a float, found {}", type_name(other))),
    }
}

pub fn type_name(v: &Value) -> &'static str {
    match v {
        Value::Float(_) => "float",
        Value::Bool(_) => "bool",
        Value::Str(_) => "string",
        Value::FloatArray(_) => "float[]",
        Value::BoolArray(_) => "bool[]",
        Value::StrArray(_) => "string[]",
    }
}

fn f1(f: fn(f64) -> f64) -> impl Fn(&[Value]) -> Result<Value, String> {
    move |a: &[Value]| Ok(Value::Float(f(num(&a[0])?)))
}

macro_rules! math1 {
    ($name:literal, $f:expr) => {
        Builtin {
            name: $name,
            min_args: 1,
            max_args: 1,
            f: |a| f1($f)(a),
        }
    };
}

static BUILTINS: &[Builtin] = &[
    math1!("abs", f64::abs),
    math1!("floor", f64::floor),
    math1!("ceil", f64::ceil),
    math1!("sqrt", f64::sqrt),
    math1!("sin", |x: f64| x.to_radians().sin()),
    math1!("cos", |x: f64| x.to_radians().cos()),
    math1!("tan", |x: f64| x.to_radians().tan()),
    Builtin {
        name: "min",
        min_args: 2,
        max_args: 2,
        f: |a| Ok(Value::Float(num(&a[0])?.min(num(&a[1])?))),
    },
    Builtin {
        name: "max",
        min_args: 2,
        max_args: 2,
        f: |a| Ok(Value::Float(num(&a[0])?.max(num(&a[1])?))),
    },
    Builtin {
        name: "str",
        min_args: 1,
        max_args: 1,
        f: |a| Ok(Value::Str(Arc::from(to_text(&a[0])))),
    },
];

pub fn lookup(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

pub fn to_text(v: &Value) -> String {
    fn f(x: f64) -> String {
        if x == x.trunc() && x.abs() < 1e15 {
            format!("{}", x as i64)
        } else {
            format!("{x}")
        }
    }
    match v {
        Value::Float(x) => f(*x),
        Value::Bool(b) => b.to_string(),
        Value::Str(s) => s.to_string(),
        Value::FloatArray(a) => format!(
            "({})[{}]",
            a.data.len(),
            a.data.iter().map(|x| f(*x)).collect::<Vec<_>>().join(",")
        ),
        Value::BoolArray(a) => format!(
            "({})[{}]",
            a.data.len(),
            a.data
                .iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(",")
        ),
        Value::StrArray(a) => format!("({})[{}]", a.data.len(), a.data.join(",")),
    }
}

pub fn unary(op: UnaryOp, _elementwise: bool, v: &Value) -> Result<Value, String> {
    match op {
        UnaryOp::Neg => Ok(Value::Float(-num(v)?)),
        UnaryOp::Plus => Ok(Value::Float(num(v)?)),
        UnaryOp::Not => match v {
            Value::Bool(b) => Ok(Value::Bool(!b)),
            other => Err(format!("`!` expects a bool, found {}", type_name(other))),
        },
    }
}

pub fn binary(op: BinaryOp, _elementwise: bool, a: &Value, b: &Value) -> Result<Value, String> {
    use BinaryOp::*;
    if op == Add {
        if let (Value::Str(_), _) | (_, Value::Str(_)) = (a, b) {
            return Ok(Value::Str(Arc::from(format!(
                "{}{}",
                to_text(a),
                to_text(b)
            ))));
        }
    }
    if matches!(op, Eq | Ne) {
        let eq = match (a, b) {
            (Value::Float(x), Value::Float(y)) => x == y,
            _ => a == b,
        };
        return Ok(Value::Bool(if op == Eq { eq } else { !eq }));
    }
    if let (Value::Str(x), Value::Str(y)) = (a, b) {
        let r = match op {
            Lt => x < y,
            Le => x <= y,
            Gt => x > y,
            Ge => x >= y,
            _ => return Err("invalid operation on strings".into()),
        };
        return Ok(Value::Bool(r));
    }
    let (x, y) = (num(a)?, num(b)?);
    Ok(match op {
        Add => Value::Float(x + y),
        Sub => Value::Float(x - y),
        Mul => Value::Float(x * y),
        Div => Value::Float(x / y),
        Rem => Value::Float(x % y),
        Lt => Value::Bool(x < y),
        Le => Value::Bool(x <= y),
        Gt => Value::Bool(x > y),
        Ge => Value::Bool(x >= y),
        And | Or | Eq | Ne => unreachable!("handled by the caller or above"),
    })
}

pub fn build_array(rows: Vec<Vec<Value>>) -> Result<Value, String> {
    let cols = rows.first().map_or(0, |r| r.len());
    let n = rows.len();
    let flat: Vec<Value> = rows.into_iter().flatten().collect();
    let (rows, cols) = if n <= 1 { (1, cols) } else { (n, cols) };
    match flat.first() {
        Some(Value::Bool(_)) => Ok(Value::BoolArray(Arc::new(Array {
            rows,
            cols,
            data: flat
                .iter()
                .map(|v| matches!(v, Value::Bool(true)))
                .collect(),
        }))),
        Some(Value::Str(_)) => Ok(Value::StrArray(Arc::new(Array {
            rows,
            cols,
            data: flat
                .iter()
                .map(|v| Arc::from(to_text(v).as_str()))
                .collect(),
        }))),
        _ => Ok(Value::FloatArray(Arc::new(Array {
            rows,
            cols,
            data: flat.iter().map(num).collect::<Result<_, _>>()?,
        }))),
    }
}

pub fn range(base: f64, step: Option<f64>, limit: f64) -> Result<Value, String> {
    let step = step.unwrap_or(1.0);
    let mut data = Vec::new();
    if step != 0.0 {
        let mut i = 0.0;
        loop {
            let v = base + i * step;
            if (step > 0.0 && v > limit) || (step < 0.0 && v < limit) || data.len() > 100_000 {
                break;
            }
            data.push(v);
            i += 1.0;
        }
    }
    Ok(Value::FloatArray(Arc::new(Array::row(data))))
}

pub fn index(base: &Value, indices: &[Value]) -> Result<Value, String> {
    let i = num(&indices[0])?;
    let i = if i < 0.0 { usize::MAX } else { i as usize };
    Ok(match base {
        Value::FloatArray(a) => Value::Float(a.data.get(i).copied().unwrap_or(0.0)),
        Value::BoolArray(a) => Value::Bool(a.data.get(i).copied().unwrap_or(false)),
        Value::StrArray(a) => Value::Str(a.data.get(i).cloned().unwrap_or_else(|| Arc::from(""))),
        other => return Err(format!("cannot index a {}", type_name(other))),
    })
}
