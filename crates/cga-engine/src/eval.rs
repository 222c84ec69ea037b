//! Expression evaluation.

use cga_syntax::ast::BinaryOp;
use cga_value::Value;

use crate::derive::{AttrSlot, Interp, RtError};
use crate::expr::{RExpr, RExprKind};
use crate::program::{AttrId, FuncId};
use crate::shape::Shape;
use crate::values as vs;

/// Stream ordinals of attribute defaults (plus the attribute's index) and
/// of const functions (plus the function's index): far from the ordinals
/// of a shape's successors.
const ATTR_STREAMS: u64 = 1 << 40;
const CONST_STREAMS: u64 = 2 << 40;

impl Interp<'_> {
    pub fn eval(&mut self, e: &RExpr, frame: &[Value], shape: &Shape) -> Result<Value, RtError> {
        match &e.kind {
            RExprKind::Const(v) => Ok(match v {
                Value::Float(_) | Value::Bool(_) => v.clone(),
                _ => self.own_literal(v),
            }),
            RExprKind::Local(i) => Ok(frame[*i as usize].clone()),
            RExprKind::Attr(id) => self.attr_value(*id, shape, e),
            RExprKind::Func(f, args) => {
                let mut values = Vec::with_capacity(args.len());
                for a in args {
                    values.push(self.eval(a, frame, shape)?);
                }
                self.call_function(*f, values, shape, e)
            }
            RExprKind::Pure(b, args) => {
                let mut values = Vec::with_capacity(args.len());
                for a in args {
                    values.push(self.eval(a, frame, shape)?);
                }
                (b.f)(&values).map_err(|m| {
                    // Most built-ins name themselves in their messages.
                    let named = m
                        .message
                        .strip_prefix(b.name)
                        .is_some_and(|rest| rest.starts_with(':'));
                    let message = if named {
                        m.message
                    } else {
                        format!("{}: {}", b.name, m.message)
                    };
                    RtError::new(message, e.span)
                })
            }
            RExprKind::Shape(f, args) => {
                let mut values = Vec::with_capacity(args.len());
                for a in args {
                    values.push(self.eval(a, frame, shape)?);
                }
                self.shape_fn(*f, &values, shape, e)
            }
            RExprKind::Unary {
                op,
                elementwise,
                operand,
            } => {
                let v = self.eval(operand, frame, shape)?;
                vs::unary(*op, *elementwise, &v).map_err(|m| RtError::new(m, e.span))
            }
            RExprKind::Binary {
                op,
                elementwise,
                lhs,
                rhs,
            } => {
                let a = self.eval(lhs, frame, shape)?;
                // `&&` and `||` on bools evaluate their right side only when needed.
                if !elementwise {
                    match (op, &a) {
                        (BinaryOp::And, Value::Bool(false)) => return Ok(Value::Bool(false)),
                        (BinaryOp::Or, Value::Bool(true)) => return Ok(Value::Bool(true)),
                        (BinaryOp::And | BinaryOp::Or, Value::Bool(_)) => {
                            let b = self.eval(rhs, frame, shape)?;
                            return match b {
                                Value::Bool(b) => Ok(Value::Bool(b)),
                                other => Err(RtError::new(
                                    format!("expected a bool, found {}", vs::type_name(&other)),
                                    rhs.span,
                                )),
                            };
                        }
                        _ => {}
                    }
                }
                let b = self.eval(rhs, frame, shape)?;
                vs::binary(*op, *elementwise, &a, &b).map_err(|m| RtError::new(m, e.span))
            }
            RExprKind::Array(rows) => {
                let mut out = Vec::with_capacity(rows.len());
                for row in rows {
                    let mut r = Vec::with_capacity(row.len());
                    for x in row {
                        r.push(self.eval(x, frame, shape)?);
                    }
                    out.push(r);
                }
                vs::build_array(&out).map_err(|m| RtError::new(m.message, e.span))
            }
            RExprKind::Range { base, step, limit } => {
                let b = self.eval_num(base, frame, shape)?;
                let s = match step {
                    Some(s) => Some(self.eval_num(s, frame, shape)?),
                    None => None,
                };
                let l = self.eval_num(limit, frame, shape)?;
                vs::range(b, s, l).map_err(|m| RtError::new(m.message, e.span))
            }
            RExprKind::Index { base, indices } => {
                let b = self.eval(base, frame, shape)?;
                let mut idx = Vec::with_capacity(indices.len());
                for i in indices {
                    idx.push(self.eval(i, frame, shape)?);
                }
                vs::index(&b, &idx).map_err(|m| RtError::new(m.message, e.span))
            }
            RExprKind::Case {
                branches,
                otherwise,
            } => {
                for (c, v) in branches {
                    if self.eval_condition(c, frame, shape)? {
                        return self.eval(v, frame, shape);
                    }
                }
                match otherwise {
                    Some(v) => self.eval(v, frame, shape),
                    None => Err(RtError::new("no case matched and there is no else", e.span)),
                }
            }
            RExprKind::Stochastic {
                branches,
                otherwise,
            } => {
                let pick = self.stochastic_pick(branches.iter().map(|(p, _)| p), frame, shape)?;
                match (pick, otherwise) {
                    (Some(i), _) => self.eval(&branches[i].1, frame, shape),
                    (None, Some(v)) => self.eval(v, frame, shape),
                    (None, None) => Err(RtError::new(
                        "no stochastic branch was chosen and there is no else",
                        e.span,
                    )),
                }
            }
            RExprKind::Relative(inner) | RExprKind::Floating(inner) => {
                // A size prefix outside an operation argument: the plain value.
                self.eval(inner, frame, shape)
            }
            RExprKind::WithLocals { locals, body } => {
                let mut inner = frame.to_vec();
                for l in locals {
                    let v = self.eval(l, &inner, shape)?;
                    inner.push(v);
                }
                self.eval(body, &inner, shape)
            }
            RExprKind::CompFn { args, block } => {
                crate::ops::comp::eval_fn(self, args, block, frame, shape, e.span)
            }
            // A comp head outside a component split (never produced by the
            // resolver): its expression.
            RExprKind::CompHead { expr, .. } => self.eval(expr, frame, shape),
            RExprKind::CompSelector(..) => Err(RtError::new(
                "a selector keyword has a value only in the head of a comp entry",
                e.span,
            )),
        }
    }

    /// The lot's own copy of `v`, a string or array literal of the program.
    /// The program is shared by the deriving threads: a clone of its value
    /// takes and later drops a reference count in a cache line the threads
    /// passed between them at every literal evaluated (Candler's texture
    /// paths, asset names and modes, for every window). A lot's copy is
    /// made once and equal by value, as strings and arrays are compared.
    #[inline(never)]
    fn own_literal(&mut self, v: &Value) -> Value {
        let address = match v {
            Value::Str(s) => s.as_ptr() as usize,
            Value::FloatArray(a) => std::sync::Arc::as_ptr(a) as usize,
            Value::BoolArray(a) => std::sync::Arc::as_ptr(a) as usize,
            Value::StrArray(a) => std::sync::Arc::as_ptr(a) as usize,
            Value::Float(_) | Value::Bool(_) => return v.clone(),
        };
        self.literals
            .entry(address)
            .or_insert_with(|| v.own_copy())
            .clone()
    }

    pub fn eval_num(&mut self, e: &RExpr, frame: &[Value], shape: &Shape) -> Result<f64, RtError> {
        match self.eval(e, frame, shape)? {
            Value::Float(x) => Ok(x),
            Value::Bool(b) => Ok(if b { 1.0 } else { 0.0 }),
            other => Err(RtError::new(
                format!("expected a float, found {}", vs::type_name(&other)),
                e.span,
            )),
        }
    }

    pub fn eval_condition(
        &mut self,
        e: &RExpr,
        frame: &[Value],
        shape: &Shape,
    ) -> Result<bool, RtError> {
        match self.eval(e, frame, shape)? {
            Value::Bool(b) => Ok(b),
            Value::Float(x) => Ok(x != 0.0),
            other => Err(RtError::new(
                format!(
                    "a condition must be a bool, found {}",
                    vs::type_name(&other)
                ),
                e.span,
            )),
        }
    }

    /// The value of an attribute for `shape`: set on the shape, else the
    /// initial shape's (evaluated once, on first use).
    pub(crate) fn attr_value(
        &mut self,
        id: AttrId,
        shape: &Shape,
        at: &RExpr,
    ) -> Result<Value, RtError> {
        if let Some(v) = shape.attr_override(id) {
            return Ok(v.clone());
        }
        self.attr_default(id, at)
    }

    pub(crate) fn attr_default(&mut self, id: AttrId, at: &RExpr) -> Result<Value, RtError> {
        match &self.attr_values[id as usize] {
            AttrSlot::Done(v) => return Ok(v.clone()),
            AttrSlot::InProgress => {
                let name = &self.program.attrs[id as usize].name;
                return Err(RtError::new(
                    format!("attribute `{name}` depends on itself"),
                    at.span,
                ));
            }
            AttrSlot::Unevaluated => {}
        }
        self.attr_values[id as usize] = AttrSlot::InProgress;
        let program = self.program;
        let def = &program.attrs[id as usize];
        let initial = self.initial_with_own_stream(ATTR_STREAMS + id as u64);
        let r = self.eval_with_locals(&[], &def.default, &initial);
        match r {
            Ok(v) => {
                let v = v.own_copy();
                self.attr_values[id as usize] = AttrSlot::Done(v.clone());
                Ok(v)
            }
            Err(err) => {
                self.attr_values[id as usize] = AttrSlot::Unevaluated;
                Err(err)
            }
        }
    }

    /// The initial shape with a random stream of its own for one attribute
    /// or const default (`ordinal`: [`ATTR_STREAMS`] or [`CONST_STREAMS`]
    /// plus its index). Each default draws its own numbers, so that
    /// `attr height = rand(10, 30)` and `attr roofAngle = rand(20, 45)` are
    /// not the same point of one stream (perfectly correlated over a city),
    /// and what one draws does not depend on which is evaluated first.
    fn initial_with_own_stream(&self, ordinal: u64) -> Shape {
        let initial = self.initial.clone();
        initial.rng.set(self.initial.child_rng(ordinal));
        initial
    }

    fn eval_with_locals(
        &mut self,
        locals: &[RExpr],
        body: &RExpr,
        shape: &Shape,
    ) -> Result<Value, RtError> {
        let mut frame = Vec::with_capacity(locals.len());
        for l in locals {
            let v = self.eval(l, &frame, shape)?;
            frame.push(v);
        }
        self.eval(body, &frame, shape)
    }

    pub(crate) fn call_function(
        &mut self,
        f: FuncId,
        mut frame: Vec<Value>,
        shape: &Shape,
        at: &RExpr,
    ) -> Result<Value, RtError> {
        let program = self.program;
        let def = &program.functions[f as usize];
        if def.is_const && def.arity == 0 {
            if let Some(v) = &self.const_values[f as usize] {
                return Ok(v.clone());
            }
            let initial = self.initial_with_own_stream(CONST_STREAMS + f as u64);
            self.enter(at, &def.name)?;
            let r = self.eval_with_locals(&def.locals, &def.body, &initial);
            self.depth -= 1;
            let v = r?;
            self.const_values[f as usize] = Some(v.clone());
            return Ok(v);
        }
        self.enter(at, &def.name)?;
        let mut r = Ok(Value::Bool(false));
        for l in &def.locals {
            match self.eval(l, &frame, shape) {
                Ok(v) => frame.push(v),
                Err(e) => {
                    r = Err(e);
                    break;
                }
            }
        }
        if r.is_ok() {
            r = self.eval(&def.body, &frame, shape);
        }
        self.depth -= 1;
        r
    }

    fn enter(&mut self, at: &RExpr, name: &str) -> Result<(), RtError> {
        if self.depth >= self.limits.max_depth {
            return Err(RtError::new(
                format!(
                    "evaluation depth limit ({}) reached in function `{name}`: it recurses without end",
                    self.limits.max_depth
                ),
                at.span,
            ).of_kind(crate::derive::RtErrorKind::Limit));
        }
        self.depth += 1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use cga_syntax::Span;
    use cga_value::Value;

    use crate::derive::{InitialInfo, Interp, Limits};
    use crate::expr::RExpr;

    /// A string literal evaluates to the lot's own copy: equal to the
    /// program's value but not its allocation (whose reference count the
    /// deriving threads would share), the same copy every time within a
    /// lot, and another lot's copy in another lot. Numbers are themselves.
    #[test]
    fn literals_evaluate_to_the_lots_own_copies() {
        let dir = std::env::temp_dir().join(format!("cga-engine-literals-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("literals.cga");
        std::fs::write(&path, "Lot --> X.\n").unwrap();
        let mut sources = cga_syntax::SourceMap::new();
        let program = crate::load(&cga_world::DiskWorld, &path, &mut sources)
            .usable()
            .expect("rules load");
        let assets = crate::assets::Assets::on_disk(&sources);
        let shape = crate::lot::initial_shape(&crate::lot::rect(2.0, 3.0), 0, 0);
        let lot = || {
            let info = InitialInfo {
                name: "lot".into(),
                start_rule: "Lot".into(),
                geo_origin: None,
            };
            Interp::new(
                &program,
                &assets,
                Limits::default(),
                info,
                shape.clone(),
                &[],
            )
        };
        let text: Arc<str> = Arc::from("facade/windows/sill.jpg");
        let literal = RExpr::constant(Value::Str(text.clone()), Span::default());
        let string = |v: Value| match v {
            Value::Str(s) => s,
            other => panic!("{other:?}"),
        };
        let mut first = lot();
        let a = string(first.eval(&literal, &[], &shape).unwrap());
        let b = string(first.eval(&literal, &[], &shape).unwrap());
        assert_eq!(a, text);
        assert!(!Arc::ptr_eq(&a, &text));
        assert!(Arc::ptr_eq(&a, &b));
        let c = string(lot().eval(&literal, &[], &shape).unwrap());
        assert_eq!(c, text);
        assert!(!Arc::ptr_eq(&c, &a));
        let number = RExpr::constant(Value::Float(2.5), Span::default());
        assert_eq!(first.eval(&number, &[], &shape).unwrap(), Value::Float(2.5));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
