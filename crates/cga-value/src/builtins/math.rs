//! Math functions. Angles are in degrees, as everywhere in CGA.

use super::{arg, arg_mismatch, float_arg};
use crate::error::ValueError;
use crate::value::Value;

/// CGA's NULL string ("missing value"), see `isNull`.
pub const NULL_STRING: &str = "\u{E000}";

/// `float f(float)`.
fn unary(args: &[Value], name: &str, f: fn(f64) -> f64) -> Result<Value, ValueError> {
    Ok(Value::Float(f(float_arg(args, 0, name)?)))
}

/// `float f(float)` and `float[] f(float[])` (element-wise).
fn unary_or_array(args: &[Value], name: &str, f: fn(f64) -> f64) -> Result<Value, ValueError> {
    match arg(args, 0, name)? {
        Value::Float(x) => Ok(Value::Float(f(*x))),
        Value::FloatArray(a) => Ok(a.map(|x| f(*x)).into()),
        v => Err(arg_mismatch(name, 0, "float or float[]", v)),
    }
}

/// `bool f(float)` and `bool[] f(float[])`.
fn test_or_array(args: &[Value], name: &str, f: fn(f64) -> bool) -> Result<Value, ValueError> {
    match arg(args, 0, name)? {
        Value::Float(x) => Ok(Value::Bool(f(*x))),
        Value::FloatArray(a) => Ok(a.map(|x| f(*x)).into()),
        v => Err(arg_mismatch(name, 0, "float or float[]", v)),
    }
}

pub fn abs(args: &[Value]) -> Result<Value, ValueError> {
    unary_or_array(args, "abs", f64::abs)
}

pub fn ceil(args: &[Value]) -> Result<Value, ValueError> {
    unary_or_array(args, "ceil", f64::ceil)
}

pub fn floor(args: &[Value]) -> Result<Value, ValueError> {
    unary_or_array(args, "floor", f64::floor)
}

/// Round to nearest, ties to even (C's `rint` in the default rounding mode).
pub fn rint(args: &[Value]) -> Result<Value, ValueError> {
    unary_or_array(args, "rint", f64::round_ties_even)
}

pub fn isinf(args: &[Value]) -> Result<Value, ValueError> {
    test_or_array(args, "isinf", f64::is_infinite)
}

pub fn isnan(args: &[Value]) -> Result<Value, ValueError> {
    test_or_array(args, "isnan", f64::is_nan)
}

/// NULL is NaN for floats and `"\ue000"` for strings.
pub fn is_null(args: &[Value]) -> Result<Value, ValueError> {
    match arg(args, 0, "isNull")? {
        Value::Float(x) => Ok(Value::Bool(x.is_nan())),
        Value::Str(s) => Ok(Value::Bool(&**s == NULL_STRING)),
        Value::FloatArray(a) => Ok(a.map(|x| x.is_nan()).into()),
        Value::StrArray(a) => Ok(a.map(|s| &**s == NULL_STRING).into()),
        v => Err(arg_mismatch(
            "isNull",
            0,
            "float, string or an array of them",
            v,
        )),
    }
}

pub fn sin(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "sin", |x| x.to_radians().sin())
}

pub fn cos(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "cos", |x| x.to_radians().cos())
}

pub fn tan(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "tan", |x| x.to_radians().tan())
}

pub fn asin(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "asin", |x| x.asin().to_degrees())
}

pub fn acos(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "acos", |x| x.acos().to_degrees())
}

pub fn atan(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "atan", |x| x.atan().to_degrees())
}

/// `atan2(y, x)` in degrees, in [-180, 180].
pub fn atan2(args: &[Value]) -> Result<Value, ValueError> {
    let y = float_arg(args, 0, "atan2")?;
    let x = float_arg(args, 1, "atan2")?;
    Ok(Value::Float(y.atan2(x).to_degrees()))
}

pub fn exp(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "exp", f64::exp)
}

pub fn ln(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "ln", f64::ln)
}

pub fn log10(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "log10", f64::log10)
}

pub fn sqrt(args: &[Value]) -> Result<Value, ValueError> {
    unary(args, "sqrt", f64::sqrt)
}

pub fn pow(args: &[Value]) -> Result<Value, ValueError> {
    let base = float_arg(args, 0, "pow")?;
    let exponent = float_arg(args, 1, "pow")?;
    Ok(Value::Float(base.powf(exponent)))
}

#[cfg(test)]
mod tests {
    use crate::builtins::call;
    use crate::value::Value;

    fn f(name: &str, args: &[f64]) -> f64 {
        let args: Vec<Value> = args.iter().map(|x| Value::Float(*x)).collect();
        call(name, &args).unwrap().as_float().unwrap()
    }

