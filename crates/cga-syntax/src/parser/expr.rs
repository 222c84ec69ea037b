//! Expressions: literals, names, calls, operators, arrays, ranges, indexing,
//! case/stochastic chains, the comp function and the `'`/`~` size prefixes.

use super::Parser;
use crate::ast::*;
use crate::lexer::{self, Tok};
use crate::span::Span;

/// Binary operators by token: (operator, element-wise, precedence).
/// Higher precedence binds tighter.
pub(super) fn binary_op(kind: Tok) -> Option<(BinaryOp, bool, u8)> {
    use BinaryOp::*;
    Some(match kind {
        Tok::OrOr => (Or, false, 1),
        Tok::DotOrOr => (Or, true, 1),
        Tok::AndAnd => (And, false, 2),
        Tok::DotAndAnd => (And, true, 2),
        Tok::EqEq => (Eq, false, 3),
        Tok::Ne => (Ne, false, 3),
        Tok::DotEqEq => (Eq, true, 3),
        Tok::DotNe => (Ne, true, 3),
        Tok::Lt => (Lt, false, 4),
        Tok::Le => (Le, false, 4),
        Tok::Gt => (Gt, false, 4),
        Tok::Ge => (Ge, false, 4),
        Tok::DotLt => (Lt, true, 4),
        Tok::DotLe => (Le, true, 4),
        Tok::DotGt => (Gt, true, 4),
        Tok::DotGe => (Ge, true, 4),
        Tok::Plus => (Add, false, 5),
        Tok::Minus => (Sub, false, 5),
        Tok::DotPlus => (Add, true, 5),
        Tok::DotMinus => (Sub, true, 5),
        Tok::Star => (Mul, false, 6),
        Tok::Slash => (Div, false, 6),
        Tok::Percent => (Rem, false, 6),
        Tok::DotStar => (Mul, true, 6),
        Tok::DotSlash => (Div, true, 6),
        Tok::DotPercent => (Rem, true, 6),
        _ => return None,
    })
}

pub(super) fn unary_op(kind: Tok) -> Option<(UnaryOp, bool)> {
    Some(match kind {
        Tok::Minus => (UnaryOp::Neg, false),
        Tok::Plus => (UnaryOp::Plus, false),
        Tok::Bang => (UnaryOp::Not, false),
        Tok::DotMinus => (UnaryOp::Neg, true),
        Tok::DotPlus => (UnaryOp::Plus, true),
        Tok::DotBang => (UnaryOp::Not, true),
        _ => return None,
    })
}

