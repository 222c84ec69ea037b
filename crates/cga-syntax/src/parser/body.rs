//! Rule bodies: operation sequences, case and stochastic chains, push/pop,
//! and the `{ ... }` blocks after split, comp and friends.

use super::Parser;
use crate::ast::*;
use crate::lexer::Tok;

/// What, besides the start of a new top-level item, ends a body.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) struct Term(u8);

impl Term {
    /// A rule body: only the next item ends it.
    pub const NONE: Term = Term(0);
    /// A block entry: `|` and `}`.
    pub const BLOCK: Term = Term(1);
    /// A push: `]`.
    pub const PUSH: Term = Term(2);
    /// A redefined rule in an import list: `,` and `)`.
    pub const IMPORT: Term = Term(4);
    /// A branch of a chain: `case`, `else`, `30%`.
    pub const CHAIN: Term = Term(8);
    /// The enclosing bracket is never closed: a function definition
    /// `name = ...` then ends the body after all.
    pub const UNCLOSED: Term = Term(16);

    fn has(self, other: Term) -> bool {
        self.0 & other.0 != 0
    }

    fn with(self, other: Term) -> Term {
        Term(self.0 | other.0)
    }

    /// Inside brackets `side = X` is a comp entry, not a function
    /// definition, so only unambiguous item starts end the body (unless
    /// the bracket is never closed).
    fn soft_item_starts(self) -> bool {
        self.has(Term::UNCLOSED) || !self.has(Term(Term::BLOCK.0 | Term::PUSH.0 | Term::IMPORT.0))
    }

    /// `term`, marked unclosed when the bracket at `open` has no partner.
    pub(super) fn inside(self, p: &Parser, open: usize) -> Term {
        if p.partner_of(open).is_some() {
            self
        } else {
            self.with(Term::UNCLOSED)
        }
    }
}