    fn text(name: &str, args: &[Value]) -> String {
        crate::to_text(&call(name, args).unwrap())
    }

    #[test]
    fn trigonometry_is_in_degrees() {
        assert_eq!(f("sin", &[90.0]), 1.0);
        assert_eq!(f("cos", &[0.0]), 1.0);
        assert!((f("sin", &[30.0]) - 0.5).abs() < 1e-15);
        assert!((f("cos", &[60.0]) - 0.5).abs() < 1e-15);
        assert!((f("tan", &[45.0]) - 1.0).abs() < 1e-15);
        assert!((f("asin", &[0.5]) - 30.0).abs() < 1e-13);
        assert_eq!(f("acos", &[-1.0]), 180.0);
        assert_eq!(f("acos", &[1.0]), 0.0);
        assert_eq!(f("atan", &[1.0]), 45.0);
        assert_eq!(f("atan2", &[1.0, -1.0]), 135.0);
        assert_eq!(f("atan2", &[-0.0, -1.0]), -180.0);
        // outside [-1, 1]: nan
        assert!(f("asin", &[2.0]).is_nan());
        assert!(f("acos", &[-1.5]).is_nan());
    }

    #[test]
    fn exponentials_and_roots() {
        assert_eq!(f("exp", &[0.0]), 1.0);
        assert_eq!(f("ln", &[1.0]), 0.0);
        assert_eq!(f("log10", &[1000.0]), 3.0);
        assert_eq!(f("pow", &[2.0, 10.0]), 1024.0);
        assert_eq!(f("sqrt", &[16.0]), 4.0);
        assert!(f("sqrt", &[-1.0]).is_nan());
        assert_eq!(f("ln", &[0.0]), f64::NEG_INFINITY);
    }

    #[test]
    fn rounding_functions_on_scalars_and_arrays() {
        assert_eq!(f("ceil", &[1.2]), 2.0);
        assert_eq!(f("ceil", &[-1.2]), -1.0);
        assert_eq!(f("floor", &[-1.2]), -2.0);
        assert_eq!(f("floor", &[3.0]), 3.0);
        assert_eq!(f("rint", &[2.5]), 2.0);
        assert_eq!(f("rint", &[3.5]), 4.0);
        assert_eq!(f("rint", &[-1.6]), -2.0);
        assert_eq!(f("abs", &[-3.5]), 3.5);
        let a = Value::float_row(vec![-1.5, 0.5, 2.5]);
        assert_eq!(text("abs", &[a.clone()]), "(3)[1.5,0.5,2.5]");
        assert_eq!(text("ceil", &[a.clone()]), "(3)[-1,1,3]");
        assert_eq!(text("floor", &[a.clone()]), "(3)[-2,0,2]");
        assert_eq!(text("rint", &[a]), "(3)[-2,0,2]");
        assert!(call("abs", &[Value::str("x")]).is_err());
    }

    /// func_isinf.md / func_isnan.md / func_isnull.md examples.
    #[test]
    fn nan_inf_and_null_tests() {
        let b = |name: &str, v: Value| call(name, &[v]).unwrap();
        assert_eq!(b("isinf", Value::Float(1.0)), Value::Bool(false));
        assert_eq!(b("isinf", Value::Float(1.0 / 0.0)), Value::Bool(true));
        assert_eq!(b("isinf", Value::Float(f64::ln(0.0))), Value::Bool(true));
        assert_eq!(b("isinf", Value::Float(f64::ln(-1.0))), Value::Bool(false));
        assert_eq!(
            text("isinf", &[Value::float_row(vec![1.0, 1.0 / 0.0])]),
            "(2)[false,true]"
        );
        assert_eq!(b("isnan", Value::Float(1.0)), Value::Bool(false));
        assert_eq!(b("isnan", Value::Float(f64::ln(-1.0))), Value::Bool(true));
        let float_a = call("float", &[Value::str("a")]).unwrap();
        assert_eq!(b("isnan", float_a), Value::Bool(true));
        assert_eq!(
            text("isnan", &[Value::float_row(vec![1.0, f64::ln(-1.0)])]),
            "(2)[false,true]"
        );
        assert_eq!(b("isNull", Value::str("CityEngine")), Value::Bool(false));
        assert_eq!(b("isNull", Value::str("\u{e000}")), Value::Bool(true));
        assert_eq!(b("isNull", Value::Float(f64::ln(-1.0))), Value::Bool(true));
        assert_eq!(
            text("isNull", &[Value::str_row(&["CityEngine", "\u{e000}"])]),
            "(2)[false,true]"
        );
    }
}