impl Parser<'_> {
    /// A full expression: a case chain, a stochastic chain or an operator
    /// expression. Used wherever a value stands on its own (definitions,
    /// arguments, array elements, branch values, parentheses).
    pub(super) fn parse_expr(&mut self) -> Expr {
        if !self.enter() {
            return self.missing_expr();
        }
        let expr = self.parse_expr_inner();
        self.leave();
        expr
    }

    fn parse_expr_inner(&mut self) -> Expr {
        match self.cur() {
            Tok::Case => {
                let chain = self.parse_case_chain(&mut |p: &mut Parser| p.parse_expr());
                let span = chain.span;
                Expr {
                    kind: ExprKind::Case(chain),
                    span,
                }
            }
            Tok::Number if self.is_percent_at(self.pos) => {
                let chain = self.parse_stochastic_chain(&mut |p: &mut Parser| p.parse_expr());
                let span = chain.span;
                Expr {
                    kind: ExprKind::Stochastic(chain),
                    span,
                }
            }
            _ => self.parse_binary(0),
        }
    }

    /// An argument or a block head: a full expression, optionally behind any
    /// number of size prefixes `'` (relative) and `~` (floating), which apply
    /// to the whole expression (`'1.85*8` is relative 14.8).
    pub(super) fn parse_arg(&mut self) -> Expr {
        let mut prefixes = Vec::new();
        // Each prefix nests the tree one level deeper: count it against the
        // depth limit (dropping a tree recurses too).
        while matches!(self.cur(), Tok::Quote | Tok::Tilde) && self.enter() {
            prefixes.push((self.cur(), self.tok_at(self.pos).start));
            self.bump();
        }
        let mut expr = self.parse_expr();
        for _ in &prefixes {
            self.leave();
        }
        for (kind, start) in prefixes.into_iter().rev() {
            let span = Span::new(self.file, start, expr.span.end);
            let inner = Box::new(expr);
            expr = Expr {
                kind: if kind == Tok::Quote {
                    ExprKind::Relative(inner)
                } else {
                    ExprKind::Floating(inner)
                },
                span,
            };
        }
        expr
    }

    /// `case c : v  case c : v  else : v` with `value` parsing each branch.
    pub(super) fn parse_case_chain<T>(
        &mut self,
        value: &mut dyn FnMut(&mut Parser) -> T,
    ) -> CaseChain<T> {
        let start = self.tok_at(self.pos).start;
        let mut branches = Vec::new();
        while self.cur() == Tok::Case {
            self.bump();
            let mark = self.diags.len();
            let cond = self.parse_binary(0);
            if !self.eat(Tok::Colon) && self.diags.len() == mark {
                self.expected("`:` after the `case` condition", "expected `:`");
            }
            branches.push((cond, value(self)));
        }
        let otherwise = self.parse_else(value, "`case`");
        CaseChain {
            branches,
            otherwise,
            span: self.span_from(start),
        }
    }

    /// `30% : v  20% : v  else : v`
    pub(super) fn parse_stochastic_chain<T>(
        &mut self,
        value: &mut dyn FnMut(&mut Parser) -> T,
    ) -> StochasticChain<T> {
        let start = self.tok_at(self.pos).start;
        let mut branches = Vec::new();
        while self.is_percent_at(self.pos) {
            let percent = self.parse_number();
            self.bump(); // %
            self.bump(); // :
            branches.push((percent, value(self)));
        }
        let otherwise = self.parse_else(value, "`%`");
        StochasticChain {
            branches,
            otherwise,
            span: self.span_from(start),
        }
    }

    fn parse_else<T>(
        &mut self,
        value: &mut dyn FnMut(&mut Parser) -> T,
        kind: &str,
    ) -> Option<Box<T>> {
        if self.eat(Tok::Else) {
            let mark = self.diags.len();
            if !self.eat(Tok::Colon) && self.diags.len() == mark {
                self.expected("`:` after `else`", "expected `:`");
            }
            return Some(Box::new(value(self)));
        }
        let next = if kind == "`case`" {
            "`case` or `else`"
        } else {
            "another `%` branch or `else`"
        };
        self.expected(
            &format!("{next} to continue the chain"),
            &format!("a {kind} chain must end with an `else` branch"),
        );
        None
    }

    /// Operator expressions by precedence climbing (left associative).
    fn parse_binary(&mut self, min_prec: u8) -> Expr {
        let mut lhs = self.parse_unary();
        // Every operator of a chain `a + b + c ...` nests the left operand
        // one level deeper: count the levels against the depth limit.
        let mut levels = 0;
        while let Some((op, elementwise, prec)) = binary_op(self.cur()) {
            if prec < min_prec {
                break;
            }
            // `30% :` starts the next stochastic branch, it is no remainder.
            if op == BinaryOp::Rem && !elementwise && self.nth(1) == Tok::Colon {
                break;
            }
            if !self.enter() {
                break;
            }
            levels += 1;
            self.bump();
            let rhs = self.parse_binary(prec + 1);
            let span = lhs.span.to(rhs.span);
            lhs = Expr {
                kind: ExprKind::Binary {
                    op,
                    elementwise,
                    lhs: Box::new(lhs),
                    rhs: Box::new(rhs),
                },
                span,
            };
        }
        for _ in 0..levels {
            self.leave();
        }
        lhs
    }

    fn parse_unary(&mut self) -> Expr {
        if !self.enter() {
            return self.missing_expr();
        }
        let expr = if let Some((op, elementwise)) = unary_op(self.cur()) {
            let start = self.tok_at(self.pos).start;
            self.bump();
            let operand = self.parse_unary();
            Expr {
                span: Span::new(self.file, start, operand.span.end),
                kind: ExprKind::Unary {
                    op,
                    elementwise,
                    operand: Box::new(operand),
                },
            }
        } else if matches!(self.cur(), Tok::Quote | Tok::Tilde) {
            let span = self.cur_span();
            let which = if self.cur() == Tok::Quote { "'" } else { "~" };
            self.error(
                format!("the size prefix `{which}` must stand at the start of an argument or a split size"),
                span,
                "not allowed inside an expression",
            );
            self.parse_arg()
        } else {
            self.parse_postfix()
        };
        self.leave();
        expr
    }

    fn parse_postfix(&mut self) -> Expr {
        let mut expr = self.parse_primary();
        let mut levels = 0;
        while self.cur() == Tok::LBracket && self.enter() {
            levels += 1;
            let open = self.pos;
            self.bump();
            let mut indices = Vec::new();
            if self.cur() == Tok::RBracket {
                let span = self.cur_span();
                self.error("expected an index inside `[ ]`", span, "empty index");
                self.bump();
            } else {
                loop {
                    let mark = self.diags.len();
                    indices.push(self.parse_element());
                    if self.eat(Tok::Comma) {
                        continue;
                    }
                    if self.eat(Tok::RBracket) {
                        break;
                    }
                    self.close_list_after_error(open, mark, "`]` to close the index", "`,` or `]`");
                    break;
                }
            }
            let span = self.span_from(expr.span.start);
            expr = Expr {
                kind: ExprKind::Index {
                    base: Box::new(expr),
                    indices,
                },
                span,
            };
        }
        for _ in 0..levels {
            self.leave();
        }
        expr
    }

    /// An element of an array or an index: an expression or a range
    /// `base : limit`, `base : step : limit`.
    fn parse_element(&mut self) -> Expr {
        let base = self.parse_expr();
        if !self.eat(Tok::Colon) {
            return base;
        }
        let second = self.parse_binary(0);
        let (step, limit) = if self.eat(Tok::Colon) {
            (Some(Box::new(second)), self.parse_binary(0))
        } else {
            (None, second)
        };
        let span = base.span.to(limit.span);
        Expr {
            kind: ExprKind::Range {
                base: Box::new(base),
                step,
                limit: Box::new(limit),
            },
            span,
        }
    }

    fn parse_number(&mut self) -> Expr {
        let text = self.text_at(self.pos);
        let value = text.parse::<f64>().unwrap_or(f64::NAN);
        let span = self.cur_span();
        self.bump();
        Expr {
            kind: ExprKind::Float(value),
            span,
        }
    }

    /// Stands in for an expression that is missing after a syntax error
    /// (an empty name); a module with errors is never evaluated.
    fn missing_expr(&self) -> Expr {
        let span = Span::new(self.file, self.prev_end(), self.prev_end());
        Expr {
            kind: ExprKind::Name(Ident {
                name: String::new(),
                span,
            }),
            span,
        }
    }

    fn parse_primary(&mut self) -> Expr {
        let start = self.tok_at(self.pos).start;
        match self.cur() {
            Tok::Number => self.parse_number(),
            Tok::Str => {
                let value = lexer::string_value(self.text_at(self.pos));
                let span = self.cur_span();
                self.bump();
                Expr {
                    kind: ExprKind::Str(value),
                    span,
                }
            }
            Tok::True | Tok::False => {
                let value = self.cur() == Tok::True;
                let span = self.cur_span();
                self.bump();
                Expr {
                    kind: ExprKind::Bool(value),
                    span,
                }
            }
            Tok::Ident | Tok::Start => {
                let name = self.ident_here();
                self.bump();
                if self.cur() != Tok::LParen {
                    let span = name.span;
                    return Expr {
                        kind: ExprKind::Name(name),
                        span,
                    };
                }
                let args = self.parse_args();
                if name.name == "comp" && self.cur() == Tok::LBrace {
                    let block = self.parse_block(|p, _, _| p.parse_expr(), false, false);
                    return Expr {
                        kind: ExprKind::CompFn { args, block },
                        span: self.span_from(start),
                    };
                }
                Expr {
                    kind: ExprKind::Call { name, args },
                    span: self.span_from(start),
                }
            }
            Tok::LParen => {
                let open = self.pos;
                self.bump();
                let mark = self.diags.len();
                let mut inner = self.parse_expr();
                if !self.eat(Tok::RParen) {
                    self.close_list_after_error(open, mark, "`)` to close the parenthesis", "`)`");
                }
                inner.span = self.span_from(start);
                inner
            }
            Tok::LBracket => self.parse_array(),
            _ => {
                self.expected("an expression", "expected an expression");
                self.missing_expr()
            }
        }
    }

    /// `(a, 'b, ~c)`: the argument list of a call (the `(` is current).
    pub(super) fn parse_args(&mut self) -> Vec<Expr> {
        let open = self.pos;
        self.bump();
        let mut args = Vec::new();
        if self.eat(Tok::RParen) {
            return args;
        }
        loop {
            let mark = self.diags.len();
            args.push(self.parse_arg());
            if self.eat(Tok::Comma) {
                continue;
            }
            if self.eat(Tok::RParen) {
                break;
            }
            self.close_list_after_error(open, mark, "`)` to close the argument list", "`,` or `)`");
            break;
        }
        args
    }

    /// `[a, b; c, d]`, `[0:2; 3, 3, 3]`
    fn parse_array(&mut self) -> Expr {
        let open = self.pos;
        let start = self.tok_at(open).start;
        self.bump();
        let mut rows = vec![Vec::new()];
        if self.cur() == Tok::RBracket {
            let span = self.span_from(start).to(self.cur_span());
            self.error("an array needs at least one element", span, "empty array");
            self.note(
                "create empty arrays with `floatArray()`, `boolArray()` or `stringArray()`"
                    .to_string(),
            );
            self.bump();
            rows.clear();
        } else {
            loop {
                let mark = self.diags.len();
                let element = self.parse_element();
                if let Some(row) = rows.last_mut() {
                    row.push(element);
                }
                match self.cur() {
                    Tok::Comma => self.bump(),
                    Tok::Semi => {
                        self.bump();
                        rows.push(Vec::new());
                    }
                    Tok::RBracket => {
                        self.bump();
                        break;
                    }
                    _ => {
                        self.close_list_after_error(
                            open,
                            mark,
                            "`]` to close the array",
                            "`,`, `;` or `]`",
                        );
                        break;
                    }
                }
            }
        }
        Expr {
            kind: ExprKind::Array(rows),
            span: self.span_from(start),
        }
    }
}