impl Parser<'_> {
    /// A body: a case chain, a stochastic chain or a sequence of operations.
    /// `after` names the token the body follows (for "expected operations after `-->`").
    pub(super) fn parse_body(&mut self, term: Term, after: &str) -> Body {
        if !self.enter() {
            return Body::Ops(Vec::new());
        }
        let chain_term = term.with(Term::CHAIN);
        let body = match self.cur() {
            Tok::Case => Body::Case(
                self.parse_case_chain(&mut |p: &mut Parser| p.parse_body(chain_term, "`:`")),
            ),
            Tok::Number if self.is_percent_at(self.pos) => Body::Stochastic(
                self.parse_stochastic_chain(&mut |p: &mut Parser| p.parse_body(chain_term, "`:`")),
            ),
            _ => Body::Ops(self.parse_ops(term, after)),
        };
        self.leave();
        body
    }

    fn at_body_end(&self, term: Term) -> bool {
        match self.cur() {
            Tok::Eof => true,
            Tok::Pipe | Tok::RBrace if term.has(Term::BLOCK) => true,
            Tok::RBracket if term.has(Term::PUSH) => true,
            Tok::Comma | Tok::RParen if term.has(Term::IMPORT) => true,
            Tok::Case | Tok::Else if term.has(Term::CHAIN) => true,
            Tok::Number if term.has(Term::CHAIN) && self.is_percent_at(self.pos) => true,
            // In a block, what cannot start an operation but starts an
            // entry (`2 : B`, `'0.5 : B`, `side = B`, `isTagged("x") : B`)
            // means a `|` is missing: end the body so that the block says so.
            Tok::Number | Tok::Quote | Tok::Tilde if term.has(Term::BLOCK) => true,
            Tok::Ident if term.has(Term::BLOCK) && self.is_entry_head() => true,
            _ => self.is_item_start(term.soft_item_starts()),
        }
    }

    /// `name :`, `name =`, `name =:`, `f(...) :` at the current token.
    fn is_entry_head(&self) -> bool {
        let after = match self.nth(1) {
            Tok::LParen => match self.partner_of(self.pos + 1) {
                Some(close) => self.kind_at(close + 1),
                None => return false,
            },
            k => k,
        };
        matches!(after, Tok::Colon | Tok::Eq | Tok::EqColon)
    }

    /// Skips a bad stretch of a body: up to where the body ends, without
    /// stopping inside brackets opened within the stretch.
    fn skip_to_body_end(&mut self, term: Term) {
        let mut depth = 0usize;
        loop {
            if depth == 0 && self.at_body_end(term) {
                return;
            }
            match self.cur() {
                Tok::Eof => return,
                Tok::LParen | Tok::LBracket | Tok::LBrace => depth += 1,
                Tok::RParen | Tok::RBracket | Tok::RBrace => depth = depth.saturating_sub(1),
                _ if depth > 0 && self.is_item_start(false) => return,
                _ => {}
            }
            self.bump();
        }
    }

    fn parse_ops(&mut self, term: Term, after: &str) -> Vec<Stmt> {
        let mut stmts = Vec::new();
        let mark = self.diags.len();
        // Whether the previous statement reported an error: a stray token
        // right after it is a consequence, not worth a second report.
        let mut prev_errored = false;
        loop {
            if self.at_body_end(term) {
                break;
            }
            let before = self.pos;
            let stmt_mark = self.diags.len();
            match self.cur() {
                Tok::Ident | Tok::Start => stmts.push(self.parse_name_stmt()),
                // `NIL.` is a leaf named NIL, not a deletion (CityEngine
                // keeps the shape: `split(x) { 5 : NIL | ~1 : NIL. }`).
                Tok::Nil if self.nth(1) == Tok::Dot && self.touches(self.pos, self.pos + 1) => {
                    let name = self.ident_here();
                    self.bump();
                    self.bump();
                    stmts.push(Stmt::Leaf(name));
                }
                Tok::Nil => {
                    stmts.push(Stmt::Nil(self.cur_span()));
                    self.bump();
                }
                Tok::LBracket => stmts.push(self.parse_push()),
                Tok::Case | Tok::Else => {
                    let span = self.cur_span();
                    let message = if self.cur() == Tok::Case {
                        "a `case` chain must stand at the start of a body"
                    } else {
                        "`else` without a preceding `case` or `%` branch"
                    };
                    self.error(message, span, "conditions cannot follow operations");
                    self.note(
                        "put the conditional in a push `[ case ... ]` to run it after operations"
                            .to_string(),
                    );
                    self.skip_to_body_end(term);
                }
                Tok::Number if self.is_percent_at(self.pos) => {
                    let span = self.cur_span();
                    self.error(
                        "a stochastic chain must stand at the start of a body",
                        span,
                        "percentages cannot follow operations",
                    );
                    self.skip_to_body_end(term);
                }
                Tok::Dot if self.pos > 0 && Self::is_name(self.kind_at(self.pos - 1)) => {
                    let span = self.cur_span();
                    self.error(
                        "unexpected `.`: a leaf is written `Name.` without space before the dot",
                        span,
                        "unexpected `.`",
                    );
                    self.bump();
                }
                _ => {
                    if !prev_errored {
                        self.expected(
                            "an operation, a rule, `NIL`, a leaf `Name.` or `[`",
                            "expected an operation",
                        );
                    }
                    self.skip_to_body_end(term);
                }
            }
            if self.pos == before {
                self.bump();
            }
            prev_errored = self.diags.len() > stmt_mark;
        }
        if stmts.is_empty() && self.diags.len() == mark {
            if self.pos > 0 && (self.cur() == Tok::Eof || self.is_item_start(true)) {
                // `R -->` at the end of its line: point at the arrow, not
                // at the next declaration.
                let next = if self.cur() == Tok::Eof {
                    "end of file"
                } else {
                    "the next declaration"
                };
                let span = self.span_at(self.pos - 1);
                self.error(
                    format!("expected operations after {after}, found {next}"),
                    span,
                    "empty body",
                );
            } else {
                self.expected(&format!("operations after {after}"), "expected operations");
            }
            self.note(
                "write `NIL` to delete the shape or `Name.` to keep it as a leaf".to_string(),
            );
        }
        stmts
    }

    /// `[ body ]`
    fn parse_push(&mut self) -> Stmt {
        let open = self.pos;
        let start = self.tok_at(open).start;
        self.bump();
        let body = self.parse_body(Term::PUSH.inside(self, open), "`[`");
        if !self.eat(Tok::RBracket) && !self.lex_error_since(open) {
            self.expected("`]` to close the push", "expected `]`");
            self.note_opened_at("`[`", open);
        }
        Stmt::Push(body, self.span_from(start))
    }

    /// A statement starting with a name: `Leaf.`, `Rule`, `op(args)`,
    /// `op(args) { block }*`, `imp(attr = v).Rule`.
    fn parse_name_stmt(&mut self) -> Stmt {
        let name_at = self.pos;
        let mut name = self.ident_here();
        let start = name.span.start;
        self.bump();
        if self.cur() == Tok::Dot && self.touches(name_at, self.pos) {
            self.bump();
            return Stmt::Leaf(name);
        }
        let mut import_overrides = None;
        let mut args = None;
        if self.cur() == Tok::LParen {
            if self.is_dynamic_import(self.pos) {
                import_overrides = Some(self.parse_import_overrides());
                self.bump(); // the `.`
                let member = self.ident_here();
                self.bump();
                name = Ident {
                    name: format!("{}.{}", name.name, member.name),
                    span: name.span.to(member.span),
                };
                if self.cur() == Tok::LParen {
                    args = Some(self.parse_args());
                }
            } else {
                args = Some(self.parse_args());
            }
        }
        let block = if self.cur() == Tok::LBrace {
            Some(self.parse_block(parse_entry_body, true, true))
        } else {
            None
        };
        let remainder_block = if block.is_some() && self.cur() == Tok::LBrace {
            Some(self.parse_block(parse_entry_body, true, true))
        } else {
            None
        };
        if self.cur() == Tok::Dot && self.touches(self.pos - 1, self.pos) {
            let span = self.cur_span();
            self.error(
                "unexpected `.` after an operation",
                span,
                "a leaf `Name.` takes no arguments",
            );
            self.bump();
        }
        Stmt::Call(Call {
            name,
            import_overrides,
            args,
            block,
            remainder_block,
            span: self.span_from(start),
        })
    }

    /// `imp( ... ).Lot`: a `(` whose partner is followed by `.Name`.
    fn is_dynamic_import(&self, open: usize) -> bool {
        match self.partner_of(open) {
            Some(close) => {
                self.kind_at(close + 1) == Tok::Dot
                    && Self::is_name(self.kind_at(close + 2))
                    && self.touches(close + 1, close + 2)
            }
            None => false,
        }
    }

    /// `{ part | part | ... }` with an optional `*` (when `repeat` is allowed).
    /// Parts are nested groups `{ ... }*`, entries `head op value`, and, for
    /// blocks after operations (`op_block`), bodies without a head
    /// (`union { A | B }`) and entries with a second head (`2 : 4 : X`).
    pub(super) fn parse_block<T>(
        &mut self,
        value: fn(&mut Parser, &str, Term) -> T,
        repeat_allowed: bool,
        op_block: bool,
    ) -> Block<T> {
        let open = self.pos;
        let start = self.tok_at(open).start;
        self.bump();
        let mut parts = Vec::new();
        if !self.enter() {
            return Block {
                parts,
                repeat: false,
                span: self.span_from(start),
            };
        }
        if self.cur() == Tok::RBrace {
            let span = self.span_from(start).to(self.cur_span());
            self.error(
                "empty block",
                span,
                "expected at least one entry such as `1 : X`",
            );
            self.bump();
        } else {
            self.parse_block_parts(open, value, op_block, &mut parts);
        }
        self.leave();
        let repeat = repeat_allowed && self.eat(Tok::Star);
        Block {
            parts,
            repeat,
            span: self.span_from(start),
        }
    }

    fn parse_block_parts<T>(
        &mut self,
        open: usize,
        value: fn(&mut Parser, &str, Term) -> T,
        op_block: bool,
        parts: &mut Vec<BlockPart<T>>,
    ) {
        // Whether the parts of this block have heads, decided by the first
        // part that is not a group: a block does not mix the two kinds, so
        // that `{ top : A | side B }` is an error (missing `:`), not a
        // headed entry followed by a bare body.
        let mut unlabeled: Option<bool> = None;
        let unclosed = self.partner_of(open).is_none();
        loop {
            let mark = self.diags.len();
            let part_start = self.cur_span().start;
            match self.cur() {
                Tok::LBrace => {
                    let group = self.parse_block(value, true, op_block);
                    parts.push(BlockPart::Group(group));
                }
                Tok::Pipe | Tok::RBrace => {
                    self.expected("a block entry such as `1 : X`", "expected an entry");
                }
                Tok::Eof => {}
                _ if *unlabeled.get_or_insert_with(|| op_block && self.is_unlabeled_part()) => {
                    let body = value(self, "`{`", Term::BLOCK.inside(self, open));
                    parts.push(BlockPart::Unlabeled {
                        body,
                        span: self.span_from(part_start),
                    });
                }
                _ => {
                    let head = self.parse_arg();
                    let op = match self.cur() {
                        Tok::Colon => Some((BlockOp::Colon, "`:`")),
                        Tok::Eq => Some((BlockOp::Equals, "`=`")),
                        Tok::EqColon => Some((BlockOp::EqualsColon, "`=:`")),
                        _ => None,
                    };
                    if let Some((op, after)) = op {
                        self.bump();
                        let mut depth = None;
                        if op_block && op == BlockOp::Colon && self.has_second_head() {
                            depth = Some(self.parse_arg());
                            self.expect(Tok::Colon, "`:` after the setback depth", "expected `:`");
                        }
                        let body = value(self, after, Term::BLOCK.inside(self, open));
                        parts.push(BlockPart::Entry(BlockEntry {
                            head,
                            depth,
                            op,
                            body,
                            span: self.span_from(part_start),
                        }));
                    } else if self.diags.len() == mark {
                        self.expected(
                            "`:`, `=` or `=:` after the block entry's head",
                            "expected `:`",
                        );
                    }
                }
            }
            // Separator or end.
            if self.eat(Tok::Pipe) {
                continue;
            }
            if self.eat(Tok::RBrace) {
                return;
            }
            if self.diags.len() == mark && !self.lex_error_since(open) {
                if self.cur() == Tok::Eof || self.is_item_start(unclosed) {
                    self.expected("`}` to close the block", "expected `}`");
                    self.note_opened_at("`{`", open);
                } else {
                    self.expected("`|` or `}` after the block entry", "expected `|` or `}`");
                }
            }
            // Resume at the next `|` or `}` of this block.
            let mut depth = 0usize;
            loop {
                match self.cur() {
                    Tok::Eof => return,
                    Tok::Pipe if depth == 0 => break,
                    Tok::RBrace if depth == 0 => break,
                    Tok::LParen | Tok::LBracket | Tok::LBrace => depth += 1,
                    Tok::RParen | Tok::RBracket | Tok::RBrace => depth = depth.saturating_sub(1),
                    _ if self.is_item_start(unclosed) => return,
                    _ => {}
                }
                self.bump();
            }
            if self.eat(Tok::RBrace) {
                return;
            }
            self.bump(); // `|`
        }
    }

    /// Whether the current token starts `depth :`, the second head of a
    /// splitAndSetbackPerimeter entry (`length : depth : ops`): one
    /// operand-operator-operand expression followed by `:`. A body never
    /// looks like that: two operands in a row (`X 2 : Y`) are two things.
    fn has_second_head(&self) -> bool {
        use super::expr::{binary_op, unary_op};
        let mut i = self.pos;
        while matches!(self.kind_at(i), Tok::Quote | Tok::Tilde) {
            i += 1;
        }
        let skip_group = |i: usize| self.partner_of(i).map(|close| close + 1);
        let mut want_operand = true;
        loop {
            let kind = self.kind_at(i);
            if want_operand {
                match kind {
                    k if unary_op(k).is_some() => i += 1,
                    Tok::Ident | Tok::Start | Tok::Number | Tok::Str | Tok::True | Tok::False => {
                        i += 1;
                        if self.kind_at(i) == Tok::LParen {
                            let Some(next) = skip_group(i) else {
                                return false;
                            };
                            i = next;
                        }
                        want_operand = false;
                    }
                    Tok::LParen | Tok::LBracket => {
                        let Some(next) = skip_group(i) else {
                            return false;
                        };
                        i = next;
                        want_operand = false;
                    }
                    _ => return false,
                }
            } else {
                match kind {
                    Tok::Colon => return true,
                    Tok::LBracket => {
                        let Some(next) = skip_group(i) else {
                            return false;
                        };
                        i = next;
                    }
                    k if binary_op(k).is_some() => {
                        i += 1;
                        want_operand = true;
                    }
                    _ => return false,
                }
            }
        }
    }

    /// Whether the block part at the current token has no head: it reaches
    /// `|` or `}` before any `:`, `=` or `=:` (`union { A | B }`,
    /// `scatter(...) { Leaf }`), or starts with a chain.
    fn is_unlabeled_part(&self) -> bool {
        if self.cur() == Tok::Case || self.is_percent_at(self.pos) {
            return true;
        }
        let mut i = self.pos;
        loop {
            match self.kind_at(i) {
                Tok::Colon | Tok::Eq | Tok::EqColon => return false,
                Tok::Eof | Tok::Pipe | Tok::RBrace | Tok::RParen | Tok::RBracket | Tok::Arrow => {
                    return true
                }
                Tok::LParen | Tok::LBracket | Tok::LBrace => match self.partner_of(i) {
                    Some(close) => i = close + 1,
                    None => return false,
                },
                _ => i += 1,
            }
        }
    }
}

fn parse_entry_body(p: &mut Parser, after: &str, term: Term) -> Body {
    p.parse_body(term, after)
}
