//! Resolved expressions and rule bodies: the syntax tree with every name
//! replaced by what it refers to (a frame slot, an attribute, a function, a
//! built-in, an operation), ready to be evaluated without lookups.

use std::sync::Arc;

use cga_syntax::ast::{BinaryOp, BlockOp, UnaryOp};
use cga_syntax::Span;
use cga_value::Value;

use crate::ops::Op;
use crate::program::{AttrId, FuncId, RuleId};
use crate::selectors::Selector;
use crate::shape_fns::ShapeFn;

#[derive(Debug, Clone)]
pub struct RExpr {
    pub kind: RExprKind,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub enum RExprKind {
    Const(Value),
    /// A parameter or `with` local of the enclosing rule/function.
    Local(u16),
    Attr(AttrId),
    /// A user function or const (constness is on the definition).
    Func(FuncId, Vec<RExpr>),
    /// A built-in that depends on its arguments only.
    Pure(&'static crate::values::Builtin, Vec<RExpr>),
    /// A built-in that reads (or, for `rand`/`p`, advances) the current shape.
    Shape(ShapeFn, Vec<RExpr>),
    Unary {
        op: UnaryOp,
        elementwise: bool,
        operand: Box<RExpr>,
    },
    Binary {
        op: BinaryOp,
        elementwise: bool,
        lhs: Box<RExpr>,
        rhs: Box<RExpr>,
    },
    Array(Vec<Vec<RExpr>>),
    Range {
        base: Box<RExpr>,
        step: Option<Box<RExpr>>,
        limit: Box<RExpr>,
    },
    Index {
        base: Box<RExpr>,
        indices: Vec<RExpr>,
    },
    Case {
        branches: Vec<(RExpr, RExpr)>,
        otherwise: Option<Box<RExpr>>,
    },
    Stochastic {
        branches: Vec<(RExpr, RExpr)>,
        otherwise: Option<Box<RExpr>>,
    },
    /// `'e`: only meaningful as an operation argument or a split size.
    Relative(Box<RExpr>),
    /// `~e`: only meaningful as a split size.
    Floating(Box<RExpr>),
    /// `with ( x := e ... )` locals of an attribute default: evaluated in
    /// order into new frame slots, then the body.
    WithLocals {
        locals: Vec<RExpr>,
        body: Box<RExpr>,
    },
    /// The comp function `comp(f) { sel : expr | ... }`.
    CompFn {
        args: Vec<RExpr>,
        block: RBlock<RExpr>,
    },
    /// A block head of `comp` (operation or function): the selector text as
    /// written (for `comp.sel`) and the selection expression.
    CompHead {
        text: Arc<str>,
        expr: Box<RExpr>,
    },
    /// A selector keyword (`front`, `world.up`, `border`, `isTagged(q)`)
    /// inside a comp head, alone or combined with `!`, `&&`, `||`: true if
    /// the component being selected matches. Only the component split
    /// evaluates it (`ops::comp`); `args` are the arguments of `isTagged`.
    CompSelector(Selector, Vec<RExpr>),
}

impl RExpr {
    pub fn constant(value: Value, span: Span) -> RExpr {
        RExpr {
            kind: RExprKind::Const(value),
            span,
        }
    }

    /// Calls `f` with each expression directly inside this one, in source
    /// order (the analyses walk expressions with it).
    pub fn for_each_child(&self, f: &mut dyn FnMut(&RExpr)) {
        match &self.kind {
            RExprKind::Const(_) | RExprKind::Local(_) | RExprKind::Attr(_) => {}
            RExprKind::Func(_, args)
            | RExprKind::Pure(_, args)
            | RExprKind::Shape(_, args)
            | RExprKind::CompSelector(_, args) => args.iter().for_each(f),
            RExprKind::Unary { operand, .. } => f(operand),
            RExprKind::Binary { lhs, rhs, .. } => {
                f(lhs);
                f(rhs);
            }
            RExprKind::Array(rows) => rows.iter().flatten().for_each(f),
            RExprKind::Range { base, step, limit } => {
                f(base);
                if let Some(s) = step {
                    f(s);
                }
                f(limit);
            }
            RExprKind::Index { base, indices } => {
                f(base);
                indices.iter().for_each(f);
            }
            RExprKind::Case {
                branches,
                otherwise,
            }
            | RExprKind::Stochastic {
                branches,
                otherwise,
            } => {
                for (c, v) in branches {
                    f(c);
                    f(v);
                }
                if let Some(o) = otherwise {
                    f(o);
                }
            }
            RExprKind::Relative(inner) | RExprKind::Floating(inner) => f(inner),
            RExprKind::WithLocals { locals, body } => {
                locals.iter().for_each(&mut *f);
                f(body);
            }
            RExprKind::CompHead { expr, .. } => f(expr),
            RExprKind::CompFn { args, block } => {
                args.iter().for_each(&mut *f);
                block_exprs(block, f);
            }
        }
    }

    /// Whether `f` holds for some expression directly inside this one.
    pub fn any_child(&self, mut f: impl FnMut(&RExpr) -> bool) -> bool {
        let mut any = false;
        self.for_each_child(&mut |c| any = any || f(c));
        any
    }
}

/// The heads, depths and bodies of a comp function's block.
fn block_exprs(block: &RBlock<RExpr>, f: &mut dyn FnMut(&RExpr)) {
    for p in &block.parts {
        match p {
            RPart::Entry {
                head, depth, body, ..
            } => {
                f(head);
                if let Some(d) = depth {
                    f(d);
                }
                f(body);
            }
            RPart::Group(g) => block_exprs(g, f),
            RPart::Unlabeled { body, .. } => f(body),
        }
    }
}

/// What a rule body, a branch, a block entry or a push block does.
#[derive(Debug, Clone)]
pub enum RBody {
    Ops(Vec<RStmt>),
    Case {
        branches: Vec<(RExpr, RBody)>,
        otherwise: Option<Box<RBody>>,
    },
    Stochastic {
        branches: Vec<(RExpr, RBody)>,
        otherwise: Option<Box<RBody>>,
    },
}

#[derive(Debug, Clone)]
pub enum RStmt {
    Op(OpCall),
    Rule(RuleCall),
    /// `Name.`, or a call of a rule name that has no rule: a leaf shape.
    Leaf(u32),
    Nil,
    Push(RBody),
    /// A CGA operation this engine does not run yet: a warning, the shape unchanged.
    Unsupported {
        name: String,
        span: Span,
    },
}

#[derive(Debug, Clone)]
pub struct OpCall {
    pub op: Op,
    pub args: Vec<RExpr>,
    pub block: Option<RBlock<RBody>>,
    /// The second block of `splitAndSetbackPerimeter(..) { .. } { remainder : .. }`.
    pub remainder_block: Option<RBlock<RBody>>,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub struct RuleCall {
    pub rule: RuleId,
    pub args: Vec<RExpr>,
    /// A dynamic import call (`imp(h = 2).Lot`, also `imp().Lot`): the
    /// imported rule set's attributes are initialised anew for this call.
    pub dynamic: bool,
    /// Attribute values set for this call only.
    pub attr_overrides: Vec<(AttrId, RExpr)>,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub struct RBlock<T> {
    pub parts: Vec<RPart<T>>,
    pub repeat: bool,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub enum RPart<T> {
    Entry {
        head: RExpr,
        /// `splitAndSetbackPerimeter` entries: `length : depth : operations`.
        depth: Option<RExpr>,
        op: BlockOp,
        body: T,
        span: Span,
    },
    Group(RBlock<T>),
    /// A part without head (`union { A | B }`, `scatter(...) { Leaf }`).
    Unlabeled {
        body: T,
        span: Span,
    },
}
