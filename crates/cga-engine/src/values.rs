//! The interpreter's bridge to `cga-value`: the syntax tree's operators
//! mapped onto the value crate's, and error texts as the interpreter wants them.

use cga_syntax::ast;
use cga_value::{BinaryOp, UnaryOp, Value};

pub use cga_value::{build_array, index, lookup, lookup_name, range, to_text, Builtin};

pub fn type_name(v: &Value) -> &'static str {
    v.type_name()
}

pub fn unary(op: ast::UnaryOp, elementwise: bool, v: &Value) -> Result<Value, String> {
    let op = match op {
        ast::UnaryOp::Neg => UnaryOp::Neg,
        ast::UnaryOp::Plus => UnaryOp::Plus,
        ast::UnaryOp::Not => UnaryOp::Not,
    };
    cga_value::unary(op, elementwise, v).map_err(|e| e.message)
}

pub fn binary(op: ast::BinaryOp, elementwise: bool, a: &Value, b: &Value) -> Result<Value, String> {
    use ast::BinaryOp as A;
    let op = match op {
        A::Add => BinaryOp::Add,
        A::Sub => BinaryOp::Sub,
        A::Mul => BinaryOp::Mul,
        A::Div => BinaryOp::Div,
        A::Rem => BinaryOp::Rem,
        A::Eq => BinaryOp::Eq,
        A::Ne => BinaryOp::Ne,
        A::Lt => BinaryOp::Lt,
        A::Le => BinaryOp::Le,
        A::Gt => BinaryOp::Gt,
        A::Ge => BinaryOp::Ge,
        A::And => BinaryOp::And,
        A::Or => BinaryOp::Or,
    };
    cga_value::binary(op, elementwise, a, b).map_err(|e| e.message)
}
